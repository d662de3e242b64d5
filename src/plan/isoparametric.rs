//! Patch-ordered, non-retraction isoparametric finishing (Shang et al. 2020, §3).
//!
//! The patches of the layout are ordered as a travelling-salesman path ([`super::order`]),
//! transit corners are chosen so each patch finishes where the next one starts
//! ([`super::corners`]), and each patch is cut by a zig-zag of iso-parameter passes whose side
//! step comes from the scallop limit (eq. 5–6, the smallest over samples of the pass) and whose
//! forward steps keep chords within the chordal tolerance. The number of passes decides the
//! corner a zig-zag ends at; where it ends at the wrong one the scallop height is tuned down
//! (by 0.1 h, then by bisection) until one more pass fits. Consecutive patches meet at their
//! shared corner, joined by a feed move (along the side, where a patch leaves the pass on
//! that side to a neighbour).

use super::corners::{self, Crossfeed};
use super::draft::{Draft, DraftBuilder, Footprint, SurfacePoint};
use super::order::{self, CostMatrix};
use super::pipeline::Planned;
use super::stepover::{self, FeedDir};
use super::toolpath::{PatchRun, Toolpath};
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::geom::{dist_to_segment, Point3, Vector3};
use crate::layout::{ConnectionKind, Patch, PatchLayout, PatchLine};
use crate::model::Model;
use crate::surface::diffgeom::unit_normal;
use crate::surface::{DiffGeom, Surface, SurfaceDerivs};

/// Samples along a pass used to find the side step to the next pass.
const SIDE_STEP_SAMPLES: usize = 33;
/// Extra samples near both ends of a pass (fractions of it): at an extraordinary corner the
/// parameterisation stretches, and the side step must shrink there too.
const END_SAMPLES: [f64; 3] = [1e-3, 4e-3, 1.6e-2];

/// Where a pass is sampled for its side step: evenly, and densely near its ends.
fn pass_samples() -> impl Iterator<Item = f64> {
    (0..SIDE_STEP_SAMPLES)
        .map(|k| k as f64 / (SIDE_STEP_SAMPLES - 1) as f64)
        .chain(END_SAMPLES.iter().flat_map(|&e| [e, 1.0 - e]))
}
/// Most halvings of a forward step before giving up on meeting the chordal tolerance.
const MAX_HALVINGS: usize = 40;
/// Bisection steps of the scallop tuning.
const TUNING_STEPS: usize = 60;
/// Part of the chordal tolerance the forward steps aim for: the chord is held against the
/// curve at a few points only, and the rest covers the gap between them (dimensionless).
pub(crate) const CHORD_MARGIN: f64 = 0.9;
/// Fractions of a forward step where the chord is held against the curve.
const CHORD_PROBES: [f64; 3] = [0.5, 0.25, 0.75];
/// Share of the scallop height reserved for the material a straight move leaves where the
/// surface is concave along the feed (dimensionless); the side steps use the rest.
pub(crate) const CHORD_SCALLOP_SHARE: f64 = 0.1;
/// Points closer than this fraction of the model size are the same corner.
const CORNER_MATCH_REL: f64 = 1e-7;

/// A surface with one parameter square, as the zig-zag sees it.
pub trait ParamSurface {
    fn subs(&self, u: f64, v: f64) -> Point3;
    /// Unit normal on the tool's side, taken from nearby where the surface is singular.
    fn normal(&self, u: f64, v: f64) -> Option<Vector3>;
    /// [`ParamSurface::subs`] and [`ParamSurface::normal`] from one evaluation.
    fn point_normal(&self, u: f64, v: f64) -> (Point3, Option<Vector3>);
    /// Where this is, for error messages.
    fn label(&self) -> String;
    /// The iso-line along `dir` at across-parameter `w` (`at(dir, t, w)` for running `t`),
    /// for many evaluations along it.
    fn line(&self, dir: FeedDir, w: f64) -> Box<dyn ParamLine + '_>;
    /// Parameters `(u, v)` of the surface's singular points (extraordinary points) on it.
    fn singular_points(&self) -> Vec<[f64; 2]> {
        Vec::new()
    }
    /// +1 if the tool works from the side `S_u × S_v` points to, −1 if from the other.
    fn side(&self) -> f64 {
        1.0
    }
}

/// A layout patch of a surface, seen from the side the tool works from.
pub struct PatchView<'a> {
    pub index: usize,
    pub patch: &'a Patch,
    pub surface: &'a Surface,
    /// +1: the tool works from the side `S_u × S_v` points to; −1: from the other
    /// ([`Model::tool_side`]).
    pub side: f64,
}

/// The patch views of `model`, seen from the side the tool works from.
pub fn patch_views(model: &Model) -> Vec<PatchView<'_>> {
    layout_views(model, &model.layout)
}

/// The patches of `layout` (another layout of `model`'s surface) as [`patch_views`] gives
/// its own.
pub fn layout_views<'a>(model: &'a Model, layout: &'a PatchLayout) -> Vec<PatchView<'a>> {
    layout
        .patches
        .iter()
        .enumerate()
        .map(|(index, patch)| PatchView {
            index,
            patch,
            surface: &model.surface,
            side: model.tool_side(),
        })
        .collect()
}

impl ParamSurface for PatchView<'_> {
    fn subs(&self, u: f64, v: f64) -> Point3 {
        self.patch.subs(self.surface, u, v)
    }
    fn normal(&self, u: f64, v: f64) -> Option<Vector3> {
        self.patch.normal(self.surface, u, v).map(|n| n * self.side)
    }
    /// Point and tool-side unit normal at `(u, v)`, from one evaluation.
    fn point_normal(&self, u: f64, v: f64) -> (Point3, Option<Vector3>) {
        let (p, n) = self.patch.point_normal(self.surface, u, v);
        (p, n.map(|n| n * self.side))
    }
    fn side(&self) -> f64 {
        self.side
    }
    fn label(&self) -> String {
        format!("patch {}", self.index)
    }
    fn line(&self, dir: FeedDir, w: f64) -> Box<dyn ParamLine + '_> {
        Box::new(ViewLine {
            line: self.patch.line(self.surface, dir == FeedDir::AlongU, w),
            side: self.side,
        })
    }
    fn singular_points(&self) -> Vec<[f64; 2]> {
        self.patch.singular_points(self.surface)
    }
}

