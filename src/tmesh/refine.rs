//! Local refinement: inserting a knot line into a T-spline without changing its surface.
//!
//! A straight knot line at parameter `c` is added across every face it crosses (in the
//! T-mesh's global parameter chart), creating vertices where it meets edges. Every old
//! blending function that the line cuts is split by knot insertion (Boehm) into two, each of
//! which must be exactly the blending function of a vertex of the refined mesh; the refined
//! control points are the sums `P'_j = Σ c_ij P_i` in homogeneous coordinates (Sederberg et
//! al. 2004; seed 003, eq. 13–20). Where a piece matches no vertex the refinement would
//! need further knots, and it is refused with an error rather than approximated.
//!
//! Owns: the global chart of a T-mesh without extraordinary points, knot-line insertion.

use super::walk::{rot, Placement};
use super::{ControlPoint, FaceLoop, Scheme, TMesh, KNOT_MATCH_REL};
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector4};
use crate::surface::basis::LocalKnots;
use std::collections::{HashMap, VecDeque};

/// Direction of an inserted knot line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KnotLine {
    /// The line `s = c` (crossing faces from bottom to top).
    S(f64),
    /// The line `t = c`.
    T(f64),
}

/// Every face placed in one parameter chart, every vertex's position and global knots.
#[derive(Debug, Clone)]
pub struct GlobalChart {
    pub faces: Vec<Placement>,
    pub vertex_pos: Vec<[f64; 2]>,
    /// Per vertex: its knot vectors along global s and t (absolute, increasing).
    pub knots: Vec<(LocalKnots, LocalKnots)>,
}

impl TMesh {
    /// The global `(s, t)` chart of a T-spline without extraordinary points whose faces fit
    /// together in one plane (no tube or torus closing on itself), with face 0 at the
    /// origin in its own frame. `None` otherwise.
    pub fn global_chart(&self) -> Option<GlobalChart> {
        self.global_chart_from(Placement {
            face: 0,
            quarter_turns: 0,
            offset: [0.0, 0.0],
        })
    }

    /// The global chart with face `start.face` placed at `start`.
    pub fn global_chart_from(&self, start: Placement) -> Option<GlobalChart> {
        let faces = self.face_placements(start)?;
        let nv = self.points.len();
        let extraordinary: Vec<bool> = (0..nv as u32).map(|v| self.is_extraordinary(v)).collect();
        if extraordinary.iter().any(|&e| e) {
            return None;
        }
        self.chart_with(faces, &extraordinary)
    }

    /// Every face placed in one parameter chart, `start.face` at `start`, walking across
    /// shared edges: `None` where the faces do not fit together in one plane (a tube, a
    /// closed surface, an extraordinary point inside the domain). Extraordinary points on
    /// the boundary, such as a hole's corners, are allowed.
    pub fn face_placements(&self, start: Placement) -> Option<Vec<Placement>> {
        let nf = self.faces.len();
        let mut placed: Vec<Option<Placement>> = vec![None; nf];
        placed[start.face as usize] = Some(start);
        let mut queue = VecDeque::from([start.face]);
        let tol = KNOT_MATCH_REL * self.knot_scale();
        while let Some(f) = queue.pop_front() {
            let pl = placed[f as usize].expect("queued faces are placed");
            for h in self.face_half_edges(f) {
                let Some(t) = self.he(h).twin else { continue };
                let g = self.he(t).face;
                let (lo, side) = self.local_frame(h);
                let knot = self.he(h).knot;
                let d = rot(side, [1.0, 0.0]);
                let r = rot(pl.quarter_turns, [lo[0] + knot * d[0], lo[1] + knot * d[1]]);
                let pos = [r[0] + pl.offset[0], r[1] + pl.offset[1]];
                let dir = (pl.quarter_turns + side + 2) % 4;
                let (lo_t, side_t) = self.local_frame(t);
                let k = (dir + 4 - side_t) % 4;
                let rt = rot(k, lo_t);
                let cand = Placement {
                    face: g,
                    quarter_turns: k,
                    offset: [pos[0] - rt[0], pos[1] - rt[1]],
                };
                match placed[g as usize] {
                    Some(p) => {
                        if p.quarter_turns != k
                            || (p.offset[0] - cand.offset[0]).abs() > tol
                            || (p.offset[1] - cand.offset[1]).abs() > tol
                        {
                            return None;
                        }
                    }
                    None => {
                        placed[g as usize] = Some(cand);
                        queue.push_back(g);
                    }
                }
            }
        }
        placed.into_iter().collect()
    }

