//! Step sizes shared by the strategies: the side step between adjacent passes from the
//! scallop limit (Shang et al. 2020, eq. 5–6) and the forward step from the chordal
//! tolerance.

use crate::error::{Error, Result};
use crate::geom::Vector3;
use crate::surface::DiffGeom;

/// Which parameter the cutting moves run along.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedDir {
    /// Passes are lines `v = const`, cutting along `u`; the side step is in `v`.
    AlongU,
    /// Passes are lines `u = const`, cutting along `v`; the side step is in `u`.
    AlongV,
}

impl FeedDir {
    /// The direction across: along the other parameter.
    pub fn other(self) -> FeedDir {
        match self {
            FeedDir::AlongU => FeedDir::AlongV,
            FeedDir::AlongV => FeedDir::AlongU,
        }
    }
}

/// Physical side step `g` (mm) between two passes of a ball of radius `r` (mm) that leaves
/// scallops of height `h` (mm) on a surface whose normal curvature across the feed is
/// `kappa` (1/mm, sign as in [`DiffGeom`]: negative where convex towards the tool).
///
/// Eq. 5 of Shang et al.: `g = sqrt(8 h r R / (R ± r))`, written with curvature so that the
/// flat case is the limit: `g = sqrt(8 h r / (1 − r·kappa))`.
pub fn side_step(h: f64, r: f64, kappa: f64) -> Result<f64> {
    let denom = 1.0 - r * kappa;
    if !(denom > 0.0) {
        return Err(Error::Degenerate {
            location: "side step".into(),
            message: format!(
                "the surface is concave with radius {:.4} mm, smaller than the tool radius {r} mm: the ball cannot reach it",
                1.0 / kappa
            ),
        });
    }
    Ok((8.0 * h * r / denom).sqrt())
}

/// Largest `r·kappa` (concave) the planner's side step takes at face value: tighter than
/// that, eq. 5 is read with this value, a smaller step than it would give (where the
/// surface is tighter than the ball, the ball cannot reach the bottom anyway; that area is
/// found and reported as rest material).
pub const MAX_CONCAVE_RK: f64 = 0.75;

/// [`side_step`] with the concave curvature clamped to [`MAX_CONCAVE_RK`]` / r`: never an
/// error, and never more than twice the flat step.
pub fn side_step_clamped(h: f64, r: f64, kappa: f64) -> f64 {
    let k = kappa.min(MAX_CONCAVE_RK / r);
    (8.0 * h * r / (1.0 - r * k)).sqrt()
}

/// Scallop height (mm) predicted by eq. 5 for a physical side step `g` (its inverse).
pub fn predicted_scallop(g: f64, r: f64, kappa: f64) -> f64 {
    g * g * (1.0 - r * kappa) / (8.0 * r)
}

/// Normal curvature (1/mm) across the feed direction at a point.
pub fn cross_curvature(dg: &DiffGeom, dir: FeedDir) -> f64 {
    match dir {
        // Perpendicular to S_u in the tangent plane: (du, dv) = (−F, E).
        FeedDir::AlongU => dg.normal_curvature(-dg.f, dg.e),
        // Perpendicular to S_v: (du, dv) = (G, −F).
        FeedDir::AlongV => dg.normal_curvature(dg.g, -dg.f),
    }
}

/// Parametric side step giving physical distance `g` (mm) between adjacent iso-lines
/// (eq. 6): the distance between lines `v` and `v + Δv` is `Δv·sqrt(EG − F²)/sqrt(E)`.
pub fn param_side_step(dg: &DiffGeom, dir: FeedDir, g: f64) -> f64 {
    let det = dg.metric_det().max(0.0).sqrt();
    match dir {
        FeedDir::AlongU => g * dg.e.sqrt() / det,
        FeedDir::AlongV => g * dg.g.sqrt() / det,
    }
}

/// Parametric distance between adjacent lines converted back to mm at a point.
pub fn physical_side_step(dg: &DiffGeom, dir: FeedDir, dparam: f64) -> f64 {
    let det = dg.metric_det().max(0.0).sqrt();
    match dir {
        FeedDir::AlongU => dparam * det / dg.e.sqrt(),
        FeedDir::AlongV => dparam * det / dg.g.sqrt(),
    }
}

/// Curvature (1/mm) of a curve with first and second derivatives `c1`, `c2`:
/// `|c1 × c2| / |c1|³`; 0 where the curve stops (`c1` nil).
pub fn curve_curvature(c1: &Vector3, c2: &Vector3) -> f64 {
    let speed = c1.norm();
    if speed > 0.0 {
        c1.cross(c2).norm() / (speed * speed * speed)
    } else {
        0.0
    }
}

/// Forward step length (mm) along a curve of curvature `k` (1/mm) whose chord deviates from
/// the curve by at most `chordal` (mm): `sqrt(8·chordal/k)` (the sagitta formula).
pub fn chord_step(chordal: f64, k: f64) -> f64 {
    if k > 0.0 {
        (8.0 * chordal / k).sqrt()
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_limit_matches_circle_geometry() {
        // On a plane the exact scallop of step g is r − sqrt(r² − g²/4); eq. 5 is its
        // small-h expansion, within 1% at h/r = 0.01.
        let (r, h) = (1.0, 0.01);
        let g = side_step(h, r, 0.0).unwrap();
        let exact = r - (r * r - g * g / 4.0).sqrt();
        assert!((exact - h).abs() / h < 0.01, "exact {exact} vs {h}");
    }

    #[test]
    fn convex_allows_smaller_step_than_concave() {
        let (r, h) = (0.5, 0.005);
        let convex = side_step(h, r, -0.1).unwrap();
        let flat = side_step(h, r, 0.0).unwrap();
        let concave = side_step(h, r, 0.1).unwrap();
        assert!(convex < flat && flat < concave);
        // Eq. 5 with R = 10 mm: convex sqrt(8hrR/(R + r)).
        let expect = (8.0 * h * r * 10.0 / (10.0 + r)).sqrt();
        assert!((convex - expect).abs() < 1e-15);
        assert!((predicted_scallop(convex, r, -0.1) - h).abs() < 1e-15);
    }

    #[test]
    fn too_tight_concavity_is_an_error_or_clamped() {
        assert!(side_step(0.01, 1.0, 1.5).is_err());
        // Clamped: the step at r·kappa = 0.75, twice the flat one, whatever tighter.
        let flat = side_step(0.01, 1.0, 0.0).unwrap();
        for k in [0.75, 1.0, 1.5, 1e6] {
            assert!((side_step_clamped(0.01, 1.0, k) - 2.0 * flat).abs() < 1e-12);
        }
        assert_eq!(
            side_step_clamped(0.01, 1.0, 0.3),
            side_step(0.01, 1.0, 0.3).unwrap()
        );
    }
}
