//! A uniform grid over the region around the surface, listing for every cell the capsules
//! that may reach into it: those whose segment passes within the tool radius plus the
//! cell's half-diagonal of the cell's centre. A query walks the cells a line segment passes
//! through (3D DDA); every capsule the segment meets is listed in one of them, and one met
//! in several cells is reported once per query. Before a listed capsule is reported, its
//! bounding ball is tested against the segment's (a few operations): most capsules of a cell
//! lie too far from a short query segment, and this test drops them before the exact one.

use super::capsule::Capsule;
use crate::geom::{Aabb, Point3};

/// Most cells the grid may have; a larger region gets coarser cells.
const MAX_CELLS: usize = 1 << 22;
/// Relative slack on the registration distance (dimensionless).
const SLACK: f64 = 1e-9;

/// Cells and the capsules in them (compressed rows).
#[derive(Debug, Clone)]
pub struct CapsuleIndex {
    origin: [f64; 3],
    cell_mm: f64,
    dims: [usize; 3],
    /// `starts[c]..starts[c + 1]` indexes `items` for cell `c`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Per capsule: the middle of its move and the radius of the ball around that middle
    /// holding the whole capsule (mm: tool radius plus half the move, with the slack).
    balls: Vec<[f64; 4]>,
    /// The tool radius with the slack (mm).
    radius_slack: f64,
}

impl CapsuleIndex {
    /// Indexes the capsules of radius `radius` that reach into `region`, on cells of about
    /// `cell_mm` (coarser if the region would need more than `MAX_CELLS` cells).
    pub fn build(capsules: &[Capsule], radius: f64, region: &Aabb, cell_mm: f64) -> Self {
        let size = region.size();
        let mut cell = cell_mm;
        let count = |c: f64| size.map(|s| ((s / c).ceil() as usize).max(1));
        while count(cell).iter().product::<usize>() > MAX_CELLS {
            cell *= 1.25;
        }
        let dims = count(cell);
        let mut index = CapsuleIndex {
            origin: region.min,
            cell_mm: cell,
            dims,
            starts: Vec::new(),
            items: Vec::new(),
            balls: capsules
                .iter()
                .map(|c| {
                    let m = c.start + c.dir * (0.5 * c.len);
                    [m.x, m.y, m.z, (radius + 0.5 * c.len) * (1.0 + SLACK)]
                })
                .collect(),
            radius_slack: radius * (1.0 + SLACK),
        };
        let ncells = dims[0] * dims[1] * dims[2];
        // A capsule meeting a point of a cell comes within r + half-diagonal of its centre;
        // the slack covers rounding in the walk along query segments.
        let half_diag = 0.5 * cell * 3f64.sqrt();
        let reach = radius + half_diag * (1.0 + SLACK);
        let reach2 = reach * reach;
        let ranges: Vec<Option<[(usize, usize); 3]>> = capsules
            .iter()
            .map(|c| {
                let (a, b) = (c.start, c.end());
                let lo = [0, 1, 2].map(|k| a[k].min(b[k]) - radius);
                let hi = [0, 1, 2].map(|k| a[k].max(b[k]) + radius);
                index.cell_range(&lo, &hi)
            })
            .collect();
        let origin = index.origin;
        let near = |c: &Capsule, cell_index: usize| {
            let x = cell_index % dims[0];
            let y = (cell_index / dims[0]) % dims[1];
            let z = cell_index / (dims[0] * dims[1]);
            let centre = Point3::new(
                origin[0] + (x as f64 + 0.5) * cell,
                origin[1] + (y as f64 + 0.5) * cell,
                origin[2] + (z as f64 + 0.5) * cell,
            );
            (c.closest_on_axis(&centre) - centre).norm_squared() <= reach2
        };
        let mut counts = vec![0u32; ncells + 1];
        for (c, range) in capsules.iter().zip(&ranges) {
            if let Some(range) = range {
                index.for_cells(range, |cell| {
                    if near(c, cell) {
                        counts[cell + 1] += 1
                    }
                });
            }
        }
        for k in 0..ncells {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[ncells] as usize];
        for (i, (c, range)) in capsules.iter().zip(&ranges).enumerate() {
            if let Some(range) = range {
                index.for_cells(range, |cell| {
                    if near(c, cell) {
                        items[fill[cell] as usize] = i as u32;
                        fill[cell] += 1;
                    }
                });
            }
        }
        index.starts = counts;
        index.items = items;
        index
    }

    /// Cell index ranges (inclusive) covering the box `lo..hi`, clipped to the grid; `None`
    /// if the box misses the grid.
    fn cell_range(&self, lo: &[f64; 3], hi: &[f64; 3]) -> Option<[(usize, usize); 3]> {
        let mut out = [(0, 0); 3];
        for k in 0..3 {
            let a = ((lo[k] - self.origin[k]) / self.cell_mm).floor();
            let b = ((hi[k] - self.origin[k]) / self.cell_mm).floor();
            let top = (self.dims[k] - 1) as f64;
            if !(b >= 0.0 && a <= top) {
                return None;
            }
            out[k] = (a.max(0.0) as usize, b.min(top) as usize);
        }
        Some(out)
    }

