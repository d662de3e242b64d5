//! Tool axes along whole passes: where the point-by-point axis search
//! ([`super::axis::choose`]) leaves a large turn between two neighbouring cut points, the
//! turn is spread over the points around it by dynamic programming over clear candidate
//! axes, so the axis turns gradually and the machine's rotary axes are not asked to jump.
//!
//! Owns: the windows around large turns, the candidate axes, the cost and its minimum.
//! Must not: decide which points are cut (that is [`super::axis::choose`]'s `why`), or
//! move cut points (only tool axes change here).

use super::axis;
use super::clearance::Clearance;
use super::reach::Why;
use super::toolpath::Toolpath;
use super::PlanOptions;
use crate::geom::Vector3;
use std::collections::HashSet;

/// Turns between neighbouring cut points larger than `max_axis_step_deg`, and than this
/// (degrees), are spread (smaller ones cost many windows for little).
const LEAST_SPOT_DEG: f64 = 2.0;
/// The turn per point aimed at when spreading (degrees): a window holds about the turn over
/// this many points either side.
const SPREAD_DEG: f64 = 1.0;
/// Fewest and most points either side of a large turn in its window.
const MIN_HALF: usize = 6;
const MAX_HALF: usize = 90;
/// Window sizes of the rounds, in multiples of the usual size.
const WIDEN: [usize; 2] = [1, 3];
/// Longest window after overlapping ones are merged (points).
const MAX_WINDOW: usize = 1200;
/// Offsets (fractions of the window) of the blends between the window's end axes tried at
/// each point, around the point's own fraction.
const BLEND_OFFSETS: [f64; 9] = [-0.4, -0.25, -0.12, -0.05, 0.0, 0.05, 0.12, 0.25, 0.4];
/// Azimuths of the ring of least clear tilts tried at each point.
const RING: usize = 6;
/// Azimuths tried between the window's end axes' azimuths (intervals).
const AZIMUTH_BLENDS: usize = 4;
/// Tilts tried along each azimuth, above its least clear tilt (degrees).
const EXTRA_TILT_DEG: [f64; 3] = [0.0, 3.0, 8.0];
/// Candidates closer than this to one already kept are dropped (radians, 0.1°).
const SAME_AXIS_RAD: f64 = 1.75e-3;
/// Weight of the squared departure from the point-by-point axis against the squared turns:
/// small, so the axis leaves the least tilt only where that spreads a turn.
const DEPARTURE_WEIGHT: f64 = 0.02;
/// Weight of the squared part of each turn above the spot size: large, so that the largest
/// turn falls first.
const EXCESS_WEIGHT: f64 = 100.0;

/// Spreads the large axis turns of `path` (see the module), unless the axes follow the
/// surface normal by request. Points with a `why` (not cut) break the passes. Returns how
/// many windows of axes it changed.
pub fn spread_turns(
    obs: &Clearance,
    path: &mut Toolpath,
    opts: &PlanOptions,
    why: &[Option<Why>],
) -> usize {
    let mut smoothed = 0;
    // Axes the user asked to follow the surface (lead and tilt from the normal, the
    // facets' normal) are kept: their large turns follow the surface and are split.
    if opts.lead_deg != 0.0 || opts.tilt_deg != 0.0 || opts.facet_normal_axis {
        return smoothed;
    }
    let n = path.moves.len();
    let cut = |i: usize| path.moves[i].kind.on_surface() && why[i].is_none();
    // Passes: maximal runs of cut points.
    let mut chains = Vec::new();
    let mut i = 0;
    while i < n {
        if !cut(i) {
            i += 1;
            continue;
        }
        let s = i;
        while i + 1 < n && cut(i + 1) {
            i += 1;
        }
        chains.push((s, i));
        i += 1;
    }
    let budget = (n / BUDGET_SHARE).max(LEAST_BUDGET);
    let mut spent = 0;
    for (s, e) in chains {
        // Turns a window cannot spread are tried again in wider windows.
        for widen in WIDEN {
            for (l, r) in windows(path, opts, (s, e), widen) {
                // Bounded work: past the budget, large turns are only split.
                if spent >= budget {
                    continue;
                }
                spent += r - l + 1;
                if spread(obs, path, opts, (l, r), (l == s, r == e)) {
                    smoothed += 1;
                }
            }
        }
    }
    smoothed
}

/// Turns larger than this are spread (degrees).
fn spot_deg(opts: &PlanOptions) -> f64 {
    opts.max_axis_step_deg.max(LEAST_SPOT_DEG)
}

/// Turn of the axis from move `k − 1` to move `k` (degrees).
fn step_deg(path: &Toolpath, k: usize) -> f64 {
    path.moves[k - 1]
        .tool_axis
        .angle(&path.moves[k].tool_axis)
        .to_degrees()
}

