//! Tool axis: the direction closest to +Z for which the shank and holder (cylinders above the
//! cutting part) stay clear of the model, smoothed along the path, with optional lead and
//! tilt.
//!
//! The ball itself cannot gouge where it touches (the side step keeps concave radii larger
//! than the ball), and the fluted length above it cuts; the non-cutting shank above the
//! flutes and the holder above the shank can hit walls elsewhere. A candidate axis is clear
//! when no triangle of a tessellation of the model meets the shank or holder cylinder grown
//! by the tessellation's deviation ([`super::clearance`]). Where +Z is not clear, the tool
//! leans the way the previous point leaned (or the nearest way that is clear), else away
//! from the obstacle, at the least clear tilt that way, found by a galloping search from
//! the previous point's tilt. The least clear tilt changes
//! continuously as the tool nears a wall, so the axis turns gradually without smoothing,
//! and it is +Z wherever +Z is clear.

use super::clearance::Clearance;
use super::reach::Why;
use super::toolpath::{Move, MoveKind, Toolpath};
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};

/// Azimuths tried around +Z when the usual ones fail.
const AZIMUTHS: usize = 12;
/// Resolution of the least clear tilt (degrees): tilts are whole multiples of it. Two
/// decimals, so that a tilt printed to four (the program's angles) never sits on a rounding
/// tie that the last bit of an arc cosine could tip either way.
const TILT_RESOLUTION_DEG: f64 = 0.08;
/// Step of the coarse tilt search, in resolutions (64 × 0.08° = 5.12°).
const TILT_STEP_UNITS: i64 = 64;
/// Least cosine between the tool axis and the surface normal at the contact point: the
/// tool must come from the side the surface faces (else its flutes and shank run into the
/// part behind the contact, as under a closed part's bottom) (cos 88°).
const MIN_AXIS_NORMAL_COS: f64 = 0.035;

/// True if `axis` comes from the side the surface faces at the contact (unit normal `n`)
/// and the shank and holder along it at ball centre `c` are clear.
pub(super) fn usable(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    axis: &Vector3,
    opts: &PlanOptions,
) -> bool {
    usable_by(obs, (c, n), axis, opts, true)
}

/// [`usable`], with the holder tested only if `holder` (else the shank alone).
fn usable_by(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    axis: &Vector3,
    opts: &PlanOptions,
    holder: bool,
) -> bool {
    axis.dot(n) >= MIN_AXIS_NORMAL_COS
        && if holder {
            obs.clear(c, axis, opts)
        } else {
            obs.shank_clear(c, axis, opts)
        }
}

/// The sample the vertical tool at ball centre `c` hits, or the contact point `cc` itself
/// where the surface faces away from +Z.
fn vertical_hit(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    cc: &Point3,
    opts: &PlanOptions,
) -> Option<Point3> {
    if n.z < MIN_AXIS_NORMAL_COS {
        return Some(*cc);
    }
    obs.hit(c, &Vector3::z(), opts)
}

/// Unit contact normal of a move (from the contact point to the ball centre).
pub(super) fn contact_normal(m: &Move) -> Vector3 {
    (m.cl_point - m.cc_point)
        .try_normalize(AXIS_MIN_NORM)
        .unwrap_or_else(Vector3::z)
}

/// Azimuths either side of "away from the obstacle" also tried (radians, 30°).
const SIDE_AZIMUTH: f64 = std::f64::consts::FRAC_PI_6;

/// Axes this close to +Z (1 − cos of the angle) count as vertical.
const VERTICAL_COS_SLACK: f64 = 1e-15;

