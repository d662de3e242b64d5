//! Univariate cubic bases: B-spline blending functions on a local knot vector and the
//! Bernstein basis used by the per-cell Bézier forms.
//!
//! Owns: basis values and derivatives, and the conversion of one polynomial piece of a
//! B-spline basis function to Bernstein coefficients. Knows nothing about meshes.

/// A local knot vector of a cubic B-spline blending function: five non-decreasing knots.
pub type LocalKnots = [f64; 5];

/// Cubic Bernstein basis at `t` with first and second derivatives (with respect to `t`).
#[inline]
pub fn bernstein3(t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let b = [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t];
    let db = [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ];
    let ddb = [6.0 * s, 18.0 * t - 12.0, 6.0 - 18.0 * t, 6.0 * t];
    (b, db, ddb)
}

/// Value at `x` of the polynomial piece of the blending function `N[knots]` that lives on
/// knot span `span` (`knots[span] < knots[span + 1]`, `span` in 0..4). The piece is evaluated
/// as a polynomial, so `x` may lie on or outside the span's ends.
pub fn bspline_piece(knots: &LocalKnots, span: usize, x: f64) -> f64 {
    // Cox–de Boor with the degree-0 functions fixed to the indicator of `span`.
    let mut n = [0.0f64; 4];
    n[span] = 1.0;
    for k in 1..=3 {
        for i in 0..=(3 - k) {
            let left = {
                let d = knots[i + k] - knots[i];
                if d > 0.0 {
                    (x - knots[i]) / d * n[i]
                } else {
                    0.0
                }
            };
            let right = {
                let d = knots[i + k + 1] - knots[i + 1];
                if d > 0.0 {
                    (knots[i + k + 1] - x) / d * n[i + 1]
                } else {
                    0.0
                }
            };
            n[i] = left + right;
        }
    }
    n[0]
}

/// Value of the blending function `N[knots]` at `x` (right-continuous, and left-continuous
/// at the last knot so that a clamped end is reached).
pub fn bspline(knots: &LocalKnots, x: f64) -> f64 {
    if x < knots[0] || x > knots[4] {
        return 0.0;
    }
    let span = (0..4)
        .filter(|&j| knots[j] < knots[j + 1])
        .find(|&j| x < knots[j + 1])
        .or_else(|| (0..4).rev().find(|&j| knots[j] < knots[j + 1]));
    match span {
        Some(j) => bspline_piece(knots, j, x),
        None => 0.0,
    }
}

/// Bernstein coefficients of the blending function `N[knots]` on the interval `[a, b]`,
/// which must lie inside one knot span (or entirely outside the support, giving zeros).
pub fn bspline_bernstein(knots: &LocalKnots, a: f64, b: f64) -> [f64; 4] {
    let mid = 0.5 * (a + b);
    let Some(span) =
        (0..4).find(|&j| knots[j] < knots[j + 1] && knots[j] <= mid && mid < knots[j + 1])
    else {
        return [0.0; 4];
    };
    let h = b - a;
    let f = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|t| bspline_piece(knots, span, a + t * h));
    bernstein_from_samples(f)
}

/// Bernstein coefficients of the cubic that takes values `f` at t = 0, 1/3, 2/3, 1.
pub fn bernstein_from_samples(f: [f64; 4]) -> [f64; 4] {
    let a = 27.0 * f[1] - 8.0 * f[0] - f[3];
    let b = 27.0 * f[2] - f[0] - 8.0 * f[3];
    [f[0], (2.0 * a - b) / 18.0, (2.0 * b - a) / 18.0, f[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval_bernstein(c: &[f64; 4], t: f64) -> f64 {
        let (b, _, _) = bernstein3(t);
        (0..4).map(|i| c[i] * b[i]).sum()
    }

    #[test]
    fn uniform_bspline_closed_form() {
        // Uniform cubic B-spline on [0,4]: value 1/6 at 1, 2/3 at 2, 1/6 at 3.
        let k = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert!((bspline(&k, 1.0) - 1.0 / 6.0).abs() < 1e-15);
        assert!((bspline(&k, 2.0) - 2.0 / 3.0).abs() < 1e-15);
        assert!((bspline(&k, 3.0) - 1.0 / 6.0).abs() < 1e-15);
        assert_eq!(bspline(&k, 4.5), 0.0);
    }

    #[test]
    fn clamped_bezier_end() {
        // [0,0,0,0,1] is the Bernstein (1-x)^3 on [0,1].
        let k = [0.0, 0.0, 0.0, 0.0, 1.0];
        for x in [0.0, 0.25, 0.5, 0.9] {
            assert!((bspline(&k, x) - (1.0 - x).powi(3)).abs() < 1e-15);
        }
    }

    #[test]
    fn partition_of_unity_nonuniform() {
        // Knot vector 0,0,0,0,1,3,3.5,6,6,6,6 and its seven blending functions.
        let t = [0.0, 0.0, 0.0, 0.0, 1.0, 3.0, 3.5, 6.0, 6.0, 6.0, 6.0];
        for step in 0..=60 {
            let x = step as f64 * 0.1;
            let sum: f64 = (0..7)
                .map(|i| bspline(&[t[i], t[i + 1], t[i + 2], t[i + 3], t[i + 4]], x))
                .sum();
            assert!((sum - 1.0).abs() < 1e-14, "x = {x}: sum {sum}");
        }
    }

    #[test]
    fn bernstein_conversion_reproduces_piece() {
        let k = [0.0, 0.5, 2.0, 2.5, 4.0];
        for (a, b) in [(0.0, 0.5), (0.7, 1.9), (2.0, 2.5), (3.0, 4.0)] {
            let c = bspline_bernstein(&k, a, b);
            for i in 0..=10 {
                let t = i as f64 / 10.0;
                let x = a + t * (b - a);
                assert!((eval_bernstein(&c, t) - bspline(&k, x)).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn bernstein_derivatives_match_differences() {
        let h = 1e-6;
        for t in [0.1, 0.5, 0.8] {
            let (_, db, ddb) = bernstein3(t);
            let (bp, dbp, _) = bernstein3(t + h);
            let (bm, dbm, _) = bernstein3(t - h);
            for i in 0..4 {
                assert!(((bp[i] - bm[i]) / (2.0 * h) - db[i]).abs() < 1e-8);
                assert!(((dbp[i] - dbm[i]) / (2.0 * h) - ddb[i]).abs() < 1e-7);
            }
        }
    }
}