/// An iso-line of a [`ParamSurface`] (a pass, or a line across the passes) evaluated at many
/// points of its running parameter `t`: the numbers the surface gives at `at(dir, t, w)`,
/// found with less work per point.
pub trait ParamLine {
    fn derivs(&mut self, t: f64) -> SurfaceDerivs;
    /// Point and tool-side unit normal.
    fn point_normal(&mut self, t: f64) -> (Point3, Option<Vector3>);
    /// Derivatives and tool-side unit normal.
    fn derivs_normal(&mut self, t: f64) -> (SurfaceDerivs, Option<Vector3>);
}

/// A patch's iso-line with the tool side's normals.
struct ViewLine<'a> {
    line: PatchLine<'a>,
    side: f64,
}

impl ParamLine for ViewLine<'_> {
    fn derivs(&mut self, t: f64) -> SurfaceDerivs {
        self.line.derivs(t)
    }
    fn point_normal(&mut self, t: f64) -> (Point3, Option<Vector3>) {
        let (p, n) = self.line.point_normal(t);
        (p, n.map(|n| n * self.side))
    }
    fn derivs_normal(&mut self, t: f64) -> (SurfaceDerivs, Option<Vector3>) {
        let (d, n) = self.line.derivs_normal(t);
        (d, n.map(|n| n * self.side))
    }
}

/// Fundamental forms at a point; `None` at a singular point (an extraordinary point's limit),
/// where curvature is undefined and must not enter step computations.
fn geom_of(s: &dyn ParamSurface, d: &SurfaceDerivs) -> Option<DiffGeom> {
    let g = DiffGeom::try_from_derivs(d)?;
    Some(if s.side() < 0.0 { g.flipped() } else { g })
}

/// The direction the passes run with crossfeed `c`: crossfeed U steps from pass to pass in
/// u, the passes u = const cut along v.
fn feed_dir(c: Crossfeed) -> FeedDir {
    match c {
        Crossfeed::U => FeedDir::AlongV,
        Crossfeed::V => FeedDir::AlongU,
    }
}

/// Point on the pass at fixed `w` (the across-parameter), moving parameter `t`.
fn at(dir: FeedDir, t: f64, w: f64) -> (f64, f64) {
    match dir {
        FeedDir::AlongU => (t, w),
        FeedDir::AlongV => (w, t),
    }
}

/// Where a pass is sampled for its side step, for a patch with singular points at
/// `singular` along the passes (the running parameter `t` of each): [`pass_samples`], and
/// for a singular point inside the pass [`END_SAMPLES`] on both sides of it. Where a pass
/// runs past an extraordinary point (a rectangle's side through a hole's corner), the
/// parameterisation stretches within a fraction of the even samples' spacing: on bumps-hole
/// cut in rectangles whose sides run through the hole's corners, the even samples missed it
/// and the cut left 0.085 mm where 0.05 mm was asked.
fn step_samples(singular: &[f64]) -> Vec<f64> {
    let near_end = END_SAMPLES.iter().copied().fold(0.0, f64::max);
    let mut ts: Vec<f64> = pass_samples().collect();
    for &t in singular {
        if t > near_end && t < 1.0 - near_end {
            ts.extend(END_SAMPLES.iter().flat_map(|&e| [t - e, t + e]));
        }
    }
    ts
}

/// Parametric side step from the pass at `w` for scallop `h`: the smallest over the pass
/// at `samples` (concave curvature tighter than the ball clamped, see
/// [`stepover::side_step_clamped`]).
fn required_step(
    s: &dyn ParamSurface,
    dir: FeedDir,
    w: f64,
    h: f64,
    r: f64,
    samples: &[f64],
) -> f64 {
    let mut best = f64::INFINITY;
    let mut line = s.line(dir, w);
    for &t in samples {
        let Some(dg) = geom_of(s, &line.derivs(t)) else {
            continue;
        };
        let kappa = stepover::cross_curvature(&dg, dir);
        let g = stepover::side_step_clamped(h, r, kappa);
        best = best.min(stepover::param_side_step(&dg, dir, g));
    }
    best
}

/// Grid intervals of a step profile across a patch.
const PROFILE_INTERVALS: usize = 256;
/// Ratio of the required steps at two neighbouring profile points above which the interval
/// between them is halved: the step changes fast there (next to a hole's corner, an
/// extraordinary point) and may dip below both ends between them (by 36 % next to
/// bumps-hole's hole on a 60 mm patch).
const PROFILE_REFINE_RATIO: f64 = 1.02;
/// Most halvings of one profile interval.
const PROFILE_REFINE_DEPTH: usize = 6;

/// The side step a pass needs as a function of where it is, for one scallop height `h0`.
/// Side steps scale exactly with `sqrt(h)` (eq. 5), so one profile serves every height the
/// tuning tries. Between points the smaller neighbouring value is used (a lower envelope,
/// on the safe side); the points are a uniform grid, halved where neighbours differ by
/// more than [`PROFILE_REFINE_RATIO`].
pub struct StepProfile {
    /// Across-parameter of each point, increasing from 0 to 1.
    w: Vec<f64>,
    d: Vec<f64>,
    h0: f64,
}

impl StepProfile {
    /// Samples the required step across the patch.
    pub fn new(s: &dyn ParamSurface, dir: FeedDir, h0: f64, r: f64) -> Result<Self> {
        // The running parameter of each singular point along the passes.
        let mut singular: Vec<f64> = s
            .singular_points()
            .iter()
            .map(|p| match dir {
                FeedDir::AlongU => p[0],
                FeedDir::AlongV => p[1],
            })
            .collect();
        crate::sort::sort_floats(&mut singular);
        singular.dedup();
        let samples = step_samples(&singular);
        let need = |w: f64| required_step(s, dir, w, h0, r, &samples);
        let mut points = vec![(0.0, need(0.0))];
        for i in 1..=PROFILE_INTERVALS {
            let w = i as f64 / PROFILE_INTERVALS as f64;
            let from = points[points.len() - 1];
            refine_profile(&need, from, (w, need(w)), PROFILE_REFINE_DEPTH, &mut points);
        }
        let (w, d) = points.into_iter().unzip();
        Ok(StepProfile { w, d, h0 })
    }

    /// Required parametric step at `w` for scallop `h`.
    fn step(&self, w: f64, h: f64) -> f64 {
        let i = self
            .w
            .partition_point(|&x| x <= w)
            .clamp(1, self.w.len() - 1);
        self.d[i - 1].min(self.d[i]) * (h / self.h0).sqrt()
    }

