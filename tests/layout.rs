//! Patch layouts: counts, coverage, rectangular charts whose evaluation matches the faces
//! (derivatives against differences), extraordinary points at patch corners, connections.

use crate::support;

use tspath::layout::ConnectionKind;
use tspath::model::samples::{self, SAMPLES};
use tspath::Model;

fn richardson(f: &dyn Fn(f64) -> tspath::geom::Vector3, h: f64) -> tspath::geom::Vector3 {
    let d = |h: f64| (f(h) - f(-h)) / (2.0 * h);
    (d(h / 2.0) * 4.0 - d(h)) / 3.0
}

#[test]
fn samples_have_their_documented_patch_counts() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        assert_eq!(m.layout.len(), s.patches, "{}", s.name);
    }
}

#[test]
fn patches_cover_the_domain_exactly_once() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let faces: f64 = m.surface.faces().iter().map(|f| f.width * f.height).sum();
        let patches: f64 = m.layout.patches.iter().map(|p| p.width * p.height).sum();
        assert!(
            (faces - patches).abs() < 1e-9 * faces,
            "{}: {faces} vs {patches}",
            s.name
        );
        // Every piece of every face appears once.
        let mut area = vec![0.0; m.surface.faces().len()];
        for p in &m.layout.patches {
            for piece in &p.pieces {
                area[piece.face as usize] +=
                    (piece.local[1] - piece.local[0]) * (piece.local[3] - piece.local[2]);
            }
        }
        for (f, a) in m.surface.faces().iter().zip(&area) {
            assert!(
                (a - f.width * f.height).abs() < 1e-9,
                "{}: face {} covered {a}",
                s.name,
                f.mesh_face
            );
        }
    }
}

fn patch_fd_error(m: &Model) -> f64 {
    let mut worst: f64 = 0.0;
    for p in &m.layout.patches {
        for &(u, v) in &[(0.23, 0.37), (0.61, 0.18), (0.43, 0.71), (0.09, 0.88)] {
            let d = p.derivs(&m.surface, u, v);
            assert!(
                (d.point - p.subs(&m.surface, u, v)).norm() < 1e-12 * m.surface.bbox().diagonal()
            );
            let h = 1e-4 / p.width.max(p.height).max(1.0);
            let fu = richardson(&|e| p.subs(&m.surface, u + e, v).coords, h);
            let fv = richardson(&|e| p.subs(&m.surface, u, v + e).coords, h);
            let fuu = richardson(&|e| p.derivs(&m.surface, u + e, v).su, h);
            let fuv = richardson(&|e| p.derivs(&m.surface, u, v + e).su, h);
            let fvv = richardson(&|e| p.derivs(&m.surface, u, v + e).sv, h);
            let s1 = d.su.norm().max(d.sv.norm());
            let s2 = d.suu.norm().max(d.suv.norm()).max(d.svv.norm()).max(s1);
            worst = worst
                .max((fu - d.su).norm() / s1)
                .max((fv - d.sv).norm() / s1)
                .max((fuu - d.suu).norm() / s2)
                .max((fuv - d.suv).norm() / s2)
                .max((fvv - d.svv).norm() / s2);
        }
    }
    worst
}

#[test]
fn patch_parameterisation_has_consistent_derivatives() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let e = patch_fd_error(&m);
        println!(
            "{}: worst relative derivative error on patches {e:.2e}",
            s.name
        );
        assert!(e < 1e-6, "{}: {e}", s.name);
    }
}

