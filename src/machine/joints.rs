//! Joint values along a whole path: one inverse-kinematics solution per move, chosen so the
//! rotaries move continuously, as little as possible and within their limits.
//!
//! Owns: branch and turn selection, unwinding at rapids, limit errors, and the blocks that keep
//! joint-space motion on the planned chords ([`linearize`]). Must not: change the path or
//! format output.
//!
//! Rules. Moves between two rapids form a *chain* the tool cuts without leaving the part.
//! From one move of a chain to the next the rotaries may take
//! - the *continuation*: the same orientation branch (the sign of the tilt) at the nearest
//!   turn — unless the arc of tool axes between the two moves passes through the singular pose
//!   (tool axis along the inner rotary, usually C), where staying on the branch would swing the
//!   inner rotary half a turn;
//! - the *smallest step*: the solution nearest in joint space (either branch, nearest turn).
//!   Where the tool axis passes near the singular pose this is the flip of the tilt's sign
//!   through the pole with a small turn of the inner rotary, while the continuation would turn
//!   the inner rotary by nearly the whole change of the axis' azimuth, up to 180° within one
//!   short move.
//!
//! At the singular pose the inner rotary keeps its value and the next move takes the smallest
//! step. Anything else (a far turn, the other branch when it is not the smaller step) is a
//! swing while cutting; when the limits leave only swings, that is an error naming the move. At
//! the first move of a chain (a rapid, clear of the part) the rotaries may take any solution
//! within their limits: that is where they are unwound.
//!
//! Among all the sequences these rules allow, the one with the least total rotary travel
//! (Euclidean, in degrees, rapids included) is chosen by dynamic programming over the whole
//! path. So a limit met late in a chain decides which way the rotaries go near the pole early
//! in it (a trunnion that tilts one way only takes the continuation), and a chain starts on the
//! turn that keeps it within the limits.
//!
//! A controller that interpolates joint values moves the ball centre off the straight chord
//! where the rotaries turn; [`linearize`] splits such moves until it stays within the chordal
//! tolerance.

use super::kinematics::{Joints, Machine, RotarySolution, Unreachable};
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};

/// Solutions this much (degrees, in joint distance) farther than the nearest one still count as
/// the smallest step (ties of round-off).
const STEP_TIE_DEG: f64 = 1e-6;

/// Two solutions whose rotary angles differ by less than this (degrees) after taking whole
/// turns of endless axes out are the same state of the dynamic programme.
const SAME_STATE_DEG: f64 = 1e-9;

/// One pose the machine must reach: tool tip and axis in the workpiece frame, and whether
/// it starts a chain (a rapid clear of the part, where the rotaries may re-choose).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseRequest {
    pub tip: Point3,
    pub axis: Vector3,
    pub starts_chain: bool,
}

/// Joint distance between two rotary poses (degrees, Euclidean).
fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

fn axis_text(v: &Vector3) -> String {
    format!("({:.6}, {:.6}, {:.6})", v.x, v.y, v.z)
}

fn unreachable(machine: &Machine, i: usize, axis: &Vector3) -> Error {
    Error::Machine {
        location: format!("move {i}"),
        message: format!(
            "tool axis {} cannot be reached by machine `{}` (no rotation of its rotaries gives it)",
            axis_text(axis),
            machine.name
        ),
    }
}

