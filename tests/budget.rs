//! Bounded work (issue 19): the CL points a plan will have are estimated before planning, and
//! settings beyond the limit are refused at once with the estimate and what to change.

use tspath::model::samples;
use tspath::plan::{self, budget, PlanOptions, Strategy};

/// The estimate is of the right size: within a factor of 4 of the points the planners make,
/// on every sample, for the patch-ordered zig-zags and the space-filling curve's grid.
#[test]
fn the_estimate_is_within_a_factor_of_four_of_the_plan() {
    let mut worst: f64 = 1.0;
    for s in samples::SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        for (strategy, r, h) in [
            (Strategy::Isoparametric, 1.0, 0.02),
            (Strategy::Isoparametric, 0.5, 0.005),
            (Strategy::Isfc, 1.0, 0.02),
        ] {
            let mut o = PlanOptions::default()
                .with_tool_radius(r)
                .with_scallop(h)
                .with_strategy(strategy);
            o.max_tilt_deg = 0.0;
            let e = budget::estimate(&m, &o);
            let Ok(p) = plan::plan(&m, &o, &mut |_| true) else {
                continue; // a sample this strategy does not plan (a domain that does not lie flat)
            };
            let actual = p.report(&o).cl_points as f64;
            let ratio = e.cl_points / actual;
            println!(
                "{:14} {:?} r {r} h {h}: estimate {:.0}, planned {actual}, ratio {ratio:.2}",
                s.name, strategy, e.cl_points
            );
            worst = worst.max(ratio.max(1.0 / ratio));
            assert!(
                (0.25..=4.0).contains(&ratio),
                "{} {strategy:?}: estimate {} vs {actual}",
                s.name,
                e.cl_points
            );
        }
    }
    println!("largest factor between estimate and plan: {worst:.2}");
}

/// `plan dome --scallop 1e-9` is refused at once (no plan is started), the message naming
/// the estimate, the limit and the settings to change; a higher limit lets a small job
/// through that a low one refuses.
#[test]
fn settings_beyond_the_limit_are_refused_with_the_estimate() {
    let args = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let e = tspath::cli::run(&args(&["plan", "dome", "--scallop", "1e-9"]))
        .unwrap_err()
        .to_string();
    for want in [
        "CL points",
        "MB",
        "2 000 000",
        "max_cl_points",
        "scallop height",
    ] {
        assert!(e.contains(want), "{want}: {e}");
    }
    println!("{e}");
    let m = samples::load_sample("keycap-convex").unwrap();
    let o = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.02);
    let est = budget::estimate(&m, &o).cl_points;
    let mut low = o.clone();
    low.max_cl_points = (est / 2.0) as u64;
    let refused = plan::plan(&m, &low, &mut |_| true).unwrap_err().to_string();
    assert!(refused.contains("max_cl_points"), "{refused}");
    // The scallop the message proposes brings the estimate within the limit.
    let h: f64 = refused
        .split("raise the scallop height to about ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    let within = budget::estimate(&m, &low.clone().with_scallop(h)).cl_points;
    assert!(
        within <= low.max_cl_points as f64 * 1.05,
        "h {h}: {within} points"
    );
    let mut high = o;
    high.max_cl_points = (est * 2.0) as u64;
    assert!(plan::plan(&m, &high, &mut |_| true).is_ok());
    // On the command line: --max-cl-points.
    let e = tspath::cli::run(&args(&["plan", "keycap-convex", "--max-cl-points", "100"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("limit of 100 "), "{e}");
}
