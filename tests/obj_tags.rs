//! OBJ subdivision tags (issue 20): `t crease`, `t corner`, `t interpolateboundary` and
//! `t hole` applied as OpenSubdiv reads them, checked against closed forms; a malformed tag
//! is refused naming its line; infinitely sharp creases bound patches and the planner lifts
//! the ball off them as off a `.tsm` crease. (Semi-sharp creases against explicit
//! subdivision: `tests/catmull_clark.rs`.)

use crate::support;

use support::{bumpy_sheet, crease_tag};

use tspath::geom::Point3;
use tspath::io;
use tspath::model::Model;
use tspath::plan::{self, PlanOptions, PlanStatus};
use tspath::surface::on_side;
use tspath::verify;

const N: usize = 6;

/// Number of the sheet's vertex `(i, j)` in the file (and in `t` tags).
fn vid(i: usize, j: usize) -> u32 {
    (j * (N + 1) + i) as u32
}

/// Number of the sheet's vertex `(i, j)` in the model's mesh (the reader numbers vertices
/// in the order faces first use them).
fn mv(m: &Model, i: usize, j: usize) -> u32 {
    m.mesh
        .points()
        .iter()
        .position(|c| c.point.x == i as f64 && c.point.y == j as f64)
        .unwrap() as u32
}

fn load(text: &str) -> Model {
    io::load(text.as_bytes(), "sheet").unwrap()
}

/// The surface point at fraction `t` along the cage edge from vertex `a` to vertex `b`,
/// evaluated on the face that runs `a → b`; `None` if that face carries no surface.
fn along_edge(m: &Model, a: u32, b: u32, t: f64) -> Option<Point3> {
    let (fi, u, v) = face_param(m, a, b, t)?;
    Some(m.surface.subs(fi, u, v))
}

/// Surface face index and `(u, v)` at fraction `t` along the cage edge `a → b` of the face
/// that runs that way; `None` if there is no such face or it carries no surface.
fn face_param(m: &Model, a: u32, b: u32, t: f64) -> Option<(usize, f64, f64)> {
    let h = m
        .mesh
        .half_edges()
        .iter()
        .find(|h| h.origin == a && m.mesh.he(h.next).origin == b)?;
    let fi = m
        .surface
        .faces()
        .iter()
        .position(|f| f.mesh_face == h.face)?;
    let (u, v) = on_side(h.side, t);
    Some((fi, u, v))
}

fn cage_point(m: &Model, v: u32) -> Point3 {
    m.mesh.points()[v as usize].point
}

