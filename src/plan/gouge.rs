//! Ball-centre gouge check against the whole surface.
//!
//! A CL point is placed by its own face's normal (`cl_point = cc + r·n`). Where the surface is
//! creased inward (C0 knot lines, e.g. those a `.tsm` grip block puts in) or another part of
//! the surface comes within the ball, that ball cuts into the neighbouring face. This module
//! owns finding such CL points and lifting them clear: the ball centre moves away from the
//! nearest surface point until it is a radius from every face, so it touches both sides of
//! the crease. It must not move a CL point that gouges nothing (tolerance below), nor change
//! moves off the surface. Only creases are looked for: where other parts of a smooth surface
//! come within the ball (thin walls) is not checked here.

use super::{Move, MoveKind, Toolpath};
use crate::error::{Error, Result};
use crate::geom::{Aabb, Point3};
use crate::model::Model;
use crate::surface::Surface;
use crate::tmesh::{Scheme, TMesh};

/// What the check found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GougeStats {
    /// CL points lifted because the ball cut into the surface.
    pub lifted: usize,
    /// Deepest cut found before lifting (mm).
    pub worst_mm: f64,
    /// The CL point of that deepest cut, before lifting (mm).
    pub worst_at: Option<Point3>,
    /// CL points still closer than a radius after the lifting rounds (mm deep at most
    /// `residual_mm`).
    pub residual: usize,
    pub residual_mm: f64,
    /// Cut points added between two cut points where the ball, moving straight from one to
    /// the other, cut into the surface (a fold or crease between them); they are lifted too.
    pub inserted: usize,
}

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
/// Lifting rounds per CL point (each moves it away from the then nearest point).
const LIFT_ROUNDS: usize = 8;
/// Moves between two checks for cancellation.
const CANCEL_EVERY: usize = 256;