    fn for_cells(&self, range: &[(usize, usize); 3], mut f: impl FnMut(usize)) {
        for z in range[2].0..=range[2].1 {
            for y in range[1].0..=range[1].1 {
                let row = (z * self.dims[1] + y) * self.dims[0];
                for x in range[0].0..=range[0].1 {
                    f(row + x);
                }
            }
        }
    }

    /// Calls `f` with every capsule listed in a cell the segment `a`–`b` passes through
    /// whose bounding ball, then whose move's segment, comes within the tool radius plus
    /// the segment's half-length of its middle (every capsule the segment meets among
    /// them); `capsules` are those the index was built from; `seen[i] == stamp` marks
    /// capsule `i` as already reported in this query.
    pub fn visit(
        &self,
        capsules: &[Capsule],
        a: &Point3,
        b: &Point3,
        seen: &mut [u32],
        stamp: u32,
        mut f: impl FnMut(u32),
    ) {
        let (mid, half) = query_ball(a, b);
        let mut emit =
            |cell: usize| self.emit_near(capsules, cell, &mid, half, seen, stamp, &mut f);
        // Clip the segment to the grid's box (slabs).
        let d = b - a;
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let lo = self.origin[k];
            let hi = self.origin[k] + self.dims[k] as f64 * self.cell_mm;
            if d[k] == 0.0 {
                if a[k] < lo || a[k] > hi {
                    return;
                }
            } else {
                let (mut ta, mut tb) = ((lo - a[k]) / d[k], (hi - a[k]) / d[k]);
                if ta > tb {
                    std::mem::swap(&mut ta, &mut tb);
                }
                t0 = t0.max(ta);
                t1 = t1.min(tb);
            }
        }
        if t0 > t1 {
            return;
        }
        let start = a + d * t0;
        let cell_of = |x: f64, k: usize| {
            (((x - self.origin[k]) / self.cell_mm).floor().max(0.0) as usize).min(self.dims[k] - 1)
        };
        let mut c = [0, 1, 2].map(|k| cell_of(start[k], k));
        let last = {
            let end = a + d * t1;
            [0, 1, 2].map(|k| cell_of(end[k], k))
        };
        // Amanatides–Woo: parameter of the next boundary crossing per axis.
        let mut step = [0i64; 3];
        let mut t_max = [f64::INFINITY; 3];
        let mut t_delta = [f64::INFINITY; 3];
        for k in 0..3 {
            if d[k] > 0.0 {
                step[k] = 1;
                let edge = self.origin[k] + (c[k] + 1) as f64 * self.cell_mm;
                t_max[k] = (edge - a[k]) / d[k];
                t_delta[k] = self.cell_mm / d[k];
            } else if d[k] < 0.0 {
                step[k] = -1;
                let edge = self.origin[k] + c[k] as f64 * self.cell_mm;
                t_max[k] = (edge - a[k]) / d[k];
                t_delta[k] = -self.cell_mm / d[k];
            }
        }
        let index = |c: &[usize; 3]| (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0];
        emit(index(&c));
        // At most one crossing per cell boundary between the two end cells.
        let mut budget: usize = (0..3).map(|k| c[k].abs_diff(last[k])).sum();
        while c != last && budget > 0 {
            let k = if t_max[0] <= t_max[1] && t_max[0] <= t_max[2] {
                0
            } else if t_max[1] <= t_max[2] {
                1
            } else {
                2
            };
            let next = c[k] as i64 + step[k];
            if next < 0 || next >= self.dims[k] as i64 {
                break;
            }
            c[k] = next as usize;
            t_max[k] += t_delta[k];
            budget -= 1;
            emit(index(&c));
        }
    }

    /// Whether the box `lo..hi` lies inside the indexed region.
    pub fn holds_box(&self, lo: &Point3, hi: &Point3) -> bool {
        (0..3).all(|k| {
            lo[k] >= self.origin[k] && hi[k] <= self.origin[k] + self.dims[k] as f64 * self.cell_mm
        })
    }

    /// Calls `f` once with every capsule listed in a cell the box `lo..hi` overlaps (clipped
    /// to the grid): among them, every capsule that comes within the radius of a point of
    /// the box. `seen` and `stamp` as for [`CapsuleIndex::visit`].
    pub fn visit_box(
        &self,
        lo: &Point3,
        hi: &Point3,
        seen: &mut [u32],
        stamp: u32,
        mut f: impl FnMut(u32),
    ) {
        if let Some(range) = self.cell_range(&[lo.x, lo.y, lo.z], &[hi.x, hi.y, hi.z]) {
            self.for_cells(&range, |cell| self.emit_new(cell, seen, stamp, &mut f));
        }
    }

    /// Calls `f` with every capsule listed in `cell` not yet marked `stamp` in `seen`, and
    /// marks it.
    #[inline]
    fn emit_new(&self, cell: usize, seen: &mut [u32], stamp: u32, f: &mut impl FnMut(u32)) {
        let (s, e) = (self.starts[cell] as usize, self.starts[cell + 1] as usize);
        for &i in &self.items[s..e] {
            if seen[i as usize] != stamp {
                seen[i as usize] = stamp;
                f(i);
            }
        }
    }

    /// As [`CapsuleIndex::emit_new`], for the capsules of `cell` that may meet a query
    /// segment within `half` of `mid` only ([`CapsuleIndex::near_query`]); the others are
    /// neither reported nor marked (a second cell listing one tests it again, with the same
    /// answer).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn emit_near(
        &self,
        capsules: &[Capsule],
        cell: usize,
        mid: &[f64; 3],
        half: f64,
        seen: &mut [u32],
        stamp: u32,
        f: &mut impl FnMut(u32),
    ) {
        let (s, e) = (self.starts[cell] as usize, self.starts[cell + 1] as usize);
        for &i in &self.items[s..e] {
            if !self.near_query(capsules, i, &self.balls[i as usize], mid, half) {
                continue;
            }
            if seen[i as usize] != stamp {
                seen[i as usize] = stamp;
                f(i);
            }
        }
    }

    /// Whether capsule `i` (its bounding ball `ball`, as [`CapsuleIndex::ball`] gives it)
    /// may meet a query segment lying within `half` of `mid` ([`query_ball`]): first its
    /// bounding ball, then its segment, within the radius plus `half` of `mid`. False only
    /// for a capsule the segment cannot meet.
    #[inline]
    pub fn near_query(
        &self,
        capsules: &[Capsule],
        i: u32,
        ball: &[f64; 4],
        mid: &[f64; 3],
        half: f64,
    ) -> bool {
        let (dx, dy, dz) = (ball[0] - mid[0], ball[1] - mid[1], ball[2] - mid[2]);
        let within = ball[3] + half;
        if dx * dx + dy * dy + dz * dz > within * within {
            return false;
        }
        // Closer: the move's segment from the query's middle.
        let c = &capsules[i as usize];
        let (a, d) = (&c.start, &c.dir);
        let (wx, wy, wz) = (mid[0] - a.x, mid[1] - a.y, mid[2] - a.z);
        let s = (wx * d.x + wy * d.y + wz * d.z).clamp(0.0, c.len);
        let (ex, ey, ez) = (wx - s * d.x, wy - s * d.y, wz - s * d.z);
        let reach = self.radius_slack + half;
        ex * ex + ey * ey + ez * ez <= reach * reach
    }

    /// Capsule `i`'s bounding ball: its middle and a radius (mm) reaching past every point
    /// of it, with a little slack for rounding.
    pub fn ball(&self, i: u32) -> [f64; 4] {
        self.balls[i as usize]
    }

    /// Edge length of a cell (mm).
    pub fn cell_mm(&self) -> f64 {
        self.cell_mm
    }
}

