//! One measurement: from a point on the design surface, along the tool-side normal, where
//! does the union of the swept balls begin? Above the point that is the material left
//! (scallop); if the point itself was swept, the depth the cut went below it (gouge).

use super::capsule::{Capsule, LineHit, Span};
use super::index::{query_ball, CapsuleIndex};
use crate::geom::{Point3, Vector3};

/// Length of the first look along the normal, either way, in index cells.
const NEAR_CELLS: f64 = 0.1;
/// Relative slack on a focus's distance test, for rounding (dimensionless).
const FOCUS_SLACK: f64 = 1e-9;

/// The capsule that decides a measurement and where the line meets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Governing {
    /// Index of the capsule (move) in the path.
    pub capsule: u32,
    /// The line hit.
    pub hit: LineHit,
}

/// What a measurement found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Material {
    /// The swept volume begins `left_mm` along the normal from the point: positive is
    /// material left (scallop), negative a gouge that deep. `governing.hit.t_in == left_mm`.
    Left { left_mm: f64, governing: Governing },
    /// No swept ball comes within the reach along the normal: the tool never came near.
    Unreached,
}

/// What [`Probe::read_against`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reading {
    /// The point was swept (a cut reaches it or goes below it; how deep is not measured).
    Swept,
    /// This much material is left above the point (mm), as [`Probe::measure`] finds it.
    Left(f64),
    /// More material than the level read against is left (how much is not measured).
    Over,
    /// No swept ball comes within the reach along the normal.
    Unreached,
}

/// A reusable query context (one per thread): the index, the capsules and scratch space.
pub struct Probe<'a> {
    capsules: &'a [Capsule],
    index: &'a CapsuleIndex,
    radius: f64,
    /// How far above the surface a ball may be and still count as having reached it (mm).
    reach: f64,
    /// Deepest gouge looked for (mm).
    max_depth: f64,
    seen: Vec<u32>,
    stamp: u32,
    hits: Vec<(u32, Span)>,
    /// Straight depth of the point last measured, where it was swept.
    depth: Option<f64>,
    /// The capsules near a small ball that queries inside it test ([`Probe::focus`]).
    focus: Option<Focus>,
}

/// The capsules that may meet a segment within `radius` of `centre`, in index order.
struct Focus {
    centre: Point3,
    radius: f64,
    capsules: Vec<u32>,
    /// Their bounding balls ([`CapsuleIndex::ball`]), side by side: a query reads them in
    /// turn and tests only the capsules near it ([`CapsuleIndex::near_query`]).
    balls: Vec<[f64; 4]>,
}

impl Focus {
    /// The capsules that may meet the segment from `a` to `b`, in the focus's order.
    fn near<'f>(
        &'f self,
        index: &'f CapsuleIndex,
        capsules: &'f [Capsule],
        a: &Point3,
        b: &Point3,
    ) -> impl Iterator<Item = u32> + 'f {
        let (mid, half) = query_ball(a, b);
        self.capsules
            .iter()
            .zip(&self.balls)
            .filter(move |(&i, ball)| index.near_query(capsules, i, ball, &mid, half))
            .map(|(&i, _)| i)
    }
}

impl<'a> Probe<'a> {
    pub fn new(
        capsules: &'a [Capsule],
        index: &'a CapsuleIndex,
        radius: f64,
        reach: f64,
        max_depth: f64,
    ) -> Self {
        Probe {
            capsules,
            index,
            radius,
            reach,
            max_depth,
            seen: vec![0; capsules.len()],
            stamp: 0,
            hits: Vec::new(),
            depth: None,
            focus: None,
        }
    }

    /// Length of the first look along the normal, either way (mm).
    pub fn near_mm(&self) -> f64 {
        (NEAR_CELLS * self.index.cell_mm()).min(self.reach)
    }

