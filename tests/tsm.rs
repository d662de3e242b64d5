//! The .tsm reader on the real T-Splines files in `www/models/grapetec/` (GrapeTec/T-SPLINE, LGPL-3.0),
//! checked against what must hold of any T-spline read right: shared face boundaries agree
//! from both sides, parameters agree with the file's own `100001uv` records, Bézier end
//! conditions interpolate the boundary corners, the surface stays in the convex hull of each
//! face's support, normals are continuous except where the file's grip blocks put a C0 knot.
//! Then malformed files (typed errors naming the line, never a panic) and a fuzz test.

use proptest::prelude::*;
use tspath::error::Error;
use tspath::geom::{Aabb, Point3, Vector3};
use tspath::io::tsm::{self, TsmMeta};
use tspath::surface::basis::bspline;
use tspath::surface::{DiffGeom, Surface};
use tspath::tmesh::walk::FaceBlend;
use tspath::tmesh::TMesh;

const FIXTURES: [&str; 3] = ["simple", "mouse", "face"];

/// Set to a folder of further `.tsm` files to run the model checks on them too (files from
/// the same software that these tests have not seen).
const EXTRA_DIR_VAR: &str = "TSPATH_EXTRA_TSM_DIR";

/// The fixtures' paths, then any extra files (sorted by name).
fn model_paths() -> Vec<String> {
    let mut out: Vec<String> = FIXTURES
        .iter()
        .map(|n| format!("www/models/grapetec/{n}.tsm"))
        .collect();
    if let Ok(dir) = std::env::var(EXTRA_DIR_VAR) {
        let mut extra: Vec<String> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{EXTRA_DIR_VAR}={dir}: {e}"))
            .filter_map(|e| Some(e.ok()?.path().to_str()?.to_string()))
            .filter(|p| {
                p.ends_with(".tsm") && !FIXTURES.iter().any(|f| p.ends_with(&format!("/{f}.tsm")))
            })
            .collect();
        extra.sort();
        out.extend(extra);
    }
    out
}

fn read_path(path: &str) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

fn fixture_bytes(name: &str) -> Vec<u8> {
    read_path(&format!("www/models/grapetec/{name}.tsm"))
}

struct Loaded {
    mesh: TMesh,
    meta: TsmMeta,
    surface: Surface,
    /// Surface index of each mesh face (domain faces only).
    surface_face: Vec<Option<usize>>,
    /// Diagonal of the control points' box (mm): the model size tolerances scale with.
    size_mm: f64,
}

