//! The exported JavaScript API, as JavaScript sees it (a module of `tests/wasm.rs`).

use tspath::wasm::{sample_names, WasmModel as Model};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::*;

/// The message of the JavaScript `Error` a failed call throws.
fn js_message(e: wasm_bindgen::JsError) -> String {
    let v: JsValue = e.into();
    let err: js_sys::Error = v
        .dyn_into()
        .expect("errors arrive in JavaScript as Error objects");
    err.message().into()
}

fn get(obj: &JsValue, key: &str) -> JsValue {
    js_sys::Reflect::get(obj, &JsValue::from_str(key)).unwrap()
}

#[wasm_bindgen_test]
fn sample_loads_plans_and_posts() {
    assert!(sample_names().iter().any(|n| n == "dome"));
    let model = Model::sample("dome").unwrap();
    let summary = model.summary().unwrap();
    assert_eq!(get(&summary, "patches").as_f64(), Some(1.0));
    let bbox = get(&summary, "bbox_mm");
    let max = js_sys::Array::from(&get(&bbox, "max"));
    assert!(
        (max.get(2).as_f64().unwrap() - 20.0).abs() < 1e-9,
        "dome apex at z = 20 mm"
    );

    let mesh = model.tessellate(0.01).unwrap();
    let positions = mesh.positions();
    let indices = mesh.indices();
    assert_eq!(positions.length() % 3, 0);
    assert!(indices.length() >= 3 * 8);
    assert_eq!(mesh.patch_ids().length() * 3, indices.length());

    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"tool_radius_mm".into(), &2.0.into()).unwrap();
    js_sys::Reflect::set(&options, &"scallop_mm".into(), &0.02.into()).unwrap();
    let calls = js_sys::Array::new();
    let progress = js_sys::Function::new_with_args("f", "this.push(f); return true;").bind0(&calls);
    let plan = model.plan(options.into(), Some(progress)).unwrap();
    assert!(calls.length() > 1, "progress is reported while planning");
    let last = calls.get(calls.length() - 1).as_f64().unwrap();
    assert!((last - 1.0).abs() < 1e-12, "progress ends at 1, got {last}");

    let cl = plan.cl_points();
    let kinds = plan.move_kinds();
    assert_eq!(cl.length(), 3 * kinds.length());
    assert_eq!(plan.axes().length(), cl.length());
    let report = plan.report().unwrap();
    assert_eq!(
        get(&report, "cl_points").as_f64(),
        Some(kinds.length() as f64)
    );
    assert!(get(&report, "max_predicted_scallop_mm").as_f64().unwrap() <= 0.02 * (1.0 + 1e-9));
    let gcode = plan.gcode().unwrap();
    assert!(gcode.contains("G21") && gcode.contains("(model: dome)"));
    assert!(gcode.lines().filter(|l| l.starts_with("G1 ")).count() > 100);
}

#[wasm_bindgen_test]
fn cancel_from_progress_callback() {
    let model = Model::sample("dome").unwrap();
    let stop = js_sys::Function::new_with_args("f", "return f < 0.2;");
    let msg = js_message(
        model
            .plan(JsValue::UNDEFINED, Some(stop))
            .err()
            .expect("cancelled"),
    );
    assert_eq!(msg, "cancelled");
}

#[wasm_bindgen_test]
fn malformed_models_throw_errors_with_reasons() {
    let cases: &[(&[u8], &str)] = &[
        (b"", "empty"),
        (b"{\"format\": \"tspath-tmesh\", \"version\": 1, \"points\": [[0, 0", "line 1"),
        (b"{\"format\": \"tspath-tmesh\", \"version\": 1, \"points\": [], \"faces\": [[0, 1, 2, 3]]}", "vertex"),
        (&[0xff, 0xfe, 0x00, 0x13, 0x99], "not a model file"),
    ];
    for (bytes, needle) in cases {
        let msg = js_message(Model::from_bytes(bytes, "bad").err().expect("must fail"));
        assert!(
            msg.contains(needle),
            "message `{msg}` should mention `{needle}`"
        );
    }
}

