//! The geometry kernel against independent references: a tensor-product NURBS evaluator
//! written here, exact rational cylinders, central differences, partition of unity, normal
//! continuity across faces and at extraordinary points, and the documented sample sizes.

use tspath::geom::{Point3, Vector3, Vector4};
use tspath::model::samples::{self, SAMPLES};
use tspath::surface::DiffGeom;
use tspath::tmesh::{ControlPoint, Scheme, TMesh};
use tspath::Model;

/// Cox–de Boor on a full knot vector: all basis functions of degree 3 at `x`
/// (right-continuous; the last span closed).
fn basis(knots: &[f64], x: f64) -> Vec<f64> {
    let n = knots.len() - 4;
    let last = knots[knots.len() - 1];
    let mut span = None;
    for i in 0..knots.len() - 1 {
        if knots[i] < knots[i + 1]
            && ((knots[i] <= x && x < knots[i + 1]) || (x == last && knots[i + 1] == last))
        {
            span = Some(i);
        }
    }
    let span = span.unwrap();
    let mut b: Vec<f64> = (0..knots.len() - 1)
        .map(|i| if i == span { 1.0 } else { 0.0 })
        .collect();
    for k in 1..=3 {
        for i in 0..knots.len() - 1 - k {
            let l = if knots[i + k] > knots[i] {
                (x - knots[i]) / (knots[i + k] - knots[i]) * b[i]
            } else {
                0.0
            };
            let r = if knots[i + k + 1] > knots[i + 1] {
                (knots[i + k + 1] - x) / (knots[i + k + 1] - knots[i + 1]) * b[i + 1]
            } else {
                0.0
            };
            b[i] = l + r;
        }
    }
    b.truncate(n);
    b
}

fn nurbs_point(pts: &[ControlPoint], nu: usize, ku: &[f64], kv: &[f64], s: f64, t: f64) -> Point3 {
    let bu = basis(ku, s);
    let bv = basis(kv, t);
    let mut acc = Vector4::zeros();
    for (j, &b) in bv.iter().enumerate() {
        for (i, &a) in bu.iter().enumerate() {
            acc += pts[j * nu + i].homogeneous() * (a * b);
        }
    }
    Point3::new(acc.x / acc.w, acc.y / acc.w, acc.z / acc.w)
}

/// A deterministic pseudo-random sequence (the test must not depend on a crate).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn tspline_without_t_junctions_equals_nurbs() {
    let mut rng = Lcg(7);
    let (nu, nv) = (7, 6);
    // Clamped, non-uniform knot vectors.
    let ku = [0.0, 0.0, 0.0, 0.0, 0.7, 1.1, 2.5, 3.0, 3.0, 3.0, 3.0];
    let kv = [0.0, 0.0, 0.0, 0.0, 1.5, 2.0, 4.0, 4.0, 4.0, 4.0];
    let pts: Vec<ControlPoint> = (0..nu * nv)
        .map(|k| ControlPoint {
            point: Point3::new(
                (k % nu) as f64 * 10.0 + rng.next(),
                (k / nu) as f64 * 8.0 + rng.next(),
                5.0 * rng.next(),
            ),
            weight: 0.5 + rng.next(),
        })
        .collect();
    let du: Vec<f64> = (0..nu - 1).map(|i| ku[i + 3] - ku[i + 2]).collect();
    let dv: Vec<f64> = (0..nv - 1).map(|j| kv[j + 3] - kv[j + 2]).collect();
    let mesh = TMesh::from_grid(pts.clone(), nu, nv, &du, &dv, Scheme::TSpline).unwrap();
    let model = Model::try_new("nurbs", "test", "mm", mesh).unwrap();
    let size = model.surface.bbox().diagonal();
    let mut worst: f64 = 0.0;
    for (fi, face) in model.surface.faces().iter().enumerate() {
        let (i, j) = (
            face.mesh_face as usize % (nu - 1),
            face.mesh_face as usize / (nu - 1),
        );
        let (s0, s1) = (ku[i + 2], ku[i + 3]);
        let (t0, t1) = (kv[j + 2], kv[j + 3]);
        for a in 0..=6 {
            for b in 0..=6 {
                let (u, v) = (a as f64 / 6.0, b as f64 / 6.0);
                let p = model.surface.subs(fi, u, v);
                let q = nurbs_point(&pts, nu, &ku, &kv, s0 + u * (s1 - s0), t0 + v * (t1 - t0));
                worst = worst.max((p - q).norm() / size);
            }
        }
    }
    println!("T-spline vs NURBS: worst relative difference {worst:.2e}");
    assert!(worst < 1e-12, "{worst}");
}

