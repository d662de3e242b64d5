//! A loaded model: its T-mesh, the surface evaluated from it, and what the reader learnt.
//!
//! Owns: the bundle handed from readers to planners and its summary. Must not: parse bytes
//! (that is `io`) or evaluate (that is `surface`).

pub mod samples;

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
    pub mesh: TMesh,
    pub surface: Surface,
    pub layout: PatchLayout,
}

/// Counts and size of a model, as shown by `tspath info` and the page.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSummary {
    pub name: String,
    pub format: String,
    pub units_read: String,
    pub vertices: usize,
    pub faces: usize,
    pub control_points: usize,
    pub t_junctions: usize,
    pub extraordinary_points: usize,
    pub holes: usize,
    pub patches: usize,
    pub bbox_mm: Aabb,
}

impl Model {
    /// Builds the surface of `mesh` and bundles it.
    pub fn try_new(name: &str, format: &str, units_read: &str, mesh: TMesh) -> Result<Self> {
        let surface = Surface::try_from_tmesh(&mesh)?;
        let layout = PatchLayout::build(&mesh, &surface);
        Ok(Model {
            layout,
            name: name.to_string(),
            format: format.to_string(),
            units_read: units_read.to_string(),
            mesh,
            surface,
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
        let nv = self.mesh.vertex_count();
        ModelSummary {
            name: self.name.clone(),
            format: self.format.clone(),
            units_read: self.units_read.clone(),
            vertices: nv,
            faces: self.mesh.faces().len(),
            control_points: nv,
            t_junctions: self.mesh.t_junctions().len(),
            extraordinary_points: (0..nv as u32)
                .filter(|&v| self.mesh.is_extraordinary(v))
                .count(),
            holes: self.mesh.boundary_loops().saturating_sub(1),
            patches: self.layout.len(),
            bbox_mm: self.surface.bbox(),
        }
    }
}
