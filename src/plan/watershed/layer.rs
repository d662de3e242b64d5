//! The watershed strategies' regions and rectangles as triangles and segments, for drawing
//! over the surface (the page's "Regions and rectangles" layer; the 3D view and its 2D
//! fallback both project these points).
//!
//! Every rectangle (a patch of the plan's layout) is filled with a small grid of triangles
//! on the surface, each tagged with its rectangle's region kind (background, convex,
//! concave); its four sides are drawn as polylines on the surface; an arrow in its middle
//! points along its passes (the direction eq. 21–22 chose). Coordinates are `f32`, mm.
//!
//! Owns: flattening the rectangles. Must not: plan anything or decide how it is drawn.

use crate::geom::Point3;
use crate::model::Model;
use crate::plan::corners::Crossfeed;

/// Floats per segment: two points of three coordinates.
pub const SEGMENT_FLOATS: usize = 6;
/// Floats per triangle: three points of three coordinates.
pub const TRIANGLE_FLOATS: usize = 9;
/// Quads per side of a rectangle's fill (each two triangles), and segments per side of its
/// outline: enough to follow a curved patch at the size it is drawn.
pub const FILL_STEPS: usize = 8;
/// The arrow's shaft spans this share of its rectangle's side along the passes (centred).
const ARROW_SHARE: f64 = 0.5;
/// The arrow's head: its two barbs reach back this share of the shaft, at this share of
/// the shaft's length to either side.
const HEAD_BACK: f64 = 0.3;
const HEAD_SIDE: f64 = 0.15;

/// What a rectangle's fill is tagged with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum FillKind {
    /// Not part of a feature region (or the multi-rectangle baseline, which has none).
    Background = 0,
    Convex = 1,
    Concave = 2,
}

/// The rectangles of a watershed plan as flat arrays.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Layer {
    /// `2 FILL_STEPS²` triangles per rectangle (in patch order), `x y z` per corner (mm).
    pub fills: Vec<f32>,
    /// Per fill triangle, its rectangle's [`FillKind`] as a byte.
    pub fill_kinds: Vec<u8>,
    /// `4 FILL_STEPS` segments per rectangle along its sides (mm).
    pub outlines: Vec<f32>,
    /// Per rectangle three segments: the shaft through its middle along the passes and the
    /// head's two barbs (mm).
    pub arrows: Vec<f32>,
}

impl Layer {
    /// The rectangles of `cut` (the model with the plan's layout, one patch per rectangle),
    /// each tagged `kinds[k]` and with passes stepping `crossfeeds[k]`.
    pub fn of(cut: &Model, kinds: &[FillKind], crossfeeds: &[Crossfeed]) -> Layer {
        let n = cut.layout.patches.len();
        let steps = FILL_STEPS;
        let mut layer = Layer {
            fills: Vec::with_capacity(n * 2 * steps * steps * TRIANGLE_FLOATS),
            fill_kinds: Vec::with_capacity(n * 2 * steps * steps),
            outlines: Vec::with_capacity(n * 4 * steps * SEGMENT_FLOATS),
            arrows: Vec::with_capacity(n * 3 * SEGMENT_FLOATS),
        };
        for (k, patch) in cut.layout.patches.iter().enumerate() {
            let at = |u: f64, v: f64| patch.subs(&cut.surface, u, v);
            let t = |i: usize| i as f64 / steps as f64;
            let grid: Vec<Point3> = (0..=steps)
                .flat_map(|j| (0..=steps).map(move |i| (i, j)))
                .map(|(i, j)| at(t(i), t(j)))
                .collect();
            let g = |i: usize, j: usize| &grid[j * (steps + 1) + i];
            let kind = kinds.get(k).copied().unwrap_or(FillKind::Background) as u8;
            for j in 0..steps {
                for i in 0..steps {
                    push(&mut layer.fills, &[g(i, j), g(i + 1, j), g(i + 1, j + 1)]);
                    push(&mut layer.fills, &[g(i, j), g(i + 1, j + 1), g(i, j + 1)]);
                    layer.fill_kinds.extend([kind, kind]);
                }
            }
            for s in 0..steps {
                push(&mut layer.outlines, &[g(s, 0), g(s + 1, 0)]);
                push(&mut layer.outlines, &[g(steps, s), g(steps, s + 1)]);
                push(&mut layer.outlines, &[g(s + 1, steps), g(s, steps)]);
                push(&mut layer.outlines, &[g(0, s + 1), g(0, s)]);
            }
            // The arrow in the rectangle's parameters, along the passes: crossfeed U steps
            // in u, so the passes run along v.
            let along_v = crossfeeds.get(k) == Some(&Crossfeed::U);
            let pt = |a: f64, c: f64| if along_v { at(c, a) } else { at(a, c) };
            let (lo, hi) = (0.5 - ARROW_SHARE / 2.0, 0.5 + ARROW_SHARE / 2.0);
            let back = hi - HEAD_BACK * ARROW_SHARE;
            let side = HEAD_SIDE * ARROW_SHARE;
            let tip = pt(hi, 0.5);
            push(&mut layer.arrows, &[&pt(lo, 0.5), &tip]);
            push(&mut layer.arrows, &[&pt(back, 0.5 - side), &tip]);
            push(&mut layer.arrows, &[&pt(back, 0.5 + side), &tip]);
        }
        layer
    }

    /// Number of rectangles drawn.
    pub fn rectangle_count(&self) -> usize {
        self.arrows.len() / (3 * SEGMENT_FLOATS)
    }
}

fn push(out: &mut Vec<f32>, points: &[&Point3]) {
    for p in points {
        out.extend_from_slice(&[p.x as f32, p.y as f32, p.z as f32]);
    }
}
