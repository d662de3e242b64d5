//! `tspath compare` (issue 17): every strategy on `keycap-convex` (r 0.5, h 0.005 mm) and
//! `bumps-hole` (r 1, h 0.01 mm), each row verified by the cutting simulation or showing
//! why it could not plan; `L_min` against closed forms on a plane and cylinders; the CSV
//! and JSON the command writes.

use tspath::model::samples;
use tspath::plan::compare::{self, Entry, ENTRIES};
use tspath::plan::{self, PlanOptions, PlanStatus};
use tspath::Model;

fn args(s: &[&str]) -> Vec<String> {
    s.iter().map(|x| x.to_string()).collect()
}

/// Splits a CSV line (RFC 4180 quoting) into its fields.
fn csv_fields(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                out.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(String::new()),
            (c, _) => out.last_mut().unwrap().push(c),
        }
    }
    out
}

#[test]
fn every_strategy_is_verified_or_says_why_not() {
    let dir = std::env::temp_dir().join(format!("tspath-compare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (model, r, h) in [("keycap-convex", 0.5, 0.005), ("bumps-hole", 1.0, 0.01)] {
        let json = dir.join(format!("{model}.json"));
        let csv = dir.join(format!("{model}.csv"));
        let table = tspath::cli::run(&args(&[
            "compare",
            model,
            "--tool-radius",
            &r.to_string(),
            "--scallop",
            &h.to_string(),
            "--report",
            json.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
        ]))
        .unwrap();
        println!("{table}");
        let c: compare::Comparison =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let names: Vec<&str> = c.runs.iter().map(|x| x.strategy.as_str()).collect();
        assert_eq!(names, ENTRIES.map(|e| e.name));
        assert!(c.l_min_mm > 0.0 && c.l_min_flat_mm > 0.0);
        let m = samples::load_sample(model).unwrap();
        let mut planned_rows = 0;
        for (run, entry) in c.runs.iter().zip(ENTRIES) {
            if let Some(e) = &run.error {
                // Its reason, in the table too.
                assert!(!e.is_empty());
                assert!(table.contains(&format!("could not plan: {e}")));
                continue;
            }
            planned_rows += 1;
            let s = run.simulated.as_ref().unwrap();
            println!(
                "{model} {}: max {:.5} ± {:.5} mm, gouges {}",
                run.strategy, s.max_scallop_mm, s.error_bound_mm, s.gouges
            );
            assert!(s.error_bound_mm <= 0.25 * h + 1e-12, "{}", run.strategy);
            if entry.baseline {
                // The constant-spacing baseline leaves steep walls over the scallop, by
                // design (the paper's point): the row says so as a problem.
                if s.max_scallop_mm > h + s.error_bound_mm {
                    assert!(
                        run.status == PlanStatus::PlannedWithProblems
                            && run.problems.iter().any(|p| p == "scallop"),
                        "{model}: {:?}",
                        run.problems
                    );
                    assert!(table.contains("planned with problems: scallop"));
                }
            } else {
                assert!(
                    s.max_scallop_mm <= h + s.error_bound_mm,
                    "{model} {}: {}",
                    run.strategy,
                    s.max_scallop_mm
                );
            }
            assert_eq!(s.gouges, 0, "{model} {}", run.strategy);
            assert!((run.efficiency - run.cutting_length_mm / c.l_min_mm).abs() < 1e-12);
            assert!((run.efficiency_flat - run.cutting_length_mm / c.l_min_flat_mm).abs() < 1e-12);
            // No path keeps the scallop with less than L_min.
            assert!(run.efficiency > 1.0, "{} {}", run.strategy, run.efficiency);
            // The row is the plan's own (the same plan again; the 3-axis machine's time).
            let o = entry.options(&PlanOptions::default().with_tool_radius(r).with_scallop(h));
            let p = plan::plan(&m, &o, &mut |_| true).unwrap();
            let rep = p.report(&o);
            assert_eq!(run.cl_points, rep.cl_points);
            assert_eq!(run.reversals, rep.reversals);
            assert_eq!(run.cutting_length_mm, rep.cutting_length_mm);
            assert_eq!(run.machining_time_min, rep.machining_time_min);
            assert_eq!(run.time_machine, "3-axis");
        }
        // Both models are planned by most strategies; the closed keycap is refused by the
        // rectangle strategies, which need a flat chart.
        let expect_planned = if model == "keycap-convex" { 4 } else { 6 };
        assert_eq!(planned_rows, expect_planned, "{model}");
        // The CSV: a header and a row per strategy, every row as wide as the header.
        let text = std::fs::read_to_string(&csv).unwrap();
        let lines: Vec<&str> = text.split("\r\n").filter(|l| !l.is_empty()).collect();
        assert_eq!(lines.len(), 1 + ENTRIES.len());
        let head = csv_fields(lines[0]);
        assert_eq!(head[0], "strategy");
        for (line, run) in lines[1..].iter().zip(&c.runs) {
            let f = csv_fields(line);
            assert_eq!(f.len(), head.len(), "{line}");
            assert_eq!(f[0], run.strategy);
            if run.error.is_none() {
                let k = head.iter().position(|x| x == "CL points").unwrap();
                assert_eq!(f[k], run.cl_points.to_string());
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `L_min = ∫ dA / g`: a plane and a convex cylinder (the straight direction has no
/// curvature) give the flat bound; a concave trough of radius R the flat bound times
/// `sqrt(1 − r / R)`; the area is the closed form `R · angle · length` (to the midpoint
/// rule's error).
#[test]
fn l_min_matches_its_closed_forms() {
    let (r, h, rr, len): (f64, f64, f64, f64) = (1.0, 0.01, 10.0, 20.0);
    let angle = 90f64.to_radians();
    let flat = |area: f64| area / (8.0 * r * h).sqrt();
    let plane = Model::try_new("plane", "test", "mm", samples::plane_patch(20.0).unwrap()).unwrap();
    let a = compare::area_mm2(&plane);
    let l = compare::l_min_mm(&plane, r, h);
    println!("plane: area {a} mm², L_min {l} mm, flat {}", flat(a));
    assert!((l - flat(a)).abs() < 1e-9 * l);
    for (inside, factor) in [(false, 1.0), (true, (1.0 - r / rr).sqrt())] {
        let m = Model::try_new(
            "cylinder",
            "test",
            "mm",
            samples::cylinder_patch(rr, len, 90.0, inside).unwrap(),
        )
        .unwrap();
        let a = compare::area_mm2(&m);
        let l = compare::l_min_mm(&m, r, h);
        let want = factor * flat(rr * angle * len);
        println!("cylinder inside={inside}: area {a:.6} mm² (closed form {:.6}), L_min {l:.4} mm, closed form {want:.4} mm", rr * angle * len);
        // The midpoint rule on 64 × 64 cells of a rational patch: 1e-5 of the area.
        assert!((a - rr * angle * len).abs() < 5e-5 * a);
        assert!((l - want).abs() < 5e-5 * want, "{l} vs {want}");
    }
}

#[test]
fn a_strategy_list_is_read_and_a_wrong_name_is_named() {
    let e = Entry::parse_list(Some("isfc, isoplanar-baseline,isfc")).unwrap();
    assert_eq!(
        e.iter().map(|x| x.name).collect::<Vec<_>>(),
        ["isfc", "isoplanar-baseline"]
    );
    assert!(!e[1].options(&PlanOptions::default()).isoplanar_deform);
    let err = tspath::cli::run(&args(&["compare", "dome", "--strategies", "isfc,spiral"]))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`spiral`") && err.contains("isoplanar-baseline"),
        "{err}"
    );
    let err = tspath::cli::run(&args(&["compare", "dome", "--strategy", "isfc"]))
        .unwrap_err()
        .to_string();
    assert!(err.contains("--strategies"), "{err}");
}

/// Progress goes one way, ends at 1, and moves while each cut is simulated (not only when
/// each strategy ends).
#[test]
fn progress_is_monotone_and_covers_the_simulations() {
    let m = samples::load_sample("dome").unwrap();
    let o = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.05);
    let entries = Entry::parse_list(Some("isoparametric,isfc")).unwrap();
    let mut seen: Vec<f64> = Vec::new();
    let (c, kept) = compare::compare(&m, &o, &entries, None, Some(1_000_000), &|| 0.0, &mut |f| {
        seen.push(f);
        true
    })
    .unwrap();
    assert!(kept.iter().all(|k| k.is_some()));
    assert_eq!(c.runs.len(), 2);
    assert!(seen.windows(2).all(|w| w[1] >= w[0]), "{seen:?}");
    assert_eq!(*seen.last().unwrap(), 1.0);
    // Inside each entry's simulation part (after its 60 % of planning).
    for k in 0..2 {
        let (lo, hi) = ((k as f64 + 0.6) / 2.0, (k as f64 + 1.0) / 2.0);
        assert!(
            seen.iter().any(|&f| f > lo && f < hi),
            "entry {k}: nothing between {lo} and {hi}: {seen:?}"
        );
    }
    // Cancelling stops the comparison with the error that says so.
    let e = compare::compare(&m, &o, &entries, None, None, &|| 0.0, &mut |f| f < 0.3).unwrap_err();
    assert!(matches!(e, tspath::Error::Cancelled), "{e}");
}
