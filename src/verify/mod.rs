//! Verification by cutting simulation: what a ball-end tool moving along a path leaves on
//! the design surface, measured independently of the planners.
//!
//! Owns: sampling the surface, the swept volume of the ball (capsules), the measurement of
//! material left and gouges along surface normals, the error bound of that sampling, the
//! summary and the per-vertex heat map. Must not: share code with `plan` (it takes only the
//! [`Surface`] and a [`CutterPath`]), or change either.
//!
//! Method. Every patch is sampled on a uniform `(u, v)` grid, samples shared among patches
//! by area. From each sample `p` with tool-side unit normal `n` the line `p + t·n` is
//! intersected exactly with the capsule of every straight move near it (found through a
//! uniform grid): the first `t ≥ 0` inside the union is the material left; if `p` itself is
//! inside, the union's extent below `p` is the gouge depth. No ball within one tool radius
//! along the normal means the tool never came near: such samples count as uncut and are
//! reported apart (`unreached_fraction`), since their material left is not a scallop.
//!
//! Error bound. Sampled maxima underestimate the true ones; the worst scallop sits on the
//! cusp between passes, usually between samples. [`bound`] turns each sample's exact
//! gradient and a bound on the second derivative into a per-cell upper bound and locates
//! the cusp, which is then measured too (`cusp_samples`); the true
//! maximum scallop lies in `[max_scallop_mm, max_scallop_mm + scallop_error_bound_mm]` and
//! the true deepest gouge in `[max_gouge_mm, max_gouge_mm + gouge_error_bound_mm]`;
//! `error_bound_mm` is the larger of the two. Both fall with the square of the spacing.
//! A cell whose bound exceeds the highest material (or deepest gouge) measured so far by
//! more than a share of the scallop is split and sampled again; a coarse pass (one sample
//! in 16, no bounds) first measures a floor for those maxima, so that flat regions, whose
//! own scallop is small, are not refined towards it.

pub mod bound;
pub mod capsule;
pub mod cutter;
mod engine;
pub mod gcode;
pub mod heatmap;
pub mod index;
pub mod probe;
pub mod rest;
pub mod stats;

pub use cutter::{CutterLocation, CutterPath, ToolTip};
pub use rest::RestRect;

use crate::error::{Error, Result};
use crate::model::Model;
use crate::plan::{PlanOptions, Planned};
use crate::surface::tessellate::Tessellation;
use crate::surface::Surface;
use serde::{Deserialize, Serialize};

/// Which side of the surface the tool works from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ToolSide {
    /// Decided from the path: the side where the ball centres near the surface are.
    #[default]
    Auto,
    /// The side the surface normal `S_u × S_v` points to.
    Normal,
    /// The other side.
    Opposite,
}

/// What to measure and how densely.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct VerifyOptions {
    /// Samples on the surface in all, shared among patches by area (a sliver patch takes
    /// a few more, to be sampled across as densely as the rest). Default 1 000 000:
    /// on a 50 × 50 mm part a spacing of 0.05 mm.
    pub samples: usize,
    /// The scallop height asked of the planner (mm): material left above it counts as
    /// uncut. Default 0.01 mm, the planner's default.
    pub scallop_mm: f64,
    /// Overcut deeper than this is a gouge (mm). Default 0.0005 mm (half a micrometre): below
    /// what machines hold, above rounding.
    pub gouge_tolerance_mm: f64,
    /// Side the tool works from. Default: decided from the path.
    pub tool_side: ToolSide,
    /// Worker threads (natively; wasm uses one). Default 0: one per available core. The
    /// result does not depend on it.
    pub threads: usize,
    /// The area the plan leaves for another tool (where its ball cannot reach): measured,
    /// but kept out of the scallop statistics and counted as `rest_fraction`. Default none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rest_area: Vec<RestRect>,
    /// A quick look, not a proof: the samples and the heat map only, without the bound on
    /// what lies between samples (its refinement is most of the work at coarse sampling);
    /// the error bounds are then infinite. Default false.
    pub preview: bool,
}

/// Largest gouge tolerance a plan's verification uses (mm): two micrometres, what a good
/// finishing machine holds.
pub const MAX_GOUGE_TOLERANCE_MM: f64 = 0.002;

