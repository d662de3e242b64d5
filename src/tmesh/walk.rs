//! Local knot vectors by walking the T-mesh, and the placement of a vertex's support.
//!
//! A ray leaves a vertex in one of its four directions and crosses knot lines: along an edge
//! it reaches the edge's far vertex; inside a face it crosses to the opposite side. Each
//! crossing is one bay, except a crossing of a fan line between its ends (a repeated knot
//! that exists only at the grip block it leaves, see [`super`]). Two bays in each direction
//! give the five knots of a cubic blending function; where the ray leaves the mesh the last
//! knot repeats.
//!
//! Everything is topological (sides of faces, quarter turns around vertices) so that zero
//! knot intervals, which encode repeated knots, walk like any others.

use super::{TMesh, KNOT_MATCH_REL};
use crate::surface::basis::LocalKnots;
use std::collections::{HashMap, VecDeque};

/// What lies in a given direction from a vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Look {
    /// An edge: the outgoing half-edge.
    Edge(u32),
    /// An edge with no outgoing half-edge (a boundary edge): the half-edge ending here.
    EdgeBack(u32),
    /// The interior of a face, entered at a T-junction: the face's outgoing half-edge at the
    /// vertex.
    Face(u32),
    /// Outside the mesh.
    Boundary,
}

/// Where a ray is.
#[derive(Debug, Clone, Copy)]
enum At {
    /// At the origin of `h_ref`, heading `theta` quarter turns counter-clockwise of it.
    Vertex { h_ref: u32, theta: u32 },
    /// Inside half-edge `h`, `pos` from its origin, heading across it (out of its face).
    Side { h: u32, pos: f64 },
}

/// Placement of a face in a vertex's frame: `chart = rot(k)·local + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub face: u32,
    pub quarter_turns: u8,
    pub offset: [f64; 2],
}

/// A blending function expressed in one face's local knot coordinates `[0,W]×[0,H]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceBlend {
    pub vertex: u32,
    pub u_knots: LocalKnots,
    pub v_knots: LocalKnots,
}

impl TMesh {
    fn look(&self, h_ref: u32, theta: u32) -> Look {
        let limit = self.half_edges.len() + 4;
        // Counter-clockwise sweep.
        let mut acc = 0;
        let mut h = h_ref;
        for _ in 0..limit {
            if acc == theta {
                return Look::Edge(h);
            }
            let q = self.sector_quarters(h);
            if acc < theta && theta < acc + q {
                return Look::Face(h);
            }
            acc += q;
            if acc == theta {
                return Look::EdgeBack(self.he(h).prev);
            }
            if acc > theta {
                break;
            }
            match self.he(self.he(h).prev).twin {
                Some(t) if t != h_ref => h = t,
                _ => break,
            }
        }
        // Clockwise sweep for the rest of the turn (reaches past a boundary from the other side).
        let phi = (4 - theta % 4) % 4;
        let mut acc = 0;
        let mut h = h_ref;
        for _ in 0..limit {
            if acc == phi {
                return Look::Edge(h);
            }
            let Some(t) = self.he(h).twin else {
                return Look::Boundary;
            };
            let n = self.he(t).next;
            let q = self.sector_quarters(n);
            if acc < phi && phi < acc + q {
                return Look::Face(n);
            }
            acc += q;
            if acc > phi || n == h_ref {
                return Look::Boundary;
            }
            h = n;
        }
        Look::Boundary
    }

    /// Length of side `side` of face `f`.
    fn side_length(&self, f: u32, side: u8) -> f64 {
        let face = &self.faces[f as usize];
        if side % 2 == 0 {
            face.width
        } else {
            face.height
        }
    }

