//! Watertight triangle meshes of the surface within a chordal tolerance, for display and
//! export, with the patch of every triangle.
//!
//! Every mesh edge is sampled once, by a count that depends only on the edge, and the two
//! faces beside it share those vertices; each face fills its inside with a grid fine enough
//! for its own curvature and stitches the grid to its boundary samples with a strip. So no
//! cracks open where faces of different sizes or T-junctions meet.

use super::{on_side, FaceSurface, Surface};
use crate::geom::{Point3, Vector3};
use crate::layout::PatchLayout;
use crate::tmesh::TMesh;
use std::collections::HashMap;

/// Flat arrays ready for a GPU or an STL writer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tessellation {
    /// `x y z` per vertex (mm).
    pub positions: Vec<f32>,
    /// Unit normal per vertex.
    pub normals: Vec<f32>,
    /// Three vertex indices per triangle, counter-clockwise seen from the normal side.
    pub indices: Vec<u32>,
    /// Patch of each triangle (index into the layout).
    pub patch_ids: Vec<u32>,
    /// Domain face and `(u, v)` of each vertex, for tests and heat maps.
    pub params: Vec<(u32, f64, f64)>,
}

/// Fewest grid cells across a face each way (so its inner ring is a rectangle).
const MIN_GRID: usize = 3;
/// Most segments along one edge or across one face.
const MAX_SEGMENTS: usize = 256;
/// Iso-parameter lines of a face sampled to size its grid.
const ISO_LINES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// Samples per curve used to estimate its length and curvature.
const PROBE: usize = 9;
/// The sagitta formula is exact for circles; grids also twist, so segments are made this
/// much shorter than it allows (dimensionless).
const SAFETY: f64 = 0.7;

/// Segments needed along the curve `c(t)`, `t ∈ [0,1]`, for chordal tolerance `tol`:
/// uniform in `t`, so sized for the fastest and most curved part of the curve.
fn segments(c: &dyn Fn(f64) -> (Point3, Vector3, Vector3), tol: f64) -> usize {
    let mut speed: f64 = 0.0;
    let mut kmax: f64 = 0.0;
    for i in 0..PROBE {
        let (_, d1, d2) = c(i as f64 / (PROBE - 1) as f64);
        let s = d1.norm();
        speed = speed.max(s);
        if s > 0.0 {
            kmax = kmax.max(d1.cross(&d2).norm() / (s * s * s));
        }
    }
    let seg = if kmax > 0.0 {
        SAFETY * (8.0 * tol / kmax).sqrt()
    } else {
        f64::INFINITY
    };
    ((speed / seg).ceil() as usize).clamp(1, MAX_SEGMENTS)
}

/// Rounds of measuring and refining a face's grid.
const GRID_ROUNDS: usize = 4;

/// Largest distance, along the normal, between a cell's centre on the surface and the
/// average of its corners, over the grid of a face with lines at `us` × `vs`.
fn grid_deviation(face: &FaceSurface, us: &[f64], vs: &[f64]) -> f64 {
    let rows: Vec<Vec<Vector3>> = vs
        .iter()
        .map(|&v| us.iter().map(|&u| face.subs(u, v).coords).collect())
        .collect();
    let mut worst: f64 = 0.0;
    for j in 0..vs.len() - 1 {
        for i in 0..us.len() - 1 {
            let (u, v) = (0.5 * (us[i] + us[i + 1]), 0.5 * (vs[j] + vs[j + 1]));
            let c = face.subs(u, v).coords;
            let avg = (rows[j][i] + rows[j][i + 1] + rows[j + 1][i] + rows[j + 1][i + 1]) * 0.25;
            let n = face.normal(u, v).unwrap_or_else(Vector3::z);
            worst = worst.max((c - avg).dot(&n).abs());
        }
    }
    worst
}

