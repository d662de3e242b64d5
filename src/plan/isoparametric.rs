//! Isoparametric zig-zag finishing, patch by patch: passes along one parameter, side steps
//! from the scallop limit (eq. 5–6, the minimum over samples of the current pass), forward
//! steps from the chordal tolerance, and retractions between patches.
//!
//! This is the strategy's single-patch core; patch ordering and non-retraction transit
//! between patches build on it.

use super::stepover::{self, FeedDir};
use super::toolpath::{Move, MoveKind, Toolpath};
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::model::Model;
use crate::surface::{DiffGeom, FaceSurface};

/// Samples along a pass used to find the side step to the next pass.
const SIDE_STEP_SAMPLES: usize = 33;
/// Most halvings of a forward step before giving up on meeting the chordal tolerance.
const MAX_HALVINGS: usize = 40;

/// Surface data at one point of a pass.
struct PassPoint {
    cc: Point3,
    normal: Vector3,
}

/// Fundamental forms at a point; `None` at a singular point (an extraordinary point's limit),
/// where curvature is undefined and must not enter step computations.
fn geom_at(face: &FaceSurface, u: f64, v: f64) -> Option<DiffGeom> {
    DiffGeom::try_from_derivs(&face.derivs(u, v))
}

/// Point on the pass at fixed `w` (the across-parameter), moving parameter `t`.
fn at(dir: FeedDir, t: f64, w: f64) -> (f64, f64) {
    match dir {
        FeedDir::AlongU => (t, w),
        FeedDir::AlongV => (w, t),
    }
}

/// Parametric side step from the pass at `w` for scallop `h`, and the most restrictive
/// point's physical step.
fn required_step(face: &FaceSurface, dir: FeedDir, w: f64, opts: &PlanOptions) -> Result<f64> {
    let mut best = f64::INFINITY;
    for k in 0..SIDE_STEP_SAMPLES {
        let t = k as f64 / (SIDE_STEP_SAMPLES - 1) as f64;
        let (u, v) = at(dir, t, w);
        let Some(dg) = geom_at(face, u, v) else {
            continue;
        };
        let kappa = stepover::cross_curvature(&dg, dir);
        let g =
            stepover::side_step(opts.scallop_mm, opts.tool_radius_mm, kappa).map_err(
                |e| match e {
                    Error::Degenerate { message, .. } => Error::Degenerate {
                        location: format!("face {} at (u, v) = ({u:.4}, {v:.4})", face.mesh_face),
                        message,
                    },
                    other => other,
                },
            )?;
        best = best.min(stepover::param_side_step(&dg, dir, g));
    }
    Ok(best)
}

/// Largest scallop predicted by eq. 5 between passes `w` and `w + dw`, sampled on both.
fn predicted_between(
    face: &FaceSurface,
    dir: FeedDir,
    w: f64,
    dw: f64,
    opts: &PlanOptions,
) -> Result<f64> {
    let mut worst: f64 = 0.0;
    for &ww in &[w, w + 0.5 * dw, w + dw] {
        for k in 0..SIDE_STEP_SAMPLES {
            let t = k as f64 / (SIDE_STEP_SAMPLES - 1) as f64;
            let (u, v) = at(dir, t, ww.min(1.0));
            let Some(dg) = geom_at(face, u, v) else {
                continue;
            };
            let kappa = stepover::cross_curvature(&dg, dir);
            let g = stepover::physical_side_step(&dg, dir, dw);
            worst = worst.max(stepover::predicted_scallop(g, opts.tool_radius_mm, kappa));
        }
    }
    Ok(worst)
}

/// The across-parameter values of all passes on a face, and the largest predicted scallop.
pub fn pass_positions(
    face: &FaceSurface,
    dir: FeedDir,
    opts: &PlanOptions,
) -> Result<(Vec<f64>, f64)> {
    let mut ws = vec![0.0];
    let mut worst: f64 = 0.0;
    let mut w = 0.0;
    while w < 1.0 {
        // Conservative: the smallest step required on this pass, half-way and at the next.
        let d0 = required_step(face, dir, w, opts)?;
        let d1 = required_step(face, dir, (w + 0.5 * d0).min(1.0), opts)?;
        let d2 = required_step(face, dir, (w + d0).min(1.0), opts)?;
        let dw = d0.min(d1).min(d2).min(1.0 - w);
        if !(dw > 0.0) {
            return Err(Error::Degenerate {
                location: format!("face {} at pass {w:.6}", face.mesh_face),
                message: "side step vanished".into(),
            });
        }
        worst = worst.max(predicted_between(face, dir, w, dw, opts)?);
        w = if 1.0 - (w + dw) < 1e-12 { 1.0 } else { w + dw };
        ws.push(w);
    }
    Ok((ws, worst))
}

/// Distance from `p` to the segment `a`–`b`.
fn dist_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

