//! `tspath verify` and `tspath plan --verify`, run in-process: the G-code `plan` writes is
//! read back and simulated, and agrees with simulating the planned path directly.

use tspath::cli::run;

fn args(s: &[&str]) -> Vec<String> {
    s.iter().map(|x| x.to_string()).collect()
}

const KEYS: &[&str] = &[
    "max_scallop_mm",
    "mean_scallop_mm",
    "p95_scallop_mm",
    "uncut_fraction",
    "max_gouge_mm",
    "gouge_count",
    "error_bound_mm",
    "samples",
];

/// A scratch directory of one test (`cargo test` runs the tests of a file side by side in one
/// process); each test removes its own when it passes.
fn scratch(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tspath-verify-cli-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn gcode_from_plan_verifies_like_the_planned_path() {
    let dir = scratch("plan");
    let nc = dir.join("dome.nc");
    let report = dir.join("report.json");
    run(&args(&[
        "plan",
        "dome",
        "--tool-radius",
        "1",
        "--scallop",
        "0.02",
        "-o",
        nc.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--verify",
        "--verify-samples",
        "200000",
    ]))
    .unwrap();
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let direct = &rep["verify"];
    for k in KEYS {
        assert!(direct[k].is_number(), "report.verify.{k} missing: {direct}");
    }
    assert_eq!(
        direct["gouge_tolerance_mm"], 0.002,
        "the plan's chordal tolerance (0.005 mm) or 0.002 mm, whichever is smaller"
    );
    // The plan's simulation raised its samples until its bound was within a quarter of the
    // scallop (issue 13).
    assert_eq!(direct["error_bound_target_mm"], 0.005);
    assert!(direct["error_bound_mm"].as_f64().unwrap() <= 0.005);
    assert_eq!(rep["status"], "planned", "{}", rep["problems"]);
    // Reached at the first round, which starts from the samples asked for or, if more,
    // from a spacing of a quarter of the flat-surface stepover sqrt(8 r h) = 0.4 mm over
    // the area (the grid rounds them a little).
    let area = direct["area_mm2"].as_f64().unwrap();
    let first = (area / (0.25f64 * 0.4).powi(2)).max(200000.0);
    let samples = direct["samples"].as_f64().unwrap();
    assert!(
        (samples - first).abs() < 0.005 * first,
        "{samples} vs {first}"
    );
    // The program read back, simulated the same way (same start, same bound).
    let verify_args = args(&[
        "verify",
        "dome",
        nc.to_str().unwrap(),
        "--tool-radius",
        "1",
        "--samples",
        "200000",
        "--bound",
        "0.005",
    ]);
    let out = run(&verify_args).unwrap();
    let again = run(&verify_args).unwrap();
    assert_eq!(out, again, "same input, same bytes");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for k in KEYS {
        assert!(v[k].is_number(), "{k} missing: {v}");
    }
    // Header tolerances are taken from the program.
    assert_eq!(v["requested_scallop_mm"], 0.02);
    assert_eq!(v["gouge_tolerance_mm"], 0.002);
    assert_eq!(v["samples"], direct["samples"]);
    // G-code coordinates have 4 decimals (±0.05 µm): the results agree to that order.
    let num = |x: &serde_json::Value, k: &str| x[k].as_f64().unwrap();
    for k in [
        "max_scallop_mm",
        "mean_scallop_mm",
        "p95_scallop_mm",
        "max_gouge_mm",
    ] {
        let (a, b) = (num(&v, k), num(direct, k));
        assert!((a - b).abs() < 1e-4, "{k}: G-code {a} vs path {b}");
    }
    assert!(num(&v, "max_scallop_mm") > 0.015 && num(&v, "max_scallop_mm") < 0.025);
    assert_eq!(v["unreached_samples"], 0);

    // --bound raises the sample count until the stated bound is reached.
    let out = run(&args(&[
        "verify",
        "dome",
        nc.to_str().unwrap(),
        "--tool-radius",
        "1",
        "--samples",
        "20000",
        "--bound",
        "0.0015",
    ]))
    .unwrap();
    let b: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(
        num(&b, "error_bound_mm") <= 0.0015,
        "{}",
        b["error_bound_mm"]
    );
    assert!(num(&b, "samples") > 20000.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cl_json_input_and_errors() {
    let dir = scratch("cl-json");
    let cl = dir.join("path.json");
    std::fs::write(
        &cl,
        r#"{"format": "tspath-cl", "tool_radius_mm": 0.5,
            "cl_points": [[-30, 0, 21], [30, 0, 21]]}"#,
    )
    .unwrap();
    // One straight pass over the apex region of the dome: most of it is never reached.
    let v: serde_json::Value = serde_json::from_str(
        &run(&args(&[
            "verify",
            "dome",
            cl.to_str().unwrap(),
            "--tool-radius",
            "0.5",
            "--samples",
            "20000",
        ]))
        .unwrap(),
    )
    .unwrap();
    assert!(v["unreached_fraction"].as_f64().unwrap() > 0.9);
    assert!(v["uncut_fraction"].as_f64().unwrap() >= v["unreached_fraction"].as_f64().unwrap());

    let err = |a: &[&str]| run(&args(a)).unwrap_err().to_string();
    let e = err(&["verify", "dome", cl.to_str().unwrap()]);
    assert!(e.contains("--tool-radius"), "{e}");
    let e = err(&["verify", "dome", cl.to_str().unwrap(), "--tool-radius", "1"]);
    assert!(e.contains("tool_radius_mm") && e.contains("0.5"), "{e}");
    let bad = dir.join("bad.nc");
    std::fs::write(
        &bad,
        "G21 G90\nG0 X0 Y0 Z30\nG1 X1 Y0 Z20 F100\nG2 X2 Y0 I1 J0\n",
    )
    .unwrap();
    let e = err(&[
        "verify",
        "dome",
        bad.to_str().unwrap(),
        "--tool-radius",
        "1",
    ]);
    assert!(e.contains("line 4") && e.contains("arcs"), "{e}");
    let e = err(&[
        "verify",
        "dome",
        cl.to_str().unwrap(),
        "--tool-radius",
        "0.5",
        "--samples",
        "3",
    ]);
    assert!(e.contains("samples"), "{e}");
    let e = err(&["verify", "dome", "/nonexistent.nc", "--tool-radius", "1"]);
    assert!(e.contains("cannot read"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
