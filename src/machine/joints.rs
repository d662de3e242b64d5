//! Joint values along a whole path: one inverse-kinematics solution per move, chosen so the
//! rotaries move continuously and stay within their limits.
//!
//! Owns: branch and turn selection, unwinding at rapids, limit errors. Must not: change the
//! path or format output.
//!
//! Rules. Moves between two rapids form a *chain* the tool cuts without leaving the part;
//! inside a chain every move takes the solution nearest (in joint space) to the previous
//! one, so no rotary jumps. At the singular pose (tool axis along the inner rotary) the
//! inner angle keeps its previous value. When the nearest solution is outside a limit, the
//! chain must not fall back on a far one (a 180° or 360° swing while cutting): that is an
//! error naming the move. At the first move of a chain (a rapid, above the part) the rotaries
//! may take any solution: the one nearest the previous pose for which the whole chain stays
//! within limits is chosen, which is how endless-looking rotaries are unwound within their
//! travel.

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

/// The joint values of every pose, or the first move the machine cannot do.
pub fn solve(machine: &Machine, poses: &[PoseRequest]) -> Result<Vec<Joints>> {
    let mut out: Vec<Joints> = Vec::with_capacity(poses.len());
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
            match follow(machine, poses, start, end, c.rotary_deg) {
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
                previous = j.last().map(|l| l.rotary_deg).unwrap_or(previous);
                out.extend(j);
            }
            None => return Err(first_error.expect("at least one candidate was tried")),
        }
        start = end;
    }
    Ok(out)
}

/// Follows one chain from the rotary pose `seed` at `start`, nearest solution each move.
fn follow(
    machine: &Machine,
    poses: &[PoseRequest],
    start: usize,
    end: usize,
    seed: [f64; 2],
) -> Result<Vec<Joints>> {
    let mut out = Vec::with_capacity(end - start);
    let mut previous = seed;
    for (i, p) in poses.iter().enumerate().take(end).skip(start) {
        let rotary_deg = if i == start {
            seed
        } else {
            let inside = machine
                .rotary_solutions(&p.axis, previous, true)
                .map_err(|Unreachable| unreachable(machine, i, &p.axis))?;
            let free = machine
                .rotary_solutions(&p.axis, previous, false)
                .map_err(|Unreachable| unreachable(machine, i, &p.axis))?;
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
                    b.rotary_deg
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
                    return Err(Error::Machine {
                        location: format!("move {i}"),
                        message: format!(
                            "going on continuously from move {} to tool axis {} needs {} on machine `{}` ({}){jump}; \
                             widen the limits or plan with a different tool axis there",
                            i - 1,
                            axis_text(&p.axis),
                            outside_text(machine, &best_free),
                            machine.name,
                            limits_text(machine)
                        ),
                    });
                }
            }
        };
        let xyz_mm = machine.linear_joints(&p.tip, rotary_deg);
        machine.check_linear(&xyz_mm, &format!("move {i}"))?;
        out.push(Joints { xyz_mm, rotary_deg });
        previous = rotary_deg;
    }
    Ok(out)
}
