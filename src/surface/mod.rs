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
pub mod sharpness;
pub mod subdiv;
pub mod tessellate;

pub use bezier::{BezierPatch, SurfaceDerivs};
use diffgeom::unit_normal;
pub use diffgeom::DiffGeom;

use crate::error::{Error, Result};
use crate::geom::{Aabb, Point3, Vector3};
use crate::tmesh::TMesh;

/// How a face is stored for evaluation.
// A face that is one regular cell keeps it inline (the common case on subdivision cages).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum FaceForm {
    /// A grid of Bézier cells (T-spline faces, cut at every knot line crossing them).
    Grid {
        /// Cell boundaries in `u` and `v`, from 0 to 1.
        u_breaks: Vec<f64>,
        v_breaks: Vec<f64>,
        /// Cells, row-major: index `j * (u_breaks.len() - 1) + i`.
        cells: Vec<BezierPatch>,
    },
    /// A quadtree of Bézier cells from local Catmull–Clark subdivision (faces at and near
    /// extraordinary points, and every face of a Catmull–Clark cage).
    Tree(subdiv::Node),
}

/// One domain face of the surface in Bézier form.
#[derive(Debug, Clone)]
pub struct FaceSurface {
    /// The T-mesh face this comes from.
    pub mesh_face: u32,
    /// Parametric width and height of the face in knot units.
    pub width: f64,
    pub height: f64,
    pub form: FaceForm,
}

/// The cell of `breaks` holding `x` (the upper one on a break).
fn cell_of(breaks: &[f64], x: f64) -> usize {
    let n = breaks.len() - 1;
    breaks[1..n].partition_point(|&b| b <= x).min(n - 1)
}

/// Bézier cell `cell` of a grid face (clamped to the grid), as its index in the face's
/// cells, `(u, v)`'s parameters inside it and the scales from them to the face's.
fn grid_cell(
    u_breaks: &[f64],
    v_breaks: &[f64],
    cell: [usize; 2],
    u: f64,
    v: f64,
) -> (usize, [f64; 2], [f64; 2]) {
    let (i, j) = (
        cell[0].min(u_breaks.len() - 2),
        cell[1].min(v_breaks.len() - 2),
    );
    let ((tu, su), (tv, sv)) = (local(u_breaks, i, u), local(v_breaks, j, v));
    (j * (u_breaks.len() - 1) + i, [tu, tv], [su, sv])
}

/// `x` in cell `i` of `breaks`: its local parameter and the cell's scale `1 / span`.
fn local(breaks: &[f64], i: usize, x: f64) -> (f64, f64) {
    let span = breaks[i + 1] - breaks[i];
    ((x - breaks[i]) / span, 1.0 / span)
}

/// Which parameter a [`FaceLine`] holds fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Held {
    /// The line `u = const`; `v` runs.
    U,
    /// The line `v = const`; `u` runs.
    V,
}

/// An iso-line of a face: point and derivatives at any value of the running parameter, with
/// the contraction across the line done once per Bézier cell it crosses (about a quarter of
/// the work per point after the first). On a line `u = const` these are the numbers of
/// [`FaceSurface::derivs`] and [`FaceSurface::first_derivs`] bit for bit; on `v = const` the
/// same up to rounding (the sums run in the other order).
pub struct FaceLine<'a> {
    face: &'a FaceSurface,
    held: Held,
    /// The held parameter's value.
    at: f64,
    /// The row or column of Bézier cells holding the line.
    cell: usize,
    /// The cell last evaluated (its index in the face's cells) and its contraction across
    /// the line.
    rows: Option<(usize, bezier::Rows)>,
}

/// A Bézier cell contracted across a line, the running parameter's value in it, the cell's
/// scales to the face's parameters and (a quadtree leaf's) origin of its coordinates.
struct OnCell<'r> {
    rows: &'r bezier::Rows,
    run: f64,
    scale: [f64; 2],
    origin: Option<&'r Vector3>,
}

