//! Built-in sample models, made by the project's own code and handed out in the project's
//! JSON format. Each sample documents its construction, patch and extraordinary-point
//! counts and its size; tests hold the samples to these numbers.
//!
//! The box-like samples (keycaps, head) are Catmull–Clark cages on the surface of a cube
//! divided into a grid, mapped to the shape, then scaled so that the *limit surface* has the
//! documented size exactly (subdivision is affine-invariant, so scaling the cage scales the
//! surface). The plates are T-splines: clamped grids (a ring of zero knot intervals gives
//! Bézier end conditions) with T-junctions, holes or bumps.

use super::Model;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector4};
use crate::io;
use crate::surface::Surface;
use crate::tmesh::{ControlPoint, FaceLoop, Scheme, TMesh};
use std::collections::HashMap;

/// A named sample and what it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleInfo {
    pub name: &'static str,
    pub description: &'static str,
    /// Rectangular patches of its layout.
    pub patches: usize,
    /// Extraordinary points.
    pub extraordinary_points: usize,
    /// Bounding box edge lengths of the surface (mm).
    pub size_mm: [f64; 3],
}

/// All built-in samples.
pub const SAMPLES: &[SampleInfo] = &[
    SampleInfo {
        name: "dome",
        description: "a piece of a sphere of radius 40 mm: one rational bicubic patch (90° × 90°), apex up, lowest corners at z = 0",
        patches: 1,
        extraordinary_points: 0,
        size_mm: [56.568542494923804, 56.568542494923804, 20.0],
    },
    SampleInfo {
        name: "keycap-convex",
        description: "convex half of a keycap mould (Shang et al. 2020): drafted walls, a dished top and a flat flange (parting surface) at the base, Catmull–Clark, 5 patches, 4 extraordinary points at the top corners",
        patches: 5,
        extraordinary_points: 4,
        size_mm: [14.4, 14.4, 6.8],
    },
    SampleInfo {
        name: "keycap-concave",
        description: "concave half of a keycap mould: a drafted cavity with a domed floor and a flat flange (parting surface) around its rim, normals into the cavity, Catmull–Clark, 5 patches, 4 extraordinary points at the floor corners",
        patches: 5,
        extraordinary_points: 4,
        size_mm: [18.0, 18.0, 8.6],
    },
    SampleInfo {
        name: "head",
        description: "closed egg-shaped surface of cube topology, Catmull–Clark, 6 patches, 8 extraordinary points",
        patches: 6,
        extraordinary_points: 8,
        size_mm: [60.0, 70.0, 80.0],
    },
    SampleInfo {
        name: "tjunction",
        description: "one wavy T-spline patch, 60 × 50 mm, with T-junctions in both directions and Bézier end conditions",
        patches: 1,
        extraordinary_points: 0,
        size_mm: [60.0, 50.0, 0.0],
    },
    SampleInfo {
        name: "plate-hole",
        description: "a gently curved plate, 80 × 60 mm, with a rectangular hole and a notched corner (irregular boundary), Catmull–Clark (sharp boundaries, corners interpolated); its 5 extraordinary points are the hole's corners and the notch's inner corner; 10 patches",
        patches: 10,
        extraordinary_points: 5,
        size_mm: [80.0, 60.0, 0.0],
    },
    SampleInfo {
        name: "bumps",
        description: "synthetic T-spline plate, 80 × 60 mm, with a convex bump (+4 mm) and a concave dimple (−3 mm)",
        patches: 1,
        extraordinary_points: 0,
        size_mm: [80.0, 60.0, 0.0],
    },
    SampleInfo {
        name: "waves",
        description: "synthetic T-spline plate, 80 × 80 mm, with two crests and two troughs (±2.5 mm) and T-junctions",
        patches: 1,
        extraordinary_points: 0,
        size_mm: [80.0, 80.0, 0.0],
    },
    SampleInfo {
        name: "bumps-hole",
        description: "synthetic plate, 80 × 60 mm, with a convex bump, a concave dimple and a square hole between them, Catmull–Clark; its 4 extraordinary points are the hole's corners; 8 patches around the hole",
        patches: 8,
        extraordinary_points: 4,
        size_mm: [80.0, 60.0, 0.0],
    },
];