/// A quarter cylinder of radius `r` about the z axis, height `h`: the rational quadratic
/// arc elevated to cubic in u, a straight line (cubic, equally spaced) in v.
fn quarter_cylinder(r: f64, h: f64) -> TMesh {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let arc = [
        (Vector3::new(r, 0.0, 0.0), 1.0),
        (Vector3::new(r, r, 0.0), w),
        (Vector3::new(0.0, r, 0.0), 1.0),
    ];
    let hq: Vec<Vector4> = arc
        .iter()
        .map(|(p, w)| Vector4::new(p.x * w, p.y * w, p.z * w, *w))
        .collect();
    let hc = [
        hq[0],
        (hq[0] + hq[1] * 2.0) / 3.0,
        (hq[1] * 2.0 + hq[2]) / 3.0,
        hq[2],
    ];
    let mut pts = Vec::new();
    for j in 0..4 {
        for c in &hc {
            pts.push(ControlPoint {
                point: Point3::new(c.x / c.w, c.y / c.w, h * j as f64 / 3.0),
                weight: c.w,
            });
        }
    }
    TMesh::from_grid(
        pts,
        4,
        4,
        &[0.0, 1.0, 0.0],
        &[0.0, 1.0, 0.0],
        Scheme::TSpline,
    )
    .unwrap()
}

#[test]
fn rational_cylinder_is_exact_with_closed_form_curvatures() {
    let r = 12.5;
    let model = Model::try_new("cyl", "test", "mm", quarter_cylinder(r, 30.0)).unwrap();
    for a in 0..=10 {
        for b in 0..=10 {
            let (u, v) = (a as f64 / 10.0, b as f64 / 10.0);
            let d = model.surface.derivs(0, u, v);
            let radial = Vector3::new(d.point.x, d.point.y, 0.0);
            assert!(
                (radial.norm() - r).abs() < 1e-12 * r,
                "off the cylinder by {}",
                radial.norm() - r
            );
            let g = DiffGeom::try_from_derivs(&d).unwrap();
            assert!((g.normal - radial / r).norm() < 1e-12, "outward normal");
            let (k1, k2) = g.principal();
            assert!(
                (k1 + 1.0 / r).abs() < 1e-10 && k2.abs() < 1e-10,
                "principal {k1} {k2}"
            );
            assert!(g.gaussian().abs() < 1e-12);
            assert!((g.mean() + 0.5 / r).abs() < 1e-10);
            assert!(
                g.normal_curvature(0.0, 1.0).abs() < 1e-12,
                "straight along the axis"
            );
            assert!(
                (g.normal_curvature(1.0, 0.0) + 1.0 / r).abs() < 1e-10,
                "circle across"
            );
            assert!((g.rms_curvature() - 1.0 / (r * 2f64.sqrt())).abs() < 1e-10);
        }
    }
}

/// Central difference of `f` at step `h`, Richardson-extrapolated (error O(h⁴)).
fn richardson(f: &dyn Fn(f64) -> Vector3, h: f64) -> Vector3 {
    let d = |h: f64| (f(h) - f(-h)) / (2.0 * h);
    (d(h / 2.0) * 4.0 - d(h)) / 3.0
}

