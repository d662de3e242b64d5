//! Joint values along a whole path: one inverse-kinematics solution per move, chosen so the
//! rotaries move continuously and stay within their limits.
//!
//! Owns: branch and turn selection, unwinding at rapids, limit errors. Must not: change the
//! path or format output.
//!
//! Rules. Moves between two rapids form a *chain* the tool cuts without leaving the part;
//! inside a chain every move keeps the orientation branch of the previous one (the sign of the
//! tilt) and takes its nearest turn, so no rotary jumps; the branch may change only where the
//! arc of tool axes between two moves meets the singular pose (tool axis along the inner
//! rotary), and there the inner angle keeps its previous value. When the continuous solution
//! is outside a limit, the chain must not fall back on a far one (a 180° or 360° swing while
//! cutting): that is an error naming the move. At the first move of a chain (a rapid, above
//! the part) the rotaries may take any solution: the one nearest the previous pose for which
//! the whole chain stays within limits is chosen, which is how rotaries are unwound within
//! their travel.
//!
//! A controller that interpolates joint values moves the ball centre off the straight chord
//! where the rotaries turn fast; [`linearize`] splits such moves until it stays within the
//! chordal tolerance.

use super::kinematics::{Joints, Machine, RotarySolution, Unreachable};
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};

/// A limit-forced solution farther than the unconstrained nearest one by more than this
/// (degrees, in the joint distance) is a jump.
const JUMP_TOL_DEG: f64 = 1e-6;

/// One pose the machine must reach: tool tip and axis in the workpiece frame, and whether
/// it starts a chain (a rapid above the part, where the rotaries may re-choose).
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
            Some((lo, hi)) if s.rotary_deg[i] < lo || s.rotary_deg[i] > hi => Some(format!(
                "{} = {:.4}° outside [{lo}, {hi}]°",
                r.name, s.rotary_deg[i]
            )),
            _ => None,
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Joint values and the orientation branch they are on (`None` at the singular pose).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solved {
    pub joints: Joints,
    pub branch: Option<u8>,
}

