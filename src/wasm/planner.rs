//! The planner's half of the JavaScript API: planning, comparing, posting and the cutting
//! simulation. Built with the `planner` feature (on by default); the
//! page's first module is built without it, so the model is drawn before this code arrives.

use super::{js_err, to_js, WasmMesh, WasmModel};
use crate::machine::{self, Dialect, JobInfo, Units};
use crate::plan::isfc::layer::Layer as IsfcLayer;
use crate::plan::watershed::layer::Layer as WatershedLayer;
use crate::plan::{PlanOptions, PlanReport, Toolpath};
use crate::verify::{self, CutterPath, RestRect, Verification, VerifyOptions};
use std::cell::RefCell;
use wasm_bindgen::prelude::*;

/// Milliseconds from the JavaScript clock (the only clock in a browser or Node).
fn now_ms() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        js_sys::Date::now()
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        0.0
    }
}

#[wasm_bindgen(js_class = Model)]
impl WasmModel {
    /// Plans with the strategy `options.strategy` names (`isoparametric`, the default, or
    /// `isfc`, the space-filling curve). `options` is a plain object with any of the
    /// [`PlanOptions`] fields (`tool_radius_mm`, `scallop_mm`, `chordal_mm`, `strategy`,
    /// `isfc_plain`, ...); `progress`, if given, is called with the fraction done and may
    /// return `false` to cancel.
    pub fn plan(
        &self,
        options: JsValue,
        progress: Option<js_sys::Function>,
    ) -> Result<WasmPlan, JsError> {
        let opts = plan_options(options)?;
        let t0 = now_ms();
        let mut cb = progress_callback(&progress);
        let planned = crate::plan::plan(&self.model, &opts, &mut cb).map_err(js_err)?;
        let mut report = planned.report(&opts);
        report.plan_ms = now_ms() - t0;
        Ok(self.wasm_plan(planned, opts, report))
    }

    /// Compares strategies on this model, as `tspath compare` does: `options` as for `plan`;
    /// `strategies` a comma-separated list (every strategy when empty or absent); `machine`
    /// a built-in name or machine JSON text, the machine the times are for (each plan's
    /// default when absent); `simulate` whether each cut is simulated (error bound a quarter
    /// of the scallop). `progress` as for `plan`. Each row's plan stays in the result, to be
    /// taken as the current plan without planning again.
    pub fn compare(
        &self,
        options: JsValue,
        strategies: Option<String>,
        machine: Option<String>,
        simulate: bool,
        progress: Option<js_sys::Function>,
    ) -> Result<WasmComparison, JsError> {
        let opts = plan_options(options)?;
        let entries = crate::plan::compare::Entry::parse_list(
            strategies.as_deref().filter(|s| !s.trim().is_empty()),
        )
        .map_err(js_err)?;
        let mach = machine
            .as_deref()
            .map(machine::resolve)
            .transpose()
            .map_err(js_err)?;
        let mut cb = progress_callback(&progress);
        let (comparison, kept) = crate::plan::compare::compare(
            &self.model,
            &opts,
            &entries,
            mach.as_ref(),
            simulate.then_some(verify::PLAN_VERIFY_MAX_SAMPLES),
            &now_ms,
            &mut cb,
        )
        .map_err(js_err)?;
        let plans = kept
            .into_iter()
            .map(|k| k.map(|(planned, o, report)| self.wasm_plan(planned, o, report)))
            .collect();
        Ok(WasmComparison { comparison, plans })
    }
}

impl WasmModel {
    /// A plan handle for JavaScript, with what its layers and the verification need.
    fn wasm_plan(
        &self,
        planned: crate::plan::Planned,
        opts: PlanOptions,
        report: PlanReport,
    ) -> WasmPlan {
        let rest_rects = planned.rest_rects(&self.model);
        let (rest_positions, rest_why) = planned.rest_triangles(&self.model);
        let job = JobInfo::for_model(&self.model, planned.strategy);
        WasmPlan {
            isfc_layer: planned.isfc_layer,
            watershed_layer: planned.watershed_layer,
            path: planned.toolpath,
            report,
            opts,
            job,
            rest_rects,
            rest_positions,
            rest_why,
            posted: RefCell::new(None),
        }
    }
}

