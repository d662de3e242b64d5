//! The JavaScript API, and the only module with `#[wasm_bindgen]`.
//!
//! Large data stays in wasm memory behind opaque handles ([`WasmModel`], [`WasmPlan`]);
//! JavaScript gets small serde objects (summaries, reports) and flat typed arrays, never one
//! call per point. Every fallible call returns `Result<_, JsError>`, which arrives in
//! JavaScript as a thrown `Error` whose message says what to fix.
//!
//! This file is what the page's first module (the viewer) holds: loading, placing and
//! tessellating models, and the names of the samples, machines and dialects. Planning, posting
//! and the simulation are in [`planner`], built with the `planner` feature (on by default).

use crate::error::Error;
use crate::machine;
use crate::model::{samples, Model};
use crate::surface::tessellate::Tessellation;
use crate::verify;
use wasm_bindgen::prelude::*;

#[cfg(target_arch = "wasm32")]
mod grow;
#[cfg(feature = "planner")]
pub mod planner;
#[cfg(feature = "planner")]
pub use planner::*;

fn js_err(e: Error) -> JsError {
    JsError::new(&e.to_string())
}

/// A summary or report as a plain JavaScript object, with absent values (`None`) as `null`,
/// as the CLI's JSON has them (not `undefined`).
fn to_js<T: serde::Serialize>(value: &T) -> Result<JsValue, JsError> {
    value
        .serialize(&serde_wasm_bindgen::Serializer::new().serialize_missing_as_null(true))
        .map_err(|e| JsError::new(&e.to_string()))
}

/// Names of the built-in sample models.
#[wasm_bindgen(js_name = sampleNames)]
pub fn sample_names() -> Vec<String> {
    samples::SAMPLES
        .iter()
        .map(|s| s.name.to_string())
        .collect()
}

/// Names of the built-in machines (`3-axis`, `table-table-ac`, ...).
#[wasm_bindgen(js_name = machineNames)]
pub fn machine_names() -> Vec<String> {
    machine::MACHINES
        .iter()
        .map(|m| m.name.to_string())
        .collect()
}

/// Names of the G-code dialects (`linuxcnc`, `fanuc`, ...).
#[wasm_bindgen(js_name = dialectNames)]
pub fn dialect_names() -> Vec<String> {
    machine::DIALECTS
        .iter()
        .map(|(_, n, _)| n.to_string())
        .collect()
}

/// A built-in machine as the JSON text users edit (see the README's "Machines").
#[wasm_bindgen(js_name = machineJson)]
pub fn machine_json(name: &str) -> Result<String, JsError> {
    machine::builtin(name)
        .map(|m| machine::to_json(&m))
        .map_err(js_err)
}

/// How far a built-in machine can tilt the tool from +Z (degrees; 0 for three axes): the
/// page's largest tilt must stay within it.
#[wasm_bindgen(js_name = machineReachableTiltDeg)]
pub fn machine_reachable_tilt_deg(name: &str) -> Result<f64, JsError> {
    machine::builtin(name)
        .map(|m| m.reachable_tilt_deg())
        .map_err(js_err)
}

/// Fewest samples a plan's cutting simulation starts with unless told otherwise (`samples` of
/// `Model.verify`; more where the spacing rule asks for more): as `tspath plan --verify`.
#[wasm_bindgen(js_name = planVerifySamples)]
pub fn plan_verify_samples() -> f64 {
    verify::PLAN_VERIFY_SAMPLES as f64
}

/// Most samples a plan's cutting simulation grows to while aiming for its error bound
/// unless told otherwise (`max_samples` of `Model.verify`): the same cap as
/// `tspath plan --verify` uses, so the page's default measures a plan as the CLI does.
#[wasm_bindgen(js_name = planVerifyMaxSamples)]
pub fn plan_verify_max_samples() -> f64 {
    verify::PLAN_VERIFY_MAX_SAMPLES as f64
}