    /// The chart from placed faces.
    fn chart_with(&self, faces: Vec<Placement>, extraordinary: &[bool]) -> Option<GlobalChart> {
        let nv = self.points.len();
        let mut vertex_pos = vec![[0.0; 2]; nv];
        let mut knots = Vec::with_capacity(nv);
        for v in 0..nv as u32 {
            let h = self.vertex_edge[v as usize];
            let pl = faces[self.he(h).face as usize];
            let (lo, side) = self.local_frame(h);
            let r = rot(pl.quarter_turns, lo);
            let p = [r[0] + pl.offset[0], r[1] + pl.offset[1]];
            vertex_pos[v as usize] = p;
            let (ks, kt) = self.local_knots(v, extraordinary);
            // The vertex frame's s runs along its reference half-edge, t a quarter turn on.
            let abs = |k: &LocalKnots, base: f64, sign: f64| -> LocalKnots {
                let mut a = k.map(|x| base + sign * x);
                if sign < 0.0 {
                    a.reverse();
                }
                a
            };
            knots.push(match (pl.quarter_turns + side) % 4 {
                0 => (abs(&ks, p[0], 1.0), abs(&kt, p[1], 1.0)),
                1 => (abs(&kt, p[0], -1.0), abs(&ks, p[1], 1.0)),
                2 => (abs(&ks, p[0], -1.0), abs(&kt, p[1], -1.0)),
                _ => (abs(&kt, p[0], 1.0), abs(&ks, p[1], -1.0)),
            });
        }
        Some(GlobalChart {
            faces,
            vertex_pos,
            knots,
        })
    }

    /// Largest face side in knot units (at least 1): the scale knot tolerances refer to.
    fn knot_scale(&self) -> f64 {
        self.faces
            .iter()
            .map(|f| f.width.max(f.height))
            .fold(1.0, f64::max)
    }