    /// Pass positions for scallop `h`: from 0, each step the smallest needed on the pass,
    /// half-way and at the next pass; the last pass on 1.
    pub fn passes(&self, h: f64) -> Vec<f64> {
        let mut ws = vec![0.0];
        let mut w = 0.0;
        while w < 1.0 {
            let d0 = self.step(w, h);
            let d1 = self.step(w + 0.5 * d0, h);
            let d2 = self.step(w + d0, h);
            let dw = d0.min(d1).min(d2).min(1.0 - w).max(MIN_PARAM_STEP);
            w = if 1.0 - (w + dw) < 1e-12 { 1.0 } else { w + dw };
            ws.push(w);
        }
        ws
    }
}

/// Appends `to` to `points`, after the points between `from` (the last one there) and `to`
/// that halving the interval up to `depth` times finds where the two ends' required steps
/// differ by more than [`PROFILE_REFINE_RATIO`].
fn refine_profile(
    need: &dyn Fn(f64) -> f64,
    from: (f64, f64),
    to: (f64, f64),
    depth: usize,
    points: &mut Vec<(f64, f64)>,
) {
    // An end where no step could be found (no tangent plane along that pass) against a
    // finite one differs too: halving finds where the surface begins to need one.
    let (lo, hi) = (from.1.min(to.1), from.1.max(to.1));
    if depth > 0 && lo.is_finite() && !(hi <= PROFILE_REFINE_RATIO * lo) {
        let w = 0.5 * (from.0 + to.0);
        let mid = (w, need(w));
        refine_profile(need, from, mid, depth - 1, points);
        refine_profile(need, mid, to, depth - 1, points);
    } else {
        points.push(to);
    }
}

/// Smallest parametric side step taken (a guard against runaway pass counts).
const MIN_PARAM_STEP: f64 = 1e-9;

/// Largest scallop predicted by eq. 5 over all adjacent passes, sampled on both passes of
/// each gap and half-way (each pass's samples serve both gaps it borders).
pub(crate) fn predicted(s: &dyn ParamSurface, dir: FeedDir, ws: &[f64], r: f64) -> f64 {
    let mut sorted = ws.to_vec();
    crate::sort::sort_floats(&mut sorted);
    let row = |w: f64| -> Vec<Option<DiffGeom>> {
        let mut line = s.line(dir, w.min(1.0));
        pass_samples()
            .map(|t| geom_of(s, &line.derivs(t)))
            .collect()
    };
    let worst_on = |row: &[Option<DiffGeom>], dw: f64| -> f64 {
        row.iter().flatten().fold(0.0, |worst: f64, dg| {
            let kappa = stepover::cross_curvature(dg, dir);
            let g = stepover::physical_side_step(dg, dir, dw);
            worst.max(stepover::predicted_scallop(g, r, kappa))
        })
    };
    let mut worst: f64 = 0.0;
    let Some(&w0) = sorted.first() else {
        return worst;
    };
    let mut first = row(w0);
    for pair in sorted.windows(2) {
        let dw = pair[1] - pair[0];
        let second = row(pair[1]);
        worst = worst
            .max(worst_on(&first, dw))
            .max(worst_on(&row(pair[0] + 0.5 * dw), dw))
            .max(worst_on(&second, dw));
        first = second;
    }
    worst
}

/// The across-parameter values of all passes for scallop `h`, and the largest predicted
/// scallop between them.
pub fn pass_positions(
    s: &dyn ParamSurface,
    dir: FeedDir,
    h: f64,
    r: f64,
) -> Result<(Vec<f64>, f64)> {
    let ws = StepProfile::new(s, dir, h, r)?.passes(h);
    let pred = predicted(s, dir, &ws, r);
    Ok((ws, pred))
}

