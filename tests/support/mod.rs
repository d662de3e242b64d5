//! Shared by the planner tests: the public `.tsm` files, the space-filling curve's models
//! and options, and independent clearance checks — dense samples of the surface (from a
//! fine tessellation, without the planner's own obstacle index) and signed distances from
//! them to the ball, shank and holder of a tool pose.
#![allow(dead_code)]

use tspath::geom::{Point3, Vector3};
use tspath::io;
use tspath::model::samples;
use tspath::plan::{PlanOptions, Strategy};
use tspath::Model;

/// A public `.tsm` file (GrapeTec/T-SPLINE, LGPL-3.0; www/models/grapetec).
pub fn public_tsm(name: &str) -> Model {
    let path = format!("{}/www/models/grapetec/{name}", env!("CARGO_MANIFEST_DIR"));
    io::load(&std::fs::read(&path).unwrap(), name).unwrap()
}

/// The space-filling curve, three-axis, ball `r`, scallop `h` (mm).
pub fn isfc_opts(r: f64, h: f64) -> PlanOptions {
    let mut o = PlanOptions::default()
        .with_tool_radius(r)
        .with_scallop(h)
        .with_strategy(Strategy::Isfc);
    o.max_tilt_deg = 0.0;
    o
}

/// The built-in samples with holes, with the curve at r 1 mm, h 0.05 mm.
pub fn holed_samples() -> Vec<(&'static str, Model, PlanOptions)> {
    ["plate-hole", "bumps-hole"]
        .into_iter()
        .map(|n| (n, samples::load_sample(n).unwrap(), isfc_opts(1.0, 0.05)))
        .collect()
}

/// Samples at most 0.3 mm apart on a tessellation within 0.01 mm of the surface: a cylinder
/// of radius r can sink between them by 0.3² / 8r (0.011 mm for a 1 mm shank).
pub fn dense_samples(m: &Model) -> Vec<Point3> {
    let (chordal, spacing) = (0.01, 0.3);
    let t = m.tessellate(chordal);
    let vertex = |i: u32| {
        let p = &t.positions[3 * i as usize..3 * i as usize + 3];
        Point3::new(p[0] as f64, p[1] as f64, p[2] as f64)
    };
    let mut samples = Vec::new();
    for tri in t.indices.chunks(3) {
        let (a, b, c) = (vertex(tri[0]), vertex(tri[1]), vertex(tri[2]));
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let n = (longest / spacing).ceil().max(1.0) as usize;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                samples.push(a + (b - a) * u + (c - a) * v);
            }
        }
    }
    samples
}

/// Signed distance (mm, negative inside) from `p` to the solid cylinder of radius `rad`
/// whose axis runs from `a` along the unit vector `dir` for `len`.
pub fn cylinder_distance(p: &Point3, a: &Point3, dir: &Vector3, len: f64, rad: f64) -> f64 {
    let d = p - a;
    let t = d.dot(dir);
    let radial = (d - dir * t).norm();
    let out_axial = (-t).max(t - len).max(0.0);
    let out_radial = (radial - rad).max(0.0);
    if out_axial == 0.0 && out_radial == 0.0 {
        -(rad - radial).min(t).min(len - t)
    } else {
        out_axial.hypot(out_radial)
    }
}

/// Surface samples in a uniform grid of cubes, for "is any sample inside this cylinder".
pub struct SampleGrid {
    cell: f64,
    cells: std::collections::HashMap<(i64, i64, i64), Vec<Point3>>,
}

impl SampleGrid {
    pub fn new(samples: &[Point3], cell: f64) -> Self {
        let mut cells: std::collections::HashMap<_, Vec<Point3>> = Default::default();
        for p in samples {
            cells.entry(Self::key(p, cell)).or_default().push(*p);
        }
        SampleGrid { cell, cells }
    }

    fn key(p: &Point3, cell: f64) -> (i64, i64, i64) {
        let k = |x: f64| (x / cell).floor() as i64;
        (k(p.x), k(p.y), k(p.z))
    }

    /// Least signed distance (mm) from a sample to the solid cylinder of radius `rad` around
    /// the segment `a`–`b`: negative inside, `reach` when no sample is nearer than that.
    pub fn clearance_to_cylinder(&self, a: &Point3, b: &Point3, rad: f64, reach: f64) -> f64 {
        let axis = b - a;
        let len = axis.norm();
        let dir = axis / len;
        let grow = rad + reach;
        let lo = a.coords.inf(&b.coords).add_scalar(-grow);
        let hi = a.coords.sup(&b.coords).add_scalar(grow);
        let (k0, k1) = (
            Self::key(&Point3::from(lo), self.cell),
            Self::key(&Point3::from(hi), self.cell),
        );
        let mut least = reach;
        for x in k0.0..=k1.0 {
            for y in k0.1..=k1.1 {
                for z in k0.2..=k1.2 {
                    let Some(ps) = self.cells.get(&(x, y, z)) else {
                        continue;
                    };
                    for p in ps {
                        least = least.min(cylinder_distance(p, a, &dir, len, rad));
                    }
                }
            }
        }
        least
    }

    /// Least distance (mm) from `c` to a sample, `reach` when none is nearer.
    pub fn nearest(&self, c: &Point3, reach: f64) -> f64 {
        let (k0, k1) = (
            Self::key(&(c - Vector3::repeat(reach)), self.cell),
            Self::key(&(c + Vector3::repeat(reach)), self.cell),
        );
        let mut least = reach;
        for x in k0.0..=k1.0 {
            for y in k0.1..=k1.1 {
                for z in k0.2..=k1.2 {
                    if let Some(ps) = self.cells.get(&(x, y, z)) {
                        for p in ps {
                            least = least.min((p - c).norm());
                        }
                    }
                }
            }
        }
        least
    }
}

