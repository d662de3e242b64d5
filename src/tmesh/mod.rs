//! The T-mesh: a half-edge mesh of rectangular faces with knot intervals on edges and rational
//! control points at vertices.
//!
//! Owns: topology (half-edges, twins, faces, sides and T-junctions), knot intervals,
//! validation, and the local knot vectors found by walking the mesh ([`walk`]).
//! Must not: evaluate the surface (that is `surface`), or know about file formats (`io`).
//!
//! Conventions. Each face is a loop of half-edges running counter-clockwise in the face's own
//! parameter frame `(s, t)`; four of its vertices are corners and split the loop into sides
//! 0..3 running `+s, +t, −s, −t`. Any other vertex on a side is a T-junction of that face.
//! Opposite sides have equal sums of knot intervals, giving the face a parametric width
//! (side 0) and height (side 1). A face of zero width or height is a *degenerate* face: it
//! carries repeated knots (e.g. Bézier end conditions) but no piece of surface.
//!
//! A degenerate face may have one empty side (side 1 or 2: two corners at the same loop
//! position, a zero-length side with no edge). Such a face is a zero-area triangle with a
//! *cusp*, where its two long sides leave one vertex in the same direction: this is how a
//! stack of repeated knot lines ends, fanning into one vertex (e.g. the repeated knots of a
//! concave boundary corner with Bézier end conditions). It occupies no angle at the cusp.
//!
//! The long sides of such a triangle that leave the stack's other lines are *fan lines*: a
//! repeated knot line that belongs to the grip block at one end only. It carries that
//! block's grips to the far vertex (a ray along it meets the far vertex), but a ray crossing
//! it between its ends meets no knot there: the repeated knot exists only at the block.

pub mod refine;
pub mod walk;

use crate::error::{Error, Result};
use crate::geom::{Aabb, Point3, Vector4};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// How faces near extraordinary points and at boundaries are evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Scheme {
    /// T-spline: blending functions from local knot vectors (knot repeated at a boundary).
    #[default]
    TSpline,
    /// Catmull–Clark limit surface (unit knot intervals; boundary edges sharp, corners
    /// interpolated unless [`SubdivTags::boundary`] says otherwise), as for OBJ cages.
    CatmullClark,
}

/// How a Catmull–Clark cage's boundary is interpolated (OpenSubdiv's vertex boundary
/// interpolation; OBJ `t interpolateboundary`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryInterpolation {
    /// No surface over the faces at boundary vertices (except where all of a vertex's
    /// boundary edges are tagged infinitely sharp).
    None,
    /// Boundary edges sharp; a boundary vertex with one face follows the crease rule (the
    /// corner is rounded).
    EdgeOnly,
    /// Boundary edges sharp and corners (boundary vertices with one face) interpolated.
    #[default]
    EdgeAndCorner,
}

/// Subdivision tags of a Catmull–Clark cage: where the modeller made the surface sharp or
/// left it open. Sharpness as [`crate::surface::sharpness`] reads it (0 smooth, infinite
/// never decays).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SubdivTags {
    /// Sharpness of creased edges, by undirected vertex pair `(min, max)`.
    pub creases: BTreeMap<(u32, u32), f64>,
    /// Sharpness of tagged corner vertices.
    pub corners: BTreeMap<u32, f64>,
    /// Faces that carry no surface (they still shape their neighbours).
    pub holes: BTreeSet<u32>,
    pub boundary: BoundaryInterpolation,
}

impl SubdivTags {
    /// True if nothing is tagged and the boundary is interpolated as by default.
    pub fn is_plain(&self) -> bool {
        *self == SubdivTags::default()
    }

    /// The tags in words, for a person ("4 sharp crease edges, 2 semi-sharp, 1 corner, 1 hole
    /// face, boundary edges only"); empty when plain.
    pub fn describe(&self) -> String {
        let plural =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        let sharp = self.creases.values().filter(|s| s.is_infinite()).count();
        let semi = self.creases.len() - sharp;
        let mut parts = Vec::new();
        if sharp > 0 {
            parts.push(plural(sharp, "sharp crease edge", "sharp crease edges"));
        }
        if semi > 0 {
            parts.push(plural(
                semi,
                "semi-sharp crease edge",
                "semi-sharp crease edges",
            ));
        }
        if !self.corners.is_empty() {
            parts.push(plural(self.corners.len(), "sharp corner", "sharp corners"));
        }
        if !self.holes.is_empty() {
            parts.push(plural(self.holes.len(), "hole face", "hole faces"));
        }
        match self.boundary {
            BoundaryInterpolation::EdgeAndCorner => {}
            BoundaryInterpolation::EdgeOnly => parts.push("boundary sharp at edges only".into()),
            BoundaryInterpolation::None => parts.push("boundary not interpolated".into()),
        }
        parts.join(", ")
    }

