//! How far the true extremes can lie from the sampled ones: per cell of four neighbouring
//! samples, an upper bound of the material left anywhere inside the cell, and the depth of
//! the shallowest gouge that could hide between samples.
//!
//! The material left is `h = min_k e_k`, the minimum over capsules `k` of the distance
//! `e_k` along the normal to capsule `k`. Each sample knows its governing capsule's `e_k`
//! and its exact gradient. Inside the cell `h ≤ e_k ≤ Q_k`, where `Q_k` is the Taylor
//! expansion of `e_k` from its sample plus a second-order remainder bound `½ δᵀHδ`. So
//! `max h ≤ max_cell min_k Q_k`, and because every `Q_k` shares the same `H`, the maximum of
//! their minimum lies at a vertex of the arrangement (cell corners, where two `Q_k` are equal
//! on an edge, or where three are equal): evaluating those points is exact. A scallop's cusp
//! (where two passes meet, the worst point, usually between samples) is found through the
//! gradients of the two passes on either side, so the bound falls with the square of the
//! sample spacing rather than with the spacing.
//!
//! The remainder `H` bounds the second derivative of the distance to a ball of radius `r`
//! over a surface: `(1/r + κ) (r/w)³` along the surface, with `κ` the largest curvature of
//! the surface bending away from the tool and `w = r·cos θ` the smallest height of the ball
//! centre above the entry point within the cell (exact for a ball over a plane, and for the
//! principal sections of spheres and cylinders, checked in tests), plus the term from the
//! parameterisation's own second derivatives times the slope. Within a cell the metric is
//! taken from its corners with a [`INTERIOR_MARGIN`]: the bound holds up to terms of third
//! order in the sample spacing.

use crate::geom::{least, most, Point3};

/// Relative growth allowed for metric and second-derivative norms between a cell's corners
/// and its interior (dimensionless).
pub const INTERIOR_MARGIN: f64 = 0.05;
/// Deepest gouge, as a share of the ball radius, that the gouge bound is worked out for
/// (dimensionless): deeper is a crash, not a tolerance question.
const GOUGE_BOUNDED_SHARE: f64 = 0.25;
/// Growth of the distance curvature over what the last round needed, so that the rounds
/// of the gouge bound settle (dimensionless).
const GOUGE_K_GROWTH: f64 = 1.05;
/// Rounds of raising the height estimate before a cell is given up as unbounded.
const MAX_ROUNDS: usize = 12;

/// What the bound needs from one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    pub point: Point3,
    /// A swept ball came within reach along the normal (and the normal exists).
    pub reached: bool,
    /// Material left along the normal (mm); negative is a gouge.
    pub left_mm: f64,
    /// How far the cut reaches past the surface here (mm, 0 where it does not): the depth
    /// inside the swept volume measured straight, the ball radius less the distance to the
    /// nearest capsule's segment ([`super::probe::Probe::straight_depth`]; never more than
    /// `−left_mm`, which along the normal can run under the other side of a concave crease).
    /// The gouge reported.
    pub overcut_mm: f64,
    /// `∂e/∂u`, `∂e/∂v` of the governing capsule's distance (mm per unit parameter).
    pub grad: [f64; 2],
    /// `r·cos θ`: height of the governing ball's centre over the entry point along the
    /// normal (mm).
    pub w_mm: f64,
    /// `|∇e|` along the surface (mm/mm).
    pub slope: f64,
    /// Largest curvature bending away from the tool, 0 if none (1/mm).
    pub kappa_convex: f64,
    /// First fundamental form `E, F, G`.
    pub metric: [f64; 3],
    /// `|S_uu|, |S_uv|, |S_vv|`.
    pub second: [f64; 3],
}

/// Bounds of one cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellBound {
    /// Upper bound of the material left anywhere in the cell (mm); `reach` if it cannot be
    /// bounded below that.
    pub scallop_upper_mm: f64,
    /// Upper bound of the deepest overcut anywhere in the cell (mm; at least the deepest
    /// at its corners).
    pub gouge_upper_mm: f64,
    /// Where in the cell (offsets in `u` and `v` from corner 0) the exact step put the
    /// maximum, if it ran: the cusp, to be measured there.
    pub argmax: Option<[f64; 2]>,
}

