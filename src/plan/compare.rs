//! Every strategy on one model with one set of options, side by side (issue 17): per
//! strategy the plan's lengths, counts, time and the cut the simulation finds; for the model
//! the surface area and two lower bounds on the cutting length — `L_min = ∫ dA / g`, with
//! `g` the scallop-limited side step of the better principal direction at each point
//! (eq. 5), and the flat form `area / sqrt(8 r h)`.
//!
//! A strategy that cannot plan the model (or whose cut cannot be simulated) gets a row with
//! its reason; the others still run.
//!
//! Owns: running and tabulating. Must not: plan or simulate differently from `plan` and
//! `verify` (it calls them).

use super::draft::Footprint;
use super::isoparametric::patch_views;
use super::stepover::side_step_clamped;
use super::{plan, PlanOptions, PlanReport, PlanStatus, Planned, Strategy};
use crate::error::{Error, Result};
use crate::machine::Machine;
use crate::model::Model;
use crate::surface::DiffGeom;
use crate::verify;
use serde::{Deserialize, Serialize};

/// Midpoint-rule cells per patch side for the surface area and `L_min`.
const AREA_CELLS: usize = 64;
/// First sample count of a simulation, before it is raised towards its bound.
const FIRST_SAMPLES: usize = 200_000;
/// Share of a strategy's progress its planning takes when its cut is simulated (the
/// simulation takes the rest).
const PLAN_SHARE: f64 = 0.6;

/// A row of the comparison: a strategy with the options it adds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// Its name in `--strategies` and the table.
    pub name: &'static str,
    pub strategy: Strategy,
    /// Iso-planar without the deformation: the constant-spacing baseline.
    pub baseline: bool,
}

/// Every row, in the table's order.
pub const ENTRIES: [Entry; 6] = [
    Entry {
        name: "isoparametric",
        strategy: Strategy::Isoparametric,
        baseline: false,
    },
    Entry {
        name: "isfc",
        strategy: Strategy::Isfc,
        baseline: false,
    },
    Entry {
        name: "watershed",
        strategy: Strategy::Watershed,
        baseline: false,
    },
    Entry {
        name: "multi-rectangle",
        strategy: Strategy::MultiRectangle,
        baseline: false,
    },
    Entry {
        name: "isoplanar",
        strategy: Strategy::Isoplanar,
        baseline: false,
    },
    Entry {
        name: "isoplanar-baseline",
        strategy: Strategy::Isoplanar,
        baseline: true,
    },
];

impl Entry {
    /// The entries a comma-separated list names (all when `None`); the error lists them.
    pub fn parse_list(list: Option<&str>) -> Result<Vec<Entry>> {
        let Some(list) = list else {
            return Ok(ENTRIES.to_vec());
        };
        let mut out: Vec<Entry> = Vec::new();
        for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let e = ENTRIES.iter().find(|e| e.name == name).ok_or_else(|| {
                Error::param(
                    "strategies",
                    format!(
                        "`{name}` is not a strategy to compare; choose from {}",
                        ENTRIES.map(|e| e.name).join(", ")
                    ),
                )
            })?;
            if !out.contains(e) {
                out.push(*e);
            }
        }
        if out.is_empty() {
            return Err(Error::param(
                "strategies",
                "names no strategy; leave it out to compare them all",
            ));
        }
        Ok(out)
    }

    /// `opts` with this entry's strategy and switches (iso-planar deformed or not, whatever
    /// `opts` says).
    pub fn options(&self, opts: &PlanOptions) -> PlanOptions {
        let mut o = opts.clone().with_strategy(self.strategy);
        if self.strategy == Strategy::Isoplanar {
            o.isoplanar_deform = !self.baseline;
        }
        o
    }
}

/// What the simulation found of one strategy's cut.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulatedCut {
    pub max_scallop_mm: f64,
    pub mean_scallop_mm: f64,
    pub p95_scallop_mm: f64,
    /// The simulation's error bound on the scallop values (mm).
    pub error_bound_mm: f64,
    /// Share of the surface left above the scallop height (0 to 1), rest area included.
    pub uncut_fraction: f64,
    /// Samples cut deeper than the gouge tolerance.
    pub gouges: usize,
    pub samples: usize,
}