fn load(name: &str) -> Loaded {
    let (mesh, meta) = tsm::read(&read_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let surface = Surface::try_from_tmesh(&mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut surface_face = vec![None; mesh.faces().len()];
    for (i, f) in surface.faces().iter().enumerate() {
        surface_face[f.mesh_face as usize] = Some(i);
    }
    let size_mm = mesh.control_bbox().diagonal();
    Loaded {
        mesh,
        meta,
        surface,
        surface_face,
        size_mm,
    }
}

/// Live `f` records of a file, counted from its text.
fn live_face_records(path: &str) -> usize {
    read_path(path)
        .split(|&b| b == b'\n')
        .filter(|l| {
            let t: Vec<&[u8]> = l
                .split(|b| b.is_ascii_whitespace())
                .filter(|x| !x.is_empty())
                .take_while(|x| !x.starts_with(b"#"))
                .collect();
            t.len() == 3 && t[0] == b"f"
        })
        .count()
}

/// `(u, v)` in `[0,1]²` of the point `pos` along half-edge `h` from its origin.
fn local_uv(mesh: &TMesh, h: u32, pos: f64) -> (f64, f64) {
    let e = mesh.he(h);
    let f = &mesh.faces()[e.face as usize];
    let o = e.offset + pos;
    let (s, t) = match e.side {
        0 => (o, 0.0),
        1 => (f.width, o),
        2 => (f.width - o, f.height),
        _ => (0.0, f.height - o),
    };
    (
        (s / f.width).clamp(0.0, 1.0),
        (t / f.height).clamp(0.0, 1.0),
    )
}

/// Where the point `pos` along domain-face half-edge `h` continues on the other side:
/// crossing zero-width faces (repeated knot lines) to the next domain face. Returns that
/// face's half-edge, the position along it, and how many zero-width faces were crossed.
/// Written here from the half-edge records alone, independently of the T-mesh's own walk.
fn across(mesh: &TMesh, h: u32, pos: f64) -> Option<(u32, f64, usize)> {
    let (mut h, mut pos) = (h, pos);
    for crossed in 0..64 {
        let t = mesh.he(h).twin?;
        let e = *mesh.he(t);
        let along = e.knot - pos;
        let face = mesh.faces()[e.face as usize];
        if face.is_domain() {
            return Some((t, along, crossed));
        }
        let (len, width) = if e.side % 2 == 0 {
            (face.width, face.height)
        } else {
            (face.height, face.width)
        };
        assert_eq!(
            width, 0.0,
            "entered a zero-area face through a side of zero length"
        );
        let q = len - (e.offset + along);
        let opp = (e.side + 2) % 4;
        let tol = 1e-12 * len.max(1.0);
        let g = mesh.face_half_edges(e.face).into_iter().find(|&g| {
            let ge = mesh.he(g);
            ge.side == opp
                && ge.knot > 0.0
                && ge.offset - tol <= q
                && q <= ge.offset + ge.knot + tol
        })?;
        h = g;
        pos = (q - mesh.he(g).offset).clamp(0.0, mesh.he(g).knot);
    }
    None
}

/// True if a blending function of `face` is only C0 across the side of `h` at `pos`: three
/// or more of its knots across the side sit on the side (a crease the file's grip blocks put
/// there), and the point lies inside its support along the side.
fn c0_blend_at(mesh: &TMesh, blends: &[Vec<FaceBlend>], h: u32, pos: f64) -> bool {
    let e = mesh.he(h);
    let f = &mesh.faces()[e.face as usize];
    let o = e.offset + pos;
    let (along, across_at, along_is_u) = match e.side {
        0 => (o, 0.0, true),
        1 => (o, f.width, false),
        2 => (f.width - o, f.height, true),
        _ => (f.height - o, 0.0, false),
    };
    let tol = 1e-9 * f.width.max(f.height);
    blends[e.face as usize].iter().any(|b| {
        let (al, ac) = if along_is_u {
            (b.u_knots, b.v_knots)
        } else {
            (b.v_knots, b.u_knots)
        };
        let on_side = ac.iter().filter(|&&k| (k - across_at).abs() <= tol).count();
        on_side >= 3 && al[0] < along && along < al[4]
    })
}

fn unit_normal(surface: &Surface, face: usize, u: f64, v: f64) -> Vector3 {
    DiffGeom::try_from_derivs(&surface.derivs(face, u, v))
        .expect("regular point")
        .normal
}

fn angle(a: Vector3, b: Vector3) -> f64 {
    a.cross(&b).norm().atan2(a.dot(&b))
}

#[test]
fn fixtures_load_validate_and_tessellate() {
    for name in &model_paths() {
        let m = tspath::io::load(&read_path(name), "model").unwrap();
        let s = m.summary();
        println!("{name}: {}", serde_json::to_string(&s).unwrap());
        assert_eq!(s.format, "tsm");
        assert_eq!(s.units_read, "millimeters (0.001 m)");
        assert_eq!(s.extraordinary_points, 0);
        // Rectangular patches covering every live face of the file.
        assert!(
            s.patches >= 1 && s.patches == m.layout.len(),
            "{name}: patches"
        );
        let faces: f64 = m.surface.faces().iter().map(|f| f.width * f.height).sum();
        let covered: f64 = m.layout.patches.iter().map(|p| p.width * p.height).sum();
        assert!(
            (faces - covered).abs() < 1e-9 * faces,
            "{name}: layout covers the domain"
        );
        assert!(
            m.surface.faces().len() >= live_face_records(name),
            "{name}: every live face has surface"
        );
        let t = m.tessellate(0.05);
        assert!(!t.indices.is_empty());
        assert!(t.positions.iter().all(|x| x.is_finite()));
        for n in t.normals.chunks(3) {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-4, "{name}: normal of length {len}");
        }
        let patches: std::collections::BTreeSet<u32> = t.patch_ids.iter().copied().collect();
        assert_eq!(
            patches.len(),
            s.patches,
            "{name}: every patch is tessellated"
        );
    }
}

#[test]
fn shared_boundaries_agree_from_both_sides_and_normals_are_continuous_except_at_creases() {
    for name in &model_paths() {
        let l = load(name);
        let (mesh, surface) = (&l.mesh, &l.surface);
        let none = vec![false; mesh.vertex_count()];
        let blends = mesh.face_blends(&none, &none);
        let (mut samples, mut creased, mut boundary) = (0, 0, 0);
        let (mut worst_gap, mut worst_angle, mut worst_crease_angle) = (0.0f64, 0.0f64, 0.0f64);
        for (fa, face) in mesh.faces().iter().enumerate() {
            let Some(sa) = l.surface_face[fa] else {
                continue;
            };
            assert!(face.is_domain());
            for h in mesh.face_half_edges(fa as u32) {
                let knot = mesh.he(h).knot;
                if knot == 0.0 {
                    continue;
                }
                for frac in [0.137, 0.5, 0.863] {
                    let pos = frac * knot;
                    let Some((g, pos_b, _crossed)) = across(mesh, h, pos) else {
                        boundary += 1;
                        continue;
                    };
                    let fb = mesh.he(g).face as usize;
                    let sb = l.surface_face[fb].expect("a domain face");
                    let (ua, va) = local_uv(mesh, h, pos);
                    let (ub, vb) = local_uv(mesh, g, pos_b);
                    let pa = surface.subs(sa, ua, va);
                    let pb = surface.subs(sb, ub, vb);
                    let gap = (pa - pb).norm();
                    worst_gap = worst_gap.max(gap);
                    assert!(
                        gap <= 1e-9 * l.size_mm,
                        "{name}: faces {fa} and {fb} part by {gap} mm at {pa}"
                    );
                    let a = angle(
                        unit_normal(surface, sa, ua, va),
                        unit_normal(surface, sb, ub, vb),
                    );
                    samples += 1;
                    if c0_blend_at(mesh, &blends, h, pos) || c0_blend_at(mesh, &blends, g, pos_b) {
                        creased += 1;
                        worst_crease_angle = worst_crease_angle.max(a);
                    } else {
                        worst_angle = worst_angle.max(a);
                        assert!(
                            a < 1e-7,
                            "{name}: normals of faces {fa} and {fb} differ by {a} rad at {pa}"
                        );
                    }
                }
            }
        }
        println!(
            "{name}: {samples} shared-boundary samples (+{boundary} on the boundary): worst gap {worst_gap:.3e} mm, worst normal angle {worst_angle:.3e} rad; {creased} at C0 knots (worst angle there {worst_crease_angle:.3e} rad)"
        );
        assert!(samples > 0);
    }
}

#[test]
fn parameters_agree_with_the_files_uv_records() {
    let mut compared_any = false;
    for name in &model_paths() {
        let l = load(name);
        let params = tsm::global_parameters(&l.mesh).expect("the fixtures lay out in a plane");
        // Consistency with the knot intervals: along every half-edge the parameters step by
        // its knot interval.
        for h in l.mesh.half_edges() {
            let a = params[h.origin as usize];
            let b = params[l.mesh.he(h.next).origin as usize];
            let d = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            assert!(
                (d - h.knot).abs() < 1e-9,
                "{name}: step {d} vs knot {}",
                h.knot
            );
        }
        let pairs: Vec<([f64; 2], [f64; 2])> = l
            .meta
            .vertex_of_slot
            .iter()
            .zip(&l.meta.uv_records)
            .filter_map(|(v, uv)| Some((params[(*v)? as usize], (*uv)?)))
            .collect();
        if pairs.is_empty() {
            println!("{name}: no 100001uv records to compare");
            continue;
        }
        compared_any = true;
        // Per axis, a least-squares scale and offset (either axis of the file may match
        // either axis of ours); the best assignment must fit exactly.
        let fit = |ours: usize, theirs: usize| -> (f64, f64, f64) {
            let n = pairs.len() as f64;
            let mx = pairs.iter().map(|p| p.0[ours]).sum::<f64>() / n;
            let my = pairs.iter().map(|p| p.1[theirs]).sum::<f64>() / n;
            let sxx: f64 = pairs.iter().map(|p| (p.0[ours] - mx).powi(2)).sum();
            let sxy: f64 = pairs
                .iter()
                .map(|p| (p.0[ours] - mx) * (p.1[theirs] - my))
                .sum();
            let a = sxy / sxx;
            let b = my - a * mx;
            let worst = pairs
                .iter()
                .map(|p| (a * p.0[ours] + b - p.1[theirs]).abs())
                .fold(0.0, f64::max);
            (a, b, worst)
        };
        let straight = [fit(0, 0), fit(1, 1)];
        let swapped = [fit(0, 1), fit(1, 0)];
        let worst = |f: &[(f64, f64, f64); 2]| f[0].2.max(f[1].2);
        let (best, swap) = if worst(&straight) <= worst(&swapped) {
            (straight, false)
        } else {
            (swapped, true)
        };
        let range = pairs
            .iter()
            .flat_map(|p| p.1)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        println!(
            "{name}: {} vertices vs 100001uv (s/t swapped: {swap}): scale {:.6} {:.6}, offset {:.6} {:.6}, worst deviation {:.3e} (uv range {:.3}..{:.3})",
            pairs.len(),
            best[0].0,
            best[1].0,
            best[0].1,
            best[1].1,
            worst(&best),
            range.0,
            range.1
        );
        assert!(
            best[0].0.abs() > 1e-6 && best[1].0.abs() > 1e-6,
            "non-degenerate fit"
        );
        assert!(worst(&best) < 1e-9 * (range.1 - range.0), "{name}");
    }
    assert!(compared_any, "face.tsm carries 100001uv records");
}

/// Domain faces whose closed parameter rectangle contains `p`, with `p`'s `(u, v)` there.
fn faces_at(l: &Loaded, params: &[[f64; 2]], p: [f64; 2]) -> Vec<(usize, f64, f64)> {
    let mut out = Vec::new();
    for (f, face) in l.mesh.faces().iter().enumerate() {
        let Some(sf) = l.surface_face[f] else {
            continue;
        };
        let hs = l.mesh.face_half_edges(f as u32);
        let first_of = |side: u8| {
            hs.iter()
                .copied()
                .find(|&h| l.mesh.he(h).side == side)
                .map(|h| params[l.mesh.he(h).origin as usize])
                .expect("sides 0, 1 and 3 of a domain face are non-empty")
        };
        let (c0, c1, c3) = (first_of(0), first_of(1), first_of(3));
        let du = [c1[0] - c0[0], c1[1] - c0[1]];
        let dv = [c3[0] - c0[0], c3[1] - c0[1]];
        let q = [p[0] - c0[0], p[1] - c0[1]];
        let u = (q[0] * du[0] + q[1] * du[1]) / (du[0] * du[0] + du[1] * du[1]);
        let v = (q[0] * dv[0] + q[1] * dv[1]) / (dv[0] * dv[0] + dv[1] * dv[1]);
        let tol = 1e-9;
        debug_assert!(face.is_domain());
        if (-tol..=1.0 + tol).contains(&u) && (-tol..=1.0 + tol).contains(&v) {
            out.push((sf, u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)));
        }
    }
    out
}

