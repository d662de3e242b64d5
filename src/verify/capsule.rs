//! Where a straight line meets the volume a ball sweeps along one straight move: a capsule,
//! the points within the tool radius of the segment its centre travels. For a ball-end tool
//! this is the exact swept volume, so the intersection below is exact (closed form).

use crate::geom::{most, Point3, Vector3};

/// The segment a ball centre travels along one move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// Ball centre at the start of the move (mm).
    pub start: Point3,
    /// Unit direction of the move; zero for a move of zero length.
    pub dir: Vector3,
    /// Length of the move (mm).
    pub len: f64,
}

/// The part of a line `o + t·n` (unit `n`) inside a capsule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineHit {
    /// Line parameter (mm) where the line enters the capsule.
    pub t_in: f64,
    /// Line parameter (mm) where it leaves.
    pub t_out: f64,
    /// Outward unit normal of the capsule's boundary at the entry point.
    pub normal_in: Vector3,
}

/// Below this squared sine of the angle between the line and the move, the two are treated
/// as parallel (dimensionless); the line's distance to the axis is then constant.
const PARALLEL_SIN2: f64 = 1e-14;

/// Interval of the line `o + t·n` inside the ball of radius `r` centred at `c`.
#[inline(always)]
fn sphere(c: &Point3, r: f64, o: &Point3, n: &Vector3) -> Option<(f64, f64)> {
    let w = o - c;
    let b = w.dot(n);
    let disc = b * b - (w.norm_squared() - r * r);
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((-b - s, -b + s))
}

impl Capsule {
    /// The capsule of a ball centre moving from `a` to `b`.
    pub fn new(a: Point3, b: Point3) -> Self {
        let d = b - a;
        let len = d.norm();
        let dir = if len > 0.0 { d / len } else { Vector3::zeros() };
        Capsule { start: a, dir, len }
    }

    /// Ball centre at the end of the move.
    pub fn end(&self) -> Point3 {
        self.start + self.dir * self.len
    }

    /// Closest point of the move's segment to `p`.
    pub fn closest_on_axis(&self, p: &Point3) -> Point3 {
        let s = (p - self.start).dot(&self.dir).clamp(0.0, self.len);
        self.start + self.dir * s
    }

    /// The part of the line `o + t·n` (`n` a unit vector) inside the capsule of radius `r`,
    /// or `None` if the line misses it.
    pub fn intersect_line(&self, r: f64, o: &Point3, n: &Vector3) -> Option<LineHit> {
        let span = self.interval(r, o, n, f64::NEG_INFINITY, f64::INFINITY)?;
        Some(LineHit {
            t_in: span.t_in,
            t_out: span.t_out,
            normal_in: self.normal_at(r, o, n, &span),
        })
    }

    /// The part of the line `o + t·n` (`n` a unit vector) inside the capsule of radius `r`,
    /// if it overlaps `[lo, hi]`; the cheap form of [`Capsule::intersect_line`] (no normal).
    #[inline(always)]
    pub fn interval(&self, r: f64, o: &Point3, n: &Vector3, lo: f64, hi: f64) -> Option<Span> {
        let w = o - self.start;
        let wn = w.dot(n);
        let ww = w.norm_squared();
        let r2 = r * r;
        if self.len == 0.0 {
            let disc = wn * wn - (ww - r2);
            if disc < 0.0 {
                return None;
            }
            let s = disc.sqrt();
            return Span::within(-wn - s, -wn + s, Part::Start, Part::Start, lo, hi);
        }
        let nd = n.dot(&self.dir);
        let wd = w.dot(&self.dir);
        let a = 1.0 - nd * nd;
        let c = ww - wd * wd - r2;
        if a < PARALLEL_SIN2 {
            // Parallel to the move: inside the infinite cylinder or not at all; the body
            // lies between the two end balls along the line, so their union is the answer.
            if c > 0.0 {
                return None;
            }
            let sa = sphere(&self.start, r, o, n);
            let sb = sphere(&self.end(), r, o, n);
            return match (sa, sb) {
                (Some(x), Some(y)) => {
                    let (t_in, pin) = if x.0 <= y.0 {
                        (x.0, Part::Start)
                    } else {
                        (y.0, Part::End)
                    };
                    let (t_out, pout) = if x.1 >= y.1 {
                        (x.1, Part::Start)
                    } else {
                        (y.1, Part::End)
                    };
                    Span::within(t_in, t_out, pin, pout, lo, hi)
                }
                (Some(x), None) => Span::within(x.0, x.1, Part::Start, Part::Start, lo, hi),
                (None, Some(y)) => Span::within(y.0, y.1, Part::End, Part::End, lo, hi),
                (None, None) => None,
            };
        }
        let b = wn - wd * nd;
        let disc = b * b - a * c;
        if disc < 0.0 {
            // The line misses the infinite cylinder, which contains the whole capsule.
            return None;
        }
        let sq = disc.sqrt();
        let inv = 1.0 / a;
        let (t0, t1) = ((-b - sq) * inv, (-b + sq) * inv);
        // The capsule lies inside the infinite cylinder: no overlap there, none at all.
        if t1 < lo || t0 > hi {
            return None;
        }
        // The capsule is convex: where the line meets the cylinder beyond an end of the
        // segment, it meets the capsule on that end's ball instead.
        let cap = |s: f64| if s < 0.0 { Part::Start } else { Part::End };
        let s0 = wd + t0 * nd;
        let (t_in, pin) = if (0.0..=self.len).contains(&s0) {
            (t0, Part::Body)
        } else {
            let part = cap(s0);
            let centre = if s0 < 0.0 { self.start } else { self.end() };
            (sphere(&centre, r, o, n)?.0, part)
        };
        let s1 = wd + t1 * nd;
        let (t_out, pout) = if (0.0..=self.len).contains(&s1) {
            (t1, Part::Body)
        } else {
            let part = cap(s1);
            let centre = if s1 < 0.0 { self.start } else { self.end() };
            match sphere(&centre, r, o, n) {
                Some((_, to)) => (to, part),
                None => (t_in, pin),
            }
        };
        // Not `f64::max`, a call in wasm: this runs for every capsule a probe passes.
        let t_out = most(t_out, t_in);
        Span::within(t_in, t_out, pin, pout, lo, hi)
    }