/// Spacing of samples along a face's side or an edge, denser towards an end at an
/// extraordinary point: near one of valence `n` a parameter step `t` spans about `t^α` of
/// the surface (`α = −log2 λ`, `λ` the subdominant eigenvalue of Catmull–Clark subdivision),
/// so samples at `t = σ^(1/α)` are about evenly spaced there. `lo` and `hi` are the exponents
/// at the two ends (1: even).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Grading {
    lo: f64,
    hi: f64,
}

impl Grading {
    const EVEN: Grading = Grading { lo: 1.0, hi: 1.0 };

    /// Parameter at fraction `σ` of the samples, and its derivative.
    fn at(&self, sigma: f64) -> (f64, f64) {
        if *self == Grading::EVEN {
            return (sigma, 1.0);
        }
        if sigma <= 0.5 {
            let x = 2.0 * sigma;
            (0.5 * x.powf(self.lo), self.lo * x.powf(self.lo - 1.0))
        } else {
            let x = 2.0 * (1.0 - sigma);
            (1.0 - 0.5 * x.powf(self.hi), self.hi * x.powf(self.hi - 1.0))
        }
    }

    /// Lines at `n` graded steps from 0 to 1.
    fn lines(&self, n: usize) -> Vec<f64> {
        (0..=n).map(|i| self.at(i as f64 / n as f64).0).collect()
    }
}

/// Grading exponent at vertex `v` of `mesh` for faces evaluated by subdivision: `1/α` for
/// an extraordinary point whose parameter steps shrink on the surface (`α < 1`), else 1. A
/// boundary vertex counts as the interior one of twice its faces (its mirror image).
fn grading_exponent(mesh: &TMesh, v: u32) -> f64 {
    if !mesh.is_extraordinary(v) {
        return 1.0;
    }
    let faces = mesh.outgoing(v).len();
    let n = if mesh.is_boundary_vertex(v) {
        2 * faces
    } else {
        faces
    } as f64;
    let c = (std::f64::consts::TAU / n).cos();
    let lambda = (5.0 + c + (std::f64::consts::PI / n).cos() * (2.0 * (9.0 + c)).sqrt()) / 16.0;
    let alpha = -lambda.log2();
    (1.0 / alpha).clamp(1.0, MAX_GRADING)
}

/// Largest grading exponent (valence 4 096 and beyond).
const MAX_GRADING: f64 = 2.0;

/// Curve along face side at fixed `v` (u from 0 to 1) or fixed `u`, with its parameter
/// graded by `g` (its derivatives scaled to match; the `g''` term is along the tangent and
/// changes neither the curvature nor the speed that [`segments`] reads).
fn iso(
    face: &FaceSurface,
    along_u: bool,
    w: f64,
    g: Grading,
) -> impl Fn(f64) -> (Point3, Vector3, Vector3) + '_ {
    move |sigma| {
        let (t, dt) = g.at(sigma);
        let d = if along_u {
            face.derivs(t, w)
        } else {
            face.derivs(w, t)
        };
        if along_u {
            (d.point, d.su * dt, d.suu * (dt * dt))
        } else {
            (d.point, d.sv * dt, d.svv * (dt * dt))
        }
    }
}

