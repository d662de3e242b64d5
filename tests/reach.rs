//! Real parts, safely (issue 13): a plan never puts the tool inside the part, plans what a
//! ball can reach and reports the rest. Programs are read back through the machine module's
//! reader and walked against dense surface samples (not the planner's own index); the cut is
//! measured by the cutting simulation with enough samples for its error bound to prove the
//! scallop (a quarter of it).

use crate::support;

use support::{
    dense_samples, extruded_obj, obj_model, public_tsm, tool_clearance, torus_obj, SampleGrid,
};
use tspath::geom::{Point3, Vector3};
use tspath::machine::{self, Dialect, JobInfo, Units};
use tspath::model::samples;
use tspath::plan::{isoparametric, reach, PlanOptions, PlanStatus, Planned};
use tspath::verify::{self, gcode::read_tool_poses};
use tspath::Model;

/// The program for `planned` on `machine` in `dialect`, read back: for every block with a
/// workpiece pose, the ball centre and the tool axis.
fn program_poses(
    planned: &Planned,
    opts: &PlanOptions,
    machine_name: &str,
    dialect: Dialect,
) -> Vec<(Point3, Vector3)> {
    let mach = machine::definition::builtin(machine_name).unwrap();
    let job = JobInfo {
        model: "test".into(),
        strategy: planned.strategy.into(),
        program_zero: "the model's origin".into(),
    };
    let text = machine::post(&planned.toolpath, opts, &job, &mach, dialect, Units::Mm).unwrap();
    let r = opts.tool_radius_mm;
    read_tool_poses(&text, &mach, dialect)
        .unwrap()
        .into_iter()
        .flatten()
        .map(|p| (p.tip + p.tool_axis * r, p.tool_axis))
        .collect()
}

/// Least clearances (mm; negative inside) of the ball and of the shank and holder from the
/// surface samples over every move of the program, the ball every `step` mm along each move
/// (tip and axis interpolated, as a controller with tool-centre-point control moves them),
/// the shank and holder at every block and every 1 mm on moves longer than that.
fn walk(
    poses: &[(Point3, Vector3)],
    grid: &SampleGrid,
    holder_grid: &SampleGrid,
    opts: &PlanOptions,
) -> (f64, f64) {
    let (r, reach, step): (f64, f64, f64) = (opts.tool_radius_mm, 2.0, 0.25);
    let (mut ball, mut tool) = (reach, reach);
    for w in poses.windows(2) {
        let ((c0, a0), (c1, a1)) = (w[0], w[1]);
        let len = (c1 - c0).norm();
        let n = (len / step).ceil().max(1.0) as usize;
        for k in 1..=n {
            let s = k as f64 / n as f64;
            let c = c0 + (c1 - c0) * s;
            ball = ball.min(grid.nearest(&c, r + reach) - r);
            if k == n || (k * 4) % n.max(4) == 0 && len > 1.0 {
                let axis = (a0 * (1.0 - s) + a1 * s).normalize();
                tool = tool.min(tool_clearance(holder_grid, opts, c, axis, reach));
            }
        }
    }
    (ball, tool)
}

/// Tolerance of the clearance walk (mm): the samples lie on a tessellation within 0.01 mm
/// of the surface and 0.3 mm apart (a 1 mm ball sinks 0.011 mm between them), and a cut may
/// go 0.002 mm in.
const WALK_TOL: f64 = 0.03;

