//! The project's own JSON T-mesh format (`"format": "tspath-tmesh"`, version 1).
//!
//! ```json
//! {
//!   "format": "tspath-tmesh", "version": 1,
//!   "name": "dome", "units": "mm", "scheme": "t-spline",
//!   "default_knot": 1.0,
//!   "points": [[x, y, z, w], [x, y, z], ...],
//!   "faces": [[a, b, c, d], {"vertices": [a, b, c, d, e], "corners": [0, 1, 3, 4]}, ...],
//!   "knots": [[a, b, interval], ...],
//!   "creases": [[a, b, sharpness], ...], "corners": [[v, sharpness], ...],
//!   "holes": [face, ...], "boundary": "edge-and-corner"
//! }
//! ```
//! Points are control points (weight 1 when omitted). A face is a counter-clockwise vertex
//! loop; a plain list is a quadrilateral, an object names which loop positions are the four
//! corners (the others are T-junctions), the first corner starting side 0. `knots` gives the
//! knot interval of edges between two vertices; unlisted edges get `default_knot`.
//! The last four (Catmull–Clark subdivision tags, optional) are as OBJ `t` tags give them:
//! sharpness 10 or more is infinitely sharp; `boundary` is `none`, `edge-only` or
//! `edge-and-corner` (the default).
//! `units` is one of `mm`, `cm`, `m`, `inch`; coordinates are scaled to millimetres on
//! reading. The writer always writes millimetres, so reading what it wrote gives back the
//! same numbers, bit for bit.

use crate::error::{Error, Result};
use crate::geom::Point3;
use crate::surface::sharpness::SHARPNESS_INFINITE_FROM;
use crate::tmesh::{
    control_point_problem, knot_problem, ControlPoint, FaceLoop, Scheme, SubdivTags, TMesh,
};
use serde_json::{json, Value};
use std::collections::{HashMap, HashSet};

const FORMAT: &str = "json";

/// What a JSON model file holds besides the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct JsonMeta {
    pub name: String,
    /// Unit name as written in the file.
    pub units: String,
}

/// Millimetres per unit for the unit names the format accepts.
pub fn unit_scale(name: &str) -> Option<f64> {
    match name {
        "mm" | "millimeters" | "millimetres" => Some(1.0),
        "cm" | "centimeters" | "centimetres" => Some(10.0),
        "m" | "meters" | "metres" => Some(1000.0),
        "in" | "inch" | "inches" => Some(25.4),
        _ => None,
    }
}

fn num(v: &Value, loc: &str) -> Result<f64> {
    v.as_f64()
        .ok_or_else(|| Error::parse(FORMAT, loc, format!("expected a number, found {v}")))
}

fn index(v: &Value, loc: &str) -> Result<u32> {
    v.as_u64()
        .filter(|&i| i <= u32::MAX as u64)
        .map(|i| i as u32)
        .ok_or_else(|| Error::parse(FORMAT, loc, format!("expected a vertex index, found {v}")))
}

