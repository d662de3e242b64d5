//! Catmull–Clark limit surfaces by local subdivision: a face's one-ring is cut out of the
//! mesh, subdivided, and every child that has become regular is turned into a bicubic Bézier
//! cell; children touching an extraordinary point are subdivided again, down to a fixed depth
//! below which the limit point stands for the whole (sub-nanometre) region.
//!
//! Rules (homogeneous coordinates, so rational cages subdivide as NURCCs): face points are
//! face averages; smooth edge points `(a + b + f0 + f1)/4`; smooth vertex points
//! `(Q + 2R + (n − 3)v)/n`. Boundary edges, creases and corners follow [`super::sharpness`]:
//! sharp edge points are midpoints, crease vertices `(a + 6v + b)/8`, corners stay, and
//! semi-sharp creases decay by one per step. A regular face (each corner smooth of valence
//! 4, on an infinitely sharp crease or boundary with two faces on this side, or a corner with
//! this face alone between its sharp edges; nothing semi-sharp) is a uniform bicubic B-spline
//! patch of its 16 one-ring points, with points mirrored across infinitely sharp sides
//! (`2·p_side − p_inner`).
//!
//! Owns: the local quad mesh, one subdivision step, regular-patch detection, the per-face
//! quadtree of Bézier cells. Must not: know about T-junctions or knot intervals other than
//! uniform ones (callers reject those near extraordinary points).

use super::bezier::{BezierPatch, SurfaceDerivs};
use super::sharpness::{self, EdgeEnd, VertexRule, INFINITELY_SHARP};
use crate::geom::{Point3, Vector3, Vector4};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hasher for the small integer keys of local meshes (FxHash's rotate-multiply): the maps
/// are rebuilt at every level, keys are not chosen by an adversary, and SipHash cost a fifth
/// of building a car-body cage's evaluator.
#[derive(Debug, Default, Clone, Copy)]
pub struct LocalHasher(u64);

impl LocalHasher {
    fn add(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for LocalHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.add(u64::from(b));
        }
    }
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A hash map keyed by local vertex numbers.
pub type LocalMap<K, V> = HashMap<K, V, BuildHasherDefault<LocalHasher>>;

/// Depth of subdivision after which the region next to an extraordinary point (2^-depth of
/// the face's side, about 1e-12) is represented by its limit point.
pub const MAX_DEPTH: usize = 40;

/// A small quad mesh cut out around one face: homogeneous points, counter-clockwise quads,
/// and for each boundary edge of the cut whether it is a true (sharp) boundary of the model
/// or only where the cut ended.
#[derive(Debug, Clone)]
pub struct LocalMesh {
    /// Homogeneous points, relative to `origin`.
    pub pts: Vec<Vector4>,
    /// Where the coordinates are measured from (mm). Subdivision near an extraordinary
    /// point re-centres on its limit point at every level, so that coordinates shrink with
    /// the region and keep their relative precision down to the deepest cells.
    pub origin: Vector3,
    pub quads: Vec<[u32; 4]>,
    /// Sharpness of the sharp undirected edges `(min, max)`: the model's boundary edges
    /// ([`INFINITELY_SHARP`]) and its creases. An open edge not listed is where the cut
    /// ended.
    pub creases: LocalMap<(u32, u32), f64>,
    /// Sharpness of the sharp vertices (tagged or interpolated corners).
    pub corners: LocalMap<u32, f64>,
}

/// The quadtree of a face evaluated by subdivision.
// Leaves are stored inline: evaluation reads them without another indirection.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum Node {
    /// A regular region: one Bézier cell over the node's square, with coordinates measured
    /// from `origin` (mm).
    Leaf { patch: BezierPatch, origin: Vector3 },
    /// Four children: `[u low v low, u high v low, u low v high, u high v high]`.
    Split(Box<[Node; 4]>),
    /// The tiny region at an extraordinary point: its limit point (homogeneous).
    Cap(Vector4),
}

/// Where a point of a [`Node`] lies: in a leaf's Bézier cell (at `uv` there, the cell `scale`
/// times smaller than the node), or on a cap.
pub(crate) enum Found<'a> {
    Leaf {
        patch: &'a BezierPatch,
        origin: &'a Vector3,
        uv: [f64; 2],
        scale: f64,
    },
    Cap(Point3),
}

impl Node {
    /// The corners of the node's square `[0,1]²` where it holds a cap (an extraordinary
    /// point's limit), in the order the tree holds them.
    pub fn cap_corners(&self) -> Vec<[f64; 2]> {
        fn walk(node: &Node, origin: [f64; 2], size: f64, out: &mut Vec<[f64; 2]>) {
            match node {
                Node::Leaf { .. } => {}
                // A cap is the tiny square at a corner of the face: the corner nearest it.
                Node::Cap(_) => {
                    out.push([origin[0] + 0.5 * size, origin[1] + 0.5 * size].map(|x| x.round()))
                }
                Node::Split(ch) => {
                    let h = 0.5 * size;
                    for (k, c) in ch.iter().enumerate() {
                        let o = [
                            origin[0] + h * (k % 2) as f64,
                            origin[1] + h * (k / 2) as f64,
                        ];
                        walk(c, o, h, out);
                    }
                }
            }
        }
        let mut out = Vec::new();
        walk(self, [0.0, 0.0], 1.0, &mut out);
        out
    }