/// Radius of the `dome` sample's sphere (mm).
pub const DOME_RADIUS_MM: f64 = 40.0;

/// Grid divisions per cube edge of the box-like cages.
const CUBE_DIVISIONS: usize = 4;

/// The T-mesh of a sample.
pub fn sample_mesh(name: &str) -> Result<TMesh> {
    match name {
        "dome" => dome(DOME_RADIUS_MM),
        "keycap-convex" => keycap_convex(),
        "keycap-concave" => keycap_concave(),
        "head" => head(),
        "tjunction" => tjunction(),
        "plate-hole" => plate_hole(),
        "bumps" => bumps(),
        "waves" => waves(),
        "bumps-hole" => bumps_hole(),
        _ => Err(Error::UnknownSample(name.to_string())),
    }
}

/// A sample as a JSON model file (the project's own format).
pub fn sample_json(name: &str) -> Result<String> {
    Ok(io::json::write(&sample_mesh(name)?, name))
}

/// A sample, loaded through the JSON reader exactly as a user's file would be.
pub fn load_sample(name: &str) -> Result<Model> {
    io::load(sample_json(name)?.as_bytes(), name)
}

/// As [`load_sample`], placed by `setup`.
pub fn load_sample_with(name: &str, setup: &super::setup::ImportSetup) -> Result<Model> {
    io::load_with(sample_json(name)?.as_bytes(), name, setup)
}

/// Quadratic rational arc from angle `-a` to `a` on the unit circle: control points and
/// weights.
fn arc(a: f64) -> [([f64; 2], f64); 3] {
    [
        ([a.cos(), -a.sin()], 1.0),
        ([1.0 / a.cos(), 0.0], a.cos()),
        ([a.cos(), a.sin()], 1.0),
    ]
}

/// Degree elevation of a homogeneous quadratic to a cubic.
fn elevate(h: [Vector4; 3]) -> [Vector4; 4] {
    [
        h[0],
        (h[0] + h[1] * 2.0) / 3.0,
        (h[1] * 2.0 + h[2]) / 3.0,
        h[2],
    ]
}

/// Rational bicubic patch exactly on a sphere of radius `r`: longitude and latitude each span
/// 90°, centred on the +Z axis, then lifted so the lowest corners sit at z = 0
/// (sphere centre at `(0, 0, -r/2)`).
pub fn dome(r: f64) -> Result<TMesh> {
    let a = std::f64::consts::FRAC_PI_4;
    let lon = arc(a);
    let lat = arc(a);
    let mut quad = [[Vector4::zeros(); 3]; 3];
    for (j, &([pr, pz], wj)) in lat.iter().enumerate() {
        for (i, &([cx, cy], wi)) in lon.iter().enumerate() {
            // Sphere of revolution about z before orientation: (r·pr·cx, r·pr·cy, r·pz).
            let (x, y, z) = (r * pr * cx, r * pr * cy, r * pz);
            // Rotate about y by -90°: (x, y, z) -> (-z, y, x); then lift by -r/2.
            let p = [-z, y, x - 0.5 * r];
            let w = wi * wj;
            quad[j][i] = Vector4::new(w * p[0], w * p[1], w * p[2], w);
        }
    }
    let rows: Vec<[Vector4; 4]> = quad.iter().map(|row| elevate(*row)).collect();
    let mut points = Vec::with_capacity(16);
    let mut grid = [[Vector4::zeros(); 4]; 4];
    for i in 0..4 {
        let col = elevate([rows[0][i], rows[1][i], rows[2][i]]);
        for (j, h) in col.iter().enumerate() {
            grid[j][i] = *h;
        }
    }
    for row in &grid {
        for h in row {
            points.push(ControlPoint {
                point: Point3::new(h.x / h.w, h.y / h.w, h.z / h.w),
                weight: h.w,
            });
        }
    }
    // One Bézier patch: clamped knots [0,0,0,0,1,1,1,1] give intervals 0, 1, 0.
    TMesh::from_grid(
        points,
        4,
        4,
        &[0.0, 1.0, 0.0],
        &[0.0, 1.0, 0.0],
        Scheme::TSpline,
    )
}