/// Second derivative (1/mm), along the surface, of the distance `e` along the normal from
/// the surface to a ball of radius `r` whose centre is `w` above the entry point along the
/// normal, over a surface whose curvature away from the tool is `kappa_convex` (≥ 0).
///
/// Exact for a principal section of a convex sphere or cylinder (circle–circle geometry:
/// with `A = 1/κ + e + w`, `B² = r² − w²`, `e'' = κ²(−A + (A² − B²)/w + A²B²/w³)`,
/// rearranged to stay finite as `κ → 0`), and `r²/w³` over a plane; it grows as `w` falls
/// and as `e` and `κ` grow, so the smallest `w` and the largest `e` and `κ` of a cell bound
/// the cell. Surfaces bending towards the tool are bounded by the plane's value.
pub fn second_derivative_bound(r: f64, kappa_convex: f64, w: f64, e: f64) -> f64 {
    if !(w > 0.0) {
        return f64::INFINITY;
    }
    let k = kappa_convex.max(0.0);
    let a = 1.0 + k * (e + w).max(0.0);
    let b2 = (r * r - w * w).max(0.0);
    a * a * r * r / (w * w * w) - k * k * b2 / w - k * a
}

/// The remainder's diagonal quadratic form in `(δu, δv)` for a given bound `k` of the
/// second derivative along the surface and slope bound `l`.
fn remainder(c: &[&Corner; 4], k: f64, l: f64) -> [f64; 2] {
    let m = 1.0 + INTERIOR_MARGIN;
    let emax = c.iter().map(|c| c.metric[0]).fold(0.0, most);
    let gmax = c.iter().map(|c| c.metric[2]).fold(0.0, most);
    let fabs = c.iter().map(|c| c.metric[1].abs()).fold(0.0, most);
    let [suu, suv, svv] = [0, 1, 2].map(|i| c.iter().map(|c| c.second[i]).fold(0.0, most));
    // 2|F δu δv| ≤ |F| (ρ δu² + δv²/ρ) for any ρ > 0; ρ = sqrt(E/G) adds at most |F|/sqrt(EG)
    // ≤ 1 of each diagonal term (the other way round a thin, stretched cell's short side
    // would take the long side's metric).
    let rho = if gmax > 0.0 {
        (emax / gmax).sqrt()
    } else {
        1.0
    };
    let (mu, mv) = if rho > 0.0 {
        (emax + fabs * rho, gmax + fabs / rho)
    } else {
        (emax + fabs, gmax + fabs)
    };
    [
        m * (k * mu + l * (suu + suv)),
        m * (k * mv + l * (svv + suv)),
    ]
}

/// Maximum over the rectangle `[0,du]×[0,dv]` of `min_k Q_k`, where `Q_k` has value
/// `vals[k]` and gradient `grads[k]` at corner `k` (order (0,0), (du,0), (0,dv), (du,dv))
/// and the common Hessian `diag(h)`, and where it is attained.
pub fn max_of_min_quadratics(
    vals: [f64; 4],
    grads: [[f64; 2]; 4],
    du: f64,
    dv: f64,
    h: [f64; 2],
) -> (f64, [f64; 2]) {
    let xs = [[0.0, 0.0], [du, 0.0], [0.0, dv], [du, dv]];
    // Q_k(x) = ½ xᵀHx + a_k·x + b_k.
    let mut a = [[0.0; 2]; 4];
    let mut b = [0.0; 4];
    for k in 0..4 {
        let x = xs[k];
        a[k] = [grads[k][0] - h[0] * x[0], grads[k][1] - h[1] * x[1]];
        b[k] = vals[k] - grads[k][0] * x[0] - grads[k][1] * x[1]
            + 0.5 * (h[0] * x[0] * x[0] + h[1] * x[1] * x[1]);
    }
    let eval = |x: [f64; 2]| {
        let q = 0.5 * (h[0] * x[0] * x[0] + h[1] * x[1] * x[1]);
        q + (0..4)
            .map(|k| a[k][0] * x[0] + a[k][1] * x[1] + b[k])
            .fold(f64::INFINITY, least)
    };
    let mut best = (f64::NEG_INFINITY, [0.0; 2]);
    let mut consider = |x: [f64; 2]| {
        let v = eval(x);
        if v > best.0 {
            best = (v, x);
        }
    };
    for x in xs {
        consider(x);
    }
    // Where Q_j = Q_k: α x + β y + γ = 0.
    let line = |j: usize, k: usize| (a[j][0] - a[k][0], a[j][1] - a[k][1], b[j] - b[k]);
    for j in 0..4 {
        for k in j + 1..4 {
            let (al, be, ga) = line(j, k);
            for y in [0.0, dv] {
                if al != 0.0 {
                    let x = -(be * y + ga) / al;
                    if (0.0..=du).contains(&x) {
                        consider([x, y]);
                    }
                }
            }
            for x in [0.0, du] {
                if be != 0.0 {
                    let y = -(al * x + ga) / be;
                    if (0.0..=dv).contains(&y) {
                        consider([x, y]);
                    }
                }
            }
        }
    }
    for (j, k, l) in [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)] {
        let (a1, b1, c1) = line(j, k);
        let (a2, b2, c2) = line(j, l);
        let det = a1 * b2 - a2 * b1;
        if det != 0.0 {
            let x = (-c1 * b2 + c2 * b1) / det;
            let y = (-a1 * c2 + a2 * c1) / det;
            if (0.0..=du).contains(&x) && (0.0..=dv).contains(&y) {
                consider([x, y]);
            }
        }
    }
    best
}