#[test]
fn three_axis_head_and_torus_keep_ball_shank_and_holder_out_of_the_part() {
    // Issue 13, 1: the three-axis head once handed out 61 262 feed moves cutting its
    // underside with a vertical tool (and an OBJ torus 952 of 1 812 points), reported as a
    // success. Now those points are left out, the area is reported, and the program read
    // back keeps the whole tool out of the part.
    let head = samples::load_sample("head").unwrap();
    let torus = obj_model(&torus_obj(20.0, 6.0, 12, 8), "torus.obj");
    for (name, m, r, h) in [("head", &head, 1.0, 0.3), ("torus", &torus, 1.0, 0.1)] {
        let mut opts = PlanOptions::default().with_tool_radius(r).with_scallop(h);
        opts.max_tilt_deg = 0.0;
        let planned = isoparametric::plan(m, &opts, &mut |_| true).unwrap();
        let report = planned.report(&opts);
        assert_eq!(report.status, PlanStatus::PlannedWithProblems, "{name}");
        let away: f64 = report
            .rest
            .iter()
            .filter(|g| g.why == tspath::plan::reach::Why::FacesAway)
            .map(|g| g.area_mm2)
            .sum();
        assert!(away > 0.0, "{name}: the underside is reported");
        assert!(report
            .problems
            .iter()
            .any(|p| p.kind == "rest_faces_away" && p.near_move.is_some()));
        let samples = dense_samples(m);
        let grid = SampleGrid::new(&samples, 1.0);
        let holder_grid = SampleGrid::new(&samples, 4.0);
        let poses = program_poses(&planned, &opts, "3-axis", Dialect::LinuxCnc);
        let (ball, tool) = walk(&poses, &grid, &holder_grid, &opts);
        println!(
            "{name} three-axis (r {r} mm, h {h} mm): {} CL points, rest {:.0} mm² (faces away {away:.0}); program of {} blocks walked: least ball clearance {ball:.4} mm, shank/holder {tool:.4} mm",
            report.cl_points,
            report.unreachable_area_mm2,
            poses.len()
        );
        assert!(
            ball > -WALK_TOL,
            "{name}: the ball enters the part by {} mm",
            -ball
        );
        assert!(
            tool > -WALK_TOL,
            "{name}: the shank or holder enters the part by {} mm",
            -tool
        );
        // Every cut point kept faces up: a vertical ball reaches it from above.
        for mv in planned
            .toolpath
            .moves
            .iter()
            .filter(|mv| mv.kind.on_surface())
        {
            assert!(
                (mv.cl_point - mv.cc_point).z > 0.0,
                "{name}: a cut point facing down is cut"
            );
        }
    }
}

/// Plans `m`, verifies the program's cut until the error bound is a quarter of the scallop
/// (the rest area masked) and returns the plan's report with the simulation's findings.
fn plan_and_verify(
    m: &Model,
    opts: &PlanOptions,
) -> (Planned, tspath::plan::PlanReport, verify::Verification) {
    let planned = isoparametric::plan(m, opts, &mut |_| true).unwrap();
    let mut report = planned.report(opts);
    let v = verify::verify_plan(
        m,
        &planned,
        opts,
        Some(200_000),
        verify::PLAN_VERIFY_MAX_SAMPLES,
    )
    .unwrap();
    report.add_verification(&v);
    (planned, report, v)
}

