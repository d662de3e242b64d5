//! The simulation proper: sample grids per patch, measurements in bands of rows (in
//! parallel natively, in a fixed order so that results do not depend on the thread count),
//! cell bounds, and the summary.

use super::bound::{cell_bound, second_derivative_bound, CellBound, CellFrame, Corner};
use super::capsule::Capsule;
use super::heatmap::{worse, HeatMap};
use super::index::CapsuleIndex;
use super::probe::{Material, Probe};
use super::rest::RestMask;
use super::stats::weighted_quantile;
use super::{CutterPath, PatchVerification, ToolSide, Verification, VerifyOptions};
use crate::geom::{Aabb, Point3, Vector3};
use crate::surface::{DiffGeom, FaceSurface, Surface, SurfaceDerivs};

/// Samples per side used to estimate a patch's area and side lengths.
const AREA_PROBE: usize = 17;
/// Most rows of samples along the sides of a sliver face, beyond its share by area
/// ([`grids`]): a face whose two sides are long but whose area is next to nothing (folded or
/// collapsed) is not sampled at the spacing of the rest over its whole parameter square.
const SLIVER_ROWS: f64 = 8.0;
/// Samples per side of each patch used to tell which side the tool is on.
const SIDE_PROBE: usize = 16;
/// Margin of the indexed region beyond the surface's box, as a fraction of its diagonal.
const REGION_MARGIN: f64 = 0.02;
/// Edge of an index cell in tool radii.
const CELL_PER_RADIUS: f64 = 0.5;
/// Where the surface has no normal, it is taken this far (in parameter) towards the middle.
const SINGULAR_NUDGE: f64 = 1e-3;
/// Entry cosine below which a line only grazes a ball (its slope is unbounded there).
const GRAZING_COS: f64 = 1e-9;
/// Sample rows per band of work.
const BAND_ROWS: usize = 32;
/// Probability mass of the reported percentile.
const PERCENTILE: f64 = 0.95;
/// Newton steps towards the bottom of the deepest gouge of a band.
const GOUGE_NEWTON_STEPS: usize = 6;
/// Share of the requested scallop by which a cell's bound may exceed the highest material
/// measured before the cell is sampled more finely ([`refined_bound`]).
const REFINE_SHARE: f64 = 0.15;
/// Most times a cell is split in four while refining its bound.
const REFINE_DEPTH: usize = 4;
/// Largest Newton step, in cells.
const GOUGE_STEP_CELLS: f64 = 2.0;
/// The coarse pass before a bounded simulation takes one sample in this many
/// ([`seed_pass`]).
const SEED_SHARE: usize = 16;
/// Share of the progress the coarse pass stands for.
const SEED_PROGRESS: f64 = 0.05;

/// How one patch is sampled.
#[derive(Debug, Clone, Copy)]
struct FaceGrid {
    nu: usize,
    nv: usize,
}

/// One measured sample.
#[derive(Debug, Clone, Copy)]
struct Sample {
    corner: Corner,
    /// Unit normal `S_u × S_v` (zero where there is none).
    normal: Vector3,
    singular: bool,
    /// `|S_u × S_v|` (mm² per unit parameter²).
    area_density: f64,
    /// Inside the plan's rest area (left for another tool).
    rest: bool,
}

/// Running totals of one band or patch.
#[derive(Debug, Clone, Default)]
struct Acc {
    samples: usize,
    singular: usize,
    unreached: usize,
    gouges: usize,
    gouge_area: f64,
    area: f64,
    unreached_area: f64,
    uncut_area: f64,
    /// Area of the cells whose corners disagree on whether more than the scallop is left.
    uncut_edge_area: f64,
    reached_area: f64,
    scallop_area: f64,
    max_left: Option<f64>,
    /// Where `max_left` was measured.
    max_left_at: Option<Point3>,
    max_gouge: f64,
    /// Where the deepest gouge was measured.
    max_gouge_at: Option<Point3>,
    /// Area inside the plan's rest area (mm²).
    rest_area: f64,
    upper: Option<f64>,
    /// Extra measurements at located cusps.
    refined: usize,
    /// Upper bound of the deepest gouge over the cells (mm).
    gouge_upper: Option<f64>,
    spacing: f64,
    /// (scallop, area weight) of every reached sample, one chunk per band.
    values: Vec<Vec<(f64, f64)>>,
}

impl Acc {
    fn merge(&mut self, o: Acc) {
        self.samples += o.samples;
        self.singular += o.singular;
        self.unreached += o.unreached;
        self.gouges += o.gouges;
        self.gouge_area += o.gouge_area;
        self.area += o.area;
        self.unreached_area += o.unreached_area;
        self.uncut_area += o.uncut_area;
        self.uncut_edge_area += o.uncut_edge_area;
        self.reached_area += o.reached_area;
        self.scallop_area += o.scallop_area;
        self.note_left(o.max_left, o.max_left_at);
        self.note_gouge(o.max_gouge, o.max_gouge_at);
        self.rest_area += o.rest_area;
        self.upper = max_opt(self.upper, o.upper);
        self.refined += o.refined;
        self.gouge_upper = max_opt(self.gouge_upper, o.gouge_upper);
        self.spacing = self.spacing.max(o.spacing);
        self.values.extend(o.values);
    }
}

