//! Rational bicubic Bézier pieces: the read-only form every face of every model is reduced to
//! once, so that evaluation is a fixed amount of arithmetic.
//!
//! Owns: evaluation of a rational bicubic patch with first and second derivatives.

use super::basis::bernstein3;
use crate::geom::{Point3, Vector3, Vector4};

/// Position and first and second partial derivatives of a surface at one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivs {
    pub point: Point3,
    pub su: Vector3,
    pub sv: Vector3,
    pub suu: Vector3,
    pub suv: Vector3,
    pub svv: Vector3,
}

impl SurfaceDerivs {
    /// The same derivatives for the parameterisation `(u, v) = (a·u', b·v')`, i.e. with
    /// first derivatives scaled by `a`/`b` and second by the products.
    pub fn scaled(self, a: f64, b: f64) -> Self {
        SurfaceDerivs {
            point: self.point,
            su: self.su * a,
            sv: self.sv * b,
            suu: self.suu * (a * a),
            suv: self.suv * (a * b),
            svv: self.svv * (b * b),
        }
    }
}

/// A rational bicubic Bézier patch on `[0,1]²`, control points stored homogeneous
/// `(w x, w y, w z, w)`, index `[j][i]` with `i` along `u`.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierPatch {
    pub cp: [[Vector4; 4]; 4],
}

impl BezierPatch {
    /// A patch with all homogeneous control points zero (the start of an accumulation).
    pub fn zero() -> Self {
        BezierPatch {
            cp: [[Vector4::zeros(); 4]; 4],
        }
    }

    /// Homogeneous value at `(u, v)` only (the cheap path for tessellation checks).
    pub fn subs_h(&self, u: f64, v: f64) -> Vector4 {
        let (bu, _, _) = bernstein3(u);
        let (bv, _, _) = bernstein3(v);
        let mut acc = Vector4::zeros();
        for j in 0..4 {
            let mut row = Vector4::zeros();
            for i in 0..4 {
                row += self.cp[j][i] * bu[i];
            }
            acc += row * bv[j];
        }
        acc
    }

    /// Surface point at `(u, v)`.
    pub fn subs(&self, u: f64, v: f64) -> Point3 {
        let h = self.subs_h(u, v);
        Point3::new(h.x / h.w, h.y / h.w, h.z / h.w)
    }

    /// Point with first and second partial derivatives at `(u, v)`.
    pub fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        let (bu, dbu, ddbu) = bernstein3(u);
        let (bv, dbv, ddbv) = bernstein3(v);
        // Contract along u for each row j: value, d/du, d²/du².
        let mut r0 = [Vector4::zeros(); 4];
        let mut r1 = [Vector4::zeros(); 4];
        let mut r2 = [Vector4::zeros(); 4];
        for j in 0..4 {
            for i in 0..4 {
                let c = self.cp[j][i];
                r0[j] += c * bu[i];
                r1[j] += c * dbu[i];
                r2[j] += c * ddbu[i];
            }
        }
        let mut a = Vector4::zeros();
        let mut au = Vector4::zeros();
        let mut av = Vector4::zeros();
        let mut auu = Vector4::zeros();
        let mut auv = Vector4::zeros();
        let mut avv = Vector4::zeros();
        for j in 0..4 {
            a += r0[j] * bv[j];
            av += r0[j] * dbv[j];
            avv += r0[j] * ddbv[j];
            au += r1[j] * bv[j];
            auv += r1[j] * dbv[j];
            auu += r2[j] * bv[j];
        }
        rational_derivs(a, au, av, auu, auv, avv)
    }
}

/// Euclidean derivatives from homogeneous ones (quotient rule up to second order).
#[inline]
pub fn rational_derivs(
    a: Vector4,
    au: Vector4,
    av: Vector4,
    auu: Vector4,
    auv: Vector4,
    avv: Vector4,
) -> SurfaceDerivs {
    let w = a.w;
    let inv = 1.0 / w;
    let s = a.xyz() * inv;
    let su = (au.xyz() - s * au.w) * inv;
    let sv = (av.xyz() - s * av.w) * inv;
    let suu = (auu.xyz() - su * (2.0 * au.w) - s * auu.w) * inv;
    let svv = (avv.xyz() - sv * (2.0 * av.w) - s * avv.w) * inv;
    let suv = (auv.xyz() - su * av.w - sv * au.w - s * auv.w) * inv;
    SurfaceDerivs {
        point: Point3::from(s),
        su,
        sv,
        suu,
        suv,
        svv,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_patch() -> BezierPatch {
        let mut p = BezierPatch::zero();
        for j in 0..4 {
            for i in 0..4 {
                let w = 1.0 + 0.3 * ((i * 7 + j * 3) % 4) as f64;
                let x = i as f64;
                let y = j as f64 + 0.2 * i as f64;
                let z = ((i * j) % 3) as f64 - 0.5 * j as f64;
                p.cp[j][i] = Vector4::new(w * x, w * y, w * z, w);
            }
        }
        p
    }

    #[test]
    fn derivatives_match_central_differences() {
        let p = sample_patch();
        let h = 1e-5;
        for &(u, v) in &[(0.2, 0.3), (0.5, 0.5), (0.9, 0.1)] {
            let d = p.derivs(u, v);
            let du = (p.subs(u + h, v) - p.subs(u - h, v)) / (2.0 * h);
            let dv = (p.subs(u, v + h) - p.subs(u, v - h)) / (2.0 * h);
            assert!((du - d.su).norm() < 1e-7 * d.su.norm().max(1.0));
            assert!((dv - d.sv).norm() < 1e-7 * d.sv.norm().max(1.0));
            let duu = (p.derivs(u + h, v).su - p.derivs(u - h, v).su) / (2.0 * h);
            let duv = (p.derivs(u, v + h).su - p.derivs(u, v - h).su) / (2.0 * h);
            let dvv = (p.derivs(u, v + h).sv - p.derivs(u, v - h).sv) / (2.0 * h);
            assert!((duu - d.suu).norm() < 1e-6 * d.suu.norm().max(1.0));
            assert!((duv - d.suv).norm() < 1e-6 * d.suv.norm().max(1.0));
            assert!((dvv - d.svv).norm() < 1e-6 * d.svv.norm().max(1.0));
            assert!((d.point - p.subs(u, v)).norm() < 1e-14);
        }
    }
}
