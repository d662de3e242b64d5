//! Placing a model (issue 18): the unit of a file that does not say, scale, up axis, quarter
//! turns and the table. Each is a similarity of the control points, so every surface point
//! moves exactly with it: checked point by point, on bounding boxes, and through the CLI.

use crate::support;

use support::extruded_obj;
use tspath::geom::Point3;
use tspath::io;
use tspath::model::setup::{ImportSetup, LengthUnit, ProgramZero, Up};

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
fn an_obj_header_naming_its_unit_is_read_in_that_unit_unless_one_is_set() {
    // OpenSubdiv's shapes (as Maya writes OBJ) open with "# This file uses centimeters as
    // units for non-parametric coordinates.": read as written, the dart was 4 mm across.
    let path = format!(
        "{}/tests/fixtures/opensubdiv/catmark_dart_edgecorner.obj",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.starts_with("# This file uses centimeters as units"));
    let width = |m: &tspath::Model| {
        let b = m.surface.bbox();
        b.max[0] - b.min[0]
    };
    let as_mm = ImportSetup {
        model_units: Some(LengthUnit::Mm),
        ..ImportSetup::default()
    };
    let written = io::load_with(text.as_bytes(), "dart", &as_mm).unwrap();
    let read = io::load(text.as_bytes(), "dart").unwrap();
    println!(
        "dart: {:.3} mm across as written, {:.3} mm in its unit ({}; {})",
        width(&written),
        width(&read),
        read.units_read,
        read.placement
    );
    // The cage's corners are sharp: the surface spans the x of the file's vertices, in cm.
    let xs: Vec<f64> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    let span = xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        - xs.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!((width(&read) - 10.0 * span).abs() <= 1e-9 * width(&read));
    assert!((width(&written) - span).abs() <= 1e-9 * width(&written));
    assert_eq!(read.units_read, "cm (the file's header comment)");
    assert!(
        read.placement.contains("numbers in cm"),
        "{}",
        read.placement
    );
    assert_eq!(written.units_read, "mm");
    // The same numbers: every surface point ten times as far from the origin.
    let mut worst: f64 = 0.0;
    for (f, u, v) in face_samples(5, read.surface.faces().len()) {
        let want = 10.0 * written.surface.subs(f, u, v).coords;
        worst = worst.max((read.surface.subs(f, u, v).coords - want).norm());
    }
    assert!(worst <= 1e-12 * width(&read), "{worst:e}");
    // Other spellings and units; a unit not listed, or a comment after the first record,
    // leaves the file's numbers as mm (assumed).
    for (header, want) in [
        (
            "# This file uses millimetres as units.",
            "mm (the file's header comment)",
        ),
        (
            "#\n# this file USES Inches AS units for coordinates",
            "inch (the file's header comment)",
        ),
        (
            "# This file uses meters as units",
            "m (the file's header comment)",
        ),
        (
            "# This file uses feet as units for non-parametric coordinates.",
            "mm (assumed)",
        ),
        ("# written by hand", "mm (assumed)"),
    ] {
        let cage = format!("{header}\n{}", y_up_cage());
        let m = io::load(cage.as_bytes(), "sheet").unwrap();
        assert_eq!(m.units_read, want, "{header}");
    }
    let late = format!("{}# This file uses centimeters as units\n", y_up_cage());
    assert_eq!(
        io::load(late.as_bytes(), "sheet").unwrap().units_read,
        "mm (assumed)"
    );
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

/// Stock and program zero (issue 18): the stock is the part's box grown by the side and top
/// stock (bottom flush), and the model moves so that the chosen point of it is the origin:
/// every surface point moves by exactly that shift, and the program says where its zero is.
#[test]
fn the_program_zero_goes_where_the_stock_says() {
    let keycap = tspath::model::samples::sample_json("keycap-convex").unwrap();
    let plain = io::load(keycap.as_bytes(), "keycap").unwrap();
    let part = plain.surface.bbox();
    let size = part.diagonal();
    let (side, top) = (2.5, 1.25);
    let c = |k: usize| 0.5 * (part.min[k] + part.max[k]);
    // Each zero, and where it is in the unplaced model's coordinates (closed form).
    let cases = [
        (ProgramZero::Model, [0.0, 0.0, 0.0]),
        (ProgramZero::StockTopCentre, [c(0), c(1), part.max[2] + top]),
        (
            ProgramZero::StockTopCorner,
            [part.min[0] - side, part.min[1] - side, part.max[2] + top],
        ),
        (ProgramZero::StockBottomCentre, [c(0), c(1), part.min[2]]),
        (
            ProgramZero::StockBottomCorner,
            [part.min[0] - side, part.min[1] - side, part.min[2]],
        ),
        (ProgramZero::At([1.5, -2.0, 3.25]), [1.5, -2.0, 3.25]),
    ];
    let faces = plain.surface.faces().len();
    for (zero, at) in cases {
        let setup = ImportSetup {
            stock_side_mm: side,
            stock_top_mm: top,
            zero,
            ..ImportSetup::default()
        };
        let m = io::load_with(keycap.as_bytes(), "keycap", &setup).unwrap();
        let shift = Point3::from(at).coords;
        let mut worst: f64 = 0.0;
        for (f, u, v) in face_samples(5, faces) {
            let want = plain.surface.subs(f, u, v) - shift;
            worst = worst.max((m.surface.subs(f, u, v) - want).norm());
        }
        assert!(worst <= 1e-12 * size, "{zero:?}: {worst:e} mm");
        // The stock: the part's box grown by the stock, moved with the part.
        let want_lo = [part.min[0] - side, part.min[1] - side, part.min[2]];
        let want_hi = [part.max[0] + side, part.max[1] + side, part.max[2] + top];
        for k in 0..3 {
            assert!((m.stock.min[k] - (want_lo[k] - at[k])).abs() <= 1e-9 * size);
            assert!((m.stock.max[k] - (want_hi[k] - at[k])).abs() <= 1e-9 * size);
        }
        assert_eq!(m.program_zero, zero.describe());
        assert_eq!(m.summary().stock_mm, m.stock);
    }
    // On the table and at the stock's top corner: the stock's top is Z 0, its corner X0 Y0.
    let args = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let info: serde_json::Value = serde_json::from_str(
        &tspath::cli::run(&args(&[
            "info",
            "keycap-convex",
            "--on-table",
            "--stock-side",
            "2.5",
            "--stock-top",
            "1.25",
            "--zero",
            "stock-top-corner",
        ]))
        .unwrap(),
    )
    .unwrap();
    let v = |b: &str, e: &str, k: usize| info[b][e][k].as_f64().unwrap();
    assert!(v("stock_mm", "min", 0).abs() < 1e-9 && v("stock_mm", "min", 1).abs() < 1e-9);
    assert!(v("stock_mm", "max", 2).abs() < 1e-9);
    assert!(
        (v("bbox_mm", "max", 2) + 1.25).abs() < 1e-9 && (v("bbox_mm", "min", 0) - 2.5).abs() < 1e-9
    );
    assert!((v("stock_mm", "min", 2) + (part.max[2] - part.min[2]) + 1.25).abs() < 1e-9);
    let p = info["placement"].as_str().unwrap();
    assert!(
        p.contains("stock 2.5 mm") && p.contains("top front-left"),
        "{p}"
    );
    // The program says where its zero is.
    let dir = std::env::temp_dir().join(format!("tspath-zero-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("k.nc");
    let run = tspath::cli::run(&args(&[
        "plan",
        "keycap-convex",
        "--tool-radius",
        "0.5",
        "--scallop",
        "0.05",
        "--zero",
        "stock-top-centre",
        "--stock-top",
        "1",
        "-o",
        out.to_str().unwrap(),
    ]));
    assert!(run.is_ok(), "{run:?}");
    let g = std::fs::read_to_string(&out).unwrap();
    assert!(
        g.contains("program zero: work offset G54, set at the centre of the stock's top"),
        "{}",
        &g[..600.min(g.len())]
    );
    // Every block at the cutting feed is below the stock's top (Z 0) by its 1 mm of stock
    // (the part's top is at Z -1; the approaches at the plunge feed come from above it).
    let mut feed = 0.0;
    let mut highest = f64::NEG_INFINITY;
    for l in g.lines().filter(|l| l.starts_with("G1 ")) {
        let word = |k: char| {
            l.split_whitespace()
                .find(|w| w.starts_with(k))
                .map(|w| w[1..].parse::<f64>().unwrap())
        };
        feed = word('F').unwrap_or(feed);
        if feed == 1000.0 {
            highest = highest.max(word('Z').unwrap_or(f64::NEG_INFINITY));
        }
    }
    assert!(
        highest <= -1.0 + 1e-4 && highest > -1.5,
        "highest tip at the cutting feed {highest} mm"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    // Bad zeros and stock are named.
    for (flags, what) in [
        (vec!["--zero", "top"], "not a program zero"),
        (vec!["--zero", "1,2"], "x,y,z"),
        (vec!["--stock-side", "-1"], "0 mm or more"),
    ] {
        let mut a = args(&["info", "dome"]);
        a.extend(args(&flags));
        let e = tspath::cli::run(&a).unwrap_err().to_string();
        assert!(e.contains(what), "{flags:?}: {e}");
    }
}

/// Stock declared above the part (issue 18 review): the safe plane clears the stock's top,
/// and every approach rapids down no lower than the feed height above it; without top
/// stock the approaches are as before (the feed height above the cut).
#[test]
fn rapids_keep_above_the_declared_stock() {
    use tspath::plan::{self, MoveKind, PlanOptions};
    let keycap = tspath::model::samples::sample_json("keycap-convex").unwrap();
    let o = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.05);
    let r = o.tool_radius_mm;
    for top in [0.0, 4.0] {
        let setup = ImportSetup {
            stock_top_mm: top,
            zero: ProgramZero::StockTopCentre,
            ..ImportSetup::default()
        };
        let m = io::load_with(keycap.as_bytes(), "keycap", &setup).unwrap();
        assert!(m.stock.max[2].abs() < 1e-9, "zero at the stock's top");
        let path = plan::plan(&m, &o, &mut |_| true).unwrap().toolpath;
        let highest = path
            .moves
            .iter()
            .map(|mv| mv.cl_point.z)
            .fold(f64::MIN, f64::max);
        assert!(
            highest >= 2.0 * r + o.clearance_mm - 1e-9,
            "safe plane {highest} mm"
        );
        let mut approaches = 0;
        let moves = &path.moves;
        for i in 1..moves.len() {
            if !(moves[i - 1].kind == MoveKind::Rapid && moves[i].kind.at_plunge_feed()) {
                continue;
            }
            approaches += 1;
            let tip = moves[i - 1].cl_point.z - r;
            let plunge = moves[i..]
                .iter()
                .find(|x| x.kind == MoveKind::Plunge)
                .unwrap();
            let cut = plunge.cl_point.z - r;
            // With top stock, the feed height counts from the stock's top (Z 0 here).
            let want = if top > 0.0 {
                o.feed_height_mm.max(o.feed_height_mm - cut)
            } else {
                o.feed_height_mm
            };
            assert!(
                tip - cut >= want - 1e-6,
                "top stock {top} mm: the rapid ends {} mm above the cut at {cut} mm",
                tip - cut
            );
        }
        assert!(approaches >= 1);
    }
}
