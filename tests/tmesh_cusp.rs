//! Zero-area faces with an empty side (a cusp): how a stack of repeated knot lines ends in a
//! fan at one vertex. Checked on a small mesh whose local knot vectors are worked out by hand.
//!
//! Layout in (s, t), with B1' a second control point at B1's parameters (zero interval):
//!
//! ```text
//!  C0 ---- C1 ---- C2        t = 2
//!  |        |\      |
//!  |  NW    | \ NE  |        the line s = 1 is doubled between B1 and B1' and fans into
//!  B0 ---- B1-B1' - B2       t = 1   C1 above and A1 below (two zero-area triangles)
//!  D0  SW   | /  SE |        D0: a boundary T-junction at t = 0.5 whose ray crosses a triangle
//!  A0 ---- A1 ---- A2        t = 0
//! ```

use std::collections::HashMap;
use tspath::geom::{Point3, Vector3};
use tspath::surface::basis::{bspline, LocalKnots};
use tspath::tmesh::walk::FaceBlend;
use tspath::tmesh::{ControlPoint, FaceLoop, Scheme, TMesh};

const A0: u32 = 0;
const A1: u32 = 1;
const A2: u32 = 2;
const D0: u32 = 3;
const B0: u32 = 4;
const B1: u32 = 5;
const B1P: u32 = 6;
const B2: u32 = 7;
const C0: u32 = 8;
const C1: u32 = 9;
const C2: u32 = 10;

fn points() -> Vec<ControlPoint> {
    let p = |x: f64, y: f64, z: f64| ControlPoint {
        point: Point3::new(x, y, z),
        weight: 1.0,
    };
    vec![
        p(0.0, 0.0, 0.0),
        p(10.0, 0.0, 1.0),
        p(20.0, 0.0, 0.0),
        p(0.0, 5.0, 0.5),
        p(0.0, 10.0, 0.0),
        p(10.0, 10.0, 4.0),
        p(12.0, 10.0, 3.0),
        p(20.0, 10.0, 0.0),
        p(0.0, 20.0, 0.0),
        p(10.0, 20.0, 1.0),
        p(20.0, 20.0, 0.0),
    ]
}

fn faces(top_corners: [u32; 4]) -> Vec<FaceLoop> {
    vec![
        FaceLoop {
            vertices: vec![A0, A1, B1, B0, D0],
            corners: [0, 1, 2, 3],
        },
        FaceLoop::quad(A1, A2, B2, B1P),
        FaceLoop::quad(B0, B1, C1, C0),
        FaceLoop::quad(B1P, B2, C2, C1),
        // Bottom fan: B1 -> A1 (side 0), empty side 1 at A1, A1 -> B1' (side 2), B1' -> B1.
        FaceLoop {
            vertices: vec![B1, A1, B1P],
            corners: [0, 1, 1, 2],
        },
        FaceLoop {
            vertices: vec![B1P, C1, B1],
            corners: top_corners,
        },
    ]
}

fn knots() -> HashMap<(u32, u32), f64> {
    let mut k = HashMap::new();
    k.insert((A0, D0), 0.5);
    k.insert((D0, B0), 0.5);
    k.insert((B1, B1P), 0.0);
    k
}

fn mesh() -> TMesh {
    TMesh::try_new(
        points(),
        &faces([0, 1, 1, 2]),
        &knots(),
        1.0,
        Scheme::TSpline,
    )
    .unwrap()
}

/// True if `got` equals `want` read in either direction.
fn same_vector(got: &LocalKnots, want: &LocalKnots) -> bool {
    let close = |a: &LocalKnots, b: &LocalKnots| (0..5).all(|i| (a[i] - b[i]).abs() < 1e-12);
    let mirrored = [-got[4], -got[3], -got[2], -got[1], -got[0]];
    close(got, want) || close(&mirrored, want)
}

/// The local knot vectors of `v` are `a` and `b` in some order and orientation.
fn assert_knots(mesh: &TMesh, v: u32, a: LocalKnots, b: LocalKnots) {
    let flags = vec![false; mesh.vertex_count()];
    let (s, t) = mesh.local_knots(v, &flags);
    let ok = (same_vector(&s, &a) && same_vector(&t, &b))
        || (same_vector(&s, &b) && same_vector(&t, &a));
    assert!(ok, "vertex {v}: got {s:?} {t:?}, want {a:?} {b:?}");
}

#[test]
fn cusp_faces_are_accepted_and_occupy_no_angle() {
    let m = mesh();
    assert_eq!(m.faces().len(), 6);
    assert!(!m.faces()[4].is_domain() && !m.faces()[5].is_domain());
    // The half-edge of the bottom triangle leaving A1 leaves a cusp.
    let hs = m.face_half_edges(4);
    let at_a1 = hs.iter().copied().find(|&h| m.he(h).origin == A1).unwrap();
    assert_eq!(m.sector_quarters(at_a1), 0);
    assert_eq!(m.he(at_a1).side, 2, "side 1 is empty");
    // Angles still add up: B1 and B1' are interior, A1 and C1 straight boundary points.
    assert_eq!(m.angle_quarters(B1) + m.angle_quarters(B1P), 4 + 4);
    assert_eq!(m.angle_quarters(A1), 2);
    assert_eq!(m.angle_quarters(C1), 2);
    assert!((0..m.vertex_count() as u32).all(|v| !m.is_extraordinary(v)));
    assert_eq!(m.t_junctions(), vec![D0]);
    // Writing the loops back gives the same corners (the empty side keeps its place).
    let loops = m.face_loops();
    assert_eq!(loops[4].corners, [0, 1, 1, 2]);
    assert_eq!(loops[0].corners, [0, 1, 2, 3]);
}