#[test]
fn bezier_end_conditions_interpolate_the_boundary_corners() {
    for name in &model_paths() {
        let l = load(name);
        assert!(
            l.meta.force_bezier_end_conditions,
            "{name} asks for Bézier ends"
        );
        let params = tsm::global_parameters(&l.mesh).unwrap();
        let none = vec![false; l.mesh.vertex_count()];
        let blends = l.mesh.face_blends(&none, &none);
        let (mut convex, mut worst) = (0, 0.0f64);
        let mut concave = Vec::new();
        for &m in l.meta.vertex_of_slot.iter().flatten() {
            if !l.mesh.is_boundary_vertex(m) {
                continue;
            }
            let quarters = l.mesh.angle_quarters(m);
            let grip = l.mesh.points()[m as usize].point;
            let at = faces_at(&l, &params, params[m as usize]);
            // One patch per inside quadrant, or fewer where a patch has a T-junction there.
            assert!(
                !at.is_empty() && at.len() <= quarters as usize,
                "{name}: corner {m} touches {} patches",
                at.len()
            );
            let miss = at
                .iter()
                .map(|&(sf, u, v)| (l.surface.subs(sf, u, v) - grip).norm())
                .fold(0.0, f64::max);
            match quarters {
                // A convex corner ends two boundary control polygons: the clamped (Bézier)
                // ends must pass through it.
                1 => {
                    convex += 1;
                    worst = worst.max(miss);
                    assert!(
                        miss < 1e-9 * l.size_mm,
                        "{name}: the surface misses corner grip {grip} by {miss} mm"
                    );
                }
                // A concave corner: the file clamps the corner grip itself (its 3 x 3 block
                // repeats the knots through it, so its blending function is 1 there), but
                // those repeated knots stop at the block: a grip further along a patch that
                // has the corner inside one of its sides sees a single knot there, and its
                // blending function still reaches the corner. GrapeTec's reader gives the
                // same surface there (`surface_agrees_with_an_independent_reader`).
                3 => {
                    let (sf, u, v) = at[0];
                    let fs = &l.surface.faces()[sf];
                    let inside = |x: f64| x.clamp(OFF_EDGE, 1.0 - OFF_EDGE);
                    let (s, t) = (inside(u) * fs.width, inside(v) * fs.height);
                    let mut own = 0.0;
                    let mut others = Vec::new();
                    for b in &blends[fs.mesh_face as usize] {
                        let n = bspline(&b.u_knots, s) * bspline(&b.v_knots, t);
                        if b.vertex == m {
                            own = n;
                        } else if n > 1e-4 {
                            let far = (l.mesh.points()[b.vertex as usize].point - grip).norm();
                            others.push(format!("{n:.4} (grip {far:.1} mm away)"));
                        }
                    }
                    assert!(
                        (own - 1.0).abs() < 1e-6,
                        "{name}: concave corner grip {grip} has blending value {own} at its corner"
                    );
                    concave.push(format!("{miss:.3} mm: {}", others.join(", ")));
                }
                _ => {}
            }
        }
        println!(
            "{name}: {convex} convex boundary corners interpolated (worst {worst:.3e} mm); {} concave corners, their grip's own blending function is 1, missed by {concave:?}",
            concave.len()
        );
        assert!(
            convex >= 4,
            "{name}: an open surface has at least four convex corners"
        );
    }
}