/// A cell of the sample grid: its parameter size, and which of its edges lie on the patch
/// boundary (order: `v = v0` (corners 0, 1), `u = u1` (1, 3), `v = v1` (2, 3), `u = u0`
/// (0, 2)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellFrame {
    pub du: f64,
    pub dv: f64,
    pub boundary: [bool; 4],
}

/// Maximum over `t` in `[0, len]` of `min(a + ½ h t², b + ½ h (len − t)²)`.
fn max_of_min_parabolas(a: f64, b: f64, len: f64, h: f64) -> f64 {
    let q = 0.5 * h * len * len;
    let mut best = a.min(b + q).max((a + q).min(b));
    if h > 0.0 && len > 0.0 {
        let t = 0.5 * len - (a - b) / (h * len);
        if (0.0..=len).contains(&t) {
            best = best.max(a + 0.5 * h * t * t);
        }
    }
    best
}

/// Upper bound of the deepest gouge in the cell (see [`cell_bound`]); no larger than `best`
/// when it cannot exceed it, `r` when it cannot be bounded below a quarter radius.
fn gouge_bound(c: &[&Corner; 4], frame: &CellFrame, r: f64, best: f64) -> f64 {
    let CellFrame { du, dv, boundary } = *frame;
    let depths = [0, 1, 2, 3].map(|i| c[i].overcut_mm);
    let deepest = depths.iter().copied().fold(f64::NEG_INFINITY, most);
    let bounded = GOUGE_BOUNDED_SHARE * r;
    // The distance to the deepest capsule's segment, `1/k` bounding its curvature, falls
    // from `r − D` at the bottom by at most the remainder over the cell: raise `k` until it
    // covers the distance its own bound allows.
    let mut k = 1.0 / r;
    for _ in 0..MAX_ROUNDS {
        let h = remainder(c, k, 1.0);
        // Most of `½ δᵀHδ` over the cell, and over a quarter of it (each point's nearest
        // corner is within half a side each way).
        let spread = 0.5 * (h[0] * du * du + h[1] * dv * dv);
        let cheap = deepest + 0.25 * spread;
        let g = if cheap <= best {
            cheap
        } else {
            let mut g = max_of_min_quadratics(depths, [[0.0; 2]; 4], du, dv, h).0;
            for (edge, &on) in boundary.iter().enumerate() {
                if on {
                    let (a, b, len, hh) = match edge {
                        0 => (depths[0], depths[1], du, h[0]),
                        1 => (depths[1], depths[3], dv, h[1]),
                        2 => (depths[2], depths[3], du, h[0]),
                        _ => (depths[0], depths[2], dv, h[1]),
                    };
                    g = g.max(max_of_min_parabolas(a, b, len, hh));
                }
            }
            g
        };
        let room = r - g.max(0.0) - spread;
        if !(g <= bounded) || !(room > 0.0) {
            return r;
        }
        if k * room >= 1.0 {
            return g;
        }
        k = GOUGE_K_GROWTH / room;
    }
    r
}