impl FaceLine<'_> {
    /// `(u, v)` at running parameter `x`.
    fn uv(&self, x: f64) -> (f64, f64) {
        match self.held {
            Held::U => (self.at, x),
            Held::V => (x, self.at),
        }
    }

    /// The cell holding `x` contracted across the line; `None` on a subdivided quadtree face.
    fn on_cell(&mut self, x: f64) -> Option<OnCell<'_>> {
        let (u, v) = self.uv(x);
        let held = self.held;
        let contract = |p: &BezierPatch, at: f64| match held {
            Held::U => p.rows_at(at),
            Held::V => p.cols_at(at),
        };
        match &self.face.form {
            FaceForm::Grid {
                u_breaks,
                v_breaks,
                cells,
            } => {
                let cell = match held {
                    Held::U => [self.cell, cell_of(v_breaks, v)],
                    Held::V => [cell_of(u_breaks, u), self.cell],
                };
                let (k, [tu, tv], scale) = grid_cell(u_breaks, v_breaks, cell, u, v);
                let (at, run) = match held {
                    Held::U => (tu, tv),
                    Held::V => (tv, tu),
                };
                if self.rows.as_ref().is_some_and(|(c, _)| *c != k) {
                    self.rows = None;
                }
                let rows = &self
                    .rows
                    .get_or_insert_with(|| (k, contract(&cells[k], at)))
                    .1;
                Some(OnCell {
                    rows,
                    run,
                    scale,
                    origin: None,
                })
            }
            // The quadtree's leaf holding the point (its cap: none), keyed by its address.
            FaceForm::Tree(node) => {
                let subdiv::Found::Leaf {
                    patch,
                    origin,
                    uv,
                    scale,
                } = node.descend(u, v)
                else {
                    return None;
                };
                let (at, run) = match held {
                    Held::U => (uv[0], uv[1]),
                    Held::V => (uv[1], uv[0]),
                };
                let key = patch as *const BezierPatch as usize;
                if self.rows.as_ref().is_some_and(|(c, _)| *c != key) {
                    self.rows = None;
                }
                let rows = &self
                    .rows
                    .get_or_insert_with(|| (key, contract(patch, at)))
                    .1;
                Some(OnCell {
                    rows,
                    run,
                    scale: [scale, scale],
                    origin: Some(origin),
                })
            }
        }
    }

    /// The parameter held and its value.
    pub fn held_at(&self) -> (Held, f64) {
        (self.held, self.at)
    }

    /// Point and derivatives at running parameter `x`.
    pub fn derivs(&mut self, x: f64) -> SurfaceDerivs {
        let held = self.held;
        let Some(c) = self.on_cell(x) else {
            let (u, v) = self.uv(x);
            return self.face.derivs(u, v);
        };
        let d = match held {
            Held::U => BezierPatch::finish_derivs(c.rows, c.run),
            Held::V => BezierPatch::finish_derivs_cols(c.rows, c.run),
        };
        let d = d.scaled(c.scale[0], c.scale[1]);
        match c.origin {
            Some(origin) => SurfaceDerivs {
                point: d.point + origin,
                ..d
            },
            None => d,
        }
    }

    /// Point and first derivatives `(S, S_u, S_v)` at running parameter `x`.
    pub fn first_derivs(&mut self, x: f64) -> (Point3, Vector3, Vector3) {
        let held = self.held;
        let Some(c) = self.on_cell(x) else {
            let (u, v) = self.uv(x);
            return self.face.first_derivs(u, v);
        };
        let (p, du, dv) = match held {
            Held::U => BezierPatch::finish_first(c.rows, c.run),
            Held::V => BezierPatch::finish_first_cols(c.rows, c.run),
        };
        let [su, sv] = c.scale;
        match c.origin {
            Some(origin) => (p + origin, du * su, dv * sv),
            None => (p, du * su, dv * sv),
        }
    }
}

impl FaceSurface {
    /// The corners of `[0,1]²` at extraordinary points (where the parameterisation is
    /// singular): those where the face's subdivision tree ends in a cap.
    pub fn singular_corners(&self) -> Vec<[f64; 2]> {
        match &self.form {
            FaceForm::Tree(node) => node.cap_corners(),
            FaceForm::Grid { .. } => Vec::new(),
        }
    }

