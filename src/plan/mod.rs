//! Tool path planning: options, the tool path type and report, shared step computations,
//! and one module per strategy.
//!
//! Must not: parse files or write G-code; planners take a [`Model`](crate::model::Model)
//! and return a [`Toolpath`].

pub mod air;
pub mod axis;
pub mod corners;
pub mod distance;
pub mod draft;
pub mod gouge;
pub mod isoparametric;
pub mod options;
pub mod order;
pub mod pipeline;
pub mod reach;
pub mod stepover;
pub mod toolpath;

pub use options::PlanOptions;
pub use pipeline::Planned;
pub use toolpath::{Move, MoveKind, PatchRun, PlanReport, PlanStatus, Problem, Toolpath};
