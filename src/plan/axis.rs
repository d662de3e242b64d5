//! Tool axis: the direction closest to +Z for which the shank and holder (cylinders above the
//! cutting part) stay clear of the model, smoothed along the path, with optional lead and
//! tilt.
//!
//! The ball itself cannot gouge where it touches (the side step keeps concave radii larger
//! than the ball), and the fluted length above it cuts; the non-cutting shank above the
//! flutes and the holder above the shank can hit walls elsewhere. The model is sampled densely
//! (tessellation vertices and triangle centres) into a spatial grid; a candidate axis is clear
//! when no sample lies inside the cylinders grown by the sampling gap. +Z is tested against a
//! height map first (cheap); where it is not clear, the tool leans the way the previous
//! point leaned (or the nearest way that is clear), else away from the obstacle, at the
//! least clear tilt that way, refined by bisection. The least clear tilt changes
//! continuously as the tool nears a wall, so the axis turns gradually without smoothing,
//! and it is +Z wherever +Z is clear.

use super::reach::Why;
use super::toolpath::{Move, MoveKind, Toolpath};
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::model::Model;

/// Azimuths tried around +Z when the usual ones fail.
const AZIMUTHS: usize = 12;
/// Step of the coarse tilt search (degrees).
const TILT_STEP_DEG: f64 = 5.0;
/// Bisection steps refining the tilt (5° / 2^6 ≈ 0.08°).
const TILT_BISECTIONS: usize = 6;
/// Least cosine between the tool axis and the surface normal at the contact point: the
/// tool must come from the side the surface faces (else its flutes and shank run into the
/// part behind the contact, as under a closed part's bottom) (cos 88°).
const MIN_AXIS_NORMAL_COS: f64 = 0.035;

/// True if `axis` comes from the side the surface faces at the contact (unit normal `n`)
/// and the shank and holder along it at ball centre `c` are clear.
pub(super) fn usable(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    axis: &Vector3,
    opts: &PlanOptions,
) -> bool {
    axis.dot(n) >= MIN_AXIS_NORMAL_COS && obs.clear(c, axis, opts)
}

/// The sample the vertical tool at ball centre `c` hits, or the contact point `cc` itself
/// where the surface faces away from +Z.
fn vertical_hit(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    cc: &Point3,
    opts: &PlanOptions,
) -> Option<Point3> {
    if n.z < MIN_AXIS_NORMAL_COS {
        return Some(*cc);
    }
    obs.hit(c, &Vector3::z(), opts)
}

/// Unit contact normal of a move (from the contact point to the ball centre).
pub(super) fn contact_normal(m: &Move) -> Vector3 {
    (m.cl_point - m.cc_point)
        .try_normalize(AXIS_MIN_NORM)
        .unwrap_or_else(Vector3::z)
}

/// Azimuths either side of "away from the obstacle" also tried (radians, 30°).
const SIDE_AZIMUTH: f64 = std::f64::consts::FRAC_PI_6;

/// Dense samples of the model's surface in a uniform grid, with a height map for vertical
/// axes.
pub struct Obstacles {
    cell: f64,
    /// Samples sorted by grid cell: those of cell `k` are `sorted[start[k]..start[k + 1]]`
    /// (single precision: half the memory; the rounding is added to the gap).
    sorted: Vec<[f32; 3]>,
    start: Vec<u32>,
    /// Grid origin and size in cells.
    origin: [f64; 3],
    dims: [usize; 3],
    /// Highest sample per column of the grid, dense over the model's x–y extent, at the
    /// grid's cell size and at [`COARSE`] times it.
    heights: HeightMap,
    coarse: HeightMap,
    /// Highest point of the model (mm).
    top: f64,
    /// Largest distance from any surface point to its nearest sample (mm): cylinders are
    /// grown by this much.
    pub gap_mm: f64,
}