/// The gouge tolerance for verifying a plan made with chordal tolerance `chordal_mm`: the
/// smaller of the two, so that a coarse chord shows up as gouges.
pub fn gouge_tolerance_for(chordal_mm: f64) -> f64 {
    chordal_mm.min(MAX_GOUGE_TOLERANCE_MM)
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions {
            samples: 1_000_000,
            scallop_mm: 0.01,
            gouge_tolerance_mm: 0.0005,
            tool_side: ToolSide::Auto,
            threads: 0,
            rest_area: Vec::new(),
            preview: false,
        }
    }
}

/// Fewest and most samples accepted.
const MIN_SAMPLES: usize = 16;
/// Each sample keeps 16 bytes for the percentile: 50 million need 800 MB.
const MAX_SAMPLES: usize = 50_000_000;
/// Most samples a plan's verification grows to while aiming for its error bound, unless
/// told otherwise: the same for the CLI's `plan --verify` and the page, so both measure a
/// plan alike (8 M samples: about 40 s in a browser tab, 130 MB).
pub const PLAN_VERIFY_MAX_SAMPLES: usize = 8_000_000;
/// Fewest samples a plan's verification starts with, unless told otherwise: the first
/// round's spacing rule ([`FIRST_SPACING_SHARE`]) asks for more on all but small parts, and
/// where it asks for fewer the bound is met from them (the convex keycap at r 0.5, h 0.01 mm:
/// 153 476 samples, bound 0.0014 mm, largest scallop 0.009752 mm; from 1 000 000 samples
/// 0.009753 mm in twice the time). The same for the CLI's `plan --verify` and the page.
pub const PLAN_VERIFY_SAMPLES: usize = 100_000;
/// The error bound a plan's verification aims for, as a share of the scallop height: a
/// bound well below the scallop is what makes the measurement prove it.
pub const PLAN_BOUND_SHARE: f64 = 0.25;

/// How a plan made with `opts` is checked: from [`PLAN_VERIFY_SAMPLES`], its scallop, the gouge tolerance its chordal
/// tolerance allows ([`gouge_tolerance_for`]), and its rest area `rest` measured apart.
pub fn plan_options(opts: &PlanOptions, rest: Vec<RestRect>) -> VerifyOptions {
    VerifyOptions::default()
        .with_samples(PLAN_VERIFY_SAMPLES)
        .with_scallop(opts.scallop_mm)
        .with_gouge_tolerance(gouge_tolerance_for(opts.chordal_mm))
        .with_rest_area(rest)
}

/// Simulates the cut of `planned` (made with `opts`) as `plan --verify` and the page do,
/// with [`plan_options`]: from `samples` (default [`VerifyOptions`]'s) until the error
/// bound is [`PLAN_BOUND_SHARE`] of the scallop, with at most `max_samples`.
pub fn verify_plan(
    model: &Model,
    planned: &Planned,
    opts: &PlanOptions,
    samples: Option<usize>,
    max_samples: usize,
) -> Result<Verification> {
    verify_plan_progress(model, planned, opts, samples, max_samples, &mut |_| {})
}

/// As [`verify_plan`], telling `progress` the fraction done on the way.
pub fn verify_plan_progress(
    model: &Model,
    planned: &Planned,
    opts: &PlanOptions,
    samples: Option<usize>,
    max_samples: usize,
    progress: &mut dyn FnMut(f64),
) -> Result<Verification> {
    let mut vo = plan_options(opts, planned.rest_rects(model));
    if let Some(n) = samples {
        vo = vo.with_samples(n);
    }
    verify_to_bound_progress(
        &model.surface,
        &CutterPath::from_toolpath(&planned.toolpath)?,
        &vo,
        PLAN_BOUND_SHARE * opts.scallop_mm,
        max_samples,
        progress,
    )
}

impl VerifyOptions {
    /// Sets the number of samples.
    pub fn with_samples(mut self, n: usize) -> Self {
        self.samples = n;
        self
    }
    /// Sets the requested scallop height (mm).
    pub fn with_scallop(mut self, mm: f64) -> Self {
        self.scallop_mm = mm;
        self
    }
    /// Sets the gouge tolerance (mm).
    pub fn with_gouge_tolerance(mut self, mm: f64) -> Self {
        self.gouge_tolerance_mm = mm;
        self
    }
    /// Sets the number of worker threads (0: one per core).
    pub fn with_threads(mut self, n: usize) -> Self {
        self.threads = n;
        self
    }
    /// Sets the rest area (see [`VerifyOptions::rest_area`]).
    pub fn with_rest_area(mut self, rects: Vec<RestRect>) -> Self {
        self.rest_area = rects;
        self
    }
    /// Sets the tool side.
    pub fn with_tool_side(mut self, side: ToolSide) -> Self {
        self.tool_side = side;
        self
    }

