//! Small geometric vocabulary shared by every module: positions are `Point3`, directions
//! and derivatives are `Vector3`, all in millimetres.

/// A position in model space, millimetres.
pub type Point3 = nalgebra::Point3<f64>;
/// A direction or derivative in model space (millimetres per unit parameter for derivatives).
pub type Vector3 = nalgebra::Vector3<f64>;
/// A homogeneous control point `(w x, w y, w z, w)`.
pub type Vector4 = nalgebra::Vector4<f64>;

/// The smaller of two numbers that are not NaN, by a plain comparison: `f64::min` is a
/// call in wasm (for its NaN rule), and the hierarchy's queries and the simulation's bounds
/// take millions. Where `b` is NaN, `a`, as `f64::min` does; folds start from a number.
#[inline]
pub fn least(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// The larger of two numbers that are not NaN (see [`least`]).
#[inline]
pub fn most(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// An axis-aligned bounding box in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Aabb {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Aabb {
    /// The empty box (grows with [`Aabb::grow`]).
    pub fn empty() -> Self {
        Aabb {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        }
    }

    /// Extends the box to contain `p`.
    pub fn grow(&mut self, p: &Point3) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(p[k]);
            self.max[k] = self.max[k].max(p[k]);
        }
    }

    /// Edge lengths of the box (mm).
    pub fn size(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| (self.max[k] - self.min[k]).max(0.0))
    }

    /// Length of the diagonal (mm); the model size that relative tolerances scale with.
    pub fn diagonal(&self) -> f64 {
        let s = self.size();
        (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
    }
}

/// The point of the segment `a`–`b` nearest `p`.
pub fn nearest_on_segment(p: &Point3, a: &Point3, b: &Point3) -> Point3 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + ab * t
}

/// Distance from `p` to the segment `a`–`b` (mm).
pub fn dist_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    (p - nearest_on_segment(p, a, b)).norm()
}