/// Plan options from a plain JavaScript object (the defaults for `undefined` or `null`).
fn plan_options(options: JsValue) -> Result<PlanOptions, JsError> {
    if options.is_undefined() || options.is_null() {
        Ok(PlanOptions::default())
    } else {
        serde_wasm_bindgen::from_value(options)
            .map_err(|e| JsError::new(&format!("invalid plan options: {e}")))
    }
}

/// A progress callback that calls `progress` (if given) with the fraction done; a `false`
/// from it cancels.
fn progress_callback(progress: &Option<js_sys::Function>) -> impl FnMut(f64) -> bool + '_ {
    move |f: f64| -> bool {
        match progress {
            Some(func) => func
                .call1(&JsValue::NULL, &JsValue::from_f64(f))
                .map(|r| r.as_bool() != Some(false))
                .unwrap_or(true),
            None => true,
        }
    }
}

/// Strategies compared on one model: the table (as `tspath compare --report` writes it),
/// its CSV, and each row's plan.
#[wasm_bindgen(js_name = Comparison)]
pub struct WasmComparison {
    comparison: crate::plan::compare::Comparison,
    plans: Vec<Option<WasmPlan>>,
}

#[wasm_bindgen(js_class = Comparison)]
impl WasmComparison {
    /// The comparison as a plain object: `model`, `tool_radius_mm`, `scallop_mm`,
    /// `area_mm2`, `l_min_mm`, `l_min_flat_mm` and `runs` (one per strategy, with `error`
    /// where it could not plan), the keys of `tspath compare --report`.
    pub fn report(&self) -> Result<JsValue, JsError> {
        to_js(&self.comparison)
    }

    /// The table as CSV, the bytes `tspath compare --csv` writes.
    pub fn csv(&self) -> String {
        self.comparison.csv()
    }

    /// The table as Markdown, as `tspath compare` prints it.
    pub fn markdown(&self) -> String {
        self.comparison.markdown()
    }

    /// Row `k`'s ball-centre points, `x y z` per move (mm; empty where it could not plan),
    /// for a small view of its path.
    #[wasm_bindgen(js_name = clPoints)]
    pub fn cl_points(&self, k: usize) -> js_sys::Float32Array {
        let pts: Vec<f32> = self
            .plans
            .get(k)
            .and_then(|p| p.as_ref())
            .map(|p| {
                p.path
                    .moves
                    .iter()
                    .flat_map(|m| m.cl_point.iter().map(|&x| x as f32).collect::<Vec<_>>())
                    .collect()
            })
            .unwrap_or_default();
        js_sys::Float32Array::from(&pts[..])
    }

    /// Row `k`'s move kinds (as `Plan.moveKinds`).
    #[wasm_bindgen(js_name = moveKinds)]
    pub fn move_kinds(&self, k: usize) -> js_sys::Uint8Array {
        let kinds: Vec<u8> = self
            .plans
            .get(k)
            .and_then(|p| p.as_ref())
            .map(|p| p.path.moves.iter().map(|m| m.kind as u8).collect())
            .unwrap_or_default();
        js_sys::Uint8Array::from(&kinds[..])
    }

    /// Takes row `k`'s plan out (to make it the current plan); throws where the strategy
    /// could not plan or the plan was taken already.
    pub fn take(&mut self, k: usize) -> Result<WasmPlan, JsError> {
        let name = self
            .comparison
            .runs
            .get(k)
            .map(|r| r.strategy.clone())
            .ok_or_else(|| JsError::new(&format!("the comparison has no row {k}")))?;
        self.plans.get_mut(k).and_then(Option::take).ok_or_else(|| {
            JsError::new(&format!(
                "{name} has no plan to take (it could not plan the model, or it was taken)"
            ))
        })
    }
}

