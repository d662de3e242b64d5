//! The tool axis never tilts past `max_tilt_deg` (issue 19: a torus cage planned with
//! `--max-tilt 120` once got a 133° tilt, which the post then refused at move 10 086 on a
//! trunnion with A ±120°, or wrote as `A133.0480` on a machine with A ±180°). Every move of
//! closed parts planned five-axis is checked, and the program posted on the trunnion.

use crate::support;

use support::{obj_model, torus_obj};
use tspath::machine::{self, Dialect, JobInfo, Units};
use tspath::model::samples;
use tspath::plan::{self, PlanOptions, Strategy};

#[test]
fn no_axis_tilts_past_the_limit_and_the_trunnion_takes_every_program() {
    let torus = obj_model(&torus_obj(20.0, 6.0, 12, 8), "torus.obj");
    let head = samples::load_sample("head").unwrap();
    let mach = machine::builtin("table-table-ac").unwrap();
    for (name, m, r, h) in [("torus", &torus, 1.0, 0.2), ("head", &head, 1.0, 0.3)] {
        for (strategy, paper) in [
            (Strategy::Isoparametric, false),
            (Strategy::Isoparametric, true),
            (Strategy::Isfc, true),
        ] {
            for max_tilt in [90.0, 120.0] {
                let mut o = PlanOptions::default()
                    .with_tool_radius(r)
                    .with_scallop(h)
                    .with_strategy(strategy);
                if paper {
                    // The space-filling-curve paper's 10° lead from the surface normal.
                    o = o.with_paper_axis();
                }
                o.max_tilt_deg = max_tilt;
                let planned = match plan::plan(m, &o, &mut |_| true) {
                    Ok(p) => p,
                    Err(e) => panic!("{name} {strategy:?} lead {}°: {e}", o.lead_deg),
                };
                // Every axis a unit vector (a lead taken in a degenerate feed frame once gave
                // one of length 0.994, which the post refused).
                let off_unit = planned
                    .toolpath
                    .moves
                    .iter()
                    .position(|mv| (mv.tool_axis.norm() - 1.0).abs() > 1e-9);
                assert_eq!(
                    off_unit, None,
                    "{name} {strategy:?}: an axis not of unit length"
                );
                let worst = planned
                    .toolpath
                    .moves
                    .iter()
                    .map(|mv| mv.tool_axis.z.clamp(-1.0, 1.0).acos().to_degrees())
                    .fold(0.0, f64::max);
                println!("{name} r {r} h {h} {strategy:?} (lead {}°) max tilt {max_tilt}°: largest tilt {worst:.4}°", o.lead_deg);
                assert!(
                    worst <= max_tilt + 1e-6,
                    "{name} {strategy:?}: a tilt of {worst}° past the limit {max_tilt}°"
                );
                let job = JobInfo::for_model(m, planned.strategy);
                let posted = machine::post(
                    &planned.toolpath,
                    &o,
                    &job,
                    &mach,
                    Dialect::LinuxCnc,
                    Units::Mm,
                );
                assert!(posted.is_ok(), "{name} {strategy:?}: {:?}", posted.err());
            }
        }
    }
}

/// The largest tilt a machine allows is the travel of its tilting axis, and the command
/// line refuses a larger `--max-tilt` naming it (the post would stop at the first such
/// move).
#[test]
fn the_largest_tilt_is_what_the_machine_reaches() {
    let reach = |name: &str| machine::builtin(name).unwrap().reachable_tilt_deg();
    assert_eq!(reach("3-axis"), 0.0);
    assert_eq!(reach("table-table-ac"), 120.0);
    assert_eq!(reach("table-table-bc"), 110.0);
    assert_eq!(reach("head-table-bc"), 100.0);
    // A table C that does not turn the whole circle: only the smaller side of A reaches
    // every azimuth.
    let mut m = machine::builtin("table-table-ac").unwrap();
    m.rotaries[0].limits_deg = Some((-30.0, 110.0));
    assert_eq!(m.reachable_tilt_deg(), 110.0);
    m.rotaries[1].limits_deg = Some((-90.0, 90.0));
    assert_eq!(m.reachable_tilt_deg(), 30.0);
    let args = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let e = tspath::cli::run(&args(&[
        "plan",
        "dome",
        "--machine",
        "table-table-ac",
        "--max-tilt",
        "135",
    ]))
    .unwrap_err()
    .to_string();
    assert!(e.contains("120°") && e.contains("--max-tilt 120"), "{e}");
}