    /// Checks every field; the error names the field and its range.
    pub fn validate(&self) -> Result<()> {
        if !(MIN_SAMPLES..=MAX_SAMPLES).contains(&self.samples) {
            return Err(Error::param(
                "samples",
                format!(
                    "must be between {MIN_SAMPLES} and {MAX_SAMPLES}, got {}",
                    self.samples
                ),
            ));
        }
        if !(self.scallop_mm.is_finite() && self.scallop_mm > 0.0) {
            return Err(Error::param(
                "scallop_mm",
                format!("must be a positive number of mm, got {}", self.scallop_mm),
            ));
        }
        if !(self.gouge_tolerance_mm.is_finite() && self.gouge_tolerance_mm >= 0.0) {
            return Err(Error::param(
                "gouge_tolerance_mm",
                format!(
                    "must be zero or a positive number of mm, got {}",
                    self.gouge_tolerance_mm
                ),
            ));
        }
        for (i, r) in self.rest_area.iter().enumerate() {
            let [u0, u1, v0, v1] = r.rect;
            let inside =
                |a: f64, b: f64| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a <= b;
            if !(inside(u0, u1) && inside(v0, v1)) {
                return Err(Error::param(
                    "rest_area",
                    format!("rectangle {i} of face {} is {:?}: it must be [u0, u1, v0, v1] with 0 ≤ u0 ≤ u1 ≤ 1 and 0 ≤ v0 ≤ v1 ≤ 1", r.face, r.rect),
                ));
            }
        }
        Ok(())
    }
}

/// The measurements of one patch (or of the whole surface).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatchVerification {
    /// Patch (domain face) index.
    pub patch: u32,
    /// Samples on this patch and the `u × v` grid they form.
    pub samples: usize,
    pub grid: [usize; 2],
    /// Area of the patch (mm²), by the samples' quadrature.
    pub area_mm2: f64,
    /// Largest distance between diagonal neighbours of the sample grid (mm).
    pub sample_spacing_mm: f64,
    /// Largest material left over the samples the tool reached, outside the rest area (mm).
    pub max_scallop_mm: f64,
    /// Where that is (mm), if any sample was reached.
    pub max_scallop_at_mm: Option<[f64; 3]>,
    /// Area-weighted mean material left over the reached area, gouges counting as 0 (mm).
    pub mean_scallop_mm: f64,
    /// Area-weighted 95th percentile of the same (mm).
    pub p95_scallop_mm: f64,
    /// Fraction of the area with more material left than the requested scallop, the
    /// unreached area included.
    pub uncut_fraction: f64,
    /// Fraction of the area in cells of four neighbouring samples that disagree on whether
    /// more than the requested scallop is left: the uncut area's edge, located only to
    /// within a cell. The true uncut share lies within `uncut_fraction` ± this, but for
    /// strips narrower than a cell that no sample meets.
    pub uncut_edge_fraction: f64,
    /// Fraction of the area no ball came within one tool radius of, along the normal.
    pub unreached_fraction: f64,
    pub unreached_samples: usize,
    /// Deepest overcut below the surface (mm); 0 if none.
    pub max_gouge_mm: f64,
    /// Where that is (mm), if anything was overcut.
    pub max_gouge_at_mm: Option<[f64; 3]>,
    /// Fraction of the area in the plan's rest area (left for another tool).
    pub rest_fraction: f64,
    /// Samples overcut deeper than the gouge tolerance.
    pub gouge_count: usize,
    /// Fraction of the area overcut deeper than the gouge tolerance.
    pub gouge_fraction: f64,
    /// Upper bound of (true − sampled) maximum scallop (mm), over the cells of four
    /// neighbouring samples the tool reached (where some were not, the area is uncut anyway).
    pub scallop_error_bound_mm: f64,
    /// The most by which the deepest gouge can exceed `max_gouge_mm` (mm), hidden gouges
    /// between samples included.
    pub gouge_error_bound_mm: f64,
    /// The larger of the two bounds (mm).
    pub error_bound_mm: f64,
    /// Samples where the surface has no normal (singular points); not measured.
    pub singular_samples: usize,
    /// Extra measurements: at cusps located between samples, in refined cells, and the
    /// coarse pass's (they enter the maxima only).
    pub cusp_samples: usize,
}