impl Acc {
    /// Raises the maximum material left to `left` (at `at`) if it is larger; ties keep the
    /// first, so that the result does not depend on the order bands finish in.
    fn note_left(&mut self, left: Option<f64>, at: Option<Point3>) {
        if let Some(l) = left {
            if self.max_left.is_none_or(|m| l > m) {
                self.max_left = Some(l);
                self.max_left_at = at;
            }
        }
    }
    /// Raises the deepest gouge to `depth` (at `at`) if it is deeper.
    fn note_gouge(&mut self, depth: f64, at: Option<Point3>) {
        if depth > self.max_gouge {
            self.max_gouge = depth;
            self.max_gouge_at = at;
        }
    }
}

fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Everything a band needs, shared read-only.
struct Ctx<'a> {
    surface: &'a Surface,
    capsules: &'a [Capsule],
    index: &'a CapsuleIndex,
    grids: &'a [FaceGrid],
    radius: f64,
    reach: f64,
    max_depth: f64,
    sigma: f64,
    opts: &'a VerifyOptions,
    rest: &'a RestMask,
    /// Material left and gouge depth (mm) measured somewhere on the surface before the
    /// bands run (by [`seed_pass`], summed up by [`seed_floor`]), if they were: the overall maxima are at least these,
    /// so a cell whose bound is within [`REFINE_SHARE`] of the scallop above them is bounded
    /// closely enough without refining it, whatever its band has measured so far.
    floor: Option<[f64; 2]>,
}