fn limits_text(machine: &Machine) -> String {
    machine
        .rotaries
        .iter()
        .map(|r| match r.limits_deg {
            Some((lo, hi)) => format!("{} in [{lo}, {hi}]°", r.name),
            None => format!("{} endless", r.name),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Which rotaries of `s` are outside their limits, as text.
fn outside_text(machine: &Machine, s: &RotarySolution) -> String {
    machine
        .rotaries
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match r.limits_deg {
            Some((lo, hi)) if !r.within(s.rotary_deg[i]) => Some(format!(
                "{} = {:.4}° outside [{lo}, {hi}]°",
                r.name, s.rotary_deg[i]
            )),
            _ => None,
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A state of the dynamic programme: the solution at one move and the cheapest way to it.
#[derive(Debug, Clone, Copy)]
struct State {
    rotary_deg: [f64; 2],
    /// Orientation branch; `None` at the singular pose.
    branch: Option<u8>,
    /// Rotary travel from the start of the path (degrees).
    travel_deg: f64,
    /// Index of the state at the previous move it comes from.
    back: u32,
}

/// States at most one move may have: a state's way back ([`solve_rotaries_by`]) is kept in
/// two bytes. A layer holds one state per orientation branch and turn the limits allow, a
/// few on any machine: two branches of 181 turns of each rotary, limits of ±32 600° on both,
/// would exceed it.
const MAX_LAYER_STATES: usize = u16::MAX as usize;

/// True when `a` and `b` are the same state (endless axes up to whole turns).
fn same_state(machine: &Machine, a: &State, b: &State) -> bool {
    a.branch == b.branch
        && machine.rotaries.iter().enumerate().all(|(k, r)| {
            let d = a.rotary_deg[k] - b.rotary_deg[k];
            let d = if r.limits_deg.is_none() {
                d - 360.0 * (d / 360.0).round()
            } else {
                d
            };
            d.abs() < SAME_STATE_DEG
        })
}

/// The solutions the rules allow at move `i`, pose `p`, coming from `from` at move `i − 1`,
/// pose `before` (`None` at the first move; limits not yet applied).
fn allowed(
    machine: &Machine,
    (p, before): (&PoseRequest, Option<&PoseRequest>),
    i: usize,
    from: &State,
    out: &mut Vec<RotarySolution>,
) -> Result<()> {
    let Some(before) = before.filter(|_| !p.starts_chain) else {
        return machine
            .rotary_solutions_into(&p.axis, from.rotary_deg, true, out)
            .map_err(|Unreachable| unreachable(machine, i, &p.axis));
    };
    machine
        .rotary_solutions_into(&p.axis, from.rotary_deg, false, out)
        .map_err(|Unreachable| unreachable(machine, i, &p.axis))?;
    let least = out
        .iter()
        .map(|s| distance(s.rotary_deg, from.rotary_deg))
        .fold(f64::INFINITY, f64::min);
    let continuation = from.branch.is_some() && !machine.arc_meets_singular(&before.axis, &p.axis);
    out.retain(|s| {
        distance(s.rotary_deg, from.rotary_deg) <= least + STEP_TIE_DEG
            || (continuation && (s.singular || Some(s.branch) == from.branch))
    });
    Ok(())
}

/// The tool tip of move `i` of `path` (the ball centre less the radius along the axis).
pub fn tip(path: &crate::plan::Toolpath, i: usize) -> Point3 {
    let m = &path.moves[i];
    m.cl_point - m.tool_axis * path.tool_radius_mm
}

/// The tool tip of every move of `path`.
pub fn tips(path: &crate::plan::Toolpath) -> Vec<Point3> {
    (0..path.moves.len()).map(|i| tip(path, i)).collect()
}

/// The pose move `i` of `path` asks for: a rapid (and the first move) starts a chain, where
/// the rotaries may re-choose.
pub fn path_request(path: &crate::plan::Toolpath, i: usize) -> PoseRequest {
    let m = &path.moves[i];
    PoseRequest {
        tip: tip(path, i),
        axis: m.tool_axis,
        starts_chain: i == 0 || m.kind == crate::plan::MoveKind::Rapid,
    }
}

/// The joint values of every pose (see the module documentation for how they are chosen), or
/// an error naming the first move the machine cannot do.
pub fn solve(machine: &Machine, poses: &[PoseRequest]) -> Result<Vec<Joints>> {
    solve_by(machine, poses.len(), |i| poses[i])
}

/// [`solve`] for `n` poses made on demand by `pose(i)` (each is asked for twice), so that a
/// long path's poses need not be held at once.
pub fn solve_by(
    machine: &Machine,
    n: usize,
    pose: impl Fn(usize) -> PoseRequest,
) -> Result<Vec<Joints>> {
    Ok(solve_rotaries_by(machine, n, &pose)?
        .into_iter()
        .enumerate()
        .map(|(i, rotary_deg)| Joints {
            xyz_mm: machine.linear_joints(&pose(i).tip, rotary_deg),
            rotary_deg,
        })
        .collect())
}

/// The rotary angles (degrees) [`solve_by`] chooses at each move, without the linear joints,
/// which follow from them and the move's tip ([`Machine::linear_joints`]): what a whole
/// path's timing needs to hold.
///
/// The way back keeps 20 bytes per state (the rotaries, and the state it comes from in two
/// bytes) and two per move (its layer's size), where whole states took 64 (16 MB on the
/// head's 197 571 moves) and then, with the layers' starts, 32: in wasm a block of that size
/// did not fit the room the plan had freed, and grew the memory by 7.6 MB.
pub fn solve_rotaries_by(
    machine: &Machine,
    n: usize,
    pose: impl Fn(usize) -> PoseRequest,
) -> Result<Vec<[f64; 2]>> {
    let home = State {
        rotary_deg: [0.0; 2],
        branch: None,
        travel_deg: 0.0,
        back: 0,
    };
    // The layers one after another (layer `i` is `sizes[i]` states, ending where layer `i
    // + 1` starts): a vector per move took its least capacity of four states, 256 bytes,
    // for the one or two most moves have (50 MB of the head's 197 571 moves).
    let mut rotary_deg: Vec<[f64; 2]> = Vec::with_capacity(n + n / 4);
    let mut back: Vec<u16> = Vec::with_capacity(n + n / 4);
    let mut sizes: Vec<u16> = Vec::with_capacity(n);
    let (mut from, mut next): (Vec<State>, Vec<State>) = (vec![home], Vec::new());
    let mut before: Option<PoseRequest> = None;
    let mut solutions = Vec::new();
    for i in 0..n {
        let p = pose(i);
        next.clear();
        for (k, f) in from.iter().enumerate() {
            allowed(machine, (&p, before.as_ref()), i, f, &mut solutions)?;
            for s in &solutions {
                let Some(rotary_deg) = machine.within_limits(s.rotary_deg) else {
                    continue;
                };
                let xyz_mm = machine.linear_joints(&p.tip, rotary_deg);
                if !machine.linear_within_limits(&xyz_mm) {
                    continue;
                }
                let state = State {
                    rotary_deg,
                    branch: (!s.singular).then_some(s.branch),
                    travel_deg: f.travel_deg + distance(rotary_deg, f.rotary_deg),
                    back: k as u32,
                };
                match next.iter_mut().find(|n| same_state(machine, n, &state)) {
                    Some(n) if n.travel_deg <= state.travel_deg => {}
                    Some(n) => *n = state,
                    None => next.push(state),
                }
            }
        }
        if next.is_empty() {
            return Err(dead_end(machine, &p, i, &from));
        }
        let Ok(size) = u16::try_from(next.len()) else {
            return Err(Error::Machine {
                location: format!("move {i}"),
                message: format!(
                    "the limits of machine `{}` ({}) allow more than {MAX_LAYER_STATES} ways to turn the rotaries to one tool axis; give a rotary that turns without end no limits",
                    machine.name,
                    limits_text(machine)
                ),
            });
        };
        sizes.push(size);
        rotary_deg.extend(next.iter().map(|s| s.rotary_deg));
        // An index into the previous layer, which held at most MAX_LAYER_STATES states.
        back.extend(next.iter().map(|s| s.back as u16));
        std::mem::swap(&mut from, &mut next);
        before = Some(p);
    }
    // `from` is the last layer, with its travel.
    let Some(mut k) =
        (0..from.len()).min_by(|&a, &b| from[a].travel_deg.total_cmp(&from[b].travel_deg))
    else {
        return Ok(Vec::new());
    };
    // The way back, from the last layer to the first. The state chosen in layer `i` is
    // noted in place of its first state's way back, which no later step reads (each step
    // reads a way back in its own layer).
    let mut end = rotary_deg.len();
    for i in (0..n).rev() {
        let start = end - sizes[i] as usize;
        let chosen = k;
        k = back[start + chosen] as usize;
        back[start] = chosen as u16;
        end = start;
    }
    // Then each chosen state to its move's place, in move order: the state chosen at move
    // `i` lies at or after `i` (every layer holds at least one state), so no place is
    // written before the state it holds is read.
    let mut start = 0;
    for i in 0..n {
        rotary_deg[i] = rotary_deg[start + back[start] as usize];
        start += sizes[i] as usize;
    }
    drop((back, sizes));
    rotary_deg.truncate(n);
    rotary_deg.shrink_to_fit();
    Ok(rotary_deg)
}

/// Why no allowed solution exists at move `i`, said from the cheapest state before it.
fn dead_end(machine: &Machine, p: &PoseRequest, i: usize, from: &[State]) -> Error {
    let f = from
        .iter()
        .min_by(|a, b| a.travel_deg.total_cmp(&b.travel_deg))
        .expect("a layer is never empty");
    let nearest = |limits: bool| -> Result<Option<RotarySolution>> {
        let all = machine
            .rotary_solutions(&p.axis, f.rotary_deg, limits)
            .map_err(|Unreachable| unreachable(machine, i, &p.axis))?;
        Ok(all.into_iter().min_by(|a, b| {
            distance(a.rotary_deg, f.rotary_deg)
                .total_cmp(&distance(b.rotary_deg, f.rotary_deg))
                .then(a.branch.cmp(&b.branch))
        }))
    };
    let linear = |s: &RotarySolution| {
        let xyz = machine.linear_joints(&p.tip, s.rotary_deg);
        machine.check_linear(&xyz, &format!("move {i}")).err()
    };
    let explain = || -> Result<Error> {
        let free = nearest(false)?.expect("an unlimited solution exists");
        let inside = nearest(true)?;
        if i == 0 || p.starts_chain {
            return Ok(match inside {
                None => Error::Machine {
                    location: format!("move {i}"),
                    message: format!(
                        "tool axis {} needs rotary angles outside the limits of machine `{}` ({}): {}",
                        axis_text(&p.axis),
                        machine.name,
                        limits_text(machine),
                        outside_text(machine, &free)
                    ),
                },
                Some(s) => linear(&s).unwrap_or_else(|| stuck(machine, i, &p.axis)),
            });
        }
        if machine.within_limits(free.rotary_deg).is_some() {
            return Ok(linear(&free).unwrap_or_else(|| stuck(machine, i, &p.axis)));
        }
        let swing = inside
            .map(|s| {
                format!(
                    "; the limits leave only a swing of {:.3}° in the rotaries",
                    distance(s.rotary_deg, f.rotary_deg)
                )
            })
            .unwrap_or_default();
        Ok(Error::Machine {
            location: format!("move {i}"),
            message: format!(
                "going on continuously from move {} to tool axis {} needs {} on machine `{}` ({}){swing}; \
                 widen the limits or plan with a different tool axis there",
                i.saturating_sub(1),
                axis_text(&p.axis),
                outside_text(machine, &free),
                machine.name,
                limits_text(machine)
            ),
        })
    };
    explain().unwrap_or_else(|e| e)
}

/// The fallback explanation when every allowed solution was refused for reasons the nearest
/// one does not show.
fn stuck(machine: &Machine, i: usize, axis: &Vector3) -> Error {
    Error::Machine {
        location: format!("move {i}"),
        message: format!(
            "tool axis {} cannot be reached continuously within the travel of machine `{}` ({})",
            axis_text(axis),
            machine.name,
            limits_text(machine)
        ),
    }
}

/// Most halvings of one move when linearising joint-space motion (2¹² pieces).
const MAX_LINEARIZE_DEPTH: usize = 12;

/// Fractions of a move where the joint-interpolated ball centre is compared with the chord.
const LINEARIZE_SAMPLES: [f64; 3] = [0.25, 0.5, 0.75];

/// One end of a move for [`linearize`]: the planned ball centre and the joint values there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    pub cl_point: Point3,
    pub joints: Joints,
}

/// Joint values a fraction `t` of the way from `a` to `b` (what a controller interpolating
/// joints commands).
pub fn lerp_joints(a: &Joints, b: &Joints, t: f64) -> Joints {
    Joints {
        xyz_mm: [0, 1, 2].map(|k| a.xyz_mm[k] + (b.xyz_mm[k] - a.xyz_mm[k]) * t),
        rotary_deg: [0, 1].map(|k| a.rotary_deg[k] + (b.rotary_deg[k] - a.rotary_deg[k]) * t),
    }
}

/// Poses to insert between `a` and `b` (move `i`) so that a controller interpolating the
/// joints linearly keeps the ball centre within `tol_mm` of the straight chord the planner
/// meant. The move is halved until every piece is within the tolerance; an inserted pose has
/// the rotaries where the controller's own interpolation puts them (so it adds no rotary
/// motion) and the linear axes that put the ball centre on the chord at the same fraction.
/// Empty when the move already is within the tolerance.
pub fn linearize(
    machine: &Machine,
    tool_radius_mm: f64,
    a: &Waypoint,
    b: &Waypoint,
    tol_mm: f64,
    i: usize,
) -> Result<Vec<Waypoint>> {
    let mut out = Vec::new();
    split(machine, tool_radius_mm, a, b, tol_mm, i, 0, &mut out)?;
    Ok(out)
}

#[allow(clippy::too_many_arguments)]
fn split(
    machine: &Machine,
    r: f64,
    a: &Waypoint,
    b: &Waypoint,
    tol: f64,
    i: usize,
    depth: usize,
    out: &mut Vec<Waypoint>,
) -> Result<()> {
    let deviation = LINEARIZE_SAMPLES
        .iter()
        .map(|&t| {
            let pose = machine.forward(&lerp_joints(&a.joints, &b.joints, t));
            let centre = pose.tip + pose.axis * r;
            (centre - (a.cl_point + (b.cl_point - a.cl_point) * t)).norm()
        })
        .fold(0.0, f64::max);
    if deviation <= tol {
        return Ok(());
    }
    if depth == MAX_LINEARIZE_DEPTH {
        return Err(Error::Machine {
            location: format!("move {i}"),
            message: format!(
                "the machine's joint motion leaves the straight path by {deviation:.4} mm even in \
                 pieces of 1/{} of the move (tolerance {tol} mm)",
                1usize << MAX_LINEARIZE_DEPTH
            ),
        });
    }
    let cl_point = a.cl_point + (b.cl_point - a.cl_point) * 0.5;
    let rotary_deg = lerp_joints(&a.joints, &b.joints, 0.5).rotary_deg;
    let axis = machine.tool_axis(rotary_deg);
    let xyz_mm = machine.linear_joints(&(cl_point - axis * r), rotary_deg);
    machine.check_linear(&xyz_mm, &format!("move {i}"))?;
    let m = Waypoint {
        cl_point,
        joints: Joints { xyz_mm, rotary_deg },
    };
    split(machine, r, a, &m, tol, i, depth + 1, out)?;
    out.push(m);
    split(machine, r, &m, b, tol, i, depth + 1, out)
}
