//! The round-trip check: plan → program text → [`reader`] → forward kinematics → compare with
//! the planned ball centres and tool axes (and feeds). Blocks the post inserted to keep
//! joint-space motion on the chords are checked as what they are: ball centre on the planned
//! chord, rotaries on the controller's own joint interpolation between the planned moves.
//!
//! Owns: interpreting read moves as tool poses for a machine and dialect, and the comparison.
//! Must not: write programs (it calls [`super::post::post_program`]).

use super::kinematics::{angle_to_arc, Joints, Kinematics, Machine, ToolPose};
use super::post::{self, Dialect, Posted, Source, Units};
use super::reader::{self, FeedMode, Program, ProgramMove};
use super::JobInfo;
use crate::error::{Error, Result};
use crate::geom::Vector3;
use crate::plan::{PlanOptions, Toolpath};
use serde::{Deserialize, Serialize};

/// Inverse-time moves at least this long (mm) have their implied feed checked. The implied
/// feed is the read-back move length times the G93 F word, and that length carries the
/// rounding of both end points: up to about 0.4 µm each in an inch program (0.127 µm per
/// written coordinate, and the last rotary digit, 1e-4°, turning points up to 100 mm from
/// the rotary axes), so about 4e-4 of a 2 mm move — well under the 1e-3 the check is for.
pub const FEED_CHECK_MIN_MM: f64 = 2.0;

/// What the round trip found (worst cases over the compared moves).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoundTrip {
    pub machine: String,
    pub dialect: String,
    pub units: String,
    /// Path moves compared (every move of the path).
    pub moves_compared: usize,
    /// Blocks the post added for the safe start and end, and round rapids that turn the
    /// rotaries.
    pub safe_blocks: usize,
    /// Blocks the post inserted on planned chords (joint-value output). Their ball centre is
    /// compared with the planned chord, their rotaries with the joint-space segment between
    /// the two planned moves around them (the controller's own interpolation).
    pub inserted_blocks: usize,
    /// Largest distance between a read-back ball centre and the planned one, or for an
    /// inserted block the planned chord (mm).
    pub max_position_error_mm: f64,
    pub worst_position_move: usize,
    /// Largest angle between a read-back tool axis and the planned one (degrees; path moves).
    pub max_axis_error_deg: f64,
    pub worst_axis_move: usize,
    /// Largest distance of an inserted block's rotary angles from the straight joint-space
    /// segment between the read-back rotaries of the planned moves around it (degrees): zero
    /// up to the rounding of the words when inserting adds no rotary motion.
    pub max_inserted_rotary_off_segment_deg: f64,
    /// Largest angle between an inserted block's tool axis and the great-circle arc between
    /// the planned axes around it (degrees): how far the machine's joint interpolation takes
    /// the axis off that arc between planned moves (it passes near the singular pose where the
    /// rotaries flip the tilt's sign).
    pub max_inserted_axis_off_arc_deg: f64,
    /// Largest relative error of the tool-tip feed implied by the program (F, or the move
    /// length times the G93 F) against the planned feed; a G93 move slowed by the rotary
    /// speed limit is compared with that limit instead. G93 moves shorter than
    /// [`FEED_CHECK_MIN_MM`] are left out: the rounding of their end points dominates.
    pub max_feed_error_rel: f64,
    /// Inverse-time blocks whose implied feed was checked (those at least
    /// [`FEED_CHECK_MIN_MM`] long).
    pub inverse_time_blocks_checked: usize,
}

/// The tool pose of each read move on `machine` as `dialect` means it; `None` for blocks in
/// machine coordinates or with unknown values.
pub fn tool_poses(program: &Program, machine: &Machine, dialect: Dialect) -> Vec<Option<ToolPose>> {
    program
        .moves
        .iter()
        .map(|m| pose_of(m, machine, dialect))
        .collect()
}

