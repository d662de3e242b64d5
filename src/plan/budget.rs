//! Bounded work: before planning, an estimate of the CL points the settings ask for, from
//! the model's patches (area, side lengths, curvature at their middles), the scallop's side
//! step and the chordal tolerance's forward step; beyond the limit the plan is refused with
//! the estimate and the setting to change, within a moment instead of running on for
//! minutes (`plan dome --scallop 1e-9`).
//!
//! Owns: the estimate and the refusal. Must not: plan (it reads the surface, nothing else).

use super::isoparametric::{CHORD_MARGIN, CHORD_SCALLOP_SHARE};
use super::stepover::{chord_step, curve_curvature};
use super::{PlanOptions, Strategy};
use crate::error::{Error, Result};
use crate::model::Model;

/// Points per patch side the estimate samples the area with.
const AREA_SAMPLES: usize = 6;
/// Forward steps per pass and patch at least (the zig-zags step at most 1/8 of a patch).
const MIN_STEPS_PER_PASS: f64 = 8.0;
/// Bytes a CL point costs in the page, roughly: the move, its parameters and footprint in
/// the plan, the flat arrays handed to the page, the program's lines.
pub const BYTES_PER_CL_POINT: f64 = 600.0;

/// What the settings ask for, estimated before planning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkEstimate {
    /// CL points (the path's moves), estimated.
    pub cl_points: f64,
    /// Memory they take in the page (MB), at [`BYTES_PER_CL_POINT`].
    pub memory_mb: f64,
    /// The scallop-limited side step on a flat surface (mm), from the planners' share of the
    /// scallop.
    pub side_step_mm: f64,
    /// The surface's area (mm²).
    pub area_mm2: f64,
}

/// The CL points `opts` would give on `model`: per patch, passes across its shorter side at
/// the flat side step, each with as many forward steps as the chordal tolerance allows at
/// the curvature of its middle (at least [`MIN_STEPS_PER_PASS`]); the space-filling curve's
/// grid is scallop-limited both ways (area over the side step squared).
pub fn estimate(model: &Model, opts: &PlanOptions) -> WorkEstimate {
    estimate_from(&sample(model), opts)
}

/// What the estimate needs of a patch, sampled once (it does not depend on the settings):
/// its area and, per sample, the speed (mm per unit parameter) and curvature (1/mm) of the
/// u and v curves.
struct PatchSamples {
    area_mm2: f64,
    /// Per sample, `[(speed, curvature) along u, (speed, curvature) along v]`.
    curves: Vec<[(f64, f64); 2]>,
}

/// Every patch of `model` at `AREA_SAMPLES` × `AREA_SAMPLES` points.
fn sample(model: &Model) -> Vec<PatchSamples> {
    let n = AREA_SAMPLES;
    let cells = (n * n) as f64;
    model
        .layout
        .patches
        .iter()
        .map(|p| {
            let mut area_mm2 = 0.0;
            let mut curves = Vec::with_capacity(n * n);
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    let d = p.derivs(&model.surface, u, v);
                    area_mm2 += d.su.cross(&d.sv).norm() / cells;
                    curves.push([
                        (d.su.norm(), curve_curvature(&d.su, &d.suu)),
                        (d.sv.norm(), curve_curvature(&d.sv, &d.svv)),
                    ]);
                }
            }
            PatchSamples { area_mm2, curves }
        })
        .collect()
}