/// A planned tool path with its report and G-code.
#[wasm_bindgen(js_name = Plan)]
pub struct WasmPlan {
    path: Toolpath,
    report: PlanReport,
    opts: PlanOptions,
    job: JobInfo,
    /// The rest area as face rectangles, for the verification's mask.
    rest_rects: Vec<RestRect>,
    /// The rest area as triangles (`x y z` per vertex, mm) and their reasons.
    rest_positions: Vec<f32>,
    rest_why: Vec<u8>,
    /// The space-filling curve's cells and tree (`isfc` plans only), kept from planning.
    isfc_layer: Option<IsfcLayer>,
    /// The rectangles (`watershed` and `multi-rectangle` plans only), kept from planning.
    watershed_layer: Option<WatershedLayer>,
    /// The last program `gcodeLines` posted and what for (machine, dialect, units), so that
    /// `gcodeFor` the same does not post it again.
    posted: RefCell<Option<([String; 3], String)>>,
}

impl WasmPlan {
    /// The cells-and-tree layer, or an error saying that only `isfc` plans have one.
    fn layer(&self) -> Result<&IsfcLayer, JsError> {
        self.isfc_layer.as_ref().ok_or_else(|| {
            JsError::new(&format!(
                "this plan's strategy is {}: only a space-filling-curve plan (strategy isfc) has cells and a tree to draw",
                self.report.strategy
            ))
        })
    }

    /// The rectangles layer, or an error saying that only the watershed strategies have one.
    fn rectangles(&self) -> Result<&WatershedLayer, JsError> {
        self.watershed_layer.as_ref().ok_or_else(|| {
            JsError::new(&format!(
                "this plan's strategy is {}: only the watershed and multi-rectangle strategies cut the surface into rectangles to draw",
                self.report.strategy
            ))
        })
    }
}

#[wasm_bindgen(js_class = Plan)]
impl WasmPlan {
    /// Ball-centre points `x y z` per move (mm).
    #[wasm_bindgen(js_name = clPoints)]
    pub fn cl_points(&self) -> js_sys::Float64Array {
        let v: Vec<f64> = self
            .path
            .moves
            .iter()
            .flat_map(|m| [m.cl_point.x, m.cl_point.y, m.cl_point.z])
            .collect();
        js_sys::Float64Array::from(&v[..])
    }
    /// Cutter-contact points `x y z` per move (mm).
    #[wasm_bindgen(js_name = ccPoints)]
    pub fn cc_points(&self) -> js_sys::Float64Array {
        let v: Vec<f64> = self
            .path
            .moves
            .iter()
            .flat_map(|m| [m.cc_point.x, m.cc_point.y, m.cc_point.z])
            .collect();
        js_sys::Float64Array::from(&v[..])
    }
    /// Unit tool axes `x y z` per move.
    pub fn axes(&self) -> js_sys::Float64Array {
        let v: Vec<f64> = self
            .path
            .moves
            .iter()
            .flat_map(|m| [m.tool_axis.x, m.tool_axis.y, m.tool_axis.z])
            .collect();
        js_sys::Float64Array::from(&v[..])
    }
    /// Move kind per move: 0 feed, 1 link, 2 retract, 3 rapid, 4 plunge, 5 approach (in the air
    /// at the plunge feed, from the feed height).
    #[wasm_bindgen(js_name = moveKinds)]
    pub fn move_kinds(&self) -> js_sys::Uint8Array {
        let v: Vec<u8> = self.path.moves.iter().map(|m| m.kind as u8).collect();
        js_sys::Uint8Array::from(&v[..])
    }
    /// Patch per move.
    #[wasm_bindgen(js_name = patchIds)]
    pub fn patch_ids(&self) -> js_sys::Uint32Array {
        let v: Vec<u32> = self.path.moves.iter().map(|m| m.patch).collect();
        js_sys::Uint32Array::from(&v[..])
    }
    /// The report: lengths (mm), counts, predicted scallop (mm), time (min), `plan_ms`,
    /// `status` (`planned` or `planned_with_problems`), `unreachable_area_mm2`, `rest`
    /// (regions) and `problems` (each with `kind`, `message`, `at_mm` and `near_move`).
    pub fn report(&self) -> Result<JsValue, JsError> {
        to_js(&self.report)
    }