/// The windows `(first, last)` around the large turns of the chain `s..=e`, merged where
/// they overlap, `widen` times the usual size.
fn windows(
    path: &Toolpath,
    opts: &PlanOptions,
    (s, e): (usize, usize),
    widen: usize,
) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for k in s + 1..=e {
        let t = step_deg(path, k);
        if t <= spot_deg(opts) {
            continue;
        }
        let half = widen * ((t / SPREAD_DEG).ceil() as usize).clamp(MIN_HALF, MAX_HALF);
        let l = k.saturating_sub(half + 1).max(s);
        let r = (k + half).min(e);
        match out.last_mut() {
            Some(w) if l <= w.1 && w.1.max(r) - w.0 < MAX_WINDOW => w.1 = w.1.max(r),
            _ => out.push((l, r)),
        }
    }
    out
}

/// Unit axis a fraction `t` of the way from unit `a` to unit `b` along the great circle, if
/// they are not opposite.
fn slerp(a: &Vector3, b: &Vector3, t: f64) -> Option<Vector3> {
    let angle = a.angle(b);
    if angle < SAME_AXIS_RAD {
        return Some(*a);
    }
    let s = angle.sin();
    if s < SAME_AXIS_RAD {
        return None;
    }
    let v = a * (((1.0 - t) * angle).sin() / s) + b * ((t * angle).sin() / s);
    v.try_normalize(SAME_AXIS_RAD)
}

/// Spreads the turns of window `l..=r` (`free`: whether each end may change, at a pass's
/// start or end) by dynamic programming; keeps the new axes if they leave fewer turns the
/// bridging cannot make clear, or as many and a smaller largest turn. True if it changed
/// them.
fn spread(
    obs: &Clearance,
    path: &mut Toolpath,
    opts: &PlanOptions,
    (l, r): (usize, usize),
    free: (bool, bool),
) -> bool {
    let moves = &path.moves;
    let (al, ar) = (moves[l].tool_axis, moves[r].tool_axis);
    // Fraction of the window's travel at each point (by index where it does not move).
    let mut travel = vec![0.0];
    for k in l + 1..=r {
        let d = (moves[k].cl_point - moves[k - 1].cl_point).norm();
        travel.push(travel[k - l - 1] + d);
    }
    let total = travel[r - l];
    let frac = |j: usize| {
        if total > 0.0 {
            travel[j] / total
        } else {
            j as f64 / (r - l) as f64
        }
    };
    // Candidates per point: its own axis first, then blends of the end axes, the ring of
    // least clear tilts (each azimuth hinted by the previous point's) and +Z; each clear
    // and within the largest tilt.
    let mut cands: Vec<Vec<Vector3>> = Vec::with_capacity(r - l + 1);
    // Azimuths: the ring, and those from the first end's to the last end's.
    let az = |v: &Vector3| v.y.atan2(v.x);
    let (phi_l, phi_r) = (az(&al), az(&ar));
    let mut turn = phi_r - phi_l;
    turn -= std::f64::consts::TAU * (turn / std::f64::consts::TAU).round();
    let azimuths: Vec<f64> = (0..RING)
        .map(|k| k as f64 * std::f64::consts::TAU / RING as f64)
        .chain((0..=AZIMUTH_BLENDS).map(|k| phi_l + turn * k as f64 / AZIMUTH_BLENDS as f64))
        .collect();
    let mut hints: Vec<Option<f64>> = vec![None; azimuths.len()];
    for j in 0..=r - l {
        let m = &moves[l + j];
        let own = m.tool_axis;
        let fixed = (j == 0 && !free.0) || (j == r - l && !free.1);
        let mut c = vec![own];
        if !fixed {
            let (cl, n) = (m.cl_point, axis::contact_normal(m));
            let add = |v: Vector3, c: &mut Vec<Vector3>| {
                if c.iter().all(|x| x.angle(&v) >= SAME_AXIS_RAD)
                    && axis::within_tilt(&v, opts)
                    && axis::usable(obs, (&cl, &n), &v, opts)
                {
                    c.push(v);
                }
            };
            for d in BLEND_OFFSETS {
                if let Some(v) = slerp(&al, &ar, (frac(j) + d).clamp(0.0, 1.0)) {
                    add(v, &mut c);
                }
            }
            add(Vector3::z(), &mut c);
            if opts.max_tilt_deg > 0.0 {
                for (&phi, hint) in azimuths.iter().zip(hints.iter_mut()) {
                    let t = axis::least_tilt(obs, (&cl, &n), opts, phi, *hint);
                    // An azimuth with no clear tilt is tried at the largest tilt first
                    // next time (two tests instead of a scan).
                    *hint = t.or(Some(opts.max_tilt_deg.to_radians()));
                    if let Some(t) = t {
                        for more in EXTRA_TILT_DEG {
                            add(axis::tilted(t + more.to_radians(), phi), &mut c);
                        }
                    }
                }
            }
        }
        cands.push(c);
    }
    let own = |j: usize| moves[l + j].tool_axis;
    let spot = spot_deg(opts).to_radians();
    // Turns the shank or holder cannot make (pairs of candidate indices into point `j`),
    // found on the cheapest path and excluded from the next; the point-by-point axes' own
    // blocked turns are left for the bridging that follows.
    let mut banned: HashSet<(usize, usize, usize)> = HashSet::new();
    let mut picks = least_cost(spot, &cands, &own, &banned);
    for _ in 0..BAN_ROUNDS {
        let mut more = false;
        for j in 1..=r - l {
            let (i, k) = (picks[j - 1], picks[j]);
            if (i, k) == (0, 0) {
                continue;
            }
            let (mut a, mut b) = (moves[l + j - 1], moves[l + j]);
            a.tool_axis = cands[j - 1][i];
            b.tool_axis = cands[j][k];
            if axis::turn_blocked(&a, &b, obs, opts) {
                banned.insert((j, i, k));
                more = true;
            }
        }
        if !more {
            break;
        }
        picks = least_cost(spot, &cands, &own, &banned);
    }
    let chosen: Vec<Vector3> = picks
        .iter()
        .enumerate()
        .map(|(j, &k)| cands[j][k])
        .collect();
    let largest = |axes: &dyn Fn(usize) -> Vector3| {
        (1..=r - l)
            .map(|j| axes(j - 1).angle(&axes(j)))
            .fold(0.0, f64::max)
    };
    let (before, after) = (largest(&own), largest(&|j| chosen[j]));
    let blocked = |axes: &dyn Fn(usize) -> Vector3| {
        (1..=r - l)
            .filter(|&j| {
                let (mut a, mut b) = (moves[l + j - 1], moves[l + j]);
                a.tool_axis = axes(j - 1);
                b.tool_axis = axes(j);
                // Blocked for good: the bridging that follows cannot split it clear.
                axis::turn_blocked(&a, &b, obs, opts)
                    && !axis::bridge(
                        &a,
                        &b,
                        (0.0, 1.0),
                        obs,
                        opts,
                        axis::BRIDGE_DEPTH,
                        &mut Vec::new(),
                    )
            })
            .count()
    };
    // Fewer turns the shank or holder cannot make first (the larger turns left are split
    // later), then a smaller largest turn.
    let (was, now) = (blocked(&own), blocked(&|j| chosen[j]));
    if now > was || (now == was && after >= before - SAME_AXIS_RAD) {
        return false;
    }
    for (j, v) in chosen.into_iter().enumerate() {
        path.moves[l + j].tool_axis = v;
    }
    true
}