/// Which faces of the cube a cage keeps.
#[derive(Clone, Copy, PartialEq)]
enum Open {
    None,
    Bottom,
    Top,
}

/// Quads on the surface of the cube `[-1,1]³` divided `n` times per edge, outward
/// counter-clockwise (reversed when `inward`), without the face(s) `open` names.
fn cube_cage(n: usize, open: Open, inward: bool) -> (Vec<[f64; 3]>, Vec<FaceLoop>) {
    let mut ids: HashMap<[usize; 3], u32> = HashMap::new();
    let mut pts = Vec::new();
    let mut faces = Vec::new();
    let mut id = |c: [usize; 3], pts: &mut Vec<[f64; 3]>| -> u32 {
        *ids.entry(c).or_insert_with(|| {
            pts.push(c.map(|k| -1.0 + 2.0 * k as f64 / n as f64));
            (pts.len() - 1) as u32
        })
    };
    for axis in 0..3 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, n] {
            if axis == 2
                && ((side == 0 && open == Open::Bottom) || (side == n && open == Open::Top))
            {
                continue;
            }
            for q in 0..n {
                for p in 0..n {
                    let at = |pp: usize, qq: usize| {
                        let mut l = [0; 3];
                        l[axis] = side;
                        l[b] = pp;
                        l[c] = qq;
                        l
                    };
                    let mut quad = [
                        id(at(p, q), &mut pts),
                        id(at(p + 1, q), &mut pts),
                        id(at(p + 1, q + 1), &mut pts),
                        id(at(p, q + 1), &mut pts),
                    ];
                    // Counter-clockwise about +axis on the positive side; reversed on the
                    // negative side and for inward normals.
                    if (side == 0) != inward {
                        quad.reverse();
                    }
                    faces.push(FaceLoop::quad(quad[0], quad[1], quad[2], quad[3]));
                }
            }
        }
    }
    if open != Open::None {
        // A flat flange around the opening (the mould's parting surface), so the walls meet
        // the boundary upright instead of curling under it.
        let directed: std::collections::HashSet<(u32, u32)> = faces
            .iter()
            .flat_map(|f| (0..4).map(move |k| (f.vertices[k], f.vertices[(k + 1) % 4])))
            .collect();
        let mut outer: HashMap<u32, u32> = HashMap::new();
        let mut ring = Vec::new();
        for &(a, b) in &directed {
            if !directed.contains(&(b, a)) {
                ring.push((a, b));
            }
        }
        ring.sort_unstable();
        for (a, b) in ring {
            let mut off = |v: u32, pts: &mut Vec<[f64; 3]>| {
                *outer.entry(v).or_insert_with(|| {
                    let p = pts[v as usize];
                    pts.push([p[0] * FLANGE, p[1] * FLANGE, p[2]]);
                    (pts.len() - 1) as u32
                })
            };
            let (a2, b2) = (off(a, &mut pts), off(b, &mut pts));
            faces.push(FaceLoop::quad(b, a, a2, b2));
        }
    }
    (pts, faces)
}

/// How far the flange reaches beyond the opening, as a factor on the cube's half-width.
const FLANGE: f64 = 1.35;

/// Builds a Catmull–Clark mesh from a cube cage mapped by `shape`, then scales and moves it
/// so its limit surface spans `size` with its lowest point at z = 0, centred on x = y = 0.
fn shaped_cage(
    open: Open,
    inward: bool,
    size: [f64; 3],
    shape: impl Fn([f64; 3]) -> [f64; 3],
) -> Result<TMesh> {
    let (cube, faces) = cube_cage(CUBE_DIVISIONS, open, inward);
    let build = |pts: &[[f64; 3]]| {
        let points = pts
            .iter()
            .map(|p| ControlPoint {
                point: Point3::new(p[0], p[1], p[2]),
                weight: 1.0,
            })
            .collect();
        TMesh::try_new(points, &faces, &HashMap::new(), 1.0, Scheme::CatmullClark)
    };
    let shaped: Vec<[f64; 3]> = cube.iter().map(|&p| shape(p)).collect();
    let bbox = Surface::try_from_tmesh(&build(&shaped)?)?.bbox();
    let fitted: Vec<[f64; 3]> = shaped
        .iter()
        .map(|p| {
            let mut q = [0.0; 3];
            for k in 0..3 {
                let s = size[k] / (bbox.max[k] - bbox.min[k]);
                let base = if k == 2 {
                    bbox.min[k]
                } else {
                    0.5 * (bbox.min[k] + bbox.max[k])
                };
                q[k] = (p[k] - base) * s;
            }
            q
        })
        .collect();
    build(&fitted)
}