/// Lead of the tool axis from the surface normal in the `gan2014` axis preset (degrees): the
/// axis of Gan et al. (2014), as `tspath plan --axis-preset gan2014` sets it (tilt 0°).
#[wasm_bindgen(js_name = paperLeadDeg)]
pub fn paper_lead_deg() -> f64 {
    crate::plan::options::PAPER_LEAD_DEG
}

/// The crate version, for page footers and G-code headers.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// A loaded model, held in wasm memory.
#[wasm_bindgen(js_name = Model)]
pub struct WasmModel {
    model: Model,
}

#[wasm_bindgen(js_class = Model)]
impl WasmModel {
    /// Loads a model file from its bytes; the format (JSON T-mesh, .tsm, .obj) is detected
    /// from the content. `name` is used when the file carries none.
    #[wasm_bindgen(js_name = fromBytes)]
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<WasmModel, JsError> {
        crate::io::load(bytes, name)
            .map(|model| WasmModel { model })
            .map_err(js_err)
    }

    /// A built-in sample model.
    pub fn sample(name: &str) -> Result<WasmModel, JsError> {
        samples::load_sample(name)
            .map(|model| WasmModel { model })
            .map_err(js_err)
    }

    /// As `fromBytes`, the model placed by `setup`: a plain object with any of
    /// `model_units` (`"mm"`, `"cm"`, `"m"`, `"inch"`: the unit of a file that does not say),
    /// `scale`, `up` (`"z"`, `"y"`), `rotate_deg` (0, 90, 180, 270) and `on_table`, as the
    /// CLI's `--model-units`, `--scale`, `--up`, `--rotate` and `--on-table`.
    #[wasm_bindgen(js_name = fromBytesPlaced)]
    pub fn from_bytes_placed(
        bytes: &[u8],
        name: &str,
        setup: JsValue,
    ) -> Result<WasmModel, JsError> {
        crate::io::load_with(bytes, name, &import_setup(setup)?)
            .map(|model| WasmModel { model })
            .map_err(js_err)
    }

    /// As `sample`, placed by `setup` (see `fromBytesPlaced`).
    #[wasm_bindgen(js_name = samplePlaced)]
    pub fn sample_placed(name: &str, setup: JsValue) -> Result<WasmModel, JsError> {
        samples::load_sample_with(name, &import_setup(setup)?)
            .map(|model| WasmModel { model })
            .map_err(js_err)
    }

    /// The model's name.
    #[wasm_bindgen(getter)]
    pub fn name(&self) -> String {
        self.model.name.clone()
    }

    /// Counts and bounding box: `{name, format, units_read, vertices, faces, control_points,
    /// t_junctions, extraordinary_points, holes, patches, bbox_mm: {min, max},
    /// smallest_concave_radius: {radius_mm, at_mm} | null}` (mm).
    pub fn summary(&self) -> Result<JsValue, JsError> {
        to_js(&self.model.summary())
    }

    /// As `summary`, without `smallest_concave_radius` (the key is absent: not looked for),
    /// whose search samples every face: what a page shows before the model is drawn.
    #[wasm_bindgen(js_name = quickSummary)]
    pub fn quick_summary(&self) -> Result<JsValue, JsError> {
        let s = to_js(&self.model.summary_without_concave())?;
        let key = JsValue::from_str("smallest_concave_radius");
        js_sys::Reflect::delete_property(s.unchecked_ref::<js_sys::Object>(), &key)
            .map_err(|_| JsError::new("could not shape the summary"))?;
        Ok(s)
    }

    /// The summary's `smallest_concave_radius`: `{radius_mm, at_mm}` (mm) or `null` where
    /// nothing is concave; found once, then remembered.
    #[wasm_bindgen(js_name = smallestConcaveRadius)]
    pub fn smallest_concave_radius(&self) -> Result<JsValue, JsError> {
        to_js(&self.model.smallest_concave_radius())
    }

    /// Positions of the extraordinary points on the surface, `x y z` each (mm).
    #[wasm_bindgen(js_name = extraordinaryPoints)]
    pub fn extraordinary_points(&self) -> js_sys::Float64Array {
        let v: Vec<f64> = self
            .model
            .extraordinary_positions()
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        js_sys::Float64Array::from(&v[..])
    }