/// Relative difference of derivatives from central differences, worst over faces and
/// interior sample points.
fn worst_fd_error(model: &Model) -> f64 {
    let h = 1e-4;
    let size = model.surface.bbox().diagonal();
    let mut worst: f64 = 0.0;
    for face in model.surface.faces() {
        // Points away from dyadic and third knot lines, where derivatives of order 3 jump.
        for &(u, v) in &[(0.23, 0.37), (0.61, 0.18), (0.43, 0.71), (0.09, 0.88)] {
            let d = face.derivs(u, v);
            let p = |du: f64, dv: f64| face.subs(u + du, v + dv).coords;
            let fu = richardson(&|e| p(e, 0.0), h);
            let fv = richardson(&|e| p(0.0, e), h);
            let fuu = richardson(&|e| face.derivs(u + e, v).su, h);
            let fuv = richardson(&|e| face.derivs(u, v + e).su, h);
            let fvv = richardson(&|e| face.derivs(u, v + e).sv, h);
            let scale = d.su.norm().max(d.sv.norm()).max(1e-3 * size);
            let scale2 = d.suu.norm().max(d.suv.norm()).max(d.svv.norm()).max(scale);
            for (e, s) in [
                ((fu - d.su).norm(), scale),
                ((fv - d.sv).norm(), scale),
                ((fuu - d.suu).norm(), scale2),
                ((fuv - d.suv).norm(), scale2),
                ((fvv - d.svv).norm(), scale2),
            ] {
                worst = worst.max(e / s);
            }
        }
    }
    worst
}

#[test]
fn derivatives_agree_with_central_differences_on_every_sample() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let e = worst_fd_error(&m);
        println!("{}: worst relative derivative error {e:.2e}", s.name);
        assert!(e < 1e-6, "{}: {e}", s.name);
    }
}

#[test]
fn blending_functions_sum_to_one_on_t_spline_samples() {
    // All T-spline samples except the rational dome have unit weights: the homogeneous
    // weight of every Bézier cell is then the sum of the blending functions.
    for name in ["tjunction", "bumps", "waves"] {
        let m = samples::load_sample(name).unwrap();
        assert!(m.mesh.points().iter().all(|p| p.weight == 1.0));
        let mut worst: f64 = 0.0;
        for face in m.surface.faces() {
            face.for_each_cell(&mut |_, cell| {
                for a in 0..=4 {
                    for b in 0..=4 {
                        let w = cell.subs_h(a as f64 / 4.0, b as f64 / 4.0).w;
                        worst = worst.max((w - 1.0).abs());
                    }
                }
            });
        }
        println!("{name}: worst |Σ B − 1| = {worst:.2e}");
        assert!(worst < 1e-12, "{name}: {worst}");
    }
}

/// Parameter on face side `k` (0..3) at fraction `t` along it.
fn on_side(k: u8, t: f64) -> (f64, f64) {
    match k {
        0 => (t, 0.0),
        1 => (1.0, t),
        2 => (1.0 - t, 1.0),
        _ => (0.0, 1.0 - t),
    }
}