#[test]
fn open_cages_with_sharp_boundaries_triangles_and_an_overhang_plan_without_gouges() {
    // Issue 13, 4: open sheets with sharp boundaries and corners, cages with triangles, and a
    // part whose retracts cannot rise straight: zero gouges beyond the tolerance.
    let wave: Vec<(f64, f64)> = (0..=8)
        .map(|i| (5.0 * i as f64, 4.0 * (0.9 * i as f64).sin()))
        .collect();
    // A C-shaped profile open towards +X: a long floor, a wall, and a roof over part of the
    // floor. Under the roof the floor is cut with a tilted tool that must leave sideways.
    let c_profile = [
        (40.0, 0.0),
        (30.0, 0.0),
        (20.0, 0.0),
        (10.0, 0.0),
        (0.0, 0.0),
        (0.0, 10.0),
        (0.0, 20.0),
        (8.0, 20.0),
        (16.0, 20.0),
    ];
    let cases = [
        ("wave", extruded_obj(&wave, 6, 5.0, false), 0.0),
        (
            "wave with triangles",
            extruded_obj(&wave, 6, 5.0, true),
            0.0,
        ),
        (
            "C with a roof",
            extruded_obj(&c_profile, 4, 6.0, false),
            120.0,
        ),
    ];
    for (name, obj, tilt) in cases {
        let m = obj_model(&obj, "cage.obj");
        let mut opts = PlanOptions::default()
            .with_tool_radius(1.0)
            .with_scallop(0.05);
        opts.max_tilt_deg = tilt;
        let (planned, report, v) = plan_and_verify(&m, &opts);
        println!(
            "{name}: {} CL points, status {:?} ({}), rest {:.1} mm²; simulated max scallop {:.4} mm (bound {:.4} mm, {} samples), {} gouges (deepest {:.4} mm); air moves escaping sideways {}",
            report.cl_points,
            report.status,
            report.problems.iter().map(|p| p.message.as_str()).collect::<Vec<_>>().join(" / "),
            report.unreachable_area_mm2,
            v.max_scallop_mm,
            v.error_bound_mm,
            v.samples,
            v.gouge_count,
            v.max_gouge_mm,
            planned.air.escaped
        );
        assert_eq!(
            v.gouge_count, 0,
            "{name}: {} gouges up to {} mm",
            v.gouge_count, v.max_gouge_mm
        );
        // Material above the scallop outside the rest area is said as loudly as an error.
        if v.max_scallop_mm > opts.scallop_mm {
            assert!(
                report.problems.iter().any(|p| p.kind == "scallop")
                    && report.status == PlanStatus::PlannedWithProblems,
                "{name}: scallop {} mm not reported",
                v.max_scallop_mm
            );
        }
        if tilt > 0.0 {
            // The roof's underside faces down (out of reach); the floor under it is cut by a
            // tilted tool whose retracts leave sideways, and the whole tool stays outside.
            assert!(
                planned.air.escaped > 0,
                "{name}: some retract leaves sideways"
            );
            let samples = dense_samples(&m);
            let grid = SampleGrid::new(&samples, 1.0);
            let holder_grid = SampleGrid::new(&samples, 4.0);
            let poses = program_poses(&planned, &opts, "table-table-ac", Dialect::LinuxCncTcp);
            let (ball, tool) = walk(&poses, &grid, &holder_grid, &opts);
            println!("{name}: program walked, least ball clearance {ball:.4} mm, shank/holder {tool:.4} mm");
            assert!(
                ball > -WALK_TOL && tool > -WALK_TOL,
                "{name}: {ball} / {tool}"
            );
        }
    }
}

// One test per file, so that the test runner spreads them over the cores.
#[test]
fn simple_tsm_plans_with_zero_gouges_and_keeps_its_scallop_where_reached() {
    plans_with_zero_gouges_and_keeps_its_scallop_where_reached("simple.tsm");
}
#[test]
fn mouse_tsm_plans_with_zero_gouges_and_keeps_its_scallop_where_reached() {
    plans_with_zero_gouges_and_keeps_its_scallop_where_reached("mouse.tsm");
}
#[test]
fn face_tsm_plans_with_zero_gouges_and_keeps_its_scallop_where_reached() {
    plans_with_zero_gouges_and_keeps_its_scallop_where_reached("face.tsm");
}
#[test]
fn fan_tsm_plans_with_zero_gouges_and_keeps_its_scallop_where_reached() {
    plans_with_zero_gouges_and_keeps_its_scallop_where_reached("fan.tsm");
}
#[test]
fn bike_tsm_plans_with_zero_gouges_and_keeps_its_scallop_where_reached() {
    plans_with_zero_gouges_and_keeps_its_scallop_where_reached("Bike.tsm");
}
#[test]
fn gearbox_tsm_plans_with_zero_gouges_and_keeps_its_scallop_where_reached() {
    plans_with_zero_gouges_and_keeps_its_scallop_where_reached("gearbox2-9.tsm");
}