#[wasm_bindgen_test]
fn impossible_parameters_throw() {
    let model = Model::sample("dome").unwrap();
    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"scallop_mm".into(), &(-1.0).into()).unwrap();
    let msg = js_message(model.plan(options.into(), None).err().expect("must fail"));
    assert!(msg.contains("scallop_mm"), "{msg}");
    assert!(js_message(model.tessellate(0.0).err().unwrap()).contains("chordal"));
}

#[wasm_bindgen_test]
fn machine_dialect_and_units_choice() {
    use tspath::wasm::{dialect_names, machine_json, machine_names};
    assert!(machine_names().iter().any(|n| n == "table-table-ac"));
    assert!(dialect_names().iter().any(|n| n == "heidenhain"));
    let model = Model::sample("dome").unwrap();
    let plan = model.plan(JsValue::UNDEFINED, None).unwrap();
    let default = plan.gcode().unwrap();
    let fanuc = plan.gcode_for("table-table-ac", "fanuc", "inch").unwrap();
    assert!(fanuc.contains("G20") && fanuc.contains("G43.4 H1") && fanuc.contains("(model: dome)"));
    // A machine given as JSON text gives the same program as by name.
    let json = machine_json("table-table-ac").unwrap();
    assert_eq!(plan.gcode_for(&json, "fanuc", "inch").unwrap(), fanuc);
    assert_eq!(plan.gcode_for("3-axis", "plain", "mm").unwrap(), default);
    let msg = js_message(
        plan.gcode_for("table-table-ac", "klingon", "mm")
            .err()
            .unwrap(),
    );
    assert!(msg.contains("klingon") && msg.contains("linuxcnc"), "{msg}");
}

#[wasm_bindgen_test]
fn tsm_bytes_load_through_the_same_loader() {
    // A real T-Splines file, detected from its `#TS0200` tag.
    let bytes = include_bytes!("../www/models/grapetec/simple.tsm");
    let model = Model::from_bytes(bytes, "simple").unwrap();
    let summary = model.summary().unwrap();
    assert_eq!(get(&summary, "format").as_string().as_deref(), Some("tsm"));
    assert_eq!(
        get(&summary, "units_read").as_string().as_deref(),
        Some("millimeters (0.001 m)")
    );
    assert!(get(&summary, "patches").as_f64().unwrap() >= 1.0);
    let broken = String::from_utf8_lossy(bytes).replace("e 0 0.5", "e 0 x");
    let msg = js_message(Model::from_bytes(broken.as_bytes(), "x").err().unwrap());
    assert!(
        msg.contains("line ") && msg.contains("knot interval"),
        "{msg}"
    );
}

/// The number after `letter` in a block (`X12.5`, `X+12.5`), if the block has that word.
fn word(block: &str, letter: char) -> Option<f64> {
    block
        .split_whitespace()
        .find_map(|w| w.strip_prefix(letter).and_then(|v| v.parse().ok()))
}