/// Worst position gap (relative) and normal angle (rad) across shared face edges.
fn worst_seam(m: &Model) -> (f64, f64) {
    let mesh = &m.mesh;
    let index: std::collections::HashMap<u32, usize> = m
        .surface
        .faces()
        .iter()
        .enumerate()
        .map(|(i, f)| (f.mesh_face, i))
        .collect();
    let size = m.surface.bbox().diagonal();
    let (mut gap, mut angle): (f64, f64) = (0.0, 0.0);
    for (hi, h) in mesh.half_edges().iter().enumerate() {
        let Some(t) = h.twin else { continue };
        if (hi as u32) > t {
            continue;
        }
        let o = mesh.he(t);
        let (Some(&fa), Some(&fb)) = (index.get(&h.face), index.get(&o.face)) else {
            continue;
        };
        if h.knot == 0.0 {
            continue;
        }
        let (fa_w, fb_w) = (
            &mesh.faces()[h.face as usize],
            &mesh.faces()[o.face as usize],
        );
        let side_len = |f: &tspath::tmesh::Face, k: u8| if k % 2 == 0 { f.width } else { f.height };
        for k in 1..8 {
            let s = k as f64 / 8.0;
            // Position along the edge from h's origin, in each face's side fraction.
            let ta = (h.offset + s * h.knot) / side_len(fa_w, h.side);
            let tb = (o.offset + (1.0 - s) * o.knot) / side_len(fb_w, o.side);
            let (ua, va) = on_side(h.side, ta);
            let (ub, vb) = on_side(o.side, tb);
            let pa = m.surface.subs(fa, ua, va);
            let pb = m.surface.subs(fb, ub, vb);
            gap = gap.max((pa - pb).norm() / size);
            let na = m.surface.normal(fa, ua, va).unwrap();
            let nb = m.surface.normal(fb, ub, vb).unwrap();
            // |na − nb| is the angle (rad) for small angles, without acos's loss near 1.
            angle = angle.max((na - nb).norm());
        }
    }
    (gap, angle)
}

#[test]
fn surfaces_are_watertight_with_continuous_normals() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let (gap, angle) = worst_seam(&m);
        println!(
            "{}: worst seam gap {gap:.2e} (relative), normal jump {:.2e}°",
            s.name,
            angle.to_degrees()
        );
        assert!(gap < 1e-12, "{}: gap {gap}", s.name);
        assert!(angle < 1e-10, "{}: normal jump {angle} rad", s.name);
    }
}

/// Largest difference between the unit normals of the faces meeting at vertex `v`, each
/// taken at fraction `t` of the way from the vertex towards its face's centre.
fn normal_spread(m: &Model, v: u32, t: f64) -> f64 {
    let mesh = &m.mesh;
    let index: std::collections::HashMap<u32, usize> = m
        .surface
        .faces()
        .iter()
        .enumerate()
        .map(|(i, f)| (f.mesh_face, i))
        .collect();
    let mut normals = Vec::new();
    let mut points = Vec::new();
    for h in mesh.outgoing(v) {
        let e = mesh.he(h);
        // The vertex is a corner: the start of side `e.side` of its face.
        let (u0, v0) = on_side(e.side, 0.0);
        let (u, w) = (u0 + (0.5 - u0) * t, v0 + (0.5 - v0) * t);
        let fi = index[&e.face];
        let d = m.surface.derivs(fi, u, w);
        normals.push(DiffGeom::try_from_derivs(&d).unwrap().normal);
        points.push(m.surface.subs(fi, u0, v0));
    }
    for p in &points {
        assert!(
            (p - points[0]).norm() < 1e-12 * m.surface.bbox().diagonal(),
            "faces meet at one limit point"
        );
    }
    normals
        .iter()
        .map(|n| (n - normals[0]).norm())
        .fold(0.0, f64::max)
}

#[test]
fn normals_agree_at_extraordinary_points() {
    for name in [
        "keycap-convex",
        "keycap-concave",
        "head",
        "plate-hole",
        "bumps-hole",
    ] {
        let m = samples::load_sample(name).unwrap();
        let mesh = &m.mesh;
        let (mut interior, mut boundary): (f64, f64) = (0.0, 0.0);
        for v in (0..mesh.vertex_count() as u32).filter(|&v| mesh.is_extraordinary(v)) {
            let spreads: Vec<f64> = [1e-3, 1e-5, 1e-7, 1e-9]
                .iter()
                .map(|&t| normal_spread(&m, v, t))
                .collect();
            if mesh.is_boundary_vertex(v) {
                // At a concave boundary corner the crease rules give a tangent plane that the
                // faces approach slowly (about as distance^0.28): it must keep shrinking.
                assert!(
                    spreads.windows(2).all(|w| w[1] < w[0]),
                    "{name} v{v}: {spreads:?}"
                );
                boundary = boundary.max(spreads[3]);
            } else {
                interior = interior.max(spreads[3]);
            }
        }
        println!(
            "{name}: normal spread at 1e-9 of the face from extraordinary points: interior {interior:.1e} rad, boundary {boundary:.1e} rad"
        );
        assert!(interior < 1e-9, "{name}: {interior}");
        assert!(boundary < 1e-3, "{name}: {boundary}");
    }
}