/// Nearest-point queries against the surface: per face its box (from the Bézier control
/// points, which contain it) and a few samples to start Newton from.
struct Nearest<'a> {
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
    fn new(surface: &'a Surface) -> Self {
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

    /// Nearest point to `c` on faces whose box comes within `reach` of it, and its distance.
    fn nearest(&self, c: &Point3, reach: f64) -> Option<(f64, Point3)> {
        let mut best: Option<(f64, Point3)> = None;
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
        for f in faces {
            let f = f as usize;
            let b = &self.boxes[f];
            let out = (0..3)
                .map(|k| (b.min[k] - c[k]).max(c[k] - b.max[k]).max(0.0))
                .fold(0.0f64, |a, x| a.hypot(x));
            if out > reach {
                continue;
            }
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
    fn nearest_from(
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
    fn descend(&self, f: usize, c: &Point3, mut u: f64, mut v: f64) -> (f64, Point3) {
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
        ((p - c).norm(), p)
    }
}

/// The grid cell holding `p` for cells of `cell` mm.
fn cell_of(p: &[f64; 3], cell: f64) -> [i64; 3] {
    p.map(|x| (x / cell).floor() as i64)
}

/// True if the surface may have C0 knot lines (creases): only repeated knots, that is zero
/// knot intervals, put them in a T-spline; Catmull–Clark limit surfaces are G1 everywhere.
pub fn may_crease(mesh: &TMesh) -> bool {
    mesh.scheme() == Scheme::TSpline && mesh.half_edges().iter().any(|h| h.knot == 0.0)
}

/// True if a ball of radius `r` placed by its contact normal may cut into the surface
/// elsewhere: the surface may crease, or somewhere it is concave (towards the tool) with a
/// radius below the ball's (within [`TIGHT_MARGIN`]). The planner runs [`lift`] only then
/// (it costs about as much as the rest of a keycap plan).
pub fn needed(model: &Model, r: f64) -> bool {
    may_crease(&model.mesh)
        || model
            .smallest_concave_radius()
            .is_some_and(|c| c.radius_mm < r * (1.0 + TIGHT_MARGIN))
}

/// Relative margin on the tool radius below which a concave radius counts as tight: the
/// smallest radius is sampled, and may lie lower between samples.
const TIGHT_MARGIN: f64 = 0.25;

/// Lifts every cutting CL point of `path` whose ball of radius `r` cuts into the surface by
/// more than `tol` mm, until it is a radius from the nearest surface point (within `tol`).
/// The contact point becomes that nearest point; `left[i]` becomes the material the lifted
/// ball leaves at move `i`'s old contact point (mm; untouched for moves not lifted).
/// Then the straight moves next to lifted points, and those over which the ball turns round
/// a convex crease, are checked between their ends: where the ball cuts in on the way, a lifted cut point is added half-way (and the halves checked
/// again, [`SEGMENT_HALVINGS`] deep). Returns what it did and, when points were added, for
/// every move of the new path the old move it is (`u32::MAX` for added ones; empty when
/// nothing was added). `keep_going` is asked every few hundred moves; false cancels.
pub fn lift(
    model: &Model,
    path: &mut Toolpath,
    r: f64,
    tol: f64,
    left: &mut [f64],
    keep_going: &mut dyn FnMut() -> bool,
) -> Result<(GougeStats, Vec<u32>)> {
    let near = Nearest::new(&model.surface);
    // Where a move's contact point is on the surface: the face and its parameters there.
    let hint = |m: &Move, q: [f64; 2]| {
        let patch = model.layout.patches.get(m.patch as usize)?;
        m.kind
            .on_surface()
            .then(|| patch.face_param(&model.surface, q[0], q[1]))
    };
    let mut stats = GougeStats::default();
    let mut lifted = vec![false; path.moves.len()];
    for (i, m) in path.moves.iter_mut().enumerate() {
        if i % CANCEL_EVERY == 0 && !keep_going() {
            return Err(Error::Cancelled);
        }
        if !matches!(m.kind, MoveKind::Feed | MoveKind::Link) {
            continue;
        }
        let Some(l) = lift_one(&near, m.cl_point, r, tol, &[], &mut stats) else {
            continue;
        };
        lifted[i] = true;
        if let Some(x) = left.get_mut(i) {
            *x = ((l.centre - m.cc_point).norm() - r).max(0.0);
        }
        m.cl_point = l.centre;
        m.cc_point = l.contact;
    }
    // Straight moves next to lifted points.
    let n = path.moves.len();
    let near_lifted = |i: usize| {
        (i.saturating_sub(SEGMENT_REACH)..(i + SEGMENT_REACH + 1).min(n)).any(|k| lifted[k])
    };
    let mut added: Vec<Vec<(Move, [f64; 2])>> = vec![Vec::new(); n];
    for i in 1..n {
        if i % CANCEL_EVERY == 0 && !keep_going() {
            return Err(Error::Cancelled);
        }
        let (a, b) = (&path.moves[i - 1], &path.moves[i]);
        if !(a.kind.on_surface() && matches!(b.kind, MoveKind::Feed | MoveKind::Link)) {
            continue;
        }
        // The ball turning round a convex crease between the two points: its centre moves
        // on an arc round the crease, the straight move cuts the chord of that arc.
        let turn = (a.cl_point - a.cc_point).angle(&(b.cl_point - b.cc_point));
        let pivots = r * (1.0 - (0.5 * turn).cos()) > tol;
        if !(pivots || near_lifted(i)) {
            continue;
        }
        let (pa, pb) = (
            path.params.get(i - 1).copied().unwrap_or_default(),
            path.params.get(i).copied().unwrap_or_default(),
        );
        let mut out = Vec::new();
        let hints: Vec<(u32, [f64; 2])> =
            [hint(a, pa), hint(b, pb)].into_iter().flatten().collect();
        split_segment(
            &near,
            (a, pa),
            (b, pb),
            (r, tol),
            &hints,
            SEGMENT_HALVINGS,
            &mut stats,
            &mut out,
        );
        stats.inserted += out.len();
        added[i] = out;
    }
    if stats.inserted == 0 {
        return Ok((stats, Vec::new()));
    }
    let mut origin = Vec::with_capacity(n + stats.inserted);
    path.rebuild(|old, i, add| {
        for (m, q) in &added[i] {
            add(*m, *q);
            origin.push(u32::MAX);
        }
        add(old.moves[i], old.param(i));
        origin.push(i as u32);
    });
    Ok((stats, origin))
}

/// Moves on either side of a lifted point whose straight moves are checked between their ends.
const SEGMENT_REACH: usize = 2;
/// Most halvings of a straight move while adding lifted points on it.
pub const SEGMENT_HALVINGS: usize = 6;
/// Where between its ends a straight move is checked (fractions of it).
const SEGMENT_PROBES: [f64; 3] = [0.5, 0.25, 0.75];

/// A ball centre lifted clear of the surface, and the point it touches.
struct Lifted {
    centre: Point3,
    contact: Point3,
}

/// Lifts the ball centred at `c` until it is a radius from the nearest surface point (within
/// `tol`), if it cuts in by more than `tol`; `None` if it does not.
fn lift_one(
    near: &Nearest,
    c: Point3,
    r: f64,
    tol: f64,
    hints: &[(u32, [f64; 2])],
    stats: &mut GougeStats,
) -> Option<Lifted> {
    let (d, q) = near.nearest_from(&c, r, hints)?;
    if d >= r - tol {
        return None;
    }
    if r - d > stats.worst_mm {
        stats.worst_mm = r - d;
        stats.worst_at = Some(c);
    }
    stats.lifted += 1;
    let (mut c, mut nearest) = (c, (d, q));
    let mut depth = r - d;
    for round in 0..LIFT_ROUNDS {
        let (d, q) = nearest;
        c += (c - q) / d * depth;
        let Some(next) = near.nearest_from(&c, r, hints) else {
            break;
        };
        nearest = next;
        depth = r - next.0;
        if depth <= 0.1 * tol || round + 1 == LIFT_ROUNDS {
            break;
        }
    }
    if depth > tol {
        stats.residual += 1;
        stats.residual_mm = stats.residual_mm.max(depth);
    }
    Some(Lifted {
        centre: c,
        contact: nearest.1,
    })
}

/// Adds to `out`, in order from `a` to `b`, lifted cut points where the ball moving straight
/// from `a` to `b` cuts in by more than `tol`, checking the halves again up to `depth` deep.
#[allow(clippy::too_many_arguments)]
fn split_segment(
    near: &Nearest,
    a: (&Move, [f64; 2]),
    b: (&Move, [f64; 2]),
    (r, tol): (f64, f64),
    hints: &[(u32, [f64; 2])],
    depth: usize,
    stats: &mut GougeStats,
    out: &mut Vec<(Move, [f64; 2])>,
) {
    if depth == 0 {
        return;
    }
    let (ma, mb) = (a.0, b.0);
    let cuts_in = SEGMENT_PROBES.iter().any(|&s| {
        let c = ma.cl_point + (mb.cl_point - ma.cl_point) * s;
        near.nearest_from(&c, r, hints)
            .is_some_and(|(d, _)| d < r - tol)
    });
    if !cuts_in {
        return;
    }
    let mid = ma.cl_point + (mb.cl_point - ma.cl_point) * 0.5;
    let (centre, contact) = match lift_one(near, mid, r, tol, hints, stats) {
        Some(l) => (l.centre, l.contact),
        None => (
            mid,
            near.nearest_from(&mid, r, hints)
                .map_or(ma.cc_point, |(_, q)| q),
        ),
    };
    let q = [0.5 * (a.1[0] + b.1[0]), 0.5 * (a.1[1] + b.1[1])];
    let m = Move {
        cl_point: centre,
        cc_point: contact,
        ..*mb
    };
    split_segment(near, a, (&m, q), (r, tol), hints, depth - 1, stats, out);
    out.push((m, q));
    split_segment(near, (&m, q), b, (r, tol), hints, depth - 1, stats, out);
}