#[test]
fn a_closed_loop_of_sharp_creases_is_the_cubic_b_spline_of_its_vertices() {
    // The loop round the square [2, 4]²: every vertex on two of its edges.
    let ring = [
        (2, 2),
        (3, 2),
        (4, 2),
        (4, 3),
        (4, 4),
        (3, 4),
        (2, 4),
        (2, 3),
    ];
    let mut chain: Vec<u32> = ring.iter().map(|&(i, j)| vid(i, j)).collect();
    chain.push(chain[0]);
    let text = format!("{}{}", bumpy_sheet(N), crease_tag(&chain, 10.0));
    let m = load(&text);
    let size = m.surface.bbox().diagonal();
    let loop_ids: Vec<u32> = ring.iter().map(|&(i, j)| mv(&m, i, j)).collect();
    let p: Vec<Point3> = loop_ids.iter().map(|&v| cage_point(&m, v)).collect();
    let k = p.len();
    let mut worst: f64 = 0.0;
    let mut kink: f64 = 0.0;
    for s in 0..k {
        let (a, b) = (loop_ids[s], loop_ids[(s + 1) % k]);
        for step in 0..=8 {
            let t = step as f64 / 8.0;
            // Uniform cubic B-spline segment between loop vertices s and s + 1.
            let w = [
                (1.0 - t).powi(3),
                3.0 * t.powi(3) - 6.0 * t * t + 4.0,
                -3.0 * t.powi(3) + 3.0 * t * t + 3.0 * t + 1.0,
                t.powi(3),
            ];
            let mut c = nalgebra::Vector3::zeros();
            for (q, wq) in w.iter().enumerate() {
                c += p[(s + k - 1 + q) % k].coords * (wq / 6.0);
            }
            // Both sides of the crease lie on the curve.
            let inside = along_edge(&m, a, b, t).unwrap();
            let outside = along_edge(&m, b, a, 1.0 - t).unwrap();
            worst = worst
                .max((inside.coords - c).norm() / size)
                .max((outside.coords - c).norm() / size);
        }
        // And the surface folds there: normals on the two sides differ.
        let normal = |a: u32, b: u32, t: f64| {
            let (fi, u, v) = face_param(&m, a, b, t).unwrap();
            m.surface.faces()[fi].normal(u, v).unwrap()
        };
        kink = kink.max(normal(a, b, 0.5).angle(&normal(b, a, 0.5)).to_degrees());
    }
    println!("crease loop: worst relative error {worst:.2e}, largest fold {kink:.1} deg");
    assert!(worst < 1e-12, "{worst}");
    assert!(kink > 5.0, "{kink}");
    // The crease bounds patches: no patch has faces on both sides of it.
    let inner: Vec<u32> = [(2, 2), (3, 2), (2, 3), (3, 3)]
        .iter()
        .map(|&(i, j)| (j * N + i) as u32)
        .collect();
    for (pi, patch) in m.layout.patches.iter().enumerate() {
        let faces: Vec<u32> = patch
            .pieces
            .iter()
            .map(|pc| m.surface.faces()[pc.face as usize].mesh_face)
            .collect();
        let ins = faces.iter().filter(|f| inner.contains(f)).count();
        assert!(
            ins == 0 || ins == faces.len(),
            "patch {pi} crosses the crease: {faces:?}"
        );
    }
    assert_eq!(load(&bumpy_sheet(N)).layout.patches.len(), 1);
    println!("patches with the crease: {}", m.layout.patches.len());
}

#[test]
fn tagged_corners_are_interpolated_and_edge_only_boundaries_round_the_corners() {
    let m = load(&format!(
        "{}t corner 1/1/0 {} 10\n",
        bumpy_sheet(N),
        vid(3, 3)
    ));
    let plain = load(&bumpy_sheet(N));
    let c = mv(&m, 3, 3);
    let at = |m: &Model| along_edge(m, mv(m, 3, 3), mv(m, 4, 3), 0.0).unwrap();
    let p = cage_point(&m, c);
    println!(
        "corner: {:.2e} mm from its vertex (untagged {:.3} mm)",
        (at(&m) - p).norm(),
        (at(&plain) - p).norm()
    );
    assert!((at(&m) - p).norm() < 1e-12);
    assert!((at(&plain) - p).norm() > 1e-2);
    // Every face round it meets there.
    for w in [mv(&m, 2, 3), mv(&m, 4, 3), mv(&m, 3, 2), mv(&m, 3, 4)] {
        assert!((along_edge(&m, c, w, 0.0).unwrap() - p).norm() < 1e-12);
    }

    // Edge only: the sheet's corner vertex 0 follows the crease rule, its limit
    // (a + 4 v + b) / 6 of its two boundary neighbours; edge and corner (the default, also
    // as `1`) keeps it.
    let edge_only = load(&format!(
        "{}t interpolateboundary 1/0/0 2\n",
        bumpy_sheet(N)
    ));
    let edge_corner = load(&format!(
        "{}t interpolateboundary 1/0/0 1\n",
        bumpy_sheet(N)
    ));
    let (v0, a, b) = (
        cage_point(&m, mv(&m, 0, 0)),
        cage_point(&m, mv(&m, 1, 0)),
        cage_point(&m, mv(&m, 0, 1)),
    );
    let want = (a.coords + v0.coords * 4.0 + b.coords) / 6.0;
    let got = along_edge(&edge_only, mv(&m, 0, 0), mv(&m, 1, 0), 0.0).unwrap();
    println!(
        "edge-only corner: {:.2e} mm from (a + 4v + b)/6",
        (got.coords - want).norm()
    );
    assert!((got.coords - want).norm() < 1e-12);
    assert!(
        (along_edge(&edge_corner, mv(&m, 0, 0), mv(&m, 1, 0), 0.0).unwrap() - v0).norm() < 1e-12
    );
    // Elsewhere the boundary rule does not matter: the middle face is the same bit for bit.
    let (c, d) = (mv(&m, 3, 3), mv(&m, 4, 3));
    assert_eq!(
        along_edge(&edge_only, c, d, 0.3),
        along_edge(&plain, c, d, 0.3)
    );
}

