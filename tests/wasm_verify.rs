//! The verification API as JavaScript sees it (a module of `tests/wasm.rs`).

use tspath::wasm::WasmModel as Model;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::*;

fn get(obj: &JsValue, key: &str) -> JsValue {
    js_sys::Reflect::get(obj, &JsValue::from_str(key)).unwrap()
}

fn js_message(e: wasm_bindgen::JsError) -> String {
    let v: JsValue = e.into();
    let err: js_sys::Error = v.dyn_into().expect("errors arrive as Error objects");
    err.message().into()
}

#[wasm_bindgen_test]
fn plan_verifies_with_a_heat_map_per_vertex() {
    let model = Model::sample("dome").unwrap();
    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"tool_radius_mm".into(), &2.0.into()).unwrap();
    js_sys::Reflect::set(&options, &"scallop_mm".into(), &0.05.into()).unwrap();
    let plan = model.plan(options.into(), None).unwrap();
    let mesh = model.tessellate(0.01).unwrap();
    let vopts = js_sys::Object::new();
    js_sys::Reflect::set(&vopts, &"samples".into(), &50_000.into()).unwrap();
    let v = model
        .verify(&plan, &mesh, vopts.clone().into(), None)
        .unwrap();
    let s = v.summary().unwrap();
    for key in [
        "max_scallop_mm",
        "mean_scallop_mm",
        "p95_scallop_mm",
        "uncut_fraction",
        "max_gouge_mm",
        "gouge_count",
        "error_bound_mm",
        "samples",
    ] {
        assert!(get(&s, key).as_f64().is_some(), "summary.{key}");
    }
    // Defaults from the plan: its scallop, and its chordal tolerance or 0.002 mm, whichever
    // is smaller.
    assert_eq!(get(&s, "requested_scallop_mm").as_f64(), Some(0.05));
    assert_eq!(get(&s, "gouge_tolerance_mm").as_f64(), Some(0.002));
    let max = get(&s, "max_scallop_mm").as_f64().unwrap();
    assert!(max > 0.03 && max < 0.07, "max scallop {max}");
    let heat = v.heat_map();
    assert_eq!(heat.length() * 3, mesh.positions().length());
    let values = heat.to_vec();
    assert!(values
        .iter()
        .all(|h| h.is_finite() && *h >= 0.0 && (*h as f64) <= max + 1e-6));
    assert!(values.iter().any(|h| *h > 0.0));

    // The G-code of the same plan gives the same picture (coordinates rounded to 0.1 µm).
    let g = model
        .verify_gcode(
            &plan.gcode().unwrap(),
            2.0,
            "3-axis",
            "linuxcnc",
            &mesh,
            vopts.into(),
        )
        .unwrap();
    let gmax = get(&g.summary().unwrap(), "max_scallop_mm")
        .as_f64()
        .unwrap();
    assert!((gmax - max).abs() < 1e-4, "{gmax} vs {max}");
    assert_eq!(g.heat_map().length(), heat.length());

    // With `bound_mm` the samples grow until the error bound is within it, and the plan's
    // report takes in what the simulation found.
    let bounded = js_sys::Object::new();
    js_sys::Reflect::set(&bounded, &"samples".into(), &20_000.into()).unwrap();
    js_sys::Reflect::set(&bounded, &"bound_mm".into(), &0.004.into()).unwrap();
    let b = model.verify(&plan, &mesh, bounded.into(), None).unwrap();
    let bs = b.summary().unwrap();
    assert!(get(&bs, "error_bound_mm").as_f64().unwrap() <= 0.004);
    assert!(get(&bs, "samples").as_f64().unwrap() > 20_000.0);
    assert_eq!(get(&bs, "error_bound_target_mm").as_f64(), Some(0.004));
    let report = plan.report_with(&b).unwrap();
    assert_eq!(
        get(&report, "status").as_string().as_deref(),
        Some("planned")
    );

    let bad = js_sys::Object::new();
    js_sys::Reflect::set(&bad, &"samples".into(), &2.into()).unwrap();
    let msg = js_message(model.verify(&plan, &mesh, bad.into(), None).err().unwrap());
    assert!(msg.contains("samples"), "{msg}");
    let msg = js_message(
        model
            .verify_gcode(
                "G0 X0 Y0 Z0\nG2 X1 Y1 I0 J1\n",
                2.0,
                "3-axis",
                "linuxcnc",
                &mesh,
                JsValue::UNDEFINED,
            )
            .err()
            .unwrap(),
    );
    assert!(msg.contains("line 2"), "{msg}");
    let msg = js_message(
        model
            .verify_gcode(
                &plan.gcode().unwrap(),
                1.0,
                "3-axis",
                "linuxcnc",
                &mesh,
                JsValue::UNDEFINED,
            )
            .err()
            .unwrap(),
    );
    assert!(msg.contains("radius 2 mm"), "{msg}");
}