fn pose_of(m: &ProgramMove, machine: &Machine, dialect: Dialect) -> Option<ToolPose> {
    if m.machine_frame {
        return None;
    }
    let mut rot = [0.0; 2];
    for (i, r) in machine.rotaries.iter().enumerate() {
        rot[i] = m.abc_deg[(r.name as u8 - b'A') as usize];
    }
    let three = machine.kinematics() == Kinematics::ThreeAxis || dialect == Dialect::Plain;
    let pose = if three {
        ToolPose {
            tip: m.xyz_mm.into(),
            axis: Vector3::z(),
        }
    } else if m.tcp || dialect.tool_tip_output() {
        ToolPose {
            tip: m.xyz_mm.into(),
            axis: machine.tool_axis(rot),
        }
    } else {
        machine.forward(&Joints {
            xyz_mm: m.xyz_mm,
            rotary_deg: rot,
        })
    };
    (pose.tip.iter().all(|x| x.is_finite()) && pose.axis.iter().all(|x| x.is_finite()))
        .then_some(pose)
}

/// Posts `path`, reads the text back and compares (see [`compare`]).
pub fn round_trip(
    path: &Toolpath,
    opts: &PlanOptions,
    job: &JobInfo,
    machine: &Machine,
    dialect: Dialect,
    units: Units,
) -> Result<RoundTrip> {
    let posted = post::post_program(path, opts, job, machine, dialect, units)?;
    let program = reader::read(&posted.text)?;
    compare(path, opts, &posted, &program, machine, dialect)
}

