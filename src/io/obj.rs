//! Wavefront `.obj` polygon cages read as Catmull–Clark limit surfaces (a T-NURCC with unit
//! knot intervals): boundary edges sharp, corners (boundary vertices with one face)
//! interpolated, as OpenSubdiv does with edge-and-corner boundary interpolation.
//!
//! `v x y z [w]` and `f a b c ...` (also `a/t/n` forms and negative indices) are read;
//! other records (`vt`, `vn`, `g`, `o`, `s`, `usemtl`, ...) are skipped. Subdivision tags
//! (`t crease`, `t corner`, `t interpolateboundary`, `t hole`) are not applied yet: each is
//! returned as a warning naming its line, so that a surface made smooth where the modeller
//! marked it sharp is said, not hidden; any other `t` tag is refused. A cage with faces that
//! are not quadrilaterals is subdivided once (which makes every face a quadrilateral and
//! leaves the limit surface unchanged). Vertices no face uses are dropped.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector4};
use crate::tmesh::{control_point_problem, ControlPoint, FaceLoop, Scheme, TMesh};
use std::collections::{HashMap, HashSet};

const FORMAT: &str = "obj";

/// The subdivision tags OBJ cages from modelling tools carry.
const KNOWN_TAGS: [&str; 4] = ["crease", "corner", "interpolateboundary", "hole"];

/// Reads an OBJ cage. Coordinates are taken as millimetres. Returns the mesh and a warning
/// per kind of subdivision tag the file has that is not applied (with its count and first
/// line).
///
/// Errors name the line at fault, with vertices numbered as in the file (from 1): bad
/// records, unknown `t` tags, and the topology a surface cannot have (an edge shared by more
/// than two faces, neighbouring faces oriented inconsistently, faces meeting only at a
/// vertex).
pub fn read(text: &str) -> Result<(TMesh, Vec<String>)> {
    // Tag name -> (count, first line).
    let mut tags: Vec<(&str, usize, usize)> = Vec::new();
    let mut pts: Vec<Vector4> = Vec::new();
    // Line (1-based) of each vertex and face record.
    let mut vertex_line: Vec<usize> = Vec::new();
    let mut face_line: Vec<usize> = Vec::new();
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
                let cp = ControlPoint {
                    point: Point3::new(nums[0], nums[1], nums[2]),
                    weight: nums.get(3).copied().unwrap_or(1.0),
                };
                if let Some(why) = control_point_problem(&cp) {
                    return Err(Error::parse(FORMAT, loc(), why));
                }
                pts.push(cp.homogeneous());
                vertex_line.push(ln + 1);
            }
            Some("f") => {
                let mut face = Vec::new();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| {
                        Error::parse(FORMAT, loc(), format!("`{w}` is not a vertex index"))
                    })?;
                    let n = pts.len() as i64;
                    if i == 0 {
                        return Err(Error::parse(
                            FORMAT,
                            loc(),
                            "vertex index 0: OBJ vertex indices start at 1 (negative ones count back from the last vertex)",
                        ));
                    }
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if idx < 0 || idx >= n {
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
                face_line.push(ln + 1);
            }
            Some("t") => {
                let tag = words.next().unwrap_or("");
                let Some(known) = KNOWN_TAGS.iter().find(|k| **k == tag) else {
                    return Err(Error::parse(
                        FORMAT,
                        loc(),
                        format!(
                            "`t {tag}` is not a subdivision tag this reader knows ({})",
                            KNOWN_TAGS.join(", ")
                        ),
                    ));
                };
                match tags.iter_mut().find(|t| t.0 == *known) {
                    Some(t) => t.1 += 1,
                    None => tags.push((known, 1, ln + 1)),
                }
            }
            _ => {}
        }
    }
    let warnings = tags
        .iter()
        .map(|(tag, n, line)| {
            format!(
                "the file's {n} `t {tag}` tag(s) (first at line {line}) are not applied: the surface is read as plain Catmull–Clark (smooth where the modeller marked {}); check it before cutting",
                match *tag {
                    "crease" => "creases",
                    "corner" => "sharp corners",
                    "hole" => "holes, which are surfaced",
                    _ => "how the boundary is interpolated",
                }
            )
        })
        .collect();
    if faces.is_empty() {
        return Err(Error::parse(
            FORMAT,
            "end of file",
            "no faces (`f` records) found",
        ));
    }
    check_topology(&faces, &face_line, &vertex_line)?;
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
    let mesh = TMesh::try_new(points, &loops, &HashMap::new(), 1.0, Scheme::CatmullClark)?;
    Ok((mesh, warnings))
}