/// One strategy's plan on the model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrategyRun {
    pub strategy: String,
    /// Why the strategy could not plan the model (or its cut could not be simulated); the
    /// other fields are then zero.
    pub error: Option<String>,
    /// Feed moves on the surface, links on the surface, moves in the air (mm).
    pub cutting_length_mm: f64,
    pub link_length_mm: f64,
    pub air_length_mm: f64,
    pub retractions: usize,
    pub reversals: usize,
    pub cl_points: usize,
    /// Largest turn of the tool axis between consecutive cut points while cutting (degrees).
    pub max_axis_step_deg: f64,
    pub plan_ms: f64,
    /// On the machine named in [`Comparison::machine`] or the plan's default machine.
    pub machining_time_min: f64,
    pub feed_time_min: f64,
    pub time_machine: String,
    /// Cutting length over [`Comparison::l_min_mm`] and over the flat bound.
    pub efficiency: f64,
    pub efficiency_flat: f64,
    pub status: PlanStatus,
    /// Kinds of the report's problems.
    pub problems: Vec<String>,
    /// The simulated cut, when the comparison simulates.
    pub simulated: Option<SimulatedCut>,
}

/// Every strategy on one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    pub model: String,
    pub tool_radius_mm: f64,
    pub scallop_mm: f64,
    /// Surface area (mm²).
    pub area_mm2: f64,
    /// `∫ dA / g` with the better principal direction's side step at each point (mm).
    pub l_min_mm: f64,
    /// `area / sqrt(8 r h)` (mm).
    pub l_min_flat_mm: f64,
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

/// `∫ dA / g` over `model` (mm): the cutting length of passes that each step the largest
/// side step eq. 5 allows at their point, across the more concave principal direction (the
/// better one; concave curvature clamped as the planners clamp it). No path is shorter
/// where passes keep the scallop to `h`.
pub fn l_min_mm(model: &Model, r: f64, h: f64) -> f64 {
    let n = AREA_CELLS;
    let step = 1.0 / n as f64;
    patch_views(model)
        .iter()
        .map(|view| {
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = ((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
                    let d = view.patch.derivs(view.surface, u, v);
                    let da = d.su.cross(&d.sv).norm() * step * step;
                    let k = match DiffGeom::try_from_derivs(&d) {
                        Some(g) => {
                            let g = if view.side < 0.0 { g.flipped() } else { g };
                            let (k1, k2) = g.principal();
                            k1.max(k2)
                        }
                        None => 0.0,
                    };
                    sum += da / side_step_clamped(h, r, k);
                }
            }
            sum
        })
        .sum()
}

/// A strategy's plan as the comparison made it: the plan, its options and its report
/// (without the simulation's findings).
pub type Kept = (Planned, PlanOptions, PlanReport);