    /// True if some crease or corner is infinitely sharp: the limit surface has a crease (a
    /// C0 line) or a cone point there.
    pub fn has_sharp_features(&self) -> bool {
        self.creases
            .values()
            .chain(self.corners.values())
            .any(|s| s.is_infinite())
    }
}

/// A rational control point: Cartesian position (mm) and weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlPoint {
    pub point: Point3,
    pub weight: f64,
}

impl ControlPoint {
    /// Homogeneous form `(w x, w y, w z, w)`.
    pub fn homogeneous(&self) -> Vector4 {
        let w = self.weight;
        Vector4::new(w * self.point.x, w * self.point.y, w * self.point.z, w)
    }
}

/// One face as given by a reader: its vertex loop (counter-clockwise) and which loop
/// positions are its four corners, starting with the corner where side 0 begins. Corners 1
/// and 2, or 2 and 3, may share a loop position on a zero-area face (an empty side).
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLoop {
    pub vertices: Vec<u32>,
    pub corners: [u32; 4],
}

impl FaceLoop {
    /// A plain quadrilateral `a b c d` (side 0 from `a` to `b`).
    pub fn quad(a: u32, b: u32, c: u32, d: u32) -> Self {
        FaceLoop {
            vertices: vec![a, b, c, d],
            corners: [0, 1, 2, 3],
        }
    }
}

/// Half-edge record. `origin` is where it starts; it ends at `origin` of `next`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfEdge {
    pub origin: u32,
    pub next: u32,
    pub prev: u32,
    pub twin: Option<u32>,
    pub face: u32,
    /// Side of the face (0..3: +s, +t, −s, −t) this half-edge lies on.
    pub side: u8,
    /// Knot interval of the edge (parameter units, ≥ 0).
    pub knot: f64,
    /// Distance along its side from the side's first corner to `origin`.
    pub offset: f64,
}

/// Face record: the half-edge that starts side 0, and the face's parametric size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Face {
    pub first: u32,
    pub width: f64,
    pub height: f64,
}

impl Face {
    /// True when the face spans a positive parameter area and so carries surface.
    pub fn is_domain(&self) -> bool {
        self.width > 0.0 && self.height > 0.0
    }
}

/// A validated T-mesh. Built once by [`TMesh::try_new`], then only read.
#[derive(Debug, Clone)]
pub struct TMesh {
    points: Vec<ControlPoint>,
    half_edges: Vec<HalfEdge>,
    faces: Vec<Face>,
    /// One outgoing half-edge per vertex; for a boundary vertex the most clockwise one.
    vertex_edge: Vec<u32>,
    /// Per half-edge: part of a fan line (see the module notes), crossed by rays unseen.
    fan_line: Vec<bool>,
    scheme: Scheme,
    tags: SubdivTags,
}

/// Relative tolerance (of the larger side) for comparing sums of knot intervals.
pub(crate) const KNOT_MATCH_REL: f64 = 1e-9;

/// Largest control-point coordinate accepted, in mm (1000 km: no machine is bigger). Keeps
/// the products and sums of rational evaluation far from `f64` overflow.
pub const MAX_COORDINATE_MM: f64 = 1e9;

/// Accepted control-point weights `[min, max]`. Only ratios of weights shape the surface;
/// weights this far apart already mean a degenerate model, and farther apart rational
/// evaluation over- or underflows.
pub const WEIGHT_RANGE: [f64; 2] = [1e-6, 1e6];

/// Accepted positive knot intervals `[min, max]` (parameter units; 0 is also accepted and
/// means a repeated knot). Beyond them basis evaluation divides by near-zero spans or sums
/// overflow.
pub const KNOT_RANGE: [f64; 2] = [1e-9, 1e9];