    /// Crosses face `f` from side `side` at position `p` along it; returns the distance
    /// travelled and where the ray lands on the opposite side.
    fn cross(&self, f: u32, side: u8, p: f64) -> (f64, At) {
        let len = self.side_length(f, side);
        let across = self.side_length(f, (side + 1) % 4);
        let opp = (side + 2) % 4;
        let q = len - p;
        let tol = KNOT_MATCH_REL * len.max(across);
        let mut landing = None;
        for h in self.face_half_edges(f) {
            let e = self.he(h);
            if e.side != opp {
                continue;
            }
            if (e.offset - q).abs() <= tol {
                landing = Some(At::Vertex { h_ref: h, theta: 3 });
                break;
            }
            if e.offset < q && q < e.offset + e.knot {
                landing = Some(At::Side {
                    h,
                    pos: q - e.offset,
                });
                break;
            }
        }
        // Falls on the side's far corner only through rounding: take the last vertex. An
        // empty opposite side (a zero-area face's cusp) lands on the cusp, the origin of the
        // next side, whose direction is a quarter turn further: the ray is two quarters on.
        let landing = landing.unwrap_or_else(|| {
            let hs = self.face_half_edges(f);
            match hs.iter().rfind(|&&h| self.he(h).side == opp) {
                Some(&h) => At::Vertex { h_ref: h, theta: 3 },
                None => {
                    let next = (opp + 1) % 4;
                    let h = hs
                        .iter()
                        .copied()
                        .find(|&h| self.he(h).side == next)
                        .unwrap_or(hs[0]);
                    At::Vertex { h_ref: h, theta: 2 }
                }
            }
        });
        (across, landing)
    }

    /// Distances from vertex `origin(h_ref)` to the next two knot lines in direction
    /// `dir` (quarter turns counter-clockwise of `h_ref`). `extraordinary` marks vertices
    /// through which a ray continues uniformly (repeating its last bay).
    fn ray(&self, h_ref: u32, dir: u32, extraordinary: &[bool]) -> [f64; 2] {
        let mut knots = [0.0f64; 2];
        let mut found = 0;
        let mut dist = 0.0;
        let mut last_step = 0.0;
        let mut state = At::Vertex { h_ref, theta: dir };
        let mut first = true;
        while found < 2 {
            let step = match state {
                At::Vertex { h_ref, theta } => {
                    let v = self.he(h_ref).origin;
                    if !first && extraordinary[v as usize] {
                        // No straight line through an extraordinary point: knot intervals are
                        // uniform around it (checked elsewhere), so the next bay repeats.
                        Some((last_step, state))
                    } else {
                        match self.look(h_ref, theta) {
                            Look::Edge(h) => {
                                let n = self.he(h).next;
                                Some((
                                    self.he(h).knot,
                                    At::Vertex {
                                        h_ref: n,
                                        theta: self.sector_quarters(n) + 2,
                                    },
                                ))
                            }
                            Look::EdgeBack(p) => {
                                Some((self.he(p).knot, At::Vertex { h_ref: p, theta: 2 }))
                            }
                            Look::Face(h) => {
                                let e = self.he(h);
                                Some(self.cross(e.face, e.side, e.offset))
                            }
                            Look::Boundary => None,
                        }
                    }
                }
                At::Side { h, pos } => match self.he(h).twin {
                    Some(t) => {
                        let e = self.he(t);
                        let along = self.he(h).knot - pos;
                        Some(self.cross(e.face, e.side, e.offset + along))
                    }
                    None => None,
                },
            };
            first = false;
            match step {
                // Crossing a fan line between its ends: no knot there, the ray goes on.
                Some((d, next @ At::Side { h, .. }))
                    if self.is_fan_line(h) && self.he(h).twin.is_some() =>
                {
                    dist += d;
                    state = next;
                }
                Some((d, next)) => {
                    dist += d;
                    last_step = d;
                    knots[found] = dist;
                    found += 1;
                    state = next;
                }
                None => break,
            }
        }
        for k in found..2 {
            knots[k] = dist;
        }
        knots
    }

    /// Local knot vectors `(s, t)` of vertex `v` in its own frame: `s` along its reference
    /// half-edge, `t` a quarter turn counter-clockwise; the vertex sits at 0 in both.
    pub fn local_knots(&self, v: u32, extraordinary: &[bool]) -> (LocalKnots, LocalKnots) {
        let h = self.vertex_edge[v as usize];
        let e = self.ray(h, 0, extraordinary);
        let n = self.ray(h, 1, extraordinary);
        let w = self.ray(h, 2, extraordinary);
        let s = self.ray(h, 3, extraordinary);
        (
            [-w[1], -w[0], 0.0, e[0], e[1]],
            [-s[1], -s[0], 0.0, n[0], n[1]],
        )
    }

