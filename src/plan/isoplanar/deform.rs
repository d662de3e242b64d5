//! The deformation of the cutter-location (CL) surface that makes constant slice spacing
//! leave a near-constant scallop (Yuan & Shao 2012, eq. 2–10, after Kim & Yang 2005).
//!
//! At every vertex of the CL mesh the ratio `ε ≥ 1` says how much denser than on a flat
//! floor the planes must lie there; the deformed coordinate `x' = X'(x)` integrates the
//! largest ratio over each thin slab of `x` (increasing, so the deformed mesh never folds).
//! Slicing the deformed CL mesh with planes `x' = const` at the flat-floor spacing
//! `d_w = 2 sqrt(2 r h − h²)` (eq. 2) gives planes that crowd where the surface is steep or
//! concave.
//!
//! The ratio (eq. 6, illegible in the paper; the consistent form): a ball of radius `r`
//! leaves scallop `h` between passes whose ball centres lie `s = sqrt(8 r h (1 − r κ))`
//! apart on the CL surface, `κ` the design surface's normal curvature across the pass
//! (negative where convex towards the tool; concave curvature clamped as the other planners
//! clamp it, [`stepover::MAX_CONCAVE_RK`]). Across a plane `x = const` the CL surface climbs
//! in `x` fastest along `c`, the tangent perpendicular to the pass, and a step `s` along it
//! advances `x` by `s |c_x|`, `|c_x| = sqrt((1 + q²) / (1 + p² + q²))` with the slopes
//! `p = ∂z/∂x`, `q = ∂z/∂y` (exact: `c` is the surface gradient of `x`). So
//! `ε = d_w / (s |c_x|) = sqrt((1 + p² + q²) / (1 + q²)) / sqrt(1 − r κ)`: a flat horizontal
//! floor gives 1, a plane inclined by `θ` about `y` gives `1 / cos θ`. The paper's shear
//! form (eq. 9), `ε = ε_x cos φ + ε_y sin |φ|` with `ε_x = 1 / (cos θ sqrt(1 − r κ))`,
//! `θ = atan p`, `φ = atan q`, is offered as [`RatioForm::Shear`]: on a plane sloping only
//! in `y` by 45° it gives 1.71 where 1 is exact, so its planes come out denser than needed.
//!
//! Where the paper (and Kim & Yang) integrate the ratio along every row `y` of a height grid
//! on its own, rows that cross a steep wall accumulate more than their neighbours and the
//! level sets turn away from the planes; in a cavity's corner they ran along the wall's
//! contours, two to three times as far apart as the scallop allows, and at the far edge rows
//! ended up to a spacing short of it (keycap-concave, r 0.5 mm, h 0.005 mm: 0.0173 mm left).
//! Here each slab takes the largest ratio over all of it, every sheet of the surface
//! included (a height grid sees only the top): the passes stay in planes `x = const`, as
//! iso-planar passes are, and the slopes come from the exact normals, which the height
//! grid's central differences (eq. 4, 8) under-read on walls a few nodes wide.
//!
//! Owns: the slicing frame, the ratio and the deformed coordinate. Must not: slice, or
//! choose which points are cut.

use crate::geom::{Point3, Vector3};
use crate::plan::stepover;

/// The slicing frame: `x` across the planes (their normal, in the XY plane), `y` along
/// them, `z` up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub x: Vector3,
    pub y: Vector3,
}

impl Frame {
    /// The frame whose planes' normal makes `angle_deg` with +X in the XY plane.
    pub fn new(angle_deg: f64) -> Self {
        let a = angle_deg.to_radians();
        Frame {
            x: Vector3::new(a.cos(), a.sin(), 0.0),
            y: Vector3::new(-a.sin(), a.cos(), 0.0),
        }
    }

    /// `(x, y, z)` of a point in the frame (mm).
    pub fn coords(&self, p: &Point3) -> [f64; 3] {
        [p.coords.dot(&self.x), p.coords.dot(&self.y), p.z]
    }
}

/// Which form of the deformation ratio.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RatioForm {
    /// `sqrt((1 + p² + q²) / (1 + q²)) / sqrt(1 − r κ)`: exact for planes.
    #[default]
    ExactPlane,
    /// Eq. 9 of the paper: `ε_x cos φ + ε_y sin |φ|` (conservative).
    Shear,
}

/// Steepest slope the ratio follows (degrees): steeper walls are sliced as if this steep
/// (their passes would otherwise pile up without bound); the pass check fills them in.
pub const MAX_SLOPE_DEG: f64 = 89.5;

