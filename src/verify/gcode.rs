//! Reads the three-axis G-code `tspath plan` writes (`machine::gcode_3axis`: tool-tip
//! `X Y Z`, tool axis +Z) back into tool tips, for [`CutterPath::from_tool_tips`].
//!
//! This is a small adapter, not a general interpreter: `G0`/`G1` moves in `G90`/`G91`,
//! `G20`/`G21`, comments in parentheses or after `;`, and the modal words the writer emits.
//! Anything that changes the geometry in ways it does not model (arcs, rotary axes, work
//! offsets, tool-length changes mid-program) is an error naming the line. Five-axis
//! programs come in through a dialect reader's tool tips and axes instead.
//!
//! [`CutterPath::from_tool_tips`]: super::CutterPath::from_tool_tips

use super::cutter::ToolTip;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};

/// What the program says, besides its moves.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodeProgram {
    /// Tool tips in program order, in mm, axis +Z.
    pub tips: Vec<ToolTip>,
    /// Ball radius from a `(tool: ball-end radius R mm, ...)` header comment, if present.
    pub header_tool_radius_mm: Option<f64>,
    /// Scallop height from the same header comment, if present.
    pub header_scallop_mm: Option<f64>,
    /// Chordal tolerance from the same header comment, if present.
    pub header_chordal_mm: Option<f64>,
}

/// Millimetres per inch.
const MM_PER_INCH: f64 = 25.4;

/// G codes that change nothing this reader models (plane, units handled separately, cutter
/// compensation off, tool length offset as programmed, canned cycles off, feed mode, exact
/// path, work coordinate systems G54–G59 taken as the model frame).
const HARMLESS_G: &[u32] = &[
    170, 180, 190, 400, 430, 490, 800, 940, 540, 550, 560, 570, 580, 590, 610, 640,
];

fn number_after(text: &str, key: &str) -> Option<f64> {
    let at = text.find(key)? + key.len();
    let rest = text[at..].trim_start();
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+'))
        .unwrap_or(rest.len());
    rest[..end].parse().ok()
}