/// Why a knot interval is not accepted (`None` if it is: 0, or within [`KNOT_RANGE`]).
pub fn knot_problem(knot: f64) -> Option<String> {
    if knot == 0.0 || (KNOT_RANGE[0]..=KNOT_RANGE[1]).contains(&knot) {
        None
    } else {
        Some(format!(
            "knot interval {knot} is not 0 or between {:e} and {:e}",
            KNOT_RANGE[0], KNOT_RANGE[1]
        ))
    }
}

/// Why a control point is not accepted (`None` if it is): coordinates within
/// ±[`MAX_COORDINATE_MM`], weight within [`WEIGHT_RANGE`].
pub fn control_point_problem(p: &ControlPoint) -> Option<String> {
    if let Some(c) = [p.point.x, p.point.y, p.point.z]
        .into_iter()
        .find(|c| !(c.abs() <= MAX_COORDINATE_MM))
    {
        return Some(format!(
            "coordinate {c} mm is not a number within ±{MAX_COORDINATE_MM:e} mm"
        ));
    }
    if !(WEIGHT_RANGE[0]..=WEIGHT_RANGE[1]).contains(&p.weight) {
        let why = if p.weight > 0.0 {
            ""
        } else {
            " (weights must be positive)"
        };
        return Some(format!(
            "weight {} is not between {:e} and {:e}{why}",
            p.weight, WEIGHT_RANGE[0], WEIGHT_RANGE[1]
        ));
    }
    None
}

impl TMesh {
    /// Builds and validates a T-mesh.
    ///
    /// `knots` gives the knot interval of undirected edges `(a, b)`; edges not listed get
    /// `default_knot`. Errors name the face, edge or vertex at fault.
    pub fn try_new(
        points: Vec<ControlPoint>,
        faces: &[FaceLoop],
        knots: &HashMap<(u32, u32), f64>,
        default_knot: f64,
        scheme: Scheme,
    ) -> Result<Self> {
        Self::try_new_with_fan_lines(points, faces, knots, default_knot, scheme, &[])
    }