/// Unit axis tilted `theta` (radians) from +Z towards azimuth `phi`.
pub(super) fn tilted(theta: f64, phi: f64) -> Vector3 {
    Vector3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The least tilt (radians) along azimuth `phi` at which the tool is clear, to within
/// [`TILT_RESOLUTION_DEG`]. From a `hint` (the tilt expected from the points before: it
/// changes smoothly from point to point) the search gallops down while clear or up while
/// not, in steps of one resolution, one more, then doubling up to [`TILT_STEP_UNITS`], and
/// bisects the last step; so the hinted tilt costs two tests, one a resolution either side
/// two or three. Without a hint it starts from the vertical in steps of [`TILT_STEP_UNITS`]
/// up to the largest allowed.
pub(super) fn least_tilt(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    opts: &PlanOptions,
    phi: f64,
    hint: Option<f64>,
) -> Option<f64> {
    // Tilts are whole multiples of the resolution (the largest tilt capping them), and the
    // search counts in those units: which tilts are tried, and how many bisections, never
    // hang on the rounding of a difference (the same plan natively and in wasm).
    let max = opts.max_tilt_deg.max(0.0).to_radians();
    let res = TILT_RESOLUTION_DEG.to_radians();
    let top = (max / res).ceil() as i64;
    let tilt = |k: i64| (k as f64 * res).min(max);
    let clear = |k: i64| usable(obs, (c, n), &tilted(tilt(k), phi), opts);
    let hint = hint.map(|h| ((h / res).round() as i64).clamp(1, top.max(1)));
    least_clear_unit(top, hint, clear).map(tilt)
}

/// The search of [`least_tilt`] in whole resolutions: the least `k` in `1..=top` for which
/// `clear(k)` holds (where clear tilts are all those from some least one up, which the
/// search assumes; elsewhere a clear `k` whose neighbour below is blocked), from the hinted
/// `k` or without one from 0 (`clear(0)` is never asked: the caller found the vertical
/// blocked).
fn least_clear_unit(
    top: i64,
    hint: Option<i64>,
    mut clear: impl FnMut(i64) -> bool,
) -> Option<i64> {
    // `hi` clear, `lo` not (or zero, where the vertical was found not clear).
    let (mut lo, mut hi) = match hint {
        Some(h) if clear(h) => {
            let (mut hi, mut steps) = (h, 0);
            loop {
                let lo = (hi - gallop_step(steps)).max(0);
                if lo == 0 || !clear(lo) {
                    break (lo, hi);
                }
                hi = lo;
                steps += 1;
            }
        }
        Some(h) => {
            let (mut lo, mut steps) = (h, 0);
            loop {
                if lo >= top {
                    return None;
                }
                let hi = (lo + gallop_step(steps)).min(top);
                if clear(hi) {
                    break (lo, hi);
                }
                lo = hi;
                steps += 1;
            }
        }
        None => {
            // `lo`: the last tilt found blocked (the vertical at first).
            let (mut lo, mut hi) = (0, TILT_STEP_UNITS.min(top));
            loop {
                if clear(hi) {
                    break (lo, hi);
                }
                if hi >= top {
                    return None;
                }
                lo = hi;
                hi = (hi + TILT_STEP_UNITS).min(top);
            }
        }
    };
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if clear(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The `k`-th step (counting from 0) of [`least_tilt`]'s gallop from a hint, in
/// resolutions: 1, 1, 2, 4, … up to [`TILT_STEP_UNITS`].
fn gallop_step(k: u32) -> i64 {
    (1i64 << k.saturating_sub(1).min(6)).min(TILT_STEP_UNITS)
}

/// A clear axis at `c`, continuing the previous point's lean: the least clear tilt along
/// its azimuth or the nearest clear one; else away from the sample the vertical tool hits;
/// failing those, around the circle. The searches start from the previous point's tilt
/// plus `trend` (radians: how much the tilt changed from the point before it, 0 where
/// unknown; the least clear tilt changes smoothly along a pass, so that is close).
fn clear_axis(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    opts: &PlanOptions,
    (prev, trend): (&Vector3, f64),
    hit: &Point3,
) -> Option<Vector3> {
    let away = (c.y - hit.y).atan2(c.x - hit.x);
    let hint = (prev.z < 1.0 - VERTICAL_COS_SLACK)
        .then(|| (prev.z.clamp(-1.0, 1.0).acos() + trend).max(0.0));
    // Keep turning the way the previous point did, at the least tilt clear that way, even
    // where another way needs less: the axis then does not swing round between
    // neighbouring points (on the head at h = 0.05 mm, switching to a way needing 5° less
    // swung the axis by more than 30° between neighbours 433 times, mean tilt 20.7°;
    // keeping the way, twice, mean tilt 33°). Where the previous azimuth has no clear tilt,
    // the nearest that has (turning either way in steps of `NEAR_AZIMUTH_STEP`).
    let kept = hint.and_then(|_| {
        let phi0 = prev.y.atan2(prev.x);
        (0..=NEAR_AZIMUTH_STEPS).find_map(|k| {
            let turn = k as f64 * NEAR_AZIMUTH_STEP.to_radians();
            let sides: &[f64] = if k == 0 { &[0.0] } else { &[turn, -turn] };
            sides
                .iter()
                .filter_map(|&d| {
                    least_tilt(obs, (c, n), opts, phi0 + d, hint).map(|t| (t, phi0 + d))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
        })
    });
    // Otherwise (or leaving +Z) the least tilt away from the sample the vertical tool hits
    // and a little either side of that; failing those, around the circle.
    let chosen = kept
        .or_else(|| {
            [away, away + SIDE_AZIMUTH, away - SIDE_AZIMUTH]
                .iter()
                .filter_map(|&phi| least_tilt(obs, (c, n), opts, phi, hint).map(|t| (t, phi)))
                .min_by(|a, b| a.0.total_cmp(&b.0))
        })
        .or_else(|| {
            (0..AZIMUTHS).find_map(|k| {
                let phi = away + k as f64 * std::f64::consts::TAU / AZIMUTHS as f64;
                least_tilt(obs, (c, n), opts, phi, None).map(|t| (t, phi))
            })
        })?;
    Some(tilted(chosen.0, chosen.1))
}

/// Azimuth steps (degrees) and how many either way are tried near the previous point's
/// azimuth when it is blocked.
const NEAR_AZIMUTH_STEP: f64 = 15.0;
const NEAR_AZIMUTH_STEPS: usize = 6;

/// Rotates `v` about unit `k` by `angle` (Rodrigues).
fn rotate(v: &Vector3, k: &Vector3, angle: f64) -> Vector3 {
    let (s, c) = angle.sin_cos();
    v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c))
}

/// What the axis assignment found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisStats {
    /// Points where the axis left +Z to clear the shank or holder.
    pub tilted: usize,
    /// Points where no axis within the allowed tilt is clear (three-axis: where +Z hits).
    pub blocked: usize,
    /// Of the blocked points, those where the surface faces away from +Z (three-axis: the
    /// tool would come from behind the surface).
    pub facing_away: usize,
    /// The first of those, for the report.
    pub first_blocked: Option<Point3>,
    /// Moves between two cut points whose axis turn was split into smaller clear turns
    /// (where it was blocked or larger than `max_axis_step_deg`).
    pub bridged: usize,
    /// Moves between two cut points during which the turning tool's shank or holder
    /// still comes within the safety margin of the model (poses checked as close together
    /// as the margin needs: [`Clearance::sweep_poses`]).
    pub sweep_hits: usize,
    /// That safety margin: the tessellations' deviation from the surface (mm) by which
    /// shank and holder are grown (the larger of the two).
    pub margin_mm: f64,
    /// The end of the first of those (ball centre, mm).
    pub first_sweep_hit: Option<Point3>,
    /// Windows of cut points whose axes were re-chosen along the pass to spread a large
    /// turn (see [`super::smooth`]).
    pub spread: usize,
}

/// True if a pose between cut points `a` and `b` (ball centre and axis interpolated
/// linearly, as close together as [`Clearance::sweep_poses`] needs for the grown cylinders
/// of the checked poses to hold the tool in between) puts the shank or holder into the
/// model.
pub(super) fn turn_blocked(a: &Move, b: &Move, obs: &Clearance, opts: &PlanOptions) -> bool {
    let counts = obs.sweep_poses(
        (&a.cl_point, &a.tool_axis),
        (&b.cl_point, &b.tool_axis),
        opts,
    );
    let poses = counts.shank.max(counts.holder);
    if poses <= 1 {
        return false;
    }
    // Where the holder needs no pose between the ends (they are checked), the shank alone.
    let holder = counts.holder > 1;
    let (na, nb) = (contact_normal(a), contact_normal(b));
    (1..poses).any(|k| {
        let s = k as f64 / poses as f64;
        let c = a.cl_point + (b.cl_point - a.cl_point) * s;
        let n = (na * (1.0 - s) + nb * s)
            .try_normalize(AXIS_MIN_NORM)
            .unwrap_or(nb);
        match (a.tool_axis * (1.0 - s) + b.tool_axis * s).try_normalize(AXIS_MIN_NORM) {
            Some(axis) => !usable_by(obs, (&c, &n), &axis, opts, holder),
            // Opposite axes: no defined turn, count it.
            None => true,
        }
    })
}

/// Halvings of a blocked turn before it is given up.
pub(super) const BRIDGE_DEPTH: usize = 6;

/// Appends to `out` cut points between `a` and `b` (at fractions of the way from `s0` to
/// `s1`) that split a blocked turn into clear ones, or a turn larger than
/// `max_axis_step_deg` into smaller ones: the midpoint of the chord with the halfway axis
/// for a clear turn; for a blocked one, +Z if that is clear, else the halfway axis if
/// clear, else the least clear tilt on the halfway azimuth, else the least tilt leaning
/// from `a`'s; then each half likewise. False if some turn stays blocked.
#[allow(clippy::too_many_arguments)]
pub(super) fn bridge(
    a: &Move,
    b: &Move,
    (s0, s1): (f64, f64),
    obs: &Clearance,
    opts: &PlanOptions,
    depth: usize,
    out: &mut Vec<(Move, f64)>,
) -> bool {
    let blocked = turn_blocked(a, b, obs, opts);
    let large = a.tool_axis.angle(&b.tool_axis) > opts.max_axis_step_deg.to_radians();
    if !blocked && !large {
        return true;
    }
    if depth == 0 {
        return !blocked;
    }
    let cl = Point3::from((a.cl_point.coords + b.cl_point.coords) * 0.5);
    let cc = Point3::from((a.cc_point.coords + b.cc_point.coords) * 0.5);
    let n = (contact_normal(a) + contact_normal(b))
        .try_normalize(AXIS_MIN_NORM)
        .unwrap_or_else(|| contact_normal(b));
    let half = (a.tool_axis + b.tool_axis).try_normalize(AXIS_MIN_NORM);
    // The halfway axis if clear; else the least clear tilt on its azimuth (the turn goes
    // round what blocks the straight one, as a tool at the largest tilt turning its
    // azimuth must).
    let halfway = || {
        half.filter(|x| within_tilt(x, opts) && usable(obs, (&cl, &n), x, opts))
            .or_else(|| {
                let x = half.filter(|x| x.z < 1.0 - VERTICAL_COS_SLACK)?;
                let phi = x.y.atan2(x.x);
                least_tilt(obs, (&cl, &n), opts, phi, Some(x.z.clamp(-1.0, 1.0).acos()))
                    .map(|t| tilted(t, phi))
            })
    };
    // Both halves through the pose with `axis` at the chord's midpoint.
    let halves = |axis: Vector3, out: &mut Vec<(Move, f64)>| {
        let mid = Move {
            cl_point: cl,
            cc_point: cc,
            tool_axis: axis,
            ..*b
        };
        let sm = 0.5 * (s0 + s1);
        let first = bridge(a, &mid, (s0, sm), obs, opts, depth - 1, out);
        out.push((mid, sm));
        let second = bridge(&mid, b, (sm, s1), obs, opts, depth - 1, out);
        first && second
    };
    if !blocked {
        // A clear turn that is only too large is split along its way, or left whole where
        // that is not clear or does not make the largest turn smaller: a split must never
        // make a clear turn blocked, nor larger.
        let Some(axis) = halfway() else {
            return true;
        };
        let kept = out.len();
        let clear = halves(axis, out);
        let axes: Vec<Vector3> = std::iter::once(a.tool_axis)
            .chain(out[kept..].iter().map(|(m, _)| m.tool_axis))
            .chain(std::iter::once(b.tool_axis))
            .collect();
        let largest = axes
            .windows(2)
            .map(|w| w[0].angle(&w[1]))
            .fold(0.0, f64::max);
        if !clear || largest >= a.tool_axis.angle(&b.tool_axis) {
            out.truncate(kept);
        }
        return true;
    }
    let axis = match vertical_hit(obs, (&cl, &n), &cc, opts) {
        None => Some(Vector3::z()),
        Some(h) => halfway().or_else(|| clear_axis(obs, (&cl, &n), opts, (&a.tool_axis, 0.0), &h)),
    };
    match axis {
        Some(axis) => halves(axis, out),
        None => false,
    }
}

/// Splits every turn of the axis between two cut points whose in-between poses would put
/// the shank or holder into the model (see [`bridge`]); counts the splits and the turns
/// that stay blocked.
pub fn bridge_turns(
    path: &mut Toolpath,
    obs: &Clearance,
    opts: &PlanOptions,
    stats: &mut AxisStats,
) {
    path.rebuild(|old, i, add| {
        let b = old.moves[i];
        let q = old.param(i);
        if i > 0
            && old.moves[i - 1].kind.on_surface()
            && matches!(b.kind, MoveKind::Feed | MoveKind::Link)
        {
            let mut inserted = Vec::new();
            let clear = bridge(
                &old.moves[i - 1],
                &b,
                (0.0, 1.0),
                obs,
                opts,
                BRIDGE_DEPTH,
                &mut inserted,
            );
            if !inserted.is_empty() {
                stats.bridged += 1;
            }
            let qa = old.param(i - 1);
            for (m, s) in inserted {
                add(m, [qa[0] + (q[0] - qa[0]) * s, qa[1] + (q[1] - qa[1]) * s]);
            }
            if !clear {
                stats.sweep_hits += 1;
                stats.first_sweep_hit.get_or_insert(b.cl_point);
            }
        }
        add(b, q);
    });
}

/// A unit vector perpendicular to unit `n`.
fn any_tangent(n: &Vector3) -> Vector3 {
    let other = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&other).normalize()
}

/// Whether unit axis `a` leans from +Z by no more than the largest tilt allowed.
pub(super) fn within_tilt(a: &Vector3, opts: &PlanOptions) -> bool {
    a.z >= opts.max_tilt_deg.max(0.0).to_radians().cos()
}

/// Shortest interpolated axis (before normalising) taken as a direction.
const AXIS_MIN_NORM: f64 = 1e-9;

/// Sets the tool axis of every cutting move of `path` (moves off the surface are left for
/// [`fill_air_axes`]): +Z where the shank and holder clear the model, else the least clear
/// tilt (up to `max_tilt_deg`; 0 plans three-axis). Returns what it found and, per move,
/// why it cannot be cut where no allowed axis is usable (the move keeps +Z then).
pub fn choose(
    obs: &Clearance,
    path: &mut Toolpath,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<(AxisStats, Vec<Option<Why>>)> {
    let n = path.moves.len();
    let mut prev = Vector3::z();
    // The move `prev` belongs to, and how much the tilt changed to it from the move before
    // (radians; 0 unless both were cut points one after the other, both tilted).
    let (mut prev_at, mut trend) = (None, 0.0);
    let mut stats = AxisStats::default();
    let mut why: Vec<Option<Why>> = vec![None; n];
    for i in 0..n {
        let m = path.moves[i];
        if !m.kind.on_surface() {
            continue;
        }
        let c = m.cl_point;
        let normal = contact_normal(&m);
        let mut axis = Vector3::z();
        if opts.lead_deg != 0.0 || opts.tilt_deg != 0.0 {
            // Lead and tilt are taken from the surface normal in the feed frame.
            let next = path
                .moves
                .get(i + 1)
                .filter(|x| x.kind.on_surface())
                .map(|x| x.cc_point);
            let before = i
                .checked_sub(1)
                .map(|j| path.moves[j])
                .filter(|x| x.kind.on_surface())
                .map(|x| x.cc_point);
            let feed = match (before, next) {
                (_, Some(q)) => q - m.cc_point,
                (Some(p), None) => m.cc_point - p,
                _ => Vector3::x(),
            };
            // In the tangent plane; where the feed is along the normal or nil (a lifted
            // point's contact repeated), any tangent: the frame must stay orthonormal, or
            // the rotations below give an axis that is not a unit vector.
            let feed = (feed - normal * feed.dot(&normal))
                .try_normalize(AXIS_MIN_NORM)
                .unwrap_or_else(|| any_tangent(&normal));
            let side = normal.cross(&feed);
            let a = rotate(&normal, &side, opts.lead_deg.to_radians());
            let a = rotate(&a, &feed, opts.tilt_deg.to_radians());
            // Within the largest tilt (issue 19: on a part's underside the normal with its
            // lead pointed up to 180° from +Z); else the search below, which keeps to it.
            if within_tilt(&a, opts) && usable(obs, (&c, &normal), &a, opts) {
                axis = a;
            }
        } else if opts.facet_normal_axis && m.tool_axis != Vector3::z() {
            // The strategy's own axis (iso-planar: the facets' area-weighted normal), within
            // the largest tilt.
            let a = m.tool_axis;
            if within_tilt(&a, opts) && usable(obs, (&c, &normal), &a, opts) {
                axis = a;
            }
        }
        let blocked_at = if axis == Vector3::z() {
            vertical_hit(obs, (&c, &normal), &m.cc_point, opts)
        } else {
            None
        };
        if let Some(h) = blocked_at {
            match (opts.max_tilt_deg > 0.0)
                .then(|| {
                    let trend = if prev_at == i.checked_sub(1) {
                        trend
                    } else {
                        0.0
                    };
                    clear_axis(obs, (&c, &normal), opts, (&prev, trend), &h)
                })
                .flatten()
            {
                Some(a) => {
                    axis = a;
                    stats.tilted += 1;
                }
                None => {
                    stats.blocked += 1;
                    // Facing away from every allowed axis: the normal further from +Z than
                    // the largest tilt and the most the axis may lean from the normal.
                    let from_z = normal.z.clamp(-1.0, 1.0).acos();
                    let faces_away = from_z
                        > opts.max_tilt_deg.max(0.0).to_radians() + MIN_AXIS_NORMAL_COS.acos();
                    if faces_away {
                        stats.facing_away += 1;
                        why[i] = Some(Why::FacesAway);
                    } else {
                        why[i] = Some(Why::ToolHits);
                    }
                    stats.first_blocked.get_or_insert(c);
                }
            }
        }
        path.moves[i].tool_axis = axis;
        if why[i].is_none() {
            let tilted = |a: &Vector3| a.z < 1.0 - VERTICAL_COS_SLACK;
            trend = if prev_at == i.checked_sub(1) && tilted(&prev) && tilted(&axis) {
                axis.z.clamp(-1.0, 1.0).acos() - prev.z.clamp(-1.0, 1.0).acos()
            } else {
                0.0
            };
            prev = axis;
            prev_at = Some(i);
        }
        if i % 512 == 0 && !progress(i as f64 / n as f64) {
            return Err(Error::Cancelled);
        }
    }
    stats.margin_mm = obs.gap_mm();
    progress(1.0);
    Ok((stats, why))
}

/// Gives every move off the surface the tool axis of the nearest cut: retracts keep the
/// axis of the cut they leave, rapids take that of the cut they come down to.
pub fn fill_air_axes(path: &mut Toolpath) {
    let n = path.moves.len();
    let mut last = None;
    for i in 0..n {
        if path.moves[i].kind.on_surface() {
            last = Some(path.moves[i].tool_axis);
        } else if let Some(a) = last {
            path.moves[i].tool_axis = a;
        }
    }
    let mut next = None;
    for i in (0..n).rev() {
        if path.moves[i].kind.on_surface() {
            next = Some(path.moves[i].tool_axis);
        } else if path.moves[i].kind == MoveKind::Rapid {
            if let Some(a) = next {
                path.moves[i].tool_axis = a;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tilt_search_finds_the_least_clear_tilt_from_any_hint_and_two_tests_from_the_right_one() {
        // Clear from `least` up: every hint (none, the answer, near it, far from it, past
        // the top) finds `least`; the hinted answer costs two tests, one either side at most
        // three (the hint is the tilt extrapolated along the pass: mostly that close).
        let top = 1500;
        for least in [1, 2, 3, 17, 64, 65, 700, 1499, 1500] {
            // Hints as the caller gives them: within 1..=top.
            let hints = [None, Some(least), Some(least - 1), Some(least + 1)]
                .into_iter()
                .chain([-300, -40, -7, -2, 2, 7, 40, 300].map(|d| Some(least + d)))
                .map(|h| h.map(|h| h.clamp(1, top)));
            for hint in hints {
                let mut tests = 0;
                let found = least_clear_unit(top, hint, |k| {
                    assert!((1..=top).contains(&k), "asked for {k}");
                    tests += 1;
                    k >= least
                });
                assert_eq!(found, Some(least), "hint {hint:?}");
                let most = match hint.map(|h| h - least) {
                    Some(0) => 2,
                    Some(-1 | 1) if least > 1 && least < top => 3,
                    // From the vertical in coarse steps, then bisecting one.
                    None => top / TILT_STEP_UNITS + 7,
                    _ => 24,
                };
                assert!(tests <= most, "least {least}, hint {hint:?}: {tests} tests");
            }
        }
        // Nothing clear: none, from every hint.
        for hint in [None, Some(1), Some(700), Some(top)] {
            assert_eq!(least_clear_unit(top, hint, |_| false), None);
        }
    }
}