#[test]
fn samples_have_their_documented_counts_and_sizes() {
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let sum = m.summary();
        assert_eq!(
            sum.extraordinary_points, s.extraordinary_points,
            "{}: EPs",
            s.name
        );
        let size = m.surface.bbox().size();
        for (k, (got, want)) in size.iter().zip(s.size_mm).enumerate() {
            if want > 0.0 {
                assert!(
                    (got - want).abs() < 1e-6,
                    "{}: size {k} is {got} mm, documented {want} mm",
                    s.name
                );
            }
        }
    }
}

/// Points with first derivatives only (`FaceSurface::first_derivs`, `point_normal`, the
/// layout's `Patch::first_derivs`) are the numbers the full evaluation gives, bit for bit,
/// on grid faces (T-splines) and subdivision trees (Catmull–Clark cages, extraordinary
/// points) alike.
#[test]
fn first_derivatives_alone_equal_the_full_evaluation_bit_for_bit() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut trees = 0;
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        for f in m.surface.faces() {
            trees += matches!(f.form, tspath::surface::FaceForm::Tree(_)) as usize;
            // Corners, sides and random points.
            let uvs = [(0.0, 0.0), (1.0, 1.0), (0.5, 1.0)]
                .into_iter()
                .chain((0..40).map(|_| (next(), next())));
            for (u, v) in uvs {
                let d = f.derivs(u, v);
                let (p, su, sv) = f.first_derivs(u, v);
                assert_eq!(
                    (p, su, sv),
                    (d.point, d.su, d.sv),
                    "{} at ({u}, {v})",
                    s.name
                );
                let (q, n) = f.point_normal(u, v);
                assert_eq!(q, d.point);
                let want = DiffGeom::try_from_derivs(&d)
                    .map(|g| g.normal)
                    .or_else(|| f.normal(u, v));
                assert_eq!(n, want, "{} at ({u}, {v})", s.name);
            }
        }
        for p in &m.layout.patches {
            for _ in 0..40 {
                let (u, v) = (next(), next());
                let d = p.derivs(&m.surface, u, v);
                assert_eq!(
                    p.first_derivs(&m.surface, u, v),
                    (d.point, d.su, d.sv),
                    "{}",
                    s.name
                );
            }
        }
    }
    assert!(trees > 0, "no subdivision face among the samples");
}

/// Parameters a line test visits: `ts`, the Bézier cells' `breaks` and just below each,
/// forwards and back (a line keeps one cell's contraction while it stays there).
fn along_a_line(ts: &[f64], breaks: &[f64]) -> Vec<f64> {
    let mut xs: Vec<f64> = ts.iter().chain(breaks).copied().collect();
    xs.extend(breaks.iter().map(|b| (b - 1e-9).max(0.0)));
    let back: Vec<f64> = xs.iter().rev().copied().collect();
    xs.extend(back);
    xs
}

