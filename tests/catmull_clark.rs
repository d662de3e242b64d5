//! Catmull–Clark evaluation against plain subdivision written independently here: every
//! face of the cage is subdivided a few times with the textbook rules (sharp boundaries,
//! corners kept; creases of integer sharpness `s` sharp for `s` steps, infinitely sharp ones
//! always, after DeRose, Kass & Truong 1998), the limit positions of the fine vertices are
//! taken with the textbook limit masks, and compared with the library's evaluation at the
//! same dyadic parameters.

use crate::support;

use std::collections::HashMap;
use support::{bumpy_sheet, crease_tag};
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
    /// Sharpness of creased edges `(min, max)` (infinite: always sharp), and of corners.
    sharp: HashMap<(usize, usize), f64>,
    corner: HashMap<usize, f64>,
    /// Boundary vertices with one face stay put (edge-and-corner interpolation).
    corners_interpolated: bool,
}

impl Mesh {
    /// Sharpness of edge `e` (boundary edges infinitely sharp).
    fn edge_sharpness(&self, ef: &HashMap<(usize, usize), Vec<usize>>, e: (usize, usize)) -> f64 {
        if ef[&e].len() == 1 {
            f64::INFINITY
        } else {
            self.sharp.get(&e).copied().unwrap_or(0.0)
        }
    }

    /// Sharpness of vertex `v`: tagged, or infinite at a boundary vertex with one face.
    fn vertex_sharpness(&self, v: usize, faces: usize, boundary: bool) -> f64 {
        if boundary && faces == 1 && self.corners_interpolated {
            f64::INFINITY
        } else {
            self.corner.get(&v).copied().unwrap_or(0.0)
        }
    }
}