fn plans_with_zero_gouges_and_keeps_its_scallop_where_reached(file: &str) {
    // Issue 13, 2–3: Bike.tsm and gearbox2-9.tsm aborted on a spot tighter than any ball;
    // mouse.tsm and face.tsm left more than the scallop. Every public file now plans
    // (three-axis, r 1 mm, h 0.05 mm; and five-axis, tilt up to 120°), cuts nothing it
    // should not, and what it leaves above the scallop is in its rest area.
    for tilt in [0.0, 120.0] {
        let m = public_tsm(file);
        let mut opts = PlanOptions::default()
            .with_tool_radius(1.0)
            .with_scallop(0.05);
        opts.max_tilt_deg = tilt;
        let (planned, report, v) = plan_and_verify(&m, &opts);
        let outside_rest = v.uncut_fraction - v.rest_fraction;
        println!(
            "{file} (tilt ≤ {tilt}°): {} CL points, status {:?}; rest {:.2} mm² ({:.2} %), simulated uncut {:.2} %; max scallop {:.4} mm (bound {:.4} mm at {} samples); gouges {} (deepest {:.4} mm); problems: {}",
            report.cl_points,
            report.status,
            report.unreachable_area_mm2,
            100.0 * v.rest_fraction,
            100.0 * v.uncut_fraction,
            v.max_scallop_mm,
            v.error_bound_mm,
            v.samples,
            v.gouge_count,
            v.max_gouge_mm,
            report.problems.iter().map(|p| p.kind.as_str()).collect::<Vec<_>>().join(", ")
        );
        assert_eq!(
            v.gouge_count, 0,
            "{file}: {} gouges up to {} mm",
            v.gouge_count, v.max_gouge_mm
        );
        assert!(
            v.error_bound_mm <= 0.25 * opts.scallop_mm,
            "{file}: unproven"
        );
        assert!(
            v.max_scallop_mm <= opts.scallop_mm * (1.0 + 1e-9),
            "{file}: {} mm left outside the rest area",
            v.max_scallop_mm
        );
        assert!(
            outside_rest < 1e-3,
            "{file}: {:.3} % of the area is uncut outside the rest area",
            100.0 * outside_rest
        );
        rest_matches_the_uncut_area(file, &m, &planned, &report, opts.scallop_mm, 4_000_000);
        assert!(!report
            .problems
            .iter()
            .any(|p| p.kind == "scallop" || p.kind == "gouge"));
    }
}

#[test]
fn face_tsm_at_the_page_defaults_keeps_its_scallop_and_proves_it() {
    at_the_page_defaults_keeps_its_scallop_and_proves_it("face.tsm");
}
#[test]
fn bike_tsm_at_the_page_defaults_keeps_its_scallop_and_proves_it() {
    at_the_page_defaults_keeps_its_scallop_and_proves_it("Bike.tsm");
}
#[test]
fn simple_tsm_at_the_page_defaults_keeps_its_scallop_and_proves_it() {
    at_the_page_defaults_keeps_its_scallop_and_proves_it("simple.tsm");
}
#[test]
fn mouse_tsm_at_the_page_defaults_keeps_its_scallop_and_proves_it() {
    at_the_page_defaults_keeps_its_scallop_and_proves_it("mouse.tsm");
}
#[test]
fn fan_tsm_at_the_page_defaults_keeps_its_scallop_and_proves_it() {
    at_the_page_defaults_keeps_its_scallop_and_proves_it("fan.tsm");
}
#[test]
fn gearbox_tsm_at_the_page_defaults_keeps_its_scallop_and_proves_it() {
    at_the_page_defaults_keeps_its_scallop_and_proves_it("gearbox2-9.tsm");
}

fn at_the_page_defaults_keeps_its_scallop_and_proves_it(file: &str) {
    // Issue 13, 3: at r 0.5, h 0.01 mm face.tsm left 1.034 h at (−12.881, 12.192, 0.916) mm,
    // between two balls lifted off the crease at a patch seam, outside the rest area: the
    // search for the material lifted balls leave, on a 5 × 5 grid per footprint, missed
    // that narrow peak; now everything above h is in the rest area.
    // Bike.tsm left 1.025 h at (3.554, −14.723, 10.204) mm
    // (a pass end on patch 52) and its simulation could not bound its gouges better than
    // 3.04 mm at 8 M samples: on a sliver face (0.024 mm across) the bound balanced the
    // metric's cross term the wrong way round, and measured gouges along the normal where
    // the straight depth is what is reported. With the patches of its one-patch-per-cell
    // layout connected along their sides the order changed, the first cut point after an
    // approach is lifted like every other, and the bound is below h / 4.
    let m = public_tsm(file);
    let opts = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.01);
    let (planned, report, v) = plan_and_verify(&m, &opts);
    println!(
        "{file} r 0.5 h 0.01: max scallop {:.5} mm at {:?} (bound {:.5} mm, gouge bound {:.5} mm, {} samples), rest {:.2} mm², gouges {} (deepest {:.5} mm)",
        v.max_scallop_mm, v.max_scallop_at_mm, v.error_bound_mm, v.gouge_error_bound_mm, v.samples, report.unreachable_area_mm2, v.gouge_count, v.max_gouge_mm
    );
    assert!(
        v.error_bound_mm <= 0.25 * opts.scallop_mm,
        "{file}: unproven"
    );
    assert_eq!(v.gouge_count, 0, "{file}");
    rest_matches_the_uncut_area(file, &m, &planned, &report, opts.scallop_mm, 8_000_000);
    assert!(
        v.max_scallop_mm <= opts.scallop_mm,
        "{file}: {} mm left outside the rest area at {:?}",
        v.max_scallop_mm,
        v.max_scallop_at_mm
    );
    assert!(
        !report
            .problems
            .iter()
            .any(|p| p.kind == "scallop" || p.kind == "gouge" || p.kind == "unproven"),
        "{file}"
    );
}