#[wasm_bindgen_test]
fn gcode_lines_point_at_the_block_of_each_move() {
    let model = Model::sample("dome").unwrap();
    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"tool_radius_mm".into(), &2.0.into()).unwrap();
    js_sys::Reflect::set(&options, &"scallop_mm".into(), &0.05.into()).unwrap();
    js_sys::Reflect::set(&options, &"max_tilt_deg".into(), &0.0.into()).unwrap();
    let plan = model.plan(options.into(), None).unwrap();
    let cl = plan.cl_points().to_vec();
    let axes = plan.axes().to_vec();
    let n = plan.move_kinds().length() as usize;
    // Tool-tip programs: 3-axis LinuxCNC in mm, Heidenhain on a 5-axis machine in inch.
    for (machine, dialect, units, scale) in [
        ("3-axis", "linuxcnc", "mm", 1.0),
        ("table-table-ac", "heidenhain", "inch", 25.4),
    ] {
        let text = plan.gcode_for(machine, dialect, units).unwrap();
        let blocks: Vec<&str> = text.lines().collect();
        let lines = plan.gcode_lines(machine, dialect, units).unwrap().to_vec();
        assert_eq!(lines.len(), n, "one line per move");
        assert!(
            lines.windows(2).all(|w| w[0] <= w[1]),
            "lines follow the moves"
        );
        let mut matched = 0;
        for (i, &line) in lines.iter().enumerate() {
            assert!(
                line >= 1 && (line as usize) <= blocks.len(),
                "move {i}: line {line}"
            );
            let block = blocks[line as usize - 1];
            // The tool tip: ball centre minus one radius along the axis.
            for (k, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                let tip_mm = cl[3 * i + k] - 2.0 * axes[3 * i + k];
                if let Some(v) = word(block, letter) {
                    assert!(
                        (v * scale - tip_mm).abs() < 2e-3,
                        "{dialect} move {i} line {line} `{block}`: {letter} {v} vs tip {tip_mm} mm"
                    );
                    matched += 1;
                }
            }
        }
        assert!(matched > 2 * n, "{dialect}: coordinates checked {matched}");
        // The program the lines were read from is kept: asked for again, the same bytes.
        assert_eq!(plan.gcode_for(machine, dialect, units).unwrap(), text);
    }
    // Kept for its machine, dialect and units only.
    let kept = plan
        .gcode_for("table-table-ac", "heidenhain", "inch")
        .unwrap();
    let other = plan
        .gcode_for("table-table-ac", "heidenhain", "mm")
        .unwrap();
    assert_ne!(kept, other);
    assert!(
        other.contains("MM") && !other.contains("INCH"),
        "the mm program"
    );
    let msg = js_message(plan.gcode_lines("3-axis", "klingon", "mm").err().unwrap());
    assert!(msg.contains("klingon"), "{msg}");
}

#[wasm_bindgen_test]
fn control_edges_follow_euler_characteristic() {
    // V − E + F = 1 for a surface with one boundary (dome, keycaps), 2 for a closed one
    // (head); the edge count comes from the half-edges, V and F from the summary.
    for (name, chi) in [("dome", 1.0), ("keycap-convex", 1.0), ("head", 2.0)] {
        let model = Model::sample(name).unwrap();
        let summary = model.summary().unwrap();
        let v = get(&summary, "vertices").as_f64().unwrap();
        let f = get(&summary, "faces").as_f64().unwrap();
        let edges = model.control_edges().to_vec();
        assert_eq!(edges.len() % 6, 0);
        let e = (edges.len() / 6) as f64;
        assert_eq!(v - e + f, chi, "{name}: V {v} E {e} F {f}");
        assert!(edges.iter().all(|x| x.is_finite()));
    }
}

#[wasm_bindgen_test]
fn stl_bytes_hold_the_shown_triangles() {
    let model = Model::sample("keycap-convex").unwrap();
    let mesh = model.tessellate(0.02).unwrap();
    let bytes = mesh.stl("keycap-convex").to_vec();
    let positions = mesh.positions().to_vec();
    let indices = mesh.indices().to_vec();
    let nt = indices.len() / 3;
    assert_eq!(bytes.len(), 84 + 50 * nt);
    assert!(
        bytes.starts_with(b"tspath ") && bytes[..80].windows(13).any(|w| w == b"keycap-convex")
    );
    assert_eq!(
        u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize,
        nt
    );
    let f = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    for t in [0, nt / 2, nt - 1] {
        let rec = 84 + 50 * t;
        for corner in 0..3 {
            let vtx = indices[3 * t + corner] as usize;
            for k in 0..3 {
                assert_eq!(f(rec + 12 + 12 * corner + 4 * k), positions[3 * vtx + k]);
            }
        }
        // The facet normal is a unit vector.
        let n = (0..3).map(|k| f(rec + 4 * k) as f64).collect::<Vec<_>>();
        assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-5);
    }
}