/// The ball round a query segment from `a` to `b` that [`CapsuleIndex::near_query`] takes:
/// its middle and half its length (mm), with a little slack for rounding.
#[inline]
pub fn query_ball(a: &Point3, b: &Point3) -> ([f64; 3], f64) {
    let mid = [0.5 * (a.x + b.x), 0.5 * (a.y + b.y), 0.5 * (a.z + b.z)];
    (mid, 0.5 * (b - a).norm() * (1.0 + SLACK))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vector3;

    /// Every capsule a query segment meets is visited, whatever the segment's direction,
    /// length and position relative to the cells.
    #[test]
    fn walk_visits_every_capsule_the_segment_meets() {
        let mut rnd = crate::testing::uniform(4242u64);
        let r = 0.4;
        let mut capsules = Vec::new();
        for _ in 0..400 {
            let a = Point3::new(10.0 * rnd(), 10.0 * rnd(), 3.0 * rnd());
            let d = Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.2 * (rnd() - 0.5)) * 3.0;
            capsules.push(Capsule::new(a, a + d));
        }
        let region = Aabb {
            min: [-1.0, -1.0, -1.0],
            max: [11.0, 11.0, 4.0],
        };
        for cell in [0.2, 0.5, 1.3] {
            let index = CapsuleIndex::build(&capsules, r, &region, cell);
            let mut seen = vec![0u32; capsules.len()];
            let mut met = 0;
            for q in 1..=2000u32 {
                let p = Point3::new(10.0 * rnd(), 10.0 * rnd(), 3.0 * rnd());
                let n = Vector3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
                let (lo, hi) = (-2.0 * rnd(), 2.0 * rnd());
                let mut visited = Vec::new();
                index.visit(&capsules, &(p + n * lo), &(p + n * hi), &mut seen, q, |i| {
                    visited.push(i)
                });
                for (i, c) in capsules.iter().enumerate() {
                    if c.interval(r, &p, &n, lo, hi).is_some() {
                        met += 1;
                        assert!(
                            visited.contains(&(i as u32)),
                            "cell {cell}: capsule {i} met by query {q} but not visited"
                        );
                    }
                }
            }
            assert!(met > 500, "{met} meetings tested");
        }
    }
}
