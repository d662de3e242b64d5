//! Wavefront `.obj` polygon cages read as Catmull–Clark limit surfaces (a T-NURCC with unit
//! knot intervals): boundary edges sharp, corners (boundary vertices with one face)
//! interpolated, as OpenSubdiv does with edge-and-corner boundary interpolation.
//!
//! `v x y z [w]` and `f a b c ...` (also `a/t/n` forms and negative indices) are read;
//! other records (`vt`, `vn`, `g`, `o`, `s`, `usemtl`, ...) are skipped. Subdivision tags are
//! applied as OpenSubdiv reads them, `t name nint/nfloat/nstring args...` with vertices and
//! faces counted from 0:
//! - `t crease n/1/0 a0 b0 a1 b1 ... s` (or one sharpness per edge): the edges `a–b` of each
//!   vertex pair get sharpness `s` (semi-sharp below 10, infinitely sharp from 10);
//! - `t corner n/1/0 v... s`: sharp vertices (interpolated from 10);
//! - `t interpolateboundary 1/0/0 k`: 0 none (the faces at a boundary vertex carry no surface
//!   unless all its boundary edges are tagged infinitely sharp),
//!   1 edges and corners (the default), 2 edges only;
//! - `t hole n/0/0 f...`: faces that carry no surface.
//!
//! Any other tag, or a malformed one, is refused naming its line. A cage with faces that are
//! not quadrilaterals is subdivided once with the same rules (which makes every face a
//! quadrilateral and leaves the limit surface unchanged). Vertices no face uses are dropped.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector4};
use crate::model::setup::LengthUnit;
use crate::surface::sharpness::{self, EdgeEnd, INFINITELY_SHARP};
use crate::tmesh::{
    control_point_problem, BoundaryInterpolation, ControlPoint, FaceLoop, Scheme, SubdivTags, TMesh,
};
use std::collections::{HashMap, HashSet};

const FORMAT: &str = "obj";

/// The subdivision tags OBJ cages from modelling tools carry (as OpenSubdiv reads them).
const KNOWN_TAGS: [&str; 4] = ["crease", "corner", "interpolateboundary", "hole"];

/// The unit a header comment names, as Maya writes it ("# This file uses centimeters as units
/// for non-parametric coordinates."; OpenSubdiv's shapes carry it): looked for in the comment
/// lines before the first record. `None` where no comment says, or names a unit not listed
/// in [`LengthUnit`].
pub fn unit_comment(text: &str) -> Option<LengthUnit> {
    let comments = text
        .lines()
        .map(str::trim)
        .take_while(|l| l.is_empty() || l.starts_with('#'));
    comments
        .filter_map(|l| {
            let words: Vec<&str> = l
                .trim_start_matches('#')
                .split_whitespace()
                .map(|w| w.trim_matches(|c: char| !c.is_alphabetic()))
                .collect();
            let at = words.windows(3).position(|w| {
                w[0].eq_ignore_ascii_case("uses") && w[2].eq_ignore_ascii_case("as")
            })?;
            (words.get(at + 3)?.eq_ignore_ascii_case("units")).then(|| words[at + 1])
        })
        .find_map(|unit| match unit.to_ascii_lowercase().as_str() {
            "millimeters" | "millimetres" | "millimeter" | "millimetre" => Some(LengthUnit::Mm),
            "centimeters" | "centimetres" | "centimeter" | "centimetre" => Some(LengthUnit::Cm),
            "meters" | "metres" | "meter" | "metre" => Some(LengthUnit::M),
            "inches" | "inch" => Some(LengthUnit::Inch),
            _ => None,
        })
}