/// Work budget: the windows' points in all, at most the path's moves over this, and at
/// least [`LEAST_BUDGET`] (each window point tries some 30 candidate axes).
const BUDGET_SHARE: usize = 8;
const LEAST_BUDGET: usize = 4000;

/// Rounds of excluding blocked turns from the cheapest path.
const BAN_ROUNDS: usize = 8;

/// The cheapest choice of one candidate per point (indices into `cands`): squared turns,
/// with a heavy weight on the part above `spot` (radians), plus a little for leaving the
/// point-by-point axis `own(j)`; the `banned` turns are not taken.
fn least_cost(
    spot: f64,
    cands: &[Vec<Vector3>],
    own: &dyn Fn(usize) -> Vector3,
    banned: &HashSet<(usize, usize, usize)>,
) -> Vec<usize> {
    let turn_cost = |a: &Vector3, b: &Vector3| {
        let t = a.angle(b);
        let over = (t - spot).max(0.0);
        t * t + EXCESS_WEIGHT * over * over
    };
    let departure = |j: usize, v: &Vector3| DEPARTURE_WEIGHT * own(j).angle(v).powi(2);
    let mut cost: Vec<f64> = cands[0].iter().map(|v| departure(0, v)).collect();
    let mut from: Vec<Vec<usize>> = vec![vec![0; cands[0].len()]];
    for j in 1..cands.len() {
        let mut next = Vec::with_capacity(cands[j].len());
        let mut back = Vec::with_capacity(cands[j].len());
        for (k, v) in cands[j].iter().enumerate() {
            let (best, arg) = cands[j - 1]
                .iter()
                .enumerate()
                .filter(|&(i, _)| !banned.contains(&(j, i, k)))
                .map(|(i, u)| (cost[i] + turn_cost(u, v), i))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            next.push(best + departure(j, v));
            back.push(arg);
        }
        cost = next;
        from.push(back);
    }
    let mut pick = (0..cost.len())
        .min_by(|&a, &b| cost[a].total_cmp(&cost[b]))
        .unwrap_or(0);
    let mut picks = vec![0; cands.len()];
    for j in (0..cands.len()).rev() {
        picks[j] = pick;
        pick = from[j][pick];
    }
    picks
}