/// "lines 3 and 7", "lines 3, 7 and 9".
fn lines_list(lines: &[usize]) -> String {
    let mut s: Vec<String> = lines.iter().map(usize::to_string).collect();
    let last = s.pop().unwrap_or_default();
    if s.is_empty() {
        format!("line {last}")
    } else {
        format!("lines {} and {last}", s.join(", "))
    }
}

fn find_root(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Checks that the faces (0-based vertex indices) form a manifold surface that can be
/// oriented as given, naming the file's lines and 1-based vertex numbers at fault.
fn check_topology(faces: &[Vec<u32>], face_line: &[usize], vertex_line: &[usize]) -> Result<()> {
    // A face is a simple loop.
    for (f, face) in faces.iter().enumerate() {
        let mut seen = HashSet::new();
        if let Some(&v) = face.iter().find(|&&v| !seen.insert(v)) {
            return Err(Error::InvalidMesh(format!(
                "line {}: the face uses vertex {} twice; a face must be a simple loop of distinct vertices",
                face_line[f],
                v + 1
            )));
        }
    }
    // Faces of each undirected edge, with the direction each runs along it, in file order.
    let mut edge_faces: HashMap<(u32, u32), Vec<(usize, bool)>> = HashMap::new();
    let mut edge_order: Vec<(u32, u32)> = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let e = edge_faces.entry((a.min(b), a.max(b))).or_default();
            if e.is_empty() {
                edge_order.push((a.min(b), a.max(b)));
            }
            e.push((f, a < b));
        }
    }
    for key in &edge_order {
        let fs = &edge_faces[key];
        if fs.len() > 2 {
            let lines: Vec<usize> = fs.iter().map(|&(f, _)| face_line[f]).collect();
            return Err(Error::InvalidMesh(format!(
                "edge {}–{} is shared by the faces on {}: an edge of a surface borders at most two faces (non-manifold edge)",
                key.0 + 1,
                key.1 + 1,
                lines_list(&lines)
            )));
        }
    }
    for key in &edge_order {
        if let [(f, d), (g, e)] = edge_faces[key][..] {
            if d == e {
                let (a, b) = if d { *key } else { (key.1, key.0) };
                return Err(Error::InvalidMesh(format!(
                    "the faces on {} both run from vertex {} to vertex {}: neighbouring faces must be oriented consistently, running along a shared edge in opposite directions (reverse the vertex order of one of them)",
                    lines_list(&[face_line[f], face_line[g]]),
                    a + 1,
                    b + 1
                )));
            }
        }
    }
    // Around each vertex its faces must form one fan: faces at the vertex joined through
    // the edges at the vertex they share. Corners are (face, position) pairs.
    let mut first_corner = Vec::with_capacity(faces.len());
    let mut total = 0;
    for face in faces {
        first_corner.push(total);
        total += face.len();
    }
    let corner_of = |f: usize, v: u32| -> usize {
        first_corner[f] + faces[f].iter().position(|&w| w == v).unwrap_or(0)
    };
    let mut parent: Vec<usize> = (0..total).collect();
    for key in &edge_order {
        if let [(f, _), (g, _)] = edge_faces[key][..] {
            for v in [key.0, key.1] {
                let (a, b) = (
                    find_root(&mut parent, corner_of(f, v)),
                    find_root(&mut parent, corner_of(g, v)),
                );
                parent[a] = b;
            }
        }
    }
    // For each vertex, the first face of its first fan and the first face of another fan.
    let mut fan: HashMap<u32, (usize, usize)> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for &v in face {
            let root = find_root(&mut parent, corner_of(f, v));
            match fan.get(&v) {
                None => {
                    fan.insert(v, (root, f));
                }
                Some(&(r, g)) if r != root => {
                    return Err(Error::InvalidMesh(format!(
                        "vertex {} (line {}) joins faces that share no edge there, such as the faces on {}: a non-manifold (bow-tie) vertex; give each fan of faces its own vertex",
                        v + 1,
                        vertex_line[v as usize],
                        lines_list(&[face_line[g], face_line[f]])
                    )));
                }
                Some(_) => {}
            }
        }
    }
    Ok(())
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