/// The result of a verification (keys as in the JSON the CLI prints).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verification {
    pub tool_radius_mm: f64,
    pub requested_scallop_mm: f64,
    pub gouge_tolerance_mm: f64,
    /// Side the tool worked from: `normal` or `opposite` (to `S_u × S_v`).
    pub tool_side: ToolSide,
    /// Straight moves simulated.
    pub moves: usize,
    /// Samples in all.
    pub samples: usize,
    pub area_mm2: f64,
    pub sample_spacing_mm: f64,
    pub max_scallop_mm: f64,
    pub max_scallop_at_mm: Option<[f64; 3]>,
    pub mean_scallop_mm: f64,
    pub p95_scallop_mm: f64,
    pub uncut_fraction: f64,
    pub uncut_edge_fraction: f64,
    pub unreached_fraction: f64,
    pub unreached_samples: usize,
    pub rest_fraction: f64,
    pub max_gouge_mm: f64,
    pub max_gouge_at_mm: Option<[f64; 3]>,
    pub gouge_count: usize,
    pub gouge_fraction: f64,
    pub scallop_error_bound_mm: f64,
    pub gouge_error_bound_mm: f64,
    pub error_bound_mm: f64,
    /// The error bound [`verify_to_bound`] aimed for (mm); `None` for a plain run.
    pub error_bound_target_mm: Option<f64>,
    pub singular_samples: usize,
    pub cusp_samples: usize,
    /// The same per patch.
    pub patches: Vec<PatchVerification>,
}

/// Simulates `path` over `surface` and measures what it leaves.
pub fn verify(surface: &Surface, path: &CutterPath, opts: &VerifyOptions) -> Result<Verification> {
    opts.validate()?;
    Ok(engine::run(surface, path, opts, None, &mut |_| {}))
}

/// Most rounds of [`verify_to_bound`].
const BOUND_ROUNDS: usize = 6;
/// Most growth of the sample count in one round: far from the asymptotic regime (cells
/// whose bound is capped) the bound's excess overstates the samples needed.
const BOUND_MAX_GROWTH: f64 = 4.0;
/// Extra samples asked for beyond what the bound's fall with the spacing squared predicts.
const BOUND_SAFETY: f64 = 1.1;

/// As [`verify`], with as many samples as it takes for `error_bound_mm ≤ target_mm`:
/// starting from `opts.samples`, the count grows in proportion to the bound's excess (the
/// bound falls with the square of the spacing, so with the number of samples), for at most
/// a few rounds; the result says what was reached (`error_bound_target_mm`).
pub fn verify_to_bound(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    target_mm: f64,
) -> Result<Verification> {
    verify_to_bound_within(surface, path, opts, target_mm, MAX_SAMPLES)
}

/// As [`verify_to_bound`] with at most `max_samples` samples.
pub fn verify_to_bound_within(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    target_mm: f64,
    max_samples: usize,
) -> Result<Verification> {
    verify_to_bound_progress(surface, path, opts, target_mm, max_samples, &mut |_| {})
}

/// As [`verify_to_bound_within`], telling `progress` the fraction done on the way (each
/// round takes half of what is left, as the rounds needed are not known beforehand).
pub fn verify_to_bound_progress(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    target_mm: f64,
    max_samples: usize,
    progress: &mut dyn FnMut(f64),
) -> Result<Verification> {
    let first = first_samples(surface, path, opts);
    bound_rounds(opts, first, target_mm, max_samples, &mut |o, round| {
        o.validate()?;
        Ok(engine::run(surface, path, o, None, &mut |f| {
            progress(round_progress(round, f))
        }))
    })
}

/// Overall progress of round `round` (from 0) done to `f`: round k spans
/// `[1 − 2^−k, 1 − 2^−(k+1)]`.
fn round_progress(round: usize, f: f64) -> f64 {
    let start = 1.0 - 0.5f64.powi(round as i32);
    start + f * 0.5f64.powi(round as i32 + 1)
}

/// As [`verify_to_bound`] with at most `max_samples` samples, and the heat map of the last
/// round (see [`verify_with_heat_map`]).
pub fn verify_to_bound_with_heat_map(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    target_mm: f64,
    max_samples: usize,
    mesh: &Tessellation,
    progress: &mut dyn FnMut(f64),
) -> Result<(Verification, Vec<f32>)> {
    let mut heat = Vec::new();
    let first = first_samples(surface, path, opts);
    let v = bound_rounds(opts, first, target_mm, max_samples, &mut |o, round| {
        let (v, h) = verify_with_heat_map_progress(surface, path, o, mesh, &mut |f| {
            progress(round_progress(round, f))
        })?;
        heat = h;
        Ok(v)
    })?;
    Ok((v, heat))
}