#[test]
fn holes_and_uninterpolated_boundaries_carry_no_surface() {
    let plain = load(&bumpy_sheet(N));
    // Face 14 (i 2, j 2) is a hole; its neighbours keep their surface exactly.
    let m = load(&format!("{}t hole 1/0/0 14\n", bumpy_sheet(N)));
    assert_eq!(m.surface.faces().len(), N * N - 1);
    assert!(m.surface.faces().iter().all(|f| f.mesh_face != 14));
    let (a, b) = (mv(&m, 2, 2), mv(&m, 3, 2));
    assert_eq!(along_edge(&m, a, b, 0.4), None);
    assert_eq!(along_edge(&m, b, a, 0.6), along_edge(&plain, b, a, 0.6));
    // The layout goes round it (a concave corner at each of its corners).
    assert!(m.layout.patches.len() > 1);
    // None: faces touching the boundary carry nothing; the inner ones are unchanged.
    let none = load(&format!(
        "{}t interpolateboundary 1/0/0 0\n",
        bumpy_sheet(N)
    ));
    assert_eq!(none.surface.faces().len(), (N - 2) * (N - 2));
    let (a, b) = (mv(&m, 2, 2), mv(&m, 3, 2));
    assert_eq!(
        along_edge(&none, a, b, 0.25),
        along_edge(&plain, a, b, 0.25)
    );
}

#[test]
fn malformed_tags_are_refused_naming_their_line() {
    let base = bumpy_sheet(N);
    let line = base.lines().count() + 1;
    for (tag, says) in [
        ("t smooth 0/0/0", "`t smooth`"),
        ("t crease 2/1/0 0 1", "announces 3 arguments"),
        ("t crease 2/1/0 0 8 2", "not joined by an edge"),
        ("t crease 2/1/0 0 1 -1", "negative"),
        ("t crease 4/3/0 0 1 1 2 1 1 1", "3 sharpness values for 2"),
        ("t crease 3/1/0 0 1 2 1", "takes vertex pairs"),
        ("t crease 2-1-0 0 1 1", "ints/floats/strings"),
        ("t corner 1/1/0 4000 10", "vertex 4000 is not in the file"),
        ("t hole 1/0/0 36", "face 36 is not in the file"),
        (
            "t interpolateboundary 1/0/0 5",
            "0 none, 1 edges and corners, 2 edges only",
        ),
        ("t crease 2/1/0 x 1 1", "`x` is not an integer"),
    ] {
        let text = format!("{base}{tag}\n");
        let e = io::load(text.as_bytes(), "sheet").unwrap_err().to_string();
        assert!(
            e.contains(&format!("line {line}")) && e.contains(says),
            "{tag}: {e}"
        );
    }
    // Several edges in one tag, each with its own sharpness.
    let ok = format!("{base}t crease 4/2/0 0 1 1 2 1 3\n");
    let m = load(&ok);
    let (a, b, c) = (mv(&m, 0, 0), mv(&m, 1, 0), mv(&m, 2, 0));
    assert_eq!(m.mesh.edge_sharpness(a, b), 1.0);
    assert_eq!(m.mesh.edge_sharpness(b, c), 3.0);
    assert!(m.warnings.is_empty());
}