    /// As [`TMesh::try_new`], with the edges `(a, b)` (either order) that are fan lines: lines
    /// of a grip block that end in a fan at the far vertex (see the module notes). Each must
    /// be an edge of the mesh with a face on both sides.
    pub fn try_new_with_fan_lines(
        points: Vec<ControlPoint>,
        faces: &[FaceLoop],
        knots: &HashMap<(u32, u32), f64>,
        default_knot: f64,
        scheme: Scheme,
        fan_lines: &[(u32, u32)],
    ) -> Result<Self> {
        let nv = points.len();
        for (i, p) in points.iter().enumerate() {
            if let Some(why) = control_point_problem(p) {
                return Err(Error::InvalidMesh(format!("control point {i}: {why}")));
            }
        }
        if faces.is_empty() {
            return Err(Error::InvalidMesh("the mesh has no faces".into()));
        }
        if let Some(why) = knot_problem(default_knot) {
            return Err(Error::InvalidMesh(format!("default {why}")));
        }
        let mut half_edges: Vec<HalfEdge> = Vec::new();
        let mut out_faces = Vec::with_capacity(faces.len());
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        let mut used = vec![false; nv];
        for (fi, fl) in faces.iter().enumerate() {
            let n = fl.vertices.len();
            if n < 3 {
                return Err(Error::InvalidMesh(format!(
                    "face {fi} has {n} vertices; at least 3 needed (4 corners, two of which may share a position on a zero-area face)"
                )));
            }
            let c = fl.corners;
            if c.iter().any(|&k| k as usize >= n) {
                return Err(Error::InvalidMesh(format!(
                    "face {fi}: a corner index is beyond its {n} vertices"
                )));
            }
            // Corners must appear in loop order starting at corners[0]; at most one of sides
            // 1 and 2 may be empty (two corners at one position).
            let rel: Vec<usize> = c
                .iter()
                .map(|&k| (k as usize + n - c[0] as usize) % n)
                .collect();
            let empty_sides = usize::from(rel[1] == rel[2]) + usize::from(rel[2] == rel[3]);
            if !(rel[0] < rel[1] && rel[1] <= rel[2] && rel[2] <= rel[3] && empty_sides <= 1) {
                return Err(Error::InvalidMesh(format!(
                    "face {fi}: corners {:?} are not loop positions in order (only side 1 or side 2 may be empty)",
                    fl.corners
                )));
            }
            let base = half_edges.len() as u32;
            let start = fl.corners[0] as usize;
            let mut side = 0u8;
            let mut offset = 0.0;
            let mut sums = [0.0f64; 4];
            for k in 0..n {
                let li = (start + k) % n;
                if k > 0 {
                    let corners_here = c.iter().filter(|&&p| p as usize == li).count();
                    if corners_here > 0 {
                        side += corners_here as u8;
                        offset = 0.0;
                    }
                }
                let a = fl.vertices[li];
                let b = fl.vertices[(li + 1) % n];
                if a as usize >= nv || b as usize >= nv {
                    return Err(Error::InvalidMesh(format!(
                        "face {fi} refers to vertex {} but there are only {nv}",
                        a.max(b)
                    )));
                }
                if a == b {
                    return Err(Error::InvalidMesh(format!(
                        "face {fi} repeats vertex {a} consecutively"
                    )));
                }
                used[a as usize] = true;
                let key = (a.min(b), a.max(b));
                let knot = knots.get(&key).copied().unwrap_or(default_knot);
                if let Some(why) = knot_problem(knot) {
                    return Err(Error::InvalidMesh(format!("edge {a}-{b}: {why}")));
                }
                let id = base + k as u32;
                if let Some(other) = directed.insert((a, b), id) {
                    return Err(Error::InvalidMesh(format!(
                        "edge {a}->{b} is used in the same direction by faces {} and {fi}: an edge borders at most two faces, which run along it in opposite directions (check the faces' orientation)",
                        half_edges[other as usize].face
                    )));
                }
                half_edges.push(HalfEdge {
                    origin: a,
                    next: base + ((k + 1) % n) as u32,
                    prev: base + ((k + n - 1) % n) as u32,
                    twin: None,
                    face: fi as u32,
                    side,
                    knot,
                    offset,
                });
                offset += knot;
                sums[side as usize] += knot;
            }
            let tol = KNOT_MATCH_REL * sums.iter().cloned().fold(0.0, f64::max).max(1.0);
            if (sums[0] - sums[2]).abs() > tol || (sums[1] - sums[3]).abs() > tol {
                return Err(Error::InvalidMesh(format!(
                    "face {fi}: opposite sides disagree in knot length (sides: {:.6} {:.6} {:.6} {:.6})",
                    sums[0], sums[1], sums[2], sums[3]
                )));
            }
            out_faces.push(Face {
                first: base,
                width: sums[0],
                height: sums[1],
            });
        }
        for (&(a, b), &h) in &directed {
            if let Some(&t) = directed.get(&(b, a)) {
                half_edges[h as usize].twin = Some(t);
            }
        }
        let mut fan_line = vec![false; half_edges.len()];
        for &(a, b) in fan_lines {
            match (directed.get(&(a, b)), directed.get(&(b, a))) {
                (Some(&h), Some(&t)) => {
                    fan_line[h as usize] = true;
                    fan_line[t as usize] = true;
                }
                _ => {
                    return Err(Error::InvalidMesh(format!(
                        "fan line {a}-{b} is not an edge with a face on both sides"
                    )))
                }
            }
        }
        if let Some(v) = used.iter().position(|u| !u) {
            return Err(Error::InvalidMesh(format!(
                "vertex {v} is not used by any face"
            )));
        }
        // One outgoing half-edge per vertex, then rotated clockwise to the boundary if any.
        let mut vertex_edge = vec![u32::MAX; nv];
        let mut out_count = vec![0usize; nv];
        for (i, h) in half_edges.iter().enumerate() {
            out_count[h.origin as usize] += 1;
            if vertex_edge[h.origin as usize] == u32::MAX {
                vertex_edge[h.origin as usize] = i as u32;
            }
        }
        let mut mesh = TMesh {
            points,
            half_edges,
            faces: out_faces,
            vertex_edge,
            fan_line,
            scheme,
            tags: SubdivTags::default(),
        };
        for v in 0..nv {
            let start = mesh.vertex_edge[v];
            let mut h = start;
            for _ in 0..out_count[v] {
                match mesh.he(h).twin {
                    Some(t) if mesh.he(t).next != start => h = mesh.he(t).next,
                    _ => break,
                }
            }
            mesh.vertex_edge[v] = h;
            if mesh.outgoing(v as u32).len() != out_count[v] {
                return Err(Error::InvalidMesh(format!(
                    "vertex {v} joins faces that do not share edges around it (non-manifold vertex)"
                )));
            }
        }
        Ok(mesh)
    }