    /// Outward unit normal of the capsule where the line of `span` enters it.
    pub fn normal_at(&self, r: f64, o: &Point3, n: &Vector3, span: &Span) -> Vector3 {
        let q = o + n * span.t_in;
        let centre = match span.part_in {
            Part::Start => self.start,
            Part::End => self.end(),
            Part::Body => self.closest_on_axis(&q),
        };
        (q - centre) / r
    }
}

/// Which part of a capsule a line enters or leaves through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The ball at the start of the move.
    Start,
    /// The ball at its end.
    End,
    /// The cylinder between.
    Body,
}

/// The interval of a line inside a capsule, and the parts it enters and leaves through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub t_in: f64,
    pub t_out: f64,
    pub part_in: Part,
    pub part_out: Part,
}

impl Span {
    #[inline]
    fn within(
        t_in: f64,
        t_out: f64,
        part_in: Part,
        part_out: Part,
        lo: f64,
        hi: f64,
    ) -> Option<Self> {
        (t_out >= lo && t_in <= hi).then_some(Span {
            t_in,
            t_out,
            part_in,
            part_out,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: march along the line and test the distance to the segment.
    fn marched(cap: &Capsule, r: f64, o: &Point3, n: &Vector3) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let steps = 200_000;
        for k in 0..=steps {
            let t = -5.0 + 10.0 * k as f64 / steps as f64;
            let q = o + n * t;
            if (q - cap.closest_on_axis(&q)).norm() <= r {
                lo = lo.min(t);
                hi = hi.max(t);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }

    #[test]
    fn agrees_with_marching_on_body_caps_and_misses() {
        let r = 0.7;
        let cap = Capsule::new(Point3::new(0.1, -0.2, 0.3), Point3::new(1.3, 0.4, -0.2));
        let mut uniform = crate::testing::uniform(12345u64);
        let mut rnd = || uniform() * 2.0 - 1.0;
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..300 {
            let o = Point3::new(0.7 + 1.5 * rnd(), 1.5 * rnd(), 1.5 * rnd());
            let n = Vector3::new(rnd(), rnd(), rnd()).normalize();
            let exact = cap.intersect_line(r, &o, &n);
            let march = marched(&cap, r, &o, &n);
            match (exact, march) {
                (Some(h), Some((lo, hi))) => {
                    hits += 1;
                    assert!((h.t_in - lo).abs() < 1e-4 && (h.t_out - hi).abs() < 1e-4);
                    let q = o + n * h.t_in;
                    let axis = cap.closest_on_axis(&q);
                    assert!((h.normal_in - (q - axis) / r).norm() < 1e-9);
                    assert!((h.normal_in.norm() - 1.0).abs() < 1e-9);
                }
                (None, None) => misses += 1,
                (e, m) => {
                    // Only tangent lines may disagree, by less than a march step.
                    let t = e.map(|h| h.t_out - h.t_in).unwrap_or(0.0);
                    let tm = m.map(|(a, b)| b - a).unwrap_or(0.0);
                    assert!(t.max(tm) < 1e-2, "exact {e:?} vs marched {m:?}");
                }
            }
        }
        assert!(hits > 50 && misses > 50, "{hits} hits, {misses} misses");
    }

    #[test]
    fn parallel_line_and_point_capsule() {
        let r = 0.5;
        let cap = Capsule::new(Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 0.0, 0.0));
        let h = cap
            .intersect_line(r, &Point3::new(-3.0, 0.3, 0.0), &Vector3::x())
            .unwrap();
        let half = (r * r - 0.09f64).sqrt();
        assert!((h.t_in - (3.0 - half)).abs() < 1e-12);
        assert!((h.t_out - (5.0 + half)).abs() < 1e-12);
        let ball = Capsule::new(Point3::new(1.0, 1.0, 1.0), Point3::new(1.0, 1.0, 1.0));
        let h = ball
            .intersect_line(r, &Point3::new(1.0, 1.0, 0.0), &Vector3::z())
            .unwrap();
        assert!((h.t_in - 0.5).abs() < 1e-15 && (h.t_out - 1.5).abs() < 1e-15);
        assert!((h.normal_in + Vector3::z()).norm() < 1e-15);
    }
}
