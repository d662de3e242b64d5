//! A loaded model: its T-mesh, the surface evaluated from it, and what the reader learnt.
//!
//! Owns: the bundle handed from readers to planners and its summary. Must not: parse bytes
//! (that is `io`) or evaluate (that is `surface`).

pub mod samples;
pub mod setup;

use crate::error::Result;
use crate::geom::Aabb;
use crate::layout::PatchLayout;
use crate::surface::Surface;
use crate::tmesh::TMesh;
use serde::{Deserialize, Serialize};

/// A model ready for planning.
#[derive(Debug, Clone)]
pub struct Model {
    pub name: String,
    /// File format it came from (`json`, `obj`, `tsm`, or `sample`).
    pub format: String,
    /// Unit the file declared; coordinates are millimetres whatever it was.
    pub units_read: String,
    /// How the model was placed ([`setup::ImportSetup::describe`]): "as modelled" unless
    /// set up.
    pub placement: String,
    /// The stock block (mm, in the model's coordinates, after placement): the part's box
    /// unless set up with stock beyond it.
    pub stock: Aabb,
    /// Where the program's zero is ([`setup::ProgramZero::describe`]).
    pub program_zero: String,
    /// What the reader could not apply (OBJ subdivision tags), for a person: every plan of
    /// the model lists these among its problems.
    pub warnings: Vec<String>,
    pub mesh: TMesh,
    pub surface: Surface,
    pub layout: PatchLayout,
    /// The smallest concave radius, found once when first asked for.
    concave: std::sync::OnceLock<Option<ConcaveSpot>>,
    /// The side the tool works from, found once when first asked for.
    side: std::sync::OnceLock<f64>,
    /// The distance sets planning built ([`Model::surface_distance`]).
    pub(crate) distance_sets: crate::plan::distance::DistanceSets,
}

/// Where the surface is most tightly concave towards the tool (on the side
/// [`Model::tool_side`] says).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConcaveSpot {
    /// The smallest concave radius of curvature found (mm): the largest ball-end radius
    /// that fits everywhere the surface is smooth.
    pub radius_mm: f64,
    /// Where (mm).
    pub at_mm: [f64; 3],
}

/// Samples per face side deciding the side the tool works from.
const SIDE_SAMPLES: usize = 4;

/// Samples per face side for the smallest concave radius, evenly, plus the same again
/// crowded towards the sides (curvature peaks at folded corners within 1% of a face).
const CONCAVE_SAMPLES: usize = 9;
/// Distances from the sides of the crowded samples (of a face side's length): written out,
/// as `0.1f64.powi(k)` rounds differently where the compiler folds it (release builds) and
/// where it is computed (debug builds), and the smallest radius found moved with it.
const CONCAVE_CROWDED: [f64; CONCAVE_SAMPLES - 1] =
    [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8];

/// Counts and size of a model, as shown by `tspath info` and the page.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSummary {
    pub name: String,
    pub format: String,
    pub units_read: String,
    /// How the model was placed: "as modelled", or the unit, scale, up axis, turn and
    /// table placement applied.
    pub placement: String,
    /// The stock block (mm): the part's box unless set up with stock beyond it.
    pub stock_mm: Aabb,
    /// Where the program's zero (X0 Y0 Z0 of the work offset) is, in words.
    pub program_zero: String,
    /// What the reader could not apply ([`Model::warnings`]).
    pub warnings: Vec<String>,
    pub vertices: usize,
    pub faces: usize,
    pub control_points: usize,
    pub t_junctions: usize,
    pub extraordinary_points: usize,
    pub holes: usize,
    /// The cage's subdivision tags in words ("3 sharp crease edges, 1 corner, ..."); empty
    /// when it has none.
    pub subdivision_tags: String,
    pub patches: usize,
    pub bbox_mm: Aabb,
    /// The smallest concave radius (mm) and where: the largest ball that reaches everywhere
    /// the surface is smooth. `None` where nothing is concave.
    pub smallest_concave_radius: Option<ConcaveSpot>,
}