    /// Lists once the capsules that may meet a query segment lying within `radius` of
    /// `centre` (those whose segment comes within the tool radius plus `radius` of it);
    /// queries inside that ball then test only these, others go through the index as
    /// before. The capsules found are the same either way (every capsule a segment meets
    /// is in both), though maybe in another order. Many measurements round one small
    /// spot then cost a few capsule tests each instead of a grid cell's worth. A ball wider
    /// than a cell's half-diagonal is not focused on.
    pub fn focus(&mut self, centre: &Point3, radius: f64) {
        let g = Vector3::repeat(radius);
        let (lo, hi) = (centre - g, centre + g);
        let (mut list, mut balls) = self
            .focus
            .take()
            .map(|f| (f.capsules, f.balls))
            .unwrap_or_default();
        list.clear();
        balls.clear();
        // Only inside the grid: outside it the index lists nothing, and the focus must find
        // what the index finds. And only a ball no wider than a cell's reach past its
        // centre: a wider one lists more capsules than a cell does (Bike.tsm's long
        // footprints made a plan 20 % slower).
        let half_diagonal = 0.5 * 3f64.sqrt() * self.index.cell_mm();
        if radius > half_diagonal || !self.index.holds_box(&lo, &hi) {
            return;
        }
        self.next_stamp();
        let within = (self.radius + radius) * (1.0 + FOCUS_SLACK);
        let caps = self.capsules;
        self.index
            .visit_box(&lo, &hi, &mut self.seen, self.stamp, |i| {
                if (caps[i as usize].closest_on_axis(centre) - centre).norm() <= within {
                    list.push(i);
                }
            });
        list.sort_unstable();
        balls.extend(list.iter().map(|&i| self.index.ball(i)));
        self.focus = Some(Focus {
            centre: *centre,
            radius,
            capsules: list,
            balls,
        });
    }

    /// Queries go through the index again.
    pub fn unfocus(&mut self) {
        self.focus = None;
    }