    /// The report with what a cutting simulation of this plan found added to its problems
    /// and status (gouges, scallop over the request, an error bound too wide to prove it).
    #[wasm_bindgen(js_name = reportWith)]
    pub fn report_with(&self, verification: &WasmVerification) -> Result<JsValue, JsError> {
        let mut r = self.report.clone();
        r.add_verification(&verification.summary);
        to_js(&r)
    }

    /// The rest area (what the plan leaves unmachined) as triangles on the surface: `x y z`
    /// per vertex (mm), three vertices per triangle.
    #[wasm_bindgen(js_name = restPositions)]
    pub fn rest_positions(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(&self.rest_positions[..])
    }

    /// Per triangle of `restPositions`, why it is not machined: 0 the surface faces away
    /// from every allowed axis, 1 the shank or holder would hit, 2 the surface is tighter
    /// than the ball, 3 no clear way there through the air.
    #[wasm_bindgen(js_name = restReasons)]
    pub fn rest_reasons(&self) -> js_sys::Uint8Array {
        js_sys::Uint8Array::from(&self.rest_why[..])
    }
    /// `isfc` plans: the outline of every 2 × 2 cell of grid vertices, four segments per
    /// cell between the vertices' contact points, `x y z x y z` per segment (mm). Throws
    /// for other strategies.
    #[wasm_bindgen(js_name = isfcCells)]
    pub fn isfc_cells(&self) -> Result<js_sys::Float32Array, JsError> {
        Ok(js_sys::Float32Array::from(&self.layer()?.cells[..]))
    }

    /// `isfc` plans: the links of the spanning tree, one segment per link from the centre of
    /// one cell to the centre of the other (the mean of its corners' contact points),
    /// `x y z x y z` (mm). Throws for other strategies.
    #[wasm_bindgen(js_name = isfcTree)]
    pub fn isfc_tree(&self) -> Result<js_sys::Float32Array, JsError> {
        Ok(js_sys::Float32Array::from(&self.layer()?.tree[..]))
    }

    /// `isfc` plans: per tree link of `isfcTree`, 1 if it joins two patches across the side
    /// they share, else 0. Throws for other strategies.
    #[wasm_bindgen(js_name = isfcTreeAcross)]
    pub fn isfc_tree_across(&self) -> Result<js_sys::Uint8Array, JsError> {
        Ok(js_sys::Uint8Array::from(&self.layer()?.across[..]))
    }

    /// `isfc` plans: where the curve starts, `x y z` (mm; empty if it has no loop). Throws
    /// for other strategies.
    #[wasm_bindgen(js_name = isfcStart)]
    pub fn isfc_start(&self) -> Result<js_sys::Float64Array, JsError> {
        let s = self.layer()?.start_mm.map_or(Vec::new(), |p| p.to_vec());
        Ok(js_sys::Float64Array::from(&s[..]))
    }

    /// `watershed` and `multi-rectangle` plans: every rectangle filled with triangles on the
    /// surface, `x y z` per corner (mm), in the order of the plan's patches. Throws for other
    /// strategies.
    #[wasm_bindgen(js_name = rectangleFills)]
    pub fn rectangle_fills(&self) -> Result<js_sys::Float32Array, JsError> {
        Ok(js_sys::Float32Array::from(&self.rectangles()?.fills[..]))
    }