/// Spacing of the first round's samples when aiming for a bound, as a share of the
/// flat-surface stepover `sqrt(8 r h)`: on coarser grids cells that straddle a pass or a
/// crease cannot be bounded from their corners, and splitting them one by one costs more
/// than sampling finely from the start (gearbox2-9.tsm, r 0.5, h 0.01 mm: 9.4 M
/// measurements at 1 M samples, the bound still 7 times too loose).
const FIRST_SPACING_SHARE: f64 = 0.25;

/// The fewest samples a bounded simulation starts with: a spacing of
/// [`FIRST_SPACING_SHARE`] of the flat-surface stepover over the surface's area.
fn first_samples(surface: &Surface, path: &CutterPath, opts: &VerifyOptions) -> usize {
    first_round_samples(surface, path.tool_radius_mm, opts.scallop_mm)
}

/// The samples the first round of a bounded simulation takes at least, for a ball of
/// `tool_radius_mm` and a scallop of `scallop_mm`: the surface's area at a spacing of
/// [`FIRST_SPACING_SHARE`] of the flat-surface stepover `sqrt(8 r h)` (it starts from the
/// options' `samples` where they are more).
pub fn first_round_samples(surface: &Surface, tool_radius_mm: f64, scallop_mm: f64) -> usize {
    let step = FIRST_SPACING_SHARE * (8.0 * tool_radius_mm * scallop_mm).sqrt();
    let n = engine::area_mm2(surface) / (step * step);
    if n.is_finite() {
        n.ceil().min(MAX_SAMPLES as f64) as usize
    } else {
        0
    }
}

/// The rounds of [`verify_to_bound`], each run by `run`, from `opts.samples` samples or
/// `first` if more.
fn bound_rounds(
    opts: &VerifyOptions,
    first: usize,
    target_mm: f64,
    max_samples: usize,
    run: &mut dyn FnMut(&VerifyOptions, usize) -> Result<Verification>,
) -> Result<Verification> {
    if !(target_mm.is_finite() && target_mm > 0.0) {
        return Err(Error::param(
            "error_bound_mm",
            format!("the target bound must be a positive number of mm, got {target_mm}"),
        ));
    }
    let cap = max_samples.clamp(MIN_SAMPLES, MAX_SAMPLES);
    let mut o = opts.clone();
    o.samples = o.samples.max(first).min(cap);
    let mut v = run(&o, 0)?;
    // The side the first round found (the vote does not depend on the samples): later
    // rounds need not vote again.
    o.tool_side = v.tool_side;
    for round in 1..BOUND_ROUNDS {
        if v.error_bound_mm <= target_mm || o.samples >= cap {
            break;
        }
        let grow = (v.error_bound_mm / target_mm * BOUND_SAFETY).clamp(1.5, BOUND_MAX_GROWTH);
        o.samples = ((o.samples as f64 * grow).ceil() as usize).min(cap);
        v = run(&o, round)?;
    }
    v.error_bound_target_mm = Some(target_mm);
    Ok(v)
}

/// As [`verify`], and the heat map: one value per vertex of `mesh` (a tessellation of
/// `surface`, e.g. from [`crate::surface::tessellate::tessellate`]): the deepest gouge
/// there as a negative number (mm) if any, else the most material left (mm), `+∞` where the
/// tool never came within one radius.
pub fn verify_with_heat_map(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    mesh: &Tessellation,
) -> Result<(Verification, Vec<f32>)> {
    verify_with_heat_map_progress(surface, path, opts, mesh, &mut |_| {})
}

/// As [`verify_with_heat_map`], telling `progress` the fraction done on the way.
pub fn verify_with_heat_map_progress(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    mesh: &Tessellation,
    progress: &mut dyn FnMut(f64),
) -> Result<(Verification, Vec<f32>)> {
    opts.validate()?;
    if mesh.positions.len() % 3 != 0 || mesh.indices.len() != 3 * mesh.patch_ids.len() {
        return Err(Error::param(
            "mesh",
            "positions must be x y z triples and every triangle needs a patch id",
        ));
    }
    let mut map = heatmap::HeatMap::new(mesh);
    let v = engine::run(surface, path, opts, Some(&mut map), progress);
    Ok((v, map.into_values()))
}
