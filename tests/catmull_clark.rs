//! Catmull–Clark evaluation against plain subdivision written independently here: every
//! face of the cage is subdivided a few times with the textbook rules (sharp boundaries,
//! corners kept), the limit positions of the fine vertices are taken with the textbook limit
//! masks, and compared with the library's evaluation at the same dyadic parameters.

use std::collections::HashMap;
use tspath::model::samples;
use tspath::tmesh::TMesh;

type P = [f64; 3];

fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: P, s: f64) -> P {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dist(a: P, b: P) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A quad mesh whose quads remember which cage face they came from and where in it.
#[derive(Clone)]
struct Mesh {
    pts: Vec<P>,
    quads: Vec<[usize; 4]>,
    /// (cage face, u0, v0, size): corner 0 of the quad sits at (u0, v0) of the cage face,
    /// corner 1 at (u0 + size, v0), corner 3 at (u0, v0 + size).
    origin: Vec<(usize, f64, f64, f64)>,
}

fn edge_faces(m: &Mesh) -> HashMap<(usize, usize), Vec<usize>> {
    let mut e: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (qi, q) in m.quads.iter().enumerate() {
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            e.entry((a.min(b), a.max(b))).or_default().push(qi);
        }
    }
    e
}

fn subdivide(m: &Mesh) -> Mesh {
    let ef = edge_faces(m);
    let n = m.pts.len();
    let fp: Vec<P> = m
        .quads
        .iter()
        .map(|q| mul(q.iter().fold([0.0; 3], |s, &i| add(s, m.pts[i])), 0.25))
        .collect();
    let mut vfaces = vec![Vec::new(); n];
    let mut vedges = vec![Vec::new(); n];
    for (qi, q) in m.quads.iter().enumerate() {
        for &v in q {
            vfaces[v].push(qi);
        }
    }
    for &(a, b) in ef.keys() {
        vedges[a].push((a, b));
        vedges[b].push((a, b));
    }
    let mut pts = Vec::new();
    for v in 0..n {
        let p = m.pts[v];
        let bnd: Vec<usize> = vedges[v]
            .iter()
            .filter(|e| ef[*e].len() == 1)
            .map(|&(a, b)| if a == v { b } else { a })
            .collect();
        let new = if !bnd.is_empty() {
            if vfaces[v].len() == 1 {
                p
            } else {
                mul(
                    add(add(m.pts[bnd[0]], m.pts[bnd[1]]), mul(p, 6.0)),
                    1.0 / 8.0,
                )
            }
        } else {
            let k = vfaces[v].len() as f64;
            let q = mul(
                vfaces[v].iter().fold([0.0; 3], |s, &f| add(s, fp[f])),
                1.0 / k,
            );
            let r = mul(
                vedges[v].iter().fold([0.0; 3], |s, &(a, b)| {
                    add(s, mul(add(m.pts[a], m.pts[b]), 0.5))
                }),
                1.0 / k,
            );
            mul(add(add(q, mul(r, 2.0)), mul(p, k - 3.0)), 1.0 / k)
        };
        pts.push(new);
    }
    let mut eid = HashMap::new();
    for (&(a, b), fs) in &ef {
        let mid = mul(add(m.pts[a], m.pts[b]), 0.5);
        let e = if fs.len() == 2 {
            mul(add(add(mid, mid), add(fp[fs[0]], fp[fs[1]])), 0.25)
        } else {
            mid
        };
        eid.insert((a, b), pts.len());
        pts.push(e);
    }
    let f0 = pts.len();
    pts.extend(fp.iter().copied());
    let e = |a: usize, b: usize| eid[&(a.min(b), a.max(b))];
    let mut quads = Vec::new();
    let mut origin = Vec::new();
    for (qi, q) in m.quads.iter().enumerate() {
        let (f, u0, v0, s) = m.origin[qi];
        let h = s / 2.0;
        let c = f0 + qi;
        quads.push([q[0], e(q[0], q[1]), c, e(q[3], q[0])]);
        origin.push((f, u0, v0, h));
        quads.push([e(q[0], q[1]), q[1], e(q[1], q[2]), c]);
        origin.push((f, u0 + h, v0, h));
        quads.push([c, e(q[1], q[2]), q[2], e(q[2], q[3])]);
        origin.push((f, u0 + h, v0 + h, h));
        quads.push([e(q[3], q[0]), c, e(q[2], q[3]), q[3]]);
        origin.push((f, u0, v0 + h, h));
    }
    Mesh { pts, quads, origin }
}

/// Limit position of vertex `v` by the textbook masks.
fn limit(m: &Mesh, ef: &HashMap<(usize, usize), Vec<usize>>, vquads: &[Vec<usize>], v: usize) -> P {
    let mut nbr = Vec::new();
    let mut diag = Vec::new();
    let mut faces = 0;
    for q in vquads[v].iter().map(|&qi| &m.quads[qi]) {
        if let Some(k) = q.iter().position(|&x| x == v) {
            faces += 1;
            nbr.push(q[(k + 1) % 4]);
            nbr.push(q[(k + 3) % 4]);
            diag.push(q[(k + 2) % 4]);
        }
    }
    nbr.sort_unstable();
    nbr.dedup();
    let bnd: Vec<usize> = nbr
        .iter()
        .copied()
        .filter(|&w| ef[&(v.min(w), v.max(w))].len() == 1)
        .collect();
    let p = m.pts[v];
    if !bnd.is_empty() {
        if faces == 1 {
            return p;
        }
        return mul(
            add(add(m.pts[bnd[0]], m.pts[bnd[1]]), mul(p, 4.0)),
            1.0 / 6.0,
        );
    }
    let n = faces as f64;
    let e = nbr.iter().fold([0.0; 3], |s, &w| add(s, m.pts[w]));
    let d = diag.iter().fold([0.0; 3], |s, &w| add(s, m.pts[w]));
    mul(
        add(add(mul(p, n * n), mul(e, 4.0)), d),
        1.0 / (n * (n + 5.0)),
    )
}