/// The joint values of every pose, or the first move the machine cannot do.
pub fn solve(machine: &Machine, poses: &[PoseRequest]) -> Result<Vec<Solved>> {
    let mut out: Vec<Solved> = Vec::with_capacity(poses.len());
    let mut previous = [0.0; 2];
    let mut start = 0;
    while start < poses.len() {
        let end = (start + 1..poses.len())
            .find(|&i| poses[i].starts_chain)
            .unwrap_or(poses.len());
        let first = &poses[start];
        let mut candidates = machine
            .rotary_solutions(&first.axis, previous, true)
            .map_err(|Unreachable| unreachable(machine, start, &first.axis))?;
        if candidates.is_empty() {
            let nearest = machine
                .rotary_solutions(&first.axis, previous, false)
                .map_err(|Unreachable| unreachable(machine, start, &first.axis))?;
            let why = nearest
                .first()
                .map(|s| outside_text(machine, s))
                .unwrap_or_default();
            return Err(Error::Machine {
                location: format!("move {start}"),
                message: format!(
                    "tool axis {} needs rotary angles outside the limits of machine `{}` ({}): {why}",
                    axis_text(&first.axis),
                    machine.name,
                    limits_text(machine)
                ),
            });
        }
        candidates.sort_by(|a, b| {
            distance(a.rotary_deg, previous)
                .total_cmp(&distance(b.rotary_deg, previous))
                .then(a.branch.cmp(&b.branch))
                .then(a.rotary_deg[0].total_cmp(&b.rotary_deg[0]))
                .then(a.rotary_deg[1].total_cmp(&b.rotary_deg[1]))
        });
        let mut first_error = None;
        let mut chain = None;
        for c in &candidates {
            match follow(machine, poses, start, end, c) {
                Ok(j) => {
                    chain = Some(j);
                    break;
                }
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        match chain {
            Some(j) => {
                previous = j.last().map(|l| l.joints.rotary_deg).unwrap_or(previous);
                out.extend(j);
            }
            None => return Err(first_error.expect("at least one candidate was tried")),
        }
        start = end;
    }
    Ok(out)
}

fn branch_of(s: &RotarySolution) -> Option<u8> {
    (!s.singular).then_some(s.branch)
}

/// The rotary solution for `axis` nearest `previous` within the limits, on the same branch as
/// `previous` unless the arc of tool axes from `previous_axis` meets the singular pose; an
/// error naming move `i` when the limits would force a swing (the nearest solution is
/// outside them).
fn continue_to(
    machine: &Machine,
    axis: &Vector3,
    previous_axis: &Vector3,
    previous: [f64; 2],
    previous_branch: Option<u8>,
    i: usize,
) -> Result<RotarySolution> {
    let free_branch = previous_branch.is_none() || machine.arc_meets_singular(previous_axis, axis);
    let keep = |s: &RotarySolution| free_branch || s.singular || Some(s.branch) == previous_branch;
    let solutions = |limits: bool| -> Result<Vec<RotarySolution>> {
        let all = machine
            .rotary_solutions(axis, previous, limits)
            .map_err(|Unreachable| unreachable(machine, i, axis))?;
        let same: Vec<RotarySolution> = all.iter().copied().filter(keep).collect();
        // A branch can end where two solutions merge (the edge of what a tilted axis reaches).
        Ok(if same.is_empty() && !limits {
            all
        } else {
            same
        })
    };
    let inside = solutions(true)?;
    let free = solutions(false)?;
    let nearest = |s: &[RotarySolution]| {
        s.iter().copied().min_by(|a, b| {
            distance(a.rotary_deg, previous)
                .total_cmp(&distance(b.rotary_deg, previous))
                .then(a.branch.cmp(&b.branch))
        })
    };
    let best_free = nearest(&free).expect("an unlimited solution exists");
    match nearest(&inside) {
        Some(b)
            if distance(b.rotary_deg, previous)
                <= distance(best_free.rotary_deg, previous) + JUMP_TOL_DEG =>
        {
            Ok(b)
        }
        forced => {
            let jump = forced
                .map(|b| {
                    format!(
                        "; the limits leave only a swing of {:.3}° in the rotaries",
                        distance(b.rotary_deg, previous)
                    )
                })
                .unwrap_or_default();
            Err(Error::Machine {
                location: format!("move {i}"),
                message: format!(
                    "going on continuously from move {} to tool axis {} needs {} on machine `{}` ({}){jump}; \
                     widen the limits or plan with a different tool axis there",
                    i.saturating_sub(1),
                    axis_text(axis),
                    outside_text(machine, &best_free),
                    machine.name,
                    limits_text(machine)
                ),
            })
        }
    }
}

/// Follows one chain from the rotary solution `seed` at `start`, continuously.
fn follow(
    machine: &Machine,
    poses: &[PoseRequest],
    start: usize,
    end: usize,
    seed: &RotarySolution,
) -> Result<Vec<Solved>> {
    let mut out = Vec::with_capacity(end - start);
    let mut previous = *seed;
    for (i, p) in poses.iter().enumerate().take(end).skip(start) {
        let s = if i == start {
            *seed
        } else {
            continue_to(
                machine,
                &p.axis,
                &poses[i - 1].axis,
                previous.rotary_deg,
                branch_of(&previous),
                i,
            )?
        };
        let xyz_mm = machine.linear_joints(&p.tip, s.rotary_deg);
        machine.check_linear(&xyz_mm, &format!("move {i}"))?;
        out.push(Solved {
            joints: Joints {
                xyz_mm,
                rotary_deg: s.rotary_deg,
            },
            branch: branch_of(&s),
        });
        previous = s;
    }
    Ok(out)
}

/// Most halvings of one move when linearising joint-space motion (2¹² pieces).
const MAX_LINEARIZE_DEPTH: usize = 12;

/// Fractions of a move where the joint-interpolated ball centre is compared with the chord.
const LINEARIZE_SAMPLES: [f64; 3] = [0.25, 0.5, 0.75];

/// One end of a move for [`linearize`]: ball centre, tool axis, joint values and branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    pub cl_point: Point3,
    pub axis: Vector3,
    pub joints: Joints,
    pub branch: Option<u8>,
}

/// Unit vector a fraction `t` of the way from `a` to `b` along the great circle.
pub fn slerp(a: &Vector3, b: &Vector3, t: f64) -> Vector3 {
    let theta = a.angle(b);
    if theta < super::kinematics::SINGULAR_CONE_RAD {
        return (a + (b - a) * t).normalize();
    }
    ((a * ((1.0 - t) * theta).sin() + b * (t * theta).sin()) / theta.sin()).normalize()
}

/// Joint values a fraction `t` of the way from `a` to `b` (what a controller interpolating
/// joints commands).
fn lerp_joints(a: &Joints, b: &Joints, t: f64) -> Joints {
    Joints {
        xyz_mm: [0, 1, 2].map(|k| a.xyz_mm[k] + (b.xyz_mm[k] - a.xyz_mm[k]) * t),
        rotary_deg: [0, 1].map(|k| a.rotary_deg[k] + (b.rotary_deg[k] - a.rotary_deg[k]) * t),
    }
}

/// Poses to insert between `a` and `b` (move `i`) so that a controller interpolating the
/// joints linearly keeps the ball centre within `tol_mm` of the straight chord the planner
/// meant: the move is halved (ball centre on the chord, tool axis along the great circle)
/// until every piece is within the tolerance. Empty when the move already is.
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
    let axis = slerp(&a.axis, &b.axis, 0.5);
    let s = continue_to(machine, &axis, &a.axis, a.joints.rotary_deg, a.branch, i)?;
    let xyz_mm = machine.linear_joints(&(cl_point - axis * r), s.rotary_deg);
    machine.check_linear(&xyz_mm, &format!("move {i}"))?;
    let m = Waypoint {
        cl_point,
        axis,
        joints: Joints {
            xyz_mm,
            rotary_deg: s.rotary_deg,
        },
        branch: branch_of(&s),
    };
    split(machine, r, a, &m, tol, i, depth + 1, out)?;
    out.push(m);
    split(machine, r, &m, b, tol, i, depth + 1, out)
}
