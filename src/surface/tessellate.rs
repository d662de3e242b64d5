//! Triangle meshes of the surface for display and export: per face a grid fine enough for a
//! chordal tolerance, with the patch id of every triangle.

use super::{DiffGeom, Surface};

/// Flat arrays ready for a GPU or an STL writer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tessellation {
    /// `x y z` per vertex (mm).
    pub positions: Vec<f32>,
    /// Unit normal per vertex.
    pub normals: Vec<f32>,
    /// Three vertex indices per triangle, counter-clockwise seen from the normal side.
    pub indices: Vec<u32>,
    /// Domain face (patch) of each triangle.
    pub patch_ids: Vec<u32>,
}

/// Fewest and most segments along a face side.
const MIN_SEGMENTS: usize = 2;
const MAX_SEGMENTS: usize = 128;
/// Samples per side used to estimate length and curvature.
const PROBE: usize = 9;

/// Tessellates every face on a grid whose segments deviate from the surface by about
/// `chordal_mm` or less.
pub fn tessellate(surface: &Surface, chordal_mm: f64) -> Tessellation {
    let mut t = Tessellation::default();
    for (fi, face) in surface.faces().iter().enumerate() {
        // Length and curvature of the iso-curves, sampled.
        let mut len_u: f64 = 0.0;
        let mut len_v: f64 = 0.0;
        let mut k_max: f64 = 0.0;
        for a in 0..PROBE {
            let x = a as f64 / (PROBE - 1) as f64;
            let mut lu = 0.0;
            let mut lv = 0.0;
            for b in 0..PROBE - 1 {
                let y0 = b as f64 / (PROBE - 1) as f64;
                let y1 = (b + 1) as f64 / (PROBE - 1) as f64;
                lu += (face.subs(y1, x) - face.subs(y0, x)).norm();
                lv += (face.subs(x, y1) - face.subs(x, y0)).norm();
                let d = face.derivs(y0, x);
                for (c1, c2) in [(d.su, d.suu), (d.sv, d.svv)] {
                    let s = c1.norm();
                    if s > 0.0 {
                        k_max = k_max.max(c1.cross(&c2).norm() / (s * s * s));
                    }
                }
            }
            len_u = len_u.max(lu);
            len_v = len_v.max(lv);
        }
        let seg = if k_max > 0.0 {
            (8.0 * chordal_mm / k_max).sqrt()
        } else {
            f64::INFINITY
        };
        let count = |len: f64| ((len / seg).ceil() as usize).clamp(MIN_SEGMENTS, MAX_SEGMENTS);
        let (nu, nv) = (count(len_u), count(len_v));
        let base = (t.positions.len() / 3) as u32;
        for j in 0..=nv {
            for i in 0..=nu {
                let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
                let d = face.derivs(u, v);
                let n = DiffGeom::try_from_derivs(&d)
                    .map(|g| g.normal)
                    .or_else(|| {
                        // At a singular point take the normal a little inside the face.
                        let (uu, vv) = (0.5 + (u - 0.5) * 0.999, 0.5 + (v - 0.5) * 0.999);
                        DiffGeom::try_from_derivs(&face.derivs(uu, vv)).map(|g| g.normal)
                    })
                    .unwrap_or_else(crate::geom::Vector3::z);
                t.positions
                    .extend([d.point.x as f32, d.point.y as f32, d.point.z as f32]);
                t.normals.extend([n.x as f32, n.y as f32, n.z as f32]);
            }
        }
        let id = |i: usize, j: usize| base + (j * (nu + 1) + i) as u32;
        for j in 0..nv {
            for i in 0..nu {
                t.indices.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.indices.extend([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                t.patch_ids.extend([fi as u32, fi as u32]);
            }
        }
    }
    t
}