    /// Point and derivatives at `(u, v)` in `[0,1]²`.
    pub fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        let (ub, vb) = self.breaks();
        self.derivs_in([cell_of(ub, u), cell_of(vb, v)], u, v)
    }

    /// The lines `u = const` and `v = const` (from 0 to 1) between which the face is one
    /// Bézier cell: only across these may it crease. A quadtree face (Catmull–Clark) is G1
    /// everywhere and has none inside.
    pub fn breaks(&self) -> (&[f64], &[f64]) {
        const WHOLE: [f64; 2] = [0.0, 1.0];
        match &self.form {
            FaceForm::Grid {
                u_breaks, v_breaks, ..
            } => (u_breaks, v_breaks),
            FaceForm::Tree(_) => (&WHOLE, &WHOLE),
        }
    }

    /// As [`FaceSurface::derivs`], taken from the cell `cell` of [`FaceSurface::breaks`]
    /// (`(u, v)` on its sides or inside): on a crease, the side of it that cell lies on.
    pub fn derivs_in(&self, cell: [usize; 2], u: f64, v: f64) -> SurfaceDerivs {
        match &self.form {
            FaceForm::Grid {
                u_breaks,
                v_breaks,
                cells,
            } => {
                let (k, [tu, tv], [su, sv]) = grid_cell(u_breaks, v_breaks, cell, u, v);
                cells[k].derivs(tu, tv).scaled(su, sv)
            }
            FaceForm::Tree(node) => node.derivs(u, v),
        }
    }

    /// Point and derivatives at every `(u, v)` of `us × vs` (`u` outer), passed to `f`: the
    /// numbers [`FaceSurface::derivs`] gives, bit for bit, found faster on a face that is one
    /// Bézier cell (most faces of a subdivision cage).
    pub fn for_each_derivs(
        &self,
        us: &[f64],
        vs: &[f64],
        f: &mut dyn FnMut(f64, f64, &SurfaceDerivs),
    ) {
        let single = match &self.form {
            FaceForm::Grid { cells, .. } if cells.len() == 1 => Some((&cells[0], None)),
            FaceForm::Tree(subdiv::Node::Leaf { patch, origin }) => Some((patch, Some(origin))),
            _ => None,
        };
        match single {
            // One cell over the whole face: its parameters are the face's, its scale 1.
            Some((patch, origin)) => {
                for &u in us {
                    patch.derivs_along_v(u, vs, &mut |k, mut d| {
                        if let Some(o) = origin {
                            d.point += o;
                        }
                        f(u, vs[k], &d)
                    });
                }
            }
            None => {
                for &u in us {
                    for &v in vs {
                        f(u, v, &self.derivs(u, v));
                    }
                }
            }
        }
    }

    /// The iso-line holding `held` at `at`, for [`FaceLine::derivs`] at many points.
    pub fn line(&self, held: Held, at: f64) -> FaceLine<'_> {
        let (ub, vb) = self.breaks();
        FaceLine {
            face: self,
            held,
            at,
            cell: cell_of(if held == Held::U { ub } else { vb }, at),
            rows: None,
        }
    }

    /// The line `u = const` of the face, for [`FaceLine::derivs`] at many `v`.
    pub fn u_line(&self, u: f64) -> FaceLine<'_> {
        self.line(Held::U, u)
    }

    /// Point at `(u, v)` in `[0,1]²`.
    pub fn subs(&self, u: f64, v: f64) -> Point3 {
        match &self.form {
            FaceForm::Grid {
                u_breaks,
                v_breaks,
                cells,
            } => {
                let (i, j) = (cell_of(u_breaks, u), cell_of(v_breaks, v));
                let ((tu, _), (tv, _)) = (local(u_breaks, i, u), local(v_breaks, j, v));
                cells[j * (u_breaks.len() - 1) + i].subs(tu, tv)
            }
            FaceForm::Tree(node) => node.subs(u, v),
        }
    }

    /// Unit normal at `(u, v)`; where the tangent plane degenerates (an extraordinary
    /// point's limit), the normal of nearby points towards the face centre.
    pub fn normal(&self, u: f64, v: f64) -> Option<Vector3> {
        let unit_at = |u, v| {
            let (_, su, sv) = self.first_derivs(u, v);
            unit_normal(&su, &sv)
        };
        unit_at(u, v).or_else(|| {
            NORMAL_PROBES.iter().find_map(|&t| {
                let (uu, vv) = (u + (0.5 - u) * t, v + (0.5 - v) * t);
                unit_at(uu, vv)
            })
        })
    }

    /// Point and unit normal at `(u, v)` from one evaluation (the normal as
    /// [`FaceSurface::normal`] gives it).
    pub fn point_normal(&self, u: f64, v: f64) -> (Point3, Option<Vector3>) {
        let (p, su, sv) = self.first_derivs(u, v);
        let n = unit_normal(&su, &sv).or_else(|| self.normal(u, v));
        (p, n)
    }

    /// Point and first derivatives `(S, S_u, S_v)` at `(u, v)`, equal to those of
    /// [`FaceSurface::derivs`] without computing the second derivatives.
    pub fn first_derivs(&self, u: f64, v: f64) -> (Point3, Vector3, Vector3) {
        match &self.form {
            FaceForm::Grid {
                u_breaks,
                v_breaks,
                cells,
            } => {
                let cell = [cell_of(u_breaks, u), cell_of(v_breaks, v)];
                let (k, [tu, tv], [su, sv]) = grid_cell(u_breaks, v_breaks, cell, u, v);
                let (p, du, dv) = cells[k].first_derivs(tu, tv);
                (p, du * su, dv * sv)
            }
            FaceForm::Tree(node) => node.first_derivs(u, v),
        }
    }

    /// Number of Bézier cells.
    pub fn cell_count(&self) -> usize {
        match &self.form {
            FaceForm::Grid { cells, .. } => cells.len(),
            FaceForm::Tree(node) => node.leaf_count(),
        }
    }

    /// Calls `f` with every cell and its `[u0, u1, v0, v1]` range.
    pub fn for_each_cell(&self, f: &mut dyn FnMut([f64; 4], &BezierPatch)) {
        match &self.form {
            FaceForm::Grid {
                u_breaks,
                v_breaks,
                cells,
            } => {
                let nu = u_breaks.len() - 1;
                for (k, c) in cells.iter().enumerate() {
                    let (i, j) = (k % nu, k / nu);
                    f(
                        [u_breaks[i], u_breaks[i + 1], v_breaks[j], v_breaks[j + 1]],
                        c,
                    );
                }
            }
            FaceForm::Tree(node) => node.for_each_leaf(f),
        }
    }
}