    /// Per triangle of `rectangleFills`, its rectangle's region: 0 background, 1 convex,
    /// 2 concave. Throws for other strategies.
    #[wasm_bindgen(js_name = rectangleKinds)]
    pub fn rectangle_kinds(&self) -> Result<js_sys::Uint8Array, JsError> {
        Ok(js_sys::Uint8Array::from(&self.rectangles()?.fill_kinds[..]))
    }

    /// The rectangles' sides on the surface, `x y z x y z` per segment (mm). Throws for
    /// other strategies.
    #[wasm_bindgen(js_name = rectangleOutlines)]
    pub fn rectangle_outlines(&self) -> Result<js_sys::Float32Array, JsError> {
        Ok(js_sys::Float32Array::from(&self.rectangles()?.outlines[..]))
    }

    /// Per rectangle an arrow along its passes (shaft and two barbs, three segments,
    /// `x y z x y z` each, mm). Throws for other strategies.
    #[wasm_bindgen(js_name = rectangleArrows)]
    pub fn rectangle_arrows(&self) -> Result<js_sys::Float32Array, JsError> {
        Ok(js_sys::Float32Array::from(&self.rectangles()?.arrows[..]))
    }

    /// The default G-code program, in mm: three-axis (plain dialect) while the tool axis
    /// stays at +Z, else LinuxCNC joint values for the `table-table-ac` machine. Written when
    /// asked for, so a plan whose default program cannot be written is still a plan; throws
    /// with the machine module's reason then (see `gcodeFor` for any other choice).
    pub fn gcode(&self) -> Result<String, JsError> {
        let m = machine::default_machine(&self.path);
        let dialect = if m.rotaries.is_empty() {
            Dialect::Plain
        } else {
            Dialect::LinuxCnc
        };
        machine::post(&self.path, &self.opts, &self.job, &m, dialect, Units::Mm).map_err(js_err)
    }

    /// The program for a machine, dialect and units: `machine` is a built-in machine name
    /// (see `machineNames()`) or the text of a machine JSON file; `dialect` one of
    /// `dialectNames()`; `units` `mm` or `inch`. Throws with a message naming the move when
    /// the machine cannot do the path.
    #[wasm_bindgen(js_name = gcodeFor)]
    pub fn gcode_for(&self, machine: &str, dialect: &str, units: &str) -> Result<String, JsError> {
        let m = machine::resolve(machine).map_err(js_err)?;
        let d = Dialect::parse(dialect).map_err(js_err)?;
        let u = Units::parse(units).map_err(js_err)?;
        let key = [machine, dialect, units].map(str::to_string);
        if let Some((k, text)) = self.posted.borrow().as_ref() {
            if *k == key {
                return Ok(text.clone());
            }
        }
        machine::post(&self.path, &self.opts, &self.job, &m, d, u).map_err(js_err)
    }

    /// Times the plan on `machine` (a built-in name or machine JSON text): the report's
    /// `machining_time_min` and `time_machine` become that machine's, as `tspath plan
    /// --machine` reports them. Throws for a machine that cannot be read.
    #[wasm_bindgen(js_name = timeOn)]
    pub fn time_on(&mut self, machine: &str) -> Result<(), JsError> {
        let m = machine::resolve(machine).map_err(js_err)?;
        self.report.set_machining_time(&self.path, &self.opts, &m);
        Ok(())
    }