/// Reference points of the fixtures' surfaces from an independent reader (GrapeTec/T-SPLINE,
/// the repository the fixtures come from), made by `scripts/grapetec/reference`.
fn reference_points(name: &str) -> Vec<(String, Point3)> {
    let path = format!("tests/reference/grapetec/{name}.txt");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            let c =
                |i: usize| -> f64 { t[i].parse().unwrap_or_else(|e| panic!("{path}: {l}: {e}")) };
            (t[0].to_string(), Point3::new(c(3), c(4), c(5)))
        })
        .collect()
}

/// Distance (mm) from `q` to the surface: nearest of a grid of samples, then Newton steps on
/// the faces of the nearest few samples (clamped to each face).
fn distance_to_surface(surface: &Surface, samples: &[(usize, f64, f64, Point3)], q: Point3) -> f64 {
    // The nearest sample of each face, then the eight nearest faces.
    let mut near = vec![(f64::INFINITY, 0.0, 0.0); surface.faces().len()];
    for &(f, u, v, p) in samples {
        let d = (p - q).norm();
        if d < near[f].0 {
            near[f] = (d, u, v);
        }
    }
    let mut order: Vec<usize> = (0..near.len()).collect();
    order.sort_by(|&a, &b| near[a].0.total_cmp(&near[b].0));
    let mut best = f64::INFINITY;
    for &f in order.iter().take(8) {
        let (_, u0, v0) = near[f];
        let (mut u, mut v) = (u0, v0);
        for _ in 0..40 {
            let d = surface.derivs(f, u, v);
            let r = d.point - q;
            let (a, b, c) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
            let (gu, gv) = (d.su.dot(&r), d.sv.dot(&r));
            let det = a * c - b * b;
            if det <= 0.0 {
                break;
            }
            u = (u - (c * gu - b * gv) / det).clamp(0.0, 1.0);
            v = (v - (a * gv - b * gu) / det).clamp(0.0, 1.0);
        }
        best = best.min((surface.subs(f, u, v) - q).norm());
    }
    best
}

#[test]
fn surface_agrees_with_an_independent_reader() {
    // GrapeTec/T-SPLINE's own knot vectors and control points, evaluated exactly at the
    // corners, edge midpoints and centre of each of its faces (concave boundary corners
    // included), must lie on our surface.
    for name in FIXTURES {
        let l = load(&format!("www/models/grapetec/{name}.tsm"));
        let n = 16;
        let mut samples = Vec::new();
        for f in 0..l.surface.faces().len() {
            for i in 0..=n {
                for j in 0..=n {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    samples.push((f, u, v, l.surface.subs(f, u, v)));
                }
            }
        }
        let reference = reference_points(name);
        assert!(reference.len() >= 9, "{name}: too few reference points");
        let tol = 1e-9 * l.size_mm;
        let mut worst = (0.0f64, String::new());
        for (face, q) in &reference {
            let d = distance_to_surface(&l.surface, &samples, *q);
            assert!(
                d <= tol,
                "{name}: GrapeTec's point {q} on its face {face} is {d:.3e} mm off our surface"
            );
            if d > worst.0 {
                worst = (d, face.clone());
            }
        }
        println!(
            "{name}: {} points of GrapeTec/T-SPLINE's reading on our surface, worst {:.3e} mm (its face {})",
            reference.len(),
            worst.0,
            worst.1
        );
    }
}

/// How far inside a face (of its parameter range) blend sums are sampled.
const OFF_EDGE: f64 = 1e-9;

#[test]
fn surface_lies_in_the_convex_hull_of_each_faces_support() {
    for name in &model_paths() {
        let l = load(name);
        let none = vec![false; l.mesh.vertex_count()];
        let blends = l.mesh.face_blends(&none, &none);
        let tol = 1e-9 * l.size_mm;
        let mut worst_mismatch = 0.0f64;
        for (sf, fs) in l.surface.faces().iter().enumerate() {
            let f = fs.mesh_face as usize;
            let support = &blends[f];
            let mut bbox = Aabb::empty();
            for b in support {
                bbox.grow(&l.mesh.points()[b.vertex as usize].point);
            }
            let inside =
                |p: &Point3| (0..3).all(|k| p[k] >= bbox.min[k] - tol && p[k] <= bbox.max[k] + tol);
            // The Bézier cells: positive weights and control points inside the support's box
            // (each is a non-negative combination of the support's control points).
            fs.for_each_cell(&mut |_, cell| {
                for c in cell.cp.iter().flatten() {
                    assert!(c.w > 0.0, "{name}: patch {sf} has a cell weight {}", c.w);
                    let p = Point3::new(c.x / c.w, c.y / c.w, c.z / c.w);
                    assert!(
                        inside(&p),
                        "{name}: patch {sf}: cell point {p} outside {bbox:?}"
                    );
                }
            });
            // Points: non-negative rational blending weights summing to one reproduce them.
            // (Samples keep off the face's edges by a hair, where knots placed by summing
            // intervals may differ from 0 in the last bit.)
            let grid = |i: usize| (i as f64 / 6.0).clamp(OFF_EDGE, 1.0 - OFF_EDGE);
            for i in 0..=6 {
                for j in 0..=6 {
                    let (u, v) = (grid(i), grid(j));
                    let p = l.surface.subs(sf, u, v);
                    assert!(
                        inside(&p),
                        "{name}: patch {sf} at ({u}, {v}): {p} outside {bbox:?}"
                    );
                    let (s, t) = (u * fs.width, v * fs.height);
                    let mut num = Vector3::zeros();
                    let mut den = 0.0;
                    for b in support {
                        let cp = l.mesh.points()[b.vertex as usize];
                        let n = bspline(&b.u_knots, s) * bspline(&b.v_knots, t);
                        assert!(n >= 0.0, "{name}: blending function below zero");
                        num += cp.point.coords * (n * cp.weight);
                        den += n * cp.weight;
                    }
                    assert!(den > 0.0, "{name}: patch {sf} at ({u}, {v}) has no weight");
                    let q = Point3::from(num / den);
                    worst_mismatch = worst_mismatch.max((p - q).norm());
                    assert!((p - q).norm() < tol, "{name}: {p} vs blend sum {q}");
                }
            }
        }
        println!("{name}: surface = convex blend of its supports within {worst_mismatch:.3e} mm");
    }
}