fn pass_point(face: &FaceSurface, dir: FeedDir, t: f64, w: f64) -> Result<PassPoint> {
    let (u, v) = at(dir, t, w);
    let normal = face.normal(u, v).ok_or_else(|| Error::Degenerate {
        location: format!("face {} at (u, v) = ({u:.6}, {v:.6})", face.mesh_face),
        message: "the surface has no tangent plane here or nearby".into(),
    })?;
    Ok(PassPoint {
        cc: face.subs(u, v),
        normal,
    })
}

/// Moving-parameter values along the pass at `w` so that chords of both the contact curve
/// and the ball-centre curve stay within the chordal tolerance.
pub fn forward_steps(
    face: &FaceSurface,
    dir: FeedDir,
    w: f64,
    opts: &PlanOptions,
) -> Result<Vec<f64>> {
    let r = opts.tool_radius_mm;
    let tol = opts.chordal_mm;
    let mut ts = vec![0.0];
    let mut t = 0.0;
    while t < 1.0 {
        let (u, v) = at(dir, t, w);
        let d = face.derivs(u, v);
        let (c1, c2) = match dir {
            FeedDir::AlongU => (d.su, d.suu),
            FeedDir::AlongV => (d.sv, d.svv),
        };
        let speed = c1.norm();
        let k = c1.cross(&c2).norm() / (speed * speed * speed);
        // Bound the curvature of the ball-centre curve too (radius shrinks by r on concave).
        let k_cl = if k * r < 0.5 {
            k / (1.0 - k * r)
        } else {
            2.0 * k
        };
        let mut dt = (stepover::chord_step(tol, k_cl) / speed)
            .min(1.0 - t)
            .min(0.125);
        let p0 = pass_point(face, dir, t, w)?;
        let mut ok = false;
        for _ in 0..MAX_HALVINGS {
            let pm = pass_point(face, dir, t + 0.5 * dt, w)?;
            let p1 = pass_point(face, dir, t + dt, w)?;
            let cc_dev = dist_to_segment(&pm.cc, &p0.cc, &p1.cc);
            let cl = |p: &PassPoint| p.cc + p.normal * r;
            let cl_dev = dist_to_segment(&cl(&pm), &cl(&p0), &cl(&p1));
            if cc_dev <= tol && cl_dev <= tol {
                ok = true;
                break;
            }
            dt *= 0.5;
        }
        if !ok {
            return Err(Error::Degenerate {
                location: format!("face {} near parameter {t:.6}", face.mesh_face),
                message: "the chordal tolerance cannot be met (a crease or cusp?)".into(),
            });
        }
        t = if 1.0 - (t + dt) < 1e-12 { 1.0 } else { t + dt };
        ts.push(t);
    }
    Ok(ts)
}

/// Plans a zig-zag on every domain face, joined by retractions. `progress` receives the
/// fraction done and returns `false` to cancel.
pub fn plan_zigzag(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Toolpath> {
    opts.validate()?;
    let surface = &model.surface;
    let r = opts.tool_radius_mm;
    let axis = Vector3::z();
    let safe_z = surface.bbox().max[2] + r * 2.0 + opts.clearance_mm;
    let dir = FeedDir::AlongU;
    let mut moves: Vec<Move> = Vec::new();
    let mut worst: f64 = 0.0;
    let nfaces = surface.faces().len();
    for (fi, face) in surface.faces().iter().enumerate() {
        let (ws, pred) = pass_positions(face, dir, opts)?;
        worst = worst.max(pred);
        let nlines = ws.len();
        for (li, &w) in ws.iter().enumerate() {
            let mut ts = forward_steps(face, dir, w, opts)?;
            if li % 2 == 1 {
                ts.reverse();
            }
            for (k, &t) in ts.iter().enumerate() {
                let p = pass_point(face, dir, t, w)?;
                let cl = p.cc + p.normal * r;
                let mk = |kind, cl_point: Point3| Move {
                    kind,
                    cc_point: p.cc,
                    cl_point,
                    tool_axis: axis,
                    patch: fi as u32,
                    line: li as u32,
                };
                if k == 0 {
                    if li == 0 {
                        // Approach: rapid above the start, then plunge onto it.
                        if let Some(last) = moves.last().copied() {
                            moves.push(Move {
                                kind: MoveKind::Retract,
                                cl_point: Point3::new(last.cl_point.x, last.cl_point.y, safe_z),
                                ..last
                            });
                        }
                        moves.push(mk(MoveKind::Rapid, Point3::new(cl.x, cl.y, safe_z)));
                        moves.push(mk(MoveKind::Plunge, cl));
                    } else {
                        moves.push(mk(MoveKind::Link, cl));
                    }
                } else {
                    moves.push(mk(MoveKind::Feed, cl));
                }
            }
            let frac = (fi as f64 + (li + 1) as f64 / nlines as f64) / nfaces as f64;
            if !progress(frac) {
                return Err(Error::Cancelled);
            }
        }
    }
    if let Some(last) = moves.last().copied() {
        moves.push(Move {
            kind: MoveKind::Retract,
            cl_point: Point3::new(last.cl_point.x, last.cl_point.y, safe_z),
            ..last
        });
    }
    Ok(Toolpath {
        tool_radius_mm: r,
        moves,
        max_predicted_scallop_mm: worst,
    })
}
