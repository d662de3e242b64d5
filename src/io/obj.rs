//! Wavefront `.obj` polygon cages read as Catmull–Clark limit surfaces (a T-NURCC with unit
//! knot intervals): boundary edges sharp, corners (boundary vertices with one face)
//! interpolated, as OpenSubdiv does with edge-and-corner boundary interpolation.
//!
//! `v x y z [w]` and `f a b c ...` (also `a/t/n` forms and negative indices) are read;
//! other records (`vt`, `vn`, `g`, `o`, `s`, `usemtl`, ...) are skipped. A cage with faces that
//! are not quadrilaterals is subdivided once (which makes every face a quadrilateral and
//! leaves the limit surface unchanged). Vertices no face uses are dropped.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector4};
use crate::tmesh::{ControlPoint, FaceLoop, Scheme, TMesh};
use std::collections::HashMap;

const FORMAT: &str = "obj";

/// Reads an OBJ cage. Coordinates are taken as millimetres.
pub fn read(text: &str) -> Result<TMesh> {
    let mut pts: Vec<Vector4> = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (ln, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let loc = || format!("line {}", ln + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let nums: Vec<f64> = words
                    .map(|w| {
                        w.parse::<f64>()
                            .ok()
                            .filter(|x| x.is_finite())
                            .ok_or_else(|| {
                                Error::parse(FORMAT, loc(), format!("`{w}` is not a finite number"))
                            })
                    })
                    .collect::<Result<_>>()?;
                if nums.len() < 3 || nums.len() > 4 {
                    return Err(Error::parse(
                        FORMAT,
                        loc(),
                        format!("a vertex needs x y z [w], found {} numbers", nums.len()),
                    ));
                }
                let w = nums.get(3).copied().unwrap_or(1.0);
                if !(w > 0.0) {
                    return Err(Error::parse(
                        FORMAT,
                        loc(),
                        format!("vertex weight {w} must be positive"),
                    ));
                }
                pts.push(Vector4::new(nums[0] * w, nums[1] * w, nums[2] * w, w));
            }
            Some("f") => {
                let mut face = Vec::new();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| {
                        Error::parse(FORMAT, loc(), format!("`{w}` is not a vertex index"))
                    })?;
                    let n = pts.len() as i64;
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || idx < 0 || idx >= n {
                        return Err(Error::parse(
                            FORMAT,
                            loc(),
                            format!("vertex index {i} does not refer to one of the {n} vertices defined so far"),
                        ));
                    }
                    face.push(idx as u32);
                }
                if face.len() < 3 {
                    return Err(Error::parse(
                        FORMAT,
                        loc(),
                        format!("a face needs at least 3 vertices, found {}", face.len()),
                    ));
                }
                faces.push(face);
            }
            _ => {}
        }
    }
    if faces.is_empty() {
        return Err(Error::parse(
            FORMAT,
            "end of file",
            "no faces (`f` records) found",
        ));
    }
    // Drop unused vertices.
    let mut map: HashMap<u32, u32> = HashMap::new();
    let mut used = Vec::new();
    for f in faces.iter_mut() {
        for v in f.iter_mut() {
            *v = *map.entry(*v).or_insert_with(|| {
                used.push(pts[*v as usize]);
                (used.len() - 1) as u32
            });
        }
    }
    let (pts, faces) = if faces.iter().all(|f| f.len() == 4) {
        (used, faces)
    } else {
        subdivide_polygons(&used, &faces)?
    };
    let points = pts
        .iter()
        .map(|h| ControlPoint {
            point: Point3::new(h.x / h.w, h.y / h.w, h.z / h.w),
            weight: h.w,
        })
        .collect();
    let loops: Vec<FaceLoop> = faces
        .iter()
        .map(|f| FaceLoop::quad(f[0], f[1], f[2], f[3]))
        .collect();
    TMesh::try_new(points, &loops, &HashMap::new(), 1.0, Scheme::CatmullClark)
}

/// One Catmull–Clark step on a polygon mesh (homogeneous points), with sharp boundaries and
/// interpolated corners. Every face becomes quadrilaterals.
pub fn subdivide_polygons(
    pts: &[Vector4],
    faces: &[Vec<u32>],
) -> Result<(Vec<Vector4>, Vec<Vec<u32>>)> {
    let nv = pts.len();
    let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut vertex_faces = vec![Vec::new(); nv];
    for (fi, f) in faces.iter().enumerate() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            let key = (a.min(b), a.max(b));
            let e = edge_faces.entry(key).or_default();
            if e.is_empty() {
                edges.push(key);
            }
            e.push(fi as u32);
            if e.len() > 2 {
                return Err(Error::InvalidMesh(format!(
                    "edge {a}-{b} is shared by more than two faces"
                )));
            }
            vertex_faces[a as usize].push(fi as u32);
        }
    }
    let face_pts: Vec<Vector4> = faces
        .iter()
        .map(|f| f.iter().map(|&v| pts[v as usize]).sum::<Vector4>() / f.len() as f64)
        .collect();
    let edge_index: HashMap<(u32, u32), u32> = edges
        .iter()
        .enumerate()
        .map(|(i, &e)| (e, i as u32))
        .collect();
    let mut vertex_edges = vec![Vec::new(); nv];
    for &(a, b) in &edges {
        vertex_edges[a as usize].push((a, b));
        vertex_edges[b as usize].push((a, b));
    }
    let mut out = Vec::with_capacity(nv + edges.len() + faces.len());
    for v in 0..nv as u32 {
        let p = pts[v as usize];
        let incident = &vertex_edges[v as usize];
        let boundary: Vec<u32> = incident
            .iter()
            .filter(|e| edge_faces[e].len() == 1)
            .map(|&(a, b)| if a == v { b } else { a })
            .collect();
        let nf = vertex_faces[v as usize].len();
        let new = if boundary.len() == 2 {
            if nf == 1 {
                p
            } else {
                (pts[boundary[0] as usize] + pts[boundary[1] as usize] + p * 6.0) / 8.0
            }
        } else if boundary.is_empty() {
            let n = incident.len() as f64;
            let q = vertex_faces[v as usize]
                .iter()
                .map(|&f| face_pts[f as usize])
                .sum::<Vector4>()
                / nf as f64;
            let r = incident
                .iter()
                .map(|&(a, b)| (pts[a as usize] + pts[b as usize]) * 0.5)
                .sum::<Vector4>()
                / n;
            (q + r * 2.0 + p * (n - 3.0)) / n
        } else {
            return Err(Error::InvalidMesh(format!(
                "vertex {v} touches the boundary {} times (non-manifold)",
                boundary.len() / 2
            )));
        };
        out.push(new);
    }
    for &(a, b) in &edges {
        let fs = &edge_faces[&(a, b)];
        let mid = (pts[a as usize] + pts[b as usize]) * 0.5;
        out.push(if fs.len() == 2 {
            (mid * 2.0 + face_pts[fs[0] as usize] + face_pts[fs[1] as usize]) * 0.25
        } else {
            mid
        });
    }
    out.extend(face_pts.iter().copied());
    let ev = |a: u32, b: u32| nv as u32 + edge_index[&(a.min(b), a.max(b))];
    let mut quads = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        let c = (nv + edges.len() + fi) as u32;
        let n = f.len();
        for k in 0..n {
            let (prev, v, next) = (f[(k + n - 1) % n], f[k], f[(k + 1) % n]);
            quads.push(vec![v, ev(v, next), c, ev(prev, v)]);
        }
    }
    Ok((out, quads))
}