#[test]
fn tags_survive_the_json_format() {
    let text = format!(
        "{}t crease 4/1/0 7 8 8 9 10\nt crease 2/1/0 15 16 2.5\nt corner 1/1/0 24 3\nt hole 1/0/0 30\nt interpolateboundary 1/0/0 2\n",
        bumpy_sheet(N)
    );
    let m = load(&text);
    let json = io::json::write(&m.mesh, "sheet");
    let back = io::load(json.as_bytes(), "sheet.json").unwrap();
    assert_eq!(back.mesh.tags(), m.mesh.tags());
    for (fi, f) in m.surface.faces().iter().enumerate() {
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5)] {
            assert_eq!(f.subs(u, v), back.surface.faces()[fi].subs(u, v));
        }
    }
}

/// A V-shaped trough (tool side up), flanks of `slope` either side of an infinitely sharp
/// crease along x = 16 mm, z = 0, 24 mm long; planned at r 1 mm, h 0.02 mm and simulated.
/// Returns the report, the simulation, and the least distance from the crease line to a ball
/// centre less the radius: what is left at the bottom of the V (mm).
fn v_trough(slope: f64) -> (tspath::plan::PlanReport, verify::Verification, f64) {
    let profile: Vec<(f64, f64)> = (0..9)
        .map(|i| {
            let x = 4.0 * i as f64;
            (x, slope * (x - 16.0).abs())
        })
        .collect();
    let sheet = support::extruded_obj(&profile, 4, 6.0, false);
    // The bottom line: vertex 4 of each profile (9 per row), rows 0..=4.
    let chain: Vec<u32> = (0..=4).map(|k| k * 9 + 4).collect();
    let text = format!("{sheet}{}", crease_tag(&chain, 10.0));
    let m = load(&text);
    assert!(m.layout.patches.len() >= 2, "{}", m.layout.patches.len());
    let opts = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.02);
    let planned = plan::plan(&m, &opts, &mut |_| true).unwrap();
    let report = planned.report(&opts);
    let v = verify::verify_plan(
        &m,
        &planned,
        &opts,
        Some(200_000),
        verify::PLAN_VERIFY_MAX_SAMPLES,
    )
    .unwrap();
    let bottom = planned
        .toolpath
        .moves
        .iter()
        .filter(|m| m.kind.on_surface())
        .map(|m| (m.cl_point.x - 16.0).hypot(m.cl_point.z))
        .fold(f64::INFINITY, f64::min)
        - 1.0;
    println!(
        "V trough of slope {slope} with a sharp crease: {} patches, status {:?}, problems {:?}, left at the bottom {bottom:.5} mm, max gouge {:.4} mm (tolerance {:.4}), max scallop {:.4} mm, bound {:.4} mm, rest {:.5}",
        m.layout.patches.len(),
        report.status,
        report.problems.iter().map(|p| &p.kind).collect::<Vec<_>>(),
        v.max_gouge_mm,
        v.gouge_tolerance_mm,
        v.max_scallop_mm,
        v.error_bound_mm,
        v.rest_fraction
    );
    (report, v, bottom)
}

#[test]
fn a_concave_sharp_crease_plans_without_gouges() {
    // The surface is concave with a fold at the crease that no ball fits. Without the tag
    // the trough is smooth. The planner must lift the ball off both flanks; the simulation
    // finds no gouge.
    let slope: f64 = 0.35;
    let (report, v, bottom) = v_trough(slope);
    // (Without the planner's crease handling the ball cuts 0.22 mm into the flanks.)
    assert_eq!(v.gouge_count, 0, "max gouge {} mm", v.max_gouge_mm);
    // A ball touches both flanks, at a radius from each: it leaves r (1 / cos θ − 1) at the
    // bottom (0.0595 mm), more than h, out of any ball's reach, and the plan says so.
    let least = 1.0 / slope.atan().cos() - 1.0;
    assert!(
        (bottom - least).abs() < 1e-3,
        "{bottom} mm left, {least} mm least"
    );
    assert_eq!(report.status, PlanStatus::PlannedWithProblems);
    assert!(report.problems.iter().any(|p| p.kind == "rest_too_tight"));
}