fn cage(mesh: &TMesh) -> Mesh {
    let pts = mesh
        .points()
        .iter()
        .map(|c| [c.point.x, c.point.y, c.point.z])
        .collect();
    let loops = mesh.face_loops();
    let quads = loops
        .iter()
        .map(|f| [0, 1, 2, 3].map(|k| f.vertices[k] as usize))
        .collect();
    let origin = (0..loops.len()).map(|f| (f, 0.0, 0.0, 1.0)).collect();
    Mesh { pts, quads, origin }
}

/// Worst distance between the library's limit surface and the subdivided cage's limit
/// points after `levels` rounds, relative to the model size.
fn worst_relative_error(model: &tspath::Model, levels: usize) -> f64 {
    let mut m = cage(&model.mesh);
    for _ in 0..levels {
        m = subdivide(&m);
    }
    let size = model.surface.bbox().diagonal();
    let face_index: HashMap<u32, usize> = model
        .surface
        .faces()
        .iter()
        .enumerate()
        .map(|(i, f)| (f.mesh_face, i))
        .collect();
    let ef = edge_faces(&m);
    let mut vquads = vec![Vec::new(); m.pts.len()];
    for (qi, q) in m.quads.iter().enumerate() {
        for &v in q {
            vquads[v].push(qi);
        }
    }
    let mut worst: f64 = 0.0;
    let mut seen = vec![false; m.pts.len()];
    for (qi, q) in m.quads.iter().enumerate() {
        let v = q[0];
        if seen[v] {
            continue;
        }
        seen[v] = true;
        let (f, u0, v0, _) = m.origin[qi];
        let p = model.surface.subs(face_index[&(f as u32)], u0, v0);
        worst = worst.max(dist([p.x, p.y, p.z], limit(&m, &ef, &vquads, v)) / size);
    }
    worst
}

fn obj_model(text: &str) -> tspath::Model {
    tspath::io::load(text.as_bytes(), "test").unwrap()
}

/// A cage with an interior vertex of valence 5 and a boundary of alternating edge vertices
/// and corners.
fn valence5_obj() -> String {
    let mut s = String::from("v 0 0 0.4\n");
    for k in 0..5 {
        let a = k as f64 * std::f64::consts::TAU / 5.0;
        let b = a + std::f64::consts::TAU / 10.0;
        s += &format!("v {} {} {}\n", a.cos(), a.sin(), 0.1 * (k as f64));
        s += &format!(
            "v {} {} {}\n",
            1.8 * b.cos(),
            1.8 * b.sin(),
            -0.2 + 0.05 * k as f64
        );
    }
    for k in 0..5 {
        let s0 = 2 + 2 * k;
        let b = 3 + 2 * k;
        let s1 = 2 + 2 * ((k + 1) % 5);
        s += &format!("f 1 {s0} {b} {s1}\n");
    }
    s
}

const CUBE_OBJ: &str =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

#[test]
fn cube_matches_plain_subdivision() {
    let m = obj_model(CUBE_OBJ);
    assert_eq!(m.summary().extraordinary_points, 8);
    let e = worst_relative_error(&m, 5);
    println!("cube: worst relative error {e:.2e}");
    assert!(e < 1e-12, "{e}");
}

#[test]
fn valence_five_matches_plain_subdivision() {
    let m = obj_model(&valence5_obj());
    assert_eq!(m.summary().extraordinary_points, 1);
    let e = worst_relative_error(&m, 5);
    println!("valence 5: worst relative error {e:.2e}");
    assert!(e < 1e-12, "{e}");
}

#[test]
fn samples_match_plain_subdivision() {
    for name in [
        "keycap-convex",
        "keycap-concave",
        "head",
        "plate-hole",
        "bumps-hole",
    ] {
        let m = samples::load_sample(name).unwrap();
        let e = worst_relative_error(&m, 3);
        println!("{name}: worst relative error {e:.2e}");
        assert!(e < 1e-12, "{name}: {e}");
    }
}

#[test]
fn non_quad_cage_is_subdivided_once_to_the_same_limit() {
    // A triangular prism: two triangles and three quads. Reading it applies one
    // Catmull–Clark step (3 quads per triangle, 4 per quad), after which the cage must
    // again agree with plain subdivision.
    let obj = "v 0 0 0\nv 2 0 0\nv 1 1.7 0\nv 0 0 2\nv 2 0 2\nv 1 1.7 2\nf 1 3 2\nf 4 5 6\nf 1 2 5 4\nf 2 3 6 5\nf 3 1 4 6\n";
    let m = obj_model(obj);
    assert_eq!(m.mesh.faces().len(), 3 * 2 + 4 * 3);
    let e = worst_relative_error(&m, 4);
    assert!(e < 1e-12, "{e}");
    // The limit of the corner-free closed prism lies strictly inside its hull.
    let b = m.surface.bbox();
    assert!(b.min[0] > 0.0 && b.max[0] < 2.0 && b.min[2] > 0.0 && b.max[2] < 2.0);
}