impl Obstacles {
    /// Samples the model for collision tests, no two neighbouring samples farther apart
    /// than `spacing` (mm), indexed in cells of about `cell_mm` (at most the model's size
    /// over `GRID_CELLS`, at least the sampling gap).
    pub fn new(model: &Model, spacing: f64, cell_mm: f64) -> Obstacles {
        let size = model.surface.bbox().diagonal().max(1e-6);
        let chordal = (0.25 * spacing).max(size * 2e-4);
        let t = model.tessellate(chordal);
        let vertices: Vec<Point3> = t
            .positions
            .chunks(3)
            .map(|q| Point3::new(q[0] as f64, q[1] as f64, q[2] as f64))
            .collect();
        // Lattice divisions per triangle side, and the lattice spacing reached.
        let mut worst: f64 = 0.0;
        let divisions: Vec<usize> = t
            .indices
            .chunks(3)
            .map(|tri| {
                let [a, b, c] = [0, 1, 2].map(|k| vertices[tri[k] as usize]);
                let longest = (a - b).norm().max((b - c).norm()).max((c - a).norm());
                let n = ((longest / spacing).ceil() as usize).max(1);
                worst = worst.max(longest / n as f64);
                n
            })
            .collect();
        // Every sample: the vertices, and inside each triangle a barycentric lattice of `n`
        // divisions per side (spacing longest / n). Generated again for each pass instead
        // of stored: the samples of a large model at a thin shank's spacing run to millions.
        let each_sample = |f: &mut dyn FnMut(&Point3)| {
            vertices.iter().for_each(&mut *f);
            for (tri, &n) in t.indices.chunks(3).zip(&divisions) {
                let [a, b, c] = [0, 1, 2].map(|k| vertices[tri[k] as usize]);
                for i in 0..=n {
                    for j in 0..=n - i {
                        let k = n - i - j;
                        if i == n || j == n || k == n {
                            continue; // the vertices are in already
                        }
                        let [x, y, z] = [i, j, k].map(|m| m as f64 / n as f64);
                        f(&Point3::from(a.coords * x + b.coords * y + c.coords * z));
                    }
                }
            }
        };
        // Lattice points lie in their triangles: the vertices bound them all.
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for q in &vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        let reach = (0..3)
            .map(|k| lo[k].abs().max(hi[k].abs()))
            .fold(0.0, f64::max);
        // Every point of a triangle is within 0.58 of the lattice spacing of a lattice point,
        // and the surface within the chordal tolerance of the triangle.
        let gap_mm = 0.58 * worst + chordal + F32_ROUNDING * reach;
        let cell = cell_mm.min(size / GRID_CELLS).max(gap_mm);
        let dims = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / cell).floor() as usize + 1).max(1));
        let index = |q: &Point3| {
            let c = [0, 1, 2].map(|k| (((q[k] - lo[k]) / cell) as usize).min(dims[k] - 1));
            (c[2] * dims[1] + c[1]) * dims[0] + c[0]
        };
        let mut heights = HeightMap::new(lo, hi, cell);
        let mut coarse = HeightMap::new(lo, hi, cell * COARSE);
        let mut start = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        each_sample(&mut |q| {
            start[index(q) + 1] += 1;
            heights.add(q);
            coarse.add(q);
        });
        for k in 1..start.len() {
            start[k] += start[k - 1];
        }
        let mut fill = start.clone();
        let mut sorted = vec![[0.0f32; 3]; start[start.len() - 1] as usize];
        each_sample(&mut |q| {
            let k = index(q);
            sorted[fill[k] as usize] = [q.x as f32, q.y as f32, q.z as f32];
            fill[k] += 1;
        });
        Obstacles {
            cell,
            sorted,
            start,
            origin: lo,
            dims,
            heights,
            coarse,
            top: model.surface.bbox().max[2],
            gap_mm,
        }
    }

    /// True if no sample within `radius` of `c` (in x–y) rises above `z`.
    fn below(&self, c: &Point3, radius: f64, z: f64) -> bool {
        let map = if radius > COARSE * self.cell {
            &self.coarse
        } else {
            &self.heights
        };
        map.below(c, radius, z)
    }

    /// A sample inside the cylinder from `c + axis·a0` to `c + axis·a1` of radius `rad` (all
    /// grown by the sampling gap), if there is one.
    fn cylinder_hit(
        &self,
        c: &Point3,
        axis: &Vector3,
        a0: f64,
        a1: f64,
        rad: f64,
    ) -> Option<Point3> {
        let g = self.gap_mm;
        let rad = rad + g;
        let (p0, p1) = (c + axis * (a0 - g), c + axis * (a1 + g));
        // Entirely above the model: nothing to hit.
        let lowest = p0.z.min(p1.z) - rad * (1.0 - axis.z * axis.z).max(0.0).sqrt();
        if lowest > self.top + g {
            return None;
        }
        let test = |q: &Point3| {
            let d = q - c;
            let axial = d.dot(axis);
            axial > a0 - g && axial < a1 + g && (d - axis * axial).norm() < rad
        };
        self.find_near_segment(&p0, &p1, rad, test)
    }

    /// A sample closer than `rad` to the segment from `p0` to `p1` (the ball swept along it),
    /// if there is one. Samples stand for the surface only to within the sampling gap, so a
    /// touch shallower than that may go unseen.
    fn capsule_hit(&self, p0: &Point3, p1: &Point3, rad: f64) -> Option<Point3> {
        let d = p1 - p0;
        let len2 = d.norm_squared();
        let test = |q: &Point3| {
            let t = if len2 > 0.0 {
                ((q - p0).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p0 + d * t - q).norm() < rad
        };
        self.find_near_segment(p0, p1, rad, test)
    }

    /// The first sample passing `test` among those of the grid cells that come within
    /// `rad` of the segment from `p0` to `p1` (every sample passing `test` must lie there).
    fn find_near_segment(
        &self,
        p0: &Point3,
        p1: &Point3,
        rad: f64,
        test: impl Fn(&Point3) -> bool,
    ) -> Option<Point3> {
        let lo = [0, 1, 2].map(|k| p0[k].min(p1[k]) - rad);
        let hi = [0, 1, 2].map(|k| p0[k].max(p1[k]) + rad);
        // Cell ranges, clamped to the grid (samples outside it do not exist).
        let range = |k: usize| -> Option<(usize, usize)> {
            let a = ((lo[k] - self.origin[k]) / self.cell).floor();
            let b = ((hi[k] - self.origin[k]) / self.cell).floor();
            if b < 0.0 || a > (self.dims[k] - 1) as f64 {
                return None;
            }
            Some((a.max(0.0) as usize, (b as usize).min(self.dims[k] - 1)))
        };
        let (rx, ry, rz) = (range(0)?, range(1)?, range(2)?);
        let d = p1 - p0;
        let len2 = d.norm_squared();
        // A cell can hold a sample within `rad` of the segment only if its centre is within
        // `rad` plus half its diagonal.
        let reach = rad + 0.5 * 3f64.sqrt() * self.cell;
        let reach2 = reach * reach;
        let half = 0.5 * self.cell;
        for k in rz.0..=rz.1 {
            let z = self.origin[2] + k as f64 * self.cell + half;
            for j in ry.0..=ry.1 {
                let y = self.origin[1] + j as f64 * self.cell + half;
                let row = (k * self.dims[1] + j) * self.dims[0];
                for i in rx.0..=rx.1 {
                    let (a, b) = (
                        self.start[row + i] as usize,
                        self.start[row + i + 1] as usize,
                    );
                    if a == b {
                        continue;
                    }
                    let q = Point3::new(self.origin[0] + i as f64 * self.cell + half, y, z);
                    let t = if len2 > 0.0 {
                        ((q - p0).dot(&d) / len2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    if (p0 + d * t - q).norm_squared() > reach2 {
                        continue;
                    }
                    if let Some(p) = self.sorted[a..b]
                        .iter()
                        .map(|q| Point3::new(q[0] as f64, q[1] as f64, q[2] as f64))
                        .find(|q| test(q))
                    {
                        return Some(p);
                    }
                }
            }
        }
        None
    }

    /// A sample inside the cylinder from `c + axis·a0` to `c + axis·a1` of radius `rad`
    /// (grown by the sampling gap), if there is one; vertical axes are tried on the height
    /// map first.
    fn segment_hit(
        &self,
        c: &Point3,
        axis: &Vector3,
        (a0, a1): (f64, f64),
        rad: f64,
    ) -> Option<Point3> {
        if axis.z > 1.0 - VERTICAL_COS_SLACK
            && self.below(c, rad + self.gap_mm, c.z + a0 - self.gap_mm)
        {
            return None;
        }
        self.cylinder_hit(c, axis, a0, a1, rad)
    }
}

/// Axes this close to +Z (1 − cos of the angle) are vertical for the height-map test.
const VERTICAL_COS_SLACK: f64 = 1e-15;

/// The model sampled for collision tests of the tool above its flutes: densely for the thin
/// shank, more coarsely for the wide holder (each set grows its cylinder by its own gap).
pub struct Clearance {
    shank: Obstacles,
    /// `None`: the holder is tested against the shank's samples (when a coarser set would
    /// hardly be coarser).
    holder: Option<Obstacles>,
}

impl Clearance {
    /// Samples `model` for the shank and holder of `opts`.
    pub fn new(model: &Model, opts: &PlanOptions) -> Clearance {
        let most = model.surface.bbox().diagonal() / OBSTACLE_SAMPLES;
        let fine = (SHANK_SPACING * opts.shank_radius()).min(most);
        let coarse = (HOLDER_SPACING * opts.holder_radius_mm).min(most).max(fine);
        // Cells about the size of the cylinder tested in them.
        let shank = Obstacles::new(model, fine, CELL_RADII * opts.shank_radius());
        let holder = (coarse > 2.0 * fine)
            .then(|| Obstacles::new(model, coarse, CELL_RADII * opts.holder_radius_mm));
        Clearance { shank, holder }
    }

    fn holder(&self) -> &Obstacles {
        self.holder.as_ref().unwrap_or(&self.shank)
    }

    /// Largest sampling gap of the two sets (mm).
    pub fn gap_mm(&self) -> f64 {
        self.shank.gap_mm.max(self.holder().gap_mm)
    }

    /// A sample inside the shank (above the flutes) or the holder of a tool with its ball
    /// centre at `c` along unit `axis`, if there is one.
    pub fn hit(&self, c: &Point3, axis: &Vector3, opts: &PlanOptions) -> Option<Point3> {
        let (f, ls, lh) = (
            opts.flute_length(),
            opts.shank_length_mm,
            opts.holder_length_mm,
        );
        self.shank
            .segment_hit(c, axis, (f, ls), opts.shank_radius())
            .or_else(|| {
                self.holder()
                    .segment_hit(c, axis, (ls, ls + lh), opts.holder_radius_mm)
            })
    }

    /// True if the shank and holder at `c` along `axis` are clear of every sample.
    pub fn clear(&self, c: &Point3, axis: &Vector3, opts: &PlanOptions) -> bool {
        self.hit(c, axis, opts).is_none()
    }

    /// A sample closer than `rad` to the segment from `p0` to `p1`, from the dense set.
    pub fn capsule_hit(&self, p0: &Point3, p1: &Point3, rad: f64) -> Option<Point3> {
        self.shank.capsule_hit(p0, p1, rad)
    }
}

/// Obstacle grid cell size, in radii of the cylinder tested against it.
const CELL_RADII: f64 = 2.0;
/// Shank obstacle sample spacing, in shank radii.
const SHANK_SPACING: f64 = 0.25;
/// Holder obstacle sample spacing, in holder radii.
const HOLDER_SPACING: f64 = 0.04;

/// Relative rounding of a coordinate stored in single precision (2⁻²⁴).
const F32_ROUNDING: f64 = 6.0e-8;

/// Ratio of the coarse height map's cell to the fine one's.
const COARSE: f64 = 8.0;

/// Highest sample in each cell of a dense x–y grid.
struct HeightMap {
    cell: f64,
    origin: [f64; 2],
    nx: usize,
    ny: usize,
    max_z: Vec<f64>,
}

impl HeightMap {
    /// An empty map over the x–y extent of the box from `lo` to `hi`.
    fn new(lo: [f64; 3], hi: [f64; 3], cell: f64) -> HeightMap {
        let nx = (((hi[0] - lo[0]) / cell).floor() as usize + 1).max(1);
        let ny = (((hi[1] - lo[1]) / cell).floor() as usize + 1).max(1);
        HeightMap {
            cell,
            origin: [lo[0], lo[1]],
            nx,
            ny,
            max_z: vec![f64::NEG_INFINITY; nx * ny],
        }
    }

    /// Raises the column of `p` to its height.
    fn add(&mut self, p: &Point3) {
        let i = (((p.x - self.origin[0]) / self.cell) as usize).min(self.nx - 1);
        let j = (((p.y - self.origin[1]) / self.cell) as usize).min(self.ny - 1);
        let h = &mut self.max_z[j * self.nx + i];
        *h = h.max(p.z);
    }

    fn below(&self, c: &Point3, radius: f64, z: f64) -> bool {
        let idx =
            |x: f64, o: f64, n: usize| (((x - o) / self.cell).floor().max(0.0) as usize).min(n - 1);
        let (i0, i1) = (
            idx(c.x - radius, self.origin[0], self.nx),
            idx(c.x + radius, self.origin[0], self.nx),
        );
        let (j0, j1) = (
            idx(c.y - radius, self.origin[1], self.ny),
            idx(c.y + radius, self.origin[1], self.ny),
        );
        (j0..=j1).all(|j| {
            self.max_z[j * self.nx + i0..=j * self.nx + i1]
                .iter()
                .all(|&h| h <= z)
        })
    }
}

/// Obstacle samples along the model's diagonal, at the least.
const OBSTACLE_SAMPLES: f64 = 150.0;
/// Grid cells along the model's diagonal in the obstacle index.
const GRID_CELLS: f64 = 64.0;

/// Unit axis tilted `theta` (radians) from +Z towards azimuth `phi`.
pub(super) fn tilted(theta: f64, phi: f64) -> Vector3 {
    Vector3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The least tilt (radians) along azimuth `phi` at which the tool is clear, to within the
/// bisection: coarse steps of [`TILT_STEP_DEG`] up to the largest allowed, refined by
/// bisection. With a `hint` (the previous point's tilt: it changes little from point to
/// point) the coarse steps start there, going down while clear or up while not, so that
/// a clear tilt costs a few tests instead of a scan from zero.
pub(super) fn least_tilt(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    opts: &PlanOptions,
    phi: f64,
    hint: Option<f64>,
) -> Option<f64> {
    let max = opts.max_tilt_deg.to_radians();
    let step = TILT_STEP_DEG.to_radians();
    let clear = |t: f64| usable(obs, (c, n), &tilted(t, phi), opts);
    // `hi` clear, `lo` not (or zero, where the vertical was found not clear).
    let (mut lo, mut hi) = match hint.map(|h| h.max(step).min(max)) {
        Some(h) if clear(h) => {
            let mut hi = h;
            loop {
                let lo = (hi - step).max(0.0);
                if lo <= 0.0 || !clear(lo) {
                    break (lo, hi);
                }
                hi = lo;
            }
        }
        start => {
            let mut hi = start.map_or(step.min(max), |h| (h + step).min(max));
            loop {
                if clear(hi) {
                    break;
                }
                if hi >= max {
                    return None;
                }
                hi = (hi + step).min(max);
            }
            ((hi - step).max(0.0), hi)
        }
    };
    for _ in 0..TILT_BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if clear(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// A clear axis at `c`, continuing the previous point's lean: the least clear tilt along
/// its azimuth or the nearest clear one; else away from the sample the vertical tool hits;
/// failing those, around the circle.
fn clear_axis(
    obs: &Clearance,
    (c, n): (&Point3, &Vector3),
    opts: &PlanOptions,
    prev: &Vector3,
    hit: &Point3,
) -> Option<Vector3> {
    let away = (c.y - hit.y).atan2(c.x - hit.x);
    let hint = (prev.z < 1.0 - VERTICAL_COS_SLACK).then(|| prev.z.clamp(-1.0, 1.0).acos());
    // Keep turning the way the previous point did, at the least tilt clear that way, even
    // where another way needs less: the axis then does not swing round between
    // neighbouring points (on the head at h = 0.05 mm, switching to a way needing 5° less
    // swung the axis by more than 30° between neighbours 433 times, mean tilt 20.7°;
    // keeping the way, twice, mean tilt 33°). Where the previous azimuth has no clear tilt,
    // the nearest that has (turning either way in steps of `NEAR_AZIMUTH_STEP`).
    let kept = hint.and_then(|_| {
        let phi0 = prev.y.atan2(prev.x);
        (0..=NEAR_AZIMUTH_STEPS).find_map(|k| {
            let turn = k as f64 * NEAR_AZIMUTH_STEP.to_radians();
            let sides: &[f64] = if k == 0 { &[0.0] } else { &[turn, -turn] };
            sides
                .iter()
                .filter_map(|&d| {
                    least_tilt(obs, (c, n), opts, phi0 + d, hint).map(|t| (t, phi0 + d))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
        })
    });
    // Otherwise (or leaving +Z) the least tilt away from the sample the vertical tool hits
    // and a little either side of that; failing those, around the circle.
    let chosen = kept
        .or_else(|| {
            [away, away + SIDE_AZIMUTH, away - SIDE_AZIMUTH]
                .iter()
                .filter_map(|&phi| least_tilt(obs, (c, n), opts, phi, hint).map(|t| (t, phi)))
                .min_by(|a, b| a.0.total_cmp(&b.0))
        })
        .or_else(|| {
            (0..AZIMUTHS).find_map(|k| {
                let phi = away + k as f64 * std::f64::consts::TAU / AZIMUTHS as f64;
                least_tilt(obs, (c, n), opts, phi, None).map(|t| (t, phi))
            })
        })?;
    Some(tilted(chosen.0, chosen.1))
}

/// Azimuth steps (degrees) and how many either way are tried near the previous point's
/// azimuth when it is blocked.
const NEAR_AZIMUTH_STEP: f64 = 15.0;
const NEAR_AZIMUTH_STEPS: usize = 6;

/// Rotates `v` about unit `k` by `angle` (Rodrigues).
fn rotate(v: &Vector3, k: &Vector3, angle: f64) -> Vector3 {
    let (s, c) = angle.sin_cos();
    v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c))
}

/// What the axis assignment found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisStats {
    /// Points where the axis left +Z to clear the shank or holder.
    pub tilted: usize,
    /// Points where no axis within the allowed tilt is clear (three-axis: where +Z hits).
    pub blocked: usize,
    /// Of the blocked points, those where the surface faces away from +Z (three-axis: the
    /// tool would come from behind the surface).
    pub facing_away: usize,
    /// The first of those, for the report.
    pub first_blocked: Option<Point3>,
    /// Moves between two cut points whose axis turn was split into smaller clear turns
    /// (where it was blocked or larger than `max_axis_step_deg`).
    pub bridged: usize,
    /// Moves between two cut points during which the turning tool's shank or holder
    /// still comes within the safety margin of the model (poses checked every
    /// `SWEEP_STEP_DEG` of turn).
    pub sweep_hits: usize,
    /// That safety margin: the obstacle samples' gap (mm) by which shank and holder are
    /// grown.
    pub margin_mm: f64,
    /// The end of the first of those (ball centre, mm).
    pub first_sweep_hit: Option<Point3>,
    /// Windows of cut points whose axes were re-chosen along the pass to spread a large
    /// turn (see [`super::smooth`]).
    pub spread: usize,
}

/// Turn of the tool axis between the poses checked while it turns from one cut point to
/// the next (degrees).
const SWEEP_STEP_DEG: f64 = 2.0;

/// True if a pose between cut points `a` and `b` (ball centre and axis interpolated
/// linearly, every [`SWEEP_STEP_DEG`] of turn and at most the samples' gap of travel apart)
/// puts the shank or holder into the model.
pub(super) fn turn_blocked(a: &Move, b: &Move, obs: &Clearance, opts: &PlanOptions) -> bool {
    let step = SWEEP_STEP_DEG.to_radians();
    let turn = a.tool_axis.angle(&b.tool_axis);
    let travel = (b.cl_point - a.cl_point).norm();
    let poses = ((turn / step).ceil() as usize).max((travel / obs.gap_mm()).ceil() as usize);
    if poses <= 1 {
        return false;
    }
    let (na, nb) = (contact_normal(a), contact_normal(b));
    (1..poses).any(|k| {
        let s = k as f64 / poses as f64;
        let c = a.cl_point + (b.cl_point - a.cl_point) * s;
        let n = (na * (1.0 - s) + nb * s)
            .try_normalize(AXIS_MIN_NORM)
            .unwrap_or(nb);
        match (a.tool_axis * (1.0 - s) + b.tool_axis * s).try_normalize(AXIS_MIN_NORM) {
            Some(axis) => !usable(obs, (&c, &n), &axis, opts),
            // Opposite axes: no defined turn, count it.
            None => true,
        }
    })
}

/// Halvings of a blocked turn before it is given up.
pub(super) const BRIDGE_DEPTH: usize = 6;

/// Appends to `out` cut points between `a` and `b` (at fractions of the way from `s0` to
/// `s1`) that split a blocked turn into clear ones, or a turn larger than
/// `max_axis_step_deg` into smaller ones: the midpoint of the chord with the halfway axis
/// for a clear turn; for a blocked one, +Z if that is clear, else the halfway axis if
/// clear, else the least tilt leaning from `a`'s; then each half likewise. False if some
/// turn stays blocked.
#[allow(clippy::too_many_arguments)]
pub(super) fn bridge(
    a: &Move,
    b: &Move,
    (s0, s1): (f64, f64),
    obs: &Clearance,
    opts: &PlanOptions,
    depth: usize,
    out: &mut Vec<(Move, f64)>,
) -> bool {
    let blocked = turn_blocked(a, b, obs, opts);
    let large = a.tool_axis.angle(&b.tool_axis) > opts.max_axis_step_deg.to_radians();
    if !blocked && !large {
        return true;
    }
    if depth == 0 {
        return !blocked;
    }
    let cl = Point3::from((a.cl_point.coords + b.cl_point.coords) * 0.5);
    let cc = Point3::from((a.cc_point.coords + b.cc_point.coords) * 0.5);
    let n = (contact_normal(a) + contact_normal(b))
        .try_normalize(AXIS_MIN_NORM)
        .unwrap_or_else(|| contact_normal(b));
    let halfway = (a.tool_axis + b.tool_axis)
        .try_normalize(AXIS_MIN_NORM)
        .filter(|x| within_tilt(x, opts) && usable(obs, (&cl, &n), x, opts));
    // Both halves through the pose with `axis` at the chord's midpoint.
    let halves = |axis: Vector3, out: &mut Vec<(Move, f64)>| {
        let mid = Move {
            cl_point: cl,
            cc_point: cc,
            tool_axis: axis,
            ..*b
        };
        let sm = 0.5 * (s0 + s1);
        let first = bridge(a, &mid, (s0, sm), obs, opts, depth - 1, out);
        out.push((mid, sm));
        let second = bridge(&mid, b, (sm, s1), obs, opts, depth - 1, out);
        first && second
    };
    if !blocked {
        // A clear turn that is only too large is halved along its way, or left whole where
        // that is not clear: a split must never make a clear turn blocked.
        let Some(axis) = halfway else {
            return true;
        };
        let kept = out.len();
        if !halves(axis, out) {
            out.truncate(kept);
        }
        return true;
    }
    let axis = match vertical_hit(obs, (&cl, &n), &cc, opts) {
        None => Some(Vector3::z()),
        Some(h) => halfway.or_else(|| clear_axis(obs, (&cl, &n), opts, &a.tool_axis, &h)),
    };
    match axis {
        Some(axis) => halves(axis, out),
        None => false,
    }
}

/// Splits every turn of the axis between two cut points whose in-between poses would put
/// the shank or holder into the model (see [`bridge`]); counts the splits and the turns
/// that stay blocked.
pub fn bridge_turns(
    path: &mut Toolpath,
    obs: &Clearance,
    opts: &PlanOptions,
    stats: &mut AxisStats,
) {
    path.rebuild(|old, i, add| {
        let b = old.moves[i];
        let q = old.param(i);
        if i > 0
            && old.moves[i - 1].kind.on_surface()
            && matches!(b.kind, MoveKind::Feed | MoveKind::Link)
        {
            let mut inserted = Vec::new();
            let clear = bridge(
                &old.moves[i - 1],
                &b,
                (0.0, 1.0),
                obs,
                opts,
                BRIDGE_DEPTH,
                &mut inserted,
            );
            if !inserted.is_empty() {
                stats.bridged += 1;
            }
            let qa = old.param(i - 1);
            for (m, s) in inserted {
                add(m, [qa[0] + (q[0] - qa[0]) * s, qa[1] + (q[1] - qa[1]) * s]);
            }
            if !clear {
                stats.sweep_hits += 1;
                stats.first_sweep_hit.get_or_insert(b.cl_point);
            }
        }
        add(b, q);
    });
}

/// A unit vector perpendicular to unit `n`.
fn any_tangent(n: &Vector3) -> Vector3 {
    let other = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&other).normalize()
}

/// Whether unit axis `a` leans from +Z by no more than the largest tilt allowed.
pub(super) fn within_tilt(a: &Vector3, opts: &PlanOptions) -> bool {
    a.z >= opts.max_tilt_deg.max(0.0).to_radians().cos()
}

/// Shortest interpolated axis (before normalising) taken as a direction.
const AXIS_MIN_NORM: f64 = 1e-9;

/// Sets the tool axis of every cutting move of `path` (moves off the surface are left for
/// [`fill_air_axes`]): +Z where the shank and holder clear the model, else the least clear
/// tilt (up to `max_tilt_deg`; 0 plans three-axis). Returns what it found and, per move,
/// why it cannot be cut where no allowed axis is usable (the move keeps +Z then).
pub fn choose(
    obs: &Clearance,
    path: &mut Toolpath,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<(AxisStats, Vec<Option<Why>>)> {
    let n = path.moves.len();
    let mut prev = Vector3::z();
    let mut stats = AxisStats::default();
    let mut why: Vec<Option<Why>> = vec![None; n];
    for i in 0..n {
        let m = path.moves[i];
        if !m.kind.on_surface() {
            continue;
        }
        let c = m.cl_point;
        let normal = contact_normal(&m);
        let mut axis = Vector3::z();
        if opts.lead_deg != 0.0 || opts.tilt_deg != 0.0 {
            // Lead and tilt are taken from the surface normal in the feed frame.
            let next = path
                .moves
                .get(i + 1)
                .filter(|x| x.kind.on_surface())
                .map(|x| x.cc_point);
            let before = i
                .checked_sub(1)
                .map(|j| path.moves[j])
                .filter(|x| x.kind.on_surface())
                .map(|x| x.cc_point);
            let feed = match (before, next) {
                (_, Some(q)) => q - m.cc_point,
                (Some(p), None) => m.cc_point - p,
                _ => Vector3::x(),
            };
            // In the tangent plane; where the feed is along the normal or nil (a lifted
            // point's contact repeated), any tangent: the frame must stay orthonormal, or
            // the rotations below give an axis that is not a unit vector.
            let feed = (feed - normal * feed.dot(&normal))
                .try_normalize(AXIS_MIN_NORM)
                .unwrap_or_else(|| any_tangent(&normal));
            let side = normal.cross(&feed);
            let a = rotate(&normal, &side, opts.lead_deg.to_radians());
            let a = rotate(&a, &feed, opts.tilt_deg.to_radians());
            // Within the largest tilt (issue 19: on a part's underside the normal with its
            // lead pointed up to 180° from +Z); else the search below, which keeps to it.
            if within_tilt(&a, opts) && usable(obs, (&c, &normal), &a, opts) {
                axis = a;
            }
        } else if opts.facet_normal_axis && m.tool_axis != Vector3::z() {
            // The strategy's own axis (iso-planar: the facets' area-weighted normal), within
            // the largest tilt.
            let a = m.tool_axis;
            if within_tilt(&a, opts) && usable(obs, (&c, &normal), &a, opts) {
                axis = a;
            }
        }
        let blocked_at = if axis == Vector3::z() {
            vertical_hit(obs, (&c, &normal), &m.cc_point, opts)
        } else {
            None
        };
        if let Some(h) = blocked_at {
            match (opts.max_tilt_deg > 0.0)
                .then(|| clear_axis(obs, (&c, &normal), opts, &prev, &h))
                .flatten()
            {
                Some(a) => {
                    axis = a;
                    stats.tilted += 1;
                }
                None => {
                    stats.blocked += 1;
                    // Facing away from every allowed axis: the normal further from +Z than
                    // the largest tilt and the most the axis may lean from the normal.
                    let from_z = normal.z.clamp(-1.0, 1.0).acos();
                    let faces_away = from_z
                        > opts.max_tilt_deg.max(0.0).to_radians() + MIN_AXIS_NORMAL_COS.acos();
                    if faces_away {
                        stats.facing_away += 1;
                        why[i] = Some(Why::FacesAway);
                    } else {
                        why[i] = Some(Why::ToolHits);
                    }
                    stats.first_blocked.get_or_insert(c);
                }
            }
        }
        path.moves[i].tool_axis = axis;
        if why[i].is_none() {
            prev = axis;
        }
        if i % 512 == 0 && !progress(i as f64 / n as f64) {
            return Err(Error::Cancelled);
        }
    }
    stats.margin_mm = obs.gap_mm();
    progress(1.0);
    Ok((stats, why))
}

/// Gives every move off the surface the tool axis of the nearest cut: retracts keep the
/// axis of the cut they leave, rapids take that of the cut they come down to.
pub fn fill_air_axes(path: &mut Toolpath) {
    let n = path.moves.len();
    let mut last = None;
    for i in 0..n {
        if path.moves[i].kind.on_surface() {
            last = Some(path.moves[i].tool_axis);
        } else if let Some(a) = last {
            path.moves[i].tool_axis = a;
        }
    }
    let mut next = None;
    for i in (0..n).rev() {
        if path.moves[i].kind.on_surface() {
            next = Some(path.moves[i].tool_axis);
        } else if path.moves[i].kind == MoveKind::Rapid {
            if let Some(a) = next {
                path.moves[i].tool_axis = a;
            }
        }
    }
}