    /// The control mesh as line segments, `x y z x y z` per edge (mm), each edge once, in
    /// half-edge order (for drawing the cage over the surface).
    #[wasm_bindgen(js_name = controlEdges)]
    pub fn control_edges(&self) -> js_sys::Float64Array {
        let mesh = &self.model.mesh;
        let mut v: Vec<f64> = Vec::new();
        for (h, he) in mesh.half_edges().iter().enumerate() {
            if he.twin.is_some_and(|t| (t as usize) < h) {
                continue;
            }
            let a = mesh.points()[he.origin as usize].point;
            let b = mesh.points()[mesh.he(he.next).origin as usize].point;
            v.extend_from_slice(&[a.x, a.y, a.z, b.x, b.y, b.z]);
        }
        js_sys::Float64Array::from(&v[..])
    }

    /// Evaluates point and first and second derivatives on an `n × n` grid of every face and
    /// returns the number of evaluations; a timing hook for the wasm benchmark script.
    #[wasm_bindgen(js_name = benchDerivs)]
    pub fn bench_derivs(&self, n: u32) -> f64 {
        let mut count = 0.0;
        let mut acc = 0.0;
        let n = n.max(1) as usize;
        for f in 0..self.model.surface.faces().len() {
            for k in 0..n * n {
                let (i, j) = (k % n, k / n);
                let d = self.model.surface.derivs(
                    f,
                    (i as f64 + 0.37) / n as f64,
                    (j as f64 + 0.61) / n as f64,
                );
                acc += d.point.x + d.suu.y + d.svv.z;
                count += 1.0;
            }
        }
        if acc.is_nan() {
            -count
        } else {
            count
        }
    }

    /// Triangles of the surface within `chordal_mm` (mm) of it.
    pub fn tessellate(&self, chordal_mm: f64) -> Result<WasmMesh, JsError> {
        if !(chordal_mm.is_finite() && chordal_mm > 0.0) {
            return Err(js_err(Error::param(
                "chordal_mm",
                format!("must be a positive number of mm, got {chordal_mm}"),
            )));
        }
        Ok(WasmMesh {
            mesh: self.model.tessellate(chordal_mm),
        })
    }
}

/// A model set-up from a plain JavaScript object (the identity for `undefined` or `null`).
fn import_setup(setup: JsValue) -> Result<crate::model::setup::ImportSetup, JsError> {
    if setup.is_undefined() || setup.is_null() {
        Ok(Default::default())
    } else {
        serde_wasm_bindgen::from_value(setup)
            .map_err(|e| JsError::new(&format!("invalid model placement: {e}")))
    }
}

/// A tessellation, copied out as typed arrays.
#[wasm_bindgen(js_name = SurfaceMesh)]
pub struct WasmMesh {
    mesh: Tessellation,
}

#[wasm_bindgen(js_class = SurfaceMesh)]
impl WasmMesh {
    /// `x y z` per vertex (mm).
    pub fn positions(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(&self.mesh.positions[..])
    }
    /// Unit normal per vertex.
    pub fn normals(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(&self.mesh.normals[..])
    }
    /// Three vertex indices per triangle.
    pub fn indices(&self) -> js_sys::Uint32Array {
        js_sys::Uint32Array::from(&self.mesh.indices[..])
    }
    /// Patch of each triangle.
    #[wasm_bindgen(js_name = patchIds)]
    pub fn patch_ids(&self) -> js_sys::Uint32Array {
        js_sys::Uint32Array::from(&self.mesh.patch_ids[..])
    }
    /// The triangles as a binary STL file (mm), the same bytes `tspath export MODEL -o
    /// FILE.stl` writes for the same tolerance; `name` goes into the 80-byte header.
    pub fn stl(&self, name: &str) -> js_sys::Uint8Array {
        js_sys::Uint8Array::from(&crate::io::export::stl(&self.mesh, name)[..])
    }
}