/// Reads an OBJ cage with its subdivision tags. Coordinates are returned as written (the
/// loader scales them by the unit: [`unit_comment`] or the one set). Returns
/// the mesh and the warnings reading it gave (none at present).
///
/// Errors name the line at fault, with vertices numbered as in the file (from 1): bad
/// records, unknown `t` tags, and the topology a surface cannot have (an edge shared by more
/// than two faces, neighbouring faces oriented inconsistently, faces meeting only at a
/// vertex).
pub fn read(text: &str) -> Result<(TMesh, Vec<String>)> {
    let mut tags = FileTags::default();
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
                if !KNOWN_TAGS.contains(&tag) {
                    return Err(Error::parse(
                        FORMAT,
                        loc(),
                        format!(
                            "`t {tag}` is not a subdivision tag this reader knows ({})",
                            KNOWN_TAGS.join(", ")
                        ),
                    ));
                }
                let args = tag_args(tag, words).map_err(|why| Error::parse(FORMAT, loc(), why))?;
                read_tag(tag, &args, ln + 1, &mut tags)
                    .map_err(|why| Error::parse(FORMAT, loc(), why))?;
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
    check_topology(&faces, &face_line, &vertex_line)?;
    let cage_tags = tags.resolve(&faces, pts.len())?;
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
    let cage_tags = SubdivTags {
        creases: cage_tags
            .creases
            .iter()
            .map(|(&(a, b), &s)| {
                let (a, b) = (map[&a], map[&b]);
                ((a.min(b), a.max(b)), s)
            })
            .collect(),
        corners: cage_tags
            .corners
            .iter()
            .filter_map(|(v, &s)| Some((*map.get(v)?, s)))
            .collect(),
        ..cage_tags
    };
    let (pts, faces, cage_tags) = if faces.iter().all(|f| f.len() == 4) {
        (used, faces, cage_tags)
    } else {
        subdivide_polygons(&used, &faces, &cage_tags)?
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
    let mesh = TMesh::try_new(points, &loops, &HashMap::new(), 1.0, Scheme::CatmullClark)?
        .with_tags(cage_tags)?;
    Ok((mesh, Vec::new()))
}

/// The `t` tags of a file as read, with the line of each, before they are checked against
/// the cage.
#[derive(Default)]
struct FileTags {
    /// `(a, b, sharpness, line)`, vertices counted from 0 as in the file.
    creases: Vec<(u32, u32, f64, usize)>,
    corners: Vec<(u32, f64, usize)>,
    /// `(face, line)`, faces counted from 0 in file order.
    holes: Vec<(u32, usize)>,
    boundary: Option<(BoundaryInterpolation, usize)>,
}

/// Arguments of a `t` tag: `nint/nfloat/nstring` then that many integers, numbers and
/// strings.
struct TagArgs {
    ints: Vec<i64>,
    floats: Vec<f64>,
}

fn tag_args<'a>(
    tag: &str,
    mut words: impl Iterator<Item = &'a str>,
) -> std::result::Result<TagArgs, String> {
    let counts = words.next().unwrap_or("");
    let n: Vec<usize> = counts
        .split('/')
        .map(|c| c.parse::<usize>())
        .collect::<std::result::Result<_, _>>()
        .ok()
        .filter(|n: &Vec<usize>| n.len() == 3)
        .ok_or_else(|| {
            format!("`t {tag}` needs its argument counts as `ints/floats/strings` (e.g. `t crease 2/1/0 4 5 2.0`), found `{counts}`")
        })?;
    let rest: Vec<&str> = words.collect();
    if rest.len() != n[0] + n[1] + n[2] {
        return Err(format!(
            "`t {tag} {counts}` announces {} arguments but {} follow",
            n[0] + n[1] + n[2],
            rest.len()
        ));
    }
    let ints = rest[..n[0]]
        .iter()
        .map(|w| {
            w.parse::<i64>()
                .map_err(|_| format!("`t {tag}`: `{w}` is not an integer"))
        })
        .collect::<std::result::Result<_, _>>()?;
    let floats = rest[n[0]..n[0] + n[1]]
        .iter()
        .map(|w| {
            w.parse::<f64>()
                .ok()
                .filter(|x| !x.is_nan())
                .ok_or_else(|| format!("`t {tag}`: `{w}` is not a number"))
        })
        .collect::<std::result::Result<_, _>>()?;
    Ok(TagArgs { ints, floats })
}

