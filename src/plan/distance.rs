//! Distance from segments (a ball's centre moving in a straight line) to the surface,
//! exactly against a tessellation within a known tolerance of it, through a bounding-volume
//! hierarchy of its triangles.
//!
//! Owns: the hierarchy and the segment–triangle distance. Must not: know what the segments
//! are for (air moves, lifted points); callers add the tessellation's tolerance to their
//! margins.

use crate::geom::{Point3, Vector3};
use crate::model::Model;

/// Triangles per leaf of the hierarchy.
const LEAF: usize = 4;

/// A node: its box, and either two children or a range of triangles.
#[derive(Debug, Clone, Copy)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Children (`left`, `left + 1`) when `count` is 0, else the first triangle.
    first: u32,
    count: u32,
}

/// The surface's triangles in a hierarchy of boxes.
pub struct SurfaceDistance {
    tris: Vec<[Point3; 3]>,
    nodes: Vec<Node>,
    /// Largest distance between the triangles and the surface (mm).
    pub tolerance_mm: f64,
}

/// Margin on the measured deviation (the triangles are measured at a few points each).
const MEASURE_MARGIN: f64 = 1.25;

impl SurfaceDistance {
    /// Tessellates `model` within about `tolerance_mm` and builds the hierarchy. The
    /// result's `tolerance_mm` is the deviation measured at each triangle's middle and edge
    /// midpoints, with a margin, and at least the one asked for.
    pub fn new(model: &Model, tolerance_mm: f64) -> Self {
        Self::with_tessellation(model, tolerance_mm)
    }

    fn with_tessellation(model: &Model, chordal_mm: f64) -> Self {
        let t = model.tessellate(chordal_mm);
        let p = |i: u32| {
            let k = 3 * i as usize;
            Point3::new(
                t.positions[k] as f64,
                t.positions[k + 1] as f64,
                t.positions[k + 2] as f64,
            )
        };
        let tris: Vec<[Point3; 3]> = t
            .indices
            .chunks(3)
            .map(|c| [p(c[0]), p(c[1]), p(c[2])])
            .collect();
        // Single-precision positions round by up to half an ulp of the coordinates.
        let reach = tris
            .iter()
            .flatten()
            .map(|q| q.x.abs().max(q.y.abs()).max(q.z.abs()))
            .fold(0.0, f64::max);
        // The deviation: the surface at the middle and the edge midpoints of each triangle
        // (in the parameters of a face that holds all three corners) from the triangle.
        let mut measured: f64 = 0.0;
        for (k, c) in t.indices.chunks(3).enumerate() {
            let [a, b, e] = [0, 1, 2].map(|i| t.params[c[i] as usize]);
            if a.0 != b.0 || a.0 != e.0 {
                continue;
            }
            let face = a.0 as usize;
            for (x, y) in [
                ((a.1 + b.1 + e.1) / 3.0, (a.2 + b.2 + e.2) / 3.0),
                (0.5 * (a.1 + b.1), 0.5 * (a.2 + b.2)),
                (0.5 * (b.1 + e.1), 0.5 * (b.2 + e.2)),
                (0.5 * (e.1 + a.1), 0.5 * (e.2 + a.2)),
            ] {
                let q = model.surface.subs(face, x, y);
                measured = measured.max(point_triangle_distance(&q, &tris[k]));
            }
        }
        let mut d = SurfaceDistance {
            tris,
            nodes: Vec::new(),
            tolerance_mm: (MEASURE_MARGIN * measured).max(chordal_mm) + reach * f32::EPSILON as f64,
        };
        d.build();
        d
    }

    fn build(&mut self) {
        let n = self.tris.len();
        if n == 0 {
            return;
        }
        let mut order: Vec<u32> = (0..n as u32).collect();
        let centre = |t: &[Point3; 3]| (t[0].coords + t[1].coords + t[2].coords) / 3.0;
        let centres: Vec<Vector3> = self.tris.iter().map(centre).collect();
        // Nodes built breadth-first so children sit next to each other.
        self.nodes.push(Node {
            lo: [0.0; 3],
            hi: [0.0; 3],
            first: 0,
            count: n as u32,
        });
        let mut stack = vec![(0usize, 0usize, n)];
        while let Some((node, a, b)) = stack.pop() {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &t in &order[a..b] {
                for q in &self.tris[t as usize] {
                    for k in 0..3 {
                        lo[k] = lo[k].min(q[k]);
                        hi[k] = hi[k].max(q[k]);
                    }
                }
            }
            self.nodes[node].lo = lo;
            self.nodes[node].hi = hi;
            if b - a <= LEAF {
                self.nodes[node].first = a as u32;
                self.nodes[node].count = (b - a) as u32;
                continue;
            }
            // Split at the median centre along the box's longest side.
            let axis = (0..3)
                .max_by(|&i, &j| (hi[i] - lo[i]).total_cmp(&(hi[j] - lo[j])))
                .unwrap_or(0);
            let mid = (a + b) / 2;
            order[a..b].select_nth_unstable_by(mid - a, |&x, &y| {
                centres[x as usize][axis].total_cmp(&centres[y as usize][axis])
            });
            let left = self.nodes.len();
            for _ in 0..2 {
                self.nodes.push(Node {
                    lo: [0.0; 3],
                    hi: [0.0; 3],
                    first: 0,
                    count: 0,
                });
            }
            self.nodes[node].first = left as u32;
            self.nodes[node].count = 0;
            stack.push((left, a, mid));
            stack.push((left + 1, mid, b));
        }
        // Leaves index the triangles in `order`: store them so.
        self.tris = order.iter().map(|&t| self.tris[t as usize]).collect();
    }