    /// Scheme used to evaluate the mesh.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The same Catmull–Clark cage with its subdivision tags. Sharpness values are taken as
    /// [`crate::surface::sharpness::from_tag`] reads them (10 and above infinite). With
    /// [`BoundaryInterpolation::None`] the faces at a boundary vertex become holes unless
    /// all the vertex's boundary edges are tagged infinitely sharp (as in OpenSubdiv). Errors
    /// name the tag at fault: a crease that is not an edge, a vertex or face out of range, a
    /// negative or non-finite sharpness, tags on a T-spline, or nothing left to carry
    /// surface.
    pub fn with_tags(mut self, mut tags: SubdivTags) -> Result<TMesh> {
        use crate::surface::sharpness::from_tag;
        if tags.is_plain() {
            self.tags = tags;
            return Ok(self);
        }
        if self.scheme != Scheme::CatmullClark {
            return Err(Error::InvalidMesh(
                "subdivision tags (creases, corners, holes) apply to Catmull–Clark cages only"
                    .into(),
            ));
        }
        let nv = self.vertex_count() as u32;
        let sharpness_problem = |s: f64| !(s.is_finite() || s == f64::INFINITY) || s < 0.0;
        let mut edges: BTreeSet<(u32, u32)> = BTreeSet::new();
        for h in &self.half_edges {
            let b = self.half_edges[h.next as usize].origin;
            edges.insert((h.origin.min(b), h.origin.max(b)));
        }
        for (&(a, b), s) in tags.creases.iter_mut() {
            if !edges.contains(&(a, b)) {
                return Err(Error::InvalidMesh(format!(
                    "crease {a}–{b}: vertices {a} and {b} are not joined by an edge of the cage"
                )));
            }
            if sharpness_problem(*s) {
                return Err(Error::InvalidMesh(format!(
                    "crease {a}–{b}: sharpness {s} is not a number ≥ 0"
                )));
            }
            *s = from_tag(*s);
        }
        tags.creases.retain(|_, s| *s > 0.0);
        for (&v, s) in tags.corners.iter_mut() {
            if v >= nv {
                return Err(Error::InvalidMesh(format!(
                    "corner {v}: the cage has vertices 0 to {}",
                    nv - 1
                )));
            }
            if sharpness_problem(*s) {
                return Err(Error::InvalidMesh(format!(
                    "corner {v}: sharpness {s} is not a number ≥ 0"
                )));
            }
            *s = from_tag(*s);
        }
        tags.corners.retain(|_, s| *s > 0.0);
        let nf = self.faces.len() as u32;
        if let Some(&f) = tags.holes.iter().find(|&&f| f >= nf) {
            return Err(Error::InvalidMesh(format!(
                "hole {f}: the cage has faces 0 to {}",
                nf - 1
            )));
        }
        if tags.boundary == BoundaryInterpolation::None {
            // OpenSubdiv's rule: the faces at a boundary vertex carry no surface unless all
            // its boundary edges are tagged infinitely sharp.
            for v in 0..nv {
                let out = self.outgoing(v);
                let Some(&last) = out.last() else { continue };
                let first = self.he(out[0]);
                let incoming = self.he(self.he(last).prev);
                let open = |a: u32, b: u32| {
                    tags.creases.get(&(a.min(b), a.max(b))) != Some(&f64::INFINITY)
                };
                let exposed = (first.twin.is_none() && open(v, self.he(first.next).origin))
                    || (incoming.twin.is_none() && open(incoming.origin, v));
                if exposed {
                    for h in out {
                        tags.holes.insert(self.he(h).face);
                    }
                }
            }
        }
        if tags.holes.len() == self.faces.len() {
            return Err(Error::InvalidMesh(
                "every face is a hole (tagged, or touching the boundary with `interpolateboundary` none): no surface is left".into(),
            ));
        }
        self.tags = tags;
        Ok(self)
    }

    /// The subdivision tags (plain for T-splines).
    pub fn tags(&self) -> &SubdivTags {
        &self.tags
    }

    /// Sharpness of the edge `a`–`b` from the tags (0 when smooth or not an edge; boundary
    /// edges are not included).
    pub fn edge_sharpness(&self, a: u32, b: u32) -> f64 {
        self.tags
            .creases
            .get(&(a.min(b), a.max(b)))
            .copied()
            .unwrap_or(0.0)
    }