/// Tessellates every domain face, watertight across faces, each edge of a triangle
/// deviating from the surface by about `chordal_mm` or less.
pub fn tessellate(
    mesh: &TMesh,
    surface: &Surface,
    layout: &PatchLayout,
    chordal_mm: f64,
) -> Tessellation {
    let faces = surface.faces();
    let domain: HashMap<u32, usize> = faces
        .iter()
        .enumerate()
        .map(|(i, f)| (f.mesh_face, i))
        .collect();
    // Coincident vertices (ends of zero-length edges) share one id.
    let nv = mesh.vertex_count();
    let mut rep: Vec<u32> = (0..nv as u32).collect();
    fn root(rep: &mut [u32], mut x: u32) -> u32 {
        while rep[x as usize] != x {
            rep[x as usize] = rep[rep[x as usize] as usize];
            x = rep[x as usize];
        }
        x
    }
    for h in mesh.half_edges() {
        if h.knot == 0.0 {
            let (a, b) = (
                root(&mut rep, h.origin),
                root(&mut rep, mesh.he(h.next).origin),
            );
            rep[a.max(b) as usize] = a.min(b);
        }
    }
    // Each vertex's grading exponent, and each face's grading across u and v: denser
    // towards corners at extraordinary points of subdivided faces.
    let exponent: Vec<f64> = (0..mesh.vertex_count() as u32)
        .map(|v| grading_exponent(mesh, v))
        .collect();
    let grading: Vec<[Grading; 2]> = faces
        .iter()
        .map(|face| {
            if !matches!(face.form, super::FaceForm::Tree(_)) {
                return [Grading::EVEN; 2];
            }
            // Corner at the start of each side: (0,0), (1,0), (1,1), (0,1).
            let mut corner = [1.0f64; 4];
            for h in mesh.face_half_edges(face.mesh_face) {
                let e = mesh.he(h);
                if e.offset == 0.0 && mesh.sector_quarters(h) == 1 {
                    corner[e.side as usize % 4] = exponent[e.origin as usize];
                }
            }
            [
                Grading {
                    lo: corner[0].max(corner[3]),
                    hi: corner[1].max(corner[2]),
                },
                Grading {
                    lo: corner[0].max(corner[1]),
                    hi: corner[3].max(corner[2]),
                },
            ]
        })
        .collect();
    // Grid cells each face needs across u and v for its own curvature.
    let grid: Vec<(usize, usize)> = faces
        .iter()
        .zip(&grading)
        .map(|(face, &[gu, gv])| {
            let most = |along_u: bool| {
                let (g, across) = if along_u { (gu, gv) } else { (gv, gu) };
                ISO_LINES
                    .iter()
                    .map(|&w| segments(&iso(face, along_u, across.at(w).0, g), chordal_mm))
                    .max()
                    .unwrap_or(1)
            };
            let (mut nu, mut nv) = (most(true), most(false));
            // A twisted cell bends away from its flat triangles by about |S_uv·n|·Δu·Δv/4
            // (in the graded parameters).
            let mut twist: f64 = 0.0;
            for &a in &ISO_LINES {
                for &b in &ISO_LINES {
                    let ((u, du), (v, dv)) = (gu.at(a), gv.at(b));
                    let d = face.derivs(u, v);
                    let n = d.su.cross(&d.sv);
                    if n.norm() > 0.0 {
                        twist = twist.max(d.suv.dot(&n).abs() * du * dv / n.norm());
                    }
                }
            }
            let need = twist / (4.0 * SAFETY * SAFETY * chordal_mm);
            if (nu * nv) as f64 <= need {
                let f = (need / (nu * nv) as f64).sqrt();
                nu = ((nu as f64 * f).ceil() as usize).min(MAX_SEGMENTS);
                nv = ((nv as f64 * f).ceil() as usize).min(MAX_SEGMENTS);
            }
            let (mut nu, mut nv) = (nu.max(MIN_GRID), nv.max(MIN_GRID));
            // Measure: the cells' centres against their corners' average, and refine where
            // the estimate fell short (near extraordinary points the parameterisation bends).
            for _ in 0..GRID_ROUNDS {
                let dev = grid_deviation(face, &gu.lines(nu), &gv.lines(nv));
                if dev <= SAFETY * chordal_mm || (nu >= MAX_SEGMENTS && nv >= MAX_SEGMENTS) {
                    break;
                }
                let f = (dev / (SAFETY * chordal_mm)).sqrt() * 1.1;
                nu = ((nu as f64 * f).ceil() as usize).min(MAX_SEGMENTS);
                nv = ((nv as f64 * f).ceil() as usize).min(MAX_SEGMENTS);
            }
            (nu, nv)
        })
        .collect();
    // An edge is graded towards its ends at extraordinary points, from its start; both faces
    // beside it sample it alike (the grading seen from the other end is reversed).
    let tree_face = |f: u32| {
        domain
            .get(&f)
            .is_some_and(|&d| matches!(faces[d].form, super::FaceForm::Tree(_)))
    };
    let edge_grading = |h: &crate::tmesh::HalfEdge| {
        if !tree_face(h.face) {
            return Grading::EVEN;
        }
        Grading {
            lo: exponent[h.origin as usize],
            hi: exponent[mesh.he(h.next).origin as usize],
        }
    };
    // Segment count per undirected edge: enough for the edge's own curve and for the grids
    // of both faces beside it, so the strips between boundary and grid stay short.
    let mut edge_segments: HashMap<(u32, u32), usize> = HashMap::new();
    for (hi, h) in mesh.half_edges().iter().enumerate() {
        if h.knot == 0.0 {
            continue;
        }
        if let Some(t) = h.twin {
            if t < hi as u32 && domain.contains_key(&mesh.he(t).face) {
                continue;
            }
        }
        let Some(&d) = domain.get(&h.face) else {
            continue;
        };
        let f = &mesh.faces()[h.face as usize];
        let len = if h.side % 2 == 0 { f.width } else { f.height };
        let (a, b) = (h.offset / len, (h.offset + h.knot) / len);
        let face = &faces[d];
        let g = edge_grading(h);
        let curve = |sigma: f64| {
            let (t, dt) = g.at(sigma);
            let s = a + (b - a) * t;
            let (u, v) = on_side(h.side, s);
            let dd = face.derivs(u, v);
            let (d1, d2) = if h.side % 2 == 0 {
                (dd.su, dd.suu)
            } else {
                (dd.sv, dd.svv)
            };
            // Sides 2 and 3 run against u and v: the same curve, its speed's sign aside.
            let step = (b - a) * dt;
            (dd.point, d1 * step, d2 * (step * step))
        };
        let mut n = segments(&curve, chordal_mm);
        for half in std::iter::once(h).chain(h.twin.map(|t| mesh.he(t))) {
            if let Some(&df) = domain.get(&half.face) {
                let mf = &mesh.faces()[half.face as usize];
                let (cells, len) = if half.side % 2 == 0 {
                    (grid[df].0, mf.width)
                } else {
                    (grid[df].1, mf.height)
                };
                n = n.max((cells as f64 * half.knot / len).ceil() as usize);
            }
        }
        let key = edge_key(h.origin, mesh.he(h.next).origin);
        edge_segments.insert(key, n.min(MAX_SEGMENTS));
    }
    // Patch of each face region: the pieces of the layout.
    let mut pieces: Vec<Vec<(u32, [f64; 4])>> = vec![Vec::new(); faces.len()];
    for (pi, p) in layout.patches.iter().enumerate() {
        for piece in &p.pieces {
            pieces[piece.face as usize].push((pi as u32, piece.local));
        }
    }
    let mut t = Tessellation::default();
    let mut shared: HashMap<(u32, u32, usize), u32> = HashMap::new();
    let mut corner: HashMap<u32, u32> = HashMap::new();
    for (d, face) in faces.iter().enumerate() {
        let mf = face.mesh_face;
        // Boundary loop: (u, v) and shared-vertex key.
        let mut outer: Vec<(f64, f64, Option<VKey>)> = Vec::new();
        let mut outer_tau: Vec<f64> = Vec::new();
        for h in mesh.face_half_edges(mf) {
            let e = mesh.he(h);
            if e.knot == 0.0 {
                continue;
            }
            let (a, b) = (e.origin, mesh.he(e.next).origin);
            let len = if e.side % 2 == 0 {
                face.width
            } else {
                face.height
            };
            let n = edge_segments[&edge_key(a, b)];
            let g = edge_grading(e);
            for k in 0..n {
                let s = (e.offset + e.knot * g.at(k as f64 / n as f64).0) / len;
                let (u, v) = on_side(e.side, s);
                let key = if k == 0 {
                    VKey::Vertex(root(&mut rep, a))
                } else {
                    // Edge samples are numbered from the edge's lower vertex id.
                    VKey::Edge(a.min(b), a.max(b), if a < b { k } else { n - k })
                };
                outer.push((u, v, Some(key)));
                outer_tau.push(e.side as f64 + s);
            }
        }
        // Inner grid, with lines at the face's patch-piece borders.
        let (nu, nv_) = grid[d];
        let mut us: Vec<f64> = grading[d][0].lines(nu);
        let mut vs: Vec<f64> = grading[d][1].lines(nv_);
        for &(_, r) in &pieces[d] {
            us.extend([r[0] / face.width, r[1] / face.width]);
            vs.extend([r[2] / face.height, r[3] / face.height]);
        }
        for g in [&mut us, &mut vs] {
            crate::sort::sort_floats(g);
            g.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        }
        let (gu, gv) = (us.len() - 1, vs.len() - 1);
        let mut add = |u: f64, v: f64, key: Option<VKey>, t: &mut Tessellation| -> u32 {
            let lookup = match key {
                Some(VKey::Vertex(v)) => corner.get(&v).copied(),
                Some(VKey::Edge(a, b, k)) => shared.get(&(a, b, k)).copied(),
                None => None,
            };
            if let Some(i) = lookup {
                return i;
            }
            let p = face.subs(u, v);
            let n = face.normal(u, v).unwrap_or_else(Vector3::z);
            let idx = (t.positions.len() / 3) as u32;
            t.positions.extend([p.x as f32, p.y as f32, p.z as f32]);
            t.normals.extend([n.x as f32, n.y as f32, n.z as f32]);
            t.params.push((d as u32, u, v));
            match key {
                Some(VKey::Vertex(v)) => {
                    corner.insert(v, idx);
                }
                Some(VKey::Edge(a, b, k)) => {
                    shared.insert((a, b, k), idx);
                }
                None => {}
            }
            idx
        };
        let outer_idx: Vec<u32> = outer
            .iter()
            .map(|&(u, v, k)| add(u, v, k, &mut t))
            .collect();
        let outer_uv: Vec<(f64, f64)> = outer.iter().map(|&(u, v, _)| (u, v)).collect();
        // Inner lattice (i, j) in 1..gu × 1..gv.
        let mut inner = vec![0u32; (gu + 1) * (gv + 1)];
        for j in 1..gv {
            for i in 1..gu {
                inner[j * (gu + 1) + i] = add(us[i], vs[j], None, &mut t);
            }
        }
        let patch_at = |u: f64, v: f64| -> u32 {
            let (x, y) = (u * face.width, v * face.height);
            pieces[d]
                .iter()
                .find(|(_, r)| x >= r[0] && x <= r[1] && y >= r[2] && y <= r[3])
                .map(|p| p.0)
                .unwrap_or(0)
        };
        let tri = |a: u32, b: u32, c: u32, uv: [(f64, f64); 3], t: &mut Tessellation| {
            if a == b || b == c || a == c {
                return;
            }
            t.indices.extend([a, b, c]);
            let cu = (uv[0].0 + uv[1].0 + uv[2].0) / 3.0;
            let cv = (uv[0].1 + uv[1].1 + uv[2].1) / 3.0;
            t.patch_ids.push(patch_at(cu, cv));
        };
        for j in 1..gv.saturating_sub(1) {
            for i in 1..gu.saturating_sub(1) {
                let id = |i: usize, j: usize| inner[j * (gu + 1) + i];
                let uv = |i: usize, j: usize| (us[i], vs[j]);
                tri(
                    id(i, j),
                    id(i + 1, j),
                    id(i + 1, j + 1),
                    [uv(i, j), uv(i + 1, j), uv(i + 1, j + 1)],
                    &mut t,
                );
                tri(
                    id(i, j),
                    id(i + 1, j + 1),
                    id(i, j + 1),
                    [uv(i, j), uv(i + 1, j + 1), uv(i, j + 1)],
                    &mut t,
                );
            }
        }
        // Inner ring, counter-clockwise from its lower-left corner (the grid has at least
        // three cells each way, so the ring is a proper rectangle), with its position around
        // the face measured like the boundary's: side number plus the coordinate along it.
        let mut ring: Vec<(usize, usize, f64)> = Vec::new();
        ring.extend((1..gu).map(|i| (i, 1, us[i])));
        ring.extend((2..gv).map(|j| (gu - 1, j, 1.0 + vs[j])));
        ring.extend((1..gu - 1).rev().map(|i| (i, gv - 1, 3.0 - us[i])));
        ring.extend((2..gv - 1).rev().map(|j| (1, j, 4.0 - vs[j])));
        let ring_idx: Vec<u32> = ring
            .iter()
            .map(|&(i, j, _)| inner[j * (gu + 1) + i])
            .collect();
        let ring_uv: Vec<(f64, f64)> = ring.iter().map(|&(i, j, _)| (us[i], vs[j])).collect();
        let ring_tau: Vec<f64> = ring.iter().map(|r| r.2).collect();
        let centre = face.derivs(0.5, 0.5);
        let (su, sv) = (centre.su.norm(), centre.sv.norm());
        let metric = |a: (f64, f64), b: (f64, f64)| ((a.0 - b.0) * su).hypot((a.1 - b.1) * sv);
        zip(
            (&outer_idx, &outer_uv, &outer_tau),
            (&ring_idx, &ring_uv, &ring_tau),
            &metric,
            &mut |a, b, c, uv| tri(a, b, c, uv, &mut t),
        );
    }
    t
}

