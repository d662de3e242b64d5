//! The curve's cells and spanning tree as line segments, for drawing over the surface (the
//! page's "Cells and tree" layer; the 3D view and its 2D fallback both project these points).
//!
//! A cell's outline is its four grid edges, each a straight segment between the contact
//! points of two grid vertices, in the cell's loop order. A tree link is a segment from the
//! centre of one cell to the centre of the other (the mean of each cell's four contact
//! points). Coordinates are `f32` (drawing needs no more), `x y z x y z` per segment, mm.
//!
//! Owns: flattening a [`Curve`]. Must not: plan anything or decide how it is drawn.

use super::Curve;
use crate::geom::{Point3, Vector3};

/// Floats per segment: two points of three coordinates.
pub const SEGMENT_FLOATS: usize = 6;

/// A [`Curve`]'s cells and tree as flat arrays of segments.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Layer {
    /// Four segments per cell (in [`Curve::cells`] order): corner 0 to 1, 1 to 2, 2 to 3,
    /// 3 to 0, between the contact points of the cell's corners (mm).
    pub cells: Vec<f32>,
    /// One segment per tree link (in [`Curve::tree`] order): from the centre of the link's
    /// cell `a` to the centre of its cell `b` (mm).
    pub tree: Vec<f32>,
    /// Per tree link: 1 if it joins cells of two patches across the side they share, else 0.
    pub across: Vec<u8>,
    /// Where the first loop starts: the contact point of its first vertex (mm).
    pub start_mm: Option<[f64; 3]>,
}

impl Layer {
    /// The cells and tree of `curve`.
    pub fn of(curve: &Curve) -> Layer {
        let at = |v: u32| curve.vertices[v as usize].cc;
        let mut cells = Vec::with_capacity(4 * SEGMENT_FLOATS * curve.cells.len());
        for cell in &curve.cells {
            let c = cell.corners;
            for k in 0..4 {
                push_segment(&mut cells, &at(c[k]), &at(c[(k + 1) % 4]));
            }
        }
        let mut tree = Vec::with_capacity(SEGMENT_FLOATS * curve.tree.len());
        let mut across = Vec::with_capacity(curve.tree.len());
        for &k in &curve.tree {
            let link = &curve.links[k];
            push_segment(
                &mut tree,
                &cell_centre(curve, link.a as usize),
                &cell_centre(curve, link.b as usize),
            );
            let (pa, pb) = (
                curve.cells[link.a as usize].patch,
                curve.cells[link.b as usize].patch,
            );
            across.push(u8::from(pa != pb));
        }
        let start_mm = curve.loops.first().and_then(|l| l.first()).map(|&v| {
            let p = at(v);
            [p.x, p.y, p.z]
        });
        Layer {
            cells,
            tree,
            across,
            start_mm,
        }
    }

    /// Number of cells drawn.
    pub fn cell_count(&self) -> usize {
        self.cells.len() / (4 * SEGMENT_FLOATS)
    }

    /// Number of tree links drawn.
    pub fn link_count(&self) -> usize {
        self.tree.len() / SEGMENT_FLOATS
    }
}

/// The centre of cell `cell` of `curve`: the mean of its four corners' contact points (mm).
pub fn cell_centre(curve: &Curve, cell: usize) -> Point3 {
    let c = curve.cells[cell].corners;
    let sum = c
        .iter()
        .map(|&v| curve.vertices[v as usize].cc.coords)
        .fold(Vector3::zeros(), |a, b| a + b);
    Point3::from(sum / 4.0)
}

fn push_segment(out: &mut Vec<f32>, a: &Point3, b: &Point3) {
    out.extend_from_slice(&[
        a.x as f32, a.y as f32, a.z as f32, b.x as f32, b.y as f32, b.z as f32,
    ]);
}