fn keycap_convex() -> Result<TMesh> {
    shaped_cage(Open::Bottom, false, [14.4, 14.4, 6.8], |[x, y, z]| {
        let t = 0.5 * (z + 1.0); // 0 at the rim, 1 on top
        let half = 1.0 - 0.2 * t; // drafted walls
        let dish = -0.06 * (1.0 - x * x) * (1.0 - y * y) * t.powi(4); // dished top
        [x * half, y * half, 0.9 * t + dish]
    })
}

fn keycap_concave() -> Result<TMesh> {
    shaped_cage(Open::Top, true, [18.0, 18.0, 8.6], |[x, y, z]| {
        let t = 0.5 * (z + 1.0); // 0 on the floor, 1 at the rim
        let half = 0.8 + 0.2 * t; // drafted walls, open upwards
        let dome = 0.05 * (1.0 - x * x) * (1.0 - y * y) * (1.0 - t).powi(4); // domed floor
        [x * half, y * half, 0.95 * t + dome]
    })
}

fn head() -> Result<TMesh> {
    shaped_cage(Open::None, false, [60.0, 70.0, 80.0], |[x, y, z]| {
        // Towards a sphere, wider at the top like an egg standing on its narrow end.
        let r = (x * x + y * y + z * z).sqrt();
        let (sx, sy, sz) = (x / r, y / r, z / r);
        let taper = 1.0 + 0.12 * sz;
        [sx * taper, sy * taper, sz]
    })
}

/// A clamped grid T-mesh: `nu × nv` control points (index `j * nu + i`) at `pos(i, j)`,
/// unit knot intervals inside and zero ones on the border ring (Bézier end conditions).
/// `drop_vertical` lists faces `(i, j)` whose edge with face `(i-1, j)` is removed, merging
/// the two and leaving T-junctions at the ends of the removed edge; `drop_horizontal` merges
/// faces `(i, j-1)` and `(i, j)` likewise.
fn clamped_plate(
    nu: usize,
    nv: usize,
    pos: impl Fn(usize, usize) -> [f64; 3],
    drop_vertical: &[(usize, usize)],
    drop_horizontal: &[(usize, usize)],
) -> Result<TMesh> {
    let id = |i: usize, j: usize| (j * nu + i) as u32;
    let knot_u = |i: usize| if i == 0 || i == nu - 2 { 0.0 } else { 1.0 };
    let knot_v = |j: usize| if j == 0 || j == nv - 2 { 0.0 } else { 1.0 };
    // Each face as a rectangle of grid cells [i0, i1) × [j0, j1).
    let mut owner: Vec<usize> = (0..(nu - 1) * (nv - 1)).collect();
    let mut rects: Vec<[usize; 4]> = Vec::new();
    for j in 0..nv - 1 {
        for i in 0..nu - 1 {
            rects.push([i, i + 1, j, j + 1]);
        }
    }
    let mut merge = |a: (usize, usize), b: (usize, usize)| {
        let (ra, rb) = (owner[a.1 * (nu - 1) + a.0], owner[b.1 * (nu - 1) + b.0]);
        let (x, y) = (rects[ra], rects[rb]);
        rects[ra] = [
            x[0].min(y[0]),
            x[1].max(y[1]),
            x[2].min(y[2]),
            x[3].max(y[3]),
        ];
        rects[rb] = [0, 0, 0, 0];
        for o in owner.iter_mut() {
            if *o == rb {
                *o = ra;
            }
        }
    };
    for &(i, j) in drop_vertical {
        merge((i - 1, j), (i, j));
    }
    for &(i, j) in drop_horizontal {
        merge((i, j - 1), (i, j));
    }
    let mut faces = Vec::new();
    for r in rects.iter().filter(|r| r[1] > r[0]) {
        let [i0, i1, j0, j1] = *r;
        let mut verts = Vec::new();
        let mut corners = [0u32; 4];
        corners[0] = 0;
        for i in i0..i1 {
            verts.push(id(i, j0));
        }
        corners[1] = verts.len() as u32;
        for j in j0..j1 {
            verts.push(id(i1, j));
        }
        corners[2] = verts.len() as u32;
        for i in (i0 + 1..=i1).rev() {
            verts.push(id(i, j1));
        }
        corners[3] = verts.len() as u32;
        for j in (j0 + 1..=j1).rev() {
            verts.push(id(i0, j));
        }
        faces.push(FaceLoop {
            vertices: verts,
            corners,
        });
    }
    let mut knots = HashMap::new();
    for j in 0..nv {
        for i in 0..nu - 1 {
            knots.insert((id(i, j), id(i + 1, j)), knot_u(i));
        }
    }
    for j in 0..nv - 1 {
        for i in 0..nu {
            knots.insert((id(i, j), id(i, j + 1)), knot_v(j));
        }
    }
    // Keep only vertices some face uses, renumbered in order.
    let mut used = vec![false; nu * nv];
    for f in &faces {
        for &v in &f.vertices {
            used[v as usize] = true;
        }
    }
    let mut renum = vec![u32::MAX; nu * nv];
    let mut points = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let k = j * nu + i;
            if used[k] {
                renum[k] = points.len() as u32;
                let p = pos(i, j);
                points.push(ControlPoint {
                    point: Point3::new(p[0], p[1], p[2]),
                    weight: 1.0,
                });
            }
        }
    }
    for f in faces.iter_mut() {
        for v in f.vertices.iter_mut() {
            *v = renum[*v as usize];
        }
    }
    let knots = knots
        .into_iter()
        .filter(|&((a, b), _)| used[a as usize] && used[b as usize])
        .map(|((a, b), k)| {
            let (x, y) = (renum[a as usize], renum[b as usize]);
            ((x.min(y), x.max(y)), k)
        })
        .collect();
    TMesh::try_new(points, &faces, &knots, 1.0, Scheme::TSpline)
}

