//! Tessellations: watertight (every inner edge shared by two triangles, Euler
//! characteristic of the model's topology), consistently oriented, within the chordal
//! tolerance, and written to STL/OBJ that read back.

use std::collections::HashMap;
use tspath::model::samples::{self, SAMPLES};

#[test]
fn tessellations_are_watertight_and_oriented() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let t = m.tessellate(0.01);
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for tri in t.indices.chunks(3) {
            for k in 0..3 {
                *directed.entry((tri[k], tri[(k + 1) % 3])).or_default() += 1;
            }
        }
        let mut boundary = 0;
        for (&(a, b), &n) in &directed {
            assert_eq!(
                n, 1,
                "{}: edge {a}->{b} used {n} times in one direction",
                s.name
            );
            if !directed.contains_key(&(b, a)) {
                boundary += 1;
            }
        }
        let v = t.positions.len() / 3;
        let f = t.indices.len() / 3;
        let e = (directed.len() + boundary) / 2;
        let euler = v as i64 - e as i64 + f as i64;
        let loops = m.mesh.boundary_loops() as i64;
        // A closed sphere-like model has χ = 2; an open one 2 − (number of boundary loops).
        assert_eq!(euler, 2 - loops, "{}: V {v} E {e} F {f}", s.name);
        assert_eq!(t.patch_ids.len(), f);
        assert!(t.patch_ids.iter().all(|&p| (p as usize) < m.layout.len()));
        println!(
            "{}: {v} vertices, {f} triangles, {boundary} boundary edges, χ = {euler}",
            s.name
        );
    }
}

#[test]
fn tessellations_stay_within_the_chordal_tolerance() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        for tol in [0.05, 0.005] {
            let t = m.tessellate(tol);
            let pos = |i: u32| {
                let k = 3 * i as usize;
                tspath::geom::Point3::new(
                    t.positions[k] as f64,
                    t.positions[k + 1] as f64,
                    t.positions[k + 2] as f64,
                )
            };
            let mut worst: f64 = 0.0;
            for tri in t.indices.chunks(3) {
                let p: Vec<_> = tri.iter().map(|&i| t.params[i as usize]).collect();
                if p[0].0 != p[1].0 || p[1].0 != p[2].0 {
                    continue;
                }
                let (u, v) = (
                    (p[0].1 + p[1].1 + p[2].1) / 3.0,
                    (p[0].2 + p[1].2 + p[2].2) / 3.0,
                );
                // Chordal error: the gap between the triangle and the surface along the
                // surface normal at the centroid's parameters.
                let on_surface = m.surface.subs(p[0].0 as usize, u, v);
                let normal = m.surface.normal(p[0].0 as usize, u, v).unwrap();
                let centroid = (pos(tri[0]).coords + pos(tri[1]).coords + pos(tri[2]).coords) / 3.0;
                worst = worst.max((on_surface.coords - centroid).dot(&normal).abs());
            }
            println!(
                "{} at {tol} mm: worst centroid deviation {worst:.5} mm",
                s.name
            );
            // f32 positions add up to 1e-5 mm on these sizes.
            assert!(worst <= tol + 2e-5, "{}: {worst} > {tol}", s.name);
        }
    }
}
