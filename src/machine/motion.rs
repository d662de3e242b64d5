//! Machining time: how long a machine takes to run a path, with its rates, accelerations,
//! jerk and corner speeds — not just length over feed.
//!
//! The model is a look-ahead planner of the kind CNC controllers run. Every move is a
//! straight line in joint space (the machine's linear axes and its rotaries), as a
//! controller interpolates it.
//! - **Nominal speed**: a feed move takes the programmed time, `length / feed` at the tool
//!   tip or longer where the rotaries cannot turn that fast (`turn / max_rotary_feed`, the
//!   G93 rule of the post) or a linear axis would pass the rapid rate; a rapid moves every
//!   joint together at the fastest rate none exceeds.
//! - **Acceleration and jerk** along each move: the linear axes' limits scaled by how much
//!   of the motion is linear, the rotaries' by how much turns (the tighter wins); speed
//!   changes follow a jerk-limited S-curve (a trapezoid where jerk is unlimited).
//! - **Corners** (junction deviation): where one move meets the next at an angle θ in joint
//!   space (rotary degrees scaled by the ratio of linear to rotary acceleration), the
//!   controller rounds it within `junction_deviation_mm`, which allows the corner speed
//!   `sqrt(a δ sin(θ/2) / (1 − sin(θ/2)))`; a reversal (θ = 180°) stops, a straight
//!   continuation keeps the feed. The machine stops between a rapid and a feed move, and
//!   around a move that only turns.
//! - **Look-ahead**: corner speeds are lowered until every move can reach them from the
//!   previous one and brake to the next (backward and forward passes over the whole path).
//!
//! Times cover the path's moves, from its first point to its last (the program's safe
//! start and end blocks are not part of the path, nor the way up and round that the post
//! gives a rapid turning the rotaries: such a rapid is timed as the one move it plans).
//!
//! Owns: the dynamics fields of a machine and the time model. Must not: change the path or
//! choose joint values (that is [`super::joints`]).

use super::joints;
use super::kinematics::Machine;
use crate::plan::{PlanOptions, Toolpath};
use serde::{Deserialize, Serialize};
use std::cell::Cell;

/// Seconds per minute.
const S_PER_MIN: f64 = 60.0;
/// A move shorter than this in joint space (mm, or degrees for a turn) takes no time.
const NULL_MOVE: f64 = 1e-12;
/// Most steps of the peak-speed search (each narrows the interval the speed lies in; a
/// bisection step halves it).
const PEAK_STEPS: usize = 60;
/// The peak speed search stops when the interval it lies in, or Newton's step, is this
/// share of its top or of where it stands.
const SPEED_REL_TOL: f64 = 1e-11;
/// Most Newton steps of [`reach`]'s cubic (it converges in a few from its start; from a
/// start far above a tiny root each step shrinks the root's bracket by at least a third).
const NEWTON_STEPS: usize = 200;

/// What limits a machine's motion. Fields default to a mid-size machining centre.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Dynamics {
    /// Rapid (G0) rate of the linear axes (mm/min).
    pub rapid_mm_min: f64,
    /// Largest acceleration of the linear axes (mm/s²): 2 000 mm/s² is about 0.2 g.
    pub linear_accel_mm_s2: f64,
    /// Largest jerk of the linear axes (mm/s³): how fast acceleration builds up.
    pub linear_jerk_mm_s3: f64,
    /// Largest angular acceleration of the rotaries (degrees/s²).
    pub rotary_accel_deg_s2: f64,
    /// Largest angular jerk of the rotaries (degrees/s³).
    pub rotary_jerk_deg_s3: f64,
    /// How far (mm) the controller may round a corner between two moves (junction
    /// deviation, as in Grbl and Marlin; LinuxCNC's G64 P tolerance plays the same part).
    pub junction_deviation_mm: f64,
}

impl Default for Dynamics {
    fn default() -> Self {
        Dynamics {
            rapid_mm_min: 15_000.0,
            linear_accel_mm_s2: 2_000.0,
            linear_jerk_mm_s3: 50_000.0,
            rotary_accel_deg_s2: 1_000.0,
            rotary_jerk_deg_s3: 20_000.0,
            junction_deviation_mm: 0.01,
        }
    }
}

