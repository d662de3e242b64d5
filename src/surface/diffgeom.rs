//! Differential geometry at a surface point: unit normal, first and second fundamental forms,
//! Gaussian / mean / principal / root-mean-square curvature, normal curvature in a direction.
//!
//! Sign convention: curvatures are taken with respect to the unit normal
//! `n = (S_u × S_v) / |S_u × S_v|`; a normal curvature is positive where the surface bends
//! towards `n` (concave as seen from the side `n` points to), negative where it bends away
//! (convex, like the outside of a sphere with outward normal).

use super::bezier::SurfaceDerivs;
use crate::geom::{Point3, Vector3};

/// First and second fundamental forms and the unit normal at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffGeom {
    pub point: Point3,
    pub normal: Vector3,
    /// First fundamental form `E = S_u·S_u`, `F = S_u·S_v`, `G = S_v·S_v` (mm² per unit²).
    pub e: f64,
    pub f: f64,
    pub g: f64,
    /// Second fundamental form `L = S_uu·n`, `M = S_uv·n`, `N = S_vv·n` (mm per unit²).
    pub l: f64,
    pub m: f64,
    pub n: f64,
}

/// The unit normal `(S_u × S_v) / |S_u × S_v|` from the first derivatives; `None` where
/// the cross product vanishes against `|S_u| |S_v|` (see [`DiffGeom::try_from_derivs`]).
pub fn unit_normal(su: &Vector3, sv: &Vector3) -> Option<Vector3> {
    let cross = su.cross(sv);
    let len = cross.norm();
    let scale = su.norm() * sv.norm();
    if !(len > 0.0) || !(len > scale * SINGULAR_SINE) {
        return None;
    }
    Some(cross / len)
}

impl DiffGeom {
    /// Fundamental forms from derivatives; `None` where `S_u × S_v` vanishes (a degenerate or
    /// singular point, e.g. an extraordinary point), since no normal exists there.
    pub fn try_from_derivs(d: &SurfaceDerivs) -> Option<Self> {
        let normal = unit_normal(&d.su, &d.sv)?;
        Some(DiffGeom {
            point: d.point,
            normal,
            e: d.su.dot(&d.su),
            f: d.su.dot(&d.sv),
            g: d.sv.dot(&d.sv),
            l: d.suu.dot(&normal),
            m: d.suv.dot(&normal),
            n: d.svv.dot(&normal),
        })
    }

    /// The same point seen from the other side: normal and second fundamental form (and
    /// so every curvature) change sign.
    pub fn flipped(self) -> Self {
        DiffGeom {
            normal: -self.normal,
            l: -self.l,
            m: -self.m,
            n: -self.n,
            ..self
        }
    }

    /// `EG − F²`, the squared area element.
    pub fn metric_det(&self) -> f64 {
        self.e * self.g - self.f * self.f
    }

    /// Gaussian curvature (1/mm²).
    pub fn gaussian(&self) -> f64 {
        (self.l * self.n - self.m * self.m) / self.metric_det()
    }

    /// Mean curvature (1/mm), the mean of the principal curvatures.
    pub fn mean(&self) -> f64 {
        (self.e * self.n - 2.0 * self.f * self.m + self.g * self.l) / (2.0 * self.metric_det())
    }

    /// Principal curvatures `(k_min, k_max)` (1/mm).
    pub fn principal(&self) -> (f64, f64) {
        let h = self.mean();
        let disc = (h * h - self.gaussian()).max(0.0).sqrt();
        (h - disc, h + disc)
    }

    /// Root-mean-square curvature `sqrt((k1² + k2²)/2) = sqrt(2H² − K)` (1/mm).
    pub fn rms_curvature(&self) -> f64 {
        let h = self.mean();
        (2.0 * h * h - self.gaussian()).max(0.0).sqrt()
    }

    /// Normal curvature (1/mm) in the parametric direction `(du, dv)`: `II / I`.
    pub fn normal_curvature(&self, du: f64, dv: f64) -> f64 {
        let first = self.e * du * du + 2.0 * self.f * du * dv + self.g * dv * dv;
        let second = self.l * du * du + 2.0 * self.m * du * dv + self.n * dv * dv;
        second / first
    }
}

/// Below this sine of the angle between `S_u` and `S_v` the tangent plane is taken as
/// undefined (relative, dimensionless).
const SINGULAR_SINE: f64 = 1e-12;