#[wasm_bindgen_test]
fn a_plan_stands_without_its_default_program() {
    // Planning writes no program: each is written when asked for, for the machine asked
    // for, so a program that cannot be written fails that request, not the plan.
    let model = Model::sample("keycap-convex").unwrap();
    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"tool_radius_mm".into(), &0.5.into()).unwrap();
    js_sys::Reflect::set(&options, &"scallop_mm".into(), &0.05.into()).unwrap();
    js_sys::Reflect::set(&options, &"tilt_deg".into(), &10.0.into()).unwrap();
    let plan = model.plan(options.into(), None).unwrap();
    let axes = plan.axes().to_vec();
    assert!(
        axes.chunks(3).any(|a| a[2] < 0.99),
        "a 10° tilt tilts the axis"
    );
    // Three-axis output refuses a tilted path, naming the move; the plan stays usable.
    let msg = js_message(plan.gcode_for("3-axis", "linuxcnc", "mm").err().unwrap());
    assert!(msg.contains("move ") && msg.contains("+Z"), "{msg}");
    let five = plan.gcode().unwrap();
    assert!(
        five.contains("table-table-ac") && five.contains("G93"),
        "default five-axis program"
    );
    assert!(plan
        .gcode_for("table-table-ac", "siemens", "mm")
        .unwrap()
        .contains("TRAORI"));
}

/// Area of the triangles `x y z` × 3 per triangle (mm²), per reason code.
fn triangle_areas(positions: &[f32], reasons: &[u8]) -> [f64; 4] {
    let mut by = [0.0; 4];
    for (t, &why) in reasons.iter().enumerate() {
        let p = |k: usize| -> [f64; 3] {
            let i = 9 * t + 3 * k;
            [
                positions[i] as f64,
                positions[i + 1] as f64,
                positions[i + 2] as f64,
            ]
        };
        let (a, b, c) = (p(0), p(1), p(2));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        by[why as usize] += (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0;
    }
    by
}

#[wasm_bindgen_test]
fn rest_area_reaches_javascript_as_the_report_says() {
    // What the page draws and lists: a 1.5 mm ball is too big for the concave keycap's
    // floor fillets (its smallest concave radius is about 0.79 mm).
    let model = Model::sample("keycap-concave").unwrap();
    let summary = model.summary().unwrap();
    let concave = get(&summary, "smallest_concave_radius");
    let radius = get(&concave, "radius_mm").as_f64().unwrap();
    assert!(
        radius > 0.5 && radius < 1.5,
        "smallest concave radius {radius} mm"
    );
    assert_eq!(js_sys::Array::from(&get(&concave, "at_mm")).length(), 3);
    // Nothing concave: null (as in the CLI's JSON), not a number.
    let head = Model::sample("head").unwrap().summary().unwrap();
    assert!(get(&head, "smallest_concave_radius").is_null());

    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"tool_radius_mm".into(), &1.5.into()).unwrap();
    js_sys::Reflect::set(&options, &"scallop_mm".into(), &0.05.into()).unwrap();
    let plan = model.plan(options.into(), None).unwrap();
    let report = plan.report().unwrap();
    assert_eq!(
        get(&report, "status").as_string().as_deref(),
        Some("planned_with_problems")
    );
    let moves = plan.move_kinds().length() as f64;
    let problems = js_sys::Array::from(&get(&report, "problems"));
    assert!(problems.length() > 0);
    let mut tight = false;
    for p in problems.iter() {
        let kind = get(&p, "kind").as_string().unwrap();
        tight |= kind == "rest_too_tight";
        assert!(
            get(&p, "message").as_string().unwrap().contains("mm²") || !kind.starts_with("rest_")
        );
        let near = get(&p, "near_move");
        assert!(
            near.is_null() || near.as_f64().unwrap() < moves,
            "{kind}: near move {near:?} of {moves}"
        );
    }
    assert!(tight, "the fillets are tighter than the ball");

    // The triangles cover the rest regions: footprints are drawn whole while only the share
    // of each the final path leaves above the scallop counts (of a point left out, most of
    // it; of one left too tight, a sliver).
    let positions = plan.rest_positions().to_vec();
    let reasons = plan.rest_reasons().to_vec();
    assert_eq!(positions.len(), 9 * reasons.len());
    assert!(reasons.iter().all(|&w| w < 4));
    let drawn = triangle_areas(&positions, &reasons);
    let names = ["faces_away", "tool_hits", "too_tight", "no_way_out"];
    let mut listed = [0.0; 4];
    for g in js_sys::Array::from(&get(&report, "rest")).iter() {
        let why = get(&g, "why").as_string().unwrap();
        let k = names
            .iter()
            .position(|n| *n == why)
            .expect("a known reason");
        listed[k] += get(&g, "area_mm2").as_f64().unwrap();
    }
    let total = get(&report, "unreachable_area_mm2").as_f64().unwrap();
    assert!((listed.iter().sum::<f64>() - total).abs() < 1e-9 * total.max(1.0));
    for k in 0..4 {
        let within = drawn[k] >= 0.95 * listed[k] - 1e-6
            && (names[k] == "too_tight" || listed[k] >= 0.5 * drawn[k]);
        assert!(
            within,
            "{}: triangles {} mm², regions {} mm²",
            names[k], drawn[k], listed[k]
        );
    }
    assert!(listed[2] > 1.0, "too tight: {} mm²", listed[2]);
}

