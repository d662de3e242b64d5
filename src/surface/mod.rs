//! Surface evaluation: every domain face of a T-mesh reduced once to rational bicubic Bézier
//! cells (Bézier extraction), then evaluated with first and second derivatives.
//!
//! Owns: B-spline/Bernstein bases, Bézier extraction, point and derivative evaluation,
//! differential geometry. Must not: change the T-mesh or know about tool paths.
//!
//! Parameters: each domain face has its own `(u, v)` in `[0,1]²`, `u` along its side 0. The
//! face's knot width and height say how long that is in the T-mesh's parameter units.

pub mod basis;
pub mod bezier;
pub mod diffgeom;
mod extract;
pub mod tessellate;

pub use bezier::{BezierPatch, SurfaceDerivs};
pub use diffgeom::DiffGeom;

use crate::error::{Error, Result};
use crate::geom::{Aabb, Point3, Vector3};
use crate::tmesh::TMesh;

/// One domain face of the surface in Bézier form: a grid of cells over `[0,1]²`.
#[derive(Debug, Clone)]
pub struct FaceSurface {
    /// The T-mesh face this comes from.
    pub mesh_face: u32,
    /// Parametric width and height of the face in knot units.
    pub width: f64,
    pub height: f64,
    /// Cell boundaries in `u` and `v`, from 0 to 1.
    u_breaks: Vec<f64>,
    v_breaks: Vec<f64>,
    /// Cells, row-major: index `j * (u_breaks.len() - 1) + i`.
    cells: Vec<BezierPatch>,
}

impl FaceSurface {
    fn locate(breaks: &[f64], x: f64) -> (usize, f64, f64) {
        let n = breaks.len() - 1;
        let i = match breaks[1..n]
            .binary_search_by(|b| b.partial_cmp(&x).unwrap_or(std::cmp::Ordering::Less))
        {
            Ok(k) => k + 1,
            Err(k) => k,
        };
        let i = i.min(n - 1);
        let span = breaks[i + 1] - breaks[i];
        ((i), (x - breaks[i]) / span, 1.0 / span)
    }

    /// Point and derivatives at `(u, v)` in `[0,1]²`.
    pub fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        let (i, tu, su) = Self::locate(&self.u_breaks, u);
        let (j, tv, sv) = Self::locate(&self.v_breaks, v);
        let nu = self.u_breaks.len() - 1;
        self.cells[j * nu + i].derivs(tu, tv).scaled(su, sv)
    }

    /// Point at `(u, v)` in `[0,1]²`.
    pub fn subs(&self, u: f64, v: f64) -> Point3 {
        let (i, tu, _) = Self::locate(&self.u_breaks, u);
        let (j, tv, _) = Self::locate(&self.v_breaks, v);
        let nu = self.u_breaks.len() - 1;
        self.cells[j * nu + i].subs(tu, tv)
    }

    /// Number of Bézier cells.
    pub fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// The cells with their `[u0,u1]×[v0,v1]` ranges.
    pub fn cells(&self) -> impl Iterator<Item = ([f64; 4], &BezierPatch)> {
        let nu = self.u_breaks.len() - 1;
        self.cells.iter().enumerate().map(move |(k, c)| {
            let (i, j) = (k % nu, k / nu);
            (
                [
                    self.u_breaks[i],
                    self.u_breaks[i + 1],
                    self.v_breaks[j],
                    self.v_breaks[j + 1],
                ],
                c,
            )
        })
    }
}

/// The evaluable surface of a model: its domain faces in Bézier form.
#[derive(Debug, Clone)]
pub struct Surface {
    faces: Vec<FaceSurface>,
    bbox: Aabb,
}

impl Surface {
    /// Reduces a validated T-mesh to Bézier form. Errors on features this version cannot
    /// evaluate exactly, with the vertex or face at fault.
    pub fn try_from_tmesh(mesh: &TMesh) -> Result<Self> {
        let faces = extract::extract(mesh)?;
        if faces.is_empty() {
            return Err(Error::InvalidMesh(
                "no face has positive parametric area (all knot intervals zero?)".into(),
            ));
        }
        let mut bbox = Aabb::empty();
        for f in &faces {
            for k in 0..=8 {
                for l in 0..=8 {
                    bbox.grow(&f.subs(k as f64 / 8.0, l as f64 / 8.0));
                }
            }
        }
        Ok(Surface { faces, bbox })
    }

    /// Domain faces.
    pub fn faces(&self) -> &[FaceSurface] {
        &self.faces
    }

    /// Point on domain face `face` at `(u, v)` in `[0,1]²`.
    pub fn subs(&self, face: usize, u: f64, v: f64) -> Point3 {
        self.faces[face].subs(u, v)
    }

    /// Point and first and second derivatives on domain face `face` at `(u, v)`.
    pub fn derivs(&self, face: usize, u: f64, v: f64) -> SurfaceDerivs {
        self.faces[face].derivs(u, v)
    }

    /// `∂S/∂u` on domain face `face`.
    pub fn uder(&self, face: usize, u: f64, v: f64) -> Vector3 {
        self.derivs(face, u, v).su
    }

    /// `∂S/∂v` on domain face `face`.
    pub fn vder(&self, face: usize, u: f64, v: f64) -> Vector3 {
        self.derivs(face, u, v).sv
    }

    /// Approximate bounding box of the surface (sampled, mm).
    pub fn bbox(&self) -> Aabb {
        self.bbox
    }
}
