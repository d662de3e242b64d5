//! The cutter-location (CL) surface as a triangle mesh: per layout patch a grid in the
//! patch's `(u, v)`, fine enough that the mesh of ball centres stays within the chordal
//! tolerance of the true offset (its lines closer together where the curvature and the
//! parameter speed ask, not evenly at the patch's worst), each vertex a ball centre a tool radius along the exact
//! limit-surface normal (not a vertex normal of a coarse mesh) from its contact point.
//!
//! Where the surface is concave with a radius below the ball's, or folds, the offset
//! self-intersects and some of its vertices lie closer than a radius to the surface; they
//! are kept here (the slices pass through them), and the shared pipeline lifts every ball
//! centre that would cut into the surface until it touches without cutting in (the same
//! lifting every strategy gets): no CL point of the plan lies closer than a radius.
//!
//! Owns: the mesh and its vertices' patch parameters. Must not: deform or slice it.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::model::Model;
use crate::plan::stepover;
use crate::surface::{DiffGeom, SurfaceDerivs};

/// The grid cells per unit parameter that `u` and `v` of `patch` ask for, per interval
/// between neighbouring samples: at each sample the parameter speed over the surface step
/// whose chord on the offset (and on the surface) keeps within the chordal tolerance, at
/// most `max_cell_mm`; per interval the largest at its ends and theirs beside (a peak
/// between samples is not missed by a sample's width), the largest across the other
/// direction.
fn density(
    patch: &crate::layout::Patch,
    surface: &crate::surface::Surface,
    r: f64,
    chordal_mm: f64,
    max_cell_mm: f64,
) -> [Vec<f64>; 2] {
    let n = SIZE_SAMPLES;
    let k = (n - 1) as f64;
    // Cells per unit parameter asked at each sample, the largest across the other side.
    let mut at = [vec![0.0f64; n], vec![0.0f64; n]];
    for a in 0..n {
        for b in 0..n {
            let d = patch.derivs(surface, a as f64 / k, b as f64 / k);
            let Some(g) = DiffGeom::try_from_derivs(&d) else {
                continue;
            };
            // The offset's curvature, taken as on the concave side whatever the side:
            // κ / (1 − rκ), capped where the offset folds (the pipeline lifts the balls
            // there). Convex, the offset bends less but its ball centres move faster than
            // the contact point; per step on the surface its sagitta grows as
            // |κ| (1 + r|κ|), which this bounds up to r|κ| = 1.
            let (k1, k2) = g.principal();
            let kk = k1.abs().max(k2.abs());
            let kcl = if kk * r < 0.5 {
                kk / (1.0 - kk * r)
            } else {
                2.0 * kk
            };
            let seg = stepover::chord_step(chordal_mm, kcl).min(max_cell_mm);
            if seg.is_finite() {
                at[0][a] = at[0][a].max(d.su.norm() / seg);
                at[1][b] = at[1][b].max(d.sv.norm() / seg);
            }
        }
    }
    at.map(|side| {
        (0..n - 1)
            .map(|i| {
                side[i.saturating_sub(1)..(i + 3).min(n)]
                    .iter()
                    .copied()
                    .fold(0.0, f64::max)
            })
            .collect()
    })
}

