//! The tool motion as the verifier sees it: a ball-end tool's centre (the cutter-location
//! point) at successive positions, joined by straight moves, with the tool axis at each.
//!
//! Built from a planned [`Toolpath`], from tool tips and axes (what a G-code reader gives:
//! the centre is the tip moved one radius along the axis), or from the JSON CL-data format
//! described in the README. Only the ball is simulated: the shank and holder are not.

use super::capsule::Capsule;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::plan::Toolpath;

/// One position of the tool.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterLocation {
    /// Ball centre (mm).
    pub cl_point: Point3,
    /// Unit tool axis, from the tip towards the spindle.
    pub tool_axis: Vector3,
}

/// A tool tip as a G-code reader reports it: the tip point, the tool axis and the source
/// line (for error messages).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolTip {
    /// Tool tip (mm): the lowest point of the ball along the axis.
    pub tip: Point3,
    /// Unit tool axis, from the tip towards the spindle.
    pub tool_axis: Vector3,
    /// 1-based line of the program this position comes from (0 if none).
    pub line: usize,
}

/// A ball-end tool's path: radius and centre positions in order, joined by straight moves
/// except where the path is broken.
#[derive(Debug, Clone, PartialEq)]
pub struct CutterPath {
    pub tool_radius_mm: f64,
    pub locations: Vec<CutterLocation>,
    /// Indices `i` of locations not reached by a straight move from location `i − 1` (the
    /// tool moved in a way the path does not know, e.g. in machine coordinates).
    pub breaks: Vec<usize>,
}

/// Largest deviation of a tool axis from unit length that is accepted (and normalised).
const AXIS_LENGTH_TOLERANCE: f64 = 1e-3;

impl CutterPath {
    /// Checks radius and positions: a positive finite radius, finite points, unit axes
    /// (within 0.1 %, then normalised), at least one position.
    pub fn try_new(tool_radius_mm: f64, locations: Vec<CutterLocation>) -> Result<Self> {
        if !(tool_radius_mm.is_finite() && tool_radius_mm > 0.0) {
            return Err(Error::param(
                "tool_radius_mm",
                format!("must be a positive number of mm, got {tool_radius_mm}"),
            ));
        }
        if locations.is_empty() {
            return Err(Error::param(
                "tool path",
                "has no positions: nothing to verify",
            ));
        }
        let mut out = Vec::with_capacity(locations.len());
        for (i, l) in locations.iter().enumerate() {
            if !l.cl_point.iter().all(|x| x.is_finite()) {
                return Err(Error::param(
                    "tool path",
                    format!("position {i} has a non-finite coordinate {:?}", l.cl_point),
                ));
            }
            let len = l.tool_axis.norm();
            if !((len - 1.0).abs() <= AXIS_LENGTH_TOLERANCE) {
                return Err(Error::param(
                    "tool path",
                    format!(
                        "position {i}: tool axis {:?} is not a unit vector (length {len})",
                        l.tool_axis
                    ),
                ));
            }
            out.push(CutterLocation {
                cl_point: l.cl_point,
                tool_axis: l.tool_axis / len,
            });
        }
        Ok(CutterPath {
            tool_radius_mm,
            locations: out,
            breaks: Vec::new(),
        })
    }

    /// Ball centres and axes of a planned tool path, every move included (rapids too: a
    /// rapid through material is a gouge).
    pub fn from_toolpath(path: &Toolpath) -> Result<Self> {
        Self::try_new(
            path.tool_radius_mm,
            path.moves
                .iter()
                .map(|m| CutterLocation {
                    cl_point: m.cl_point,
                    tool_axis: m.tool_axis,
                })
                .collect(),
        )
    }

    /// Ball centres from tool tips: `centre = tip + r·axis`.
    pub fn from_tool_tips(
        tool_radius_mm: f64,
        tips: impl IntoIterator<Item = ToolTip>,
    ) -> Result<Self> {
        Self::from_tool_poses(tool_radius_mm, tips.into_iter().map(Some))
    }

    /// Ball centres from tool tips, where `None` (a position the reader could not place in
    /// the workpiece frame) breaks the path: no straight move is assumed across it.
    pub fn from_tool_poses(
        tool_radius_mm: f64,
        poses: impl IntoIterator<Item = Option<ToolTip>>,
    ) -> Result<Self> {
        let mut tips: Vec<ToolTip> = Vec::new();
        let mut breaks: Vec<usize> = Vec::new();
        let mut broken = false;
        for p in poses {
            match p {
                Some(t) => {
                    if broken && !tips.is_empty() {
                        breaks.push(tips.len());
                    }
                    broken = false;
                    tips.push(t);
                }
                None => broken = true,
            }
        }
        for t in &tips {
            let len = t.tool_axis.norm();
            if !((len - 1.0).abs() <= AXIS_LENGTH_TOLERANCE) {
                return Err(Error::param(
                    "tool path",
                    format!(
                        "line {}: tool axis {:?} is not a unit vector (length {len})",
                        t.line, t.tool_axis
                    ),
                ));
            }
        }
        let mut path = Self::try_new(
            tool_radius_mm,
            tips.iter()
                .map(|t| {
                    let axis = t.tool_axis / t.tool_axis.norm();
                    CutterLocation {
                        cl_point: t.tip + axis * tool_radius_mm,
                        tool_axis: axis,
                    }
                })
                .collect(),
        )?;
        path.breaks = breaks;
        Ok(path)
    }