/// Plans `model` with each of `entries` and `opts` otherwise, times each on `machine` (each
/// plan's default machine when `None`) and, with `verify_max_samples`, simulates each cut
/// until its error bound is a quarter of the scallop (or that many samples). Returns the
/// table and each row's plan (`None` where it could not plan), so that a caller can make
/// one the current plan without planning again. `clock` gives
/// milliseconds (the caller owns the clock); `progress` gets the fraction done and returns
/// `false` to cancel (an [`Error::Cancelled`]).
pub fn compare(
    model: &Model,
    opts: &PlanOptions,
    entries: &[Entry],
    machine: Option<&Machine>,
    verify_max_samples: Option<usize>,
    clock: &dyn Fn() -> f64,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<(Comparison, Vec<Option<Kept>>)> {
    opts.validate()?;
    let (r, h) = (opts.tool_radius_mm, opts.scallop_mm);
    let area = area_mm2(model);
    let l_min = l_min_mm(model, r, h);
    let l_min_flat = area / (8.0 * r * h).sqrt();
    let mut runs = Vec::new();
    let mut kept = Vec::new();
    let n = entries.len() as f64;
    for (k, entry) in entries.iter().enumerate() {
        let base = k as f64 / n;
        let o = entry.options(opts);
        // `f`: the fraction of this entry done.
        let mut sub = |f: f64| progress(base + f / n);
        let run = match run_one(
            model,
            &o,
            entry,
            machine,
            verify_max_samples,
            clock,
            &mut sub,
        ) {
            Ok((mut run, plan)) => {
                run.efficiency = run.cutting_length_mm / l_min;
                run.efficiency_flat = run.cutting_length_mm / l_min_flat;
                kept.push(Some(plan));
                run
            }
            Err(Error::Cancelled) => return Err(Error::Cancelled),
            Err(e) => {
                kept.push(None);
                failed(entry, e.to_string())
            }
        };
        runs.push(run);
        if !progress((k + 1) as f64 / n) {
            return Err(Error::Cancelled);
        }
    }
    let c = Comparison {
        model: model.name.clone(),
        tool_radius_mm: r,
        scallop_mm: h,
        area_mm2: area,
        l_min_mm: l_min,
        l_min_flat_mm: l_min_flat,
        runs,
    };
    Ok((c, kept))
}

fn failed(entry: &Entry, error: String) -> StrategyRun {
    StrategyRun {
        strategy: entry.name.into(),
        error: Some(error),
        cutting_length_mm: 0.0,
        link_length_mm: 0.0,
        air_length_mm: 0.0,
        retractions: 0,
        reversals: 0,
        cl_points: 0,
        max_axis_step_deg: 0.0,
        plan_ms: 0.0,
        machining_time_min: 0.0,
        feed_time_min: 0.0,
        time_machine: String::new(),
        efficiency: 0.0,
        efficiency_flat: 0.0,
        status: PlanStatus::PlannedWithProblems,
        problems: Vec::new(),
        simulated: None,
    }
}

fn run_one(
    model: &Model,
    o: &PlanOptions,
    entry: &Entry,
    machine: Option<&Machine>,
    verify_max_samples: Option<usize>,
    clock: &dyn Fn() -> f64,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<(StrategyRun, Kept)> {
    let t0 = clock();
    // Planning takes the whole entry, or its share where the cut is simulated after.
    let plan_share = if verify_max_samples.is_some() {
        PLAN_SHARE
    } else {
        1.0
    };
    let planned = plan(model, o, &mut |f| progress(f * plan_share))?;
    let mut report = planned.report(o);
    report.plan_ms = clock() - t0;
    if let Some(m) = machine {
        report.set_machining_time(&planned.toolpath, o, m);
    }
    let plan_report = report.clone();
    let simulated = match verify_max_samples {
        Some(max) => {
            let mut tell = |f: f64| {
                progress(PLAN_SHARE + (1.0 - PLAN_SHARE) * f);
            };
            let v = verify::verify_plan_progress(
                model,
                &planned,
                o,
                Some(FIRST_SAMPLES.min(max)),
                max,
                &mut tell,
            )?;
            report.add_verification(&v);
            Some(SimulatedCut {
                max_scallop_mm: v.max_scallop_mm,
                mean_scallop_mm: v.mean_scallop_mm,
                p95_scallop_mm: v.p95_scallop_mm,
                error_bound_mm: v.error_bound_mm,
                uncut_fraction: v.uncut_fraction,
                gouges: v.gouge_count,
                samples: v.samples,
            })
        }
        None => None,
    };
    let run = StrategyRun {
        strategy: entry.name.into(),
        error: None,
        cutting_length_mm: report.cutting_length_mm,
        link_length_mm: report.link_length_mm,
        air_length_mm: report.rapid_length_mm,
        retractions: report.retractions,
        reversals: report.reversals,
        cl_points: report.cl_points,
        max_axis_step_deg: report.max_axis_step_deg,
        plan_ms: report.plan_ms,
        machining_time_min: report.machining_time_min,
        feed_time_min: report.feed_time_min,
        time_machine: report.time_machine.clone(),
        efficiency: 0.0,
        efficiency_flat: 0.0,
        status: report.status,
        problems: report
            .problems
            .iter()
            .map(|p| p.kind.as_str().to_string())
            .collect(),
        simulated,
    };
    Ok((run, (planned, o.clone(), plan_report)))
}

/// The table's columns: heading (with unit) and the cell of a run that planned.
type Column = (&'static str, fn(&StrategyRun) -> String);

fn sim(r: &StrategyRun, f: fn(&SimulatedCut) -> String) -> String {
    r.simulated.as_ref().map(f).unwrap_or_else(|| "–".into())
}

const COLUMNS: &[Column] = &[
    ("cutting (mm)", |r| format!("{:.1}", r.cutting_length_mm)),
    ("link (mm)", |r| format!("{:.1}", r.link_length_mm)),
    ("air (mm)", |r| format!("{:.1}", r.air_length_mm)),
    ("retractions", |r| r.retractions.to_string()),
    ("reversals", |r| r.reversals.to_string()),
    ("CL points", |r| r.cl_points.to_string()),
    ("max scallop (mm)", |r| {
        sim(r, |s| format!("{:.4}", s.max_scallop_mm))
    }),
    ("mean scallop (mm)", |r| {
        sim(r, |s| format!("{:.4}", s.mean_scallop_mm))
    }),
    ("p95 scallop (mm)", |r| {
        sim(r, |s| format!("{:.4}", s.p95_scallop_mm))
    }),
    ("bound (mm)", |r| {
        sim(r, |s| format!("{:.4}", s.error_bound_mm))
    }),
    ("uncut (%)", |r| {
        sim(r, |s| format!("{:.2}", 100.0 * s.uncut_fraction))
    }),
    ("gouges", |r| sim(r, |s| s.gouges.to_string())),
    ("largest axis step (°)", |r| {
        format!("{:.2}", r.max_axis_step_deg)
    }),
    ("plan (ms)", |r| format!("{:.0}", r.plan_ms)),
    ("machining (min)", |r| {
        format!("{:.2}", r.machining_time_min)
    }),
    ("length ÷ feed (min)", |r| {
        format!("{:.2}", r.feed_time_min)
    }),
    ("cut ÷ L_min", |r| format!("{:.3}", r.efficiency)),
    ("cut ÷ flat L_min", |r| format!("{:.3}", r.efficiency_flat)),
];

fn status_text(r: &StrategyRun) -> String {
    match (&r.error, r.status) {
        (Some(e), _) => format!("could not plan: {e}"),
        (None, PlanStatus::Planned) => "planned".into(),
        (None, PlanStatus::PlannedWithProblems) => {
            format!("planned with problems: {}", r.problems.join(", "))
        }
    }
}

impl Comparison {
    /// The rows as cells, the strategy first; a run that could not plan shows only its
    /// reason (in the status column).
    fn cells(&self) -> Vec<Vec<String>> {
        self.runs
            .iter()
            .map(|r| {
                let mut row = vec![r.strategy.clone()];
                for (_, f) in COLUMNS {
                    row.push(if r.error.is_some() {
                        String::new()
                    } else {
                        f(r)
                    });
                }
                row.push(status_text(r));
                row
            })
            .collect()
    }

    fn headings() -> Vec<&'static str> {
        std::iter::once("strategy")
            .chain(COLUMNS.iter().map(|c| c.0))
            .chain(std::iter::once("status"))
            .collect()
    }

    /// What the table is of: the model, tool, scallop, area and bounds.
    pub fn title(&self) -> String {
        format!(
            "{}: ball r {} mm, scallop {} mm; area {:.1} mm², L_min {:.1} mm (curvature), {:.1} mm (flat)",
            self.model,
            self.tool_radius_mm,
            self.scallop_mm,
            self.area_mm2,
            self.l_min_mm,
            self.l_min_flat_mm
        )
    }

    /// The table as Markdown, under its title.
    pub fn markdown(&self) -> String {
        let heads = Self::headings();
        let mut s = format!("{}\n\n| {} |\n|", self.title(), heads.join(" | "));
        s.push_str(&"---|".repeat(heads.len()));
        s.push('\n');
        for row in self.cells() {
            s.push_str(&format!("| {} |\n", row.join(" | ")));
        }
        s
    }

    /// The table as CSV (RFC 4180: fields with commas, quotes or line breaks quoted), one
    /// header line and a line per strategy.
    pub fn csv(&self) -> String {
        let field = |f: &str| {
            if f.contains([',', '"', '\n']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f.to_string()
            }
        };
        let line = |cells: Vec<String>| {
            cells.iter().map(|c| field(c)).collect::<Vec<_>>().join(",") + "\r\n"
        };
        let mut s = line(Self::headings().iter().map(|h| h.to_string()).collect());
        for row in self.cells() {
            s.push_str(&line(row));
        }
        s
    }
}