#[wasm_bindgen_test]
fn the_simulation_cap_is_the_clis() {
    // The page's default for `max_samples` is read from here; `plan --verify` uses the same.
    assert_eq!(
        tspath::wasm::plan_verify_max_samples(),
        tspath::verify::PLAN_VERIFY_MAX_SAMPLES as f64
    );
    assert_eq!(tspath::wasm::plan_verify_max_samples(), 8_000_000.0);
}

/// Plan options as a JavaScript object.
fn js_options(fields: &[(&str, JsValue)]) -> JsValue {
    let o = js_sys::Object::new();
    for (k, v) in fields {
        js_sys::Reflect::set(&o, &JsValue::from_str(k), v).unwrap();
    }
    o.into()
}

#[wasm_bindgen_test]
fn isfc_plans_one_pass_and_hands_over_its_cells_and_tree() {
    // plate-hole: ten patches round a hole; the space-filling curve cuts it in one loop.
    let model = Model::sample("plate-hole").unwrap();
    let options = |plain: bool| {
        js_options(&[
            ("tool_radius_mm", 1.0.into()),
            ("scallop_mm", 0.05.into()),
            ("max_tilt_deg", 0.0.into()),
            ("strategy", "isfc".into()),
            ("isfc_plain", plain.into()),
        ])
    };
    let plan = model.plan(options(false), None).unwrap();
    let report = plan.report().unwrap();
    let num = |k: &str| get(&report, k).as_f64().unwrap_or(f64::NAN);
    assert_eq!(
        get(&report, "strategy").as_string().as_deref(),
        Some("isfc")
    );
    assert_eq!(num("retractions"), 0.0, "one pass, no retraction");
    let cells = num("cells");
    assert!(cells > 100.0, "{cells} cells");
    assert_eq!(num("tree_links"), cells - 1.0, "a tree over every cell");
    let grid = get(&report, "grid");
    let vertices = get(&grid, "vertices").as_f64().unwrap();
    assert_eq!(vertices, 4.0 * cells, "every grid vertex is in a cell");
    assert!(get(&grid, "s_lines").as_f64().unwrap() >= 20.0);
    assert!(get(&grid, "t_lines").as_f64().unwrap() >= 20.0);
    assert!(num("compensated_corners") > 0.0);

    // The layer: four segments per cell, one per tree link, in typed arrays.
    let outline = plan.isfc_cells().unwrap().to_vec();
    let tree = plan.isfc_tree().unwrap().to_vec();
    let across = plan.isfc_tree_across().unwrap().to_vec();
    assert_eq!(outline.len() as f64, 24.0 * cells);
    assert_eq!(tree.len() as f64, 6.0 * (cells - 1.0));
    assert_eq!(across.len() as f64, cells - 1.0);
    let crossing = across.iter().filter(|&&a| a == 1).count();
    assert!(
        crossing >= 9 && across.iter().all(|&a| a <= 1),
        "ten patches in one loop need at least nine links across sides ({crossing})"
    );
    // Each tree link ends at the centres of two cells (the mean of their corners).
    let centres: Vec<[f64; 3]> = outline
        .chunks(24)
        .map(|c| {
            let mut m = [0.0; 3];
            for k in 0..4 {
                for d in 0..3 {
                    m[d] += f64::from(c[6 * k + d]) / 4.0;
                }
            }
            m
        })
        .collect();
    for (k, s) in tree.chunks(6).enumerate() {
        for end in [&s[..3], &s[3..]] {
            let at = centres.iter().any(|c| {
                (0..3).all(|d| (c[d] - f64::from(end[d])).abs() < 1e-4 * c[d].abs().max(1.0))
            });
            assert!(at, "tree link {k} ends at {end:?}, no cell's centre");
        }
    }
    // The start is in mm, as the report's note says it.
    let start = plan.isfc_start().unwrap().to_vec();
    assert_eq!(start.len(), 3);
    let said = format!(
        "starting at ({:.3}, {:.3}, {:.3}) mm",
        start[0], start[1], start[2]
    );
    let notes = js_sys::Array::from(&get(&report, "notes"));
    assert!(
        notes.iter().any(|n| n.as_string().unwrap().contains(&said)),
        "a note says {said}"
    );

    // The paper's plain curve: no parity repair, no corner detours.
    let plain = model.plan(options(true), None).unwrap().report().unwrap();
    assert_eq!(get(&plain, "repaired_cells").as_f64(), Some(0.0));
    assert_eq!(get(&plain, "compensated_corners").as_f64(), Some(0.0));

    // Zig-zags have no cells: the call says so instead of drawing nothing.
    let zig = model
        .plan(js_options(&[("scallop_mm", 0.05.into())]), None)
        .unwrap();
    assert!(get(&zig.report().unwrap(), "cells").is_undefined());
    let msg = js_message(zig.isfc_cells().expect_err("isoparametric has no cells"));
    assert!(
        msg.contains("isoparametric") && msg.contains("isfc"),
        "{msg}"
    );
    // A strategy that does not exist is named in the error with the ones that do.
    let msg = js_message(
        model
            .plan(js_options(&[("strategy", "zigzag".into())]), None)
            .err()
            .expect("no such strategy"),
    );
    assert!(msg.contains("zigzag") && msg.contains("isfc"), "{msg}");
    assert_eq!(tspath::wasm::paper_lead_deg(), 10.0);
}