#[test]
fn rays_walk_through_the_fan_as_a_repeated_knot() {
    let m = mesh();
    // D0's ray to +s crosses SW (1), the zero-width triangle (0), SE (1): the double line at
    // s = 1 is a double knot.
    assert_knots(
        &m,
        D0,
        [0.0, 0.0, 0.0, 1.0, 1.0],
        [-0.5, -0.5, 0.0, 0.5, 1.5],
    );
    assert_knots_along_the_block(&m);
}

/// B1 and B1' see each other as a double knot; from the cusp at A1 the ray up runs along
/// either fan edge, then on through B1 or B1'. Rays along the block and the fan lines, the
/// same whether or not the second line is a fan line.
fn assert_knots_along_the_block(m: &TMesh) {
    assert_knots(
        m,
        B1P,
        [-1.0, 0.0, 0.0, 1.0, 1.0],
        [-1.0, -1.0, 0.0, 1.0, 1.0],
    );
    assert_knots(
        m,
        B1,
        [-1.0, -1.0, 0.0, 0.0, 1.0],
        [-1.0, -1.0, 0.0, 1.0, 1.0],
    );
    assert_knots(
        m,
        A1,
        [-1.0, -1.0, 0.0, 1.0, 1.0],
        [0.0, 0.0, 0.0, 1.0, 2.0],
    );
}

/// The rational sum of the blending functions covering `face` at its local `(u, v)` (knot
/// units), straight from the walk's knot vectors.
fn eval(m: &TMesh, blends: &[Vec<FaceBlend>], face: usize, u: f64, v: f64) -> Point3 {
    let mut num = Vector3::zeros();
    let mut den = 0.0;
    for b in &blends[face] {
        let p = m.points()[b.vertex as usize];
        let n = bspline(&b.u_knots, u) * bspline(&b.v_knots, v) * p.weight;
        num += p.point.coords * n;
        den += n;
    }
    Point3::from(num / den)
}

#[test]
fn surface_is_continuous_across_the_fan() {
    // This mesh has plain (not Bézier) boundaries, so it is evaluated away from them by the
    // blending functions themselves. With or without the second line as a fan line.
    for m in [mesh(), fan_mesh()] {
        let flags = vec![false; m.vertex_count()];
        let blends = m.face_blends(&flags, &flags);
        for k in 1..10 {
            let v = 0.2 + 0.6 * k as f64 / 10.0;
            // SW (u = s, v = t) meets SE (u = s - 1, v = t) along s = 1.
            let a = eval(&m, &blends, 0, 1.0, v);
            let b = eval(&m, &blends, 1, 0.0, v);
            assert!((a - b).norm() < 1e-12, "t = {v}: {a} vs {b}");
            // NW meets NE along s = 1, t = 1 + v.
            let c = eval(&m, &blends, 2, 1.0, v);
            let d = eval(&m, &blends, 3, 0.0, v);
            assert!((c - d).norm() < 1e-12, "t = {}: {c} vs {d}", 1.0 + v);
        }
    }
}

#[test]
fn malformed_empty_sides_are_rejected() {
    // An empty side 0 is not allowed (side 0 starts the face's frame).
    let mut bad = faces([0, 1, 1, 2]);
    bad[5].corners = [0, 0, 1, 2];
    let e = TMesh::try_new(points(), &bad, &knots(), 1.0, Scheme::TSpline).unwrap_err();
    assert!(e.to_string().contains("face 5"), "{e}");
    // Two empty sides are not a face.
    let mut bad = faces([0, 1, 1, 2]);
    bad[1] = FaceLoop {
        vertices: vec![A1, A2, B2, B1P],
        corners: [0, 1, 1, 1],
    };
    let e = TMesh::try_new(points(), &bad, &knots(), 1.0, Scheme::TSpline).unwrap_err();
    assert!(e.to_string().contains("face 1"), "{e}");
    // An empty side opposite a side of positive length fails the knot-sum check.
    let mut k = knots();
    k.insert((B1, B1P), 0.25);
    let e = TMesh::try_new(points(), &faces([0, 1, 1, 2]), &k, 1.0, Scheme::TSpline).unwrap_err();
    assert!(e.to_string().contains("opposite sides disagree"), "{e}");
}

/// The same mesh with the second line (B1' to A1 and to C1) marked as a fan line: the double
/// knot at s = 1 belongs to the block B1 B1' only.
fn fan_mesh() -> TMesh {
    TMesh::try_new_with_fan_lines(
        points(),
        &faces([0, 1, 1, 2]),
        &knots(),
        1.0,
        Scheme::TSpline,
        &[(A1, B1P), (C1, B1P)],
    )
    .unwrap()
}

#[test]
fn rays_cross_a_fan_line_unseen_but_still_run_along_it() {
    let m = fan_mesh();
    // D0's ray to +s crosses SW (1), then the fan line unseen, then SE (1): single knots.
    assert_knots(
        &m,
        D0,
        [0.0, 0.0, 0.0, 1.0, 2.0],
        [-0.5, -0.5, 0.0, 0.5, 1.5],
    );
    // Rays along the block and along the fan lines are as before.
    assert_knots_along_the_block(&m);
}

#[test]
fn a_fan_line_must_be_an_inner_edge() {
    for bad in [(A0, C2), (A0, A1)] {
        let e = TMesh::try_new_with_fan_lines(
            points(),
            &faces([0, 1, 1, 2]),
            &knots(),
            1.0,
            Scheme::TSpline,
            &[bad],
        )
        .unwrap_err();
        assert!(e.to_string().contains("fan line"), "{bad:?}: {e}");
    }
}