    /// For each move, the 1-based line of the program `gcodeFor(machine, dialect, units)`
    /// returns that ends at it (for highlighting the block beside a scrubbed tool): the post
    /// records the line of each motion block it writes and which move that block is; a move
    /// the post wrote no block for gets the line of the block before it.
    #[wasm_bindgen(js_name = gcodeLines)]
    pub fn gcode_lines(
        &self,
        machine: &str,
        dialect: &str,
        units: &str,
    ) -> Result<js_sys::Uint32Array, JsError> {
        let m = machine::resolve(machine).map_err(js_err)?;
        let d = Dialect::parse(dialect).map_err(js_err)?;
        let u = Units::parse(units).map_err(js_err)?;
        let posted = machine::post::post_program(&self.path, &self.opts, &self.job, &m, d, u)
            .map_err(js_err)?;
        let mut lines = vec![0u32; self.path.moves.len()];
        for (src, &line) in posted.sources.iter().zip(&posted.lines) {
            if let machine::post::Source::Move(i) = *src {
                if let Some(l) = lines.get_mut(i) {
                    *l = line as u32;
                }
            }
        }
        let key = [machine, dialect, units].map(str::to_string);
        *self.posted.borrow_mut() = Some((key, posted.text));
        let mut last = 0;
        for l in lines.iter_mut() {
            if *l == 0 {
                *l = last;
            } else {
                last = *l;
            }
        }
        Ok(js_sys::Uint32Array::from(&lines[..]))
    }
}

/// The `bound_mm` and `max_samples` fields of verify options, if given.
fn bound_options(options: &JsValue) -> Result<(Option<f64>, usize), JsError> {
    if options.is_undefined() || options.is_null() {
        return Ok((None, verify::PLAN_VERIFY_MAX_SAMPLES));
    }
    let given: serde_json::Value = serde_wasm_bindgen::from_value(options.clone())
        .map_err(|e| JsError::new(&format!("invalid verify options: {e}")))?;
    let bound = given.get("bound_mm").and_then(|v| v.as_f64());
    let max = given
        .get("max_samples")
        .and_then(|v| v.as_u64())
        .map_or(verify::PLAN_VERIFY_MAX_SAMPLES, |v| v as usize);
    Ok((bound, max))
}

/// Verification options from a JavaScript object over `base`: any fields of
/// [`VerifyOptions`] given replace those of `base` (`bound_mm` and `max_samples` are read
/// by [`bound_options`]).
fn verify_options(base: VerifyOptions, options: JsValue) -> Result<VerifyOptions, JsError> {
    if options.is_undefined() || options.is_null() {
        return Ok(base);
    }
    let mut given: serde_json::Value = serde_wasm_bindgen::from_value(options)
        .map_err(|e| JsError::new(&format!("invalid verify options: {e}")))?;
    if let Some(o) = given.as_object_mut() {
        o.remove("bound_mm");
        o.remove("max_samples");
    }
    let mut merged = serde_json::to_value(&base).expect("options serialise");
    match (given, &mut merged) {
        (serde_json::Value::Object(g), serde_json::Value::Object(m)) => {
            for (k, v) in g {
                m.insert(k, v);
            }
        }
        _ => return Err(JsError::new("invalid verify options: expected an object")),
    }
    serde_json::from_value(merged)
        .map_err(|e| JsError::new(&format!("invalid verify options: {e}")))
}

#[wasm_bindgen(js_class = Model)]
impl WasmModel {
    /// The samples the first round of `plan`'s bounded simulation takes at least (the
    /// model's area at the spacing rule's density; it starts from `samples` where more).
    #[wasm_bindgen(js_name = verifyFirstSamples)]
    pub fn verify_first_samples(&self, plan: &WasmPlan) -> f64 {
        verify::first_round_samples(
            &self.model.surface,
            plan.opts.tool_radius_mm,
            plan.opts.scallop_mm,
        ) as f64
    }

