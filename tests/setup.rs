//! Placing a model (issue 18): the unit of a file that does not say, scale, up axis, quarter
//! turns and the table. Each is a similarity of the control points, so every surface point
//! moves exactly with it: checked point by point, on bounding boxes, and through the CLI.

mod support;

use support::extruded_obj;
use tspath::geom::Point3;
use tspath::io;
use tspath::model::setup::{ImportSetup, LengthUnit, Up};

/// A wavy sheet as a modelling tool writes it, Y up: profile in x–y, extruded along z.
fn y_up_cage() -> String {
    // extruded_obj writes (x, k dy, z) from a profile in x–z; swap to a Y-up file: the
    // profile's height goes into y and the extrusion into z.
    let profile: Vec<(f64, f64)> = (0..9)
        .map(|i| {
            let x = i as f64 * 0.5;
            (x, 0.3 * (x * 1.3).sin())
        })
        .collect();
    extruded_obj(&profile, 4, 0.6, false)
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(rest) => {
                let c: Vec<f64> = rest
                    .split_whitespace()
                    .map(|x| x.parse().unwrap())
                    .collect();
                format!("v {} {} {}\n", c[0], c[2], -c[1])
            }
            None => format!("{l}\n"),
        })
        .collect()
}

/// Sample points `(face, u, v)` over every face.
fn face_samples(n: usize, faces: usize) -> Vec<(usize, f64, f64)> {
    (0..faces)
        .flat_map(|f| {
            (0..n).flat_map(move |i| {
                (0..n).map(move |j| (f, (i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64))
            })
        })
        .collect()
}

#[test]
fn a_y_up_cage_in_centimetres_lands_in_millimetres_z_up_on_the_table() {
    let text = y_up_cage();
    let raw = io::load(text.as_bytes(), "sheet").unwrap();
    let setup = ImportSetup {
        model_units: Some(LengthUnit::Cm),
        up: Up::Y,
        ..ImportSetup::default()
    };
    let placed = io::load_with(text.as_bytes(), "sheet", &setup).unwrap();
    // (x, y, z) in cm, Y up -> (10 x, -10 z, 10 y) mm, Z up: at every sample, exactly.
    let map = |p: &Point3| Point3::new(10.0 * p.x, -10.0 * p.z, 10.0 * p.y);
    let size = placed.surface.bbox().diagonal();
    let faces = raw.surface.faces().len();
    assert_eq!(faces, placed.surface.faces().len());
    let mut worst: f64 = 0.0;
    for (f, u, v) in face_samples(7, faces) {
        let want = map(&raw.surface.subs(f, u, v));
        worst = worst.max((placed.surface.subs(f, u, v) - want).norm());
    }
    println!("largest difference from the mapped surface: {worst:e} mm of {size:.1} mm");
    assert!(worst <= 1e-12 * size);
    // The sheet's height (y in the file) is now z, ten times larger.
    let (a, b) = (raw.surface.bbox(), placed.surface.bbox());
    assert!(((b.max[2] - b.min[2]) - 10.0 * (a.max[1] - a.min[1])).abs() <= 1e-9 * size);
    assert!(((b.max[0] - b.min[0]) - 10.0 * (a.max[0] - a.min[0])).abs() <= 1e-9 * size);
    assert_eq!(placed.units_read, "cm");
    assert!(placed.placement.contains("Y up"), "{}", placed.placement);
    // On the table: the lowest point at Z 0; a quarter turn swaps x and y extents.
    let on = ImportSetup {
        on_table: true,
        rotate_deg: 90,
        ..setup
    };
    let t = io::load_with(text.as_bytes(), "sheet", &on).unwrap();
    let c = t.surface.bbox();
    println!("on the table, turned: {:?} .. {:?}", c.min, c.max);
    assert!(c.min[2].abs() <= 1e-9 * size);
    assert!(((c.max[1] - c.min[1]) - (b.max[0] - b.min[0])).abs() <= 1e-9 * size);
    assert!(((c.max[0] - c.min[0]) - (b.max[1] - b.min[1])).abs() <= 1e-9 * size);
    assert!(t.placement.contains("table") && t.placement.contains("90°"));
}

#[test]
fn bad_set_ups_are_refused_naming_what_to_change() {
    let dome = tspath::model::samples::sample_json("dome").unwrap();
    // The JSON file says mm: another unit is refused, the scale is the way to resize.
    let e = io::load_with(
        dome.as_bytes(),
        "dome",
        &ImportSetup {
            model_units: Some(LengthUnit::Inch),
            strict_units: true,
            ..ImportSetup::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("scale") && e.contains("inch"), "{e}");
    // Not strict (the page, one setting for every file): left unused for a file that says.
    let lenient = io::load_with(
        dome.as_bytes(),
        "dome",
        &ImportSetup {
            model_units: Some(LengthUnit::Inch),
            ..ImportSetup::default()
        },
    )
    .unwrap();
    let plain = io::load(dome.as_bytes(), "dome").unwrap();
    assert_eq!(lenient.surface.bbox(), plain.surface.bbox());
    assert_eq!(lenient.placement, "as modelled");
    for (s, what) in [
        (
            ImportSetup {
                scale: 0.0,
                ..ImportSetup::default()
            },
            "scale",
        ),
        (
            ImportSetup {
                rotate_deg: 45,
                ..ImportSetup::default()
            },
            "rotate",
        ),
    ] {
        let e = io::load_with(dome.as_bytes(), "dome", &s)
            .unwrap_err()
            .to_string();
        assert!(e.contains(what), "{e}");
    }
    let args = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    for (flags, what) in [
        (vec!["--rotate", "45"], "quarter turn"),
        (vec!["--up", "x"], "up axis"),
        (vec!["--model-units", "ft"], "not a unit"),
    ] {
        let mut a = args(&["info", "dome"]);
        a.extend(args(&flags));
        let e = tspath::cli::run(&a).unwrap_err().to_string();
        assert!(e.contains(what), "{flags:?}: {e}");
    }
}

/// The CLI: `info` reports the placement and the millimetre box; a scaled dome is the dome
/// scaled.
#[test]
fn the_cli_places_models_as_asked() {
    let args = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let plain: serde_json::Value =
        serde_json::from_str(&tspath::cli::run(&args(&["info", "dome"])).unwrap()).unwrap();
    let scaled: serde_json::Value = serde_json::from_str(
        &tspath::cli::run(&args(&["info", "dome", "--scale", "2", "--on-table"])).unwrap(),
    )
    .unwrap();
    assert_eq!(plain["placement"], "as modelled");
    let p = scaled["placement"].as_str().unwrap();
    assert!(p.contains("× 2") && p.contains("table"), "{p}");
    let (a, b) = (&plain["bbox_mm"], &scaled["bbox_mm"]);
    for k in 0..3 {
        let ext =
            |x: &serde_json::Value| x["max"][k].as_f64().unwrap() - x["min"][k].as_f64().unwrap();
        assert!((ext(b) - 2.0 * ext(a)).abs() < 1e-9 * ext(b).max(1.0));
    }
    assert!(b["min"][2].as_f64().unwrap().abs() < 1e-9);
}