/// [`estimate`] from the patches' samples.
fn estimate_from(patches: &[PatchSamples], opts: &PlanOptions) -> WorkEstimate {
    let r = opts.tool_radius_mm;
    // The planners' share of the scallop for the side steps, and their chord tolerance.
    let h_target = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
    let h = (h_target / (1.0 + h_target / (2.0 * r))).min(r);
    let flat = (8.0 * r * h).sqrt().max(f64::MIN_POSITIVE);
    // The side step across a curve of curvature k taken as convex (the smaller step).
    let side = |k: f64| flat * (1.0 / (1.0 + k * r)).sqrt();
    let chord = CHORD_MARGIN
        * opts
            .chordal_mm
            .min(opts.overcut_mm())
            .min(CHORD_SCALLOP_SHARE * opts.scallop_mm);
    let mut points = 0.0;
    let mut area = 0.0;
    for p in patches {
        // Means over the samples: side lengths, steps per mm along and across u, v; the
        // largest curvatures (the space-filling curve's lines take the least step along the
        // whole line).
        let cells = p.curves.len() as f64;
        let mut len = [0.0; 2];
        let (mut per_side, mut per_chord) = ([0.0; 2], [0.0; 2]);
        let mut k_max: [f64; 2] = [0.0; 2];
        for sample in &p.curves {
            for (q, &(speed, k)) in sample.iter().enumerate() {
                len[q] += speed / cells;
                if speed <= 0.0 {
                    continue; // a collapsed side: no length, no steps
                }
                per_side[q] += 1.0 / side(k) / cells;
                per_chord[q] += 1.0 / chord_step(chord, k).min(speed / MIN_STEPS_PER_PASS) / cells;
                k_max[q] = k_max[q].max(k);
            }
        }
        area += p.area_mm2;
        points += match opts.strategy {
            // Lines stepped across each direction at the least step along them.
            Strategy::Isfc => {
                (len[0] / side(k_max[0])).max(1.0) * (len[1] / side(k_max[1])).max(1.0)
            }
            _ => {
                // Passes along the longer side, stepped across the shorter one.
                let (along, across) = if len[0] >= len[1] { (0, 1) } else { (1, 0) };
                let passes = (len[across] * per_side[across]).max(1.0);
                passes * len[along] * per_chord[along]
            }
        };
    }
    WorkEstimate {
        cl_points: points,
        memory_mb: points * BYTES_PER_CL_POINT / 1e6,
        side_step_mm: flat,
        area_mm2: area,
    }
}

/// Refuses settings whose estimate is beyond `opts.max_cl_points`, naming the estimate,
/// the limit and what to change.
pub fn check(model: &Model, opts: &PlanOptions) -> Result<WorkEstimate> {
    let patches = sample(model);
    let e = estimate_from(&patches, opts);
    let limit = opts.max_cl_points as f64;
    // Within the limit, or no estimate to go by (not finite): plan.
    if !(e.cl_points > limit && e.cl_points.is_finite()) {
        return Ok(e);
    }
    // The scallop that would bring it within the limit (the estimate falls as h grows).
    // The surface is sampled once; only the settings change.
    let fits = |h: f64| estimate_from(&patches, &opts.clone().with_scallop(h)).cl_points <= limit;
    let largest = opts.tool_radius_mm;
    let advice = if fits(largest) {
        let (mut lo, mut hi) = (opts.scallop_mm.ln(), largest.ln());
        for _ in 0..SCALLOP_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if fits(mid.exp()) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        format!(
            "raise the scallop height to about {} mm or more, use a larger ball or a larger chordal tolerance, or raise the limit",
            sig(hi.exp())
        )
    } else {
        "no scallop height up to the ball radius fits: use a larger ball, or raise the limit".into()
    };
    Err(Error::param(
        "scallop_mm",
        format!(
            "these settings need about {} CL points (≈ {} MB; {:.0} mm² at a side step of {} mm), more than the limit of {} (max_cl_points): {advice}",
            group(e.cl_points),
            group(e.memory_mb),
            e.area_mm2,
            sig(e.side_step_mm),
            group(limit),
        ),
    ))
}

/// Halvings of the (logarithmic) scallop interval when looking for one that fits.
const SCALLOP_BISECTIONS: usize = 30;

/// A length with four significant digits, in plain decimals where that reads well.
fn sig(x: f64) -> String {
    if (1e-3..1e4).contains(&x.abs()) {
        let d = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.d$}")
    } else {
        format!("{x:.3e}")
    }
}

/// A count with thousands separated by spaces, as the reports write them.
fn group(x: f64) -> String {
    if !x.is_finite() || x >= 1e15 {
        return format!("{x:.2e}");
    }
    let s = format!("{:.0}", x);
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}
