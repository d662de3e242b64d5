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

use super::{MoveKind, Toolpath};
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
}

/// Samples per face side for the nearest-point start.
const START_SAMPLES: usize = 6;
/// Newton steps of the nearest-point search on one face.
const NEWTON_STEPS: usize = 30;
/// Parameter step (of a face's unit square) below which the search has converged.
const NEWTON_CONVERGED: f64 = 1e-12;
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
}

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
        Nearest {
            surface,
            boxes,
            starts,
        }
    }

    /// Nearest point to `c` on faces whose box comes within `reach` of it, and its distance.
    fn nearest(&self, c: &Point3, reach: f64) -> Option<(f64, Point3)> {
        let mut best: Option<(f64, Point3)> = None;
        for (f, b) in self.boxes.iter().enumerate() {
            let out = (0..3)
                .map(|k| (b.min[k] - c[k]).max(c[k] - b.max[k]).max(0.0))
                .fold(0.0f64, |a, x| a.hypot(x));
            if out > reach {
                continue;
            }
            let &(mut u, mut v, _) = self.starts[f]
                .iter()
                .min_by(|a, b| (a.2 - c).norm().total_cmp(&(b.2 - c).norm()))
                .expect("samples");
            for _ in 0..NEWTON_STEPS {
                let d = self.surface.derivs(f, u, v);
                let r = d.point - c;
                let (a, b, cc) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
                let (gu, gv) = (d.su.dot(&r), d.sv.dot(&r));
                let det = a * cc - b * b;
                if det.is_nan() || det <= 0.0 {
                    break;
                }
                let (nu, nv) = (
                    (u - (cc * gu - b * gv) / det).clamp(0.0, 1.0),
                    (v - (a * gv - b * gu) / det).clamp(0.0, 1.0),
                );
                let moved = (nu - u).abs().max((nv - v).abs());
                (u, v) = (nu, nv);
                if moved < NEWTON_CONVERGED {
                    break;
                }
            }
            let p = self.surface.subs(f, u, v);
            let d = (p - c).norm();
            match best {
                Some((bd, _)) if bd <= d => {}
                _ => best = Some((d, p)),
            }
        }
        best
    }
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
/// `keep_going` is asked every few hundred moves; false cancels.
pub fn lift(
    surface: &Surface,
    path: &mut Toolpath,
    r: f64,
    tol: f64,
    left: &mut [f64],
    keep_going: &mut dyn FnMut() -> bool,
) -> Result<GougeStats> {
    let near = Nearest::new(surface);
    let mut stats = GougeStats::default();
    for (i, m) in path.moves.iter_mut().enumerate() {
        if i % CANCEL_EVERY == 0 && !keep_going() {
            return Err(Error::Cancelled);
        }
        if !matches!(m.kind, MoveKind::Feed | MoveKind::Link) {
            continue;
        }
        let Some((d, q)) = near.nearest(&m.cl_point, r) else {
            continue;
        };
        if d >= r - tol {
            continue;
        }
        if r - d > stats.worst_mm {
            stats.worst_mm = r - d;
            stats.worst_at = Some(m.cl_point);
        }
        stats.lifted += 1;
        let (mut c, mut nearest) = (m.cl_point, (d, q));
        let mut depth = r - d;
        for round in 0..LIFT_ROUNDS {
            let (d, q) = nearest;
            c += (c - q) / d * depth;
            let Some(next) = near.nearest(&c, r) else {
                break;
            };
            nearest = next;
            depth = r - next.0;
            if depth <= 0.1 * tol || round + 1 == LIFT_ROUNDS {
                break;
            }
        }
        let contact = nearest.1;
        if depth > tol {
            stats.residual += 1;
            stats.residual_mm = stats.residual_mm.max(depth);
        }
        if let Some(l) = left.get_mut(i) {
            *l = ((c - m.cc_point).norm() - r).max(0.0);
        }
        m.cl_point = c;
        m.cc_point = contact;
    }
    Ok(stats)
}