#[test]
fn the_unit_record_scales_to_millimetres() {
    let text = String::from_utf8_lossy(&fixture_bytes("simple")).into_owned();
    let inches = text.replace("units 0.001 millimeters", "units 0.0254 inches");
    let (mm, _) = tsm::read(text.as_bytes()).unwrap();
    let (inch, meta) = tsm::read(inches.as_bytes()).unwrap();
    assert_eq!(meta.units, "inches");
    assert_eq!(meta.units_label(), "inches (0.0254 m)");
    for (a, b) in mm.points().iter().zip(inch.points()) {
        assert!((b.point - a.point * 25.4).norm() < 1e-9 * (1.0 + a.point.coords.norm()));
    }
    let m = tspath::io::load(inches.as_bytes(), "x").unwrap();
    assert_eq!(m.summary().units_read, "inches (0.0254 m)");
}

#[test]
fn gbk_comments_and_skipped_records_do_not_matter() {
    let bytes = fixture_bytes("mouse");
    assert!(
        std::str::from_utf8(&bytes).is_err(),
        "mouse.tsm has non-UTF-8 comments"
    );
    let (mesh, meta) = tsm::read(&bytes).unwrap();
    // 105sym, 105plane, six 105a and the odd-grip-map flag.
    assert_eq!(meta.skipped_records, 1 + 1 + 6 + 1);
    // The `ec 0` records are exactly the edges with a link outside (face -1), read here from
    // the text's `l` records.
    let mut outside_edges: Vec<u32> = bytes
        .split(|&b| b == b'\n')
        .filter_map(|l| {
            let l = &l[..l.iter().position(|&b| b == b'#').unwrap_or(l.len())];
            let t: Vec<&str> = std::str::from_utf8(l).ok()?.split_whitespace().collect();
            (t.len() == 8 && t[0] == "l" && t[5] == "-1").then(|| t[6].parse().unwrap())
        })
        .collect();
    outside_edges.sort_unstable();
    let mut marked: Vec<u32> = meta.edge_conditions.iter().map(|&(e, _)| e).collect();
    marked.sort_unstable();
    assert_eq!(marked, outside_edges);
    assert!(meta.edge_conditions.iter().all(|&(_, c)| c == 0));
    assert!(mesh.boundary_loops() == 1);
    // Stripping every comment gives the same mesh.
    let stripped: Vec<u8> = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .flat_map(|(i, l)| {
            let keep = if i == 0 {
                &l[..7]
            } else {
                &l[..l.iter().position(|&b| b == b'#').unwrap_or(l.len())]
            };
            keep.iter()
                .copied()
                .chain(std::iter::once(b'\n'))
                .collect::<Vec<u8>>()
        })
        .collect();
    let (a, _) = tsm::read(&bytes).unwrap();
    let (b, _) = tsm::read(&stripped).unwrap();
    assert_eq!(a.face_loops(), b.face_loops());
    assert_eq!(a.points(), b.points());
}

// ---------------------------------------------------------------------------------------
// Malformed files.