fn face_size(face: &FaceSurface) -> (f64, f64, f64) {
    let n = AREA_PROBE;
    let h = 1.0 / n as f64;
    let mut area = 0.0;
    for i in 0..n {
        for j in 0..n {
            let d = face.derivs((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
            area += d.su.cross(&d.sv).norm() * h * h;
        }
    }
    let (mut lu, mut lv) = (0.0, 0.0);
    for a in 0..n {
        let x = (a as f64 + 0.5) * h;
        for b in 0..n {
            let (y0, y1) = (b as f64 * h, (b + 1) as f64 * h);
            lu += (face.subs(y1, x) - face.subs(y0, x)).norm();
            lv += (face.subs(x, y1) - face.subs(x, y0)).norm();
        }
    }
    (area, lu / n as f64, lv / n as f64)
}

/// The surface's area (mm²), as the sample grids estimate it.
pub fn area_mm2(surface: &Surface) -> f64 {
    surface.faces().iter().map(|f| face_size(f).0).sum()
}

fn grids(surface: &Surface, samples: usize) -> Vec<FaceGrid> {
    let sizes: Vec<(f64, f64, f64)> = surface.faces().iter().map(face_size).collect();
    let total: f64 = sizes.iter().map(|s| s.0).sum();
    // The samples' spacing where each has its share of the area (mm).
    let spacing = (total / samples.max(1) as f64).sqrt();
    sizes
        .iter()
        .map(|&(area, lu, lv)| {
            let share = if total > 0.0 {
                samples as f64 * area / total
            } else {
                samples as f64 / sizes.len() as f64
            };
            let aspect = if lu > 0.0 && lv > 0.0 { lu / lv } else { 1.0 };
            // At least 2 × 2, and by area no more than half its share along either side...
            let most = (0.5 * share).max(2.0);
            let mut nu = (share * aspect).sqrt().round().clamp(2.0, most);
            let mut nv = (share / nu).round().clamp(2.0, most);
            // ...but one with a side of 2 (a sliver, or a patch smaller than a few samples'
            // share) is sampled at the spacing of the rest across and along, up to its share
            // and SLIVER_ROWS rows along its sides: Bike.tsm's watershed layout has a
            // rectangle 0.017-0.024 mm wide, whose two samples across (its sides) held the
            // plan's error bound at 0.0066 mm with 8 M samples.
            if (nu == 2.0 || nv == 2.0) && spacing > 0.0 {
                nu = nu.max((lu / spacing).ceil() + 1.0);
                nv = nv.max((lv / spacing).ceil() + 1.0);
                let limit = share + SLIVER_ROWS * (lu + lv) / spacing;
                if nu * nv > limit {
                    let shrink = (limit / (nu * nv)).sqrt();
                    nu = (nu * shrink).floor().max(2.0);
                    nv = (nv * shrink).floor().max(2.0);
                }
            }
            FaceGrid {
                nu: nu as usize,
                nv: nv as usize,
            }
        })
        .collect()
}

/// Derivatives with a usable normal: `d`, those at `(u, v)`, else nudged towards the middle.
fn geometry(
    face: &FaceSurface,
    d: SurfaceDerivs,
    u: f64,
    v: f64,
) -> Option<(SurfaceDerivs, DiffGeom)> {
    if let Some(g) = DiffGeom::try_from_derivs(&d) {
        return Some((d, g));
    }
    let (uu, vv) = (
        0.5 + (u - 0.5) * (1.0 - SINGULAR_NUDGE),
        0.5 + (v - 0.5) * (1.0 - SINGULAR_NUDGE),
    );
    let d2 = face.derivs(uu, vv);
    DiffGeom::try_from_derivs(&d2).map(|g| {
        (
            SurfaceDerivs {
                point: d.point,
                ..d2
            },
            g,
        )
    })
}

fn measure(ctx: &Ctx, probe: &mut Probe, fi: usize, u: f64, v: f64) -> Sample {
    let d = ctx.surface.faces()[fi].derivs(u, v);
    measure_with(ctx, probe, fi, u, v, d)
}

/// As [`measure`], with the surface's derivatives at `(u, v)` given.
fn measure_with(
    ctx: &Ctx,
    probe: &mut Probe,
    fi: usize,
    u: f64,
    v: f64,
    d: SurfaceDerivs,
) -> Sample {
    let face = &ctx.surface.faces()[fi];
    let rest = ctx.rest.contains(fi, u, v);
    let unmeasured = |point: Point3, singular: bool, area_density: f64| Sample {
        corner: Corner {
            point,
            reached: false,
            left_mm: f64::INFINITY,
            overcut_mm: 0.0,
            grad: [0.0; 2],
            w_mm: 0.0,
            slope: 0.0,
            kappa_convex: 0.0,
            metric: [0.0; 3],
            second: [0.0; 3],
        },
        normal: Vector3::zeros(),
        singular,
        area_density,
        rest,
    };
    let Some((d, g)) = geometry(face, d, u, v) else {
        return unmeasured(face.subs(u, v), true, 0.0);
    };
    let area_density = d.su.cross(&d.sv).norm();
    let n = g.normal * ctx.sigma;
    let Material::Left { left_mm, governing } = probe.measure(&d.point, &n) else {
        return unmeasured(d.point, false, area_density);
    };
    // Weingarten: derivatives of the unit normal S_u × S_v, then to the tool side.
    let det = g.metric_det();
    let nu = (d.su * (g.m * g.f - g.l * g.g) + d.sv * (g.l * g.f - g.m * g.e)) / det * ctx.sigma;
    let nv = (d.su * (g.n * g.f - g.m * g.g) + d.sv * (g.m * g.f - g.n * g.e)) / det * ctx.sigma;
    let m = governing.hit.normal_in;
    let mn = m.dot(&n);
    let t = left_mm;
    let (grad, w_mm) = if mn < -GRAZING_COS {
        (
            [-m.dot(&(d.su + nu * t)) / mn, -m.dot(&(d.sv + nv * t)) / mn],
            -ctx.radius * mn,
        )
    } else {
        ([f64::INFINITY; 2], 0.0)
    };
    let slope = if w_mm > 0.0 {
        ((g.g * grad[0] * grad[0] - 2.0 * g.f * grad[0] * grad[1] + g.e * grad[1] * grad[1]) / det)
            .max(0.0)
            .sqrt()
    } else {
        f64::INFINITY
    };
    let overcut_mm = overcut(probe, &d.point, &n, left_mm);
    let (k_lo, k_hi) = g.principal();
    let k_min_tool_side = if ctx.sigma > 0.0 { k_lo } else { -k_hi };
    Sample {
        corner: Corner {
            point: d.point,
            reached: true,
            left_mm,
            overcut_mm,
            grad,
            w_mm,
            slope,
            kappa_convex: (-k_min_tool_side).max(0.0),
            metric: [g.e, g.f, g.g],
            second: [d.suu.norm(), d.suv.norm(), d.svv.norm()],
        },
        normal: g.normal,
        singular: false,
        area_density,
        rest,
    }
}

/// The overcut at a point of the surface whose material left along the tool-side normal `n`
/// is `left_mm` (see [`Corner::overcut_mm`]), just measured by `probe`.
fn overcut(probe: &mut Probe, p: &Point3, n: &Vector3, left_mm: f64) -> f64 {
    if left_mm >= 0.0 {
        0.0
    } else {
        let depth = match probe.last_straight_depth() {
            Some(d) => d,
            None => probe.straight_depth(p, n),
        };
        (-left_mm).min(depth)
    }
}

/// The heat value of a sample: gouge depth (negative) beyond the tolerance, else material
/// left, `+∞` if unreached, NaN if unmeasured.
fn heat_value(s: &Sample, tol: f64) -> f32 {
    if s.singular {
        f32::NAN
    } else if !s.corner.reached {
        f32::INFINITY
    } else if s.corner.overcut_mm > tol {
        -s.corner.overcut_mm as f32
    } else {
        s.corner.left_mm.max(0.0) as f32
    }
}

/// Measures rows `j0..=j1` of face `fi` and the cells between them; row `j0` is counted
/// only if `own_first`.
fn band(
    ctx: &Ctx,
    probe: &mut Probe,
    fi: usize,
    j0: usize,
    j1: usize,
    own_first: bool,
    mut heat: Option<&mut HeatMap>,
) -> Acc {
    let FaceGrid { nu, nv } = ctx.grids[fi];
    let (du, dv) = (1.0 / (nu - 1) as f64, 1.0 / (nv - 1) as f64);
    let r = ctx.radius;
    let tol = ctx.opts.gouge_tolerance_mm;
    let h_req = ctx.opts.scallop_mm;
    let mut acc = Acc::default();
    let mut deepest: Option<(f64, f64, f64)> = None;
    let mut values: Vec<(f64, f64)> = Vec::new();
    let mut prev: Vec<Sample> = Vec::new();
    let mut row: Vec<Sample> = Vec::with_capacity(nu);
    // Grid coordinates by division, so that the last row and column are exactly 1.
    let at = |k: usize, n: usize| k as f64 / (n - 1) as f64;
    // The band's columns: each contracted along u once per Bézier cell.
    let face = &ctx.surface.faces()[fi];
    let mut columns: Vec<_> = (0..nu).map(|i| face.u_line(at(i, nu))).collect();
    for j in j0..=j1 {
        let v = at(j, nv);
        row.clear();
        for (i, column) in columns.iter_mut().enumerate() {
            row.push(measure_with(ctx, probe, fi, at(i, nu), v, column.derivs(v)));
        }
        if j > j0 || own_first {
            let wv = if j == 0 || j == nv - 1 { 0.5 } else { 1.0 };
            for (i, s) in row.iter().enumerate() {
                let wu = if i == 0 || i == nu - 1 { 0.5 } else { 1.0 };
                let w = s.area_density * du * dv * wu * wv;
                acc.samples += 1;
                acc.area += w;
                if let Some(h) = heat.as_deref_mut() {
                    h.add(&s.corner.point, &s.normal, heat_value(s, tol));
                }
                if s.singular {
                    acc.singular += 1;
                    continue;
                }
                if s.rest {
                    acc.rest_area += w;
                }
                if !s.corner.reached {
                    acc.unreached += 1;
                    acc.unreached_area += w;
                    acc.uncut_area += w;
                    continue;
                }
                let left = s.corner.left_mm;
                if left > h_req {
                    acc.uncut_area += w;
                }
                let cut_in = s.corner.overcut_mm;
                if cut_in > tol {
                    acc.gouges += 1;
                    acc.gouge_area += w;
                }
                acc.note_gouge(cut_in, Some(s.corner.point));
                if cut_in > 0.0 && deepest.is_none_or(|(d, ..)| -cut_in < d) {
                    deepest = Some((-cut_in, at(i, nu), v));
                }
                if s.rest {
                    // Left for another tool by the plan: not a scallop.
                    continue;
                }
                acc.reached_area += w;
                acc.note_left(Some(left), Some(s.corner.point));
                let scallop = left.max(0.0);
                acc.scallop_area += scallop * w;
                values.push((scallop, w));
            }
        }
        if j > j0 {
            for i in 0..nu - 1 {
                let c = [
                    &prev[i].corner,
                    &prev[i + 1].corner,
                    &row[i].corner,
                    &row[i + 1].corner,
                ];
                acc.spacing = acc.spacing.max(
                    (c[0].point - c[3].point)
                        .norm()
                        .max((c[1].point - c[2].point).norm()),
                );
                // The uncut area's edge runs through a cell whose measured corners disagree.
                let cell = [&prev[i], &prev[i + 1], &row[i], &row[i + 1]];
                let uncut = |s: &Sample| !s.corner.reached || s.corner.left_mm > h_req;
                let measured = cell.iter().filter(|s| !s.singular);
                let uncut_corners = measured.clone().filter(|s| uncut(s)).count();
                if uncut_corners > 0 && uncut_corners < measured.count() {
                    let density = 0.25 * cell.iter().map(|s| s.area_density).sum::<f64>();
                    acc.uncut_edge_area += density * du * dv;
                }
                if c.iter().any(|c| !c.reached) {
                    continue;
                }
                if ctx.opts.preview {
                    // No bound between samples: it is unknown.
                    acc.upper = Some(f64::INFINITY);
                    acc.gouge_upper = Some(f64::INFINITY);
                    continue;
                }
                let best = [
                    acc.upper.unwrap_or(f64::NEG_INFINITY),
                    acc.gouge_upper.unwrap_or(f64::NEG_INFINITY),
                ];
                let frame = CellFrame {
                    du,
                    dv,
                    boundary: [j == 1, i + 2 == nu, j + 1 == nv, i == 0],
                };
                let mut b = cell_bound(&c, &frame, r, ctx.reach, best);
                let corner_rest = [prev[i].rest, prev[i + 1].rest, row[i].rest, row[i + 1].rest];
                let in_rest = corner_rest.iter().any(|&x| x);
                // A cell whose bound would raise the error bound is sampled more finely
                // (near extraordinary points and tight folds the metric and the curvature
                // change too much across a cell for its corners to bound it).
                let [floor_left, floor_gouge] = ctx.floor.unwrap_or([0.0; 2]);
                let above = [
                    acc.max_left.unwrap_or(0.0).max(0.0).max(floor_left) + REFINE_SHARE * h_req,
                    acc.max_gouge.max(0.0).max(floor_gouge) + REFINE_SHARE * h_req,
                ];
                let loose_scallop =
                    !in_rest && b.scallop_upper_mm > above[0] && b.scallop_upper_mm > best[0];
                let loose_gouge = b.gouge_upper_mm > above[1] && b.gouge_upper_mm > best[1];
                if loose_scallop || loose_gouge {
                    let corners = [*c[0], *c[1], *c[2], *c[3]];
                    let origin = (at(i, nu), at(j - 1, nv));
                    if let Some(fine) = refined_bound(
                        ctx,
                        probe,
                        fi,
                        origin,
                        &corners,
                        corner_rest,
                        &frame,
                        above,
                        REFINE_DEPTH,
                        &mut acc,
                    ) {
                        b = fine;
                    }
                }
                acc.gouge_upper = max_opt(acc.gouge_upper, Some(b.gouge_upper_mm));
                if in_rest {
                    // Part of the cell is rest area: its material left is not a scallop.
                    continue;
                }
                acc.upper = max_opt(acc.upper, Some(b.scallop_upper_mm));
                // Measure at the cusp the bound located, where it could raise the maximum.
                // (Below the floor it could not raise the overall maximum.)
                if let Some([x, y]) = b.argmax {
                    let above_floor = ctx.floor.is_none_or(|[f, _]| b.scallop_upper_mm > f);
                    if acc.max_left.is_none_or(|m| b.scallop_upper_mm > m) && above_floor {
                        let (u, v) = ((at(i, nu) + x).min(1.0), (at(j - 1, nv) + y).min(1.0));
                        let s = measure(ctx, probe, fi, u, v);
                        if s.corner.reached {
                            acc.note_left(Some(s.corner.left_mm), Some(s.corner.point));
                            acc.refined += 1;
                        }
                    }
                }
            }
        }
        std::mem::swap(&mut prev, &mut row);
    }
    acc.values.push(values);
    if let Some((_, u, v)) = deepest {
        let (bottom, at) = gouge_bottom(ctx, probe, fi, u, v, du, dv);
        acc.note_gouge(-bottom, Some(at));
    }
    acc
}

/// Bound of the cell with corner 0 at `origin` (face parameters), sides `frame.du` and
/// `frame.dv`, from its four quarters, each bounded from its own corners (five new samples)
/// and split again while its scallop or gouge bound stays above `above` (scallop, gouge), up
/// to `depth` times. The new
/// samples' material left counts towards the maximum. `None` where a new sample cannot be
/// used (unreached, singular, in the rest area): the cell keeps its own bound.
#[allow(clippy::too_many_arguments)]
fn refined_bound(
    ctx: &Ctx,
    probe: &mut Probe,
    fi: usize,
    origin: (f64, f64),
    c: &[Corner; 4],
    corner_rest: [bool; 4],
    frame: &CellFrame,
    above: [f64; 2],
    depth: usize,
    acc: &mut Acc,
) -> Option<CellBound> {
    let (du, dv) = (0.5 * frame.du, 0.5 * frame.dv);
    // A 3 × 3 grid: the old corners and five new samples.
    let mut g: [[Option<Corner>; 3]; 3] = [[None; 3]; 3];
    // Which of the nine lie in the rest area (the old corners as the caller found them).
    let mut rest = [[false; 3]; 3];
    for (k, (a, b)) in [(0, 0), (2, 0), (0, 2), (2, 2)].into_iter().enumerate() {
        rest[a][b] = corner_rest[k];
    }
    g[0][0] = Some(c[0]);
    g[2][0] = Some(c[1]);
    g[0][2] = Some(c[2]);
    g[2][2] = Some(c[3]);
    for (a, b) in [(1, 0), (0, 1), (1, 1), (2, 1), (1, 2)] {
        let s = measure(
            ctx,
            probe,
            fi,
            (origin.0 + du * a as f64).min(1.0),
            (origin.1 + dv * b as f64).min(1.0),
        );
        if !s.corner.reached || s.singular {
            return None;
        }
        if s.rest {
            rest[a][b] = true;
        } else {
            acc.note_left(Some(s.corner.left_mm), Some(s.corner.point));
        }
        acc.note_gouge(s.corner.overcut_mm, Some(s.corner.point));
        acc.refined += 1;
        g[a][b] = Some(s.corner);
    }
    let g = g.map(|col| col.map(|x| x.expect("all nine samples set")));
    let mut out: Option<CellBound> = None;
    for (a, b) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let corners = [g[a][b], g[a + 1][b], g[a][b + 1], g[a + 1][b + 1]];
        let sub = CellFrame {
            du,
            dv,
            boundary: [
                b == 0 && frame.boundary[0],
                a == 1 && frame.boundary[1],
                b == 1 && frame.boundary[2],
                a == 0 && frame.boundary[3],
            ],
        };
        let refs = [&corners[0], &corners[1], &corners[2], &corners[3]];
        let sub_origin = (origin.0 + du * a as f64, origin.1 + dv * b as f64);
        let sub_rest = [
            rest[a][b],
            rest[a + 1][b],
            rest[a][b + 1],
            rest[a + 1][b + 1],
        ];
        let mut sb = cell_bound(&refs, &sub, ctx.radius, ctx.reach, [f64::NEG_INFINITY; 2]);
        let in_rest = sub_rest.iter().any(|&x| x);
        if ((!in_rest && sb.scallop_upper_mm > above[0]) || sb.gouge_upper_mm > above[1])
            && depth > 1
        {
            if let Some(fine) = refined_bound(
                ctx,
                probe,
                fi,
                sub_origin,
                &corners,
                sub_rest,
                &sub,
                above,
                depth - 1,
                acc,
            ) {
                sb = fine;
            }
        }
        if in_rest {
            // Part of it is rest area: its material left is not a scallop.
            sb.scallop_upper_mm = f64::NEG_INFINITY;
            sb.argmax = None;
        }
        // The cusp the bound located, relative to the whole cell's corner 0.
        let argmax = sb
            .argmax
            .map(|[x, y]| [x + du * a as f64, y + dv * b as f64]);
        out = Some(match out {
            None => CellBound { argmax, ..sb },
            Some(o) => CellBound {
                scallop_upper_mm: o.scallop_upper_mm.max(sb.scallop_upper_mm),
                gouge_upper_mm: o.gouge_upper_mm.max(sb.gouge_upper_mm),
                argmax: if sb.scallop_upper_mm > o.scallop_upper_mm {
                    argmax
                } else {
                    o.argmax
                },
            },
        });
    }
    out
}

/// From a gouged sample at `(u, v)`, Newton steps towards the bottom of the gouge (where
/// the depth's gradient vanishes), measuring at each; the deepest material left found (mm,
/// negative) and where.
fn gouge_bottom(
    ctx: &Ctx,
    probe: &mut Probe,
    fi: usize,
    u: f64,
    v: f64,
    du: f64,
    dv: f64,
) -> (f64, Point3) {
    let first = measure(ctx, probe, fi, u, v);
    let mut best = -first.corner.overcut_mm;
    let mut best_at = first.corner.point;
    let mut at = (u, v, first.corner);
    for _ in 0..GOUGE_NEWTON_STEPS {
        let c = &at.2;
        if !(c.reached && c.w_mm > 0.0) {
            break;
        }
        let k = second_derivative_bound(ctx.radius, c.kappa_convex, c.w_mm, c.left_mm);
        let [e, f, g] = c.metric.map(|m| m * k);
        let det = e * g - f * f;
        if !(det > 0.0) {
            break;
        }
        let su = -(g * c.grad[0] - f * c.grad[1]) / det;
        let sv = -(-f * c.grad[0] + e * c.grad[1]) / det;
        let (su, sv) = (
            su.clamp(-GOUGE_STEP_CELLS * du, GOUGE_STEP_CELLS * du),
            sv.clamp(-GOUGE_STEP_CELLS * dv, GOUGE_STEP_CELLS * dv),
        );
        let (nu, nv) = ((at.0 + su).clamp(0.0, 1.0), (at.1 + sv).clamp(0.0, 1.0));
        let next = measure(ctx, probe, fi, nu, nv);
        if !(next.corner.reached && next.corner.left_mm < at.2.left_mm) {
            break;
        }
        if -next.corner.overcut_mm < best {
            best = -next.corner.overcut_mm;
            best_at = next.corner.point;
        }
        at = (nu, nv, next.corner);
    }
    (best, best_at)
}

/// +1 if the tool works from the side `S_u × S_v` points to, −1 if from the other: the
/// majority, over a coarse grid, of the side where the nearest ball centre lies. The count
/// stops once the votes left cannot change the outcome.
fn vote_side(ctx: &Ctx, probe: &mut Probe) -> f64 {
    let mut votes: i64 = 0;
    let mut left = (ctx.surface.faces().len() * SIDE_PROBE * SIDE_PROBE) as i64;
    for face in ctx.surface.faces() {
        for i in 0..SIDE_PROBE {
            for j in 0..SIDE_PROBE {
                // A tie goes to +1.
                if votes - left >= 0 {
                    return 1.0;
                }
                if votes + left < 0 {
                    return -1.0;
                }
                left -= 1;
                let (u, v) = (
                    (i as f64 + 0.5) / SIDE_PROBE as f64,
                    (j as f64 + 0.5) / SIDE_PROBE as f64,
                );
                let Some((d, g)) = geometry(face, face.derivs(u, v), u, v) else {
                    continue;
                };
                if let Some(c) = probe.nearest_centre(&d.point, &g.normal, 2.0 * ctx.radius) {
                    let s = (c - d.point).dot(&g.normal);
                    votes += if s > 0.0 {
                        1
                    } else if s < 0.0 {
                        -1
                    } else {
                        0
                    };
                }
            }
        }
    }
    if votes < 0 {
        -1.0
    } else {
        1.0
    }
}

/// Work items: (face, first row, last row, owns first row).
fn work_items(grids: &[FaceGrid]) -> Vec<(usize, usize, usize, bool)> {
    let mut items = Vec::new();
    for (fi, g) in grids.iter().enumerate() {
        let mut j0 = 0;
        while j0 < g.nv - 1 {
            let j1 = (j0 + BAND_ROWS).min(g.nv - 1);
            items.push((fi, j0, j1, j0 == 0));
            j0 = j1;
        }
    }
    items
}

fn threads(asked: usize) -> usize {
    #[cfg(target_arch = "wasm32")]
    {
        let _ = asked;
        1
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        if asked > 0 {
            asked
        } else {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        }
    }
}

/// Runs every work item, in parallel where threads exist; results in item order.
fn run_items(
    ctx: &Ctx,
    items: &[(usize, usize, usize, bool)],
    heat: Option<&mut HeatMap>,
    progress: &mut dyn FnMut(f64),
) -> Vec<Acc> {
    let workers = threads(ctx.opts.threads).min(items.len()).max(1);
    let new_probe = || {
        Probe::new(
            ctx.capsules,
            ctx.index,
            ctx.radius,
            ctx.reach,
            ctx.max_depth,
        )
    };
    if workers == 1 {
        let mut probe = new_probe();
        let mut heat = heat;
        let n = items.len().max(1) as f64;
        return items
            .iter()
            .enumerate()
            .map(|(k, &(fi, j0, j1, own))| {
                let acc = band(ctx, &mut probe, fi, j0, j1, own, heat.as_deref_mut());
                progress((k + 1) as f64 / n);
                acc
            })
            .collect();
    }
    #[cfg(target_arch = "wasm32")]
    {
        unreachable!("one worker on wasm")
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        use std::sync::atomic::{AtomicUsize, Ordering};
        use std::sync::Mutex;
        let next = AtomicUsize::new(0);
        let results: Mutex<Vec<Option<Acc>>> = Mutex::new(vec![None; items.len()]);
        let template = heat.as_deref().cloned();
        let maps: Vec<Option<HeatMap>> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..workers)
                .map(|_| {
                    let mut map = template.clone();
                    let (next, results) = (&next, &results);
                    s.spawn(move || {
                        let mut probe = new_probe();
                        loop {
                            let k = next.fetch_add(1, Ordering::Relaxed);
                            let Some(&(fi, j0, j1, own)) = items.get(k) else {
                                break;
                            };
                            let acc = band(ctx, &mut probe, fi, j0, j1, own, map.as_mut());
                            results.lock().expect("no worker panics")[k] = Some(acc);
                        }
                        map
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("verification worker panicked"))
                .collect()
        });
        if let Some(h) = heat {
            for m in maps.into_iter().flatten() {
                h.merge(&m);
            }
        }
        // The threads report nothing on the way (only wasm, single-threaded, has a page to
        // show progress on).
        progress(1.0);
        results
            .into_inner()
            .expect("no worker panics")
            .into_iter()
            .map(|a| a.expect("every item ran"))
            .collect()
    }
}

/// The coarse pass before a bounded simulation: every patch sampled with one sample in
/// [`SEED_SHARE`], bounding nothing; its totals per patch. Without it a band refines every
/// cell whose bound is above what that band has measured so far, which on a part whose
/// scallop varies is most cells of its flatter bands (gearbox2-9.tsm, r 0.5 mm, h 0.01 mm:
/// 13.5 M extra measurements for 3.8 M samples).
fn seed_pass(ctx: &Ctx, progress: &mut dyn FnMut(f64)) -> Vec<Acc> {
    let opts = VerifyOptions {
        preview: true,
        samples: (ctx.opts.samples / SEED_SHARE).max(1),
        ..ctx.opts.clone()
    };
    let grids = grids(ctx.surface, opts.samples);
    let coarse = Ctx {
        grids: &grids,
        opts: &opts,
        ..*ctx
    };
    let items = work_items(&grids);
    let mut per_face: Vec<Acc> = vec![Acc::default(); grids.len()];
    for (&(fi, ..), acc) in items.iter().zip(run_items(&coarse, &items, None, progress)) {
        per_face[fi].merge(acc);
    }
    per_face
}

/// The highest material left and deepest gouge (mm, at least 0) of the coarse pass.
fn seed_floor(seeds: &[Acc]) -> [f64; 2] {
    seeds.iter().fold([0.0, 0.0], |[l, g], a| {
        [l.max(a.max_left.unwrap_or(0.0)), g.max(a.max_gouge)]
    })
}

/// The summary of `acc`; a `preview` bounds nothing between samples (infinite bounds).
fn summarise(patch: u32, grid: [usize; 2], acc: &Acc, preview: bool) -> PatchVerification {
    let frac = |a: f64| if acc.area > 0.0 { a / acc.area } else { 0.0 };
    let max_scallop = acc.max_left.map_or(0.0, |m| m.max(0.0));
    let unbounded = if preview { f64::INFINITY } else { 0.0 };
    let scallop_bound = acc.upper.map_or(unbounded, |u| (u - max_scallop).max(0.0));
    let gouge_bound = acc
        .gouge_upper
        .map_or(unbounded, |g| (g - acc.max_gouge.max(0.0)).max(0.0));
    PatchVerification {
        patch,
        samples: acc.samples,
        grid,
        area_mm2: acc.area,
        sample_spacing_mm: acc.spacing,
        max_scallop_mm: max_scallop,
        max_scallop_at_mm: acc.max_left_at.map(|p| [p.x, p.y, p.z]),
        mean_scallop_mm: if acc.reached_area > 0.0 {
            acc.scallop_area / acc.reached_area
        } else {
            0.0
        },
        p95_scallop_mm: weighted_quantile(&acc.values, PERCENTILE).unwrap_or(0.0),
        uncut_fraction: frac(acc.uncut_area),
        uncut_edge_fraction: frac(acc.uncut_edge_area),
        unreached_fraction: frac(acc.unreached_area),
        unreached_samples: acc.unreached,
        max_gouge_mm: acc.max_gouge.max(0.0),
        max_gouge_at_mm: acc
            .max_gouge_at
            .filter(|_| acc.max_gouge > 0.0)
            .map(|p| [p.x, p.y, p.z]),
        rest_fraction: frac(acc.rest_area),
        gouge_count: acc.gouges,
        gouge_fraction: frac(acc.gouge_area),
        scallop_error_bound_mm: scallop_bound,
        gouge_error_bound_mm: gouge_bound,
        error_bound_mm: scallop_bound.max(gouge_bound),
        singular_samples: acc.singular,
        cusp_samples: acc.refined,
    }
}

/// Simulates the cut; `progress` gets the fraction of the sample bands done.
pub(super) fn run(
    surface: &Surface,
    path: &CutterPath,
    opts: &VerifyOptions,
    mut heat: Option<&mut HeatMap>,
    progress: &mut dyn FnMut(f64),
) -> Verification {
    let r = path.tool_radius_mm;
    let reach = r;
    let capsules = path.capsules();
    let bbox = surface.bbox();
    let grow = reach + r + REGION_MARGIN * bbox.diagonal();
    let region = Aabb {
        min: bbox.min.map(|x| x - grow),
        max: bbox.max.map(|x| x + grow),
    };
    progress(0.0);
    let index = CapsuleIndex::build(&capsules, r, &region, CELL_PER_RADIUS * r);
    progress(0.0);
    let grids = grids(surface, opts.samples);
    progress(0.0);
    let rest = RestMask::new(&opts.rest_area, grids.len());
    let mut ctx = Ctx {
        surface,
        capsules: &capsules,
        index: &index,
        grids: &grids,
        radius: r,
        reach,
        max_depth: region.diagonal(),
        sigma: 1.0,
        opts,
        rest: &rest,
        floor: None,
    };
    let mut probe = Probe::new(&capsules, &index, r, reach, ctx.max_depth);
    ctx.sigma = match opts.tool_side {
        ToolSide::Normal => 1.0,
        ToolSide::Opposite => -1.0,
        ToolSide::Auto => vote_side(&ctx, &mut probe),
    };
    let seeds = if opts.preview {
        None
    } else {
        let seeds = seed_pass(&ctx, &mut |f| progress(SEED_PROGRESS * f));
        ctx.floor = Some(seed_floor(&seeds));
        Some(seeds)
    };
    let share = if seeds.is_some() { SEED_PROGRESS } else { 0.0 };
    let items = work_items(&grids);
    let results = run_items(&ctx, &items, heat.as_deref_mut(), &mut |f| {
        progress(share + (1.0 - share) * f)
    });
    let mut per_face: Vec<Acc> = vec![Acc::default(); grids.len()];
    for (&(fi, ..), acc) in items.iter().zip(results) {
        per_face[fi].merge(acc);
    }
    // The coarse pass's maxima are measurements like the others.
    for (face, seed) in per_face.iter_mut().zip(seeds.iter().flatten()) {
        face.note_left(seed.max_left, seed.max_left_at);
        face.note_gouge(seed.max_gouge, seed.max_gouge_at);
        face.refined += seed.samples;
    }
    if let Some(h) = heat {
        for (i, p, n) in h.unfilled() {
            let n = n * ctx.sigma;
            let value = match probe.measure(&p, &n) {
                Material::Left { left_mm, .. } => {
                    let cut_in = overcut(&mut probe, &p, &n, left_mm);
                    if cut_in > opts.gouge_tolerance_mm {
                        -cut_in as f32
                    } else {
                        left_mm.max(0.0) as f32
                    }
                }
                Material::Unreached => f32::INFINITY,
            };
            h.set(i, worse(f32::NAN, value));
        }
    }
    let patches: Vec<PatchVerification> = per_face
        .iter()
        .enumerate()
        .map(|(fi, a)| summarise(fi as u32, [grids[fi].nu, grids[fi].nv], a, opts.preview))
        .collect();
    let mut all = Acc::default();
    for a in per_face {
        all.merge(a);
    }
    let o = summarise(u32::MAX, [0, 0], &all, opts.preview);
    Verification {
        tool_radius_mm: r,
        requested_scallop_mm: opts.scallop_mm,
        gouge_tolerance_mm: opts.gouge_tolerance_mm,
        tool_side: if ctx.sigma > 0.0 {
            ToolSide::Normal
        } else {
            ToolSide::Opposite
        },
        moves: capsules.len(),
        samples: o.samples,
        area_mm2: o.area_mm2,
        sample_spacing_mm: o.sample_spacing_mm,
        max_scallop_mm: o.max_scallop_mm,
        max_scallop_at_mm: o.max_scallop_at_mm,
        mean_scallop_mm: o.mean_scallop_mm,
        p95_scallop_mm: o.p95_scallop_mm,
        uncut_fraction: o.uncut_fraction,
        uncut_edge_fraction: o.uncut_edge_fraction,
        unreached_fraction: o.unreached_fraction,
        unreached_samples: o.unreached_samples,
        rest_fraction: o.rest_fraction,
        max_gouge_mm: o.max_gouge_mm,
        max_gouge_at_mm: o.max_gouge_at_mm,
        gouge_count: o.gouge_count,
        gouge_fraction: o.gouge_fraction,
        scallop_error_bound_mm: o.scallop_error_bound_mm,
        gouge_error_bound_mm: o.gouge_error_bound_mm,
        error_bound_mm: o.error_bound_mm,
        error_bound_target_mm: None,
        singular_samples: o.singular_samples,
        cusp_samples: o.cusp_samples,
        patches,
    }
}