/// Key of a vertex shared between faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum VKey {
    Vertex(u32),
    Edge(u32, u32, usize),
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// How far (in sides of the rectangles) one loop may run ahead of the other before the
/// zipper must advance the one behind, whatever the edge lengths say.
const STEP_SLACK: f64 = 1e-9;

/// A closed loop: vertex ids, parameters, and positions around its rectangle (0..4,
/// increasing, starting at the lower-left corner).
type Loop<'a> = (&'a [u32], &'a [(f64, f64)], &'a [f64]);

/// Triangulates the band between a closed outer loop and a closed inner loop, both
/// counter-clockwise, by walking both in step around the square.
fn zip(
    outer: Loop,
    inner: Loop,
    metric: &dyn Fn((f64, f64), (f64, f64)) -> f64,
    tri: &mut dyn FnMut(u32, u32, u32, [(f64, f64); 3]),
) {
    let (oi, ouv, ot) = outer;
    let (ii, iuv, it) = inner;
    let (no, ni) = (oi.len(), ii.len());
    if no == 0 || ni == 0 {
        return;
    }
    let pos = |t: &[f64], k: usize| if k >= t.len() { 4.0 } else { t[k] };
    let (mut i, mut j) = (0usize, 0usize);
    while i < no || j < ni {
        let (o0, n0) = (i % no, j % ni);
        let (o1, n1) = ((i + 1) % no, (j + 1) % ni);
        let advance_outer = if i == no {
            false
        } else if j == ni {
            true
        } else {
            // Both loops stay roughly in step around their rectangles; between the two
            // possible triangles take the one with the shorter new edge.
            let (to, ti) = (pos(ot, i + 1), pos(it, j + 1));
            if (to - ti).abs() > STEP_SLACK {
                to < ti
            } else {
                metric(ouv[o1], iuv[n0]) <= metric(ouv[o0], iuv[n1])
            }
        };
        if advance_outer {
            tri(oi[o0], oi[o1], ii[n0], [ouv[o0], ouv[o1], iuv[n0]]);
            i += 1;
        } else {
            tri(oi[o0], ii[n1], ii[n0], [ouv[o0], iuv[n1], iuv[n0]]);
            j += 1;
        }
    }
}
