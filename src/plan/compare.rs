//! The strategies side by side on one model and one set of options (issue 14's table): the
//! surface area, the flat-surface bound on the cutting length `L_min = area / sqrt(8 r h)`
//! (parallel passes a flat-surface ball step apart), and per strategy the plan's lengths,
//! retractions and time, optionally with the simulated cut.
//!
//! Owns: running and tabulating. Must not: plan or simulate differently from `plan` and
//! `verify` (it calls them).

use super::draft::Footprint;
use super::{plan, PlanOptions, PlanStatus, Strategy};
use crate::error::Result;
use crate::model::Model;
use crate::verify;
use serde::{Deserialize, Serialize};

/// Midpoint-rule cells per patch side for the surface area.
const AREA_CELLS: usize = 64;
/// First sample count of a simulation, before it is raised towards its bound.
const FIRST_SAMPLES: usize = 200_000;

/// One strategy's plan on the model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrategyRun {
    pub strategy: String,
    /// Feed moves on the surface (mm), and that over [`Comparison::l_min_mm`].
    pub cutting_length_mm: f64,
    pub cutting_over_l_min: f64,
    /// Everything the tool travels (mm), links and rapids included.
    pub length_mm: f64,
    pub retractions: usize,
    pub cl_points: usize,
    pub machining_time_min: f64,
    pub plan_ms: f64,
    pub status: PlanStatus,
    /// Kinds of the report's problems.
    pub problems: Vec<String>,
    /// The simulated cut, if asked for: max scallop outside the rest area, its error
    /// bound, and the samples gouged deeper than the tolerance.
    pub max_scallop_mm: Option<f64>,
    pub error_bound_mm: Option<f64>,
    pub gouges: Option<usize>,
}

/// Both strategies on one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    pub tool_radius_mm: f64,
    pub scallop_mm: f64,
    /// Surface area (mm²).
    pub area_mm2: f64,
    /// `area / sqrt(8 r h)` (mm).
    pub l_min_mm: f64,
    pub runs: Vec<StrategyRun>,
}

/// Surface area of `model` (mm²), each patch by the midpoint rule.
pub fn area_mm2(model: &Model) -> f64 {
    (0..model.layout.patches.len())
        .map(|p| {
            Footprint {
                patch: p as u32,
                rect: [0.0, 1.0, 0.0, 1.0],
            }
            .area_mm2_fine(model, AREA_CELLS)
        })
        .sum()
}

/// Plans `model` with every strategy and `opts` otherwise; with `verify_max_samples`, also
/// simulates each cut until its error bound is a quarter of the scallop (or that many
/// samples). `clock` gives milliseconds (the caller owns the clock; wasm has none here).
pub fn compare(
    model: &Model,
    opts: &PlanOptions,
    verify_max_samples: Option<usize>,
    clock: &dyn Fn() -> f64,
) -> Result<Comparison> {
    let (r, h) = (opts.tool_radius_mm, opts.scallop_mm);
    let area = area_mm2(model);
    let l_min = area / (8.0 * r * h).sqrt();
    let mut runs = Vec::new();
    for strategy in [Strategy::Isoparametric, Strategy::Isfc] {
        let o = opts.clone().with_strategy(strategy);
        let t0 = clock();
        let planned = plan(model, &o, &mut |_| true)?;
        let plan_ms = clock() - t0;
        let mut report = planned.report(&o);
        let mut run = StrategyRun {
            strategy: planned.strategy.into(),
            cutting_length_mm: report.cutting_length_mm,
            cutting_over_l_min: report.cutting_length_mm / l_min,
            length_mm: report.length_mm,
            retractions: report.retractions,
            cl_points: report.cl_points,
            machining_time_min: report.machining_time_min,
            plan_ms,
            status: report.status,
            problems: Vec::new(),
            max_scallop_mm: None,
            error_bound_mm: None,
            gouges: None,
        };
        if let Some(max) = verify_max_samples {
            let v = verify::verify_plan(model, &planned, &o, Some(FIRST_SAMPLES.min(max)), max)?;
            report.add_verification(&v);
            run.status = report.status;
            run.max_scallop_mm = Some(v.max_scallop_mm);
            run.error_bound_mm = Some(v.error_bound_mm);
            run.gouges = Some(v.gouge_count);
        }
        run.problems = report
            .problems
            .iter()
            .map(|p| p.kind.as_str().to_string())
            .collect();
        runs.push(run);
    }
    Ok(Comparison {
        tool_radius_mm: r,
        scallop_mm: h,
        area_mm2: area,
        l_min_mm: l_min,
        runs,
    })
}

impl Comparison {
    /// The comparison as one row of a Markdown table (`name` first), the columns of
    /// [`Comparison::MARKDOWN_HEADER`].
    pub fn markdown_row(&self, name: &str) -> String {
        let cell = |s: &StrategyRun| {
            let sim = match (s.max_scallop_mm, s.error_bound_mm) {
                (Some(m), Some(b)) => format!(", {m:.4} ± {b:.4}"),
                _ => String::new(),
            };
            let gouges = match s.gouges {
                Some(g) if g > 0 => format!(", {g} gouges"),
                _ => String::new(),
            };
            format!(
                "{:.0}, {:.2}, {}, {:.1}{sim}{gouges}",
                s.cutting_length_mm, s.cutting_over_l_min, s.retractions, s.machining_time_min
            )
        };
        let ratio = match &self.runs[..] {
            [a, b] if a.cutting_length_mm > 0.0 => b.cutting_length_mm / a.cutting_length_mm,
            _ => f64::NAN,
        };
        format!(
            "| {name} | {:.0} | {:.0} | {} | {} | {ratio:.2} |",
            self.area_mm2,
            self.l_min_mm,
            cell(&self.runs[0]),
            cell(&self.runs[1])
        )
    }

    /// The header of [`Comparison::markdown_row`]'s table.
    pub const MARKDOWN_HEADER: &'static str = "| model | area (mm²) | L_min (mm) | patch by patch: cut (mm), ÷ L_min, retractions, time (min)[, scallop ± bound (mm)] | space-filling curve: the same | curve ÷ patch by patch |\n|---|---:|---:|---|---|---:|";
}
