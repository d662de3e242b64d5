//! `tspath plan --machine/--dialect/--units` and `tspath machine`, run in-process.

use tspath::cli::run;

fn args(s: &[&str]) -> Vec<String> {
    s.iter().map(|x| x.to_string()).collect()
}

#[test]
fn plan_writes_the_chosen_machine_dialect_and_units() {
    let dir = std::env::temp_dir().join(format!("tspath-machine-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let list = run(&args(&["machine", "--list"])).unwrap();
    for name in [
        "3-axis",
        "table-table-ac",
        "table-table-bc",
        "linuxcnc",
        "fanuc",
        "heidenhain",
        "siemens",
    ] {
        assert!(list.contains(name), "--list names {name}");
    }
    // A built-in machine written as JSON, then used from the file: same program as by name.
    run(&args(&["machine", "table-table-bc", "-o", &p("bc.json")])).unwrap();
    let plan = |machine: &str, dialect: &str, units: &str, out: &str| {
        run(&args(&[
            "plan",
            "dome",
            "--tool-radius",
            "3",
            "--scallop",
            "0.05",
            "--machine",
            machine,
            "--dialect",
            dialect,
            "--units",
            units,
            "-o",
            &p(out),
            "--report",
            &p("report.json"),
        ]))
        .unwrap();
        std::fs::read_to_string(p(out)).unwrap()
    };
    let by_name = plan("table-table-bc", "siemens", "inch", "a.mpf");
    let by_file = plan(&p("bc.json"), "siemens", "inch", "b.mpf");
    assert_eq!(by_name, by_file);
    assert!(by_name.contains("G700") && by_name.contains("TRAORI") && by_name.contains("TRAFOOF"));
    let h = plan("table-table-ac", "heidenhain", "mm", "c.h");
    assert!(h.starts_with("0 BEGIN PGM DOME MM\n") && h.contains("FUNCTION TCPM"));
    assert!(h.trim_end().ends_with("END PGM DOME MM"));
    // Defaults: 3-axis, linuxcnc, mm.
    run(&args(&[
        "plan",
        "dome",
        "--tool-radius",
        "3",
        "--scallop",
        "0.05",
        "-o",
        &p("d.ngc"),
    ]))
    .unwrap();
    let d = std::fs::read_to_string(p("d.ngc")).unwrap();
    assert!(d.contains("G21 G90") && d.contains("machine: 3-axis, dialect: linuxcnc"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn machine_and_dialect_errors_are_actionable() {
    let e = run(&args(&["plan", "dome", "--dialect", "mazak"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("mazak") && e.contains("linuxcnc") && e.contains("heidenhain"),
        "{e}"
    );
    let e = run(&args(&["plan", "dome", "--machine", "no-such-machine"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no-such-machine") && e.contains("table-table-ac"),
        "{e}"
    );
    let e = run(&args(&["plan", "dome", "--units", "furlong"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("furlong") && e.contains("inch"), "{e}");
    let dir = std::env::temp_dir().join(format!("tspath-machine-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("m.json");
    std::fs::write(&f, r#"{"format": "tspath-machine", "version": 1, "name": "x", "rotaries": [{"name": "A", "mount": "table", "axis": [1, 0, 0], "direction": 3}, {"name": "C", "mount": "table", "axis": [0, 0, 1]}]}"#).unwrap();
    let e = run(&args(&["plan", "dome", "--machine", f.to_str().unwrap()]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.json") && e.contains("rotaries[0].direction"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rapids_turn_the_rotaries_only_at_the_top_of_z() {
    // gearbox2-9.tsm with a fat short shank needs tilted axes and retractions between cuts
    // whose axes differ (the rest area it leaves out). A rapid that turned the rotaries
    // while traversing would swing the table (and the part) under the tool: they turn at the
    // top of Z first. (face.tsm served until its layout stopped forcing retractions, issue
    // 20.)
    let dir = std::env::temp_dir().join(format!("tspath-rapids-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("gearbox.nc").to_str().unwrap().to_string();
    // In joint output and in tool-tip output alike (a control need not keep the tip on the
    // line while a rapid turns the rotaries); the joint program is read back below.
    for dialect in ["linuxcnc-tcp", "linuxcnc"] {
        run(&args(&[
            "plan",
            "www/models/grapetec/gearbox2-9.tsm",
            "--tool-radius",
            "1",
            "--scallop",
            "0.3",
            "--max-tilt",
            "90",
            "--shank",
            "2",
            "--shank-length",
            "6",
            "--holder",
            "10",
            "--holder-length",
            "30",
            "--machine",
            "table-table-ac",
            "--dialect",
            dialect,
            "-o",
            &out,
        ]))
        .unwrap();
        let program = std::fs::read_to_string(&out).unwrap();
        let word = |line: &str, c: char| {
            line.split_whitespace()
                .find(|w| w.starts_with(c))
                .map(|w| w[1..].to_string())
        };
        // Joint output turns at the top of Z (after G53); tool-tip output, whose
        // tool-centre-point mode stays on, at the program's highest Z (the safe plane).
        let joints = dialect == "linuxcnc";
        // The highest Z in the program's frame (not G53) but the post's own final retract
        // along the tool axis (its last motion block).
        let motion = |l: &&str| {
            !l.starts_with("G53") && l.split_whitespace().any(|w| w == "G0" || w == "G1")
        };
        let lines: Vec<&str> = program.lines().filter(motion).collect();
        let top = lines[..lines.len() - 1]
            .iter()
            .filter_map(|l| word(l, 'Z').map(|z| z.parse::<f64>().unwrap()))
            .fold(f64::MIN, f64::max);
        let (mut rot, mut at_top, mut turned_at_top) = ((None, None), false, 0);
        let mut z: Option<f64> = None;
        // After a turn: the level move to above the target, then the way down onto it.
        let (mut after_turn, mut level_xy) = (0, (None, None));
        for line in program.lines() {
            if line.starts_with("G53") {
                at_top = true;
                continue;
            }
            let has = |g: &str| line.split_whitespace().any(|w| w == g);
            let rapid = has("G0");
            if !(rapid || has("G1")) {
                continue;
            }
            let (a, c) = (word(line, 'A'), word(line, 'C'));
            let (x, y) = (word(line, 'X'), word(line, 'Y'));
            let new_z = word(line, 'Z').map(|v| v.parse::<f64>().unwrap());
            let moves_xyz = x.is_some() || y.is_some() || new_z.is_some();
            let turns = (a.is_some() || c.is_some())
                && rot != (a.clone(), c.clone())
                && rot != (None, None);
            if rapid && turns {
                let high = if joints {
                    at_top
                } else {
                    z.is_some_and(|z| (z - top).abs() < 1e-9)
                };
                assert!(
                    high && !moves_xyz,
                    "{dialect}: a rapid turns the rotaries away from the top: {line}"
                );
                turned_at_top += 1;
                after_turn = 1;
            } else if after_turn == 1 {
                assert!(
                    rapid && new_z.is_none_or(|v| Some(v) == z),
                    "{dialect}: after a turn the tool moves level: {line}"
                );
                (after_turn, level_xy) = (2, (x.clone(), y.clone()));
            } else if after_turn == 2 {
                assert!(
                    (x.clone(), y.clone()) == level_xy || (x.is_none() && y.is_none()),
                    "{dialect}: after a turn the tool comes straight down: {line} after {level_xy:?}"
                );
                after_turn = 0;
            }
            if moves_xyz {
                at_top = false;
            }
            if new_z.is_some() {
                z = new_z;
            }
            if a.is_some() || c.is_some() {
                rot = (a, c);
            }
        }
        println!(
            "gearbox2-9.tsm, table-table-ac, {dialect}: the rotaries turn {turned_at_top} times at the top of Z"
        );
        assert!(
            turned_at_top >= 2,
            "the retractions between cuts turn the rotaries"
        );
        // The program reads back and simulates (ball moves, the rises and turns between
        // cuts included) without a gouge.
        let report = run(&args(&[
            "verify",
            "www/models/grapetec/gearbox2-9.tsm",
            &out,
            "--tool-radius",
            "1",
            "--machine",
            "table-table-ac",
            "--dialect",
            dialect,
            "--samples",
            "20000",
        ]))
        .unwrap();
        assert!(
            report.contains("\"gouge_count\": 0,"),
            "{dialect}: {report}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
