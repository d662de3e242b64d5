//! Nearest points on the surface to a ball centre: per face a box and a few samples to start
//! from, then Newton steps on the squared distance across the face's Bézier cells.
//!
//! Owns the search only; must not decide what a distance means for the tool.

use crate::geom::{Aabb, Point3};
use crate::surface::Surface;

/// Samples per face side for the nearest-point start.
const START_SAMPLES: usize = 6;
/// Samples of a face Newton starts from (the nearest ones).
const NEAREST_STARTS: usize = 3;
/// Newton steps of the nearest-point search on one face.
const NEWTON_STEPS: usize = 30;
/// Parameter step (of a face's unit square) below which the search has converged.
const NEWTON_CONVERGED: f64 = 1e-12;
/// Most steps from one Bézier cell of a face into the next during one descent, besides
/// the Newton steps.
const MAX_CELL_CROSSINGS: usize = 16;

/// Nearest-point queries against the surface: per face its box (from the Bézier control
/// points, which contain it) and a few samples to start Newton from.
pub(super) struct Nearest<'a> {
    surface: &'a Surface,
    boxes: Vec<Aabb>,
    starts: Vec<Vec<(f64, f64, Point3)>>,
    /// The faces whose box meets each cell of a uniform grid (cells of `cell` mm).
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
    cell: f64,
}

/// Most grid cells one face's box may be listed in; larger boxes make the cells coarser.
const CELLS_PER_FACE: f64 = 64.0;