    /// True if face `f` carries a piece of the surface: it spans a parameter area and is not
    /// a hole.
    pub fn carries_surface(&self, f: u32) -> bool {
        self.faces[f as usize].is_domain() && !self.tags.holes.contains(&f)
    }

    /// Control points, indexed by vertex.
    pub fn points(&self) -> &[ControlPoint] {
        &self.points
    }

    /// The same mesh with every control point mapped by `f` (a placement: scale, rotation,
    /// shift); errors where a mapped point is out of range, naming the vertex.
    pub fn map_points(&self, f: impl Fn(&ControlPoint) -> ControlPoint) -> Result<TMesh> {
        let mut out = self.clone();
        for (v, p) in out.points.iter_mut().enumerate() {
            *p = f(p);
            if let Some(problem) = control_point_problem(p) {
                return Err(Error::InvalidMesh(format!(
                    "vertex {v} after placing the model: {problem}"
                )));
            }
        }
        Ok(out)
    }

    /// All faces, indexed by face id.
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// All half-edges.
    pub fn half_edges(&self) -> &[HalfEdge] {
        &self.half_edges
    }

    /// One half-edge.
    #[inline]
    pub fn he(&self, h: u32) -> &HalfEdge {
        &self.half_edges[h as usize]
    }

    /// True if half-edge `h` is part of a fan line: a ray crossing it meets no knot there.
    pub fn is_fan_line(&self, h: u32) -> bool {
        self.fan_line[h as usize]
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.points.len()
    }

    /// Outgoing half-edges of vertex `v` in counter-clockwise order, starting at the most
    /// clockwise one for a boundary vertex.
    pub fn outgoing(&self, v: u32) -> Vec<u32> {
        let start = self.vertex_edge[v as usize];
        let mut out = vec![start];
        let mut h = start;
        loop {
            let p = self.he(h).prev;
            match self.he(p).twin {
                Some(t) if t != start => {
                    out.push(t);
                    h = t;
                }
                _ => break,
            }
            if out.len() > self.half_edges.len() {
                break;
            }
        }
        out
    }