    /// Local origin and direction (quarter turns) of half-edge `h` in its face's frame.
    pub(crate) fn local_frame(&self, h: u32) -> ([f64; 2], u8) {
        let e = self.he(h);
        let f = &self.faces[e.face as usize];
        let o = e.offset;
        let p = match e.side {
            0 => [o, 0.0],
            1 => [f.width, o],
            2 => [f.width - o, f.height],
            _ => [0.0, f.height - o],
        };
        (p, e.side)
    }

    /// Faces whose closed rectangles meet the closed box `[s0,s1]×[t0,t1]` in vertex `v`'s
    /// frame, placed by a breadth-first walk across edges from the vertex.
    pub fn place_support(&self, v: u32, s: (f64, f64), tb: (f64, f64)) -> Vec<Placement> {
        let h0 = self.vertex_edge[v as usize];
        let scale = (s.1 - s.0)
            .abs()
            .max((tb.1 - tb.0).abs())
            .max(f64::MIN_POSITIVE);
        let tol = KNOT_MATCH_REL * scale;
        let mut placed: HashMap<u32, Placement> = HashMap::new();
        let mut order = Vec::new();
        let mut queue = VecDeque::new();
        let place = |h: u32, pos: [f64; 2], dir: u8| -> Placement {
            let (lo, side) = self.local_frame(h);
            let k = (dir + 4 - side) % 4;
            let r = rot(k, lo);
            Placement {
                face: self.he(h).face,
                quarter_turns: k,
                offset: [pos[0] - r[0], pos[1] - r[1]],
            }
        };
        let first = place(h0, [0.0, 0.0], 0);
        placed.insert(first.face, first);
        order.push(first);
        queue.push_back(first);
        while let Some(pl) = queue.pop_front() {
            for h in self.face_half_edges(pl.face) {
                let Some(t) = self.he(h).twin else { continue };
                let g = self.he(t).face;
                if placed.contains_key(&g) {
                    continue;
                }
                let (lo, side) = self.local_frame(h);
                let knot = self.he(h).knot;
                let d = unit(side);
                let end_local = [lo[0] + knot * d[0], lo[1] + knot * d[1]];
                let r = rot(pl.quarter_turns, end_local);
                let pos = [r[0] + pl.offset[0], r[1] + pl.offset[1]];
                let dir = (pl.quarter_turns + side + 2) % 4;
                let cand = place(t, pos, dir);
                let (lo_c, hi_c) = self.chart_rect(&cand);
                let meets = lo_c[0] <= s.1 + tol
                    && hi_c[0] >= s.0 - tol
                    && lo_c[1] <= tb.1 + tol
                    && hi_c[1] >= tb.0 - tol;
                placed.insert(g, cand);
                if meets {
                    order.push(cand);
                    queue.push_back(cand);
                }
            }
        }
        order
    }

    /// The rectangle `(min, max)` a placed face covers in the chart.
    pub fn chart_rect(&self, p: &Placement) -> ([f64; 2], [f64; 2]) {
        let f = &self.faces[p.face as usize];
        let a = rot(p.quarter_turns, [0.0, 0.0]);
        let b = rot(p.quarter_turns, [f.width, f.height]);
        let lo = [a[0].min(b[0]) + p.offset[0], a[1].min(b[1]) + p.offset[1]];
        let hi = [a[0].max(b[0]) + p.offset[0], a[1].max(b[1]) + p.offset[1]];
        (lo, hi)
    }