impl Dynamics {
    /// The fields that are not positive (jerk may be infinite: no jerk limit), named.
    pub fn invalid_field(&self) -> Option<(&'static str, f64)> {
        [
            ("rapid_mm_min", self.rapid_mm_min, false),
            ("linear_accel_mm_s2", self.linear_accel_mm_s2, false),
            ("linear_jerk_mm_s3", self.linear_jerk_mm_s3, true),
            ("rotary_accel_deg_s2", self.rotary_accel_deg_s2, false),
            ("rotary_jerk_deg_s3", self.rotary_jerk_deg_s3, true),
            ("junction_deviation_mm", self.junction_deviation_mm, false),
        ]
        .into_iter()
        .find(|&(_, v, may_be_infinite)| {
            !(v > 0.0 && (v.is_finite() || (may_be_infinite && v == f64::INFINITY)))
        })
        .map(|(name, v, _)| (name, v))
    }
}

/// One move as the controller runs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Change of the linear axes (mm).
    pub linear_mm: [f64; 3],
    /// Change of the two rotaries (degrees; zero on a three-axis machine).
    pub rotary_deg: [f64; 2],
    /// Programmed path length at the tool tip (mm), which the feed applies to.
    pub tip_length_mm: f64,
    /// Programmed feed (mm/min); `None` for a rapid.
    pub feed_mm_min: Option<f64>,
}

/// A move's motion along its own path coordinate `p` (joint-space mm, or degrees for a move
/// that only turns): length, top speed, acceleration and jerk (per second).
#[derive(Debug, Clone, Copy)]
struct Motion {
    p: f64,
    top: f64,
    accel: f64,
    jerk: f64,
    /// Path speed per unit of corner speed (joint-space speed scaled as in the corner rule).
    to_path: f64,
}

/// A move's [`Motion`] and what the corner rule needs of it.
#[derive(Debug, Clone, Copy)]
struct Profile {
    motion: Motion,
    /// Unit direction in scaled joint space (x, y, z, r1, r2), `None` for a null move.
    dir: Option<[f64; 5]>,
    rapid: bool,
    /// Only turns: the machine stops before and after.
    turn_only: bool,
}

fn profile(s: &Segment, rotary_feed_deg_min: f64, d: &Dynamics) -> Profile {
    let lin = s.linear_mm.iter().map(|x| x * x).sum::<f64>().sqrt();
    let rot = s.rotary_deg[0].abs().max(s.rotary_deg[1].abs());
    let turn_only = lin <= NULL_MOVE && rot > NULL_MOVE;
    let p = if turn_only { rot } else { lin };
    // Nominal time (s): the programmed one, or the joints' own rates where slower.
    let by_joints = (lin / d.rapid_mm_min).max(rot / rotary_feed_deg_min);
    let minutes = match s.feed_mm_min {
        Some(f) => (s.tip_length_mm / f).max(by_joints),
        None => by_joints,
    };
    let top = if minutes > 0.0 {
        p / (minutes * S_PER_MIN)
    } else {
        0.0
    };
    // Limits along p: each joint group's limit over its share of the motion.
    let (mut accel, mut jerk) = (f64::INFINITY, f64::INFINITY);
    if lin > NULL_MOVE {
        accel = accel.min(d.linear_accel_mm_s2 * p / lin);
        jerk = jerk.min(d.linear_jerk_mm_s3 * p / lin);
    }
    if rot > NULL_MOVE {
        accel = accel.min(d.rotary_accel_deg_s2 * p / rot);
        jerk = jerk.min(d.rotary_jerk_deg_s3 * p / rot);
    }
    // The corner rule's space: rotary degrees as the millimetres that take the same
    // acceleration.
    let k = d.linear_accel_mm_s2 / d.rotary_accel_deg_s2;
    let v = [
        s.linear_mm[0],
        s.linear_mm[1],
        s.linear_mm[2],
        s.rotary_deg[0] * k,
        s.rotary_deg[1] * k,
    ];
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let dir = (norm > NULL_MOVE && !turn_only).then(|| v.map(|x| x / norm));
    Profile {
        motion: Motion {
            p,
            top,
            accel,
            jerk,
            to_path: if norm > NULL_MOVE { p / norm } else { 1.0 },
        },
        dir,
        rapid: s.feed_mm_min.is_none(),
        turn_only,
    }
}

