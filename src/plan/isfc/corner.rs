//! Corner compensation (Gan et al. 2014, §4.5, eq. 10–13). Where the curve turns at a vertex
//! `Q` (coming from `G`, leaving to `H`), the grid square outside the turn has no pass on the
//! sides at `Q`; its far corner `P = Q + (Q − G) − (H − Q)` (in grid steps) is a pass's, and
//! between the balls at `P` and `Q`, a diagonal apart, more than the scallop may be left. A
//! detour `Q → K → Q` of two cubic Hermite curves brings a ball to the check point
//! `K = (1 − λ)P + λQ` on the diagonal, with `λ` found by bisection so that the cusp
//! between the balls at `P` and `K` is the scallop height (within `ε`).
//!
//! Reading of eq. 12 (its last row is garbled in the paper): `C1(0) = C2(1) = Q`,
//! `C1(1) = C2(0) = K`, `C1′(0) = Q − G`, `C2′(1) = H − Q` and
//! `C1′(1) = C2′(0) = −((Q − G) + (H − Q))/2`: the curve leaves `Q` along the incoming
//! direction and returns along the outgoing one (G¹ at `Q`), and crosses the diagonal at `K`
//! square to it. Everything is in the patch's `(u, v)`; the tangents are the grid edges.
//! The bisection keeps `h_PK ≤ h`, so the compensated corner holds the scallop.
//!
//! Owns: the curves and the check point. Must not: decide which turns exist.

/// A cubic Hermite curve in the parameter plane (eq. 10–11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hermite {
    /// `a t³ + b t² + c t + d` per coordinate.
    coeffs: [[f64; 4]; 2],
}

impl Hermite {
    /// The curve with `C(0) = p0`, `C(1) = p1`, `C′(0) = d0`, `C′(1) = d1` (eq. 11: the
    /// coefficients are `M⁻¹·[C(0), C(1), C′(0), C′(1)]ᵀ`).
    pub fn new(p0: [f64; 2], p1: [f64; 2], d0: [f64; 2], d1: [f64; 2]) -> Self {
        let coeffs = [0, 1].map(|k| {
            let (c0, c1, t0, t1) = (p0[k], p1[k], d0[k], d1[k]);
            [
                2.0 * c0 - 2.0 * c1 + t0 + t1,
                -3.0 * c0 + 3.0 * c1 - 2.0 * t0 - t1,
                t0,
                c0,
            ]
        });
        Hermite { coeffs }
    }

    /// The point at `t` in `[0, 1]`.
    pub fn at(&self, t: f64) -> [f64; 2] {
        self.coeffs
            .map(|[a, b, c, d]| ((a * t + b) * t + c) * t + d)
    }

    /// The derivative at `t`.
    pub fn tangent(&self, t: f64) -> [f64; 2] {
        self.coeffs
            .map(|[a, b, c, _]| (3.0 * a * t + 2.0 * b) * t + c)
    }
}

/// A corner's detour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detour {
    /// The far corner of the square outside the turn (patch parameters).
    pub p: [f64; 2],
    /// The check point on the diagonal.
    pub k: [f64; 2],
    /// Where `K` lies: 0 at `P`, 1 at `Q`.
    pub lambda: f64,
    /// The cusp between the balls at `P` and `Q` (mm), and at `P` and `K`.
    pub h_pq_mm: f64,
    pub h_pk_mm: f64,
    /// `Q → K` and `K → Q`.
    pub out: Hermite,
    pub back: Hermite,
}

/// Bisection steps of the check-point search.
const LAMBDA_STEPS: usize = 40;
/// λ where the corner needs no compensation: the diagonal's middle, which still rounds the
/// corner (as the paper does).
const LAMBDA_UNNEEDED: f64 = 0.5;

/// The detour at `q` for a turn from `g` to `h` (patch parameters) whose outer square's far
/// corner is `p`, given `cusp(x, y)`, the cusp between the balls at two parameter points
/// (mm); `scallop` is the height to hold and `eps` the check point's tolerance (mm).
pub fn detour(
    g: [f64; 2],
    q: [f64; 2],
    h: [f64; 2],
    p: [f64; 2],
    scallop: f64,
    eps: f64,
    cusp: &mut dyn FnMut([f64; 2], [f64; 2]) -> f64,
) -> Detour {
    let lerp = |lambda: f64| [0, 1].map(|k| (1.0 - lambda) * p[k] + lambda * q[k]);
    let h_pq = cusp(p, q);
    let (lambda, h_pk) = if h_pq <= scallop {
        let k = lerp(LAMBDA_UNNEEDED);
        (LAMBDA_UNNEEDED, cusp(p, k))
    } else {
        // h_PK grows from 0 at λ = 0 to h_PQ at λ = 1: the largest λ with h_PK ≤ h.
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut at_lo = 0.0;
        for _ in 0..LAMBDA_STEPS {
            let mid = 0.5 * (lo + hi);
            let c = cusp(p, lerp(mid));
            if c <= scallop {
                (lo, at_lo) = (mid, c);
                if scallop - c <= eps {
                    break;
                }
            } else {
                hi = mid;
            }
        }
        (lo, at_lo)
    };
    let k = lerp(lambda);
    let gq = [q[0] - g[0], q[1] - g[1]];
    let qh = [h[0] - q[0], h[1] - q[1]];
    let tk = [-0.5 * (gq[0] + qh[0]), -0.5 * (gq[1] + qh[1])];
    Detour {
        p,
        k,
        lambda,
        h_pq_mm: h_pq,
        h_pk_mm: h_pk,
        out: Hermite::new(q, k, gq, tk),
        back: Hermite::new(k, q, tk, qh),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_meets_its_ends_and_tangents() {
        let c = Hermite::new([0.0, 0.0], [1.0, 2.0], [3.0, -1.0], [0.5, 0.25]);
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-12;
        assert!(close(c.at(0.0), [0.0, 0.0]) && close(c.at(1.0), [1.0, 2.0]));
        assert!(close(c.tangent(0.0), [3.0, -1.0]) && close(c.tangent(1.0), [0.5, 0.25]));
        // The tangent is the derivative of the point (central differences).
        let e = 1e-6;
        for t in [0.2, 0.5, 0.8] {
            let (a, b) = (c.at(t - e), c.at(t + e));
            let fd = [(b[0] - a[0]) / (2.0 * e), (b[1] - a[1]) / (2.0 * e)];
            let d = c.tangent(t);
            assert!((fd[0] - d[0]).abs() < 1e-6 && (fd[1] - d[1]).abs() < 1e-6);
        }
    }
}