/// Reads a JSON T-mesh.
pub fn read(text: &str) -> Result<(TMesh, JsonMeta)> {
    let root: Value = serde_json::from_str(text).map_err(|e| {
        Error::parse(
            FORMAT,
            format!("line {} column {}", e.line(), e.column()),
            e.to_string(),
        )
    })?;
    let obj = root
        .as_object()
        .ok_or_else(|| Error::parse(FORMAT, "top level", "expected an object"))?;
    match obj.get("format").and_then(Value::as_str) {
        Some("tspath-tmesh") => {}
        other => {
            return Err(Error::parse(
                FORMAT,
                "\"format\"",
                format!("expected \"tspath-tmesh\", found {other:?}"),
            ))
        }
    }
    match obj.get("version").and_then(Value::as_u64) {
        Some(1) => {}
        other => {
            return Err(Error::parse(
                FORMAT,
                "\"version\"",
                format!("this reader knows version 1, found {other:?}"),
            ))
        }
    }
    let name = obj
        .get("name")
        .and_then(Value::as_str)
        .unwrap_or("model")
        .to_string();
    let units = obj
        .get("units")
        .and_then(Value::as_str)
        .unwrap_or("mm")
        .to_string();
    let scale = unit_scale(&units).ok_or_else(|| {
        Error::parse(
            FORMAT,
            "\"units\"",
            format!("unknown unit {units:?}; use mm, cm, m or inch"),
        )
    })?;
    let scheme = match obj.get("scheme") {
        None => Scheme::TSpline,
        Some(v) => serde_json::from_value(v.clone()).map_err(|_| {
            Error::parse(
                FORMAT,
                "\"scheme\"",
                format!("expected \"t-spline\" or \"catmull-clark\", found {v}"),
            )
        })?,
    };
    let default_knot = match obj.get("default_knot") {
        None => 1.0,
        Some(v) => {
            let k = num(v, "\"default_knot\"")?;
            if let Some(why) = knot_problem(k) {
                return Err(Error::parse(FORMAT, "\"default_knot\"", why));
            }
            k
        }
    };
    let pts = obj
        .get("points")
        .and_then(Value::as_array)
        .ok_or_else(|| Error::parse(FORMAT, "\"points\"", "missing or not an array"))?;
    let mut points = Vec::with_capacity(pts.len());
    for (i, p) in pts.iter().enumerate() {
        let loc = format!("points[{i}]");
        let a = p.as_array().ok_or_else(|| {
            Error::parse(
                FORMAT,
                &loc,
                format!("expected [x, y, z] or [x, y, z, w], found {p}"),
            )
        })?;
        if a.len() != 3 && a.len() != 4 {
            return Err(Error::parse(
                FORMAT,
                &loc,
                format!(
                    "expected [x, y, z] or [x, y, z, w], found {} numbers",
                    a.len()
                ),
            ));
        }
        let c: Vec<f64> = a.iter().map(|x| num(x, &loc)).collect::<Result<_>>()?;
        let point = ControlPoint {
            point: Point3::new(c[0] * scale, c[1] * scale, c[2] * scale),
            weight: c.get(3).copied().unwrap_or(1.0),
        };
        if let Some(why) = control_point_problem(&point) {
            return Err(Error::parse(FORMAT, &loc, why));
        }
        points.push(point);
    }
    let np = points.len();
    let fcs = obj
        .get("faces")
        .and_then(Value::as_array)
        .ok_or_else(|| Error::parse(FORMAT, "\"faces\"", "missing or not an array"))?;
    let mut faces = Vec::with_capacity(fcs.len());
    // Undirected edges of the faces, for checking the knot records.
    let mut edges = HashSet::new();
    for (i, f) in fcs.iter().enumerate() {
        let loc = format!("faces[{i}]");
        let (verts, corners) = match f {
            Value::Array(a) => (a, None),
            Value::Object(o) => (
                o.get("vertices").and_then(Value::as_array).ok_or_else(|| {
                    Error::parse(FORMAT, &loc, "object face needs a \"vertices\" list")
                })?,
                Some(o.get("corners").and_then(Value::as_array).ok_or_else(|| {
                    Error::parse(FORMAT, &loc, "object face needs a \"corners\" list")
                })?),
            ),
            _ => {
                return Err(Error::parse(
                    FORMAT,
                    &loc,
                    format!("expected a vertex list or an object, found {f}"),
                ))
            }
        };
        let vertices: Vec<u32> = verts
            .iter()
            .map(|x| index(x, &loc))
            .collect::<Result<_>>()?;
        if let Some(&v) = vertices.iter().find(|&&v| v as usize >= np) {
            return Err(Error::parse(
                FORMAT,
                &loc,
                format!(
                    "vertex {v} does not exist: there are {np} points (indices 0 to {})",
                    np as i64 - 1
                ),
            ));
        }
        let n = vertices.len();
        let corners = match corners {
            None if n == 4 => [0, 1, 2, 3],
            None => {
                return Err(Error::parse(
                    FORMAT,
                    &loc,
                    format!(
                        "a plain vertex list is a quadrilateral and needs 4 vertices, found {n} \
                         vertices (a face with T-junctions is an object with \"vertices\" and \
                         \"corners\")"
                    ),
                ))
            }
            Some(c) => {
                if n < 3 {
                    return Err(Error::parse(
                        FORMAT,
                        &loc,
                        format!("a face needs at least 3 vertices, found {n} vertices"),
                    ));
                }
                if c.len() != 4 {
                    return Err(Error::parse(
                        FORMAT,
                        &loc,
                        format!(
                            "expected four \"corners\" (loop positions of the face's corners), found {}",
                            c.len()
                        ),
                    ));
                }
                let c: Vec<u32> = c
                    .iter()
                    .map(|x| {
                        x.as_u64()
                            .filter(|&k| (k as usize) < n)
                            .map(|k| k as u32)
                            .ok_or_else(|| {
                                Error::parse(
                                    FORMAT,
                                    &loc,
                                    format!(
                                        "corner {x} is not a loop position of its {n} vertices (0 to {})",
                                        n - 1
                                    ),
                                )
                            })
                    })
                    .collect::<Result<_>>()?;
                [c[0], c[1], c[2], c[3]]
            }
        };
        for k in 0..n {
            let (a, b) = (vertices[k], vertices[(k + 1) % n]);
            edges.insert((a.min(b), a.max(b)));
        }
        faces.push(FaceLoop { vertices, corners });
    }
    // Interval of each edge and the record that gave it.
    let mut knots: HashMap<(u32, u32), f64> = HashMap::new();
    let mut knot_record: HashMap<(u32, u32), usize> = HashMap::new();
    if let Some(k) = obj.get("knots") {
        let arr = k.as_array().ok_or_else(|| {
            Error::parse(FORMAT, "\"knots\"", "expected an array of [a, b, interval]")
        })?;
        for (i, e) in arr.iter().enumerate() {
            let loc = format!("knots[{i}]");
            let a = e.as_array().filter(|a| a.len() == 3).ok_or_else(|| {
                Error::parse(
                    FORMAT,
                    &loc,
                    format!("expected [a, b, interval], found {e}"),
                )
            })?;
            let (x, y) = (index(&a[0], &loc)?, index(&a[1], &loc)?);
            let key = (x.min(y), x.max(y));
            if !edges.contains(&key) {
                return Err(Error::parse(
                    FORMAT,
                    &loc,
                    format!("no face has an edge between vertices {x} and {y}"),
                ));
            }
            let interval = num(&a[2], &loc)?;
            if let Some(why) = knot_problem(interval) {
                return Err(Error::parse(FORMAT, &loc, why));
            }
            if let Some(&j) = knot_record.get(&key) {
                if knots[&key] != interval {
                    return Err(Error::parse(
                        FORMAT,
                        &loc,
                        format!(
                            "edge {x}-{y} already has interval {} from knots[{j}]",
                            knots[&key]
                        ),
                    ));
                }
            }
            knots.insert(key, interval);
            knot_record.entry(key).or_insert(i);
        }
    }
    let tags = read_tags(obj)?;
    let mesh = TMesh::try_new(points, &faces, &knots, default_knot, scheme)?.with_tags(tags)?;
    Ok((mesh, JsonMeta { name, units }))
}