/// simple.tsm with line `n` (1-based) replaced.
fn simple_with(n: usize, line: &str) -> String {
    let text = String::from_utf8(fixture_bytes("simple")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[n - 1] = line;
    lines.join("\n")
}

fn parse_error_line(e: &Error) -> Option<usize> {
    match e {
        Error::Parse { location, .. } => location.strip_prefix("line ")?.parse().ok(),
        _ => None,
    }
}

#[test]
fn malformed_records_name_their_line() {
    let text = String::from_utf8(fixture_bytes("simple")).unwrap();
    let line_of = |prefix: &str| text.lines().position(|l| l == prefix).unwrap() + 1;
    let cases: Vec<(usize, &str, &str)> = vec![
        (
            line_of("l 11 14 1 0 0 0 0"),
            "l 11 14 1 0 0 99 0",
            "edge 99",
        ),
        (
            line_of("l 11 14 1 0 0 0 0"),
            "l 11 14 1 0 0 0",
            "7 operands",
        ),
        (
            line_of("l 11 14 1 0 0 0 0"),
            "l 11 14 1 0 0 0 x",
            "flag must be an integer",
        ),
        (
            line_of("l 11 14 1 0 0 0 0"),
            "l 11 14 2 0 0 0 0",
            "opposite",
        ),
        (line_of("e 0 0.5"), "e 0", "2 operands"),
        (line_of("e 0 0.5"), "e 0 -0.5", "negative"),
        (line_of("e 0 0.5"), "e 0 nan", "finite number"),
        (line_of("e 0 0.5"), "e 0 0.75", "opposite sides"),
        (line_of("v 0 EAST"), "v 0 UP", "direction"),
        (line_of("v 0 EAST"), "v 2 EAST", "starts at vertex 1"),
        (line_of("f 0 0"), "f 1 0", "not in face 0"),
        (
            line_of("0g 5 0 0 1"),
            "0g 5 zero 0 1",
            "y must be a finite number",
        ),
        (
            line_of("0g 5 0 0 1"),
            "0g 5 0 0 0",
            "weight must be positive",
        ),
        (
            line_of("0m cg 0 4 1 0 0 1 5 1 6"),
            "0m cg 0 4 1 0 0 1 5 1",
            "lists 3 grips",
        ),
        (
            line_of("0m cg 0 4 1 0 0 1 5 1 6"),
            "0m cg 0 4 1 0 0 1 5 1 99",
            "grip 99",
        ),
        (
            line_of("0m cg 0 4 1 0 0 1 5 1 6"),
            "0m cg 0 4 1 0 0 1 5 1 -1",
            "grip 6",
        ),
        (line_of("0m gvp 0"), "0m gvp 9", "vertex 9"),
        (
            line_of("units 0.001 millimeters"),
            "units 0 millimeters",
            "positive",
        ),
        (
            line_of("l 11 14 1 0 0 0 0"),
            "l 11 14 1 0 0 0 0 \u{00ff}",
            "7 operands",
        ),
    ];
    for (n, replacement, needle) in cases {
        let bad = simple_with(n, replacement);
        let e = tsm::read(bad.as_bytes()).expect_err(replacement);
        let msg = e.to_string();
        assert!(msg.contains(needle), "`{replacement}`: {msg}");
        let at = parse_error_line(&e).or_else(|| {
            msg.split("line ")
                .nth(1)?
                .split(|c: char| !c.is_ascii_digit())
                .next()?
                .parse()
                .ok()
        });
        assert!(
            at.is_some(),
            "`{replacement}` gives an error naming a line: {msg}"
        );
        println!("{replacement:28} -> {msg}");
    }
}

#[test]
fn malformed_files_give_typed_errors() {
    let simple = fixture_bytes("simple");
    // Empty, blank, no tag, binary garbage, non-text outside comments, unsupported degree.
    let mut garbage = b"#TS0200\n".to_vec();
    garbage.extend((0..2000u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8));
    let mut non_text = simple.clone();
    let at = non_text.windows(7).position(|w| w == b"e 0 0.5").unwrap();
    non_text[at + 4] = 0xB0;
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty", Vec::new()),
        ("blank", b"\n  \r\n\t\n".to_vec()),
        ("no tag", b"degree 3\nf 0 0\n".to_vec()),
        ("garbage", garbage),
        ("non-text", non_text),
        (
            "degree 2",
            String::from_utf8(simple.clone())
                .unwrap()
                .replace("degree 3", "degree 2")
                .into_bytes(),
        ),
        (
            "no degree",
            String::from_utf8(simple.clone())
                .unwrap()
                .replace("degree 3", "")
                .into_bytes(),
        ),
        (
            "valence 5",
            String::from_utf8(simple.clone())
                .unwrap()
                .replace("0m cg 3 4 0 0 0 1 11", "0m cg 3 5 0 0 0 1 0 11")
                .into_bytes(),
        ),
    ];
    for (what, bytes) in cases {
        let e = tsm::read(&bytes).expect_err(what);
        println!("{what:10} -> {e}");
        assert!(
            matches!(e, Error::Parse { .. } | Error::Unsupported(_)),
            "{what}: {e:?}"
        );
        // Through the format detection too.
        assert!(tspath::io::load(&bytes, "x").is_err());
    }
}

#[test]
fn every_truncation_of_every_fixture_fails_cleanly_or_loads() {
    for name in FIXTURES {
        let bytes = fixture_bytes(name);
        let (mut errors, mut loads) = (0, 0);
        let cuts: Vec<usize> = bytes
            .iter()
            .enumerate()
            .filter(|(_, &b)| b == b'\n')
            .map(|(i, _)| i)
            .chain((0..bytes.len()).step_by(97))
            .collect();
        for cut in cuts {
            match tsm::read(&bytes[..cut]) {
                Ok((mesh, _)) => {
                    loads += 1;
                    let _ = Surface::try_from_tmesh(&mesh);
                }
                Err(e) => {
                    errors += 1;
                    assert!(!e.to_string().is_empty());
                }
            }
        }
        println!("{name}: truncations: {errors} errors, {loads} loads (only the trailer cut)");
        assert!(errors > 0 && loads > 0);
    }
}

// ---------------------------------------------------------------------------------------
// Fuzz: mutated .tsm text never panics; errors are typed and say where.

#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize, usize),
    SwapLines(usize, usize),
    ReplaceToken(usize, usize, String),
    DropToken(usize, usize),
    InsertBytes(usize, Vec<u8>),
    Truncate(usize),
}

fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        (-3i64..400).prop_map(|i| i.to_string()),
        any::<i64>().prop_map(|i| i.to_string()),
        any::<f64>().prop_map(|x| x.to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        prop::sample::select(vec![
            "NORTH", "EAST", "SOUTH", "WEST", "cg", "gv", "gvp", "l", "f", "e", "v", "0g", "0m",
            "#", ""
        ])
        .prop_map(str::to_string),
        "[ -~]{0,6}",
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::DuplicateLine(a, b)),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        (any::<usize>(), any::<usize>(), token())
            .prop_map(|(a, b, t)| Mutation::ReplaceToken(a, b, t)),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::DropToken(a, b)),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(a, b)| Mutation::InsertBytes(a, b)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn mutate(base: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = base.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    for m in muts {
        let n = lines.len().max(1);
        match m {
            Mutation::DeleteLine(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Mutation::DuplicateLine(i, j) if !lines.is_empty() => {
                let l = lines[i % n].clone();
                lines.insert(j % n, l);
            }
            Mutation::SwapLines(i, j) if !lines.is_empty() => lines.swap(i % n, j % n),
            Mutation::ReplaceToken(i, k, _) | Mutation::DropToken(i, k) if !lines.is_empty() => {
                let line = &lines[i % n];
                let mut toks: Vec<Vec<u8>> =
                    line.split(|&b| b == b' ').map(<[u8]>::to_vec).collect();
                let at = k % toks.len();
                match m {
                    Mutation::ReplaceToken(_, _, t) => toks[at] = t.as_bytes().to_vec(),
                    _ => {
                        toks.remove(at);
                    }
                }
                lines[i % n] = toks.join(&b' ');
            }
            Mutation::InsertBytes(i, b) if !lines.is_empty() => {
                let line = &mut lines[i % n];
                let at = i % (line.len() + 1);
                line.splice(at..at, b.iter().copied());
            }
            Mutation::Truncate(i) => {
                let mut flat = lines.join(&b'\n');
                flat.truncate(i % (flat.len() + 1));
                lines = flat.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
            }
            _ => {}
        }
    }
    lines.join(&b'\n')
}

proptest! {
    // 600 cases by default; PROPTEST_CASES=N runs more.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(600),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn fuzz_mutated_tsm_never_panics(
        which in 0usize..3,
        muts in prop::collection::vec(mutation(), 1..5),
    ) {
        let base = fixture_bytes(FIXTURES[which]);
        let bytes = mutate(&base, &muts);
        match tsm::read(&bytes) {
            Ok((mesh, meta)) => {
                // Whatever loads is a valid T-mesh, and evaluating it must not panic either.
                prop_assert_eq!(meta.vertex_of_slot.len(), meta.uv_records.len());
                if let Ok(s) = Surface::try_from_tmesh(&mesh) {
                    for f in 0..s.faces().len() {
                        let p = s.subs(f, 0.5, 0.5);
                        prop_assert!(p.x.is_finite() && p.y.is_finite() && p.z.is_finite());
                    }
                }
            }
            Err(Error::Parse { location, message, .. }) => {
                prop_assert!(!location.is_empty() && !message.is_empty());
            }
            Err(Error::InvalidMesh(m)) | Err(Error::Unsupported(m)) => prop_assert!(!m.is_empty()),
            Err(e) => prop_assert!(false, "unexpected error kind {:?}", e),
        }
    }
}

