//! Local refinement: inserting knot lines leaves the surface unchanged (compared point by
//! point in the global parameter chart) and changes the control net as knot insertion must.

use crate::support;

use support::chart_point as at;
use tspath::model::samples;
use tspath::surface::Surface;
use tspath::tmesh::refine::KnotLine;

fn check(name: &str, lines: &[KnotLine]) -> usize {
    let model = samples::load_sample(name).unwrap();
    let size = model.surface.bbox().diagonal();
    let chart = model.mesh.global_chart().unwrap();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &chart.vertex_pos {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let mut ok = 0;
    for &line in lines {
        let refined = match model.mesh.insert_knot_line(line) {
            Ok(m) => m,
            Err(e) => {
                println!("{name} {line:?}: refused: {e}");
                continue;
            }
        };
        let surface = Surface::try_from_tmesh(&refined).unwrap();
        assert!(refined.vertex_count() > model.mesh.vertex_count());
        let mut worst: f64 = 0.0;
        let mut n = 0;
        for i in 0..=40 {
            for j in 0..=40 {
                let s = lo[0] + (hi[0] - lo[0]) * (i as f64 + 0.5) / 41.0;
                let t = lo[1] + (hi[1] - lo[1]) * (j as f64 + 0.5) / 41.0;
                if let (Some(a), Some(b)) = (
                    at(&model.mesh, &model.surface, s, t),
                    at(&refined, &surface, s, t),
                ) {
                    worst = worst.max((a - b).norm());
                    n += 1;
                }
            }
        }
        println!(
            "{name} {line:?}: {} → {} control points, {n} points compared, worst difference {:.2e} of the model size",
            model.mesh.vertex_count(),
            refined.vertex_count(),
            worst / size
        );
        assert!(n > 500);
        assert!(worst <= 1e-12 * size, "{name} {line:?}: {worst}");
        ok += 1;
    }
    ok
}

#[test]
fn knot_insertion_leaves_nurbs_like_surfaces_unchanged() {
    assert_eq!(check("dome", &[KnotLine::S(0.3), KnotLine::T(0.71)]), 2);
    assert_eq!(
        check(
            "bumps",
            &[KnotLine::S(3.5), KnotLine::T(4.25), KnotLine::S(0.5)]
        ),
        3
    );
}

#[test]
fn knot_insertion_next_to_t_junctions() {
    // Lines far enough from the T-junctions refine; the ones that would need more knots
    // are refused with a reason, never approximated.
    let done = check(
        "tjunction",
        &[
            KnotLine::S(1.5),
            KnotLine::T(6.5),
            KnotLine::S(3.3),
            KnotLine::T(2.5),
        ],
    );
    assert!(done >= 1, "at least one line refines the T-junction sample");
    assert!(check("waves", &[KnotLine::S(5.5), KnotLine::T(5.5)]) >= 1);
}

#[test]
fn refinement_refuses_what_it_cannot_do() {
    let m = samples::sample_mesh("bumps").unwrap();
    assert!(
        m.insert_knot_line(KnotLine::S(2.0)).is_err(),
        "an existing knot line"
    );
    assert!(
        m.insert_knot_line(KnotLine::S(500.0)).is_err(),
        "outside the mesh"
    );
    let k = samples::sample_mesh("keycap-convex").unwrap();
    assert!(
        k.insert_knot_line(KnotLine::S(0.5)).is_err(),
        "Catmull–Clark cage"
    );
}