/// Writes a T-mesh as JSON (millimetres), one record per line. Deterministic: same mesh,
/// same bytes; numbers are written in the shortest form that reads back to the same `f64`.
pub fn write(mesh: &TMesh, name: &str) -> String {
    let num = |x: f64| serde_json::to_string(&x).expect("finite numbers serialise");
    let mut out = String::new();
    out.push_str("{\n  \"format\": \"tspath-tmesh\",\n  \"version\": 1,\n");
    out.push_str(&format!(
        "  \"name\": {},\n",
        serde_json::to_string(name).expect("strings serialise")
    ));
    out.push_str("  \"units\": \"mm\",\n");
    out.push_str(&format!(
        "  \"scheme\": {},\n",
        serde_json::to_string(&mesh.scheme()).expect("scheme serialises")
    ));
    out.push_str("  \"default_knot\": 1.0,\n  \"points\": [\n");
    let pts: Vec<String> = mesh
        .points()
        .iter()
        .map(|p| {
            format!(
                "    [{}, {}, {}, {}]",
                num(p.point.x),
                num(p.point.y),
                num(p.point.z),
                num(p.weight)
            )
        })
        .collect();
    out.push_str(&pts.join(",\n"));
    out.push_str("\n  ],\n  \"faces\": [\n");
    let faces: Vec<String> = mesh
        .face_loops()
        .into_iter()
        .map(|f| {
            let vs = json!(f.vertices).to_string();
            if f.vertices.len() == 4 && f.corners == [0, 1, 2, 3] {
                format!("    {vs}")
            } else {
                format!(
                    "    {{\"vertices\": {vs}, \"corners\": {}}}",
                    json!(f.corners)
                )
            }
        })
        .collect();
    out.push_str(&faces.join(",\n"));
    out.push_str("\n  ],\n  \"knots\": [\n");
    let mut knots: Vec<(u32, u32, f64)> = mesh
        .half_edges()
        .iter()
        .map(|h| {
            let (a, b) = (h.origin, mesh.he(h.next).origin);
            (a.min(b), a.max(b), h.knot)
        })
        .collect();
    crate::sort::sort_by_key(&mut knots, |x| (x.0, x.1));
    knots.dedup_by(|x, y| x.0 == y.0 && x.1 == y.1);
    let knots: Vec<String> = knots
        .into_iter()
        .map(|(a, b, k)| format!("    [{a}, {b}, {}]", num(k)))
        .collect();
    out.push_str(&knots.join(",\n"));
    out.push_str("\n  ]");
    let tags = mesh.tags();
    if !tags.is_plain() {
        // Infinite sharpness is written as the tag value that means it.
        let sharp = |s: f64| num(s.min(SHARPNESS_INFINITE_FROM));
        let creases: Vec<String> = tags
            .creases
            .iter()
            .map(|(&(a, b), &s)| format!("[{a}, {b}, {}]", sharp(s)))
            .collect();
        let corners: Vec<String> = tags
            .corners
            .iter()
            .map(|(&v, &s)| format!("[{v}, {}]", sharp(s)))
            .collect();
        out.push_str(&format!(
            ",\n  \"creases\": [{}],\n  \"corners\": [{}],\n  \"holes\": {},\n  \"boundary\": {}",
            creases.join(", "),
            corners.join(", "),
            json!(tags.holes),
            serde_json::to_string(&tags.boundary).expect("enum serialises")
        ));
    }
    out.push_str("\n}\n");
    out
}

