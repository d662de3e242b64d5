//! The command-line front end, run in-process.

use tspath::cli::run;

fn args(s: &[&str]) -> Vec<String> {
    s.iter().map(|x| x.to_string()).collect()
}

#[test]
fn sample_list_and_info() {
    let list = run(&args(&["sample", "--list"])).unwrap();
    assert!(list.lines().any(|l| l == "dome"));
    let info: serde_json::Value =
        serde_json::from_str(&run(&args(&["info", "dome"])).unwrap()).unwrap();
    assert_eq!(info["patches"], 1);
    assert_eq!(info["control_points"], 16);
    assert_eq!(info["units_read"], "mm");
    let max_z = info["bbox_mm"]["max"][2].as_f64().unwrap();
    assert!((max_z - 20.0).abs() < 1e-9);
}

#[test]
fn sample_written_and_planned_from_file() {
    let dir = std::env::temp_dir().join(format!("tspath-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("dome.json");
    let nc = dir.join("dome.nc");
    let report = dir.join("report.json");
    run(&args(&["sample", "dome", "-o", model.to_str().unwrap()])).unwrap();
    run(&args(&[
        "plan",
        model.to_str().unwrap(),
        "--tool-radius",
        "2",
        "--scallop",
        "0.05",
        "-o",
        nc.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]))
    .unwrap();
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for key in [
        "length_mm",
        "cutting_length_mm",
        "link_length_mm",
        "retractions",
        "reversals",
        "cl_points",
        "max_predicted_scallop_mm",
        "plan_ms",
    ] {
        assert!(r.get(key).is_some(), "report has {key}");
    }
    assert!(r["max_predicted_scallop_mm"].as_f64().unwrap() <= 0.05 * (1.0 + 1e-9));
    let g = std::fs::read_to_string(&nc).unwrap();
    assert!(g.starts_with("%\n(tspath"));
    assert_eq!(
        g.lines()
            .filter(|l| l.starts_with("G0 ") || l.starts_with("G1 "))
            .count() as u64,
        r["cl_points"].as_u64().unwrap()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_are_actionable() {
    let e = run(&args(&["info", "no-such-model"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no-such-model") && e.contains("sample --list"),
        "{e}"
    );
    let e = run(&args(&["plan", "dome", "--scallop", "abc"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("--scallop") && e.contains("abc"), "{e}");
    let e = run(&args(&[
        "plan",
        "dome",
        "--scallop",
        "5",
        "--tool-radius",
        "1",
    ]))
    .unwrap_err()
    .to_string();
    assert!(e.contains("scallop_mm"), "{e}");
    // A 5 mm ball: its default flute (four radii, 20 mm) reaches the default shank's length;
    // the error says what the default was and which flag to change (found planning a car
    // body cage in metres).
    let e = run(&args(&["plan", "dome", "--tool-radius", "5"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("four ball radii, 20 mm") && e.contains("--shank-length"),
        "{e}"
    );
    assert!(run(&args(&[
        "plan",
        "dome",
        "--tool-radius",
        "5",
        "--scallop",
        "0.5",
        "--shank-length",
        "40",
        "-o",
        "/dev/null"
    ]))
    .is_ok());
}