/// Grid coordinate of control column `i` of `n` over `[0, len]` for a clamped plate whose
/// border control points sit on the border (Greville-like spacing).
fn plate_coord(i: usize, n: usize, len: f64) -> f64 {
    // Knots 0,0,0,0,1,2,...,m,m,m,m (m = n - 3) with Greville abscissae.
    let m = (n - 3) as f64;
    let t = |k: isize| -> f64 { (k - 3).clamp(0, n as isize - 3) as f64 };
    let g = (t(i as isize + 1) + t(i as isize + 2) + t(i as isize + 3)) / 3.0;
    g / m * len
}

fn tjunction() -> Result<TMesh> {
    let (nu, nv) = (10, 9);
    clamped_plate(
        nu,
        nv,
        |i, j| {
            let x = plate_coord(i, nu, 60.0) - 30.0;
            let y = plate_coord(j, nv, 50.0) - 25.0;
            let z = 3.0 * (x / 12.0).sin() * (y / 15.0).cos() + 0.002 * x * y;
            [x, y, z]
        },
        &[(3, 2), (6, 2), (4, 6)],
        &[(7, 4), (2, 5)],
    )
}

fn plate_hole() -> Result<TMesh> {
    // 13 × 10 cage cells; a 3 × 2 hole and a 3 × 3 notch at one corner.
    let mut holes = Vec::new();
    for j in 4..6 {
        for i in 4..7 {
            holes.push((i, j));
        }
    }
    for j in 7..10 {
        for i in 10..13 {
            holes.push((i, j));
        }
    }
    cc_plate(14, 11, [80.0, 60.0], &holes, |x, y| {
        5.0 - (x * x + y * y) / 400.0
    })
}