/// The optional subdivision tags: `"creases": [[a, b, sharpness], ...]`, `"corners": [[v,
/// sharpness], ...]`, `"holes": [face, ...]`, `"boundary": "none" | "edge-only" |
/// "edge-and-corner"`.
fn read_tags(obj: &serde_json::Map<String, Value>) -> Result<SubdivTags> {
    let mut tags = SubdivTags::default();
    let list = |key: &str| -> Result<Vec<Value>> {
        match obj.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => Ok(a.clone()),
            Some(_) => Err(Error::parse(FORMAT, format!("\"{key}\""), "not an array")),
        }
    };
    let entry = |key: &str, i: usize, v: &Value, n: usize| -> Result<Vec<f64>> {
        let loc = format!("{key}[{i}]");
        let a = v
            .as_array()
            .filter(|a| a.len() == n)
            .ok_or_else(|| Error::parse(FORMAT, &loc, format!("expected {n} numbers")))?;
        a.iter().map(|x| num(x, &loc)).collect()
    };
    let index = |x: f64, loc: String| -> Result<u32> {
        if x >= 0.0 && x.fract() == 0.0 && x <= u32::MAX as f64 {
            Ok(x as u32)
        } else {
            Err(Error::parse(FORMAT, loc, format!("{x} is not an index")))
        }
    };
    for (i, v) in list("creases")?.iter().enumerate() {
        let e = entry("creases", i, v, 3)?;
        let (a, b) = (
            index(e[0], format!("creases[{i}]"))?,
            index(e[1], format!("creases[{i}]"))?,
        );
        tags.creases.insert((a.min(b), a.max(b)), e[2]);
    }
    for (i, v) in list("corners")?.iter().enumerate() {
        let e = entry("corners", i, v, 2)?;
        tags.corners
            .insert(index(e[0], format!("corners[{i}]"))?, e[1]);
    }
    for (i, v) in list("holes")?.iter().enumerate() {
        let loc = format!("holes[{i}]");
        tags.holes.insert(index(num(v, &loc)?, loc)?);
    }
    if let Some(v) = obj.get("boundary") {
        tags.boundary = serde_json::from_value(v.clone()).map_err(|_| {
            Error::parse(
                FORMAT,
                "\"boundary\"",
                format!("expected \"none\", \"edge-only\" or \"edge-and-corner\", found {v}"),
            )
        })?;
    }
    Ok(tags)
}