    fn next_stamp(&mut self) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.iter_mut().for_each(|s| *s = 0);
            self.stamp = 1;
        }
    }

    /// Hits of the line `p + t·n` for `t` in `[lo, hi]` with every capsule near it.
    fn gather(&mut self, p: &Point3, n: &Vector3, lo: f64, hi: f64) {
        self.hits.clear();
        let (a, b) = (p + n * lo, p + n * hi);
        let (caps, r) = (self.capsules, self.radius);
        if let (Some(f), true) = (&self.focus, self.focused(&a, &b)) {
            for i in f.near(self.index, caps, &a, &b) {
                if let Some(h) = caps[i as usize].interval(r, p, n, lo, hi) {
                    self.hits.push((i, h));
                }
            }
            return;
        }
        self.next_stamp();
        let hits = &mut self.hits;
        self.index
            .visit(caps, &a, &b, &mut self.seen, self.stamp, |i| {
                if let Some(h) = caps[i as usize].interval(r, p, n, lo, hi) {
                    hits.push((i, h));
                }
            });
    }

    /// Gathers the hits of the first look of [`Probe::measure`] (over `[−near, near]`),
    /// stopping at the first capsule containing `p`: returns whether there is one (then
    /// the hits are incomplete) or, if not, leaves every hit of that look gathered.
    fn gather_unless_swept(&mut self, p: &Point3, n: &Vector3) -> bool {
        let near = self.near_mm();
        self.hits.clear();
        let (a, b) = (p - n * near, p + n * near);
        let focused = self.focused(&a, &b);
        if !focused {
            self.next_stamp();
        }
        let (caps, r) = (self.capsules, self.radius);
        let hits = &mut self.hits;
        let mut found = false;
        // Tests capsule `i` unless one containing `p` was found; says whether one was.
        let mut test = |i: u32| {
            if !found {
                if let Some(h) = caps[i as usize].interval(r, p, n, -near, near) {
                    found = h.t_in <= 0.0 && h.t_out >= 0.0;
                    hits.push((i, h));
                }
            }
            found
        };
        match (&self.focus, focused) {
            (Some(f), true) => {
                for i in f.near(self.index, caps, &a, &b) {
                    if test(i) {
                        return true;
                    }
                }
                false
            }
            _ => {
                let mut swept = false;
                self.index
                    .visit(caps, &a, &b, &mut self.seen, self.stamp, |i| {
                        swept = test(i);
                    });
                swept
            }
        }
    }

    /// Whether the focus holds every capsule meeting the segment from `a` to `b`.
    fn focused(&self, a: &Point3, b: &Point3) -> bool {
        self.focus
            .as_ref()
            .is_some_and(|f| (a - f.centre).norm() <= f.radius && (b - f.centre).norm() <= f.radius)
    }

    /// What [`Probe::measure`] finds at `p` along the unit tool-side normal `n`, read
    /// against `level` (mm): how deep a swept point was cut and how much more than `level`
    /// is left are not measured, where finding them would cost more than the rest (many
    /// overlapping balls; a long look along the normal). Material left up to `level` is
    /// measured as [`Probe::measure`] does.
    pub fn read_against(&mut self, p: &Point3, n: &Vector3, level: f64) -> Reading {
        self.depth = None;
        if self.gather_unless_swept(p, n) {
            return Reading::Swept;
        }
        let near = self.near_mm();
        // As `measure`: nothing contains `p`, so the first capsule entered decides.
        if let Some(t) = self
            .hits
            .iter()
            .filter(|(_, h)| h.t_in > 0.0 && h.t_in <= near)
            .map(|(_, h)| h.t_in)
            .min_by(f64::total_cmp)
        {
            return Reading::Left(t);
        }
        if level > near {
            return match self.measure(p, n) {
                Material::Left { left_mm, .. } => Reading::Left(left_mm),
                Material::Unreached => Reading::Unreached,
            };
        }
        // More than `near` is left if any ball comes within the reach: look up to it, and
        // stop at the first.
        let (a, b) = (p + n * near, p + n * self.reach);
        let focused = self.focused(&a, &b);
        if !focused {
            self.next_stamp();
        }
        let (caps, r, reach) = (self.capsules, self.radius, self.reach);
        let mut found = false;
        let test = |i: u32| {
            found = found
                || caps[i as usize]
                    .interval(r, p, n, near, reach)
                    .is_some_and(|h| h.t_in > 0.0);
        };
        match (&self.focus, focused) {
            (Some(f), true) => f.near(self.index, caps, &a, &b).for_each(test),
            _ => self
                .index
                .visit(caps, &a, &b, &mut self.seen, self.stamp, test),
        }
        if found {
            Reading::Over
        } else {
            Reading::Unreached
        }
    }

    /// The capsule nearest to `p` (distance from its segment) within `within` mm, and the
    /// closest point of its segment; used to tell which side of the surface the tool is on.
    pub fn nearest_centre(&mut self, p: &Point3, n: &Vector3, within: f64) -> Option<Point3> {
        self.next_stamp();
        let (a, b) = (p - n * within, p + n * within);
        let caps = self.capsules;
        let mut best: Option<(f64, Point3)> = None;
        self.index
            .visit(caps, &a, &b, &mut self.seen, self.stamp, |i| {
                let c = caps[i as usize].closest_on_axis(p);
                let d = (c - p).norm();
                if d <= within && best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, c));
                }
            });
        best.map(|(_, c)| c)
    }

    /// How deep the point `p` lies inside the swept volume, measured straight (mm): the ball
    /// radius less the distance from `p` to the nearest capsule's segment, 0 if outside every
    /// capsule. For a point the line along the normal found swept, this is how far the cut
    /// reaches past the surface there; along the normal itself a cut may look much deeper
    /// near a concave crease, where the normal of one side runs inside the thin layer cut
    /// under the other side.
    pub fn straight_depth(&mut self, p: &Point3, n: &Vector3) -> f64 {
        let r = self.radius;
        self.nearest_centre(p, n, r)
            .map_or(0.0, |c| (r - (c - p).norm()).max(0.0))
    }

    /// The measurement `left_mm` decided by capsule `i` entered along `span`.
    fn left(&self, p: &Point3, n: &Vector3, i: u32, span: &Span) -> Material {
        Material::Left {
            left_mm: span.t_in,
            governing: Governing {
                capsule: i,
                hit: LineHit {
                    t_in: span.t_in,
                    t_out: span.t_out,
                    normal_in: self.capsules[i as usize].normal_at(self.radius, p, n, span),
                },
            },
        }
    }

    /// Measures at `p` along the unit tool-side normal `n`. Where `p` was swept, also finds
    /// its [`Probe::straight_depth`] from the same look ([`Probe::last_straight_depth`]).
    pub fn measure(&mut self, p: &Point3, n: &Vector3) -> Material {
        // Most points are cut within a cell's length above them or lie in the thin layer a
        // chord cuts below the surface: one look over [−near, near] serves both. Every
        // capsule containing `p` or entered before `near` meets that segment.
        let near = self.near_mm();
        self.gather(p, n, -near, near);
        self.depth = None;
        let contains = |h: &Span| h.t_in <= 0.0 && h.t_out >= 0.0;
        if !self.hits.iter().any(|(_, h)| contains(h)) {
            if let Some(&(i, h)) = self
                .hits
                .iter()
                .filter(|(_, h)| h.t_in > 0.0 && h.t_in <= near)
                .min_by(|a, b| a.1.t_in.total_cmp(&b.1.t_in))
            {
                return self.left(p, n, i, &h);
            }
            // Nothing near: look up to the reach.
            self.gather(p, n, near, self.reach);
            return match self
                .hits
                .iter()
                .filter(|(_, h)| h.t_in > 0.0)
                .min_by(|a, b| a.1.t_in.total_cmp(&b.1.t_in))
            {
                Some(&(i, h)) => self.left(p, n, i, &h),
                None => Material::Unreached,
            };
        }
        // The capsules containing `p` are those whose segment is within the radius of it:
        // the nearest decides the straight depth.
        let r = self.radius;
        let nearest = self
            .hits
            .iter()
            .filter(|(_, h)| contains(h))
            .map(|&(i, _)| {
                let c = &self.capsules[i as usize];
                (c.closest_on_axis(p) - p).norm()
            })
            .fold(f64::INFINITY, f64::min);
        self.depth = Some((r - nearest).max(0.0));
        // The point was swept: follow overlapping capsules downwards to the deepest point of
        // the swept region connected to it (the first look's hits serve down to −near).
        let mut lo = -near;
        let mut first = true;
        loop {
            if !first {
                self.gather(p, n, lo, 0.0);
            }
            first = false;
            let mut deepest: Option<(u32, Span)> = None;
            for &(i, h) in &self.hits {
                if contains(&h) && deepest.is_none_or(|(_, d)| h.t_in < d.t_in) {
                    deepest = Some((i, h));
                }
            }
            let Some(mut d) = deepest else {
                // Only rounding can get here (the first look found a capsule at 0).
                return match self.hits.first() {
                    Some(&(i, h)) => self.left(p, n, i, &h),
                    None => Material::Unreached,
                };
            };
            loop {
                let mut grew = false;
                for &(i, h) in &self.hits {
                    if h.t_in < d.1.t_in && h.t_out >= d.1.t_in {
                        d = (i, h);
                        grew = true;
                    }
                }
                if !grew {
                    break;
                }
            }
            if d.1.t_in <= lo && lo > -self.max_depth {
                // The cut may go deeper than this look reached: look further down.
                lo = (lo * 4.0).max(-self.max_depth);
                continue;
            }
            return self.left(p, n, d.0, &d.1);
        }
    }

    /// The [`Probe::straight_depth`] of the point the last [`Probe::measure`] found swept
    /// (`None` if it was not, or a [`Probe::read_against`] came after it), found from the
    /// same look.
    pub fn last_straight_depth(&self) -> Option<f64> {
        self.depth
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Aabb;

    /// The box the scattered moves lie in, with room round them (mm).
    const REGION: Aabb = Aabb {
        min: [-2.0, -2.0, -3.0],
        max: [8.0, 8.0, 3.0],
    };

    /// `count` random straight moves of balls of radius `r` over a 6 mm square, their
    /// lowest points from 0.3 mm below to 0.9 mm above Z 0.
    fn scattered(rnd: &mut impl FnMut() -> f64, count: usize, r: f64) -> Vec<Capsule> {
        (0..count)
            .map(|_| {
                let a = Point3::new(6.0 * rnd(), 6.0 * rnd(), r - 0.3 + 1.2 * rnd());
                let d = Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.3 * (rnd() - 0.5)) * 2.0;
                Capsule::new(a, a + d)
            })
            .collect()
    }

    /// The measurement equals a brute force over every capsule: the first entry above the
    /// point, or the bottom of the swept region containing it.
    #[test]
    fn agrees_with_brute_force_over_all_capsules() {
        let mut rnd = crate::testing::uniform(777u64);
        let r = 0.5;
        let capsules = scattered(&mut rnd, 300, r);
        let index = CapsuleIndex::build(&capsules, r, &REGION, 0.5 * r);
        let mut probe = Probe::new(&capsules, &index, r, r, 10.0);
        let (mut gouges, mut left, mut unreached) = (0, 0, 0);
        for _ in 0..3000 {
            let p = Point3::new(6.0 * rnd(), 6.0 * rnd(), 0.0);
            let n = Vector3::new(0.2 * (rnd() - 0.5), 0.2 * (rnd() - 0.5), 1.0).normalize();
            let spans: Vec<Span> = capsules
                .iter()
                .filter_map(|c| c.interval(r, &p, &n, f64::NEG_INFINITY, f64::INFINITY))
                .collect();
            let expect = if spans.iter().any(|s| s.t_in <= 0.0 && s.t_out >= 0.0) {
                let mut lo = 0.0f64;
                loop {
                    let next = spans
                        .iter()
                        .filter(|s| s.t_out >= lo && s.t_in <= lo)
                        .map(|s| s.t_in)
                        .fold(lo, f64::min);
                    if next == lo {
                        break;
                    }
                    lo = next;
                }
                gouges += 1;
                Some(lo)
            } else {
                let first = spans
                    .iter()
                    .filter(|s| s.t_in > 0.0 && s.t_in <= r)
                    .map(|s| s.t_in)
                    .fold(f64::INFINITY, f64::min);
                if first.is_finite() {
                    left += 1;
                    Some(first)
                } else {
                    unreached += 1;
                    None
                }
            };
            match (probe.measure(&p, &n), expect) {
                (Material::Left { left_mm, governing }, Some(e)) => {
                    assert_eq!(left_mm, e);
                    assert_eq!(governing.hit.t_in, e);
                }
                (Material::Unreached, None) => {}
                (got, e) => panic!("at {p:?}: measured {got:?}, brute force {e:?}"),
            }
        }
        assert!(
            gouges > 100 && left > 100 && unreached > 10,
            "{gouges} {left} {unreached}"
        );
    }

    /// A reading against a level says what the full measurement says: swept where it
    /// finds the point cut (left ≤ 0), the same material left up to the level, more than the
    /// level where it reads `Over`, unreached alike; through the index and through a focus,
    /// with the level below and above the first look's length.
    #[test]
    fn reading_against_a_level_agrees_with_the_measurement() {
        let mut rnd = crate::testing::uniform(4711u64);
        let r = 0.5;
        let capsules = scattered(&mut rnd, 400, r);
        let index = CapsuleIndex::build(&capsules, r, &REGION, 0.5 * r);
        let mut probe = Probe::new(&capsules, &index, r, r, 10.0);
        let near = probe.near_mm();
        let mut seen = [0usize; 4];
        for k in 0..4000 {
            let p = Point3::new(6.0 * rnd(), 6.0 * rnd(), 0.3 - 1.3 * rnd());
            let n = Vector3::new(0.2 * (rnd() - 0.5), 0.2 * (rnd() - 0.5), 1.0).normalize();
            // Every other point through a focus round it (wide enough for the first look
            // every time, for the look up to the reach only sometimes).
            if k % 2 == 0 {
                probe.focus(&p, 2.0 * near + 0.5 * r * rnd());
            } else {
                probe.unfocus();
            }
            let level = if k % 3 == 0 { 2.0 * near } else { 0.5 * near };
            let reading = probe.read_against(&p, &n, level);
            probe.unfocus();
            let measured = probe.measure(&p, &n);
            match (reading, measured) {
                (Reading::Swept, Material::Left { left_mm, .. }) if left_mm <= 0.0 => seen[0] += 1,
                (Reading::Left(t), Material::Left { left_mm, .. }) if t == left_mm && t > 0.0 => {
                    seen[1] += 1
                }
                (Reading::Over, Material::Left { left_mm, .. }) if left_mm > level => seen[2] += 1,
                (Reading::Unreached, Material::Unreached) => seen[3] += 1,
                (got, m) => panic!("at {p:?} against {level} mm: read {got:?}, measured {m:?}"),
            }
        }
        assert!(seen.iter().all(|&c| c > 50), "{seen:?}");
    }
}