/// The largest ratio, [`MAX_SLOPE_DEG`] with the tightest concave curvature.
pub fn max_ratio() -> f64 {
    1.0 / (MAX_SLOPE_DEG.to_radians().cos() * (1.0 - stepover::MAX_CONCAVE_RK).sqrt())
}

/// `1 / sqrt(1 − r κ)` with the concave curvature clamped (dimensionless): how much denser
/// than on a plane passes must lie on the CL surface where the design surface's normal
/// curvature across them is `κ` (1/mm, negative where convex towards the tool).
pub fn curvature_factor(r: f64, kappa: f64) -> f64 {
    let k = kappa.min(stepover::MAX_CONCAVE_RK / r);
    1.0 / (1.0 - r * k).sqrt()
}

/// The deformation ratio at a point with CL-surface slopes `p = ∂z/∂x`, `q = ∂z/∂y`
/// (dimensionless) and design-surface normal curvatures across the feed `kappa_x` and, for
/// the shear form, along `y` `kappa_y` (1/mm, negative where convex towards the tool), for a
/// ball of radius `r` (mm). At least 1 on a flat floor, at most [`max_ratio`].
pub fn ratio(form: RatioForm, p: f64, q: f64, r: f64, kappa_x: f64, kappa_y: f64) -> f64 {
    let cap = MAX_SLOPE_DEG.to_radians().tan();
    let (p, q) = (p.clamp(-cap, cap), q.clamp(-cap, cap));
    let e = match form {
        RatioForm::ExactPlane => {
            ((1.0 + p * p + q * q) / (1.0 + q * q)).sqrt() * curvature_factor(r, kappa_x)
        }
        RatioForm::Shear => {
            let (theta, phi) = (p.atan(), q.atan());
            let ex = curvature_factor(r, kappa_x) / theta.cos();
            let ey = curvature_factor(r, kappa_y) / phi.cos();
            ex * phi.cos() + ey * phi.sin().abs()
        }
    };
    e.min(max_ratio())
}

/// The flat-floor spacing of eq. 2, `d_w = 2 sqrt(2 r h − h²)` (mm): the exact width of the
/// band a ball of radius `r` cuts to within `h` of a plane.
pub fn flat_spacing(r: f64, h: f64) -> f64 {
    2.0 * (2.0 * r * h - h * h).max(0.0).sqrt()
}

/// The deformed coordinate `x' = X'(x)` (mm) over slabs of `x`: the largest ratio of each
/// slab, integrated from the first slab's lower edge.
///
/// Where the surface turns to face along `x` (a closed part's side, a wall's foot) the ratio
/// grows without bound as `1 / sin` of the angle from facing, yet its integral — the arc
/// length — stays finite; a slab's ratio taken at a few points under-reads it there (the
/// head, r 1 mm, h 0.05 mm: 0.24 mm left at its side). So the ratio is also taken over the
/// mesh's edges as secants: an edge's length across the planes over its extent in `x`.
#[derive(Debug, Clone, PartialEq)]
pub struct Deformation {
    /// Lower edge of the first slab (mm).
    pub x0: f64,
    /// Slab width (mm).
    pub step: f64,
    /// Ratio of each slab (at least 1).
    pub ratio: Vec<f64>,
    /// `X'` at each slab's lower edge, and one more at the last slab's upper edge (mm).
    pub x_prime: Vec<f64>,
}

impl Deformation {
    /// From intervals `(x_a, x_b, ratio)` over `[x_lo, x_hi]` (mm) in slabs of width at
    /// least `min_step` (mm) and at most `max_slabs` of them: each slab takes the largest
    /// ratio of the intervals it meets and of its neighbours' (so a ratio near a slab's edge
    /// holds on both sides), 1 where it meets none.
    pub fn new(
        intervals: &[(f64, f64, f64)],
        x_lo: f64,
        x_hi: f64,
        min_step: f64,
        max_slabs: usize,
    ) -> Self {
        let span = (x_hi - x_lo).max(0.0);
        let step = (span / max_slabs as f64)
            .max(min_step)
            .max(f64::MIN_POSITIVE);
        let n = ((span / step).ceil() as usize).max(1);
        let mut own = vec![1.0f64; n];
        // Truncation is the floor of what is not negative (and a call cheaper).
        let slab = |x: f64| (((x - x_lo) / step).max(0.0) as usize).min(n - 1);
        for &(a, b, e) in intervals {
            for o in &mut own[slab(a.min(b))..=slab(a.max(b))] {
                *o = o.max(e);
            }
        }
        let ratio: Vec<f64> = (0..n)
            .map(|k| {
                own[k.saturating_sub(1)..(k + 2).min(n)]
                    .iter()
                    .copied()
                    .fold(1.0, f64::max)
            })
            .collect();
        let mut x_prime = Vec::with_capacity(n + 1);
        x_prime.push(0.0);
        for k in 0..n {
            x_prime.push(x_prime[k] + ratio[k] * step);
        }
        Deformation {
            x0: x_lo,
            step,
            ratio,
            x_prime,
        }
    }