#[test]
fn a_shallow_concave_crease_is_cut_to_its_bottom() {
    // Flanks of 8.5° either side: a ball touching both leaves r (1 / cos θ − 1) = 0.0112 mm
    // at the bottom, under h. The balls lifted off the far flank slide down it until they
    // touch their own again (lifted straight off it, they left 0.042 mm there and the plan
    // reported the bottom as too tight for the ball).
    let slope: f64 = 0.15;
    let (report, v, bottom) = v_trough(slope);
    let least = 1.0 / slope.atan().cos() - 1.0;
    assert!(
        (bottom - least).abs() < 1e-3,
        "{bottom} mm left, {least} mm least"
    );
    assert_eq!(v.gouge_count, 0, "max gouge {} mm", v.max_gouge_mm);
    assert!(
        !report.problems.iter().any(|p| p.kind == "rest_too_tight"),
        "{:?}",
        report.problems
    );
    assert_eq!(v.rest_fraction, 0.0);
    assert!(
        v.max_scallop_mm + v.error_bound_mm <= 0.02,
        "{} mm",
        v.max_scallop_mm
    );
}

fn opensubdiv_text(name: &str) -> String {
    let path = format!(
        "{}/tests/fixtures/opensubdiv/catmark_{name}.obj",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn fractional_sharpness_blends_the_neighbouring_whole_ones() {
    // One step with sharpness f in (0, 1) is the sharp step times f plus the smooth step
    // times 1 − f, and every later step is linear: so the limit surface with sharpness
    // k + f is (1 − f) times the one with k plus f times the one with k + 1. OpenSubdiv's
    // torus_creases0 has its creases all at 4.7.
    let text = opensubdiv_text("torus_creases0");
    assert!(text.contains(" 4.7"));
    let with = |s: &str| load(&text.replace(" 4.7", &format!(" {s}")));
    let (m, lo, hi) = (with("4.7"), with("4"), with("5"));
    let size = m.surface.bbox().diagonal();
    let mut worst: f64 = 0.0;
    let mut moved: f64 = 0.0;
    for fi in 0..m.surface.faces().len() {
        for j in 0..=4 {
            for i in 0..=4 {
                let (u, v) = (i as f64 / 4.0, j as f64 / 4.0);
                let (p, a, b) = (
                    m.surface.subs(fi, u, v),
                    lo.surface.subs(fi, u, v),
                    hi.surface.subs(fi, u, v),
                );
                let want = a.coords * 0.3 + b.coords * 0.7;
                worst = worst.max((p.coords - want).norm() / size);
                moved = moved.max((b - a).norm() / size);
            }
        }
    }
    println!("torus_creases0 at 4.7: {worst:.2e} of the size from the blend of 4 and 5 (which differ by {moved:.2e})");
    assert!(worst < 1e-12, "{worst}");
    assert!(moved > 1e-4, "{moved}");
}

#[test]
fn opensubdiv_shapes_load_with_their_tags() {
    // Every shape: its tags applied, the surface closed up across faces (each shared cage
    // edge gives the same points from both sides, so nothing tears at creases or holes).
    for name in [
        "cube_creases0",
        "cube_creases1",
        "cube_creases2",
        "dart_edgeonly",
        "dart_edgecorner",
        "edgeonly",
        "edgenone",
        "hole_test2",
        "single_crease",
        "pyramid_creases0",
        "tent_creases0",
        "torus_creases0",
    ] {
        let m = load(&opensubdiv_text(name));
        assert!(m.warnings.is_empty(), "{name}: {:?}", m.warnings);
        let size = m.surface.bbox().diagonal();
        let mut worst: f64 = 0.0;
        for h in m.mesh.half_edges() {
            let (a, b) = (h.origin, m.mesh.he(h.next).origin);
            for t in [0.0, 0.3, 0.5, 1.0] {
                if let (Some(p), Some(q)) = (along_edge(&m, a, b, t), along_edge(&m, b, a, 1.0 - t))
                {
                    worst = worst.max((p - q).norm() / size);
                }
            }
        }
        println!(
            "{name}: {} faces with surface, {} patches, {}; largest gap between sides {worst:.1e}",
            m.surface.faces().len(),
            m.layout.patches.len(),
            m.mesh.tags().describe()
        );
        assert!(worst < 1e-12, "{name}: {worst}");
    }
}
