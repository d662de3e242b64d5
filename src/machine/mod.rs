//! Machines and G-code: turning a [`Toolpath`] into text a controller runs, and reading it
//! back.
//!
//! Owns: machine models and their kinematics ([`kinematics`]), machine definitions as JSON
//! and the built-in machines ([`definition`]), joint values along a path ([`joints`]),
//! controller dialects ([`mod@post`]), machining time ([`motion`]), the program reader ([`reader`]) and the round-trip check
//! ([`roundtrip`]). Must not: plan or change the path.
//!
//! The one entry point the rest of the crate uses is [`post()`].

pub mod definition;
pub mod joints;
pub mod kinematics;
pub mod motion;
pub mod post;
pub mod reader;
pub mod roundtrip;

pub use definition::{builtin, from_json, resolve, to_json, MachineInfo, MACHINES};
pub use kinematics::{Joints, Kinematics, Machine, Mount, Rotary, ToolPose};
pub use motion::{path_times, Dynamics, PathTimes};
pub use post::{Dialect, OutputMode, Posted, Units, DIALECTS};
pub use roundtrip::{round_trip, RoundTrip};

use crate::error::Result;
use crate::plan::{PlanOptions, Toolpath};

/// What the program header says about where the path came from.
#[derive(Debug, Clone, PartialEq)]
pub struct JobInfo {
    pub model: String,
    pub strategy: String,
    /// Where the program's zero is on the part or stock, in words ("the model's origin").
    pub program_zero: String,
}

impl JobInfo {
    /// The header of a program for `model` planned with `strategy`.
    pub fn for_model(model: &crate::model::Model, strategy: &str) -> JobInfo {
        JobInfo {
            model: model.name.clone(),
            strategy: strategy.into(),
            program_zero: model.program_zero.clone(),
        }
    }
}

/// The program for `path` on `machine` in `dialect` and `units`. Deterministic: the same
/// input gives the same bytes. Errors name the move the machine cannot do (tool axis not +Z
/// on a 3-axis machine, a rotary or linear limit, a rotary swing forced by limits while
/// cutting).
pub fn post(
    path: &Toolpath,
    opts: &PlanOptions,
    job: &JobInfo,
    machine: &Machine,
    dialect: Dialect,
    units: Units,
) -> Result<String> {
    post::post_program(path, opts, job, machine, dialect, units).map(|p| p.text)
}

/// Three-axis G-code in millimetres for a LinuxCNC / Fanuc compatible controller: positions
/// are the tool tip (ball centre minus the radius along the axis). Same as [`post()`] with the
/// `3-axis` machine, the `plain` dialect and mm; errors when a tool axis is not +Z.
pub fn gcode_3axis(path: &Toolpath, opts: &PlanOptions, job: &JobInfo) -> Result<String> {
    let machine = builtin("3-axis")?;
    post(path, opts, job, &machine, Dialect::Plain, Units::Mm)
}

/// The machine a path's default program is posted for: `3-axis` while the tool axis stays
/// at +Z, `table-table-ac` otherwise.
pub fn default_machine(path: &Toolpath) -> Machine {
    let three_axis = path
        .moves
        .iter()
        .all(|m| m.tool_axis == crate::geom::Vector3::z());
    builtin(if three_axis {
        "3-axis"
    } else {
        "table-table-ac"
    })
    .expect("the built-in machines are valid")
}