impl Model {
    /// Builds the surface of `mesh` and bundles it.
    pub fn try_new(name: &str, format: &str, units_read: &str, mesh: TMesh) -> Result<Self> {
        let surface = Surface::try_from_tmesh(&mesh)?;
        let layout = PatchLayout::build(&mesh, &surface);
        Ok(Model {
            layout,
            stock: surface.bbox(),
            program_zero: setup::ProgramZero::Model.describe(),
            warnings: Vec::new(),
            name: name.to_string(),
            format: format.to_string(),
            units_read: units_read.to_string(),
            placement: "as modelled".into(),
            mesh,
            surface,
            concave: std::sync::OnceLock::new(),
            side: std::sync::OnceLock::new(),
            distance_sets: Default::default(),
        })
    }

    /// As [`Model::try_new`], the mesh placed by `setup` first, its file having said its
    /// unit (`declared_mm`, mm per unit) or not: scaled and turned, then (if asked) moved so
    /// the surface's lowest point is at Z 0 (the surface is built again for that).
    pub fn try_new_placed(
        name: &str,
        format: &str,
        units_read: &str,
        mesh: TMesh,
        setup: &setup::ImportSetup,
        declared_mm: Option<f64>,
    ) -> Result<Self> {
        let factor = setup.factor(declared_mm)?;
        let turned = factor != 1.0 || setup.up != setup::Up::Z || setup.rotate_deg != 0;
        let mesh = if turned {
            setup.apply(&mesh, factor)?
        } else {
            mesh
        };
        let mut m = Model::try_new(name, format, units_read, mesh)?;
        // On the table, then the zero: one shift (a translation moves the box with it).
        let part = m.surface.bbox();
        let table = if setup.on_table { -part.min[2] } else { 0.0 };
        let on_table = Aabb {
            min: [part.min[0], part.min[1], part.min[2] + table],
            max: [part.max[0], part.max[1], part.max[2] + table],
        };
        let stock = setup::stock_box(&on_table, setup);
        let zero = setup.zero.point(&stock);
        let shift = crate::geom::Vector3::new(-zero.x, -zero.y, table - zero.z);
        if shift != crate::geom::Vector3::zeros() {
            let mesh = setup::shifted(&m.mesh, shift)?;
            m = Model::try_new(name, format, units_read, mesh)?;
        }
        m.stock = Aabb {
            min: [0, 1, 2].map(|k| stock.min[k] - zero[k]),
            max: [0, 1, 2].map(|k| stock.max[k] - zero[k]),
        };
        m.placement = setup.describe(declared_mm.is_some());
        m.program_zero = setup.zero.describe();
        Ok(m)
    }

    /// The same surface cut into the patches of `layout` (a strategy's own rectangles).
    pub fn with_layout(&self, layout: PatchLayout) -> Model {
        Model {
            name: self.name.clone(),
            format: self.format.clone(),
            units_read: self.units_read.clone(),
            placement: self.placement.clone(),
            stock: self.stock,
            program_zero: self.program_zero.clone(),
            warnings: self.warnings.clone(),
            mesh: self.mesh.clone(),
            surface: self.surface.clone(),
            layout,
            concave: self.concave.clone(),
            side: self.side.clone(),
            // Tessellations follow the layout's patches: none are shared.
            distance_sets: Default::default(),
        }
    }