/// Adds one tag's meaning to `tags`; errors say what is wrong with it.
fn read_tag(
    tag: &str,
    a: &TagArgs,
    line: usize,
    tags: &mut FileTags,
) -> std::result::Result<(), String> {
    let index = |i: i64, what: &str| -> std::result::Result<u32, String> {
        u32::try_from(i)
            .map_err(|_| format!("`t {tag}`: {what} {i} is negative (tags count {what}s from 0)"))
    };
    // One sharpness for all, or one per item.
    let sharpness = |k: usize, items: usize| -> std::result::Result<f64, String> {
        let s = match a.floats.len() {
            1 => a.floats[0],
            n if n == items => a.floats[k],
            n => {
                return Err(format!(
                "`t {tag}` has {n} sharpness values for {items} item(s): give one, or one per item"
            ))
            }
        };
        if s < 0.0 {
            return Err(format!("`t {tag}`: sharpness {s} is negative"));
        }
        Ok(s)
    };
    match tag {
        "crease" => {
            // Vertex pairs, one edge each (as OpenSubdiv's shape reader takes them).
            if a.ints.len() < 2 || a.ints.len() % 2 != 0 {
                return Err(format!("`t crease` takes vertex pairs, one per edge, and a sharpness (e.g. `t crease 4/1/0 4 5 5 6 2.0` for edges 4–5 and 5–6); found {} vertices", a.ints.len()));
            }
            let edges = a.ints.len() / 2;
            for (k, pair) in a.ints.chunks(2).enumerate() {
                let (p, q) = (index(pair[0], "vertex")?, index(pair[1], "vertex")?);
                tags.creases.push((p, q, sharpness(k, edges)?, line));
            }
        }
        "corner" => {
            if a.ints.is_empty() {
                return Err("`t corner` needs at least one vertex and a sharpness (e.g. `t corner 1/1/0 7 10.0`)".into());
            }
            for (k, &v) in a.ints.iter().enumerate() {
                tags.corners
                    .push((index(v, "vertex")?, sharpness(k, a.ints.len())?, line));
            }
        }
        "hole" => {
            if a.ints.is_empty() || !a.floats.is_empty() {
                return Err("`t hole` takes face numbers only (e.g. `t hole 2/0/0 3 8`)".into());
            }
            for &f in &a.ints {
                tags.holes.push((index(f, "face")?, line));
            }
        }
        _ => {
            let mode = match (a.ints.as_slice(), a.floats.len()) {
                ([0], 0) => BoundaryInterpolation::None,
                ([1], 0) => BoundaryInterpolation::EdgeAndCorner,
                ([2], 0) => BoundaryInterpolation::EdgeOnly,
                _ => {
                    return Err("`t interpolateboundary` takes one integer: 0 none, 1 edges and corners, 2 edges only (e.g. `t interpolateboundary 1/0/0 1`)".into())
                }
            };
            tags.boundary = Some((mode, line));
        }
    }
    Ok(())
}