/// Time (s) and distance of a speed change from `a` to `b` under `accel` and `jerk`: the
/// jerk-limited S-curve (constant jerk, then constant acceleration if the change is large
/// enough, then constant jerk back to zero); its mean speed is `(a + b) / 2` by symmetry.
fn change(a: f64, b: f64, accel: f64, jerk: f64) -> (f64, f64) {
    let dv = (b - a).abs();
    let t = if !jerk.is_finite() {
        dv / accel
    } else if dv >= accel * accel / jerk {
        dv / accel + accel / jerk
    } else {
        2.0 * (dv / jerk).sqrt()
    };
    (t, 0.5 * (a + b) * t)
}

/// How fast the distance of the speed change between `a` and `v` ([`change`]) grows with
/// `v ≥ a`: `t/2 + (a + v)/2 · dt/dv`, the time's rate `1/accel` where the change has a
/// constant-acceleration part, `1/sqrt(j (v − a))` where it has not (infinite at `v = a`).
fn distance_slope(a: f64, v: f64, accel: f64, jerk: f64) -> f64 {
    let dv = (v - a).abs();
    let (t, rate) = if !jerk.is_finite() {
        (dv / accel, 1.0 / accel)
    } else if dv >= accel * accel / jerk {
        (dv / accel + accel / jerk, 1.0 / accel)
    } else {
        (2.0 * (dv / jerk).sqrt(), 1.0 / (dv * jerk).sqrt())
    };
    0.5 * t + 0.5 * (a + v) * rate
}

/// The highest speed reachable from `from` within `p` (never above `cap`): the speed change
/// `x` whose S-curve ([`change`]) covers exactly `p`, in closed form where the curve has a
/// constant-acceleration part (a quadratic in `x`) and by Newton's method where it has not
/// (`j s³ + 2·from·s = p` with `x = j s²`).
fn reach(from: f64, p: f64, cap: f64, accel: f64, jerk: f64) -> f64 {
    if cap <= from || change(from, cap, accel, jerk).1 <= p {
        return cap;
    }
    // x² + b x − c = 0 (c ≥ 0): the positive root, in the form without cancellation.
    let root = |b: f64, c: f64| 2.0 * c / (b + (b * b + 4.0 * c).sqrt());
    let x = if !jerk.is_finite() {
        // p = (from + x/2) x / a.
        root(2.0 * from, 2.0 * accel * p)
    } else if change(from, from + accel * accel / jerk, accel, jerk).1 <= p {
        // p = (from + x/2)(x/a + a/j).
        let t = accel * accel / jerk;
        root(2.0 * from + t, 2.0 * accel * (p - from * accel / jerk))
    } else {
        // p = (from + j s²/2) 2 s: convex and increasing in s ≥ 0, so Newton's method from
        // s = a/j (where the constant-acceleration part would begin, beyond the root) falls
        // to the root monotonically; it stops when a step no longer shrinks s.
        let f = |s: f64| jerk * s * s * s + 2.0 * from * s - p;
        let mut s = accel / jerk;
        for _ in 0..NEWTON_STEPS {
            let next = s - f(s) / (3.0 * jerk * s * s + 2.0 * from);
            if !(next < s) {
                break;
            }
            s = next.max(0.0);
        }
        jerk * s * s
    };
    (from + x).min(cap)
}