    /// No deformation: `X' = x − x_lo`.
    pub fn identity(x_lo: f64, x_hi: f64) -> Self {
        Deformation::new(&[], x_lo, x_hi, (x_hi - x_lo).max(1.0), 1)
    }

    /// `X'(x)` (mm): the ratio's integral, linear within each slab, so increasing; beyond
    /// the slabs continued with ratio 1.
    pub fn at(&self, x: f64) -> f64 {
        let n = self.ratio.len();
        let f = (x - self.x0) / self.step;
        if f <= 0.0 {
            return f * self.step;
        }
        if f >= n as f64 {
            return self.x_prime[n] + (f - n as f64) * self.step;
        }
        let k = (f.floor() as usize).min(n - 1);
        self.x_prime[k] + (f - k as f64) * self.step * self.ratio[k]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_floor_is_not_deformed_and_an_inclined_plane_by_its_slope() {
        let r = 1.0;
        assert_eq!(ratio(RatioForm::ExactPlane, 0.0, 0.0, r, 0.0, 0.0), 1.0);
        assert_eq!(ratio(RatioForm::Shear, 0.0, 0.0, r, 0.0, 0.0), 1.0);
        // Inclined by θ about y: 1 / cos θ in both forms.
        let theta = 30f64.to_radians();
        for form in [RatioForm::ExactPlane, RatioForm::Shear] {
            let e = ratio(form, theta.tan(), 0.0, r, 0.0, 0.0);
            assert!((e - 1.0 / theta.cos()).abs() < 1e-12, "{form:?} {e}");
        }
        // Sloping only along the planes: exact 1, the shear form denser (1.71 at 45°).
        let q = 1.0;
        assert!((ratio(RatioForm::ExactPlane, 0.0, q, r, 0.0, 0.0) - 1.0).abs() < 1e-12);
        let shear = ratio(RatioForm::Shear, 0.0, q, r, 0.0, 0.0);
        assert!((shear - (0.5f64.sqrt() + 1.0)).abs() < 1e-12, "{shear}");
        // Concave across the feed: denser; convex: sparser.
        assert!(ratio(RatioForm::ExactPlane, 0.0, 0.0, r, 0.2, 0.0) > 1.0);
        assert!(ratio(RatioForm::ExactPlane, 0.0, 0.0, r, -0.2, 0.0) < 1.0);
        // A wall: capped.
        let wall = ratio(RatioForm::ExactPlane, 1e9, 0.0, r, 0.0, 0.0);
        assert!((wall - 1.0 / MAX_SLOPE_DEG.to_radians().cos()).abs() < 1e-12);
    }

    #[test]
    fn the_deformed_coordinate_integrates_the_ratio_and_never_folds() {
        // Slabs of 1 mm over [0, 10]; a ratio of 2 at x = 5.5 raises slabs 4 to 6.
        let d = Deformation::new(&[(5.5, 5.5, 2.0), (1.2, 1.6, 0.5)], 0.0, 10.0, 1.0, 100);
        assert_eq!((d.ratio.len(), d.step), (10, 1.0));
        assert_eq!(d.ratio[3], 1.0);
        assert_eq!(&d.ratio[4..7], &[2.0, 2.0, 2.0]);
        assert!((d.at(4.0) - 4.0).abs() < 1e-12);
        assert!((d.at(5.5) - 7.0).abs() < 1e-12);
        assert!((d.at(10.0) - 13.0).abs() < 1e-12);
        // Beyond the slabs: ratio 1.
        assert!((d.at(12.0) - 15.0).abs() < 1e-12);
        assert!((d.at(-1.0) + 1.0).abs() < 1e-12);
        // Increasing.
        let mut last = f64::NEG_INFINITY;
        for k in 0..400 {
            let x = -2.0 + 0.035 * k as f64;
            let v = d.at(x);
            assert!(v > last);
            last = v;
        }
        assert!((Deformation::identity(0.0, 10.0).at(7.25) - 7.25).abs() < 1e-12);
    }

    #[test]
    fn the_flat_spacing_is_the_width_a_ball_cuts_to_within_the_scallop() {
        let (r, h) = (1.0, 0.01);
        let d = flat_spacing(r, h);
        // Two balls d apart leave exactly h midway on a plane.
        let left = r - (r * r - 0.25 * d * d).sqrt();
        assert!((left - h).abs() < 1e-15);
    }
}