/// One less, for the next step.
fn decay(s: f64) -> f64 {
    s - 1.0
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
        let boundary = vedges[v].iter().any(|e| ef[e].len() == 1);
        // Edges sharp in this step: sharpness at least 1.
        let sharp: Vec<usize> = vedges[v]
            .iter()
            .filter(|e| m.edge_sharpness(&ef, **e) >= 1.0)
            .map(|&(a, b)| if a == v { b } else { a })
            .collect();
        let new = if m.vertex_sharpness(v, vfaces[v].len(), boundary) >= 1.0 || sharp.len() > 2 {
            p
        } else if sharp.len() == 2 {
            mul(
                add(add(m.pts[sharp[0]], m.pts[sharp[1]]), mul(p, 6.0)),
                1.0 / 8.0,
            )
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
        let e = if fs.len() == 2 && m.edge_sharpness(&ef, (a, b)) < 1.0 {
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
    let mut sharp = HashMap::new();
    for (&(a, b), &s) in &m.sharp {
        if decay(s) > 0.0 {
            let mid = e(a, b);
            sharp.insert((a.min(mid), a.max(mid)), decay(s));
            sharp.insert((b.min(mid), b.max(mid)), decay(s));
        }
    }
    let corner = m
        .corner
        .iter()
        .filter(|(_, &s)| decay(s) > 0.0)
        .map(|(&v, &s)| (v, decay(s)))
        .collect();
    Mesh {
        pts,
        quads,
        origin,
        sharp,
        corner,
        corners_interpolated: m.corners_interpolated,
    }
}

/// Limit position of vertex `v` by the textbook masks; `None` at a dart (one sharp edge),
/// whose limit has no such mask (the smooth one assumes smooth edges).
fn limit(
    m: &Mesh,
    ef: &HashMap<(usize, usize), Vec<usize>>,
    vquads: &[Vec<usize>],
    v: usize,
) -> Option<P> {
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
    // Once every finite sharpness has run out, only infinitely sharp edges are left.
    let sharp: Vec<usize> = nbr
        .iter()
        .copied()
        .filter(|&w| m.edge_sharpness(ef, (v.min(w), v.max(w))) > 0.0)
        .collect();
    let p = m.pts[v];
    let boundary = nbr.iter().any(|&w| ef[&(v.min(w), v.max(w))].len() == 1);
    if m.vertex_sharpness(v, faces, boundary) > 0.0 || sharp.len() > 2 {
        return Some(p);
    }
    if sharp.len() == 2 {
        return Some(mul(
            add(add(m.pts[sharp[0]], m.pts[sharp[1]]), mul(p, 4.0)),
            1.0 / 6.0,
        ));
    }
    if sharp.len() == 1 {
        return None;
    }
    let n = faces as f64;
    let e = nbr.iter().fold([0.0; 3], |s, &w| add(s, m.pts[w]));
    let d = diag.iter().fold([0.0; 3], |s, &w| add(s, m.pts[w]));
    Some(mul(
        add(add(mul(p, n * n), mul(e, 4.0)), d),
        1.0 / (n * (n + 5.0)),
    ))
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
    let tags = mesh.tags();
    Mesh {
        pts,
        quads,
        origin,
        sharp: tags
            .creases
            .iter()
            .map(|(&(a, b), &s)| ((a as usize, b as usize), s))
            .collect(),
        corner: tags
            .corners
            .iter()
            .map(|(&v, &s)| (v as usize, s))
            .collect(),
        corners_interpolated: tags.boundary == tspath::tmesh::BoundaryInterpolation::EdgeAndCorner,
    }
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
        let (f, u0, v0, _) = m.origin[qi];
        // (A hole's quads have no surface; their corners are checked from other faces.)
        let Some(&face) = face_index.get(&(f as u32)) else {
            continue;
        };
        if seen[v] {
            continue;
        }
        seen[v] = true;
        let p = model.surface.subs(face, u0, v0);
        if let Some(l) = limit(&m, &ef, &vquads, v) {
            worst = worst.max(dist([p.x, p.y, p.z], l) / size);
        }
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

#[test]
fn creased_cube_matches_plain_subdivision() {
    // Issue 20: the top face's loop infinitely sharp (vertices of valence 3 with two sharp
    // edges follow the crease rule), one vertical edge sharp for 2 steps (making two top
    // corners corners for 2 steps), a bottom corner tagged with sharpness 3.
    let obj = format!(
        "{CUBE_OBJ}{}t crease 2/1/0 1 5 2\nt corner 1/1/0 3 3\n",
        crease_tag(&[4, 5, 6, 7, 4], 10.0)
    );
    let m = obj_model(&obj);
    assert_eq!(m.mesh.tags().creases.len(), 5);
    let e = worst_relative_error(&m, 5);
    println!("creased cube: worst relative error {e:.2e}");
    assert!(e < 1e-12, "{e}");
}

#[test]
fn semi_sharp_creases_and_darts_match_plain_subdivision() {
    // Issue 20: "semi-sharp sharpness s behaves as s sharp subdivision steps then smooth
    // ones". On a 6 × 6 sheet: a chain of sharpness 3 across, one of sharpness 1 crossing it,
    // an infinitely sharp one ending inside (a dart at vertex 24), and a corner of sharpness 2.
    let n = 6;
    let v = |i: usize, j: usize| j * (n + 1) + i;
    let chain =
        |pts: &[(usize, usize)]| pts.iter().map(|&(i, j)| v(i, j) as u32).collect::<Vec<_>>();
    let across: Vec<(usize, usize)> = (0..=n).map(|i| (i, 2)).collect();
    let crossing: Vec<(usize, usize)> = (0..=n).map(|j| (4, j)).collect();
    let dart = [(1, 5), (2, 5), (3, 5), (3, 4)];
    let obj = format!(
        "{}{}{}{}t corner 1/1/0 {} 2\n",
        bumpy_sheet(n),
        crease_tag(&chain(&across), 3.0),
        crease_tag(&chain(&crossing), 1.0),
        crease_tag(&chain(&dart), 10.0),
        v(1, 1)
    );
    let m = obj_model(&obj);
    let e = worst_relative_error(&m, 5);
    println!("semi-sharp sheet: worst relative error {e:.2e}");
    assert!(e < 1e-12, "{e}");
    // The tags change the surface (the test would pass vacuously otherwise).
    let plain = obj_model(&bumpy_sheet(n));
    // Face 16 (i 4, j 2): its corner is where the two chains cross.
    let probe = |m: &tspath::Model| m.surface.subs(2 * n + 4, 0.0, 0.0);
    assert!((probe(&m) - probe(&plain)).norm() > 1e-3);
}

/// An OpenSubdiv regression shape (`tests/fixtures/opensubdiv`).
fn opensubdiv_shape(name: &str) -> tspath::Model {
    let path = format!(
        "{}/tests/fixtures/opensubdiv/catmark_{name}.obj",
        env!("CARGO_MANIFEST_DIR")
    );
    obj_model(&std::fs::read_to_string(path).unwrap())
}

#[test]
fn opensubdiv_shapes_with_whole_sharpness_match_plain_subdivision() {
    // Issue 20: cages tagged by another tool (OpenSubdiv's regression shapes): creases of
    // sharpness 2, 3 and 10, darts, corners of sharpness 2 and 10, boundaries edge-only and
    // none, triangles. (The others have fractional sharpness: `tests/obj_tags.rs`.)
    for name in [
        "cube_creases0",
        "dart_edgeonly",
        "dart_edgecorner",
        "edgeonly",
        "edgenone",
        "pyramid_creases0",
        "tent_creases0",
    ] {
        let m = opensubdiv_shape(name);
        assert!(!m.mesh.tags().is_plain(), "{name}");
        let e = worst_relative_error(&m, 5);
        println!(
            "{name}: {}; worst relative error {e:.2e}",
            m.mesh.tags().describe()
        );
        assert!(e < 1e-12, "{name}: {e}");
    }
}