/// Bounds of the cell with corners `c` (order (0,0), (du,0), (0,dv), (du,dv)) for a ball
/// of radius `r`. Material beyond `reach` is not scallop (the tool never came near), so the
/// scallop bound is capped there. Cells whose bounds cannot exceed `best` (scallop, gouge)
/// skip the exact step and return cheaper bounds that are still no larger than `best`.
///
/// Gouges: a gouge's depth measured straight is `D(x) = max_j (r − |S(x) − c_j(x)|)` over
/// the capsules' segments, and its deepest point `x*` in the cell is a critical point of the
/// capsule `j` deepest there. Along the surface `−(r − dist_j)'' ≤ |S'|²/dist_j + |S''|`
/// (the distance to a segment is convex in space, its gradient a unit vector), and, its slope
/// vanishing at `x*`, `dist_j ≥ r − D(x*) − ½ δᵀHδ` across the cell, so every corner sees
/// `D_k ≥ D(x*) − ½ δ_kᵀHδ_k`: `D` is at most `max_x min_k (D_k + ½ δ_kᵀHδ_k)`. On the patch
/// boundary the bottom may have a slope across the edge; along the edge it has none, so the
/// edge's two corners bound it. A bound above a quarter of the radius is not attempted
/// (`r` is returned).
pub fn cell_bound(
    c: &[&Corner; 4],
    frame: &CellFrame,
    r: f64,
    reach: f64,
    best: [f64; 2],
) -> CellBound {
    let CellFrame { du, dv, .. } = *frame;
    let diam = (c[0].point - c[3].point)
        .norm()
        .max((c[1].point - c[2].point).norm());
    let kappa = c.iter().map(|c| c.kappa_convex).fold(0.0, most);
    let slope = c.iter().map(|c| c.slope).fold(0.0, most);
    let quarter = [0.25 * du * du, 0.25 * dv * dv];

    let gouge_upper_mm = gouge_bound(c, frame, r, best[1]);
    let best = best[0];

    if c.iter().any(|c| !(c.w_mm > 0.0)) {
        return CellBound {
            scallop_upper_mm: reach,
            gouge_upper_mm,
            argmax: None,
        };
    }
    // Cheap bound: from each corner over its quarter of the cell.
    let first_order = |k: &Corner| k.left_mm + 0.5 * (k.grad[0].abs() * du + k.grad[1].abs() * dv);
    let reach_first = c
        .iter()
        .map(|k| first_order(k))
        .fold(f64::NEG_INFINITY, most);
    let mut e_hi = reach_first;
    for _ in 0..MAX_ROUNDS {
        let w_min = c
            .iter()
            .map(|k| k.w_mm - (e_hi - k.left_mm))
            .fold(f64::INFINITY, least);
        if !(w_min > 0.0) || e_hi >= reach {
            break;
        }
        let k = second_derivative_bound(r, kappa, w_min, e_hi);
        let h = remainder(c, k, slope + k * diam);
        let cheap = reach_first + 0.5 * (h[0] * quarter[0] + h[1] * quarter[1]);
        if cheap <= e_hi {
            // The height estimate holds throughout the cell, so `h` is a valid remainder.
            let (upper, argmax) = if cheap <= best {
                (cheap, None)
            } else {
                let vals = [0, 1, 2, 3].map(|i| c[i].left_mm);
                let grads = [0, 1, 2, 3].map(|i| c[i].grad);
                let (u, x) = max_of_min_quadratics(vals, grads, du, dv, h);
                (u.min(cheap), Some(x))
            };
            return CellBound {
                scallop_upper_mm: upper.min(reach),
                gouge_upper_mm,
                argmax,
            };
        }
        e_hi = cheap + (cheap - e_hi).max(0.0);
    }
    CellBound {
        scallop_upper_mm: reach,
        gouge_upper_mm,
        argmax: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In a principal section of a sphere or cylinder of radius `big` (convex or concave
    /// towards the tool) or a plane (`big` infinite), the distance `e(x)` along the normal
    /// to a ball whose centre is at height `c` over the foot of the axis, as a function of
    /// arclength `x`, and `w = −r (m·n)` at the entry point: closed forms of circle–circle
    /// geometry. The bound must dominate the second derivative, and be tight at the bottom.
    #[test]
    fn second_derivative_bound_dominates_circle_geometry() {
        let r = 0.5;
        for big in [1.0, 2.5, 10.0, 80.0, f64::INFINITY] {
            for convex in [true, false] {
                if !convex && big <= r {
                    continue;
                }
                for c in [r, r - 0.02, r + 0.01] {
                    let kappa = if convex && big.is_finite() {
                        1.0 / big
                    } else {
                        0.0
                    };
                    // (e, w) at arclength x.
                    let at = |x: f64| -> Option<(f64, f64)> {
                        if !big.is_finite() {
                            let q = r * r - x * x;
                            if q <= 0.0 {
                                return None;
                            }
                            return Some((c - q.sqrt(), q.sqrt()));
                        }
                        let phi = x / big;
                        let d = if convex { big + c } else { big - c };
                        let q = r * r - (d * phi.sin()).powi(2);
                        if q <= 0.0 {
                            return None;
                        }
                        // Ray from the axis at angle phi; the ball centre on angle 0.
                        let s = if convex {
                            d * phi.cos() - q.sqrt()
                        } else {
                            d * phi.cos() + q.sqrt()
                        };
                        let e = if convex { s - big } else { big - s };
                        let hit = [s * phi.cos(), s * phi.sin()];
                        let m = [(hit[0] - d) / r, hit[1] / r];
                        let n = if convex {
                            [phi.cos(), phi.sin()]
                        } else {
                            [-phi.cos(), -phi.sin()]
                        };
                        Some((e, -r * (m[0] * n[0] + m[1] * n[1])))
                    };
                    let step = 1e-4;
                    let mut checked = 0;
                    for i in 0..400 {
                        let x = i as f64 * 0.001;
                        let (Some((e0, w)), Some((em, _)), Some((ep, _))) =
                            (at(x), at(x - step), at(x + step))
                        else {
                            break;
                        };
                        if w < 0.2 * r {
                            break;
                        }
                        let second = (ep - 2.0 * e0 + em) / (step * step);
                        let bound = second_derivative_bound(r, kappa, w, e0);
                        assert!(
                            second <= bound * (1.0 + 1e-4),
                            "R {big} convex {convex} c {c} x {x}: e'' {second} > {bound}"
                        );
                        if convex || !big.is_finite() {
                            // Exact there, not only a bound.
                            assert!((second - bound).abs() < 1e-4 * bound, "{second} vs {bound}");
                        }
                        checked += 1;
                    }
                    assert!(checked > 100, "{checked} points checked");
                }
            }
        }
    }

    /// Brute force over a fine grid of the rectangle.
    fn brute(vals: [f64; 4], grads: [[f64; 2]; 4], du: f64, dv: f64, h: [f64; 2]) -> f64 {
        let xs = [[0.0, 0.0], [du, 0.0], [0.0, dv], [du, dv]];
        let mut best = f64::NEG_INFINITY;
        let n = 400;
        for i in 0..=n {
            for j in 0..=n {
                let x = [du * i as f64 / n as f64, dv * j as f64 / n as f64];
                let m = (0..4)
                    .map(|k| {
                        let d = [x[0] - xs[k][0], x[1] - xs[k][1]];
                        vals[k]
                            + grads[k][0] * d[0]
                            + grads[k][1] * d[1]
                            + 0.5 * (h[0] * d[0] * d[0] + h[1] * d[1] * d[1])
                    })
                    .fold(f64::INFINITY, f64::min);
                best = best.max(m);
            }
        }
        best
    }

    #[test]
    fn parabola_envelope_maximum() {
        for (a, b, len, h) in [
            (0.0, 0.0, 1.0, 2.0),
            (0.3, -0.1, 0.5, 4.0),
            (-1.0, 0.2, 0.1, 1.0),
        ] {
            let brute = (0..=100_000)
                .map(|i| {
                    let t = len * i as f64 / 100_000.0;
                    (a + 0.5 * h * t * t).min(b + 0.5 * h * (len - t).powi(2))
                })
                .fold(f64::NEG_INFINITY, f64::max);
            let exact = max_of_min_parabolas(a, b, len, h);
            assert!(
                exact >= brute - 1e-15 && exact - brute < 1e-9,
                "{exact} vs {brute}"
            );
        }
    }

    #[test]
    fn arrangement_vertices_give_the_maximum() {
        let mut uniform = crate::testing::uniform(99u64);
        let mut rnd = || uniform() * 2.0 - 1.0;
        for _ in 0..200 {
            let vals = [rnd(), rnd(), rnd(), rnd()].map(|x| 0.01 * x);
            let grads = [0; 4].map(|_| [rnd(), rnd()]);
            let (du, dv) = (0.02 * (1.5 + rnd()), 0.02 * (1.5 + rnd()));
            let h = [2.0 * (1.0 + rnd()), 2.0 * (1.0 + rnd())];
            let (exact, at) = max_of_min_quadratics(vals, grads, du, dv, h);
            assert!((0.0..=du).contains(&at[0]) && (0.0..=dv).contains(&at[1]));
            let b = brute(vals, grads, du, dv, h);
            // The brute force samples a subset: it can only be lower, and only slightly.
            assert!(exact >= b - 1e-15, "{exact} < {b}");
            // ... by at most its grid step times the steepest slope.
            let slope = grads
                .iter()
                .map(|g| g[0].abs() + g[1].abs())
                .fold(0.0, f64::max)
                + h[0] * du
                + h[1] * dv;
            assert!(exact - b <= slope * (du + dv) / 400.0, "{exact} vs {b}");
        }
    }
}