/// A Catmull–Clark plate: `nu × nv` cage vertices on a regular grid, the cells in `holes`
/// left out, heights from `z(x, y)`, scaled so the limit surface spans `size` in x and y
/// (centred on the origin).
fn cc_plate(
    nu: usize,
    nv: usize,
    size: [f64; 2],
    holes: &[(usize, usize)],
    z: impl Fn(f64, f64) -> f64,
) -> Result<TMesh> {
    let mut used = vec![false; nu * nv];
    let mut cells = Vec::new();
    for j in 0..nv - 1 {
        for i in 0..nu - 1 {
            if holes.contains(&(i, j)) {
                continue;
            }
            let c = [
                j * nu + i,
                j * nu + i + 1,
                (j + 1) * nu + i + 1,
                (j + 1) * nu + i,
            ];
            for &k in &c {
                used[k] = true;
            }
            cells.push(c);
        }
    }
    let mut renum = vec![u32::MAX; nu * nv];
    let mut xy = Vec::new();
    for k in 0..nu * nv {
        if used[k] {
            renum[k] = xy.len() as u32;
            let (i, j) = (k % nu, k / nu);
            xy.push([
                i as f64 / (nu - 1) as f64 - 0.5,
                j as f64 / (nv - 1) as f64 - 0.5,
            ]);
        }
    }
    let faces: Vec<FaceLoop> = cells
        .iter()
        .map(|c| FaceLoop::quad(renum[c[0]], renum[c[1]], renum[c[2]], renum[c[3]]))
        .collect();
    let build = |pts: Vec<[f64; 3]>| {
        let points = pts
            .iter()
            .map(|p| ControlPoint {
                point: Point3::new(p[0], p[1], p[2]),
                weight: 1.0,
            })
            .collect();
        TMesh::try_new(points, &faces, &HashMap::new(), 1.0, Scheme::CatmullClark)
    };
    // The limit of a sharp boundary is the B-spline of the boundary polygon: measure it on a
    // flat plate and stretch the cage so it spans `size`.
    let flat =
        Surface::try_from_tmesh(&build(xy.iter().map(|p| [p[0], p[1], 0.0]).collect())?)?.bbox();
    let sx = size[0] / (flat.max[0] - flat.min[0]);
    let sy = size[1] / (flat.max[1] - flat.min[1]);
    build(
        xy.iter()
            .map(|p| {
                let (x, y) = (p[0] * sx, p[1] * sy);
                [x, y, z(x, y)]
            })
            .collect(),
    )
}

fn bump(x: f64, y: f64, cx: f64, cy: f64, r: f64, h: f64) -> f64 {
    let d2 = ((x - cx).powi(2) + (y - cy).powi(2)) / (r * r);
    h * (-2.0 * d2).exp()
}

fn bumps_z(x: f64, y: f64) -> f64 {
    bump(x, y, -20.0, 0.0, 14.0, 4.0) + bump(x, y, 20.0, 2.0, 12.0, -3.0)
}

fn bumps() -> Result<TMesh> {
    let (nu, nv) = (14, 11);
    clamped_plate(
        nu,
        nv,
        |i, j| {
            let x = plate_coord(i, nu, 80.0) - 40.0;
            let y = plate_coord(j, nv, 60.0) - 30.0;
            [x, y, bumps_z(x, y)]
        },
        &[],
        &[],
    )
}

fn bumps_hole() -> Result<TMesh> {
    let holes = [(6, 5), (7, 5), (6, 6), (7, 6)];
    cc_plate(15, 13, [80.0, 60.0], &holes, bumps_z)
}

/// A Catmull–Clark plate, 80 × 80 mm, with four round bosses (+3 mm, at x, y = ±20 mm) and
/// a square hole between them, like seed 003's third surface; not a listed sample, used by
/// the feature-region tests.
pub fn four_bosses_hole() -> Result<TMesh> {
    let holes = [(7, 7), (8, 7), (7, 8), (8, 8)];
    cc_plate(17, 17, [80.0, 80.0], &holes, |x, y| {
        [(-20.0, -20.0), (20.0, -20.0), (-20.0, 20.0), (20.0, 20.0)]
            .iter()
            .map(|&(cx, cy)| bump(x, y, cx, cy, 10.0, 3.0))
            .sum()
    })
}