/// Issue 13: the rest area a plan reports is the area the cutting simulation finds uncut.
/// Footprints left too tight count the part of them measured above the scallop (the edge of
/// that part located to 1/64 of the footprint), not the whole footprint: mouse.tsm at the
/// page defaults reported 24.64 mm², then 0.80 mm² (9 × 9 samples, a strip along a crease
/// counted as wide as a sample's share), where the simulation finds 0.20 mm² uncut. The
/// plan is simulated again without its rest area masked, at 8 M samples, and the two must
/// agree within the two measurements' own uncertainties — the simulation's (the area of the
/// cells on the uncut area's edge, or one sample's share) and the rest's (a footprint left
/// too tight counts at least one finest cell, [`reach::LEAST_SHARE`] of it, so that a peak
/// only the search found is not reported as nothing, so it may raise the rest but never
/// lower it: Bike.tsm r 1 mm h 0.05 mm reports 0.00012 mm² from such footprints where 4 M
/// samples find none, one sample's share being 0.00011 mm²) — and within a factor 1.5 where
/// it is more than 0.01 mm².
fn rest_matches_the_uncut_area(
    file: &str,
    m: &Model,
    planned: &Planned,
    report: &tspath::plan::PlanReport,
    scallop_mm: f64,
    samples: usize,
) {
    let opts = verify::VerifyOptions::default()
        .with_samples(samples)
        .with_scallop(scallop_mm);
    let path = verify::CutterPath::from_toolpath(&planned.toolpath).unwrap();
    let v = verify::verify(&m.surface, &path, &opts).unwrap();
    let uncut = v.uncut_fraction * v.area_mm2;
    // Its uncertainty: the cells on the uncut area's edge, and at least one sample's share
    // (an area smaller than that may lie between samples).
    let edge = v.uncut_edge_fraction * v.area_mm2 + v.area_mm2 / v.samples as f64;
    let rest = report.unreachable_area_mm2;
    // The least share the plan counts of each footprint left too tight, of the footprint's
    // area as the plan takes it.
    let floor: f64 = planned
        .rest
        .footprints
        .iter()
        .filter(|(_, why)| *why == reach::Why::TooTight)
        .map(|(f, _)| reach::LEAST_SHARE * f.area_mm2(m))
        .sum::<f64>()
        + 0.0; // (an empty sum is −0)
    println!(
        "{file}: rest {rest:.4} mm² (at least {floor:.5} mm² counted), simulated uncut {uncut:.4} ± {edge:.4} mm²"
    );
    if uncut > 0.0 {
        assert!(rest > 0.0, "{file}: {uncut} mm² uncut, none reported");
    }
    assert!(
        rest - uncut <= edge + floor && uncut - rest <= edge,
        "{file}: rest {rest} mm², simulated uncut {uncut} ± {edge} mm², rest's least share {floor} mm²"
    );
    if uncut > 0.01 {
        assert!(
            rest <= 1.5 * uncut && uncut <= 1.5 * rest,
            "{file}: rest {rest} mm², simulated uncut {uncut} mm²"
        );
    }
}