    /// Simulates the ball-end cut of `plan` on this model and measures scallops and gouges.
    /// `mesh` is the tessellation the page shows (from `tessellate`): the heat map has one
    /// value per vertex of it. `options` is a plain object with any of `samples`,
    /// `scallop_mm`, `gouge_tolerance_mm`, `tool_side` (`"auto"`, `"normal"`, `"opposite"`);
    /// the scallop defaults to the plan's, the gouge tolerance to its chordal tolerance or
    /// 0.002 mm, whichever is smaller, and the plan's rest area is measured apart. With
    /// `bound_mm` the sample count grows from `samples` (to at most `max_samples`, default
    /// 8 000 000) until the error bound is within it. `progress`, if given, is called with
    /// the fraction done (its answer is ignored: the page cancels by stopping the worker).
    pub fn verify(
        &self,
        plan: &WasmPlan,
        mesh: &WasmMesh,
        options: JsValue,
        progress: Option<js_sys::Function>,
    ) -> Result<WasmVerification, JsError> {
        let (bound, max_samples) = bound_options(&options)?;
        let base = verify::plan_options(&plan.opts, plan.rest_rects.clone());
        let opts = verify_options(base, options)?;
        let path = CutterPath::from_toolpath(&plan.path).map_err(js_err)?;
        let t0 = now_ms();
        let mut cb = progress_callback(&progress);
        let mut report = |f: f64| {
            cb(f);
        };
        let (summary, heat) = match bound {
            Some(b) => verify::verify_to_bound_with_heat_map(
                &self.model.surface,
                &path,
                &opts,
                b,
                max_samples,
                &mesh.mesh,
                &mut report,
            ),
            None => verify::verify_with_heat_map_progress(
                &self.model.surface,
                &path,
                &opts,
                &mesh.mesh,
                &mut report,
            ),
        }
        .map_err(js_err)?;
        Ok(WasmVerification {
            summary,
            heat,
            verify_ms: now_ms() - t0,
        })
    }

    /// As `verify`, for a program (any dialect the project writes, for `machine`, a
    /// built-in name or machine JSON, and `dialect`, as for `gcodeFor`) cut with a ball-end
    /// of radius `tool_radius_mm` (mm). The scallop and gouge tolerance default to those in
    /// the program's header.
    #[wasm_bindgen(js_name = verifyGcode)]
    pub fn verify_gcode(
        &self,
        gcode: &str,
        tool_radius_mm: f64,
        machine: &str,
        dialect: &str,
        mesh: &WasmMesh,
        options: JsValue,
    ) -> Result<WasmVerification, JsError> {
        let m = machine::resolve(machine).map_err(js_err)?;
        let d = Dialect::parse(dialect).map_err(js_err)?;
        let (path, header) =
            verify::gcode::read_program(gcode, tool_radius_mm, &m, d).map_err(js_err)?;
        let opts = verify_options(header.options(), options)?;
        let t0 = now_ms();
        let (summary, heat) =
            verify::verify_with_heat_map(&self.model.surface, &path, &opts, &mesh.mesh)
                .map_err(js_err)?;
        Ok(WasmVerification {
            summary,
            heat,
            verify_ms: now_ms() - t0,
        })
    }
}

/// The result of a verification: its summary and the heat map.
#[wasm_bindgen(js_name = Verification)]
pub struct WasmVerification {
    summary: Verification,
    heat: Vec<f32>,
    verify_ms: f64,
}

#[wasm_bindgen(js_class = Verification)]
impl WasmVerification {
    /// `{max_scallop_mm, mean_scallop_mm, p95_scallop_mm, uncut_fraction,
    /// unreached_fraction, max_gouge_mm, gouge_count, error_bound_mm, samples, ...,
    /// patches: [...]}` (all lengths in mm), as `tspath verify` prints it.
    pub fn summary(&self) -> Result<JsValue, JsError> {
        to_js(&self.summary)
    }

    /// One value per vertex of the mesh passed to `verify`: the deepest gouge as a negative
    /// number (mm) where the cut went below the surface by more than the gouge tolerance,
    /// else the most material left (mm); `Infinity` where the tool never came within one
    /// radius.
    #[wasm_bindgen(js_name = heatMap)]
    pub fn heat_map(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(&self.heat[..])
    }

    /// Wall time of the simulation (ms).
    #[wasm_bindgen(getter, js_name = verifyMs)]
    pub fn verify_ms(&self) -> f64 {
        self.verify_ms
    }
}