/// Grid lines (patch parameters from 0 to 1) for [`density`] `d` times `scale`: per side
/// the cells the density integrates to (at least [`MIN_CELLS`], at most [`MAX_CELLS`]),
/// each holding an equal share of the integral (evenly spaced where it is zero).
fn grid_lines(d: &[Vec<f64>; 2], scale: f64) -> [Vec<f64>; 2] {
    [0, 1].map(|side| {
        let w = 1.0 / d[side].len() as f64;
        let cells: Vec<f64> = d[side].iter().map(|&c| c * scale * w).collect();
        let sum: f64 = cells.iter().sum();
        let n = if sum.is_finite() {
            (sum.ceil() as usize).clamp(MIN_CELLS, MAX_CELLS)
        } else {
            MAX_CELLS
        };
        if !(sum > 0.0) || !sum.is_finite() {
            return (0..=n).map(|i| i as f64 / n as f64).collect();
        }
        // Line i where the running integral reaches i / n of the whole, linear within an
        // interval.
        let mut lines = Vec::with_capacity(n + 1);
        lines.push(0.0);
        let (mut run, mut k) = (0.0, 0);
        for i in 1..n {
            let want = sum * i as f64 / n as f64;
            while k + 1 < cells.len() && run + cells[k] < want {
                run += cells[k];
                k += 1;
            }
            let f = if cells[k] > 0.0 {
                ((want - run) / cells[k]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            lines.push((k as f64 + f) * w);
        }
        lines.push(1.0);
        lines
    })
}

/// A vertex of the CL mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClVertex {
    pub patch: u32,
    /// Patch parameters of its contact point.
    pub uv: [f64; 2],
    /// Contact point on the surface (mm).
    pub cc: Point3,
    /// Unit normal on the tool's side.
    pub normal: Vector3,
    /// Ball centre, `cc + r·normal` (mm).
    pub cl: Point3,
}

/// The mesh: vertices (`None` at singular points, where the surface has no normal) and
/// triangles, each within one patch, counter-clockwise in `(u, v)`.
#[derive(Debug, Clone)]
pub struct ClMesh {
    pub vertices: Vec<Option<ClVertex>>,
    pub triangles: Vec<[u32; 3]>,
    /// Per patch: its first vertex and its grid's cells `(nu, nv)`.
    pub patches: Vec<(u32, [usize; 2])>,
}

/// Fewest and most grid cells along a patch side.
const MIN_CELLS: usize = 2;
const MAX_CELLS: usize = 256;
/// Samples per side of a patch that place its grid lines.
const SIZE_SAMPLES: usize = 33;
/// Most vertices of the whole mesh: beyond it the grids are coarsened (evenly).
const MAX_VERTICES: usize = 2_000_000;

/// Takes a vertex's index and the surface's derivatives at its contact point (patch
/// parameters) as [`ClMesh::new_with`] makes it.
pub type VertexVisit<'a> = &'a mut dyn FnMut(usize, &SurfaceDerivs);

impl ClMesh {
    /// The CL mesh of `model` for a ball of radius `r` (mm) within chordal tolerance
    /// `chordal_mm` of the true offset surface.
    pub fn new(model: &Model, r: f64, chordal_mm: f64, max_cell_mm: f64) -> Result<Self> {
        Self::build(model, r, chordal_mm, max_cell_mm, None)
    }

    /// [`ClMesh::new`], handing each vertex's index and the surface's derivatives there
    /// (in the patch's parameters) to `each` as the vertex is made: one evaluation serves
    /// the mesh and a caller that needs the curvature at every vertex. The mesh is the
    /// same bit for bit (the point and first derivatives equal those evaluated alone).
    pub fn new_with(
        model: &Model,
        r: f64,
        chordal_mm: f64,
        max_cell_mm: f64,
        each: VertexVisit,
    ) -> Result<Self> {
        Self::build(model, r, chordal_mm, max_cell_mm, Some(each))
    }

    fn build(
        model: &Model,
        r: f64,
        chordal_mm: f64,
        max_cell_mm: f64,
        mut each: Option<VertexVisit>,
    ) -> Result<Self> {
        let side = model.tool_side();
        let surface = &model.surface;
        let layout = &model.layout;
        // Each patch's grid lines, placed by the density its samples ask for: the
        // parameter speed over the chord the offset's curvature allows, the worst across
        // the other direction.
        let densities: Vec<[Vec<f64>; 2]> = layout
            .patches
            .iter()
            .map(|patch| density(patch, surface, r, chordal_mm, max_cell_mm))
            .collect();
        let lines = |scale: f64| -> Vec<[Vec<f64>; 2]> {
            densities.iter().map(|d| grid_lines(d, scale)).collect()
        };
        let mut breaks = lines(1.0);
        let total: usize = breaks.iter().map(|[u, v]| u.len() * v.len()).sum();
        if total > MAX_VERTICES {
            // Coarsened evenly: the same density, scaled down.
            breaks = lines((MAX_VERTICES as f64 / total as f64).sqrt());
        }
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        let mut patches = Vec::with_capacity(breaks.len());
        for (pi, (patch, [us, vs])) in layout.patches.iter().zip(&breaks).enumerate() {
            let first = vertices.len() as u32;
            let (nu, nv) = (us.len() - 1, vs.len() - 1);
            patches.push((first, [nu, nv]));
            for &v in vs {
                for &u in us {
                    let uv = [u, v];
                    let (cc, n) = match each.as_deref_mut() {
                        Some(f) => {
                            let (d, n) = patch.derivs_normal(surface, uv[0], uv[1]);
                            f(vertices.len(), &d);
                            (d.point, n)
                        }
                        None => patch.point_normal(surface, uv[0], uv[1]),
                    };
                    vertices.push(n.map(|n| {
                        let normal = n * side;
                        ClVertex {
                            patch: pi as u32,
                            uv,
                            cc,
                            normal,
                            cl: cc + normal * r,
                        }
                    }));
                }
            }
            let id = |i: usize, j: usize| first + (j * (nu + 1) + i) as u32;
            for j in 0..nv {
                for i in 0..nu {
                    let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
        // Triangles through a singular vertex are dropped (their neighbours' slices end there).
        triangles.retain(|t| t.iter().all(|&v| vertices[v as usize].is_some()));
        if triangles.is_empty() {
            return Err(Error::Degenerate {
                location: "CL surface".into(),
                message: "the surface has no tangent plane anywhere the mesh samples it".into(),
            });
        }
        Ok(ClMesh {
            vertices,
            triangles,
            patches,
        })
    }

    /// Vertex `i` (which the triangles only name where it exists).
    pub fn vertex(&self, i: u32) -> &ClVertex {
        self.vertices[i as usize]
            .as_ref()
            .expect("triangles name existing vertices")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density's integral over `[a, b]` (piecewise constant per interval).
    fn integral(d: &[f64], a: f64, b: f64) -> f64 {
        let w = 1.0 / d.len() as f64;
        d.iter()
            .enumerate()
            .map(|(i, &c)| {
                let (lo, hi) = (i as f64 * w, (i + 1) as f64 * w);
                c * (hi.min(b) - lo.max(a)).max(0.0)
            })
            .sum()
    }

    #[test]
    fn grid_lines_split_the_density_into_equal_shares() {
        // A peak in the middle, a flat stretch of zero, and an even density.
        let peaked: Vec<f64> = (0..32)
            .map(|i| {
                if (12..16).contains(&i) {
                    400.0
                } else if i < 4 {
                    0.0
                } else {
                    10.0
                }
            })
            .collect();
        let even = vec![37.0; 32];
        let [u, v] = grid_lines(&[peaked.clone(), even.clone()], 1.0);
        for (lines, d) in [(&u, &peaked), (&v, &even)] {
            let total = integral(d, 0.0, 1.0);
            let n = lines.len() - 1;
            assert_eq!(n, total.ceil() as usize);
            assert_eq!((lines[0], lines[n]), (0.0, 1.0));
            for w in lines.windows(2) {
                assert!(w[1] > w[0], "{w:?}");
                // Each cell holds an equal share of the integral, so at most one cell.
                let share = integral(d, w[0], w[1]);
                assert!((share - total / n as f64).abs() < 1e-9 * total, "{share}");
            }
        }
        // An even density gives evenly spaced lines.
        for (i, x) in v.iter().enumerate() {
            assert!((x - i as f64 / (v.len() - 1) as f64).abs() < 1e-12);
        }
        // Nothing asked: the fewest cells, evenly; over the most: the most.
        assert_eq!(
            grid_lines(&[vec![0.0; 32], vec![0.0; 32]], 1.0)[0],
            vec![0.0, 0.5, 1.0]
        );
        assert_eq!(
            grid_lines(&[vec![1e6; 32], even], 1.0)[0].len(),
            MAX_CELLS + 1
        );
    }
}