/// The allocator grows the memory in steps (`src/wasm/grow.rs`): small allocations that
/// outgrow the memory make it grow by at least 1 MiB (16 pages) at once, where the standard
/// allocator alone grows it by the one page they lack.
#[wasm_bindgen_test]
fn memory_grows_in_steps() {
    use std::arch::wasm32::memory_size;
    let mut kept: Vec<Vec<u8>> = Vec::new();
    let mut steps = Vec::new();
    // Three growths in a row, each seen right after the allocation that caused it.
    while steps.len() < 3 {
        let before = memory_size::<0>();
        kept.push(vec![1; 1000]);
        let after = memory_size::<0>();
        if after != before {
            steps.push(after - before);
        }
    }
    assert!(
        steps.iter().all(|&pages| pages >= 16),
        "pages grown at once: {steps:?}"
    );
}

/// The quick summary is the summary without its smallest concave radius, which comes on
/// its own: the same values as the whole summary's, for a concave and a convex model.
#[wasm_bindgen_test]
fn quick_summary_and_concave_radius_make_the_summary() {
    let json = |v: &JsValue| String::from(js_sys::JSON::stringify(v).unwrap());
    for name in ["keycap-concave", "head"] {
        let model = Model::sample(name).unwrap();
        let quick = model.quick_summary().unwrap();
        let key = JsValue::from_str("smallest_concave_radius");
        assert!(
            !js_sys::Reflect::has(&quick, &key).unwrap(),
            "{name}: not looked for"
        );
        let concave = model.smallest_concave_radius().unwrap();
        let whole = model.summary().unwrap();
        assert_eq!(
            json(&concave),
            json(&get(&whole, "smallest_concave_radius"))
        );
        js_sys::Reflect::set(&quick, &key, &concave).unwrap();
        assert_eq!(json(&quick), json(&whole), "{name}");
    }
}
