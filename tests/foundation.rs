//! The thin slice end to end, natively: the built-in dome is exactly a sphere, survives the
//! JSON round trip bit for bit, and its G-code keeps the ball on the sphere.

use tspath::geom::{Point3, Vector3};
use tspath::model::samples::{self, DOME_RADIUS_MM};
use tspath::plan::{isoparametric, MoveKind, PlanOptions};
use tspath::surface::DiffGeom;

fn dome_centre() -> Point3 {
    Point3::new(0.0, 0.0, -0.5 * DOME_RADIUS_MM)
}

#[test]
fn dome_lies_on_its_sphere_with_sphere_curvature() {
    let m = samples::load_sample("dome").unwrap();
    let r = DOME_RADIUS_MM;
    let c = dome_centre();
    assert_eq!(m.surface.faces().len(), 1);
    for i in 0..=20 {
        for j in 0..=20 {
            let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
            let d = m.surface.derivs(0, u, v);
            let radial = d.point - c;
            assert!(
                (radial.norm() - r).abs() < 1e-12 * r,
                "({u}, {v}): distance {} from the centre",
                radial.norm()
            );
            let g = DiffGeom::try_from_derivs(&d).unwrap();
            assert!(
                (g.normal - radial / r).norm() < 1e-12,
                "outward unit normal"
            );
            let (k1, k2) = g.principal();
            assert!(
                (k1 + 1.0 / r).abs() < 1e-9 && (k2 + 1.0 / r).abs() < 1e-9,
                "k = {k1}, {k2}"
            );
            assert!((g.gaussian() - 1.0 / (r * r)).abs() < 1e-9 / (r * r));
            assert!((g.rms_curvature() - 1.0 / r).abs() < 1e-9 / r);
        }
    }
}

#[test]
fn json_round_trip_is_exact() {
    let text = samples::sample_json("dome").unwrap();
    let (mesh, meta) = tspath::io::json::read(&text).unwrap();
    assert_eq!(meta.name, "dome");
    let again = tspath::io::json::write(&mesh, &meta.name);
    assert_eq!(text, again, "write(read(x)) == x byte for byte");
}

#[test]
fn json_units_scale_to_millimetres() {
    let text = samples::sample_json("dome")
        .unwrap()
        .replace("\"units\": \"mm\"", "\"units\": \"inch\"");
    let m = tspath::io::load(text.as_bytes(), "x").unwrap();
    let mm = samples::load_sample("dome").unwrap();
    let (a, b) = (m.surface.subs(0, 0.3, 0.7), mm.surface.subs(0, 0.3, 0.7));
    assert!((a.coords - b.coords * 25.4).norm() < 1e-9);
    assert_eq!(m.summary().units_read, "inch");
}

#[test]
fn plan_keeps_the_ball_on_the_sphere_and_the_scallop_under_the_limit() {
    let m = samples::load_sample("dome").unwrap();
    let opts = PlanOptions::default()
        .with_tool_radius(2.0)
        .with_scallop(0.02);
    let path = isoparametric::plan_zigzag(&m, &opts, &mut |_| true).unwrap();
    let c = dome_centre();
    let mut cuts = 0;
    for mv in &path.moves {
        if matches!(mv.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge) {
            // Ball centre at distance R + r from the sphere centre, contact point on the sphere.
            assert!(((mv.cl_point - c).norm() - (DOME_RADIUS_MM + 2.0)).abs() < 1e-9);
            assert!(((mv.cc_point - c).norm() - DOME_RADIUS_MM).abs() < 1e-9);
            cuts += 1;
        }
        assert!((mv.tool_axis - Vector3::z()).norm() < 1e-15);
    }
    assert!(cuts > 100);
    assert!(path.max_predicted_scallop_mm <= 0.02 * (1.0 + 1e-9));
    let report = path.report("isoparametric", 1000.0, 300.0);
    assert_eq!(report.retractions, 0, "one patch needs no retraction");
    assert!(
        report.reversals > 10,
        "a zig-zag reverses at every line end"
    );
}

#[test]
fn same_input_same_gcode() {
    let m = samples::load_sample("dome").unwrap();
    let opts = PlanOptions::default()
        .with_tool_radius(3.0)
        .with_scallop(0.05);
    let job = tspath::machine::JobInfo {
        model: "dome".into(),
        strategy: "isoparametric".into(),
        program_zero: "the model's origin".into(),
    };
    let a = isoparametric::plan_zigzag(&m, &opts, &mut |_| true).unwrap();
    let b = isoparametric::plan_zigzag(&m, &opts, &mut |_| true).unwrap();
    let ga = tspath::machine::gcode_3axis(&a, &opts, &job).unwrap();
    assert_eq!(ga, tspath::machine::gcode_3axis(&b, &opts, &job).unwrap());
    // Tool tip = ball centre − r·Z, so every cutting line puts the ball on the sphere; the
    // others are the approaches from the feed height, in the air above it.
    let c = dome_centre();
    let mut n = 0;
    let mut in_air = 0;
    for line in ga.lines().filter(|l| l.starts_with("G1 ")) {
        let word = |k: char| -> f64 {
            line.split_whitespace()
                .find(|w| w.starts_with(k))
                .map(|w| w[1..].parse().unwrap())
                .unwrap()
        };
        let centre = Point3::new(word('X'), word('Y'), word('Z') + 3.0);
        let off = (centre - c).norm() - (DOME_RADIUS_MM + 3.0);
        if off > 0.05 {
            in_air += 1;
            continue;
        }
        assert!(off.abs() < 2e-4, "{line}");
        n += 1;
    }
    assert!(n > 100);
    let approaches = a
        .moves
        .iter()
        .filter(|m| m.kind == MoveKind::Approach)
        .count();
    assert_eq!(in_air, approaches);
}
