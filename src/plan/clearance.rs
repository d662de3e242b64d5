//! Clearance of the tool above its flutes: the shank and the holder as flat-ended cylinders
//! tested exactly against a tessellation of the model through a bounding-volume hierarchy
//! (see [`super::distance`]), each grown by that tessellation's measured deviation from the
//! surface.
//!
//! Owns: which tessellations stand for the model and by how much the cylinders grow for
//! them. Must not: choose axes (that is [`super::axis`]) or know about moves.

use super::distance::SurfaceDistance;
use super::PlanOptions;
use crate::geom::{Point3, Vector3};
use crate::model::Model;

/// Chordal tolerance of the tessellation tested against a cylinder, in its radii: the
/// cylinder grows by about this much, so a thin shank is tested against fine triangles and
/// the wide holder against coarse ones.
const CHORDAL_RADII: f64 = 0.05;
/// Finest and coarsest chordal tolerance, as shares of the model's diagonal (the triangle
/// count of a large model at a thin shank's tolerance stays bounded; a wide holder's margin
/// stays small beside the model).
const MIN_CHORDAL_SHARE: f64 = 2e-4;
const MAX_CHORDAL_SHARE: f64 = 2.5e-3;
/// The holder gets its own, coarser tessellation only when it is at least this many times
/// coarser than the shank's.
const OWN_HOLDER_SET: f64 = 2.0;

/// The model as seen by the shank and by the holder.
pub struct Clearance {
    shank: SurfaceDistance,
    /// `None`: the holder is tested against the shank's triangles.
    holder: Option<SurfaceDistance>,
}

impl Clearance {
    /// Tessellates `model` for the shank and holder of `opts`.
    pub fn new(model: &Model, opts: &PlanOptions) -> Clearance {
        let size = model.surface.bbox().diagonal();
        let chordal = |radius: f64| {
            (CHORDAL_RADII * radius)
                .min(MAX_CHORDAL_SHARE * size)
                .max(MIN_CHORDAL_SHARE * size)
        };
        let fine = chordal(opts.shank_radius());
        let coarse = chordal(opts.holder_radius_mm).max(fine);
        let shank = SurfaceDistance::new(model, fine);
        let holder = (coarse > OWN_HOLDER_SET * fine).then(|| SurfaceDistance::new(model, coarse));
        Clearance { shank, holder }
    }

    fn holder(&self) -> &SurfaceDistance {
        self.holder.as_ref().unwrap_or(&self.shank)
    }

    /// The safety margin: the larger deviation of the two tessellations from the surface
    /// (mm), by which shank and holder are grown.
    pub fn gap_mm(&self) -> f64 {
        self.shank.tolerance_mm.max(self.holder().tolerance_mm)
    }

    /// A point of the model inside the shank (above the flutes) or the holder of a tool
    /// with its ball centre at `c` along unit `axis`, if there is one.
    pub fn hit(&self, c: &Point3, axis: &Vector3, opts: &PlanOptions) -> Option<Point3> {
        let (f, ls, lh) = (
            opts.flute_length(),
            opts.shank_length_mm,
            opts.holder_length_mm,
        );
        grown_hit(&self.shank, c, axis, (f, ls), opts.shank_radius())
            .or_else(|| grown_hit(self.holder(), c, axis, (ls, ls + lh), opts.holder_radius_mm))
    }

    /// True if the shank and holder at `c` along `axis` are clear of the model.
    pub fn clear(&self, c: &Point3, axis: &Vector3, opts: &PlanOptions) -> bool {
        self.hit(c, axis, opts).is_none()
    }
}

/// A triangle point inside the cylinder from `c + axis·a0` to `c + axis·a1` of radius `rad`,
/// the cylinder grown at its ends and side by the triangles' deviation from the surface.
fn grown_hit(
    set: &SurfaceDistance,
    c: &Point3,
    axis: &Vector3,
    (a0, a1): (f64, f64),
    rad: f64,
) -> Option<Point3> {
    let g = set.tolerance_mm;
    set.cylinder_hit(c, axis, (a0 - g, a1 + g), rad + g)
}