/// Compares a read-back program with the path it was posted from. `posted.sources` says which
/// path move each motion block is; the values come from `program` only.
pub fn compare(
    path: &Toolpath,
    opts: &PlanOptions,
    posted: &Posted,
    program: &Program,
    machine: &Machine,
    dialect: Dialect,
) -> Result<RoundTrip> {
    let mismatch = |m: String| Error::Machine {
        location: "round trip".into(),
        message: m,
    };
    if program.moves.len() != posted.sources.len() {
        return Err(mismatch(format!(
            "the program reads back {} motion blocks, the post wrote {}",
            program.moves.len(),
            posted.sources.len()
        )));
    }
    // The post's record of where each block is (the page highlights by it) against the
    // reader's count of lines.
    if let Some((k, (line, block))) = posted
        .lines
        .iter()
        .zip(&program.moves)
        .enumerate()
        .find(|(_, (&line, block))| line != block.line)
    {
        return Err(mismatch(format!(
            "motion block {k} reads back at line {}, the post recorded line {line}",
            block.line
        )));
    }
    let poses = tool_poses(program, machine, dialect);
    let r = path.tool_radius_mm;
    let mut out = RoundTrip {
        machine: machine.name.clone(),
        dialect: dialect.name().into(),
        units: program.units.name().into(),
        moves_compared: 0,
        safe_blocks: 0,
        inserted_blocks: 0,
        max_position_error_mm: 0.0,
        worst_position_move: 0,
        max_axis_error_deg: 0.0,
        worst_axis_move: 0,
        max_inserted_rotary_off_segment_deg: 0.0,
        max_inserted_axis_off_arc_deg: 0.0,
        max_feed_error_rel: 0.0,
        inverse_time_blocks_checked: 0,
    };
    // The block of each path move, for the segments inserted blocks lie on.
    let mut block_of_move = vec![None; path.moves.len()];
    for (k, src) in posted.sources.iter().enumerate() {
        if let Source::Move(i) = *src {
            if let Some(b) = block_of_move.get_mut(i) {
                *b = Some(k);
            }
        }
    }
    let rotaries_of = |k: usize| -> [f64; 2] {
        let mut rot = [0.0; 2];
        for (i, r) in machine.rotaries.iter().enumerate() {
            rot[i] = program.moves[k].abc_deg[(r.name as u8 - b'A') as usize];
        }
        rot
    };
    let mut previous: Option<(ToolPose, [f64; 3])> = None;
    for (k, src) in posted.sources.iter().enumerate() {
        let read = &program.moves[k];
        let (i, inserted) = match *src {
            Source::Safe => {
                out.safe_blocks += 1;
                previous = poses[k].map(|p| (p, read.abc_deg));
                continue;
            }
            Source::Move(i) => (i, false),
            Source::Inserted(i) if i > 0 => (i, true),
            Source::Inserted(_) => {
                return Err(mismatch("a block is inserted before the first move".into()))
            }
        };
        let planned = &path.moves[i];
        let pose = poses[k].ok_or_else(|| {
            mismatch(format!(
                "line {} (move {i}) does not give a complete tool pose",
                read.line
            ))
        })?;
        let centre = pose.tip + pose.axis * r;
        let e_pos = if inserted {
            // On the chord from the previous move (its nearest point).
            let a = &path.moves[i - 1];
            let ab = planned.cl_point - a.cl_point;
            let t = if ab.norm_squared() > 0.0 {
                ((centre - a.cl_point).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (Some(ka), Some(kb)) = (block_of_move[i - 1], block_of_move[i]) else {
                return Err(mismatch(format!(
                    "line {} is inserted in move {i}, but a move around it has no block",
                    read.line
                )));
            };
            let off = off_segment(rotaries_of(k), rotaries_of(ka), rotaries_of(kb));
            let off_arc = angle_to_arc(&a.tool_axis, &planned.tool_axis, &pose.axis).to_degrees();
            if !(off <= out.max_inserted_rotary_off_segment_deg) {
                out.max_inserted_rotary_off_segment_deg = off;
            }
            if !(off_arc <= out.max_inserted_axis_off_arc_deg) {
                out.max_inserted_axis_off_arc_deg = off_arc;
            }
            out.inserted_blocks += 1;
            (centre - (a.cl_point + ab * t)).norm()
        } else {
            let e_ax = pose.axis.angle(&planned.tool_axis).to_degrees();
            if !(e_ax <= out.max_axis_error_deg) {
                out.max_axis_error_deg = e_ax;
                out.worst_axis_move = i;
            }
            out.moves_compared += 1;
            (centre - planned.cl_point).norm()
        };
        if !(e_pos <= out.max_position_error_mm) {
            out.max_position_error_mm = e_pos;
            out.worst_position_move = i;
        }
        let planned_feed = opts.feed_for(planned.kind).unwrap_or(opts.feed_mm_min);
        let feed_err = match read.feed_mode {
            FeedMode::Rapid => None,
            FeedMode::PerMinute => Some((read.feed - planned_feed).abs() / planned_feed),
            FeedMode::InverseTime => previous.and_then(|(p, abc)| {
                let len = (pose.tip - p.tip).norm();
                if len < FEED_CHECK_MIN_MM {
                    return None;
                }
                let speed = len * read.feed;
                let turn = (0..3)
                    .map(|a| (read.abc_deg[a] - abc[a]).abs())
                    .filter(|x| x.is_finite())
                    .fold(0.0, f64::max);
                let by_feed = (speed - planned_feed).abs() / planned_feed;
                let by_rotary = (turn * read.feed - machine.max_rotary_feed_deg_min).abs()
                    / machine.max_rotary_feed_deg_min;
                Some(if speed <= planned_feed {
                    by_feed.min(by_rotary)
                } else {
                    by_feed
                })
            }),
        };
        if let Some(e) = feed_err {
            out.max_feed_error_rel = out.max_feed_error_rel.max(e);
            if read.feed_mode == FeedMode::InverseTime {
                out.inverse_time_blocks_checked += 1;
            }
        }
        previous = Some((pose, read.abc_deg));
    }
    if out.moves_compared != path.moves.len() {
        return Err(mismatch(format!(
            "{} of {} path moves are in the program",
            out.moves_compared,
            path.moves.len()
        )));
    }
    Ok(out)
}

/// Distance (degrees) from rotary angles `x` to the joint-space segment from `a` to `b`.
fn off_segment(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ax = [x[0] - a[0], x[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if len2 > 0.0 {
        ((ax[0] * ab[0] + ax[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (ax[0] - ab[0] * t).hypot(ax[1] - ab[1] * t)
}
