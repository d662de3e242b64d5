//! The cutter-location (CL) surface as a triangle mesh: per layout patch a grid in the
//! patch's `(u, v)`, fine enough that the mesh of ball centres stays within the chordal
//! tolerance of the true offset, each vertex a ball centre a tool radius along the exact
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
/// Samples per side of a patch that size its grid.
const SIZE_SAMPLES: usize = 9;
/// Most vertices of the whole mesh: beyond it the grids are coarsened (evenly).
const MAX_VERTICES: usize = 2_000_000;

/// Takes a vertex's index and the surface's derivatives at its contact point (patch
/// parameters) as [`ClMesh::new_with`] makes it.
pub type VertexVisit<'a> = &'a mut dyn FnMut(usize, &SurfaceDerivs);

impl ClMesh {
    /// The CL mesh of `model` for a ball of radius `r` (mm) within chordal tolerance
    /// `chordal_mm` of the true offset surface.
    pub fn new(model: &Model, r: f64, chordal_mm: f64) -> Result<Self> {
        Self::build(model, r, chordal_mm, None)
    }

    /// [`ClMesh::new`], handing each vertex's index and the surface's derivatives there
    /// (in the patch's parameters) to `each` as the vertex is made: one evaluation serves
    /// the mesh and a caller that needs the curvature at every vertex. The mesh is the
    /// same bit for bit (the point and first derivatives equal those evaluated alone).
    pub fn new_with(model: &Model, r: f64, chordal_mm: f64, each: VertexVisit) -> Result<Self> {
        Self::build(model, r, chordal_mm, Some(each))
    }

    fn build(
        model: &Model,
        r: f64,
        chordal_mm: f64,
        mut each: Option<VertexVisit>,
    ) -> Result<Self> {
        let side = model.tool_side();
        let surface = &model.surface;
        let layout = &model.layout;
        // Cells per side of every patch from the fastest parameter speed and the tightest
        // curvature of the offset over samples.
        let mut sizes: Vec<[usize; 2]> = Vec::with_capacity(layout.len());
        for patch in &layout.patches {
            let (mut speed, mut kmax) = ([0.0f64; 2], 0.0f64);
            let k = (SIZE_SAMPLES - 1) as f64;
            for a in 0..SIZE_SAMPLES {
                for b in 0..SIZE_SAMPLES {
                    let d = patch.derivs(surface, a as f64 / k, b as f64 / k);
                    speed[0] = speed[0].max(d.su.norm());
                    speed[1] = speed[1].max(d.sv.norm());
                    if let Some(g) = DiffGeom::try_from_derivs(&d) {
                        let (k1, k2) = g.principal();
                        let kk = k1.abs().max(k2.abs());
                        // The offset's curvature: κ / (1 − rκ) on the concave side (capped).
                        let kcl = if kk * r < 0.5 {
                            kk / (1.0 - kk * r)
                        } else {
                            2.0 * kk
                        };
                        kmax = kmax.max(kcl.max(kk));
                    }
                }
            }
            let seg = stepover::chord_step(chordal_mm, kmax);
            let cells = |s: f64| {
                if seg.is_finite() {
                    ((s / seg).ceil() as usize).clamp(MIN_CELLS, MAX_CELLS)
                } else {
                    MIN_CELLS
                }
            };
            sizes.push([cells(speed[0]), cells(speed[1])]);
        }
        let total: usize = sizes.iter().map(|s| (s[0] + 1) * (s[1] + 1)).sum();
        if total > MAX_VERTICES {
            let f = (MAX_VERTICES as f64 / total as f64).sqrt();
            for s in &mut sizes {
                for n in s.iter_mut() {
                    *n = ((*n as f64 * f).floor() as usize).max(MIN_CELLS);
                }
            }
        }
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        let mut patches = Vec::with_capacity(sizes.len());
        for (pi, (patch, &[nu, nv])) in layout.patches.iter().zip(&sizes).enumerate() {
            let first = vertices.len() as u32;
            patches.push((first, [nu, nv]));
            for j in 0..=nv {
                for i in 0..=nu {
                    let uv = [i as f64 / nu as f64, j as f64 / nv as f64];
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