impl FileTags {
    /// The tags checked against the cage's faces and `nv` vertices (file numbering), errors
    /// naming the tag's line.
    fn resolve(&self, faces: &[Vec<u32>], nv: usize) -> Result<SubdivTags> {
        let at = |line: usize| format!("line {line}");
        // Faces at each undirected edge (the cage's edges; one face: its boundary).
        let mut edge_count: HashMap<(u32, u32), usize> = HashMap::new();
        for f in faces {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                *edge_count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let vertex = |v: u32, line: usize| -> Result<()> {
            if (v as usize) < nv {
                Ok(())
            } else {
                Err(Error::parse(
                    FORMAT,
                    at(line),
                    format!("vertex {v} is not in the file (tags count vertices from 0; there are {nv})"),
                ))
            }
        };
        let mut out = SubdivTags::default();
        for &(a, b, s, line) in &self.creases {
            vertex(a, line)?;
            vertex(b, line)?;
            let key = (a.min(b), a.max(b));
            if !edge_count.contains_key(&key) {
                return Err(Error::parse(
                    FORMAT,
                    at(line),
                    format!("`t crease`: vertices {a} and {b} (counted from 0) are not joined by an edge of any face"),
                ));
            }
            out.creases.insert(key, sharpness::from_tag(s));
        }
        for &(v, s, line) in &self.corners {
            vertex(v, line)?;
            out.corners.insert(v, sharpness::from_tag(s));
        }
        for &(f, line) in &self.holes {
            if f as usize >= faces.len() {
                return Err(Error::parse(
                    FORMAT,
                    at(line),
                    format!(
                        "`t hole`: face {f} is not in the file (tags count faces from 0; there are {})",
                        faces.len()
                    ),
                ));
            }
            out.holes.insert(f);
        }
        if let Some((mode, _)) = self.boundary {
            out.boundary = mode;
        }
        if out.boundary == BoundaryInterpolation::None {
            // OpenSubdiv's rule, on the cage before any polygon is split: the faces at a
            // boundary vertex carry no surface unless all its boundary edges are tagged
            // infinitely sharp.
            let on_boundary: HashSet<u32> = edge_count
                .iter()
                .filter(|(e, &n)| n == 1 && out.creases.get(e) != Some(&INFINITELY_SHARP))
                .flat_map(|(&(a, b), _)| [a, b])
                .collect();
            for (fi, f) in faces.iter().enumerate() {
                if f.iter().any(|v| on_boundary.contains(v)) {
                    out.holes.insert(fi as u32);
                }
            }
        }
        Ok(out)
    }
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

/// One Catmull–Clark step on a polygon mesh (homogeneous points) with its subdivision tags:
/// boundaries sharp, creases and corners by [`sharpness`]'s rules, corners (boundary vertices
/// with one face) interpolated unless the boundary is interpolated at edges only. Every face
/// becomes quadrilaterals (face `f`'s children are consecutive, one per corner); returns the
/// fine mesh and its tags (creases decayed by one step, holes passed to the children).
pub fn subdivide_polygons(
    pts: &[Vector4],
    faces: &[Vec<u32>],
    tags: &SubdivTags,
) -> Result<(Vec<Vector4>, Vec<Vec<u32>>, SubdivTags)> {
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
    let sharpness_of = |e: &(u32, u32)| {
        if edge_faces[e].len() == 1 {
            INFINITELY_SHARP
        } else {
            tags.creases.get(e).copied().unwrap_or(0.0)
        }
    };
    let corner_rule = tags.boundary == BoundaryInterpolation::EdgeAndCorner;
    let vertex_sharpness = |v: u32| {
        let boundary = vertex_edges[v as usize]
            .iter()
            .any(|e| edge_faces[e].len() == 1);
        if corner_rule && boundary && vertex_faces[v as usize].len() == 1 {
            INFINITELY_SHARP
        } else {
            tags.corners.get(&v).copied().unwrap_or(0.0)
        }
    };
    let mut out = Vec::with_capacity(nv + edges.len() + faces.len());
    for v in 0..nv as u32 {
        let p = pts[v as usize];
        let incident = &vertex_edges[v as usize];
        let open = incident
            .iter()
            .filter(|e| edge_faces[*e].len() == 1)
            .count();
        if open != 0 && open != 2 {
            return Err(Error::InvalidMesh(format!(
                "vertex {v} touches the boundary {} times (non-manifold)",
                open / 2
            )));
        }
        let ends: Vec<EdgeEnd> = incident
            .iter()
            .map(|e| EdgeEnd {
                point: pts[(if e.0 == v { e.1 } else { e.0 }) as usize],
                sharpness: sharpness_of(e),
            })
            .collect();
        let smooth = || {
            let nf = vertex_faces[v as usize].len();
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
        };
        out.push(sharpness::vertex_point(
            p,
            vertex_sharpness(v),
            &ends,
            smooth,
        ));
    }
    for e in &edges {
        let fs = &edge_faces[e];
        let faces = (fs.len() == 2).then(|| (face_pts[fs[0] as usize], face_pts[fs[1] as usize]));
        out.push(sharpness::edge_point(
            pts[e.0 as usize],
            pts[e.1 as usize],
            faces,
            sharpness_of(e),
        ));
    }
    out.extend(face_pts.iter().copied());
    let ev = |a: u32, b: u32| nv as u32 + edge_index[&(a.min(b), a.max(b))];
    let mut quads = Vec::new();
    let mut holes = std::collections::BTreeSet::new();
    for (fi, f) in faces.iter().enumerate() {
        let c = (nv + edges.len() + fi) as u32;
        let n = f.len();
        for k in 0..n {
            if tags.holes.contains(&(fi as u32)) {
                holes.insert(quads.len() as u32);
            }
            let (prev, v, next) = (f[(k + n - 1) % n], f[k], f[(k + 1) % n]);
            quads.push(vec![v, ev(v, next), c, ev(prev, v)]);
        }
    }
    let creases = sharpness::child_creases(&tags.creases, |a, b| Some(ev(a, b))).collect();
    let corners = sharpness::child_corners(&tags.corners).collect();
    let fine = SubdivTags {
        creases,
        corners,
        holes,
        boundary: tags.boundary,
    };
    Ok((out, quads, fine))
}