#[test]
fn extraordinary_points_sit_at_patch_corners() {
    for name in ["keycap-convex", "head", "plate-hole", "bumps-hole"] {
        let m = samples::load_sample(name).unwrap();
        let size = m.surface.bbox().diagonal();
        let corners: Vec<_> = m
            .layout
            .patches
            .iter()
            .flat_map(|p| {
                [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                    .map(|(u, v)| p.subs(&m.surface, u, v))
            })
            .collect();
        let index: std::collections::HashMap<u32, usize> = m
            .surface
            .faces()
            .iter()
            .enumerate()
            .map(|(i, f)| (f.mesh_face, i))
            .collect();
        for v in (0..m.mesh.vertex_count() as u32).filter(|&v| m.mesh.is_extraordinary(v)) {
            let h = m.mesh.outgoing(v)[0];
            let e = m.mesh.he(h);
            let (u0, v0) = match e.side {
                0 => (0.0, 0.0),
                1 => (1.0, 0.0),
                2 => (1.0, 1.0),
                _ => (0.0, 1.0),
            };
            let p = m.surface.subs(index[&e.face], u0, v0);
            let n = corners
                .iter()
                .filter(|c| (*c - p).norm() < 1e-9 * size)
                .count();
            let faces = m.mesh.outgoing(v).len();
            assert_eq!(
                n, faces,
                "{name}: EP {v} is a corner of {n} patches, has {faces} faces"
            );
        }
    }
}

#[test]
fn connections_of_the_box_samples() {
    let k = samples::load_sample("keycap-convex").unwrap();
    let boundary: Vec<_> = k
        .layout
        .connections
        .iter()
        .filter(|c| c.kind == ConnectionKind::Boundary)
        .collect();
    // Top to four walls, and each wall to its two neighbours.
    assert_eq!(boundary.len(), 8);
    assert!(k
        .layout
        .connections
        .iter()
        .all(|c| c.kind == ConnectionKind::Boundary));
    let h = samples::load_sample("head").unwrap();
    assert_eq!(h.layout.connections.len(), 12, "the cube's 12 edges");
    for c in &h.layout.connections {
        let (sa, sb) = c.sides.unwrap();
        let pa = &h.layout.patches[c.a as usize];
        let pb = &h.layout.patches[c.b as usize];
        // The middle of the shared side is the same point seen from both patches.
        let mid = |p: &tspath::layout::Patch, s: u8| {
            let (u, v) = [(0.5, 0.0), (1.0, 0.5), (0.5, 1.0), (0.0, 0.5)][s as usize];
            p.subs(&h.surface, u, v)
        };
        assert!((mid(pa, sa) - mid(pb, sb)).norm() < 1e-9);
    }
}

#[test]
fn valence_five_gives_corner_connections() {
    // Five quads around an interior vertex: five patches; neighbours share a side,
    // the others only the extraordinary point.
    let mut s = String::from("v 0 0 0\n");
    for k in 0..5 {
        let a = k as f64 * std::f64::consts::TAU / 5.0;
        let b = a + std::f64::consts::TAU / 10.0;
        s += &format!(
            "v {} {} 0\nv {} {} 0\n",
            a.cos(),
            a.sin(),
            1.8 * b.cos(),
            1.8 * b.sin()
        );
    }
    for k in 0..5 {
        s += &format!(
            "f 1 {} {} {}\n",
            2 + 2 * k,
            3 + 2 * k,
            2 + 2 * ((k + 1) % 5)
        );
    }
    let m = tspath::io::load(s.as_bytes(), "v5").unwrap();
    assert_eq!(m.layout.len(), 5);
    let kinds: Vec<_> = m.layout.connections.iter().map(|c| c.kind).collect();
    assert_eq!(
        kinds
            .iter()
            .filter(|k| **k == ConnectionKind::Boundary)
            .count(),
        5
    );
    assert_eq!(
        kinds
            .iter()
            .filter(|k| **k == ConnectionKind::Corner)
            .count(),
        5
    );
}

#[test]
fn a_model_in_one_chart_that_is_no_rectangle_is_cut_only_at_its_concave_corners() {
    // Issue 20: Bike.tsm and face.tsm lie in one chart whose outline is not a rectangle (a
    // slot in Bike's, two holes in face's), and were laid out one patch per cell: 81 and 135
    // patches, a checkerboard of passes. Now the chart is cut only by the lines its concave
    // corners need: 5 and 13 patches, covering the surface once (their area equals the
    // faces'), meeting side to side and corner to corner (every boundary connection a whole
    // side of both patches, so the patch order can pass at a shared corner), and (issue 13)
    // every boundary connection a stretch of side the two patches really share.
    for (file, before, now) in [("Bike.tsm", 81, 5), ("face.tsm", 135, 13)] {
        let m = support::public_tsm(file);
        let tol = 1e-7 * m.surface.bbox().diagonal();
        let side = |p: &tspath::layout::Patch, s: u8, n: usize| -> Vec<tspath::geom::Point3> {
            (0..=n)
                .map(|k| {
                    let t = k as f64 / n as f64;
                    let (u, v) = [(t, 0.0), (1.0, t), (t, 1.0), (0.0, t)][s as usize];
                    p.subs(&m.surface, u, v)
                })
                .collect()
        };
        // Points of `a` within `tol` of the polyline `b` (dense enough to be the curve).
        let on = |a: &[tspath::geom::Point3], b: &[tspath::geom::Point3]| {
            a.iter()
                .filter(|q| {
                    b.windows(2).any(|w| {
                        let d = w[1] - w[0];
                        let t = ((*q - w[0]).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                        (w[0] + d * t - *q).norm() < tol.max(1e-4 * d.norm())
                    })
                })
                .count()
        };
        let patches = m.layout.patches.len();
        println!("{file}: {patches} patches (were {before})");
        assert_eq!(patches, now, "{file}");
        // Area by the midpoint rule on each face, and as the comparison takes it on each
        // patch: two parametrisations of the same surface.
        let n = 96;
        let mid = |k: usize| (k as f64 + 0.5) / n as f64;
        let faces: f64 = m
            .surface
            .faces()
            .iter()
            .map(|f| {
                let mut a = 0.0;
                for i in 0..n {
                    for j in 0..n {
                        let d = f.derivs(mid(i), mid(j));
                        a += d.su.cross(&d.sv).norm();
                    }
                }
                a / (n * n) as f64
            })
            .sum();
        let laid = tspath::plan::compare::area_mm2(&m);
        println!("{file}: area {laid:.3} mm² by patch, {faces:.3} mm² by face");
        assert!(
            (laid - faces).abs() <= 2e-3 * faces,
            "{file}: {laid} against {faces}"
        );
        let boundary: Vec<_> = m
            .layout
            .connections
            .iter()
            .filter(|c| c.kind == ConnectionKind::Boundary)
            .collect();
        println!("{file}: {} boundary connections", boundary.len());
        assert!(boundary.len() >= patches - 1, "{file}: {}", boundary.len());
        for c in boundary {
            let (sa, sb) = c.sides.unwrap();
            let pa = &m.layout.patches[c.a as usize];
            let pb = &m.layout.patches[c.b as usize];
            // Whole sides: all 33 points of each side lie on the other's.
            let shared = (
                on(&side(pa, sa, 32), &side(pb, sb, 2048)),
                on(&side(pb, sb, 32), &side(pa, sa, 2048)),
            );
            assert_eq!(shared, (33, 33), "{file}: patches {} and {}", c.a, c.b);
        }
    }
}

#[test]
fn a_rectangle_reaching_a_patch_side_reaches_its_faces_sides() {
    // Issue 20: face.tsm cut at its holes' corners put a piece a few ulps wide of a face
    // into the neighbouring patch, and the rest area of a footprint reaching the patch's
    // side ended 6e-16 short of the face's: the simulation's samples on that side fell
    // outside the rest area (0.01004 mm left there against h 0.01 mm, r 0.5 mm). Every
    // patch's whole rectangle, taken back to its faces, covers each face exactly once, its
    // sides exactly at 0 or 1 where they reach the face's, and where two patches share a
    // face, exactly (bit for bit) where the other's piece begins.
    for file in ["Bike.tsm", "face.tsm", "mouse.tsm"] {
        let m = support::public_tsm(file);
        let mut rects: Vec<Vec<[f64; 4]>> = vec![Vec::new(); m.surface.faces().len()];
        for p in &m.layout.patches {
            for (face, r) in p.face_rects(&m.surface, [0.0, 1.0, 0.0, 1.0]) {
                assert!(r[1] > r[0] && r[3] > r[2], "{file}: face {face}: {r:?}");
                for x in r {
                    assert!(
                        x == 0.0 || x == 1.0 || (1e-9..=1.0 - 1e-9).contains(&x),
                        "{file}: face {face}: {r:?}"
                    );
                }
                rects[face as usize].push(r);
            }
        }
        let mut split = 0;
        for (face, rs) in rects.iter().enumerate() {
            let a: f64 = rs.iter().map(|r| (r[1] - r[0]) * (r[3] - r[2])).sum();
            assert!((a - 1.0).abs() < 1e-12, "{file}: face {face} covered {a}");
            for r in rs {
                // A side inside the face: another piece starts exactly there.
                for (k, x) in r.iter().enumerate() {
                    if *x == 0.0 || *x == 1.0 {
                        continue;
                    }
                    split += 1;
                    let other = k ^ 1;
                    assert!(
                        rs.iter().any(|q| q[other] == *x),
                        "{file}: face {face}: {r:?} side {k} meets no other piece in {rs:?}"
                    );
                }
            }
        }
        println!("{file}: {split} piece sides inside faces, each met exactly");
    }
}

#[test]
fn patch_lines_give_the_patchs_own_numbers() {
    // The planner evaluates passes (and lines across them) by PatchLine: the numbers of
    // Patch::derivs, derivs_normal and point_normal, bit for bit where the piece's face holds
    // its u, to rounding where it holds its v; on every patch of every sample, both ways,
    // forwards and back across pieces.
    let xs: Vec<f64> = (0..=40).map(|k| k as f64 / 40.0).collect();
    let back: Vec<f64> = xs.iter().rev().copied().collect();
    let (mut exact, mut close, mut worst) = (0usize, 0usize, 0.0f64);
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let size = m.surface.bbox().diagonal();
        let rel =
            |a: tspath::geom::Vector3, b: tspath::geom::Vector3| (a - b).norm() / (size + b.norm());
        for p in &m.layout.patches {
            for along_u in [true, false] {
                for &at in &[0.0, 0.13, 0.5, 0.871, 1.0] {
                    let mut line = p.line(&m.surface, along_u, at);
                    for &x in xs.iter().chain(&back) {
                        let (u, v) = if along_u { (x, at) } else { (at, x) };
                        let d = p.derivs(&m.surface, u, v);
                        let (ld, ln) = line.derivs_normal(x);
                        let (dn, nn) = p.derivs_normal(&m.surface, u, v);
                        assert_eq!(dn, d);
                        let (lp, lpn) = line.point_normal(x);
                        let (pp, pn) = p.point_normal(&m.surface, u, v);
                        assert_eq!(ln.is_some(), nn.is_some(), "{}", s.name);
                        assert_eq!(lpn.is_some(), pn.is_some(), "{}", s.name);
                        if line.derivs(x) == d && ld == d && ln == nn && (lp, lpn) == (pp, pn) {
                            exact += 1;
                            continue;
                        }
                        close += 1;
                        // Each order against its largest value (see derivs_gap in
                        // geometry.rs: a second derivative can be a small difference).
                        let first = d.su.norm().max(d.sv.norm());
                        let second = d.suu.norm().max(d.suv.norm()).max(d.svv.norm());
                        let mut gap = [
                            rel(ld.point.coords, d.point.coords),
                            (ld.su - d.su).norm() / (size + first),
                            (ld.sv - d.sv).norm() / (size + first),
                            (ld.suu - d.suu).norm() / (size + second),
                            (ld.suv - d.suv).norm() / (size + second),
                            (ld.svv - d.svv).norm() / (size + second),
                            rel(lp.coords, pp.coords),
                        ]
                        .into_iter()
                        .fold(0.0, f64::max);
                        for (a, b) in [(ln, nn), (lpn, pn)] {
                            if let (Some(a), Some(b)) = (a, b) {
                                gap = gap.max((a - b).norm());
                            }
                        }
                        worst = worst.max(gap);
                    }
                }
            }
        }
    }
    println!("patch lines: {exact} points bit for bit, {close} to rounding (worst {worst:.1e})");
    assert!(exact > 1000 && close > 1000, "{exact} exact, {close} close");
    assert!(worst < 1e-12, "{worst:e}");
}