    /// The leaf or cap holding `(u, v)` (in the node's square `[0,1]²`).
    pub(crate) fn descend(&self, mut u: f64, mut v: f64) -> Found<'_> {
        let mut node = self;
        let mut scale = 1.0;
        loop {
            match node {
                Node::Leaf { patch, origin } => {
                    return Found::Leaf {
                        patch,
                        origin,
                        uv: [u, v],
                        scale,
                    }
                }
                Node::Cap(h) => return Found::Cap(Point3::new(h.x / h.w, h.y / h.w, h.z / h.w)),
                Node::Split(ch) => {
                    let (hu, hv) = (u >= 0.5, v >= 0.5);
                    u = if hu { 2.0 * u - 1.0 } else { 2.0 * u };
                    v = if hv { 2.0 * v - 1.0 } else { 2.0 * v };
                    scale *= 2.0;
                    node = &ch[(hu as usize) + 2 * (hv as usize)];
                }
            }
        }
    }

    /// Point and derivatives at `(u, v)` in the node's square `[0,1]²`.
    pub fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        match self.descend(u, v) {
            Found::Leaf {
                patch,
                origin,
                uv,
                scale,
            } => {
                let mut d = patch.derivs(uv[0], uv[1]).scaled(scale, scale);
                d.point += origin;
                d
            }
            Found::Cap(point) => SurfaceDerivs {
                point,
                su: Vector3::zeros(),
                sv: Vector3::zeros(),
                suu: Vector3::zeros(),
                suv: Vector3::zeros(),
                svv: Vector3::zeros(),
            },
        }
    }

    /// Point and first derivatives at `(u, v)` in the node's square `[0,1]²`: those of
    /// [`Node::derivs`] without the second derivatives.
    pub fn first_derivs(&self, u: f64, v: f64) -> (Point3, Vector3, Vector3) {
        match self.descend(u, v) {
            Found::Leaf {
                patch,
                origin,
                uv,
                scale,
            } => {
                let (p, su, sv) = patch.first_derivs(uv[0], uv[1]);
                (p + origin, su * scale, sv * scale)
            }
            Found::Cap(point) => (point, Vector3::zeros(), Vector3::zeros()),
        }
    }

    /// Point only.
    pub fn subs(&self, mut u: f64, mut v: f64) -> Point3 {
        let mut node = self;
        loop {
            match node {
                Node::Leaf { patch, origin } => return patch.subs(u, v) + origin,
                Node::Cap(h) => return Point3::new(h.x / h.w, h.y / h.w, h.z / h.w),
                Node::Split(ch) => {
                    let (hu, hv) = (u >= 0.5, v >= 0.5);
                    u = if hu { 2.0 * u - 1.0 } else { 2.0 * u };
                    v = if hv { 2.0 * v - 1.0 } else { 2.0 * v };
                    node = &ch[(hu as usize) + 2 * (hv as usize)];
                }
            }
        }
    }

    /// Number of Bézier cells.
    pub fn leaf_count(&self) -> usize {
        match self {
            Node::Leaf { .. } => 1,
            Node::Cap(_) => 0,
            Node::Split(ch) => ch.iter().map(Node::leaf_count).sum(),
        }
    }

    /// Calls `f` with each leaf's square `[u0, u1, v0, v1]` and patch (in model
    /// coordinates).
    pub fn for_each_leaf(&self, f: &mut dyn FnMut([f64; 4], &BezierPatch)) {
        fn walk(n: &Node, r: [f64; 4], f: &mut dyn FnMut([f64; 4], &BezierPatch)) {
            match n {
                Node::Leaf { patch, origin } => {
                    let mut p = patch.clone();
                    for c in p.cp.iter_mut().flatten() {
                        let w = c.w;
                        *c += Vector4::new(origin.x * w, origin.y * w, origin.z * w, 0.0);
                    }
                    f(r, &p)
                }
                Node::Cap(_) => {}
                Node::Split(ch) => {
                    let um = 0.5 * (r[0] + r[1]);
                    let vm = 0.5 * (r[2] + r[3]);
                    walk(&ch[0], [r[0], um, r[2], vm], f);
                    walk(&ch[1], [um, r[1], r[2], vm], f);
                    walk(&ch[2], [r[0], um, vm, r[3]], f);
                    walk(&ch[3], [um, r[1], vm, r[3]], f);
                }
            }
        }
        walk(self, [0.0, 1.0, 0.0, 1.0], f);
    }
}