/// Face parameters `(u, v)` at fraction `s` along side `side` (0..3: `v = 0` forwards,
/// `u = 1` forwards, `v = 1` backwards, `u = 0` backwards), the direction half-edges run.
pub fn on_side(side: u8, s: f64) -> (f64, f64) {
    match side {
        0 => (s, 0.0),
        1 => (1.0, s),
        2 => (1.0 - s, 1.0),
        _ => (0.0, 1.0 - s),
    }
}

/// Fractions of the way towards the face centre at which a normal is looked for when the
/// surface is singular at the point asked (relative, dimensionless).
const NORMAL_PROBES: [f64; 4] = [1e-9, 1e-7, 1e-5, 1e-3];

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
        let bbox = extreme_box(&faces);
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

    /// Unit normal on domain face `face` (see [`FaceSurface::normal`]).
    pub fn normal(&self, face: usize, u: f64, v: f64) -> Option<Vector3> {
        self.faces[face].normal(u, v)
    }

    /// `∂S/∂u` on domain face `face`.
    pub fn uder(&self, face: usize, u: f64, v: f64) -> Vector3 {
        self.derivs(face, u, v).su
    }

    /// `∂S/∂v` on domain face `face`.
    pub fn vder(&self, face: usize, u: f64, v: f64) -> Vector3 {
        self.derivs(face, u, v).sv
    }

    /// Bounding box of the surface (mm), located to about 1e-9 of the model size.
    pub fn bbox(&self) -> Aabb {
        self.bbox
    }
}

/// Samples per face side when looking for the extremes of the surface.
const BOX_SAMPLES: usize = 9;
/// Faces whose best sample is refined, per direction.
const BOX_CANDIDATES: usize = 4;
/// Rounds of local refinement around a candidate (each shrinks the search square by 4).
const BOX_ROUNDS: usize = 14;

/// Bounding box of the faces: coarse samples, then a shrinking local search around the best
/// few candidates in each of the six directions.
fn extreme_box(faces: &[FaceSurface]) -> Aabb {
    let n = BOX_SAMPLES;
    let grid = |k: usize| k as f64 / (n - 1) as f64;
    let mut bbox = Aabb::empty();
    // (value, face, u, v) of the best sample per face and direction.
    let mut best: Vec<[(f64, usize, f64, f64); 6]> = Vec::with_capacity(faces.len());
    for (fi, f) in faces.iter().enumerate() {
        let mut b = [(f64::NEG_INFINITY, fi, 0.0, 0.0); 6];
        for j in 0..n {
            for i in 0..n {
                let p = f.subs(grid(i), grid(j));
                bbox.grow(&p);
                for d in 0..6 {
                    let val = if d < 3 { p[d] } else { -p[d - 3] };
                    if val > b[d].0 {
                        b[d] = (val, fi, grid(i), grid(j));
                    }
                }
            }
        }
        best.push(b);
    }
    for d in 0..6 {
        let mut cands: Vec<(f64, usize, f64, f64)> = best.iter().map(|b| b[d]).collect();
        crate::sort::sort_by(&mut cands, |a, b| b.0.total_cmp(&a.0));
        for &(_, fi, mut u, mut v) in cands.iter().take(BOX_CANDIDATES) {
            let f = &faces[fi];
            let mut half = 1.0 / (n - 1) as f64;
            for _ in 0..BOX_ROUNDS {
                let (mut bu, mut bv, mut bval) = (u, v, f64::NEG_INFINITY);
                for a in -2i32..=2 {
                    for c in -2i32..=2 {
                        let uu = (u + half * a as f64 / 2.0).clamp(0.0, 1.0);
                        let vv = (v + half * c as f64 / 2.0).clamp(0.0, 1.0);
                        let p = f.subs(uu, vv);
                        bbox.grow(&p);
                        let val = if d < 3 { p[d] } else { -p[d - 3] };
                        if val > bval {
                            (bu, bv, bval) = (uu, vv, val);
                        }
                    }
                }
                (u, v) = (bu, bv);
                half *= 0.25;
            }
        }
    }
    bbox
}