fn waves() -> Result<TMesh> {
    let n = 13;
    clamped_plate(
        n,
        n,
        |i, j| {
            let x = plate_coord(i, n, 80.0) - 40.0;
            let y = plate_coord(j, n, 80.0) - 40.0;
            let z = 2.5
                * (std::f64::consts::PI * x / 40.0).sin()
                * (std::f64::consts::PI * y / 40.0).sin();
            [x, y, z]
        },
        &[(3, 1), (9, 1), (3, 10), (9, 10)],
        &[(1, 4), (10, 8)],
    )
}

/// A piece of a cylinder of radius `radius` (mm) about the y axis, spanning `angle_deg`
/// (< 180°) symmetrically about +Z and `length` (mm) along y: one rational bicubic patch,
/// exactly on the cylinder. `u` runs round the circle, `v` along the axis. With `inside`
/// the normals point to the axis (a concave trough seen from above, when placed below the
/// axis: the patch is then the lower part of the circle).
pub fn cylinder_patch(radius: f64, length: f64, angle_deg: f64, inside: bool) -> Result<TMesh> {
    let a = 0.5 * angle_deg.to_radians();
    let arc_pts = arc(a);
    // The arc in the x–z plane around +Z (outside) or around −Z (inside, lower half).
    let row: Vec<Vector4> = arc_pts
        .iter()
        .map(|&([c, s], w)| {
            let (x, z) = if inside {
                (s * radius, -c * radius)
            } else {
                (s * radius, c * radius)
            };
            Vector4::new(w * x, 0.0, w * z, w)
        })
        .collect();
    let cubic = elevate([row[0], row[1], row[2]]);
    let mut points = Vec::with_capacity(16);
    for j in 0..4 {
        let y = length * j as f64 / 3.0 - 0.5 * length;
        for h in &cubic {
            points.push(ControlPoint {
                point: Point3::new(h.x / h.w, y, h.z / h.w),
                weight: h.w,
            });
        }
    }
    TMesh::from_grid(
        points,
        4,
        4,
        &[0.0, 1.0, 0.0],
        &[0.0, 1.0, 0.0],
        Scheme::TSpline,
    )
}

/// A flat square patch of side `side` (mm) in the plane z = 0, normal +Z.
pub fn plane_patch(side: f64) -> Result<TMesh> {
    let mut points = Vec::with_capacity(16);
    for j in 0..4 {
        for i in 0..4 {
            points.push(ControlPoint {
                point: Point3::new(
                    side * (i as f64 / 3.0 - 0.5),
                    side * (j as f64 / 3.0 - 0.5),
                    0.0,
                ),
                weight: 1.0,
            });
        }
    }
    TMesh::from_grid(
        points,
        4,
        4,
        &[0.0, 1.0, 0.0],
        &[0.0, 1.0, 0.0],
        Scheme::TSpline,
    )
}

/// OBJ text of a bowl-shaped open cage round one vertex of valence `n` (for tests and
/// benchmarks of extraordinary points): rings of `2n` points at about 10, 20 and 30 mm,
/// `n` faces at the pole and `4n` beyond; the far corner of each pole face has 3 faces (so
/// `n` valence-3 points ring the pole). Heights follow no symmetry of the cage.
pub fn pole_cage_obj(n: usize) -> String {
    let mut s = String::from("v 0 0 3\n");
    for r in 1..=3 {
        for k in 0..2 * n {
            let a = k as f64 * std::f64::consts::PI / n as f64;
            let rr = r as f64 * 10.0 * if k % 2 == 0 { 1.0 } else { 1.05 };
            let z = 3.0 - 0.3 * (r * r) as f64 + 0.5 * (1.7 * a + 0.3).sin() * r as f64 / 3.0;
            s += &format!("v {:.6} {:.6} {z:.6}\n", rr * a.cos(), rr * a.sin());
        }
    }
    let id = |r: usize, k: usize| 2 + (r - 1) * 2 * n + k % (2 * n);
    for k in 0..n {
        let (a, b, c) = (2 * k, 2 * k + 1, 2 * k + 2);
        s += &format!("f 1 {} {} {}\n", id(1, a), id(1, b), id(1, c));
        for r in 1..3 {
            for j in [a, b] {
                s += &format!(
                    "f {} {} {} {}\n",
                    id(r, j),
                    id(r + 1, j),
                    id(r + 1, j + 1),
                    id(r, j + 1)
                );
            }
        }
    }
    s
}