impl<'a> Nearest<'a> {
    pub(super) fn new(surface: &'a Surface) -> Self {
        let n = surface.faces().len();
        let mut boxes = Vec::with_capacity(n);
        let mut starts = Vec::with_capacity(n);
        for (f, face) in surface.faces().iter().enumerate() {
            let mut b = Aabb::empty();
            face.for_each_cell(&mut |_, cell| {
                for c in cell.cp.iter().flatten() {
                    if c.w > 0.0 {
                        b.grow(&Point3::new(c.x / c.w, c.y / c.w, c.z / c.w));
                    }
                }
            });
            let mut s = Vec::with_capacity((START_SAMPLES + 1) * (START_SAMPLES + 1));
            for i in 0..=START_SAMPLES {
                for j in 0..=START_SAMPLES {
                    let (u, v) = (
                        i as f64 / START_SAMPLES as f64,
                        j as f64 / START_SAMPLES as f64,
                    );
                    let p = surface.subs(f, u, v);
                    b.grow(&p);
                    s.push((u, v, p));
                }
            }
            boxes.push(b);
            starts.push(s);
        }
        // Cells about the size of a face's box, coarser if some boxes would span too many.
        let sizes: Vec<f64> = boxes
            .iter()
            .map(|b| (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0, f64::max))
            .collect();
        let mean = sizes.iter().sum::<f64>() / sizes.len().max(1) as f64;
        let largest = sizes.iter().fold(0.0f64, |a, &b| a.max(b));
        let cell = mean
            .max(largest / CELLS_PER_FACE.cbrt())
            .max(f64::MIN_POSITIVE);
        let mut cells: std::collections::HashMap<[i64; 3], Vec<u32>> = Default::default();
        for (f, b) in boxes.iter().enumerate() {
            let (lo, hi) = (cell_of(&b.min, cell), cell_of(&b.max, cell));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        cells.entry([x, y, z]).or_default().push(f as u32);
                    }
                }
            }
        }
        Nearest {
            surface,
            boxes,
            starts,
            cells,
            cell,
        }
    }

    /// Faces whose box comes within `reach` of `c`, in order.
    pub(super) fn faces_near(&self, c: &Point3, reach: f64) -> Vec<u32> {
        let lo = cell_of(&[c.x - reach, c.y - reach, c.z - reach], self.cell);
        let hi = cell_of(&[c.x + reach, c.y + reach, c.z + reach], self.cell);
        let mut faces: Vec<u32> = Vec::new();
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    if let Some(fs) = self.cells.get(&[x, y, z]) {
                        faces.extend_from_slice(fs);
                    }
                }
            }
        }
        faces.sort_unstable();
        faces.dedup();
        faces.retain(|&f| {
            let b = &self.boxes[f as usize];
            let out = (0..3)
                .map(|k| (b.min[k] - c[k]).max(c[k] - b.max[k]).max(0.0))
                .fold(0.0f64, |a, x| a.hypot(x));
            out <= reach
        });
        faces
    }

    /// The start sample of face `f` nearest `c`: its parameters.
    pub(super) fn nearest_start(&self, f: usize, c: &Point3) -> (f64, f64) {
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for &(u, v, p) in &self.starts[f] {
            let d = (p - c).norm_squared();
            if d < best.0 {
                best = (d, u, v);
            }
        }
        (best.1, best.2)
    }

    /// Nearest point to `c` on faces whose box comes within `reach` of it, and its distance.
    pub(super) fn nearest(&self, c: &Point3, reach: f64) -> Option<(f64, Point3)> {
        let mut best: Option<(f64, Point3)> = None;
        for f in self.faces_near(c, reach) {
            let f = f as usize;
            // Newton from the nearest few samples: on a tightly folded face the nearest
            // sample may lie on the wrong side of the fold.
            let mut starts = [(f64::INFINITY, 0.0, 0.0); NEAREST_STARTS];
            for &(u, v, p) in &self.starts[f] {
                let d = (p - c).norm_squared();
                // Kept in order, nearest first (ties: the earlier sample).
                if d < starts[NEAREST_STARTS - 1].0 {
                    let at = starts.iter().position(|s| d < s.0).unwrap_or(0);
                    starts.copy_within(at..NEAREST_STARTS - 1, at + 1);
                    starts[at] = (d, u, v);
                }
            }
            for &(d, u, v) in &starts {
                if !d.is_finite() {
                    break;
                }
                let (d, p) = self.descend(f, c, u, v);
                match best {
                    Some((bd, _)) if bd <= d => {}
                    _ => best = Some((d, p)),
                }
            }
        }
        best
    }

    /// As [`Nearest::nearest`], also searching from `hints` (face, parameters in its unit
    /// square): the samples nearest `c` may lie in another valley of the distance than the
    /// nearest point (a face folded or creased inside).
    pub(super) fn nearest_from(
        &self,
        c: &Point3,
        reach: f64,
        hints: &[(u32, [f64; 2])],
    ) -> Option<(f64, Point3)> {
        let mut best = self.nearest(c, reach);
        for &(f, [u, v]) in hints {
            let (d, p) = self.descend(f as usize, c, u, v);
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, p));
            }
        }
        best
    }

    /// Local nearest point to `c` on face `f` from `(u, v)`: Newton steps on the squared
    /// distance within one Bézier cell of the face at a time. A coordinate that reaches a
    /// side while the distance still falls outwards goes on into the next cell if the
    /// distance falls that way there too; otherwise (the face's own side, or a crease the
    /// distance has its kink on) it stays on the side and the other one goes on alone.
    pub(super) fn descend(&self, f: usize, c: &Point3, u: f64, v: f64) -> (f64, Point3) {
        let foot = self.foot(f, c, u, v);
        (foot.dist, foot.point)
    }

    /// As [`Nearest::descend`], with where on the face the search ended.
    pub(super) fn foot(&self, f: usize, c: &Point3, mut u: f64, mut v: f64) -> Foot {
        let face = &self.surface.faces()[f];
        let breaks = face.breaks();
        let breaks = [breaks.0, breaks.1];
        let cell_of = |b: &[f64], x: f64| b[1..b.len() - 1].partition_point(|&k| k <= x);
        let mut cell = [cell_of(breaks[0], u), cell_of(breaks[1], v)];
        // The gradient of the squared distance from cell `k`.
        let grad = |k: [usize; 2], u: f64, v: f64| {
            let d = face.derivs_in(k, u, v);
            let r = d.point - c;
            (d.su.dot(&r), d.sv.dot(&r), d, r)
        };
        let mut steps = 0;
        while steps < NEWTON_STEPS + MAX_CELL_CROSSINGS {
            steps += 1;
            let (gu, gv, d, r) = grad(cell, u, v);
            // A side the gradient pushes out of: the next cell's, or stay on it.
            let mut fixed = [false, false];
            let mut crossed = false;
            for (k, (x, g)) in [(u, gu), (v, gv)].into_iter().enumerate() {
                let b = breaks[k];
                let (lo, hi) = (b[cell[k]], b[cell[k] + 1]);
                let out = if x <= lo && g > 0.0 {
                    (cell[k] > 0).then(|| cell[k] - 1)
                } else if x >= hi && g < 0.0 {
                    (cell[k] + 2 < b.len()).then(|| cell[k] + 1)
                } else {
                    continue;
                };
                let next = out.filter(|&n| {
                    let mut nc = cell;
                    nc[k] = n;
                    let (nu, nv, _, _) = grad(nc, u, v);
                    let gn = if k == 0 { nu } else { nv };
                    gn * g > 0.0
                });
                match next {
                    Some(n) => {
                        cell[k] = n;
                        crossed = true;
                    }
                    _ => fixed[k] = true,
                }
            }
            if crossed {
                continue;
            }
            // Gauss–Newton (the metric) plus the curvature terms where that stays positive.
            let (mut a, mut b, mut cc) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
            let (fa, fb, fc) = (a + d.suu.dot(&r), b + d.suv.dot(&r), cc + d.svv.dot(&r));
            if fa > 0.0 && fc > 0.0 && fa * fc - fb * fb > 0.0 {
                (a, b, cc) = (fa, fb, fc);
            }
            let (du, dv) = match fixed {
                [true, true] => break,
                [true, false] => (0.0, if cc > 0.0 { -gv / cc } else { 0.0 }),
                [false, true] => (if a > 0.0 { -gu / a } else { 0.0 }, 0.0),
                [false, false] => {
                    let det = a * cc - b * b;
                    if det.is_nan() || det <= 0.0 {
                        break;
                    }
                    (-(cc * gu - b * gv) / det, -(a * gv - b * gu) / det)
                }
            };
            if !(du.is_finite() && dv.is_finite()) {
                break;
            }
            let (bu, bv) = (breaks[0], breaks[1]);
            let nu = (u + du).clamp(bu[cell[0]], bu[cell[0] + 1]);
            let nv = (v + dv).clamp(bv[cell[1]], bv[cell[1] + 1]);
            let moved = (nu - u).abs().max((nv - v).abs());
            (u, v) = (nu, nv);
            if moved < NEWTON_CONVERGED {
                break;
            }
        }
        let p = face.derivs_in(cell, u, v).point;
        Foot {
            dist: (p - c).norm(),
            point: p,
            cell,
            uv: [u, v],
        }
    }
}

/// Where a nearest-point search on one face ended.
pub(super) struct Foot {
    /// Distance from the query point (mm).
    pub dist: f64,
    pub point: Point3,
    /// The Bézier cell of the face (of its breaks) and the face parameters.
    pub cell: [usize; 2],
    pub uv: [f64; 2],
}

/// The grid cell holding `p` for cells of `cell` mm.
fn cell_of(p: &[f64; 3], cell: f64) -> [i64; 3] {
    p.map(|x| (x / cell).floor() as i64)
}
