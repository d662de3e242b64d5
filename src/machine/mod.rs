//! Machines and G-code: turning a [`Toolpath`] into text a controller runs.
//!
//! Owns: post-processing (number formatting, modal words, program start and end).
//! Must not: plan or change the path.

use crate::plan::{MoveKind, PlanOptions, Toolpath};
use std::fmt::Write;

/// What the program header says about where the path came from.
#[derive(Debug, Clone, PartialEq)]
pub struct JobInfo {
    pub model: String,
    pub strategy: String,
}

/// Formats a coordinate in mm with 4 decimals (0.1 µm), without a negative zero.
fn coord(x: f64) -> String {
    let s = format!("{x:.4}");
    if s == "-0.0000" {
        "0.0000".into()
    } else {
        s
    }
}

/// Three-axis G-code for a controller in millimetres (LinuxCNC / Fanuc compatible subset):
/// positions are the tool tip (ball centre minus the radius along the axis), the axis must
/// be +Z. Deterministic: the same path gives the same bytes.
pub fn gcode_3axis(path: &Toolpath, opts: &PlanOptions, job: &JobInfo) -> String {
    let mut g = String::new();
    let r = path.tool_radius_mm;
    let _ = writeln!(g, "%");
    let _ = writeln!(
        g,
        "(tspath {} - three-axis finishing)",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(g, "(model: {})", sanitize(&job.model));
    let _ = writeln!(g, "(strategy: {})", sanitize(&job.strategy));
    let _ = writeln!(
        g,
        "(tool: ball-end radius {} mm, scallop {} mm, chordal {} mm)",
        opts.tool_radius_mm, opts.scallop_mm, opts.chordal_mm
    );
    let _ = writeln!(g, "(units: mm; positions are the tool tip)");
    let _ = writeln!(g, "G21 G90 G17 G94 G40 G49 G80");
    let _ = writeln!(g, "T1 M6");
    let _ = writeln!(g, "G43 H1");
    let _ = writeln!(g, "S{:.0} M3", opts.spindle_rpm);
    let mut feed: Option<f64> = None;
    for m in &path.moves {
        let tip = m.cl_point - m.tool_axis * r;
        let xyz = format!("X{} Y{} Z{}", coord(tip.x), coord(tip.y), coord(tip.z));
        match m.kind {
            MoveKind::Rapid | MoveKind::Retract => {
                let _ = writeln!(g, "G0 {xyz}");
            }
            MoveKind::Feed | MoveKind::Link | MoveKind::Plunge => {
                let f = if m.kind == MoveKind::Plunge {
                    opts.plunge_feed_mm_min
                } else {
                    opts.feed_mm_min
                };
                if feed != Some(f) {
                    let _ = writeln!(g, "G1 {xyz} F{f:.0}");
                    feed = Some(f);
                } else {
                    let _ = writeln!(g, "G1 {xyz}");
                }
            }
        }
    }
    let _ = writeln!(g, "M5");
    let _ = writeln!(g, "M2");
    let _ = writeln!(g, "%");
    g
}

/// Parentheses end a G-code comment: keep them out of names.
fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c == '(' || c == ')' || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect()
}
