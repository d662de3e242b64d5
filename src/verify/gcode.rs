//! Programs as the verifier reads them: the machine module's reader and kinematics turn any
//! dialect the project writes (and common hand-written G-code) into tool tips and axes, and
//! this adapter hands those to [`CutterPath::from_tool_poses`]. Blocks in machine
//! coordinates (a `G53` retract, say) have no workpiece pose: the path is broken there.
//!
//! The header comment `tool: ... ball-end radius R mm, scallop H mm, chordal C mm` that the
//! post writes is read too, for the tolerances the program was made for.
//!
//! [`CutterPath::from_tool_poses`]: super::CutterPath::from_tool_poses

use super::cutter::{CutterPath, ToolTip};
use super::VerifyOptions;
use crate::error::{Error, Result};
use crate::machine::{reader, roundtrip, Dialect, Machine};

/// What a program's header says about the tool and the tolerances.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProgramHeader {
    /// Ball radius (mm), if stated.
    pub tool_radius_mm: Option<f64>,
    /// Scallop height asked of the planner (mm), if stated.
    pub scallop_mm: Option<f64>,
    /// Chordal tolerance of the planner (mm), if stated.
    pub chordal_mm: Option<f64>,
}

fn number_after(text: &str, key: &str) -> Option<f64> {
    let at = text.find(key)? + key.len();
    let rest = text[at..].trim_start();
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+'))
        .unwrap_or(rest.len());
    rest[..end].parse().ok()
}

impl ProgramHeader {
    /// The first line mentioning a `ball-end radius` (in a comment of any dialect).
    pub fn parse(text: &str) -> Self {
        text.lines()
            .find(|l| l.contains("ball-end radius"))
            .map(|l| ProgramHeader {
                tool_radius_mm: number_after(l, "ball-end radius"),
                scallop_mm: number_after(l, "scallop"),
                chordal_mm: number_after(l, "chordal"),
            })
            .unwrap_or_default()
    }
}

/// The tool tip and axis of every motion block of `text` on `machine` as `dialect` means it;
/// `None` for blocks without a workpiece pose. Errors name the line the reader stopped at.
pub fn read_tool_poses(
    text: &str,
    machine: &Machine,
    dialect: Dialect,
) -> Result<Vec<Option<ToolTip>>> {
    let program = reader::read(text)?;
    let poses = roundtrip::tool_poses(&program, machine, dialect);
    let out: Vec<Option<ToolTip>> = program
        .moves
        .iter()
        .zip(poses)
        .map(|(m, pose)| {
            pose.map(|p| ToolTip {
                tip: p.tip,
                tool_axis: p.axis,
                line: m.line,
            })
        })
        .collect();
    if out.iter().all(|p| p.is_none()) {
        return Err(Error::parse(
            "G-code",
            format!("line {}", text.lines().count()),
            "the program has no move with a known tool position in the workpiece frame",
        ));
    }
    Ok(out)
}

/// A program as a cutter path for a ball of radius `tool_radius_mm`, and its header. Errors
/// if the header states another radius (the program was made for another tool).
pub fn read_program(
    text: &str,
    tool_radius_mm: f64,
    machine: &Machine,
    dialect: Dialect,
) -> Result<(CutterPath, ProgramHeader)> {
    let header = ProgramHeader::parse(text);
    if let Some(hr) = header.tool_radius_mm {
        if hr != tool_radius_mm {
            return Err(Error::param(
                "tool_radius_mm",
                format!(
                    "the program says it was made for a ball-end radius {hr} mm, but the tool radius given is {tool_radius_mm} mm"
                ),
            ));
        }
    }
    let poses = read_tool_poses(text, machine, dialect)?;
    Ok((CutterPath::from_tool_poses(tool_radius_mm, poses)?, header))
}

impl ProgramHeader {
    /// Verification options for the tolerances the program was made for: its scallop, and
    /// as gouge tolerance its chordal tolerance or 0.002 mm, whichever is smaller
    /// ([`super::gouge_tolerance_for`]); defaults where it says nothing.
    pub fn options(&self) -> VerifyOptions {
        let mut o = VerifyOptions::default();
        if let Some(h) = self.scallop_mm {
            o.scallop_mm = h;
        }
        if let Some(c) = self.chordal_mm {
            o.gouge_tolerance_mm = super::gouge_tolerance_for(c);
        }
        o
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::builtin;

    #[test]
    fn header_and_moves() {
        let text = "%\n(tool: T1 ball-end radius 0.5 mm, scallop 0.01 mm, chordal 0.005 mm)\nG21 G90 G17\nG0 X1 Y2 Z3\nG1 Z1.5 F100\nX-1.25\nG53 G0 Z0\nG0 X0 Y0 Z5\nM2\n%\n";
        let h = ProgramHeader::parse(text);
        assert_eq!(
            (h.tool_radius_mm, h.scallop_mm, h.chordal_mm),
            (Some(0.5), Some(0.01), Some(0.005))
        );
        let m = builtin("3-axis").unwrap();
        let tips = read_tool_poses(text, &m, Dialect::LinuxCnc).unwrap();
        let xyz: Vec<Option<[f64; 3]>> = tips
            .iter()
            .map(|t| t.map(|t| [t.tip.x, t.tip.y, t.tip.z]))
            .collect();
        assert_eq!(
            xyz,
            vec![
                Some([1.0, 2.0, 3.0]),
                Some([1.0, 2.0, 1.5]),
                Some([-1.25, 2.0, 1.5]),
                None,
                Some([0.0, 0.0, 5.0])
            ]
        );
        assert_eq!(tips[1].unwrap().line, 5);
        assert!(tips
            .iter()
            .flatten()
            .all(|t| t.tool_axis == crate::geom::Vector3::z()));
    }

    #[test]
    fn errors_name_the_line() {
        let m = builtin("3-axis").unwrap();
        let e = read_tool_poses("G0 X0 Y0 Z0\nG2 X1 Y1 I0 J1\n", &m, Dialect::LinuxCnc)
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = read_tool_poses("(nothing)\n", &m, Dialect::LinuxCnc)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no move"), "{e}");
    }
}