/// Which software's conventions a synthetic `.tsm` file follows.
#[derive(Clone, Copy, PartialEq)]
enum Writer {
    /// Fusion: `end-conditions SUBD_CREASES`, no `0m` records, coordinates in metres.
    Fusion,
    /// T-Splines for Rhino: Bézier end conditions, `0m gvp` grip records, `0m cg` records of
    /// valence 3 or 5 without extra grips at star points, millimetres.
    Rhino,
}

/// A `.tsm` file without grip blocks, every vertex `NORTH`, one grip per vertex, with the
/// header, grip records and trailer of `writer`. Built here from quadrilaterals
/// (counter-clockwise seen from outside), with outside links along the boundary of an open
/// grid. Coordinates in file units.
fn synthetic_tsm(writer: Writer, points: &[[f64; 3]], quads: &[[usize; 4]]) -> String {
    struct Link {
        a: usize,
        b: usize,
        face: i64,
        prev: usize,
        next: usize,
        edge: usize,
        flag: usize,
    }
    let mut links: Vec<Link> = Vec::new();
    let mut edge_of = std::collections::HashMap::new();
    let mut edges: Vec<usize> = Vec::new();
    let mut corners = vec![0usize; points.len()];
    for (f, q) in quads.iter().enumerate() {
        let base = links.len();
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            let id = *edge_of.entry((a.min(b), a.max(b))).or_insert_with(|| {
                edges.push(base + k);
                edges.len() - 1
            });
            corners[a] += 1;
            links.push(Link {
                a,
                b,
                face: f as i64,
                prev: base + (k + 3) % 4,
                next: base + (k + 1) % 4,
                edge: id,
                flag: 0,
            });
        }
    }
    let directed: std::collections::HashMap<(usize, usize), usize> = links
        .iter()
        .enumerate()
        .map(|(i, l)| ((l.a, l.b), i))
        .collect();
    let inner = links.len();
    for i in 0..inner {
        let (a, b, edge) = (links[i].a, links[i].b, links[i].edge);
        if !directed.contains_key(&(b, a)) {
            // Outside link; the outside occupies the quarter turns the faces leave.
            links.push(Link {
                a: b,
                b: a,
                face: -1,
                prev: 0,
                next: 0,
                edge,
                flag: 3 - corners[b],
            });
        }
    }
    let index: std::collections::HashMap<(usize, usize), usize> = links
        .iter()
        .enumerate()
        .map(|(i, l)| ((l.a, l.b), i))
        .collect();
    for i in inner..links.len() {
        let (a, b) = (links[i].a, links[i].b);
        links[i].next = (inner..links.len()).find(|&j| links[j].a == b).unwrap();
        links[i].prev = (inner..links.len()).find(|&j| links[j].b == a).unwrap();
    }
    let mut out = String::from(match writer {
        Writer::Fusion => "#TS0200\n\ndegree 3\ncap-type G1CAPS\nstar-smoothness 0\nunits 1 meters\nend-conditions SUBD_CREASES\nstar-knot-rule NURCCS\n\n",
        Writer::Rhino => "#TS0200\n\ndegree 3\ncap-type 1\nstar-smoothness 0\nunits 0.001 millimeters\nforce-bezier-end-conditions 1\n",
    });
    for f in 0..quads.len() {
        out += &format!("f {} 0\n", 4 * f);
    }
    for &l in &edges {
        out += &format!("e {l} 1\n");
    }
    for v in 0..points.len() {
        let l = links.iter().position(|l| l.a == v).unwrap();
        out += &format!("v {l} NORTH\n");
    }
    for l in &links {
        let opp = index[&(l.b, l.a)];
        out += &format!(
            "l {} {} {opp} {} {} {} {}\n",
            l.prev, l.next, l.a, l.face, l.edge, l.flag
        );
    }
    for p in points {
        out += &format!("0g {} {} {} 1\n", p[0], p[1], p[2]);
    }
    if writer == Writer::Fusion {
        out += "\ntol 1.00000000000000008e-05\ngeom-tol 1.00000000000000008e-05\nver 992\nbehavior-version 14.2.0\ncompat-version 13.3.0\n";
        return out;
    }
    out += "0m odd-grip-map\n";
    for v in 0..points.len() {
        out += &format!("0m gvp {v}\n");
    }
    for (v, &n) in corners.iter().enumerate() {
        let boundary = links.iter().any(|l| l.face < 0 && l.a == v);
        if !boundary && n != 4 {
            out += &format!("0m cg {v} {n}{}\n", " 0".repeat(n));
        }
    }
    out += "\ntol 1.0000000000000001e-05\nver 904\n";
    out
}