/// Time (s) of one move entered at `v0` and left at `v1` (path speeds both reachable).
fn move_time(m: &Motion, v0: f64, v1: f64) -> f64 {
    if m.p <= NULL_MOVE || m.top <= 0.0 {
        return 0.0;
    }
    let (ta, da) = change(v0, m.top, m.accel, m.jerk);
    let (td, dd) = change(m.top, v1, m.accel, m.jerk);
    if da + dd <= m.p {
        return ta + td + (m.p - da - dd) / m.top;
    }
    // Never reaches the top speed: the peak `v` where speeding up and braking fill the
    // move, the root of `g(v) = distance(v0 → v) + distance(v → v1) − p`, which rises with
    // `v` from `base = max(v0, v1)`. Its slope is infinite at `base` under a jerk limit
    // (the time of a small change grows as its square root), and the peak often lies
    // there (a move that only speeds up), so the search runs on `s = sqrt(v − base)`,
    // where `g` is smooth: Newton's method inside the bracket `[lo, hi]` of `s` (a
    // bisection step wherever Newton's would leave it), until the bracket or Newton's step
    // is within SPEED_REL_TOL of where it stands (of `s`, not the bracket: the root may lie
    // near 0, on a short move between near-equal speeds). `g` is convex in `s`, so Newton's steps
    // from the top stay above the root.
    let base = v0.max(v1);
    let g = |v: f64| change(v0, v, m.accel, m.jerk).1 + change(v, v1, m.accel, m.jerk).1 - m.p;
    let (mut lo, mut hi) = (0.0, (m.top - base).max(0.0).sqrt());
    let mut s = hi;
    // Where the steps run out, the top of the bracket (above the root: a slight overestimate
    // of the time, never a peak at `base` that the move cannot hold).
    let mut found = false;
    let mut end = hi;
    for _ in 0..PEAK_STEPS {
        let v = base + s * s;
        let gv = g(v);
        if gv <= 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        if hi - lo <= SPEED_REL_TOL * hi {
            end = lo;
            found = true;
            break;
        }
        let slope = 2.0
            * s
            * (distance_slope(v0, v, m.accel, m.jerk) + distance_slope(v1, v, m.accel, m.jerk));
        let newton = s - gv / slope;
        if (newton - s).abs() <= SPEED_REL_TOL * s {
            // Converged (to just above the root, as `g` is convex).
            end = newton.min(s);
            found = true;
            break;
        }
        s = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
    }
    // The time below is exact at a peak where `g <= 0` (the rest of the move at the peak
    // speed); above the root the speed change alone overruns the move, and where the slope
    // is steep (a short move between near-equal speeds) one rounding step of `v` overruns
    // it by a share of 1e-5. So an end above the root steps down by growing multiples of
    // its rounding step until below it, and the last steps are a bisection on `v` itself.
    let (mut below, mut peak) = (
        base + lo * lo,
        base + if found { end * end } else { hi * hi },
    );
    if g(peak) > 0.0 {
        let mut step = f64::EPSILON * peak;
        for _ in 0..PEAK_STEPS {
            let c = (peak - step).max(below);
            if c <= below || g(c) <= 0.0 {
                below = c;
                break;
            }
            peak = c;
            step *= 4.0;
        }
        for _ in 0..PEAK_STEPS {
            let mid = 0.5 * (below + peak);
            if mid <= below || mid >= peak {
                break;
            }
            if g(mid) <= 0.0 {
                below = mid;
            } else {
                peak = mid;
            }
        }
        peak = below;
    }
    let (ta, da) = change(v0, peak, m.accel, m.jerk);
    let (td, dd) = change(peak, v1, m.accel, m.jerk);
    // What the search leaves of the move, at the peak speed.
    ta + td + (m.p - da - dd).max(0.0) / peak.max(f64::MIN_POSITIVE)
}

/// The corner speed (in the corner rule's scaled joint space, per second) allowed between
/// two moves by the junction deviation.
fn corner_speed(a: &Profile, b: &Profile, d: &Dynamics) -> f64 {
    let (Some(u), Some(w)) = (a.dir, b.dir) else {
        return 0.0;
    };
    if a.rapid != b.rapid || a.turn_only || b.turn_only {
        return 0.0;
    }
    // sin(θ/2) of the corner angle θ between the reversed entry and the exit: half the
    // length of `u + w` (unit directions), not `sqrt((1 − cos θ) / 2)`, which near a
    // reversal turns a rounding step of the cosine into 1e-8 and a corner speed where the
    // machine must stop (native and wasm then disagreed on an isfc detour's time by 1.5e-9
    // of the whole).
    let half = (0.5 * (0..5).map(|k| (u[k] + w[k]).powi(2)).sum::<f64>().sqrt()).min(1.0);
    if half >= 1.0 - 1e-12 {
        return f64::INFINITY; // straight on
    }
    (d.linear_accel_mm_s2 * d.junction_deviation_mm * half / (1.0 - half)).sqrt()
}

/// Seconds each segment takes (same order), with the machine stopped before the first
/// and after the last. `rotary_feed_deg_min` is the rotaries' fastest rate.
pub fn segment_times(segs: &[Segment], rotary_feed_deg_min: f64, d: &Dynamics) -> Vec<f64> {
    segment_times_by(segs.len(), |k| segs[k], rotary_feed_deg_min, d)
}