/// Passes with a count of the wanted parity: with `h`, or with the scallop tuned down until
/// one more pass fits (0.1 h steps, then bisection). Returns the passes, the scallop height
/// used and the predicted scallop.
fn tuned_passes(
    s: &dyn ParamSurface,
    dir: FeedDir,
    profile: &StepProfile,
    odd: bool,
    h: f64,
    r: f64,
) -> Result<(Vec<f64>, f64, f64)> {
    let done = |ws: Vec<f64>, hh: f64| {
        let pred = predicted(s, dir, &ws, r);
        Ok((ws, hh, pred))
    };
    let ws = profile.passes(h);
    let n = ws.len();
    if (n % 2 == 1) == odd {
        return done(ws, h);
    }
    let (mut hi, mut lo) = (h, h);
    for k in 1..10 {
        lo = h * (1.0 - 0.1 * k as f64);
        let m = profile.passes(lo).len();
        if m == n + 1 {
            return done(profile.passes(lo), lo);
        }
        if m > n + 1 {
            break;
        }
        hi = lo;
    }
    // Bisection between `hi` (n passes) and `lo` (more than n + 1).
    for _ in 0..TUNING_STEPS {
        let mid = 0.5 * (hi + lo);
        let m = profile.passes(mid).len();
        if m == n + 1 {
            return done(profile.passes(mid), mid);
        }
        if m <= n {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // The count jumps past n + 1: add a pass half-way across the widest gap of the n-pass
    // solution instead (the scallop only shrinks).
    let mut ws = profile.passes(hi);
    let k = (0..ws.len() - 1)
        .max_by(|&a, &b| (ws[a + 1] - ws[a]).total_cmp(&(ws[b + 1] - ws[b])))
        .unwrap_or(0);
    ws.insert(k + 1, 0.5 * (ws[k] + ws[k + 1]));
    done(ws, hi)
}

/// Material left along the unit normal `n` at surface point `q` by a ball of radius `r`
/// swept along the line through `c` with unit direction `e` (a cylinder: the swept ball
/// near a point of its pass), in mm, negative if `q` is inside; infinity if the normal
/// line misses it.
fn left_by_swept_ball(q: &Point3, n: &Vector3, (c, e): (&Point3, &Vector3), r: f64) -> f64 {
    let d = c - q;
    let (dp, np) = (d - e * d.dot(e), n - e * n.dot(e));
    let a = np.norm_squared();
    if a < SWEEP_PARALLEL {
        // The normal runs along the pass: the ball itself.
        let b = d.dot(n);
        let disc = b * b - (d.norm_squared() - r * r);
        return if disc < 0.0 {
            f64::INFINITY
        } else {
            b - disc.sqrt()
        };
    }
    let b = np.dot(&dp);
    let disc = b * b - a * (dp.norm_squared() - r * r);
    if disc < 0.0 {
        f64::INFINITY
    } else {
        (b - disc.sqrt()) / a
    }
}

/// Below this squared sine the surface normal runs along the pass (dimensionless).
const SWEEP_PARALLEL: f64 = 1e-12;
/// Parameter step of the finite difference giving a pass's direction.
const TANGENT_STEP: f64 = 1e-5;

/// Most steps locating the cusp between two passes; a bisection would bracket it to 2⁻¹²
/// of their gap in as many.
const CUSP_STEPS: usize = 12;
/// Share of the scallop height within which the cusp between two passes is located: the
/// step stops where the material the two balls leave differs by less (dimensionless).
const CUSP_LOCATE_SHARE: f64 = 1e-3;
/// Relative excess of a cusp over its target tolerated before its gap is split: eq. 5 spaces
/// passes for the target itself, so its cusps reach it to rounding; kinks exceed it by far.
const CUSP_SLACK: f64 = 0.02;
/// Times a gap between passes is split in three before its cusp is left as it is.
const CUSP_SPLITS: usize = 4;

/// A pass near one of its samples, as [`cusp_between`] sees it.
#[derive(Clone, Copy)]
struct Sweep {
    /// Contact point and unit normal.
    cc: (Point3, Vector3),
    /// Ball centre, and the ball-centre curve's unit tangent (zero where it has none).
    cl: Point3,
    tangent: Vector3,
}

/// The pass at `w` at each of [`pass_samples`]: the ball-centre curve's tangent
/// `S_t + r n_t` from the derivatives where the surface has a normal (`n_t` the derivative
/// of `S_u × S_v / |S_u × S_v|`), else by a finite difference.
fn sweeps(s: &dyn ParamSurface, dir: FeedDir, w: f64, r: f64) -> Result<Vec<Sweep>> {
    let mut line = s.line(dir, w);
    pass_samples()
        .map(|t| {
            let (d, n) = line.derivs_normal(t);
            let cc = match n {
                Some(n) => (d.point, n),
                // No normal here or nearby: pass_point says so.
                None => pass_point(s, dir, t, w)?,
            };
            let (st, mt) = match dir {
                FeedDir::AlongU => (d.su, d.suu.cross(&d.sv) + d.su.cross(&d.suv)),
                FeedDir::AlongV => (d.sv, d.suv.cross(&d.sv) + d.su.cross(&d.svv)),
            };
            let tangent = match unit_normal(&d.su, &d.sv) {
                Some(m) => {
                    let len = d.su.cross(&d.sv).norm();
                    let nt = (mt - m * m.dot(&mt)) * (s.side() / len);
                    (st + nt * r).try_normalize(0.0)
                }
                None => {
                    let cl = |t: f64| -> Result<Point3> {
                        let (p, n) = pass_point(s, dir, t, w)?;
                        Ok(p + n * r)
                    };
                    let (ta, tb) = ((t - TANGENT_STEP).max(0.0), (t + TANGENT_STEP).min(1.0));
                    (cl(tb)? - cl(ta)?).try_normalize(0.0)
                }
            };
            Ok(Sweep {
                cc,
                cl: cc.0 + cc.1 * r,
                tangent: tangent.unwrap_or_else(Vector3::zeros),
            })
        })
        .collect()
}

/// The highest cusp between the passes at `w0` and `w1` (mm), whose [`sweeps`] are `s0` and
/// `s1`: at samples of the passes, the material left at the point between them where the two
/// passes' swept balls (centred a radius along the surface normal from the contact points,
/// swept along the ball-centre curve's tangent) leave equal material, found along the
/// iso-line across by false position (Illinois) until the two differ by less than `tol`
/// (mm), with a bisection step where a ball misses the normal line.
fn cusp_between(
    s: &dyn ParamSurface,
    dir: FeedDir,
    (w0, s0): (f64, &[Sweep]),
    (w1, s1): (f64, &[Sweep]),
    r: f64,
    tol: f64,
) -> Result<f64> {
    let mut worst: f64 = 0.0;
    let across = dir.other();
    for ((t, p0), p1) in pass_samples().zip(s0).zip(s1) {
        let mut line = s.line(across, t);
        // Material left by each pass at a point with normal n.
        let left_at = |(q, n): (Point3, Vector3)| -> (f64, f64) {
            (
                left_by_swept_ball(&q, &n, (&p0.cl, &p0.tangent), r),
                left_by_swept_ball(&q, &n, (&p1.cl, &p1.tangent), r),
            )
        };
        let mut left = |x: f64| -> Result<(f64, f64)> {
            let w = w0 + x * (w1 - w0);
            Ok(left_at(line_point(s, &mut *line, across, w, t)?))
        };
        // g = a − b rises across the gap: the first pass leaves least on its own line.
        let g = |(a, b): (f64, f64)| a - b;
        let (mut lo, mut hi) = (0.0, 1.0);
        let (mut g_lo, mut g_hi) = (g(left_at(p0.cc)), g(left_at(p1.cc)));
        let mut best = f64::INFINITY;
        // Which end moved last (Illinois: the other end's value is halved when one end
        // moves twice running).
        let mut last_side = 0i8;
        for _ in 0..CUSP_STEPS {
            let x = if g_lo.is_finite() && g_hi.is_finite() && g_lo < 0.0 && g_hi > 0.0 {
                let x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
                if x > lo && x < hi {
                    x
                } else {
                    0.5 * (lo + hi)
                }
            } else {
                0.5 * (lo + hi)
            };
            let (a, b) = left(x)?;
            best = best.min(a.max(b));
            let gx = g((a, b));
            if gx.abs() <= tol {
                break;
            }
            if a < b {
                lo = x;
                g_lo = gx;
                if last_side == -1 {
                    g_hi *= 0.5;
                }
                last_side = -1;
            } else {
                hi = x;
                g_hi = gx;
                if last_side == 1 {
                    g_lo *= 0.5;
                }
                last_side = 1;
            }
        }
        // The cusp lies between the lesser of the two at the bracket's ends and the least
        // of the greater over the search: take the upper end, unless a ball was missed.
        let cusp = if best.is_finite() {
            best
        } else {
            let (a0, b0) = left(lo)?;
            let (a1, b1) = left(hi)?;
            a0.min(b0).max(a1.min(b1))
        };
        if cusp.is_finite() {
            worst = worst.max(cusp);
        }
    }
    Ok(worst)
}

/// Checks the cusp between every two adjacent passes `ws` against `h` (mm); a gap whose
/// cusp is higher gets two more passes (splitting it in three keeps the count's parity, and
/// so the corner the zig-zag ends at), up to [`CUSP_SPLITS`] times. Returns the passes and
/// the highest cusp left.
fn cusp_checked(
    s: &dyn ParamSurface,
    dir: FeedDir,
    ws: Vec<f64>,
    h: f64,
    r: f64,
) -> Result<(Vec<f64>, f64)> {
    let mut out = vec![ws[0]];
    let mut worst: f64 = 0.0;
    let tol = CUSP_LOCATE_SHARE * h;
    // The gaps come in order across the patch: each one's first pass is the last one's second.
    let mut last: (f64, Vec<Sweep>) = (ws[0], sweeps(s, dir, ws[0], r)?);
    for pair in ws.windows(2) {
        // Gaps still to check, last first, with how often each was split.
        let mut todo = vec![(pair[0], pair[1], 0usize)];
        while let Some((a, b, depth)) = todo.pop() {
            let first = if last.0 == a {
                std::mem::take(&mut last.1)
            } else {
                sweeps(s, dir, a, r)?
            };
            let second = sweeps(s, dir, b, r)?;
            let c = cusp_between(s, dir, (a, &first), (b, &second), r, tol)?;
            last = (b, second);
            if c > h * (1.0 + CUSP_SLACK) && depth < CUSP_SPLITS {
                let d = (b - a) / 3.0;
                todo.extend([
                    (a + 2.0 * d, b, depth + 1),
                    (a + d, a + 2.0 * d, depth + 1),
                    (a, a + d, depth + 1),
                ]);
                continue;
            }
            worst = worst.max(c);
            out.push(b);
        }
    }
    Ok((out, worst))
}

/// Contact point and unit normal on a pass.
fn pass_point(s: &dyn ParamSurface, dir: FeedDir, t: f64, w: f64) -> Result<(Point3, Vector3)> {
    let (u, v) = at(dir, t, w);
    with_normal(s, u, v, s.point_normal(u, v))
}

/// [`pass_point`] from `line`, the surface's line along `dir` at `w`.
fn line_point(
    s: &dyn ParamSurface,
    line: &mut dyn ParamLine,
    dir: FeedDir,
    t: f64,
    w: f64,
) -> Result<(Point3, Vector3)> {
    let (u, v) = at(dir, t, w);
    with_normal(s, u, v, line.point_normal(t))
}

/// A contact point with its normal, or the error that `(u, v)` of `s` has none.
fn with_normal(
    s: &dyn ParamSurface,
    u: f64,
    v: f64,
    (p, n): (Point3, Option<Vector3>),
) -> Result<(Point3, Vector3)> {
    let n = n.ok_or_else(|| Error::Degenerate {
        location: format!("{} at (u, v) = ({u:.6}, {v:.6})", s.label()),
        message: "the surface has no tangent plane here or nearby".into(),
    })?;
    Ok((p, n))
}

/// How far a straight move may stray from the curve it replaces (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChordLimits {
    /// Chord of the contact curve from the curve, either way.
    pub contact: f64,
    /// Chord of the ball-centre curve below that curve: the ball cuts into the surface.
    pub overcut: f64,
    /// Chord of the ball-centre curve above it: material left, which adds to the scallop.
    pub leave: f64,
}

/// Moving-parameter values along the pass at `w` so that chords stay within `lim`, each
/// with its contact point and unit normal.
pub fn forward_steps(
    s: &dyn ParamSurface,
    dir: FeedDir,
    w: f64,
    lim: ChordLimits,
    r: f64,
) -> Result<Vec<(f64, Point3, Vector3)>> {
    let (tol, dip, leave) = (lim.contact, lim.overcut, lim.leave);
    let mut t = 0.0;
    let mut line = s.line(dir, w);
    let mut p0 = line_point(s, &mut *line, dir, 0.0, w)?;
    let mut out = vec![(0.0, p0.0, p0.1)];
    // Points of the last try by parameter: halving a step makes its middle the next try's
    // end and its quarter the next try's middle.
    let mut tried: Vec<(f64, (Point3, Vector3))> = Vec::with_capacity(4);
    let mut now: Vec<(f64, (Point3, Vector3))> = Vec::with_capacity(4);
    let point = |line: &mut dyn ParamLine,
                 x: f64,
                 tried: &[(f64, (Point3, Vector3))]|
     -> Result<(Point3, Vector3)> {
        match tried.iter().find(|(y, _)| *y == x) {
            Some(&(_, p)) => Ok(p),
            None => line_point(s, line, dir, x, w),
        }
    };
    while t < 1.0 {
        let d = line.derivs(t);
        let (c1, c2) = match dir {
            FeedDir::AlongU => (d.su, d.suu),
            FeedDir::AlongV => (d.sv, d.svv),
        };
        let speed = c1.norm();
        let k = stepover::curve_curvature(&c1, &c2);
        // Bound the curvature of the ball-centre curve too (radius shrinks by r on concave).
        let k_cl = if k * r < 0.5 {
            k / (1.0 - k * r)
        } else {
            2.0 * k
        };
        let first = if speed > 0.0 {
            stepover::chord_step(tol.min(dip), k_cl) / speed
        } else {
            1e-3
        };
        let mut dt = first.min(1.0 - t).min(0.125);
        let mut accepted = None;
        tried.clear();
        for _ in 0..MAX_HALVINGS {
            now.clear();
            let p1 = point(&mut *line, t + dt, &tried)?;
            now.push((t + dt, p1));
            let cl = |p: &(Point3, Vector3)| p.0 + p.1 * r;
            let (a, b) = (cl(&p0), cl(&p1));
            let ab = b - a;
            // The chord against the curve at a quarter, half and three quarters of the step
            // (where the curvature varies the largest gap is off the middle).
            let mut ok = true;
            for f in CHORD_PROBES {
                let pm = point(&mut *line, t + f * dt, &tried)?;
                now.push((t + f * dt, pm));
                let m = cl(&pm);
                let along = if ab.norm_squared() > 0.0 {
                    ((m - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let off = m - (a + ab * along);
                // The curve above the chord (along the normal): the chord dips into the material.
                let cl_tol = if off.dot(&pm.1) >= 0.0 { dip } else { leave };
                if dist_to_segment(&pm.0, &p0.0, &p1.0) > tol || off.norm() > cl_tol {
                    ok = false;
                    break;
                }
            }
            if ok {
                accepted = Some(p1);
                break;
            }
            std::mem::swap(&mut tried, &mut now);
            dt *= 0.5;
        }
        let Some(p1) = accepted else {
            return Err(Error::Degenerate {
                location: format!("{} near parameter {t:.6}", s.label()),
                message: "the chordal tolerance cannot be met (a crease or cusp?)".into(),
            });
        };
        if 1.0 - (t + dt) < 1e-12 {
            // The pass ends exactly at its side.
            t = 1.0;
            p0 = line_point(s, &mut *line, dir, 1.0, w)?;
        } else {
            t += dt;
            p0 = p1;
        }
        out.push((t, p0.0, p0.1));
    }
    Ok(out)
}

/// Identity of each patch corner: corners at the same point share an id.
pub fn corner_ids(model: &Model) -> Vec<[u32; 4]> {
    let tol = CORNER_MATCH_REL * model.surface.bbox().diagonal().max(1.0);
    let mut points: Vec<Point3> = Vec::new();
    model
        .layout
        .patches
        .iter()
        .map(|p| {
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| {
                let q = p.subs(&model.surface, u, v);
                match points.iter().position(|x| (x - q).norm() <= tol) {
                    Some(i) => i as u32,
                    None => {
                        points.push(q);
                        (points.len() - 1) as u32
                    }
                }
            })
        })
        .collect()
}

/// Travelling-salesman costs between the model's patches: the layout's connections, and
/// patches whose corners coincide in space (across a crease's zero-width faces the layout
/// sees no shared edge, but the tool can pass): two shared corners make a boundary
/// connection, one a corner connection.
pub fn patch_costs(model: &Model) -> CostMatrix {
    let mut m = CostMatrix::new(model.layout.len());
    for c in &model.layout.connections {
        let cost = match c.kind {
            ConnectionKind::Boundary => order::BOUNDARY_COST,
            ConnectionKind::Corner => order::CORNER_COST,
        };
        m.connect(c.a as usize, c.b as usize, cost);
    }
    let ids = corner_ids(model);
    for a in 0..ids.len() {
        for b in a + 1..ids.len() {
            let shared = ids[a].iter().filter(|x| ids[b].contains(x)).count();
            match shared {
                0 => {}
                1 => m.connect(a, b, order::CORNER_COST),
                _ => m.connect(a, b, order::BOUNDARY_COST),
            }
        }
    }
    m
}

/// Arc length of a patch's iso-lines: the total path length of a zig-zag with crossfeed
/// `c` is about the length of one pass times the number of passes, which goes with the
/// length across; so the shorter path crosses the longer way.
pub fn preferred_crossfeed(view: &PatchView) -> Crossfeed {
    longer_side_crossfeed(side_lengths_mm(view))
}

/// The crossfeed that cuts along the longer of a patch's sides (`[along u, along v]`, mm):
/// passes along u (crossfeed V) are as long as the u-lines, and there are as many as the
/// v-extent needs; the path length is about len_u · len_v / g either way, but fewer, longer
/// passes mean fewer reversals.
pub fn longer_side_crossfeed([len_u, len_v]: [f64; 2]) -> Crossfeed {
    if len_u >= len_v {
        Crossfeed::V
    } else {
        Crossfeed::U
    }
}

/// Lengths (mm) of a patch's sides on the surface, `[along u, along v]`: the mean of the
/// iso-lines at a quarter, half and three quarters across, each in 16 chords.
pub fn side_lengths_mm(view: &PatchView) -> [f64; 2] {
    [true, false].map(|along_u| {
        let mut total = 0.0;
        for w in [0.25, 0.5, 0.75] {
            let mut prev = if along_u {
                view.subs(0.0, w)
            } else {
                view.subs(w, 0.0)
            };
            for k in 1..=16 {
                let t = k as f64 / 16.0;
                let p = if along_u {
                    view.subs(t, w)
                } else {
                    view.subs(w, t)
                };
                total += (p - prev).norm();
                prev = p;
            }
        }
        total / 3.0
    })
}

/// Plans the whole model: the zig-zags ([`draft`]) through the shared pipeline (tool
/// axes, lifting, rest area, air moves). `progress` receives the fraction done and returns
/// `false` to cancel.
pub fn plan(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Planned> {
    super::pipeline::plan_with(model, opts, progress, DRAFT_SHARE, |p| {
        draft(model, opts, p)
    })
}

/// Share of the progress bar the zig-zags take (the pipeline takes the rest).
const DRAFT_SHARE: f64 = 0.7;

/// The patch order, transit corners and per-patch zig-zags, as a draft for the pipeline.
pub fn draft(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Draft> {
    draft_with(model, opts, progress, None, &[], "isoparametric")
}

/// As [`draft`], with each patch's crossfeed given (`crossfeeds`, one per patch; the
/// option's or the longer side's otherwise), the draft named `strategy`. A crossfeed given
/// here or in the options is kept even where that costs a retraction; the longer side's
/// gives way where turning the patch lets the path go on without one.
///
/// `seams[k]` (empty: none) says whether patch `k`'s pass on its side at across-parameter
/// 0 and at 1 is a neighbour's to cut (the neighbour's passes run the same way and it
/// keeps its pass there, [`crate::plan::watershed::rects::shared_seams`]): that pass is
/// left out, and the pass one side step in is the first. A patch of two passes leaves
/// only the one at across-parameter 0. The transit from the previous patch's finishing
/// corner, and to the next one's starting corner, runs along the side to the first pass
/// and from the last. Seams count only with the crossfeeds given (`crossfeeds` or the
/// options): a patch turned across would leave a pass that is no seam's.
pub fn draft_with(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
    crossfeeds: Option<&[Crossfeed]>,
    seams: &[[bool; 2]],
    strategy: &'static str,
) -> Result<Draft> {
    opts.validate()?;
    let np = model.layout.len();
    if np == 0 {
        return Err(Error::InvalidMesh(
            "the model has no patches to machine".into(),
        ));
    }
    for (name, p) in [
        ("start_patch", opts.start_patch),
        ("finish_patch", opts.finish_patch),
    ] {
        if let Some(p) = p {
            if p as usize >= np {
                return Err(Error::param(
                    name,
                    format!(
                        "patch {p} does not exist; the model has patches 0 to {}",
                        np - 1
                    ),
                ));
            }
        }
    }
    let r = opts.tool_radius_mm;
    let views = patch_views(model);
    let preferred: Vec<Crossfeed> = views
        .iter()
        .map(
            |v| match (crossfeeds.and_then(|c| c.get(v.index)), opts.crossfeed) {
                (Some(&c), _) | (None, Some(c)) => c,
                (None, None) => preferred_crossfeed(v),
            },
        )
        .collect();
    let start = opts.start_patch.unwrap_or(0) as usize;
    let finish = opts
        .finish_patch
        .map(|f| f as usize)
        .filter(|&f| f != start || np == 1);
    let costs = patch_costs(model);
    let ids = corner_ids(model);
    let order = order::patch_order(&costs, start, finish);
    // Crossfeeds given are kept; the longer side's may turn to save a retraction.
    let strict = crossfeeds.is_some() || opts.crossfeed.is_some();
    // The scallop budget: most to the side step, the rest to the material a straight move
    // leaves above a surface that is concave along the feed.
    // Eq. 5 is the small-h form of the circle geometry and comes out low by about
    // h/(2r); ask it for correspondingly less.
    let h_target = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
    let h_side = h_target / (1.0 + h_target / (2.0 * r));
    // With the crossfeeds kept, where each patch finishes along its passes is what the
    // corners still choose: the end its own pass count reaches saves a pass at a smaller
    // side step.
    // (Each patch's profile, made for that, then serves its passes: kept crossfeeds are
    // the ones cut.)
    let mut profiles: Vec<Option<StepProfile>> = if strict {
        views
            .iter()
            .zip(&preferred)
            .map(|(v, &c)| StepProfile::new(v, feed_dir(c), h_side, r).map(Some))
            .collect::<Result<_>>()?
    } else {
        views.iter().map(|_| None).collect()
    };
    // Each patch's pass count at the scallop asked, where its profile is made already.
    let natural: Vec<Option<usize>> = profiles
        .iter()
        .map(|p| p.as_ref().map(|p| p.passes(h_side).len()))
        .collect();
    // Per patch, the boundary passes left to neighbours (at across-parameter 0 and 1).
    let left_out: Vec<[bool; 2]> = (0..np)
        .map(|k| {
            let given = seams
                .get(k)
                .copied()
                .filter(|_| strict)
                .unwrap_or([false; 2]);
            // A patch of two passes leaving both would have none of its own.
            if given == [true, true] && natural[k].is_none_or(|n| n <= 2) {
                [true, false]
            } else {
                given
            }
        })
        .collect();
    let dropped = |k: usize| left_out[k].iter().filter(|&&x| x).count();
    let natural_odd: Option<Vec<bool>> = strict.then(|| {
        natural
            .iter()
            .enumerate()
            .filter_map(|(k, n)| Some((n.as_ref()? - dropped(k)) % 2 == 1))
            .collect()
    });
    let (transits, forced) = corners::select(
        &order,
        &ids,
        &preferred,
        strict,
        natural_odd.as_deref(),
        None,
    );
    let mut out = DraftBuilder::new(model, opts);
    let mut runs: Vec<PatchRun> = Vec::new();
    let mut worst: f64 = 0.0;
    for (k, tr) in transits.iter().enumerate() {
        let view = &views[tr.patch];
        let (su, sv) = corners::corner_uv(tr.start_corner);
        let dir = feed_dir(tr.crossfeed);
        let odd = corners::finishes_odd(tr.start_corner, tr.finish_corner, tr.crossfeed);
        let leave = opts.chordal_mm.min(CHORD_SCALLOP_SHARE * opts.scallop_mm);
        let profile = match profiles[tr.patch].take() {
            Some(p) => p,
            None => StepProfile::new(view, dir, h_side, r)?,
        };
        // The passes with those on seams a neighbour cuts: its pass stands for this one's
        // in the tuning and the checks.
        let left = left_out[tr.patch];
        let odd_all = odd != (dropped(tr.patch) % 2 == 1);
        let (ws, h_used, pred) = tuned_passes(view, dir, &profile, odd_all, h_side, r)?;
        // Eq. 5 sees the curvature of each face, not the kinks between faces (a convex
        // crease between two passes widens their cusp by about r times its angle): the
        // cusps between the passes are computed from the two balls and split where too high.
        let (mut ws, cusp) = cusp_checked(view, dir, ws, h_target, r)?;
        worst = worst.max(pred).max(cusp);
        if left[1] {
            ws.pop();
        }
        if left[0] {
            ws.remove(0);
        }
        // How far across the first and last passes' strips reach: to the seam where the
        // pass on it is left out.
        let mut ends = [
            if left[0] { 0.0 } else { ws[0] },
            if left[1] { 1.0 } else { ws[ws.len() - 1] },
        ];
        // The passes start on the start corner's side and each runs away from the corner's
        // coordinate along the pass first.
        let (w_start, t_start) = match dir {
            FeedDir::AlongV => (su, sv),
            FeedDir::AlongU => (sv, su),
        };
        if w_start == 1 {
            ws.reverse();
            ends.reverse();
        }
        let first_move = out.len();
        let nlines = ws.len();
        let patch = tr.patch as u32;
        // The strip across the passes each pass stands for: half-way to its neighbours.
        let strip = |li: usize| -> (f64, f64) {
            let w = ws[li];
            let lo = if li > 0 {
                0.5 * (ws[li - 1] + w)
            } else {
                ends[0]
            };
            let hi = if li + 1 < nlines {
                0.5 * (w + ws[li + 1])
            } else {
                ends[1]
            };
            (lo.min(hi), lo.max(hi))
        };
        for (li, &w) in ws.iter().enumerate() {
            let limits = ChordLimits {
                contact: CHORD_MARGIN * opts.chordal_mm,
                overcut: CHORD_MARGIN * opts.overcut_mm(),
                leave,
            };
            let mut steps = forward_steps(view, dir, w, limits, r)?;
            let reversed = (li % 2 == 1) != (t_start == 1);
            if reversed {
                steps.reverse();
            }
            let ts: Vec<f64> = steps.iter().map(|s| s.0).collect();
            let (w0, w1) = strip(li);
            for (j, &(t, cc, n)) in steps.iter().enumerate() {
                let (pu, pv) = at(dir, t, w);
                let p = SurfacePoint {
                    patch,
                    uv: [pu, pv],
                    cc,
                    normal: n,
                };
                // Along the pass: half-way to the neighbouring points.
                let t0 = if j > 0 { 0.5 * (ts[j - 1] + t) } else { t };
                let t1 = if j + 1 < ts.len() {
                    0.5 * (t + ts[j + 1])
                } else {
                    t
                };
                let (t0, t1) = (t0.min(t1), t0.max(t1));
                let fp = Footprint {
                    patch,
                    rect: match dir {
                        FeedDir::AlongU => [t0, t1, w0, w1],
                        FeedDir::AlongV => [w0, w1, t0, t1],
                    },
                };
                let line = li as u32;
                if j == 0 {
                    if li == 0 {
                        if k == 0 || tr.retract_before {
                            out.approach(&p, line, fp);
                        } else {
                            // Transit from the previous patch's finishing corner: along
                            // the side to the first pass where the pass on the seam is a
                            // neighbour's.
                            if ends[0] != w {
                                link_between(
                                    view, dir, &mut out, ends[0], w, t, opts, r, patch, line,
                                )?;
                            }
                            out.link(&p, line, fp);
                        }
                    } else {
                        link_between(view, dir, &mut out, ws[li - 1], w, t, opts, r, patch, line)?;
                        out.link(&p, line, fp);
                    }
                } else {
                    out.feed(&p, line, fp);
                }
            }
            let frac = (k as f64 + (li + 1) as f64 / nlines as f64) / transits.len() as f64;
            if !progress(frac) {
                return Err(Error::Cancelled);
            }
        }
        // Where the pass on the finishing seam is a neighbour's, along the side to the
        // finishing corner, where the next patch's transit starts.
        let last = nlines - 1;
        if ends[1] != ws[last] && transits.get(k + 1).is_some_and(|n| !n.retract_before) {
            let line = last as u32;
            // The last pass runs towards t = 1 unless the zig-zag turned it round.
            let t_end = if (last % 2 == 1) != (t_start == 1) {
                0.0
            } else {
                1.0
            };
            link_between(
                view, dir, &mut out, ws[last], ends[1], t_end, opts, r, patch, line,
            )?;
            let corner = surface_point(view, dir, t_end, ends[1], patch)?;
            out.link(&corner, line, Footprint::NONE);
        }
        runs.push(PatchRun {
            patch: tr.patch as u32,
            start_corner: tr.start_corner,
            finish_corner: tr.finish_corner,
            crossfeed: tr.crossfeed,
            passes: nlines,
            scallop_used_mm: h_used,
            retract_before: tr.retract_before || k == 0,
            first_move,
            last_move: out.len() - 1,
        });
    }
    Ok(out.finish(strategy, runs, worst, forced))
}

/// Feed moves along the patch boundary from pass `w0` to pass `w1` at parameter `t`, split
/// where one straight link would leave the chordal tolerance (the last point is added by the
/// caller). They add no area of their own: the passes' footprints cover the boundary.
#[allow(clippy::too_many_arguments)]
fn link_between(
    s: &dyn ParamSurface,
    dir: FeedDir,
    out: &mut DraftBuilder,
    w0: f64,
    w1: f64,
    t: f64,
    opts: &PlanOptions,
    r: f64,
    patch: u32,
    line: u32,
) -> Result<()> {
    let other = dir.other();
    let (a, b) = (w0.min(w1), w0.max(w1));
    // Points between the passes on the boundary line, by the same chordal rule.
    let mut inner = Vec::new();
    let mut cur = a;
    let mut p0 = pass_point(s, other, a, t)?;
    while b - cur > 1e-12 {
        let mut dt = b - cur;
        for _ in 0..MAX_HALVINGS {
            let pm = pass_point(s, other, cur + 0.5 * dt, t)?;
            let p1 = pass_point(s, other, cur + dt, t)?;
            let cl = |p: &(Point3, Vector3)| p.0 + p.1 * r;
            if dist_to_segment(&pm.0, &p0.0, &p1.0) <= opts.chordal_mm
                && dist_to_segment(&cl(&pm), &cl(&p0), &cl(&p1)) <= opts.overcut_mm()
            {
                break;
            }
            dt *= 0.5;
        }
        cur += dt;
        if b - cur > 1e-12 {
            inner.push(cur);
        }
        p0 = pass_point(s, other, cur, t)?;
    }
    if w1 < w0 {
        inner.reverse();
    }
    for w in inner {
        out.link(
            &surface_point(s, other, w, t, patch)?,
            line,
            Footprint::NONE,
        );
    }
    Ok(())
}

/// The point of patch `patch` at `t` along the pass at `w` (contact point and normal).
fn surface_point(
    s: &dyn ParamSurface,
    dir: FeedDir,
    t: f64,
    w: f64,
    patch: u32,
) -> Result<SurfacePoint> {
    let (cc, normal) = pass_point(s, dir, t, w)?;
    let (u, v) = at(dir, t, w);
    Ok(SurfacePoint {
        patch,
        uv: [u, v],
        cc,
        normal,
    })
}

/// The planned tool path alone (see [`plan`]).
pub fn plan_zigzag(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Toolpath> {
    plan(model, opts, progress).map(|p| p.toolpath)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ball-centre curve's tangent from the derivatives against a central difference of
    /// ball centres (the second method), along both parameters, on samples machined from
    /// either side.
    #[test]
    fn sweep_tangents_match_finite_differences_of_the_ball_centre_curve() {
        let r = 0.7;
        let mut checked = 0;
        for name in ["keycap-convex", "keycap-concave", "bumps", "tjunction"] {
            let model = crate::model::samples::load_sample(name).unwrap();
            for view in patch_views(&model) {
                for dir in [FeedDir::AlongU, FeedDir::AlongV] {
                    for w in [0.13, 0.5, 0.91] {
                        let got = sweeps(&view, dir, w, r).unwrap();
                        for (t, sweep) in pass_samples().zip(&got) {
                            if !(0.01..=0.99).contains(&t) {
                                continue;
                            }
                            let cl = |t: f64| {
                                let (p, n) = pass_point(&view, dir, t, w).unwrap();
                                p + n * r
                            };
                            let h = 1e-6;
                            let fd = (cl(t + h) - cl(t - h)).normalize();
                            let angle = sweep.tangent.angle(&fd);
                            assert!(
                                angle < 1e-4,
                                "{name} patch {} {dir:?} w {w} t {t}: {angle} rad",
                                view.index
                            );
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 1000, "{checked} tangents");
    }
}