    /// True if the segment from `a` to `b` comes closer than `limit` (mm) to some triangle.
    pub fn segment_within(&self, a: &Point3, b: &Point3, limit: f64) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = self.nodes[i];
            if !segment_meets_box(a, b, &node.lo, &node.hi, limit) {
                continue;
            }
            if node.count == 0 {
                stack.push(node.first as usize);
                stack.push(node.first as usize + 1);
                continue;
            }
            let first = node.first as usize;
            for t in &self.tris[first..first + node.count as usize] {
                if segment_triangle_distance(a, b, t) < limit {
                    return true;
                }
            }
        }
        false
    }
}

/// True if the segment comes within `grow` of the box (tested against the box grown by
/// `grow` on every side, which contains that neighbourhood).
fn segment_meets_box(a: &Point3, b: &Point3, lo: &[f64; 3], hi: &[f64; 3], grow: f64) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        let (l, h) = (lo[k] - grow, hi[k] + grow);
        if d[k].abs() < f64::MIN_POSITIVE {
            if a[k] < l || a[k] > h {
                return false;
            }
            continue;
        }
        let (mut u, mut v) = ((l - a[k]) / d[k], (h - a[k]) / d[k]);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        t0 = t0.max(u);
        t1 = t1.min(v);
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// Distance between point `p` and triangle `t`.
fn point_triangle_distance(p: &Point3, t: &[Point3; 3]) -> f64 {
    (p - closest_on_triangle(p, t)).norm()
}

/// The point of triangle `t` nearest to `p` (by the regions of its plane).
fn closest_on_triangle(p: &Point3, t: &[Point3; 3]) -> Point3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        return a;
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// Distance between segments `p0 p1` and `q0 q1`.
fn segment_segment_distance(p0: &Point3, p1: &Point3, q0: &Point3, q1: &Point3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t);
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return r.norm();
    }
    if a <= f64::MIN_POSITIVE {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= f64::MIN_POSITIVE {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut ss = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut tt = (b * ss + f) / e;
            if tt < 0.0 {
                tt = 0.0;
                ss = (-c / a).clamp(0.0, 1.0);
            } else if tt > 1.0 {
                tt = 1.0;
                ss = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = ss;
            t = tt;
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

/// Distance between segment `a b` and triangle `t`: zero if the segment crosses it, else
/// the least of the endpoints' distances to it and the segment's to its edges.
pub fn segment_triangle_distance(a: &Point3, b: &Point3, t: &[Point3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let (da, db) = ((a - t[0]).dot(&n), (b - t[0]).dot(&n));
    if da * db <= 0.0 && n.norm_squared() > 0.0 && da != db {
        // The segment meets the plane: inside the triangle is distance zero.
        let x = a + (b - a) * (da / (da - db));
        if point_triangle_distance(&x, t) <= f64::EPSILON * (1.0 + x.coords.norm()) {
            return 0.0;
        }
    }
    let mut best = point_triangle_distance(a, t).min(point_triangle_distance(b, t));
    for k in 0..3 {
        best = best.min(segment_segment_distance(a, b, &t[k], &t[(k + 1) % 3]));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_triangle_distances_match_hand_computed_ones() {
        let t = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 2.0, 0.0),
        ];
        let d = |a: [f64; 3], b: [f64; 3]| {
            segment_triangle_distance(&Point3::from(a), &Point3::from(b), &t)
        };
        // Above the inside, parallel to the plane.
        assert!((d([0.2, 0.2, 1.0], [0.5, 0.5, 1.0]) - 1.0).abs() < 1e-15);
        // Through the triangle.
        assert_eq!(d([0.5, 0.5, -1.0], [0.5, 0.5, 1.0]), 0.0);
        // Beside the hypotenuse, crossing the plane outside: distance to the edge.
        let q = 3.0 / 2f64.sqrt() - 2f64.sqrt();
        assert!((d([1.5, 1.5, -1.0], [1.5, 1.5, 1.0]) - q).abs() < 1e-14);
        // Skew to an edge: the segment x = 1, z = 1 runs over the edge y = 0, z = 0.
        assert!((d([1.0, -1.0, 1.0], [1.0, -3.0, 1.0]) - 2f64.sqrt()).abs() < 1e-14);
    }

    #[test]
    fn the_hierarchy_finds_what_brute_force_finds() {
        let m = crate::model::samples::load_sample("keycap-convex").unwrap();
        let dist = SurfaceDistance::new(&m, 0.01);
        let bb = m.surface.bbox();
        let mut rnd = crate::testing::uniform(12345u64);
        let mut agree = 0;
        for _ in 0..200 {
            let p = |r: &mut dyn FnMut() -> f64| {
                Point3::new(
                    bb.min[0] + (bb.max[0] - bb.min[0]) * r(),
                    bb.min[1] + (bb.max[1] - bb.min[1]) * r(),
                    bb.min[2] + (bb.max[2] - bb.min[2]) * (1.5 * r() - 0.25),
                )
            };
            let (a, b) = (p(&mut rnd), p(&mut rnd));
            let limit = 0.5 * rnd();
            let brute = dist
                .tris
                .iter()
                .any(|t| segment_triangle_distance(&a, &b, t) < limit);
            assert_eq!(dist.segment_within(&a, &b, limit), brute);
            agree += brute as usize;
        }
        assert!(
            agree > 10,
            "some segments must come near the surface: {agree}"
        );
    }
}