#[test]
fn grid_and_line_evaluation_equal_point_by_point_bit_for_bit() {
    // Model::smallest_concave_radius and tool_side evaluate whole grids per face at once
    // (issue 20: the summary of a 10 000-face cage); the numbers must be derivs' own, on
    // T-spline cells, subdivision leaves (measured from an origin) and deeper trees.
    let ts = [0.0, 1e-3, 0.2, 0.5, 0.77, 0.999, 1.0];
    let (mut single, mut lines, mut multi_cell) = (0, 0, 0);
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        for f in m.surface.faces() {
            single += matches!(
                f.form,
                tspath::surface::FaceForm::Tree(tspath::surface::subdiv::Node::Leaf { .. })
            ) as usize;
            let mut seen = 0;
            f.for_each_derivs(&ts, &ts, &mut |u, v, d| {
                assert_eq!(*d, f.derivs(u, v), "{} at ({u}, {v})", s.name);
                assert_eq!((u, v), (ts[seen / ts.len()], ts[seen % ts.len()]));
                seen += 1;
            });
            assert_eq!(seen, ts.len() * ts.len());
            // Lines u = const (the simulation's columns, the planner's passes), point and first
            // derivatives: through every Bézier cell and across its breaks, forwards and back
            // (the line keeps one cell's rows).
            let (ub, vb) = f.breaks();
            let vs = along_a_line(&ts, vb);
            for &u in ts.iter().chain(ub) {
                let mut line = f.u_line(u);
                for &v in &vs {
                    lines += 1;
                    multi_cell += (ub.len() > 2 || vb.len() > 2) as usize;
                    assert_eq!(line.derivs(v), f.derivs(u, v), "{} at ({u}, {v})", s.name);
                    assert_eq!(line.first_derivs(v), f.first_derivs(u, v), "{}", s.name);
                }
            }
        }
    }
    assert!(single > 100, "{single} one-leaf faces checked");
    assert!(
        multi_cell > 1000,
        "{multi_cell} points on faces of several cells"
    );
    assert!(lines > 10_000, "{lines} points along lines");
}

/// Largest difference between two sets of derivatives, each order's relative to `scale`
/// plus the second's largest of that order (near an extraordinary point a second derivative
/// can be the small difference of large terms: rounding is measured against the terms).
fn derivs_gap(
    a: &tspath::surface::SurfaceDerivs,
    b: &tspath::surface::SurfaceDerivs,
    scale: f64,
) -> f64 {
    let first = scale + b.su.norm().max(b.sv.norm());
    let second = scale + b.suu.norm().max(b.suv.norm()).max(b.svv.norm());
    ((a.point - b.point).norm() / (scale + b.point.coords.norm()))
        .max((a.su - b.su).norm() / first)
        .max((a.sv - b.sv).norm() / first)
        .max((a.suu - b.suu).norm() / second)
        .max((a.suv - b.suv).norm() / second)
        .max((a.svv - b.svv).norm() / second)
}

#[test]
fn lines_v_const_equal_point_evaluation_to_rounding() {
    // The planner's passes along u read faces by lines v = const (columns contracted once
    // per cell); the sums run in the other order than point by point, so the numbers agree
    // to rounding, not bit for bit: at most 1e-12 of the model size plus the largest value
    // of the same order.
    use tspath::surface::Held;
    let ts = [0.0, 1e-3, 0.2, 0.5, 0.77, 0.999, 1.0];
    let (mut points, mut worst) = (0usize, 0.0f64);
    for s in SAMPLES {
        let m = samples::load_sample(s.name).unwrap();
        let size = m.surface.bbox().diagonal();
        for f in m.surface.faces() {
            let (ub, vb) = f.breaks();
            let us = along_a_line(&ts, ub);
            for &v in ts.iter().chain(vb) {
                let mut line = f.line(Held::V, v);
                assert_eq!(line.held_at(), (Held::V, v));
                for &u in &us {
                    points += 1;
                    let d = f.derivs(u, v);
                    worst = worst.max(derivs_gap(&line.derivs(u), &d, size));
                    let (p, su, sv) = line.first_derivs(u);
                    let first = tspath::surface::SurfaceDerivs {
                        point: p,
                        su,
                        sv,
                        ..d
                    };
                    worst = worst.max(derivs_gap(&first, &d, size));
                }
            }
        }
    }
    println!("{points} points on lines v = const: worst relative gap {worst:.1e}");
    assert!(points > 10_000, "{points}");
    assert!(worst < 1e-12, "{worst:e}");
}