#[test]
fn fusion_exports_read_as_catmull_clark_cages() {
    // An open 4 x 4 grid with one raised point: the same surface as the cage read from OBJ
    // (Catmull–Clark with sharp boundaries), the file's metres read as millimetres.
    let n = 4;
    let mut pts = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let z = if (x, y) == (1, 2) { 0.004 } else { 0.0 };
            pts.push([0.01 * x as f64, 0.01 * y as f64 + 0.002 * x as f64, z]);
        }
    }
    let mut quads = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let v = y * n + x;
            quads.push([v, v + 1, v + n + 1, v + n]);
        }
    }
    let tsm = synthetic_tsm(Writer::Fusion, &pts, &quads);
    let mut obj = String::new();
    for p in &pts {
        obj += &format!("v {} {} {}\n", p[0] * 1000.0, p[1] * 1000.0, p[2] * 1000.0);
    }
    for q in &quads {
        obj += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    let a = tspath::io::load(tsm.as_bytes(), "grid").unwrap();
    let b = tspath::io::load(obj.as_bytes(), "grid").unwrap();
    assert_eq!(a.summary().units_read, "meters (1 m)");
    let samples: Vec<_> = (0..b.surface.faces().len())
        .flat_map(|f| {
            let s = &b.surface;
            (0..=16).flat_map(move |i| {
                (0..=16).map(move |j| {
                    let (u, v) = (i as f64 / 16.0, j as f64 / 16.0);
                    (f, u, v, s.subs(f, u, v))
                })
            })
        })
        .collect();
    let mut worst = 0.0f64;
    for f in 0..a.surface.faces().len() {
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (0.5, 0.5), (1.0, 0.2), (0.9, 1.0)] {
            let p = a.surface.subs(f, u, v);
            worst = worst.max(distance_to_surface(&b.surface, &samples, p));
        }
    }
    println!("Fusion-style grid: {worst:.3e} mm from the OBJ cage's Catmull–Clark surface");
    assert!(worst < 1e-9, "{worst} mm");
    // The surface reaches the grid's corners (subdivision creases along the boundary).
    let corner = Point3::new(30.0, 36.0, 0.0);
    assert!(distance_to_surface(&a.surface, &samples_of(&a.surface), corner) < 1e-9);

    // A closed box: eight star points (valence 3), read and tessellated.
    let (pts, quads) = box_cage(0.01);
    let m = tspath::io::load(
        synthetic_tsm(Writer::Fusion, &pts, &quads).as_bytes(),
        "box",
    )
    .unwrap();
    let s = m.summary();
    assert_eq!((s.extraordinary_points, s.holes), (8, 0));
    let t = m.tessellate(0.05);
    assert!(!t.indices.is_empty() && t.positions.iter().all(|x| x.is_finite()));
    // Symmetric cage, symmetric limit surface about the box's centre.
    let bb = m.surface.bbox();
    for k in 0..3 {
        assert!((bb.min[k] + bb.max[k] - 10.0).abs() < 1e-9, "{bb:?}");
        assert!(bb.min[k] > 0.0 && bb.max[k] < 10.0, "{bb:?}");
    }
}

/// A cube of side `side` (file units) from the origin: corners and outward quadrilaterals.
fn box_cage(side: f64) -> (Vec<[f64; 3]>, [[usize; 4]; 6]) {
    let pts = (0..8)
        .map(|i: usize| [i >> 2 & 1, i >> 1 & 1, i & 1].map(|b| side * b as f64))
        .collect();
    let v = |x: usize, y: usize, z: usize| 4 * x + 2 * y + z;
    let quads = [
        [v(0, 0, 0), v(0, 1, 0), v(1, 1, 0), v(1, 0, 0)],
        [v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1)],
        [v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1)],
        [v(0, 1, 0), v(0, 1, 1), v(1, 1, 1), v(1, 1, 0)],
        [v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0)],
        [v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)],
    ];
    (pts, quads)
}

fn samples_of(s: &Surface) -> Vec<(usize, f64, f64, Point3)> {
    (0..s.faces().len())
        .flat_map(|f| {
            (0..=8).flat_map(move |i| {
                (0..=8).map(move |j| {
                    let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                    (f, u, v, s.subs(f, u, v))
                })
            })
        })
        .collect()
}

#[test]
fn star_points_of_t_splines_for_rhino_are_read() {
    // A closed box in T-Splines for Rhino's conventions: its eight corners are star points of
    // valence 3 (`0m cg V 3 0 0 0`). Read as a T-spline, every face touches a star point and
    // is evaluated by subdivision: the same surface as the box read as a Fusion cage.
    let (pts, quads) = box_cage(10.0);
    let text = synthetic_tsm(Writer::Rhino, &pts, &quads);
    assert_eq!(text.matches("0m cg").count(), 8);
    let (mesh, meta) = tsm::read(text.as_bytes()).unwrap();
    assert!(meta.force_bezier_end_conditions);
    assert_eq!(mesh.scheme(), tspath::tmesh::Scheme::TSpline);
    let rhino = tspath::io::load(text.as_bytes(), "box").unwrap();
    assert_eq!(rhino.summary().extraordinary_points, 8);
    let metres: Vec<[f64; 3]> = pts.iter().map(|p| p.map(|x| x / 1000.0)).collect();
    let fusion = tspath::io::load(
        synthetic_tsm(Writer::Fusion, &metres, &quads).as_bytes(),
        "box",
    )
    .unwrap();
    let samples = samples_of(&fusion.surface);
    let mut worst = 0.0f64;
    for f in 0..rhino.surface.faces().len() {
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (0.5, 0.5), (1.0, 0.2)] {
            let p = rhino.surface.subs(f, u, v);
            worst = worst.max(distance_to_surface(&fusion.surface, &samples, p));
        }
    }
    println!("Rhino-style box with 8 star points: {worst:.3e} mm from the Catmull–Clark box");
    assert!(worst < 1e-9, "{worst} mm");
    // A star point with extra grips (Bézier end conditions or creases there) is refused
    // with a reason.
    let bad = text.replacen("0m cg 0 3 0 0 0", "0m cg 0 3 1 0 0 7", 1);
    let e = tsm::read(bad.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("star point"), "{e}");
}