    /// The swept volume of every straight move, and a ball at every position that no move
    /// reaches or leaves (a lone position between breaks).
    pub fn capsules(&self) -> Vec<Capsule> {
        let n = self.locations.len();
        let joined = |i: usize| i > 0 && i < n && !self.breaks.contains(&i);
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let p = self.locations[i].cl_point;
            if joined(i + 1) {
                out.push(Capsule::new(p, self.locations[i + 1].cl_point));
            } else if !joined(i) {
                out.push(Capsule::new(p, p));
            }
        }
        out
    }

    /// Reads the JSON CL-data format:
    /// `{"format": "tspath-cl", "tool_radius_mm": R, "cl_points": [[x, y, z], ...],
    /// "tool_axes": [[x, y, z], ...]}` (`tool_axes` optional, default +Z for every point;
    /// `tool_radius_mm` optional, and if given must equal `tool_radius_mm`).
    pub fn from_cl_json(text: &str, tool_radius_mm: f64) -> Result<Self> {
        let err = |loc: &str, msg: String| Error::parse("CL-data JSON", loc.to_string(), msg);
        let v: serde_json::Value = serde_json::from_str(text).map_err(|e| {
            err(
                &format!("line {} column {}", e.line(), e.column()),
                e.to_string(),
            )
        })?;
        if v.get("format").and_then(|f| f.as_str()) != Some("tspath-cl") {
            return Err(err(
                "format",
                "expected \"format\": \"tspath-cl\" (a tool path as ball-centre points)".into(),
            ));
        }
        if let Some(r) = v.get("tool_radius_mm") {
            let r = r
                .as_f64()
                .ok_or_else(|| err("tool_radius_mm", "expected a number of mm".into()))?;
            if r != tool_radius_mm {
                return Err(err(
                    "tool_radius_mm",
                    format!(
                        "the file says {r} mm but the tool radius given is {tool_radius_mm} mm"
                    ),
                ));
            }
        }
        let triple = |x: &serde_json::Value, loc: String| -> Result<[f64; 3]> {
            let a = x
                .as_array()
                .filter(|a| a.len() == 3)
                .ok_or_else(|| err(&loc, "expected an array of three numbers".into()))?;
            let mut out = [0.0; 3];
            for k in 0..3 {
                out[k] = a[k]
                    .as_f64()
                    .ok_or_else(|| err(&loc, format!("element {k} is not a number")))?;
            }
            Ok(out)
        };
        let points = v
            .get("cl_points")
            .and_then(|p| p.as_array())
            .ok_or_else(|| err("cl_points", "expected an array of [x, y, z] (mm)".into()))?;
        let axes = match v.get("tool_axes") {
            None => None,
            Some(a) => {
                let a = a
                    .as_array()
                    .ok_or_else(|| err("tool_axes", "expected an array of [x, y, z]".into()))?;
                if a.len() != points.len() {
                    return Err(err(
                        "tool_axes",
                        format!("has {} entries but cl_points has {}", a.len(), points.len()),
                    ));
                }
                Some(a)
            }
        };
        let mut locations = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            let c = triple(p, format!("cl_points[{i}]"))?;
            let axis = match axes {
                Some(a) => triple(&a[i], format!("tool_axes[{i}]"))?,
                None => [0.0, 0.0, 1.0],
            };
            locations.push(CutterLocation {
                cl_point: Point3::new(c[0], c[1], c[2]),
                tool_axis: Vector3::new(axis[0], axis[1], axis[2]),
            });
        }
        Self::try_new(tool_radius_mm, locations)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn breaks_leave_no_move_across_them() {
        let tip = |x: f64, line| {
            Some(ToolTip {
                tip: Point3::new(x, 0.0, 0.0),
                tool_axis: Vector3::z(),
                line,
            })
        };
        // a–b joined, break, lone c, break, d–e joined.
        let p = CutterPath::from_tool_poses(
            0.5,
            [
                tip(0.0, 1),
                tip(1.0, 2),
                None,
                tip(2.0, 4),
                None,
                None,
                tip(3.0, 7),
                tip(4.0, 8),
            ],
        )
        .unwrap();
        assert_eq!(p.breaks, vec![2, 3]);
        assert_eq!(p.locations[0].cl_point, Point3::new(0.0, 0.0, 0.5));
        let caps: Vec<(f64, f64)> = p
            .capsules()
            .iter()
            .map(|c| (c.start.x, c.end().x))
            .collect();
        assert_eq!(caps, vec![(0.0, 1.0), (2.0, 2.0), (3.0, 4.0)]);
        assert!(CutterPath::from_tool_poses(0.5, [None, None]).is_err());
    }
}