    /// Every vertex's blending function, expressed in the local coordinates of each face it
    /// covers with positive area. Indexed by face. Vertices flagged in `skip` contribute
    /// nothing (extraordinary points, whose faces are evaluated by subdivision).
    pub fn face_blends(&self, extraordinary: &[bool], skip: &[bool]) -> Vec<Vec<FaceBlend>> {
        let mut out: Vec<Vec<FaceBlend>> = vec![Vec::new(); self.faces.len()];
        for v in 0..self.points.len() as u32 {
            if skip[v as usize] {
                continue;
            }
            let (sk, tk) = self.local_knots(v, extraordinary);
            let placements = self.place_support(v, (sk[0], sk[4]), (tk[0], tk[4]));
            for pl in placements {
                let face = &self.faces[pl.face as usize];
                if !face.is_domain() {
                    continue;
                }
                let [tx, ty] = pl.offset;
                let (uk, vk) = match pl.quarter_turns {
                    0 => (shift(&sk, -tx), shift(&tk, -ty)),
                    1 => (shift(&tk, -ty), mirror(&sk, tx)),
                    2 => (mirror(&sk, tx), mirror(&tk, ty)),
                    _ => (mirror(&tk, ty), shift(&sk, -tx)),
                };
                let tol_u = KNOT_MATCH_REL * face.width;
                let tol_v = KNOT_MATCH_REL * face.height;
                let overlap_u = uk[4].min(face.width) - uk[0].max(0.0);
                let overlap_v = vk[4].min(face.height) - vk[0].max(0.0);
                if overlap_u > tol_u && overlap_v > tol_v {
                    out[pl.face as usize].push(FaceBlend {
                        vertex: v,
                        u_knots: uk,
                        v_knots: vk,
                    });
                }
            }
        }
        out
    }
}

/// Rotation by `k` quarter turns counter-clockwise.
#[inline]
pub(crate) fn rot(k: u8, p: [f64; 2]) -> [f64; 2] {
    match k % 4 {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    }
}

/// Unit vector of quarter-turn direction `k`.
#[inline]
pub(crate) fn unit(k: u8) -> [f64; 2] {
    rot(k, [1.0, 0.0])
}

/// Knots `k + d`.
fn shift(k: &LocalKnots, d: f64) -> LocalKnots {
    k.map(|x| x + d)
}

/// Knots of `x ↦ N(c − x)`: `c − k`, reversed.
fn mirror(k: &LocalKnots, c: f64) -> LocalKnots {
    [c - k[4], c - k[3], c - k[2], c - k[1], c - k[0]]
}

/// One step of a knot line traced through the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LineStep {
    /// Along an edge (given by one of its half-edges).
    Edge(u32),
    /// Across face `face`, perpendicular to its side `side`, entering at distance `pos`
    /// (knot units) from that side's first corner.
    Cross { face: u32, side: u8, pos: f64 },
}

impl TMesh {
    /// Traces the straight knot line that leaves vertex `origin(h)` along half-edge `h`:
    /// through vertices (straight on), across faces where it meets a T-junction's stem,
    /// until `stop` returns true at a vertex it reaches, or it leaves the mesh.
    pub fn trace_line(&self, h: u32, stop: &mut dyn FnMut(u32) -> bool) -> Vec<LineStep> {
        let mut steps = vec![LineStep::Edge(h)];
        let limit = self.half_edges.len() + self.faces.len() + 4;
        let n = self.he(h).next;
        let mut state = At::Vertex {
            h_ref: n,
            theta: self.sector_quarters(n) + 2,
        };
        for _ in 0..limit {
            match state {
                At::Vertex { h_ref, theta } => {
                    if stop(self.he(h_ref).origin) {
                        break;
                    }
                    match self.look(h_ref, theta) {
                        Look::Edge(e) => {
                            steps.push(LineStep::Edge(e));
                            let n = self.he(e).next;
                            state = At::Vertex {
                                h_ref: n,
                                theta: self.sector_quarters(n) + 2,
                            };
                        }
                        Look::EdgeBack(p) => {
                            steps.push(LineStep::Edge(p));
                            state = At::Vertex { h_ref: p, theta: 2 };
                        }
                        Look::Face(f) => {
                            let e = self.he(f);
                            steps.push(LineStep::Cross {
                                face: e.face,
                                side: e.side,
                                pos: e.offset,
                            });
                            state = self.cross(e.face, e.side, e.offset).1;
                        }
                        Look::Boundary => break,
                    }
                }
                At::Side { h, pos } => {
                    let Some(t) = self.he(h).twin else { break };
                    let e = self.he(t);
                    let at = e.offset + self.he(h).knot - pos;
                    steps.push(LineStep::Cross {
                        face: e.face,
                        side: e.side,
                        pos: at,
                    });
                    state = self.cross(e.face, e.side, at).1;
                }
            }
        }
        steps
    }
}