    /// The side of the surface a tool machines: +1 where the normal `S_u × S_v` points to,
    /// −1 for the other. A closed surface is machined from outside (the side its normal
    /// points to when the enclosed volume comes out positive); an open one from the side
    /// that faces up on the whole (the area-weighted mean of the normal's z), as a part
    /// lies on the table. Found once, then remembered.
    pub fn tool_side(&self) -> f64 {
        *self.side.get_or_init(|| {
            let n = SIDE_SAMPLES;
            let (mut volume, mut up) = (0.0, 0.0);
            let ts: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) / n as f64).collect();
            for face in self.surface.faces() {
                face.for_each_derivs(&ts, &ts, &mut |_, _, d| {
                    let a = d.su.cross(&d.sv);
                    volume += d.point.coords.dot(&a);
                    up += a.z;
                });
            }
            let closed = self.mesh.boundary_loops() == 0;
            let s = if closed { volume } else { up };
            if s < 0.0 {
                -1.0
            } else {
                1.0
            }
        })
    }

    /// The smallest concave radius of the surface, sampled on every face (evenly and
    /// densely near its sides); `None` where nothing is concave. C0 creases are not
    /// curvature and are not seen here. Found once, then remembered.
    pub fn smallest_concave_radius(&self) -> Option<ConcaveSpot> {
        *self.concave.get_or_init(|| {
            let n = CONCAVE_SAMPLES;
            let even = (0..n).map(|k| k as f64 / (n - 1) as f64);
            let crowded = CONCAVE_CROWDED.iter().flat_map(|&e| [e, 1.0 - e]);
            let ts: Vec<f64> = even.chain(crowded).collect();
            let mut best: Option<ConcaveSpot> = None;
            let flip = self.tool_side() < 0.0;
            for face in self.surface.faces() {
                face.for_each_derivs(&ts, &ts, &mut |_, _, d| {
                    let Some(g) = crate::surface::DiffGeom::try_from_derivs(d) else {
                        return;
                    };
                    let g = if flip { g.flipped() } else { g };
                    let (_, k_hi) = g.principal();
                    if !(k_hi > 0.0 && k_hi.is_finite()) {
                        return;
                    }
                    let radius = 1.0 / k_hi;
                    if best.is_none_or(|b| radius < b.radius_mm) {
                        best = Some(ConcaveSpot {
                            radius_mm: radius,
                            at_mm: [d.point.x, d.point.y, d.point.z],
                        });
                    }
                });
            }
            best
        })
    }

    /// Watertight triangles within `chordal_mm` of the surface, with patch ids.
    pub fn tessellate(&self, chordal_mm: f64) -> crate::surface::tessellate::Tessellation {
        crate::surface::tessellate::tessellate(&self.mesh, &self.surface, &self.layout, chordal_mm)
    }

    /// Surface positions of the extraordinary points (mm), in vertex order.
    pub fn extraordinary_positions(&self) -> Vec<crate::geom::Point3> {
        let index: std::collections::HashMap<u32, usize> = self
            .surface
            .faces()
            .iter()
            .enumerate()
            .map(|(i, f)| (f.mesh_face, i))
            .collect();
        (0..self.mesh.vertex_count() as u32)
            .filter(|&v| self.mesh.is_extraordinary(v))
            .filter_map(|v| {
                self.mesh.outgoing(v).into_iter().find_map(|h| {
                    let e = self.mesh.he(h);
                    let &fi = index.get(&e.face)?;
                    let face = &self.mesh.faces()[e.face as usize];
                    let s = e.offset
                        / if e.side % 2 == 0 {
                            face.width
                        } else {
                            face.height
                        };
                    let (u, v) = crate::surface::on_side(e.side, s);
                    Some(self.surface.subs(fi, u, v))
                })
            })
            .collect()
    }

    /// Counts and bounding box.
    pub fn summary(&self) -> ModelSummary {
        ModelSummary {
            smallest_concave_radius: self.smallest_concave_radius(),
            ..self.summary_without_concave()
        }
    }

    /// [`Model::summary`] without looking for the smallest concave radius (`None` there):
    /// quick, where that search samples every face (0.6 s in wasm for 10 000 faces), for a
    /// page that shows the rest first.
    pub fn summary_without_concave(&self) -> ModelSummary {
        let nv = self.mesh.vertex_count();
        ModelSummary {
            name: self.name.clone(),
            format: self.format.clone(),
            units_read: self.units_read.clone(),
            placement: self.placement.clone(),
            stock_mm: self.stock,
            program_zero: self.program_zero.clone(),
            warnings: self.warnings.clone(),
            vertices: nv,
            faces: self.mesh.faces().len(),
            control_points: nv,
            t_junctions: self.mesh.t_junctions().len(),
            extraordinary_points: (0..nv as u32)
                .filter(|&v| self.mesh.is_extraordinary(v))
                .count(),
            holes: self.mesh.boundary_loops().saturating_sub(1),
            subdivision_tags: self.mesh.tags().describe(),
            patches: self.layout.len(),
            bbox_mm: self.surface.bbox(),
            smallest_concave_radius: None,
        }
    }
}