/// [`segment_times`] of the `n` segments `seg(k)` makes on demand: a long path's segments
/// and whole profiles need not be held at once, only each move's [`Motion`] and a speed per
/// corner.
fn segment_times_by(
    n: usize,
    seg: impl Fn(usize) -> Segment,
    rotary_feed_deg_min: f64,
    d: &Dynamics,
) -> Vec<f64> {
    let profile = |k: usize| profile(&seg(k), rotary_feed_deg_min, d);
    // Corner k joins move k-1 and move k, as a speed in the corner rule's space; corners 0
    // and n are the start and end (stopped). The passes below need only the motions.
    let mut w = vec![0.0; n + 1];
    let mut m = Chunked::with_capacity(n);
    let cap = |p: &Profile| {
        if p.motion.to_path > 0.0 {
            p.motion.top / p.motion.to_path
        } else {
            0.0
        }
    };
    let mut before: Option<Profile> = None;
    for k in 0..n {
        let b = profile(k);
        if let Some(a) = &before {
            w[k] = corner_speed(a, &b, d).min(cap(a)).min(cap(&b));
        }
        m.push(b.motion);
        before = Some(b);
    }
    // Backward: every move must brake from its entry to its exit.
    for k in (0..n).rev() {
        let mv = m.get(k);
        if mv.p <= NULL_MOVE {
            w[k] = w[k].min(w[k + 1]);
            continue;
        }
        let exit = w[k + 1] * mv.to_path;
        let entry = reach(exit, mv.p, w[k] * mv.to_path, mv.accel, mv.jerk);
        w[k] = w[k].min(entry / mv.to_path);
    }
    // Forward: and speed up from its entry to its exit.
    for k in 0..n {
        let mv = m.get(k);
        if mv.p <= NULL_MOVE {
            w[k + 1] = w[k + 1].min(w[k]);
            continue;
        }
        let entry = w[k] * mv.to_path;
        let exit = reach(entry, mv.p, w[k + 1] * mv.to_path, mv.accel, mv.jerk);
        w[k + 1] = w[k + 1].min(exit / mv.to_path);
    }
    // Each move's time over its entry speed, which no later move reads: the corner speeds'
    // vector becomes the times' (one place to spare).
    for k in 0..n {
        let mv = m.get(k);
        w[k] = move_time(mv, w[k] * mv.to_path, w[k + 1] * mv.to_path);
    }
    w.truncate(n);
    w
}

/// Motions kept in blocks of [`CHUNK`]: in wasm, where memory is never given back, one
/// block for a long path's motions (7.9 MB on the head five-axis) found no room among
/// what the plan had freed and grew the memory by that much.
struct Chunked {
    chunks: Vec<Vec<Motion>>,
}

/// Motions per block (160 KB).
const CHUNK: usize = 4096;

impl Chunked {
    fn with_capacity(n: usize) -> Self {
        Chunked {
            chunks: Vec::with_capacity(n.div_ceil(CHUNK)),
        }
    }

    fn push(&mut self, m: Motion) {
        match self.chunks.last_mut() {
            Some(c) if c.len() < CHUNK => c.push(m),
            _ => {
                let mut c = Vec::with_capacity(CHUNK);
                c.push(m);
                self.chunks.push(c);
            }
        }
    }

    fn get(&self, k: usize) -> &Motion {
        &self.chunks[k / CHUNK][k % CHUNK]
    }
}

/// How long a path takes on a machine.
#[derive(Debug, Clone, PartialEq)]
pub struct PathTimes {
    /// Seconds per move: entry `i` is the motion from move `i - 1` to move `i` (entry 0 is 0).
    pub seconds: Vec<f64>,
    /// False where the machine cannot take the path's tool axes (a joint limit) and the
    /// rotaries' motion was taken as the tool axis' own turn instead.
    pub from_joints: bool,
}

impl PathTimes {
    /// The whole path (min).
    pub fn total_min(&self) -> f64 {
        self.seconds.iter().sum::<f64>() / S_PER_MIN
    }
}