/// Adjacency of a local mesh, built once per mesh: each vertex's outgoing directed edges
/// (one per quad at the vertex, in quad order), stored contiguously.
struct Adjacency {
    /// Vertex `v`'s edges are entries `start[v]..start[v + 1]`.
    start: Vec<u32>,
    /// Far end of each directed edge.
    to: Vec<u32>,
    /// Quad holding each directed edge, and the corner index of its start there.
    quad: Vec<u32>,
    corner: Vec<u8>,
}

impl Adjacency {
    fn new(m: &LocalMesh) -> Self {
        let n = m.pts.len();
        let mut start = vec![0u32; n + 1];
        for q in &m.quads {
            for &v in q {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let total = start[n] as usize;
        let (mut to, mut quad, mut corner) = (vec![0; total], vec![0; total], vec![0; total]);
        let mut fill = start.clone();
        for (qi, q) in m.quads.iter().enumerate() {
            for k in 0..4 {
                let slot = &mut fill[q[k] as usize];
                let i = *slot as usize;
                *slot += 1;
                to[i] = q[(k + 1) % 4];
                quad[i] = qi as u32;
                corner[i] = k as u8;
            }
        }
        Adjacency {
            start,
            to,
            quad,
            corner,
        }
    }

    fn range(&self, v: u32) -> std::ops::Range<usize> {
        self.start[v as usize] as usize..self.start[v as usize + 1] as usize
    }

    /// Quads at vertex `v`, in quad order.
    fn quads_at(&self, v: u32) -> &[u32] {
        &self.quad[self.range(v)]
    }

    /// The quad holding the directed edge `(a, b)` and the corner index of `a` in it.
    fn directed(&self, a: u32, b: u32) -> Option<(u32, u8)> {
        self.range(a)
            .find(|&i| self.to[i] == b)
            .map(|i| (self.quad[i], self.corner[i]))
    }

    /// True if the undirected edge has a quad on one side only.
    fn is_open(&self, a: u32, b: u32) -> bool {
        self.directed(a, b).is_none() || self.directed(b, a).is_none()
    }
}

/// A vertex of a local mesh with everything its rules need.
struct Around {
    faces: usize,
    /// Every edge at the vertex once: its far end and sharpness.
    edges: Vec<(u32, f64)>,
    /// False where some of its faces were cut away: its rules cannot be applied.
    complete: bool,
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl LocalMesh {
    /// Sharpness of the edge `a`–`b` (0 when smooth).
    fn edge_sharpness(&self, a: u32, b: u32) -> f64 {
        self.creases.get(&edge_key(a, b)).copied().unwrap_or(0.0)
    }

    fn vertex_sharpness(&self, v: u32) -> f64 {
        self.corners.get(&v).copied().unwrap_or(0.0)
    }

    /// The quad holding the directed edge `(a, b)` (the one across that edge from a quad
    /// running `b → a`) and the corner index of `a` in it; `None` where there is none or the
    /// edge is infinitely sharp.
    fn across(&self, adj: &Adjacency, a: u32, b: u32) -> Option<(u32, u8)> {
        if self.edge_sharpness(a, b) == INFINITELY_SHARP {
            return None;
        }
        adj.directed(a, b)
    }

    fn around(&self, adj: &Adjacency, v: u32) -> Around {
        let quads = adj.quads_at(v);
        let mut edges: Vec<(u32, f64)> = Vec::with_capacity(quads.len() + 1);
        let mut complete = true;
        for &q in quads {
            let quad = &self.quads[q as usize];
            let k = quad
                .iter()
                .position(|&x| x == v)
                .expect("vertex is in its quad");
            for w in [quad[(k + 1) % 4], quad[(k + 3) % 4]] {
                if edges.iter().any(|e| e.0 == w) {
                    continue;
                }
                let s = self.edge_sharpness(v, w);
                // An open edge is the model's boundary only if it is marked (infinitely sharp).
                if adj.is_open(v, w) && s != INFINITELY_SHARP {
                    complete = false;
                }
                edges.push((w, s));
            }
        }
        Around {
            faces: quads.len(),
            edges,
            complete,
        }
    }

    fn rule(&self, v: u32, a: &Around) -> VertexRule {
        VertexRule::of(self.vertex_sharpness(v), a.edges.iter().map(|e| e.1))
    }

    /// Quads of the sector of `v` holding quad `q`: those reached from `q` round `v` without
    /// crossing an edge that blocks.
    fn sector_size(&self, adj: &Adjacency, q: u32, v: u32) -> usize {
        let pos = |quad: u32| {
            let qd = &self.quads[quad as usize];
            (qd, qd.iter().position(|&x| x == v).expect("vertex in quad"))
        };
        let limit = adj.quads_at(v).len();
        let mut count = 1;
        // Counter-clockwise across each quad's side leaving `v` (corner k + 1), then
        // clockwise across the side arriving (corner k + 3), each until an edge blocks; a
        // full turn round `v` ends both.
        for leaving in [true, false] {
            let mut cur = q;
            while count < limit {
                let (qd, k) = pos(cur);
                let next = if leaving {
                    self.across(adj, qd[(k + 1) % 4], v)
                } else {
                    self.across(adj, v, qd[(k + 3) % 4])
                };
                match next {
                    Some((n, _)) if n != q => {
                        cur = n;
                        count += 1;
                    }
                    Some(_) => return count,
                    None => break,
                }
            }
        }
        count
    }

    /// True if corner `v` of quad `q` is regular for `q`: the uniform bicubic B-spline of the
    /// one-ring (mirrored across infinitely sharp edges) is `q`'s limit there. A smooth
    /// vertex of four faces, a crease vertex with two faces on `q`'s side of the crease, a
    /// corner with `q` alone between its sharp edges; no semi-sharp edge or vertex.
    fn regular_corner(&self, adj: &Adjacency, q: u32, v: u32) -> bool {
        let a = self.around(adj, v);
        let vs = self.vertex_sharpness(v);
        let finite = |s: f64| s > 0.0 && s != INFINITELY_SHARP;
        if !a.complete || finite(vs) || a.edges.iter().any(|e| finite(e.1)) {
            return false;
        }
        match self.rule(v, &a) {
            VertexRule::Smooth => a.faces == 4,
            VertexRule::Dart => false,
            VertexRule::Crease => self.sector_size(adj, q, v) == 2,
            VertexRule::Corner => self.sector_size(adj, q, v) == 1,
        }
    }

    /// One Catmull–Clark step. Returns the fine mesh; quad `q` of `self` has children
    /// `4q..4q+4` ordered `[u low v low, u high v low, u high v high, u low v high]`, each with
    /// its first corner at its own `(0, 0)` in the parent's frame. Creases and corners decay
    /// by one step ([`sharpness::decayed`]).
    pub fn subdivide(&self) -> LocalMesh {
        let adj = Adjacency::new(self);
        let nv = self.pts.len();
        // Edges, numbered in first-seen order.
        let mut edge_id: LocalMap<(u32, u32), u32> = LocalMap::default();
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for q in &self.quads {
            for k in 0..4 {
                let key = edge_key(q[k], q[(k + 1) % 4]);
                edge_id.entry(key).or_insert_with(|| {
                    edges.push(key);
                    (edges.len() - 1) as u32
                });
            }
        }
        let ne = edges.len();
        let face_pts: Vec<Vector4> = self
            .quads
            .iter()
            .map(|q| q.iter().map(|&i| self.pts[i as usize]).sum::<Vector4>() * 0.25)
            .collect();
        let mut pts = Vec::with_capacity(nv + ne + self.quads.len());
        // Vertex points.
        let mut ends: Vec<EdgeEnd> = Vec::new();
        for v in 0..nv as u32 {
            let p = self.pts[v as usize];
            let a = self.around(&adj, v);
            if !a.complete {
                pts.push(p);
                continue;
            }
            ends.clear();
            ends.extend(a.edges.iter().map(|&(w, s)| EdgeEnd {
                point: self.pts[w as usize],
                sharpness: s,
            }));
            let smooth = || {
                let n = a.faces as f64;
                let quads = adj.quads_at(v);
                let q: Vector4 = quads.iter().map(|&f| face_pts[f as usize]).sum::<Vector4>() / n;
                let mut r = Vector4::zeros();
                for &f in quads {
                    let quad = &self.quads[f as usize];
                    let k = quad.iter().position(|&x| x == v).unwrap();
                    // Each edge is shared by two of the quads: count the outgoing one.
                    r += (p + self.pts[quad[(k + 1) % 4] as usize]) * 0.5;
                }
                r /= n;
                (q + r * 2.0 + p * (n - 3.0)) / n
            };
            pts.push(sharpness::vertex_point(
                p,
                self.vertex_sharpness(v),
                &ends,
                smooth,
            ));
        }
        // Edge points.
        for &(a, b) in &edges {
            let faces = match (adj.directed(a, b), adj.directed(b, a)) {
                (Some((q0, _)), Some((q1, _))) => {
                    Some((face_pts[q0 as usize], face_pts[q1 as usize]))
                }
                _ => None,
            };
            pts.push(sharpness::edge_point(
                self.pts[a as usize],
                self.pts[b as usize],
                faces,
                self.edge_sharpness(a, b),
            ));
        }
        pts.extend(face_pts.iter().copied());
        let ev = |a: u32, b: u32| nv as u32 + edge_id[&edge_key(a, b)];
        let mut quads = Vec::with_capacity(self.quads.len() * 4);
        for (qi, q) in self.quads.iter().enumerate() {
            let f = (nv + ne + qi) as u32;
            let [c0, c1, c2, c3] = *q;
            let (e01, e12, e23, e30) = (ev(c0, c1), ev(c1, c2), ev(c2, c3), ev(c3, c0));
            quads.push([c0, e01, f, e30]);
            quads.push([e01, c1, e12, f]);
            quads.push([f, e12, c2, e23]);
            quads.push([e30, f, e23, c3]);
        }
        // (A crease between two kept vertices whose quads were cut away has no edge point.)
        let creases = sharpness::child_creases(&self.creases, |a, b| {
            edge_id.get(&edge_key(a, b)).map(|&id| nv as u32 + id)
        })
        .collect();
        let corners = sharpness::child_corners(&self.corners).collect();
        LocalMesh {
            pts,
            origin: self.origin,
            quads,
            creases,
            corners,
        }
    }

    /// The same mesh with coordinates measured from `origin + shift` (mm).
    fn recentred(mut self, shift: Vector3) -> LocalMesh {
        for p in self.pts.iter_mut() {
            let w = p.w;
            *p -= Vector4::new(shift.x * w, shift.y * w, shift.z * w, 0.0);
        }
        self.origin += shift;
        self
    }

    /// The quads sharing a vertex with quad `q`, as a new local mesh; returns it and the
    /// index of `q` in it.
    pub fn one_ring(&self, q: u32) -> (LocalMesh, u32) {
        self.one_ring_with(&Adjacency::new(self), q)
    }

    fn one_ring_with(&self, adj: &Adjacency, q: u32) -> (LocalMesh, u32) {
        let mut keep: Vec<u32> = Vec::new();
        for &v in &self.quads[q as usize] {
            for &f in adj.quads_at(v) {
                if !keep.contains(&f) {
                    keep.push(f);
                }
            }
        }
        keep.sort_unstable();
        let mut map: LocalMap<u32, u32> = LocalMap::default();
        let mut pts = Vec::new();
        let mut quads = Vec::with_capacity(keep.len());
        for &f in &keep {
            let quad = self.quads[f as usize];
            quads.push(quad.map(|v| {
                *map.entry(v).or_insert_with(|| {
                    pts.push(self.pts[v as usize]);
                    (pts.len() - 1) as u32
                })
            }));
        }
        let creases = self
            .creases
            .iter()
            .filter_map(|(&(a, b), &s)| Some((edge_key(*map.get(&a)?, *map.get(&b)?), s)))
            .collect();
        let corners = self
            .corners
            .iter()
            .filter_map(|(v, &s)| Some((*map.get(v)?, s)))
            .collect();
        let idx = keep.binary_search(&q).expect("q is in its own one-ring") as u32;
        (
            LocalMesh {
                pts,
                origin: self.origin,
                quads,
                creases,
                corners,
            },
            idx,
        )
    }

    /// The 16 control points of quad `q` as a uniform bicubic B-spline patch, indexed
    /// `[j][i]` with `i` along the quad's first side; `None` unless the quad is regular.
    pub fn regular_grid(&self, q: u32) -> Option<[[Vector4; 4]; 4]> {
        let adj = Adjacency::new(self);
        self.regular_grid_with(&adj, q)
    }

    fn regular_grid_with(&self, adj: &Adjacency, q: u32) -> Option<[[Vector4; 4]; 4]> {
        let quad = self.quads[q as usize];
        if !quad.iter().all(|&c| self.regular_corner(adj, q, c)) {
            return None;
        }
        let mut g: [[Option<Vector4>; 4]; 4] = [[None; 4]; 4];
        // Corner k sits at grid (i, j); its outer quadrant points (a, diag, b).
        const CORNER: [(usize, usize); 4] = [(1, 1), (2, 1), (2, 2), (1, 2)];
        const OUTER: [[(usize, usize); 3]; 4] = [
            [(0, 1), (0, 0), (1, 0)],
            [(2, 0), (3, 0), (3, 1)],
            [(3, 2), (3, 3), (2, 3)],
            [(1, 3), (0, 3), (0, 2)],
        ];
        let at = |quad: u32, k: i32| -> u32 { self.quads[quad as usize][k.rem_euclid(4) as usize] };
        for k in 0..4 {
            let p = quad[k];
            let prev = quad[(k + 3) % 4];
            let next = quad[(k + 1) % 4];
            let (ci, cj) = CORNER[k];
            g[cj][ci] = Some(self.pts[p as usize]);
            let mut found: [Option<u32>; 3] = [None; 3];
            // Counter-clockwise: the quad across the previous side, then the diagonal one
            // (never across an infinitely sharp edge: the other side is mirrored instead).
            if let Some((l, i)) = self.across(adj, p, prev) {
                let a = at(l, i as i32 - 1);
                found[0] = Some(a);
                if let Some((d, j)) = self.across(adj, p, a) {
                    found[1] = Some(at(d, j as i32 + 2));
                    found[2] = Some(at(d, j as i32 - 1));
                }
            }
            // Clockwise: the quad across the next side, then the diagonal one.
            if let Some((b_quad, i)) = self.across(adj, next, p) {
                let b = at(b_quad, i as i32 + 2);
                found[2] = found[2].or(Some(b));
                if let Some((d, j)) = self.across(adj, b, p) {
                    found[1] = found[1].or(Some(at(d, j as i32 + 3)));
                    found[0] = found[0].or(Some(at(d, j as i32 + 2)));
                }
            }
            for (slot, v) in OUTER[k].iter().zip(found) {
                if let Some(v) = v {
                    g[slot.1][slot.0] = Some(self.pts[v as usize]);
                }
            }
        }
        // Mirror across sharp sides (model boundaries and infinitely sharp creases): side 0 →
        // row 0, side 1 → column 3, side 2 → row 3, side 3 → column 0.
        let sharp_side = |k: usize| {
            let (a, b) = (quad[k], quad[(k + 1) % 4]);
            self.edge_sharpness(a, b) == INFINITELY_SHARP
        };
        let sides = [sharp_side(0), sharp_side(1), sharp_side(2), sharp_side(3)];
        for _ in 0..3 {
            for j in 0..4 {
                for i in 0..4 {
                    if g[j][i].is_some() {
                        continue;
                    }
                    let mirror = |a: Option<Vector4>, b: Option<Vector4>| Some(a? * 2.0 - b?);
                    let cand = if i == 0 && sides[3] {
                        mirror(g[j][1], g[j][2])
                    } else if i == 3 && sides[1] {
                        mirror(g[j][2], g[j][1])
                    } else {
                        None
                    }
                    .or_else(|| {
                        if j == 0 && sides[0] {
                            mirror(g[1][i], g[2][i])
                        } else if j == 3 && sides[2] {
                            mirror(g[2][i], g[1][i])
                        } else {
                            None
                        }
                    });
                    g[j][i] = cand;
                }
            }
        }
        let mut out = [[Vector4::zeros(); 4]; 4];
        for j in 0..4 {
            for i in 0..4 {
                out[j][i] = g[j][i]?;
            }
        }
        Some(out)
    }

    /// The limit point of vertex `v` (homogeneous), whose faces must all be present. A
    /// semi-sharp vertex or edge is taken as sharp (callers ask only once it is one or the
    /// other, or for a nearby point).
    pub fn limit_point(&self, v: u32) -> Vector4 {
        self.limit_point_with(&Adjacency::new(self), v)
    }

    fn limit_point_with(&self, adj: &Adjacency, v: u32) -> Vector4 {
        let p = self.pts[v as usize];
        let a = self.around(adj, v);
        if !a.complete {
            return p;
        }
        let smooth = || {
            let n = a.faces as f64;
            let mut e = Vector4::zeros();
            let mut f = Vector4::zeros();
            for &q in adj.quads_at(v) {
                let quad = &self.quads[q as usize];
                let k = quad.iter().position(|&x| x == v).unwrap();
                e += self.pts[quad[(k + 1) % 4] as usize];
                f += self.pts[quad[(k + 2) % 4] as usize];
            }
            (p * (n * n) + e * 4.0 + f) / (n * (n + 5.0))
        };
        let ends = a
            .edges
            .iter()
            .filter(|e| e.1 > 0.0)
            .map(|e| self.pts[e.0 as usize]);
        sharpness::limit_point(p, self.rule(v, &a), ends, smooth)
    }

    /// The quadtree of quad `q`: a Bézier cell if it is regular, else its children after
    /// one subdivision step, recursively.
    pub fn face_tree(&self, q: u32) -> Node {
        self.tree_at(q, 0, true)
    }

    /// `learn`: whether rings that repeat their topology may use a [`LinearStep`].
    fn tree_at(&self, q: u32, depth: usize, learn: bool) -> Node {
        let adj = Adjacency::new(self);
        if let Some(grid) = self.regular_grid_with(&adj, q) {
            return Node::Leaf {
                patch: bspline_to_bezier(&grid),
                origin: self.origin,
            };
        }
        let (ring, qi) = self.one_ring_with(&adj, q);
        ring.ring_tree(qi, depth, None, learn)
    }

    /// True if `other` (with face `other_q`) has the same topology and sharpness as `self`
    /// (with face `q`): one subdivision step acts on both points alike.
    fn same_topology(&self, q: u32, other: &LocalMesh, other_q: u32) -> bool {
        q == other_q
            && self.pts.len() == other.pts.len()
            && self.quads == other.quads
            && self.creases == other.creases
            && self.corners == other.corners
    }

    /// The quadtree of face `qi` of `self`, which is that face's one-ring and not regular.
    /// With `step`, learnt on a ring of this topology, a level costs one sparse product.
    fn ring_tree(self, qi: u32, depth: usize, step: Option<&LinearStep>, learn: bool) -> Node {
        // The irregular corner's limit point: the coordinates are measured from it so that
        // they shrink with the region.
        let (limit, corner) = match step {
            Some(s) => (LinearStep::apply(&s.limit, &self.pts), None),
            None => {
                let adj = Adjacency::new(&self);
                let quad = self.quads[qi as usize];
                let c = quad
                    .iter()
                    .copied()
                    .find(|&c| !self.regular_corner(&adj, qi, c))
                    .unwrap_or(quad[0]);
                (self.limit_point_with(&adj, c), Some(c))
            }
        };
        if depth >= MAX_DEPTH {
            let o = self.origin;
            return Node::Cap(
                limit + Vector4::new(o.x * limit.w, o.y * limit.w, o.z * limit.w, 0.0),
            );
        }
        let ring = self.recentred(limit.xyz() / limit.w);
        if let Some(s) = step {
            return s.tree(ring, qi, depth);
        }
        let fine = ring.subdivide();
        let fine_adj = Adjacency::new(&fine);
        let base = 4 * qi;
        let mut children: Vec<Node> = Vec::with_capacity(4);
        let mut learnt: Option<LinearStep> = None;
        // Once learning failed for this topology it would fail again below: stop trying.
        let mut learn = learn;
        for k in 0..4 {
            if let Some(grid) = fine.regular_grid_with(&fine_adj, base + k) {
                children.push(Node::Leaf {
                    patch: bspline_to_bezier(&grid),
                    origin: fine.origin,
                });
                continue;
            }
            let (next, nq) = fine.one_ring_with(&fine_adj, base + k);
            // A ring that comes back unchanged one level down (an extraordinary point in a
            // smooth or infinitely creased neighbourhood) is subdivided the same way at
            // every level below: learn that step once.
            if learn
                && learnt.is_none()
                && ring.pts.len() <= LinearStep::MAX_POINTS
                && ring.same_topology(qi, &next, nq)
            {
                learnt = LinearStep::learn(&ring, qi, corner.expect("generic level"));
                learn = learnt.is_some();
            }
            children.push(next.ring_tree(nq, depth + 1, learnt.as_ref(), learn));
        }
        // Children are stored [ll, u high, both high, v high]; the tree wants
        // [ll, u high, v high, both high].
        let mut it = children.into_iter();
        let (c0, c1, c2, c3) = (
            it.next().expect("4 children"),
            it.next().expect("4 children"),
            it.next().expect("4 children"),
            it.next().expect("4 children"),
        );
        Node::Split(Box::new([c0, c1, c3, c2]))
    }
}

/// Weights of a ring's points giving one point (sparse: zero weights left out).
type Row = Vec<(u32, f64)>;

/// One level of an irregular face's quadtree as a linear map of its one-ring's points, for
/// a ring whose topology comes back unchanged one level down (an extraordinary point in a
/// smooth or infinitely creased neighbourhood). Learnt once per face by subdividing unit
/// points through the generic step, then applied at every deeper level instead of building
/// and subdividing a mesh (OpenSubdiv builds such stencils once, too).
struct LinearStep {
    /// The irregular corner's limit point.
    limit: Row,
    /// Per child (in [`LocalMesh::subdivide`]'s order): a regular child's 16 Bézier control
    /// points (`[j][i]` row-major), or `None` for the irregular child.
    children: [Option<Box<[Row; 16]>>; 4],
    /// The irregular child's one-ring points.
    next: Vec<Row>,
}

impl LinearStep {
    /// Largest ring (points) a step is learnt for: learning costs a generic level per four
    /// points, so beyond this (valence about 28) subdividing is cheaper.
    const MAX_POINTS: usize = 64;

    fn apply(row: &Row, pts: &[Vector4]) -> Vector4 {
        row.iter().map(|&(i, w)| pts[i as usize] * w).sum()
    }

    /// The step of ring `ring` (face `qi`, irregular corner `corner`), found by pushing unit
    /// points through the generic step four at a time (one per homogeneous coordinate);
    /// `None` unless exactly one child is irregular and its ring has `ring`'s topology.
    fn learn(ring: &LocalMesh, qi: u32, corner: u32) -> Option<LinearStep> {
        let n = ring.pts.len();
        let mut step = LinearStep {
            limit: Vec::new(),
            children: [None, None, None, None],
            next: vec![Vec::new(); n],
        };
        let mut leaves: [Option<[Row; 16]>; 4] = Default::default();
        let mut irregular: Option<u32> = None;
        let mut probe = ring.clone();
        probe.origin = Vector3::zeros();
        for first in (0..n).step_by(4) {
            for (i, p) in probe.pts.iter_mut().enumerate() {
                let unit = |c: usize| if i == first + c { 1.0 } else { 0.0 };
                *p = Vector4::new(unit(0), unit(1), unit(2), unit(3));
            }
            // Column `first + c` of every output is its coordinate `c`.
            let record = |row: &mut Row, v: Vector4| {
                for c in 0..4 {
                    if first + c < n && v[c] != 0.0 {
                        row.push(((first + c) as u32, v[c]));
                    }
                }
            };
            record(&mut step.limit, probe.limit_point(corner));
            let fine = probe.subdivide();
            for k in 0..4u32 {
                let child = 4 * qi + k;
                match fine.regular_grid(child) {
                    Some(grid) => {
                        let patch = bspline_to_bezier(&grid);
                        let rows = leaves[k as usize].get_or_insert_with(Default::default);
                        for (r, p) in rows.iter_mut().zip(patch.cp.iter().flatten()) {
                            record(r, *p);
                        }
                    }
                    None => {
                        if irregular.is_some_and(|j| j != k) {
                            return None;
                        }
                        irregular = Some(k);
                        let (next, nq) = fine.one_ring(child);
                        if !ring.same_topology(qi, &next, nq) {
                            return None;
                        }
                        for (r, p) in step.next.iter_mut().zip(&next.pts) {
                            record(r, *p);
                        }
                    }
                }
            }
        }
        irregular?;
        for (slot, rows) in step.children.iter_mut().zip(leaves) {
            *slot = rows.map(Box::new);
        }
        Some(step)
    }

    /// The children of `ring` (already measured from its corner's limit point) at `depth`,
    /// by this step.
    fn tree(&self, ring: LocalMesh, qi: u32, depth: usize) -> Node {
        let LocalMesh {
            pts,
            origin,
            quads,
            creases,
            corners,
        } = ring;
        let mut next = Some(LocalMesh {
            pts: self.next.iter().map(|r| Self::apply(r, &pts)).collect(),
            origin,
            quads,
            creases,
            corners,
        });
        let mut child = |k: usize| match &self.children[k] {
            Some(rows) => {
                let mut patch = BezierPatch::zero();
                for (c, r) in patch.cp.iter_mut().flatten().zip(rows.iter()) {
                    *c = Self::apply(r, &pts);
                }
                Node::Leaf { patch, origin }
            }
            None => {
                next.take()
                    .expect("one irregular child")
                    .ring_tree(qi, depth + 1, Some(self), true)
            }
        };
        let (c0, c1, c2, c3) = (child(0), child(1), child(2), child(3));
        Node::Split(Box::new([c0, c1, c3, c2]))
    }
}

/// Bézier form of the uniform bicubic B-spline segment of a 4×4 grid `[j][i]`.
pub fn bspline_to_bezier(g: &[[Vector4; 4]; 4]) -> BezierPatch {
    // Rows of the uniform cubic B-spline → Bézier conversion.
    const M: [[f64; 4]; 4] = [
        [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
        [0.0, 4.0 / 6.0, 2.0 / 6.0, 0.0],
        [0.0, 2.0 / 6.0, 4.0 / 6.0, 0.0],
        [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
    ];
    let mut rows = [[Vector4::zeros(); 4]; 4];
    for j in 0..4 {
        for a in 0..4 {
            rows[j][a] = (0..4).map(|i| g[j][i] * M[a][i]).sum();
        }
    }
    let mut out = BezierPatch::zero();
    for b in 0..4 {
        for a in 0..4 {
            out.cp[b][a] = (0..4).map(|j| rows[j][a] * M[b][j]).sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::tmesh::TMesh;

    /// A bowl round one interior vertex of valence `n`.
    fn star(n: usize) -> TMesh {
        let (m, _) = crate::io::obj::read(&crate::model::samples::pole_cage_obj(n)).unwrap();
        m
    }

    #[test]
    fn learnt_steps_give_the_subdivided_tree() {
        use super::*;
        // The faces at a valence-5 and a valence-3 point: the tree whose deep levels are one
        // learnt linear map each equals the tree subdivided level by level, to rounding,
        // down to the cap (parameters 2^-k from the point).
        for n in [3, 5, 7] {
            let mesh = star(n);
            let size = mesh.control_bbox().diagonal();
            let mut worst: f64 = 0.0;
            // Each point's face is followed by four faces of the outer rings.
            for f in (0..n as u32).map(|k| 5 * k) {
                let (local, q) = crate::surface::extract::local_one_ring(&mesh, f).unwrap();
                // One level down the ring repeats its topology and a step is learnt.
                let (ring, qi) = local.one_ring(q);
                let down = |m: &LocalMesh, qi: u32| {
                    let fine = m.subdivide();
                    let child = (4 * qi..4 * qi + 4)
                        .find(|&c| fine.regular_grid(c).is_none())
                        .unwrap();
                    fine.one_ring(child)
                };
                let (r1, q1) = down(&ring, qi);
                let (r2, q2) = down(&r1, q1);
                assert!(r1.same_topology(q1, &r2, q2));
                let adj = Adjacency::new(&r1);
                let corner = r1.quads[q1 as usize]
                    .into_iter()
                    .find(|&c| !r1.regular_corner(&adj, q1, c))
                    .unwrap();
                assert!(LinearStep::learn(&r1, q1, corner).is_some());
                let fast = local.face_tree(q);
                let slow = local.tree_at(q, 0, false);
                assert_eq!(fast.leaf_count(), slow.leaf_count());
                for k in 0..45 {
                    let t = 0.7f64.powi(k);
                    for (u, v) in [(t, t), (t, 0.3 * t), (0.01 * t, t), (0.5, t)] {
                        let (a, b) = (fast.subs(u, v), slow.subs(u, v));
                        worst = worst.max((a - b).norm() / size);
                    }
                }
            }
            println!("valence {n}: learnt steps against subdivision {worst:.2e} of the size");
            assert!(worst < 1e-14, "valence {n}: {worst}");
        }
    }
}