    /// True if `v` lies on the boundary of the mesh (on an edge with one face).
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        let start = self.vertex_edge[v as usize];
        self.he(start).twin.is_none() || {
            let last = *self.outgoing(v).last().unwrap();
            self.he(self.he(last).prev).twin.is_none()
        }
    }

    /// Angle (in quarter turns) the face of half-edge `h` occupies at `h`'s origin: 1 at a
    /// corner of the face, 2 where the origin is a T-junction on one of its sides, 0 at the
    /// cusp of a face with an empty side.
    #[inline]
    pub fn sector_quarters(&self, h: u32) -> u32 {
        let e = self.he(h);
        match (e.side + 4 - self.he(e.prev).side) % 4 {
            0 => 2,
            1 => 1,
            _ => 0,
        }
    }

    /// Total angle around vertex `v` in quarter turns (4 at a regular interior vertex).
    pub fn angle_quarters(&self, v: u32) -> u32 {
        self.outgoing(v)
            .iter()
            .map(|&h| self.sector_quarters(h))
            .sum()
    }

    /// Number of edges at `v`.
    pub fn valence(&self, v: u32) -> usize {
        let n = self.outgoing(v).len();
        if self.is_boundary_vertex(v) {
            n + 1
        } else {
            n
        }
    }

    /// True if `v` is an extraordinary point. T-spline scheme: an interior vertex whose faces
    /// do not add up to a full turn, or a boundary vertex whose faces exceed three quarter
    /// turns. Catmull–Clark: an interior vertex with other than 4 faces, or a boundary vertex
    /// with more than 2.
    pub fn is_extraordinary(&self, v: u32) -> bool {
        let boundary = self.is_boundary_vertex(v);
        match self.scheme {
            Scheme::TSpline => {
                let a = self.angle_quarters(v);
                if boundary {
                    a > 3
                } else {
                    a != 4
                }
            }
            Scheme::CatmullClark => {
                let faces = self.outgoing(v).len();
                if boundary {
                    faces > 2
                } else {
                    faces != 4
                }
            }
        }
    }

    /// Vertices that are T-junctions of some face (lie inside one of its sides).
    pub fn t_junctions(&self) -> Vec<u32> {
        let mut v: Vec<u32> = (0..self.half_edges.len() as u32)
            .filter(|&h| self.sector_quarters(h) == 2)
            .map(|h| self.he(h).origin)
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Half-edges of face `f`, in loop order starting at side 0.
    pub fn face_half_edges(&self, f: u32) -> Vec<u32> {
        let first = self.faces[f as usize].first;
        let mut out = vec![first];
        let mut h = self.he(first).next;
        while h != first {
            out.push(h);
            h = self.he(h).next;
        }
        out
    }

    /// Bounding box of the control points (mm).
    pub fn control_bbox(&self) -> Aabb {
        let mut b = Aabb::empty();
        for p in &self.points {
            b.grow(&p.point);
        }
        b
    }

    /// Number of boundary loops (outer boundary and holes).
    pub fn boundary_loops(&self) -> usize {
        let mut seen = vec![false; self.half_edges.len()];
        let mut loops = 0;
        for h in 0..self.half_edges.len() as u32 {
            if self.he(h).twin.is_some() || seen[h as usize] {
                continue;
            }
            loops += 1;
            // Follow boundary half-edges: the next boundary edge starts where h ends.
            let mut e = h;
            loop {
                seen[e as usize] = true;
                // Rotate around the end vertex to the next boundary half-edge.
                let mut n = self.he(e).next;
                let mut guard = 0;
                while let Some(t) = self.he(n).twin {
                    n = self.he(t).next;
                    guard += 1;
                    if guard > self.half_edges.len() {
                        break;
                    }
                }
                if n == h || seen[n as usize] {
                    break;
                }
                e = n;
            }
        }
        loops
    }

    /// The face loops and knot intervals, for writing the mesh back out.
    pub fn face_loops(&self) -> Vec<FaceLoop> {
        (0..self.faces.len() as u32)
            .map(|f| {
                let hs = self.face_half_edges(f);
                let vertices: Vec<u32> = hs.iter().map(|&h| self.he(h).origin).collect();
                let mut corners = [0u32; 4];
                let mut k = 1;
                for (i, &h) in hs.iter().enumerate().skip(1) {
                    // A side step of two is an empty side: two corners at one position.
                    let step = (self.he(h).side + 4 - self.he(self.he(h).prev).side) % 4;
                    for _ in 0..step {
                        if k < 4 {
                            corners[k] = i as u32;
                        }
                        k += 1;
                    }
                }
                FaceLoop { vertices, corners }
            })
            .collect()
    }
}

impl TMesh {
    /// The T-mesh of a tensor-product grid of `nu × nv` control points (index `j * nu + i`,
    /// `i` along `s`), with knot intervals `du` (`nu − 1` of them) between columns and `dv`
    /// between rows. A clamped NURBS surface with knot vectors `t` has intervals
    /// `t[i+3] − t[i+2]`: zero at both ends.
    pub fn from_grid(
        points: Vec<ControlPoint>,
        nu: usize,
        nv: usize,
        du: &[f64],
        dv: &[f64],
        scheme: Scheme,
    ) -> Result<Self> {
        if nu < 2 || nv < 2 || points.len() != nu * nv || du.len() + 1 != nu || dv.len() + 1 != nv {
            return Err(Error::InvalidMesh(format!(
                "grid of {nu} x {nv} needs {} points, {} u-intervals and {} v-intervals (got {}, {}, {})",
                nu * nv,
                nu.saturating_sub(1),
                nv.saturating_sub(1),
                points.len(),
                du.len(),
                dv.len()
            )));
        }
        let id = |i: usize, j: usize| (j * nu + i) as u32;
        let mut faces = Vec::new();
        let mut knots = HashMap::new();
        for j in 0..nv - 1 {
            for i in 0..nu - 1 {
                faces.push(FaceLoop::quad(
                    id(i, j),
                    id(i + 1, j),
                    id(i + 1, j + 1),
                    id(i, j + 1),
                ));
            }
        }
        for j in 0..nv {
            for i in 0..nu - 1 {
                knots.insert((id(i, j), id(i + 1, j)), du[i]);
            }
        }
        for j in 0..nv - 1 {
            for i in 0..nu {
                knots.insert((id(i, j), id(i, j + 1)), dv[j]);
            }
        }
        TMesh::try_new(points, &faces, &knots, 1.0, scheme)
    }
}
