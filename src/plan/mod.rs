//! Tool path planning: options, the tool path type and report, shared step computations,
//! and one module per strategy.
//!
//! Must not: parse files or write G-code; planners take a [`Model`](crate::model::Model)
//! and return a [`Toolpath`].

pub mod air;
pub mod axis;
pub mod budget;
pub mod clearance;
pub mod compare;
pub mod corners;
pub mod distance;
pub mod draft;
pub mod gouge;
pub mod isfc;
pub mod isoparametric;
pub mod isoplanar;
pub mod options;
pub mod order;
pub mod pipeline;
pub mod reach;
pub mod smooth;
pub mod stepover;
pub mod toolpath;
pub mod watershed;

pub use options::{PlanOptions, Strategy};

use crate::error::Result;
use crate::model::Model;

/// Plans `model` with the strategy `opts.strategy` names, through the shared pipeline.
/// `progress` receives the fraction done and returns `false` to cancel.
pub fn plan(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Planned> {
    // Settings that would run for minutes are refused first, with the estimate.
    opts.validate()?;
    budget::check(model, opts)?;
    match opts.strategy {
        Strategy::Isoparametric => isoparametric::plan(model, opts, progress),
        Strategy::Isfc => isfc::plan(model, opts, progress),
        Strategy::Watershed => watershed::plan(model, opts, progress, true),
        Strategy::MultiRectangle => watershed::plan(model, opts, progress, false),
        Strategy::Isoplanar => isoplanar::plan(model, opts, progress),
    }
}
pub use pipeline::Planned;
pub use toolpath::{Move, MoveKind, PatchRun, PlanReport, PlanStatus, Problem, Toolpath};