/// Least clearance (mm, negative inside) between the surface samples and the shank above the
/// flutes or the holder of a tool with ball centre `c` and axis `axis`; `reach` when farther.
pub fn tool_clearance(
    grid: &SampleGrid,
    o: &PlanOptions,
    c: Point3,
    axis: Vector3,
    reach: f64,
) -> f64 {
    let (f, ls, lh) = (o.flute_length(), o.shank_length_mm, o.holder_length_mm);
    let shank =
        grid.clearance_to_cylinder(&(c + axis * f), &(c + axis * ls), o.shank_radius(), reach);
    let holder = grid.clearance_to_cylinder(
        &(c + axis * ls),
        &(c + axis * (ls + lh)),
        o.holder_radius_mm,
        reach,
    );
    shank.min(holder)
}

/// The surface point at global chart position `(s, t)`, found through the chart.
pub fn chart_point(
    mesh: &tspath::tmesh::TMesh,
    surface: &tspath::surface::Surface,
    s: f64,
    t: f64,
) -> Option<tspath::geom::Point3> {
    let chart = mesh.global_chart()?;
    let index: std::collections::HashMap<u32, usize> = surface
        .faces()
        .iter()
        .enumerate()
        .map(|(i, f)| (f.mesh_face, i))
        .collect();
    for pl in &chart.faces {
        let f = &mesh.faces()[pl.face as usize];
        let Some(&fi) = index.get(&pl.face) else {
            continue;
        };
        // Inverse placement: local = rot(-k)(chart - offset).
        let (x, y) = (s - pl.offset[0], t - pl.offset[1]);
        let (lx, ly) = match pl.quarter_turns % 4 {
            0 => (x, y),
            1 => (y, -x),
            2 => (-x, -y),
            _ => (-y, x),
        };
        if lx >= 0.0 && lx <= f.width && ly >= 0.0 && ly <= f.height {
            return Some(surface.subs(fi, lx / f.width, ly / f.height));
        }
    }
    None
}

/// An open sheet cage from a profile in the XZ plane extruded along Y over `ny` quads of
/// `dy` mm (boundary edges sharp, corners interpolated, as OBJ cages are read). With
/// `triangles`, every other quad of the first row is split into two triangles.
pub fn extruded_obj(profile: &[(f64, f64)], ny: usize, dy: f64, triangles: bool) -> String {
    let mut s = String::new();
    let np = profile.len();
    for k in 0..=ny {
        for &(x, z) in profile {
            s += &format!("v {x} {} {z}\n", k as f64 * dy);
        }
    }
    let id = |i: usize, k: usize| k * np + i + 1;
    for k in 0..ny {
        for i in 0..np - 1 {
            let (a, b, c, d) = (id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1));
            if triangles && k == 0 && i % 2 == 0 {
                s += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            } else {
                s += &format!("f {a} {b} {c} {d}\n");
            }
        }
    }
    s
}

/// A model from OBJ text.
pub fn obj_model(text: &str, name: &str) -> Model {
    io::load(text.as_bytes(), name).unwrap()
}

/// A closed torus cage (Catmull–Clark): `m` × `n` quads on a torus of radii `big` and `small`
/// (mm) lying on the XY plane.
pub fn torus_obj(big: f64, small: f64, m: usize, n: usize) -> String {
    let mut s = String::new();
    for i in 0..m {
        let a = std::f64::consts::TAU * i as f64 / m as f64;
        for j in 0..n {
            let b = std::f64::consts::TAU * j as f64 / n as f64;
            let r = big + small * b.cos();
            s += &format!(
                "v {} {} {}\n",
                r * a.cos(),
                r * a.sin(),
                small + small * b.sin()
            );
        }
    }
    let id = |i: usize, j: usize| (i % m) * n + (j % n) + 1;
    for i in 0..m {
        for j in 0..n {
            s += &format!(
                "f {} {} {} {}\n",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            );
        }
    }
    s
}

/// An `n × m` grid of quads as OBJ text: vertex `(i, j)` at `at(i, j)`, numbered from 1
/// row by row (`j * (n + 1) + i + 1`), faces row by row (`j * n + i`).
pub fn quad_grid_obj(n: usize, m: usize, at: impl Fn(usize, usize) -> [f64; 3]) -> String {
    let mut s = String::new();
    for j in 0..=m {
        for i in 0..=n {
            let [x, y, z] = at(i, j);
            s += &format!("v {x} {y} {z}\n");
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i + 1;
    for j in 0..m {
        for i in 0..n {
            s += &format!(
                "f {} {} {} {}\n",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            );
        }
    }
    s
}

/// A sheet of `n` × `n` unit quads with a bumpy height, vertices numbered from 0 row by row
/// (`j * (n + 1) + i`), faces from 0 row by row (`j * n + i`), as OBJ text.
pub fn bumpy_sheet(n: usize) -> String {
    quad_grid_obj(n, n, |i, j| {
        let (x, y) = (i as f64, j as f64);
        [x, y, 0.3 * (1.3 * x).sin() * (0.9 * y).cos() + 0.05 * x * y]
    })
}

/// A `t crease` tag creasing the edges along the vertex chain `chain` (counted from 0) with
/// sharpness `s`: one vertex pair per edge, as OBJ cages carry them.
pub fn crease_tag(chain: &[u32], s: f64) -> String {
    let pairs: Vec<String> = chain
        .windows(2)
        .map(|w| format!("{} {}", w[0], w[1]))
        .collect();
    format!("t crease {}/1/0 {} {s}\n", 2 * pairs.len(), pairs.join(" "))
}