    /// Inserts the knot line `line` across every face it crosses. Returns the refined mesh,
    /// whose surface is the same as this one's; old vertices keep their ids, new ones follow.
    pub fn insert_knot_line(&self, line: KnotLine) -> Result<TMesh> {
        if self.scheme != Scheme::TSpline {
            return Err(Error::Unsupported(
                "knot insertion works on T-spline meshes".into(),
            ));
        }
        let chart = self.global_chart().ok_or_else(|| {
            Error::Unsupported(
                "knot insertion needs a T-spline without extraordinary points that lies flat in one parameter chart"
                    .into(),
            )
        })?;
        // Work as if inserting s = c; for t = c swap the chart's axes.
        let (c, swap) = match line {
            KnotLine::S(c) => (c, false),
            KnotLine::T(c) => (c, true),
        };
        let sw = |p: [f64; 2]| if swap { [p[1], p[0]] } else { p };
        let tol = KNOT_MATCH_REL * self.knot_scale();
        if !c.is_finite() {
            return Err(Error::param("knot", format!("{c} is not a number")));
        }
        if chart
            .vertex_pos
            .iter()
            .any(|p| (sw(*p)[0] - c).abs() <= tol)
        {
            return Err(Error::param(
                "knot",
                format!("{c} is already a knot line; refinement inserts new ones"),
            ));
        }
        let mut positions: Vec<[f64; 2]> = chart.vertex_pos.iter().map(|p| sw(*p)).collect();
        // One new vertex on every edge the line crosses.
        let mut points: Vec<ControlPoint> = self.points.clone();
        let mut split: HashMap<(u32, u32), u32> = HashMap::new();
        let mut knots: HashMap<(u32, u32), f64> = HashMap::new();
        for h in &self.half_edges {
            let (a, b) = (h.origin, self.he(h.next).origin);
            let k = (a.min(b), a.max(b));
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            let crosses = (pa[1] - pb[1]).abs() <= tol
                && pa[0].min(pb[0]) + tol < c
                && c < pa[0].max(pb[0]) - tol;
            if !crosses {
                knots.insert(k, h.knot);
                continue;
            }
            if let std::collections::hash_map::Entry::Vacant(e) = split.entry(k) {
                let v = points.len() as u32;
                points.push(self.points[a as usize]);
                positions.push([c, pa[1]]);
                e.insert(v);
                knots.insert((a.min(v), a.max(v)), (c - pa[0]).abs());
                knots.insert((b.min(v), b.max(v)), (pb[0] - c).abs());
            }
        }
        // Split the faces the line crosses; unsplit faces keep their index.
        let loops = self.face_loops();
        let mut out: Vec<FaceLoop> = Vec::with_capacity(loops.len() + split.len());
        let mut extra: Vec<FaceLoop> = Vec::new();
        let mut first_unsplit = None;
        for (f, fl) in loops.iter().enumerate() {
            let n = fl.vertices.len();
            let mut verts = Vec::with_capacity(n + 2);
            let mut corner = Vec::with_capacity(n + 2);
            let mut cuts = Vec::new();
            for k in 0..n {
                let (a, b) = (fl.vertices[k], fl.vertices[(k + 1) % n]);
                verts.push(a);
                corner.push(fl.corners.contains(&(k as u32)));
                if let Some(&v) = split.get(&(a.min(b), a.max(b))) {
                    cuts.push(verts.len());
                    verts.push(v);
                    corner.push(true);
                }
            }
            match cuts.len() {
                0 => {
                    first_unsplit.get_or_insert(f);
                    out.push(fl.clone());
                }
                2 => {
                    let (i, j) = (cuts[0], cuts[1]);
                    let (x, y) = (verts[i], verts[j]);
                    let (pa, pb) = (positions[x as usize], positions[y as usize]);
                    knots.insert((x.min(y), x.max(y)), (pb[1] - pa[1]).abs());
                    let m = verts.len();
                    let part = |from: usize, to: usize| -> Result<FaceLoop> {
                        let mut vs = Vec::new();
                        let mut cs = Vec::new();
                        let mut k = from;
                        loop {
                            if corner[k] {
                                cs.push(vs.len() as u32);
                            }
                            vs.push(verts[k]);
                            if k == to {
                                break;
                            }
                            k = (k + 1) % m;
                        }
                        let corners: [u32; 4] = cs.try_into().map_err(|cs: Vec<u32>| {
                            Error::Unsupported(format!(
                                "face {f}: the knot line crosses it so that a part has {} corners",
                                cs.len()
                            ))
                        })?;
                        Ok(FaceLoop { vertices: vs, corners })
                    };
                    out.push(part(i, j)?);
                    extra.push(part(j, i)?);
                }
                k => {
                    return Err(Error::Unsupported(format!(
                        "face {f} is crossed by the knot line {k} times; only straight crossings are supported"
                    )))
                }
            }
        }
        if split.is_empty() {
            return Err(Error::param(
                "knot",
                format!("the line at {c} crosses no face"),
            ));
        }
        let start = first_unsplit.ok_or_else(|| {
            Error::Unsupported(
                "the knot line crosses every face; nothing anchors the refined chart".into(),
            )
        })?;
        out.extend(extra);
        let refined = TMesh::try_new(points.clone(), &out, &knots, 1.0, Scheme::TSpline)?;
        let chart2 = refined
            .global_chart_from(chart.faces[start])
            .ok_or_else(|| {
                Error::Unsupported("the refined mesh does not lie flat in one chart".into())
            })?;
        // Knots of every refined vertex, as (along the insertion, across it).
        let sk = |k: &(LocalKnots, LocalKnots)| if swap { (k.1, k.0) } else { (k.0, k.1) };
        let same =
            |a: &LocalKnots, b: &LocalKnots| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol);
        let mut index: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        let cell = |x: f64| (x / (1e3 * tol)).round() as i64;
        for (j, k) in chart2.knots.iter().enumerate() {
            let (a, b) = sk(k);
            index
                .entry((cell(a[2]), cell(b[2])))
                .or_default()
                .push(j as u32);
        }
        let find = |a: &LocalKnots, b: &LocalKnots| -> Option<u32> {
            let (ca, cb) = (cell(a[2]), cell(b[2]));
            for da in -1..=1 {
                for db in -1..=1 {
                    if let Some(list) = index.get(&(ca + da, cb + db)) {
                        for &j in list {
                            let (x, y) = sk(&chart2.knots[j as usize]);
                            if same(&x, a) && same(&y, b) {
                                return Some(j);
                            }
                        }
                    }
                }
            }
            None
        };
        let mut acc = vec![Vector4::zeros(); points.len()];
        let mut hit = vec![false; points.len()];
        for (i, k) in chart.knots.iter().enumerate() {
            let (a, b) = sk(k);
            let h = self.points[i].homogeneous();
            for (piece, coef) in split_function(&a, c, tol) {
                let j = find(&piece, &b).ok_or_else(|| {
                    Error::Unsupported(format!(
                        "inserting the knot line at {c} would split vertex {i}'s blending function into one no vertex of the refined mesh has (T-junctions nearby need more knots); choose another line"
                    ))
                })?;
                acc[j as usize] += h * coef;
                hit[j as usize] = true;
            }
        }
        if let Some(j) = hit.iter().position(|h| !h) {
            return Err(Error::Unsupported(format!(
                "inserting the knot line at {c} leaves refined vertex {j} without a control point; choose another line"
            )));
        }
        let points: Vec<ControlPoint> = acc
            .iter()
            .map(|h| ControlPoint {
                point: Point3::new(h.x / h.w, h.y / h.w, h.z / h.w),
                weight: h.w,
            })
            .collect();
        TMesh::try_new(points, &out, &knots, 1.0, Scheme::TSpline)
    }
}

/// The blending function `N[a]` with knot `c` inserted (Boehm), as one or two functions and
/// their coefficients; unchanged if `c` is outside its support.
fn split_function(a: &LocalKnots, c: f64, tol: f64) -> Vec<(LocalKnots, f64)> {
    if !(a[0] + tol < c && c < a[4] - tol) {
        return vec![(*a, 1.0)];
    }
    let mut six = [a[0], a[1], a[2], a[3], a[4], c];
    crate::sort::sort_floats(&mut six);
    let first = [six[0], six[1], six[2], six[3], six[4]];
    let last = [six[1], six[2], six[3], six[4], six[5]];
    let alpha = if a[3] > a[0] {
        ((c - a[0]) / (a[3] - a[0])).min(1.0)
    } else {
        1.0
    };
    let beta = if a[4] > a[1] {
        ((a[4] - c) / (a[4] - a[1])).min(1.0)
    } else {
        1.0
    };
    let mut out = Vec::new();
    if alpha > 0.0 {
        out.push((first, alpha));
    }
    if beta > 0.0 {
        out.push((last, beta));
    }
    out
}