/// How long `machine` takes to run `path` at `opts`' feeds (see the module documentation).
/// The joint values are the post's ([`joints::solve`]); where the machine cannot take the
/// path, the tool axis' turn stands in for the rotaries'.
pub fn path_times(path: &Toolpath, opts: &PlanOptions, machine: &Machine) -> PathTimes {
    let n = path.moves.len();
    let rotaries = if machine.rotaries.is_empty() {
        None
    } else {
        joints::solve_rotaries_by(machine, n, |i| joints::path_request(path, i)).ok()
    };
    let from_joints = machine.rotaries.is_empty() || rotaries.is_some();
    let last_linear: Cell<Option<(usize, [f64; 3])>> = Cell::new(None);
    let seg = |k: usize| {
        let i = k + 1;
        let (a, b) = (&path.moves[i - 1], &path.moves[i]);
        let (p, q) = (joints::tip(path, i - 1), joints::tip(path, i));
        let tip = q - p;
        let (linear_mm, rotary_deg) = match &rotaries {
            Some(r) => {
                let (r0, r1) = (r[i - 1], r[i]);
                // The segments come in order: the linear joints at this one's start are the
                // last one's end.
                let p = match last_linear.get() {
                    Some((j, xyz)) if j == i - 1 => xyz,
                    _ => machine.linear_joints(&p, r0),
                };
                let q = machine.linear_joints(&q, r1);
                last_linear.set(Some((i, q)));
                (
                    [0, 1, 2].map(|k| q[k] - p[k]),
                    [0, 1].map(|k| r1[k] - r0[k]),
                )
            }
            None => {
                let turn = a.tool_axis.angle(&b.tool_axis).to_degrees();
                ([tip.x, tip.y, tip.z], [turn, 0.0])
            }
        };
        Segment {
            linear_mm,
            rotary_deg,
            tip_length_mm: tip.norm(),
            feed_mm_min: opts.feed_for(b.kind),
        }
    };
    let mut seconds = Vec::new();
    if n > 0 {
        seconds = segment_times_by(
            n - 1,
            seg,
            machine.max_rotary_feed_deg_min,
            &machine.dynamics,
        );
        // Within the capacity `segment_times_by` leaves.
        seconds.insert(0, 0.0);
    }
    PathTimes {
        seconds,
        from_joints,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vector3;

    /// [`move_time`]'s peak speed by plain bisection on `v` (the search before Newton's):
    /// the second method.
    fn move_time_by_bisection(m: &Motion, v0: f64, v1: f64) -> f64 {
        let (ta, da) = change(v0, m.top, m.accel, m.jerk);
        let (td, dd) = change(m.top, v1, m.accel, m.jerk);
        if da + dd <= m.p {
            return ta + td + (m.p - da - dd) / m.top;
        }
        let (mut lo, mut hi) = (v0.max(v1), m.top);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            let d = change(v0, mid, m.accel, m.jerk).1 + change(mid, v1, m.accel, m.jerk).1;
            if d <= m.p {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (ta, da) = change(v0, lo, m.accel, m.jerk);
        let (td, dd) = change(lo, v1, m.accel, m.jerk);
        ta + td + (m.p - da - dd).max(0.0) / lo.max(f64::MIN_POSITIVE)
    }

    #[test]
    fn move_time_equals_bisection_in_every_regime() {
        let mut next = crate::testing::uniform(0x9e37_79b9_7f4a_7c15);
        let mut newton_cases = 0;
        for case in 0..20_000 {
            // Top speeds 1–100 mm/s, lengths 1e-6–10 mm, accelerations 10–5000 mm/s², jerks
            // 100–1e6 mm/s³ or none; end speeds at rest, equal, or anywhere below the top
            // that the move can join (the planner only asks for such).
            let top = 1.0 + 99.0 * next();
            let p = 10f64.powf(-6.0 + 7.0 * next());
            let accel = 10f64.powf(1.0 + 2.7 * next());
            let jerk = if case % 4 == 0 {
                f64::INFINITY
            } else {
                10f64.powf(2.0 + 4.0 * next())
            };
            let v0 = match case % 3 {
                0 => 0.0,
                _ => top * next(),
            };
            let v1 = match case % 5 {
                0 => 0.0,
                1 => v0,
                _ => reach(v0, p, top * next(), accel, jerk),
            };
            let v0 = v0.min(reach(v1, p, top, accel, jerk));
            let m = Motion {
                p,
                top,
                accel,
                jerk,
                to_path: 1.0,
            };
            let (got, want) = (move_time(&m, v0, v1), move_time_by_bisection(&m, v0, v1));
            if change(v0, top, accel, jerk).1 + change(top, v1, accel, jerk).1 > p {
                newton_cases += 1;
            }
            assert!(
                got.is_finite() && (got - want).abs() <= 1e-9 * want,
                "case {case}: {got} s, bisection {want} s (v0 {v0}, v1 {v1}, top {top}, p {p}, a {accel}, j {jerk})"
            );
        }
        assert!(
            newton_cases > 5_000,
            "{newton_cases} moves below their top speed"
        );
    }

    /// [`reach`] by bisection on [`change`]'s distance: the second method.
    fn reach_by_bisection(from: f64, p: f64, cap: f64, accel: f64, jerk: f64) -> f64 {
        if cap <= from || change(from, cap, accel, jerk).1 <= p {
            return cap;
        }
        let (mut lo, mut hi) = (from, cap);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if change(from, mid, accel, jerk).1 <= p {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    #[test]
    fn reach_equals_bisection_in_every_regime() {
        // A fixed pseudo-random sequence, so the cases are the same every run.
        let mut next = crate::testing::uniform(0x2545_f491_4f6c_dd1d);
        let mut regimes = [0usize; 4];
        for case in 0..20_000 {
            // Speeds 0–100 mm/s, distances 1e-6–10 mm, accelerations 10–5000 mm/s², jerks
            // 100–1e6 mm/s³ or none.
            let from = if case % 5 == 0 { 0.0 } else { 100.0 * next() };
            let cap = from + 100.0 * next();
            let p = 10f64.powf(-6.0 + 7.0 * next());
            let accel = 10f64.powf(1.0 + 2.7 * next());
            let jerk = if case % 7 == 0 {
                f64::INFINITY
            } else {
                10f64.powf(2.0 + 4.0 * next())
            };
            let want = reach_by_bisection(from, p, cap, accel, jerk);
            let got = reach(from, p, cap, accel, jerk);
            assert!(
                (got - want).abs() <= 1e-9 * cap.max(1.0),
                "from {from} p {p} cap {cap} a {accel} j {jerk}: {got} against {want}"
            );
            // Which closed form or search answered.
            let k = if want >= cap {
                0
            } else if !jerk.is_finite() {
                1
            } else if want - from >= accel * accel / jerk {
                2
            } else {
                3
            };
            regimes[k] += 1;
        }
        // Every regime was exercised.
        assert!(regimes.iter().all(|&n| n > 100), "{regimes:?}");
    }
    #[test]
    fn corner_speeds_follow_the_closed_form_and_a_reversal_stops_to_rounding() {
        // Junction deviation: v = sqrt(a δ sin(θ/2) / (1 − sin(θ/2))), θ the angle between
        // the reversed entry and the exit (θ = π straight on, 0 a reversal).
        let d = Dynamics::default();
        let with_dir = |dir: [f64; 5]| Profile {
            motion: Motion {
                p: 1.0,
                top: 100.0,
                accel: 1000.0,
                jerk: f64::INFINITY,
                to_path: 1.0,
            },
            dir: Some(dir),
            rapid: false,
            turn_only: false,
        };
        let x = with_dir([1.0, 0.0, 0.0, 0.0, 0.0]);
        for deg in [10.0f64, 45.0, 90.0, 135.0, 170.0] {
            // The exit turned by `deg` from the entry: θ = π − deg.
            let t = deg.to_radians();
            let y = with_dir([t.cos(), t.sin(), 0.0, 0.0, 0.0]);
            let half = ((std::f64::consts::PI - t) / 2.0).sin();
            let want =
                (d.linear_accel_mm_s2 * d.junction_deviation_mm * half / (1.0 - half)).sqrt();
            let got = corner_speed(&x, &y, &d);
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{deg}°: {got} against {want}"
            );
        }
        // Reversals whose directions are opposite only to rounding (a unit vector and the
        // negated normalisation of a nearby one): the corner speed stays at rounding level
        // (the cosine's form gave 5e-4 mm/s here).
        let mut worst: f64 = 0.0;
        for k in 1..200 {
            let v = Vector3::new(0.3 + 1e-3 * k as f64, 0.7, -0.2 * k as f64).normalize();
            let w = (-v * 3.0).normalize();
            let a = with_dir([v.x, v.y, v.z, 0.0, 0.0]);
            let b = with_dir([w.x, w.y, w.z, 0.0, 0.0]);
            worst = worst.max(corner_speed(&a, &b, &d));
        }
        assert!(worst < 1e-6, "{worst} mm/s at a reversal");
    }
}