/// Parses a program; errors name the line and the word.
pub fn read_3axis(text: &str) -> Result<GcodeProgram> {
    let err = |line: usize, msg: String| Error::parse("G-code", format!("line {line}"), msg);
    let mut prog = GcodeProgram {
        tips: Vec::new(),
        header_tool_radius_mm: None,
        header_scallop_mm: None,
        header_chordal_mm: None,
    };
    let mut pos: [Option<f64>; 3] = [None; 3];
    let mut motion: Option<u32> = None;
    let mut scale = 1.0;
    let mut absolute = true;
    for (idx, raw) in text.lines().enumerate() {
        let line_no = idx + 1;
        // Comments: (...) and ; to the end of the line. Header comments carry the tool.
        let mut code = String::with_capacity(raw.len());
        let mut rest = raw;
        while let Some(open) = rest.find(['(', ';']) {
            code.push_str(&rest[..open]);
            if rest[open..].starts_with(';') {
                rest = "";
                break;
            }
            let Some(close) = rest[open..].find(')') else {
                return Err(err(
                    line_no,
                    "comment `(` is not closed on this line".into(),
                ));
            };
            let comment = &rest[open + 1..open + close];
            if comment.trim_start().starts_with("tool:") {
                prog.header_tool_radius_mm = number_after(comment, "radius");
                prog.header_scallop_mm = number_after(comment, "scallop");
                prog.header_chordal_mm = number_after(comment, "chordal");
            }
            rest = &rest[open + close + 1..];
        }
        code.push_str(rest);
        let code = code.trim();
        if code.is_empty() || code == "%" {
            continue;
        }
        // Words: a letter and a number.
        let mut words: Vec<(char, f64, &str)> = Vec::new();
        let bytes = code.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let c = bytes[i] as char;
            if c.is_ascii_whitespace() {
                i += 1;
                continue;
            }
            if !c.is_ascii_alphabetic() {
                return Err(err(line_no, format!("expected a word letter, found `{c}`")));
            }
            let start = i + 1;
            let mut j = start;
            while j < bytes.len() && {
                let d = bytes[j] as char;
                d.is_ascii_digit() || d == '.' || d == '-' || d == '+' || d == ' '
            } {
                j += 1;
            }
            let num_text: String = code[start..j].chars().filter(|c| *c != ' ').collect();
            let value: f64 = num_text.parse().map_err(|_| {
                err(
                    line_no,
                    format!(
                        "word `{c}` needs a number, found `{}`",
                        code[start..j].trim()
                    ),
                )
            })?;
            if !value.is_finite() {
                return Err(err(line_no, format!("word `{c}` has a non-finite value")));
            }
            words.push((c.to_ascii_uppercase(), value, &code[i..j]));
            i = j;
        }
        let mut coords: [Option<f64>; 3] = [None; 3];
        let mut end = false;
        for &(letter, value, text) in &words {
            match letter {
                'G' => {
                    let g = (value * 10.0).round() as u32;
                    match g {
                        0 | 10 => motion = Some(g / 10),
                        20 | 30 => {
                            return Err(err(
                                line_no,
                                format!("`{}`: arcs are not supported by this reader", text.trim()),
                            ))
                        }
                        200 => scale = MM_PER_INCH,
                        210 => scale = 1.0,
                        900 => absolute = true,
                        910 => absolute = false,
                        g if HARMLESS_G.contains(&g) => {}
                        _ => {
                            return Err(err(
                                line_no,
                                format!("`{}` is not supported by the three-axis reader", text.trim()),
                            ))
                        }
                    }
                }
                'X' => coords[0] = Some(value),
                'Y' => coords[1] = Some(value),
                'Z' => coords[2] = Some(value),
                'A' | 'B' | 'C' => {
                    return Err(err(
                        line_no,
                        format!(
                            "rotary axis word `{}`: this reader takes three-axis programs (tool axis +Z); read five-axis programs with a dialect reader and pass its tool tips",
                            text.trim()
                        ),
                    ))
                }
                'M' => {
                    if matches!(value as u32, 2 | 30) && value.fract() == 0.0 {
                        end = true;
                    }
                }
                'F' | 'S' | 'T' | 'H' | 'N' | 'D' => {}
                other => {
                    return Err(err(
                        line_no,
                        format!("word `{other}` is not supported by the three-axis reader"),
                    ))
                }
            }
        }
        if coords.iter().any(|c| c.is_some()) {
            if motion.is_none() {
                return Err(err(
                    line_no,
                    "coordinates before any G0 or G1 motion mode".into(),
                ));
            }
            for k in 0..3 {
                if let Some(c) = coords[k] {
                    let c = c * scale;
                    pos[k] = Some(if absolute {
                        c
                    } else {
                        pos[k].unwrap_or(0.0) + c
                    });
                }
            }
            if let [Some(x), Some(y), Some(z)] = pos {
                prog.tips.push(ToolTip {
                    tip: Point3::new(x, y, z),
                    tool_axis: Vector3::z(),
                    line: line_no,
                });
            }
        }
        if end {
            break;
        }
    }
    if prog.tips.is_empty() {
        return Err(err(
            text.lines().count(),
            "the program has no move with all of X, Y and Z known".into(),
        ));
    }
    Ok(prog)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_modal_moves_units_and_header() {
        let text = "%\n(tool: ball-end radius 0.5 mm, scallop 0.01 mm, chordal 0.005 mm)\nG21 G90 G17\nG0 X1 Y2 Z3\nG1 Z1.5 F100\nX-1.25\nG91 X1\nG20 G90 X1 Y0 Z0\nM2\nG0 X9\n%\n";
        let p = read_3axis(text).unwrap();
        assert_eq!(p.header_tool_radius_mm, Some(0.5));
        assert_eq!(p.header_scallop_mm, Some(0.01));
        assert_eq!(p.header_chordal_mm, Some(0.005));
        let tips: Vec<[f64; 3]> = p.tips.iter().map(|t| [t.tip.x, t.tip.y, t.tip.z]).collect();
        assert_eq!(
            tips,
            vec![
                [1.0, 2.0, 3.0],
                [1.0, 2.0, 1.5],
                [-1.25, 2.0, 1.5],
                [-0.25, 2.0, 1.5],
                [25.4, 0.0, 0.0]
            ]
        );
        assert_eq!(p.tips[1].line, 5);
    }

    #[test]
    fn errors_name_the_line() {
        for (text, line, what) in [
            ("G0 X0 Y0 Z0\nG2 X1 Y1 I0 J1\n", 2, "arcs"),
            ("G0 X0 Y0 Z0 A30\n", 1, "rotary"),
            ("G1 X0 Y0 Z0\nG1 Xabc\n", 2, "number"),
            ("X1 Y1 Z1\n", 1, "motion mode"),
            ("G1 X0 Y0 Z0 (open\n", 1, "not closed"),
            ("G28\n", 1, "G28"),
            ("(nothing)\n", 1, "no move"),
        ] {
            let e = read_3axis(text).unwrap_err().to_string();
            assert!(
                e.contains(&format!("line {line}")) && e.contains(what),
                "{text:?}: {e}"
            );
        }
    }
}
