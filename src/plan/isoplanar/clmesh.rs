//! The cutter-location (CL) surface as a triangle mesh: per layout patch a grid in the
//! patch's `(u, v)`, fine enough that the mesh of ball centres stays within the chordal
//! tolerance of the true offset (its lines closer together where the curvature and the
//! parameter speed ask, not evenly at the patch's worst; near spots convex tighter than the
//! ball, where sampled curvature can miss how fast the ball centres swing, each cell checked
//! against the offset at its middle and halved while it strays), each vertex a ball centre a
//! tool radius along the exact limit-surface normal (not a vertex normal of a coarse mesh)
//! from its contact point.
//!
//! Where the surface is concave with a radius below the ball's, or folds, the offset
//! self-intersects and some of its vertices lie closer than a radius to the surface; they
//! are kept here (the slices pass through them), and the shared pipeline lifts every ball
//! centre that would cut into the surface until it touches without cutting in (the same
//! lifting every strategy gets): no CL point of the plan lies closer than a radius.
//!
//! Where two patches meet at a convex crease (their normals differ along the seam), the ball
//! centres that touch the seam's edge pivot about it from one patch's normal to the other's;
//! they belong to neither patch's grid, so the mesh gets a pivot strip there ([`Strip`]):
//! rows of ball centres `p + r·n(k)` over the seam points `p`, `n(k)` turning from one
//! normal to the other in steps the chordal tolerance allows. Without it the CL surface has a
//! gap `r` times the crease's angle wide along the seam, and a plane running along the gap
//! cuts neither side (Bike.tsm at 0°: 0.0137 mm left beside its middle crease, h 0.01 mm).
//! At a concave crease the two sides' offsets cross instead, and the ball that cleans the
//! groove touches both sides: the mesh keeps one row of ball centres there, pivoted half-way
//! (`k` ½, a radius from the crease, so cutting into both sides), not meshed, for a pass
//! along the groove; the pipeline lifts those balls until they touch without cutting in.
//!
//! Owns: the mesh and its vertices' patch parameters. Must not: deform or slice it.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::layout::{side_param, side_uv};
use crate::model::Model;
use crate::plan::stepover;
use crate::surface::diffgeom::unit_normal;
use crate::surface::{DiffGeom, SurfaceDerivs};

/// The grid cells per unit parameter that `u` and `v` of `patch` ask for, per interval
/// between neighbouring samples: at each sample the parameter speed over the surface step
/// whose chord on the offset (and on the surface) keeps within the chordal tolerance, at
/// most `max_cell_mm`; per interval the largest at its ends and theirs beside (a peak
/// between samples is not missed by a sample's width), the largest across the other
/// direction.
///
/// Also, per side and sample, whether the surface there is convex towards the tool with a
/// radius under the ball's ([`TIGHT_CONVEX_RK`]) somewhere across the other direction
/// (`side` is the tool's side, [`Model::tool_side`]): where [`refine_lines`] checks the
/// cells.
fn density(
    patch: &crate::layout::Patch,
    surface: &crate::surface::Surface,
    side: f64,
    r: f64,
    chordal_mm: f64,
    max_cell_mm: f64,
) -> ([Vec<f64>; 2], [Vec<bool>; 2]) {
    let n = SIZE_SAMPLES;
    let k = (n - 1) as f64;
    // Cells per unit parameter asked at each sample, the largest across the other side.
    let mut at = [vec![0.0f64; n], vec![0.0f64; n]];
    let mut tight = [vec![false; n], vec![false; n]];
    for a in 0..n {
        for b in 0..n {
            let d = patch.derivs(surface, a as f64 / k, b as f64 / k);
            let Some(g) = DiffGeom::try_from_derivs(&d) else {
                continue;
            };
            // The offset's curvature, taken as on the concave side whatever the side:
            // κ / (1 − rκ), capped where the offset folds (the pipeline lifts the balls
            // there). Convex, the offset bends less but its ball centres move faster than
            // the contact point; per step on the surface its sagitta grows as
            // |κ| (1 + r|κ|), which this bounds up to r|κ| = 1.
            let (k1, k2) = g.principal();
            let kk = k1.abs().max(k2.abs());
            let kcl = if kk * r < 0.5 {
                kk / (1.0 - kk * r)
            } else {
                2.0 * kk
            };
            let seg = stepover::chord_step(chordal_mm, kcl).min(max_cell_mm);
            if seg.is_finite() {
                at[0][a] = at[0][a].max(d.su.norm() / seg);
                at[1][b] = at[1][b].max(d.sv.norm() / seg);
            }
            // Convex towards the tool: negative on the tool's side.
            if (-side * k1).max(-side * k2) * r >= TIGHT_CONVEX_RK {
                tight[0][a] = true;
                tight[1][b] = true;
            }
        }
    }
    let cells = at.map(|side| {
        (0..n - 1)
            .map(|i| {
                side[i.saturating_sub(1)..(i + 3).min(n)]
                    .iter()
                    .copied()
                    .fold(0.0, f64::max)
            })
            .collect()
    });
    (cells, tight)
}

/// `lines` (grid lines of one side of `patch`, the other side's parameter running across)
/// with lines added where the CL mesh's cells would stray from the offset: between
/// neighbouring lines near a sample flagged `tight`, the ball centre half-way (at
/// [`CELL_PROBES`] + 1 places across) checked against the middle of the chord between the
/// lines' ball centres, and the interval halved while it strays by more than the chordal
/// tolerance (at most [`CELL_HALVINGS`] times). The density, sampled [`SIZE_SAMPLES`] times
/// per side, misses an edge rounded to a sliver between samples: Bike.tsm's middle crease
/// starts in a patch 0.013 mm wide whose ball centres swing 0.18 mm within its last half,
/// which the grid took as two straight cells.
#[allow(clippy::too_many_arguments)]
fn refine_lines(
    patch: &crate::layout::Patch,
    surface: &crate::surface::Surface,
    side: f64,
    r: f64,
    chordal_mm: f64,
    dir: usize,
    lines: &[f64],
    tight: &[bool],
) -> Vec<f64> {
    let k = (tight.len() - 1) as f64;
    let near_tight = |x0: f64, x1: f64| {
        tight
            .iter()
            .enumerate()
            .any(|(a, &t)| t && a as f64 / k >= x0 - 1.0 / k && a as f64 / k <= x1 + 1.0 / k)
    };
    // The ball centres along a line, at the places across where cells are checked.
    let row = |x: f64| -> Vec<Option<Point3>> {
        (0..=CELL_PROBES)
            .map(|j| {
                let w = j as f64 / CELL_PROBES as f64;
                let (u, v) = if dir == 0 { (x, w) } else { (w, x) };
                let (p, n) = patch.point_normal(surface, u, v);
                n.map(|n| p + n * (side * r))
            })
            .collect()
    };
    type Row = Vec<Option<Point3>>;
    // Adds the lines between `x0` and `x1` (their rows `r0`, `r1`) that bring the cells
    // within the tolerance.
    let split = |x0: f64, r0: &Row, x1: f64, r1: &Row, out: &mut Vec<f64>| {
        fn go(
            (x0, r0): (f64, &Row),
            (x1, r1): (f64, &Row),
            depth: usize,
            row: &dyn Fn(f64) -> Row,
            chordal_mm: f64,
            out: &mut Vec<f64>,
        ) {
            if depth == 0 {
                return;
            }
            let mid = 0.5 * (x0 + x1);
            let rm = row(mid);
            let strays = r0
                .iter()
                .zip(r1)
                .zip(&rm)
                .any(|((a, b), m)| match (a, b, m) {
                    (Some(a), Some(b), Some(m)) => {
                        (m - Point3::from(0.5 * (a.coords + b.coords))).norm() > chordal_mm
                    }
                    _ => false,
                });
            if !strays {
                return;
            }
            go((x0, r0), (mid, &rm), depth - 1, row, chordal_mm, out);
            out.push(mid);
            go((mid, &rm), (x1, r1), depth - 1, row, chordal_mm, out);
        }
        go((x0, r0), (x1, r1), CELL_HALVINGS, &row, chordal_mm, out);
    };
    let mut out = vec![lines[0]];
    let mut last: Option<(f64, Row)> = None;
    for w in lines.windows(2) {
        if near_tight(w[0], w[1]) {
            let r0 = match last.take() {
                Some((x, r)) if x == w[0] => r,
                _ => row(w[0]),
            };
            let r1 = row(w[1]);
            split(w[0], &r0, w[1], &r1, &mut out);
            last = Some((w[1], r1));
        }
        out.push(w[1]);
    }
    out
}

/// Grid lines (patch parameters from 0 to 1) for [`density`] `d` times `scale`: per side
/// the cells the density integrates to (at least [`MIN_CELLS`], at most [`MAX_CELLS`]),
/// each holding an equal share of the integral (evenly spaced where it is zero).
fn grid_lines(d: &[Vec<f64>; 2], scale: f64) -> [Vec<f64>; 2] {
    [0, 1].map(|side| {
        let w = 1.0 / d[side].len() as f64;
        let cells: Vec<f64> = d[side].iter().map(|&c| c * scale * w).collect();
        let sum: f64 = cells.iter().sum();
        let n = if sum.is_finite() {
            (sum.ceil() as usize).clamp(MIN_CELLS, MAX_CELLS)
        } else {
            MAX_CELLS
        };
        if !(sum > 0.0) || !sum.is_finite() {
            return (0..=n).map(|i| i as f64 / n as f64).collect();
        }
        // Line i where the running integral reaches i / n of the whole, linear within an
        // interval.
        let mut lines = Vec::with_capacity(n + 1);
        lines.push(0.0);
        let (mut run, mut k) = (0.0, 0);
        for i in 1..n {
            let want = sum * i as f64 / n as f64;
            while k + 1 < cells.len() && run + cells[k] < want {
                run += cells[k];
                k += 1;
            }
            let f = if cells[k] > 0.0 {
                ((want - run) / cells[k]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            lines.push((k as f64 + f) * w);
        }
        lines.push(1.0);
        lines
    })
}

/// A vertex of the CL mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClVertex {
    /// Its layout patch, or past the layout's patches its pivot strip (see
    /// [`ClMesh::strip`]).
    pub patch: u32,
    /// Patch parameters of its contact point (a strip's: along the seam, and the turn).
    pub uv: [f64; 2],
    /// Contact point on the surface (mm).
    pub cc: Point3,
    /// Unit normal on the tool's side.
    pub normal: Vector3,
    /// Ball centre, `cc + r·normal` (mm).
    pub cl: Point3,
}

/// The mesh: vertices (`None` at singular points, where the surface has no normal) and
/// triangles, each within one patch or strip, counter-clockwise in `(u, v)`.
#[derive(Debug, Clone)]
pub struct ClMesh {
    pub vertices: Vec<Option<ClVertex>>,
    pub triangles: Vec<[u32; 3]>,
    /// Per layout patch, then per pivot strip: its first vertex and its grid's cells
    /// `(nu, nv)`.
    pub patches: Vec<(u32, [usize; 2])>,
    /// The pivot strips at creases, numbered after the layout's patches.
    pub strips: Vec<Strip>,
    /// The sides two patches share, as [`crate::plan::isfc`] finds them:
    /// `(patch, side, patch, side)`.
    pub shared: Vec<(u32, u8, u32, u8)>,
}

/// Ball centres pivoting about a crease: where patch `a`'s side `side` lies on patch `b` and
/// the normals on either side differ, the strip's parameters `(s, k)` are the parameter `s`
/// along `a`'s side and the turn `k` from `a`'s normal (0) to `b`'s (1); its contact point is
/// the seam's point at `s` whatever `k`.
#[derive(Debug, Clone, PartialEq)]
pub struct Strip {
    /// Convex (the strip is meshed, its rows turning from one side's normal to the other's),
    /// or concave (its one row, at `k` ½, is the groove's pass and is not meshed).
    pub convex: bool,
    pub a: u32,
    /// Side of `a` (0: `v = 0`, 1: `u = 1`, 2: `v = 1`, 3: `u = 0`).
    pub side: u8,
    pub b: u32,
    /// The side of `b` the seam lies on.
    pub side_b: u8,
    /// Its columns, in increasing `s`: `s`, and `b`'s patch parameters at the same point
    /// (between columns taken linearly).
    pub cols: Vec<(f64, [f64; 2])>,
}

/// Of first derivatives `su`, `sv` on side `side`: the one along the side, and the one into
/// the patch from it.
fn along_into(side: u8, su: Vector3, sv: Vector3) -> (Vector3, Vector3) {
    match side {
        0 => (su, sv),
        1 => (sv, -su),
        2 => (su, -sv),
        _ => (sv, su),
    }
}

/// The angle (radians) between unit normals `na` and `nb`, by the arctangent of its sine
/// over its cosine (accurate for small turns, where the arccosine of the dot product is not).
fn turn_between(na: &Vector3, nb: &Vector3) -> f64 {
    na.cross(nb).norm().atan2(na.dot(nb))
}

/// The unit normal a turn `k` (0 to 1) of the way from unit normal `na` to `nb` about their
/// common perpendicular (exactly `na` at 0 and `nb` at 1).
pub fn pivot_normal(na: &Vector3, nb: &Vector3, k: f64) -> Vector3 {
    if k <= 0.0 {
        return *na;
    }
    if k >= 1.0 {
        return *nb;
    }
    let theta = turn_between(na, nb);
    let s = theta.sin();
    if !(s > 0.0) {
        return (*na * (1.0 - k) + *nb * k)
            .try_normalize(0.0)
            .unwrap_or(*na);
    }
    (*na * ((1.0 - k) * theta).sin() + *nb * (k * theta).sin()) / s
}

impl Strip {
    /// The seam's point and the tool-side unit normal at strip parameters `[s, k]` (`s`
    /// held within the columns, `k` within 0 to 1); `None` where either patch has no
    /// normal.
    pub fn at(&self, model: &Model, sk: [f64; 2]) -> Option<(Point3, Vector3)> {
        let (p, na, nb) = self.ends(model, sk[0])?;
        Some((p, pivot_normal(&na, &nb, sk[1])))
    }

    /// The seam's point at `s` (held within the columns) and the tool-side unit normals of
    /// `a` and of `b` there.
    pub fn ends(&self, model: &Model, s: f64) -> Option<(Point3, Vector3, Vector3)> {
        let n = self.cols.len();
        let s = s.clamp(self.cols[0].0, self.cols[n - 1].0);
        let i = self.cols.partition_point(|c| c.0 <= s).clamp(1, n - 1);
        let ((s0, b0), (s1, b1)) = (self.cols[i - 1], self.cols[i]);
        let f = if s1 > s0 { (s - s0) / (s1 - s0) } else { 0.0 };
        let uvb = [b0[0] + f * (b1[0] - b0[0]), b0[1] + f * (b1[1] - b0[1])];
        let patches = &model.layout.patches;
        let uva = side_uv(self.side, s);
        let (p, na) = patches[self.a as usize].point_normal(&model.surface, uva[0], uva[1]);
        let nb = patches[self.b as usize].normal(&model.surface, uvb[0], uvb[1])?;
        let side = model.tool_side();
        Some((p, na? * side, nb * side))
    }

    /// The same seam seen from `b`: its columns along `b`'s side, in increasing order.
    pub fn reversed(&self) -> Strip {
        let mut cols: Vec<(f64, [f64; 2])> = self
            .cols
            .iter()
            .map(|&(s, uv_b)| (side_param(self.side_b, uv_b), side_uv(self.side, s)))
            .collect();
        crate::sort::sort_by(&mut cols, |x, y| x.0.total_cmp(&y.0));
        Strip {
            convex: self.convex,
            a: self.b,
            side: self.side_b,
            b: self.a,
            side_b: self.side,
            cols,
        }
    }
}

/// Fewest and most grid cells along a patch side.
const MIN_CELLS: usize = 2;
const MAX_CELLS: usize = 256;
/// Samples per side of a patch that place its grid lines.
const SIZE_SAMPLES: usize = 33;
/// `r κ` of a convex spot above which [`refine_lines`] checks the cells near it: a radius
/// under the ball's, where the ball centres swing more than twice as fast as the contact
/// point and the density's bound on the offset's sagitta no longer holds.
const TIGHT_CONVEX_RK: f64 = 1.0;
/// Places across a cell where [`refine_lines`] checks it, less one.
const CELL_PROBES: usize = 8;
/// Most halvings of a cell by [`refine_lines`].
const CELL_HALVINGS: usize = 5;
/// Most vertices of the whole mesh: beyond it the grids are coarsened (evenly).
const MAX_VERTICES: usize = 2_000_000;
/// Places along a shared side (less one) where it is first checked for a crease.
const CREASE_PROBES: usize = 16;
/// Most rows of a pivot strip (a crease of 180° at the chordal steps of a coarse tolerance).
const MAX_PIVOT_ROWS: usize = 64;
/// Newton steps finding the point of a side nearest a point of another.
const PROJECT_STEPS: usize = 16;
/// A Newton step below this (in a side's parameter) ends the search.
const PROJECT_PARAM_TOL: f64 = 1e-13;

/// Takes a vertex's index and the surface's derivatives at its contact point (patch
/// parameters) as [`ClMesh::new_with`] makes it.
pub type VertexVisit<'a> = &'a mut dyn FnMut(usize, &SurfaceDerivs);

/// Two triangles per cell of an `nu` × `nv` grid of vertices numbered row by row from `first`.
fn grid_triangles(first: u32, nu: usize, nv: usize, triangles: &mut Vec<[u32; 3]>) {
    let id = |i: usize, j: usize| first + (j * (nu + 1) + i) as u32;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
}

/// The parameter of the point of side `side` of `patch` nearest `p`, by Newton steps from
/// `t0`.
fn nearest_on_side(model: &Model, patch: u32, side: u8, p: &Point3, t0: f64) -> f64 {
    let patch = &model.layout.patches[patch as usize];
    let mut t = t0;
    for _ in 0..PROJECT_STEPS {
        let uv = side_uv(side, t);
        let (q, su, sv) = patch.first_derivs(&model.surface, uv[0], uv[1]);
        let (along, _) = along_into(side, su, sv);
        let g = along.norm_squared();
        if !(g > 0.0) {
            break;
        }
        let next = (t - (q - p).dot(&along) / g).clamp(0.0, 1.0);
        let done = (next - t).abs() < PROJECT_PARAM_TOL;
        t = next;
        if done {
            break;
        }
    }
    t
}

/// A column of a strip as it is found: the parameter along the first patch's side, the
/// other patch's parameters there, the normals' turn (radians) and its kind.
#[derive(Debug, Clone, Copy)]
struct Column {
    s: f64,
    uv_b: [f64; 2],
    turn: f64,
    convex: bool,
}

/// The pivot strips of `model` for a ball of radius `r` over patch grids `breaks`, with their
/// rows: along each side two patches share, its columns at the grid lines of the first
/// patch's side where the seam is a crease (the normals on either side, seen from the tool,
/// turn by more than the chordal tolerance over `r`), convex (each normal leaning away from
/// the other patch) or concave (each towards it), in runs of at least two of one kind; rows
/// of a convex strip every turn the chordal tolerance allows (and the longest cell side), at
/// least one; a concave strip's none (its one row of vertices is not meshed).
fn pivot_strips(
    model: &Model,
    shared: &[(u32, u8, u32, u8)],
    breaks: &[[Vec<f64>; 2]],
    r: f64,
    chordal_mm: f64,
    max_cell_mm: f64,
) -> Vec<(Strip, usize)> {
    let (surface, patches, side) = (&model.surface, &model.layout.patches, model.tool_side());
    let min_turn = chordal_mm / r;
    let turn_step = (2.0 * (1.0 - chordal_mm / r).clamp(-1.0, 1.0).acos()).min(max_cell_mm / r);
    let mut out = Vec::new();
    for &(a, sa, b, sb) in shared {
        // Where b's side runs, for the nearest point's first guess: its grid's points.
        let lines = |p: u32, s: u8| &breaks[p as usize][if s % 2 == 0 { 0 } else { 1 }];
        let guesses: Vec<(f64, Point3)> = lines(b, sb)
            .iter()
            .map(|&t| {
                let uv = side_uv(sb, t);
                (t, patches[b as usize].subs(surface, uv[0], uv[1]))
            })
            .collect();
        // The column at `t` whatever its turn, and whether it is a crease's.
        let column = |t: f64| -> Option<(Column, bool)> {
            let uva = side_uv(sa, t);
            let (p, su, sv) = patches[a as usize].first_derivs(surface, uva[0], uva[1]);
            let na = unit_normal(&su, &sv)? * side;
            let (_, into_a) = along_into(sa, su, sv);
            let t0 = guesses
                .iter()
                .min_by(|x, y| (x.1 - p).norm().total_cmp(&(y.1 - p).norm()))?
                .0;
            let uvb = side_uv(sb, nearest_on_side(model, b, sb, &p, t0));
            let (q, su_b, sv_b) = patches[b as usize].first_derivs(surface, uvb[0], uvb[1]);
            if (q - p).norm() > chordal_mm {
                return None;
            }
            let nb = unit_normal(&su_b, &sv_b)? * side;
            let (_, into_b) = along_into(sb, su_b, sv_b);
            let turn = turn_between(&na, &nb);
            // Convex: each patch's normal leans away from the other patch; concave: towards.
            let (lean_a, lean_b) = (nb.dot(&into_a), na.dot(&into_b));
            let convex = lean_a < 0.0 && lean_b < 0.0;
            let concave = lean_a > 0.0 && lean_b > 0.0;
            let c = Column {
                s: t,
                uv_b: uvb,
                turn,
                convex,
            };
            Some((c, turn > min_turn && (convex || concave)))
        };
        // Most seams are smooth: a few places along first, where a crease would turn the
        // normal by over half the least turn.
        let probes = (0..=CREASE_PROBES).map(|j| j as f64 / CREASE_PROBES as f64);
        if !probes
            .filter_map(column)
            .any(|(c, _)| c.turn > 0.5 * min_turn)
        {
            continue;
        }
        let cols: Vec<Option<Column>> = lines(a, sa)
            .iter()
            .map(|&t| column(t).and_then(|(c, crease)| crease.then_some(c)))
            .collect();
        // Runs of columns of one kind.
        let mut runs: Vec<Vec<Column>> = Vec::new();
        let mut run: Vec<Column> = Vec::new();
        for c in cols.iter().chain([&None]) {
            match c {
                Some(c) if run.last().is_none_or(|l| l.convex == c.convex) => run.push(*c),
                _ => {
                    runs.push(std::mem::take(&mut run));
                    run.extend(*c);
                }
            }
        }
        for run in runs.into_iter().filter(|run| run.len() >= 2) {
            let convex = run[0].convex;
            let widest = run.iter().map(|c| c.turn).fold(0.0, f64::max);
            let rows = if convex {
                ((widest / turn_step).ceil() as usize).clamp(1, MAX_PIVOT_ROWS)
            } else {
                0
            };
            out.push((
                Strip {
                    convex,
                    a,
                    side: sa,
                    b,
                    side_b: sb,
                    cols: run.iter().map(|c| (c.s, c.uv_b)).collect(),
                },
                rows,
            ));
        }
    }
    out
}

impl ClMesh {
    /// The CL mesh of `model` for a ball of radius `r` (mm) within chordal tolerance
    /// `chordal_mm` of the true offset surface.
    pub fn new(model: &Model, r: f64, chordal_mm: f64, max_cell_mm: f64) -> Result<Self> {
        Self::build(model, r, chordal_mm, max_cell_mm, None)
    }

    /// [`ClMesh::new`], handing each patch grid vertex's index and the surface's derivatives
    /// there (in the patch's parameters) to `each` as the vertex is made (the pivot strips'
    /// vertices, made last, are not handed over): one evaluation serves
    /// the mesh and a caller that needs the curvature at every vertex. The mesh is the
    /// same bit for bit (the point and first derivatives equal those evaluated alone).
    pub fn new_with(
        model: &Model,
        r: f64,
        chordal_mm: f64,
        max_cell_mm: f64,
        each: VertexVisit,
    ) -> Result<Self> {
        Self::build(model, r, chordal_mm, max_cell_mm, Some(each))
    }

    fn build(
        model: &Model,
        r: f64,
        chordal_mm: f64,
        max_cell_mm: f64,
        mut each: Option<VertexVisit>,
    ) -> Result<Self> {
        let side = model.tool_side();
        let surface = &model.surface;
        let layout = &model.layout;
        // Each patch's grid lines, placed by the density its samples ask for: the
        // parameter speed over the chord the offset's curvature allows, the worst across
        // the other direction.
        let (densities, tight): (Vec<_>, Vec<_>) = layout
            .patches
            .iter()
            .map(|patch| density(patch, surface, side, r, chordal_mm, max_cell_mm))
            .unzip();
        let lines = |scale: f64| -> Vec<[Vec<f64>; 2]> {
            densities.iter().map(|d| grid_lines(d, scale)).collect()
        };
        let mut breaks = lines(1.0);
        let total: usize = breaks.iter().map(|[u, v]| u.len() * v.len()).sum();
        if total > MAX_VERTICES {
            // Coarsened evenly: the same density, scaled down.
            breaks = lines((MAX_VERTICES as f64 / total as f64).sqrt());
        } else {
            // Cells checked against the offset near tight convex spots.
            for ((patch, lines), tight) in layout.patches.iter().zip(&mut breaks).zip(&tight) {
                for dir in 0..2 {
                    if tight[dir].iter().any(|&t| t) {
                        lines[dir] = refine_lines(
                            patch,
                            surface,
                            side,
                            r,
                            chordal_mm,
                            dir,
                            &lines[dir],
                            &tight[dir],
                        );
                    }
                }
            }
        }
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        let mut patches = Vec::with_capacity(breaks.len());
        for (pi, (patch, [us, vs])) in layout.patches.iter().zip(&breaks).enumerate() {
            let first = vertices.len() as u32;
            let (nu, nv) = (us.len() - 1, vs.len() - 1);
            patches.push((first, [nu, nv]));
            for &v in vs {
                for &u in us {
                    let uv = [u, v];
                    let (cc, n) = match each.as_deref_mut() {
                        Some(f) => {
                            let (d, n) = patch.derivs_normal(surface, uv[0], uv[1]);
                            f(vertices.len(), &d);
                            (d.point, n)
                        }
                        None => patch.point_normal(surface, uv[0], uv[1]),
                    };
                    vertices.push(n.map(|n| {
                        let normal = n * side;
                        ClVertex {
                            patch: pi as u32,
                            uv,
                            cc,
                            normal,
                            cl: cc + normal * r,
                        }
                    }));
                }
            }
            grid_triangles(first, nu, nv, &mut triangles);
        }
        // Pivot strips along the creases, after the patches.
        let views = crate::plan::isoparametric::patch_views(model);
        let shared = crate::plan::isfc::shared_sides(model, &views);
        let mut strips = Vec::new();
        for (strip, rows) in pivot_strips(model, &shared, &breaks, r, chordal_mm, max_cell_mm) {
            let first = vertices.len() as u32;
            let pi = (layout.patches.len() + strips.len()) as u32;
            let (nu, nv) = (strip.cols.len() - 1, rows);
            patches.push((first, [nu, nv]));
            for j in 0..=nv {
                let k = if nv == 0 { 0.5 } else { j as f64 / nv as f64 };
                for &(s, _) in &strip.cols {
                    let uv = [s, k];
                    vertices.push(strip.at(model, uv).map(|(cc, normal)| ClVertex {
                        patch: pi,
                        uv,
                        cc,
                        normal,
                        cl: cc + normal * r,
                    }));
                }
            }
            grid_triangles(first, nu, nv, &mut triangles);
            strips.push(strip);
        }
        // Triangles through a singular vertex are dropped (their neighbours' slices end there).
        triangles.retain(|t| t.iter().all(|&v| vertices[v as usize].is_some()));
        if triangles.is_empty() {
            return Err(Error::Degenerate {
                location: "CL surface".into(),
                message: "the surface has no tangent plane anywhere the mesh samples it".into(),
            });
        }
        Ok(ClMesh {
            vertices,
            triangles,
            patches,
            strips,
            shared,
        })
    }

    /// The pivot strip that `patch` (a vertex's or a slice point's) numbers, if it is one.
    pub fn strip(&self, patch: u32) -> Option<&Strip> {
        let first = self.patches.len() - self.strips.len();
        (patch as usize).checked_sub(first).map(|k| &self.strips[k])
    }

    /// Vertex `i` (which the triangles only name where it exists).
    pub fn vertex(&self, i: u32) -> &ClVertex {
        self.vertices[i as usize]
            .as_ref()
            .expect("triangles name existing vertices")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density's integral over `[a, b]` (piecewise constant per interval).
    fn integral(d: &[f64], a: f64, b: f64) -> f64 {
        let w = 1.0 / d.len() as f64;
        d.iter()
            .enumerate()
            .map(|(i, &c)| {
                let (lo, hi) = (i as f64 * w, (i + 1) as f64 * w);
                c * (hi.min(b) - lo.max(a)).max(0.0)
            })
            .sum()
    }

    #[test]
    fn the_pivot_normal_turns_evenly_from_one_normal_to_the_other() {
        let na = Vector3::new(-0.4, 0.0, 1.0).normalize();
        let nb = Vector3::new(0.7, -0.2, 0.5).normalize();
        let turn = na.cross(&nb).norm().atan2(na.dot(&nb));
        assert_eq!(pivot_normal(&na, &nb, 0.0), na);
        assert_eq!(pivot_normal(&na, &nb, 1.0), nb);
        for i in 1..10 {
            let k = i as f64 / 10.0;
            let n = pivot_normal(&na, &nb, k);
            assert!((n.norm() - 1.0).abs() < 1e-12);
            // In the plane of the two, k of the way round from one and 1 − k from the other.
            assert!(n.dot(&na.cross(&nb)).abs() < 1e-12);
            let from = |m: &Vector3| n.cross(m).norm().atan2(n.dot(m));
            assert!((from(&na) - k * turn).abs() < 1e-12);
            assert!((from(&nb) - (1.0 - k) * turn).abs() < 1e-12);
        }
        // Equal normals stay put.
        assert!((pivot_normal(&na, &na, 0.5) - na).norm() < 1e-15);
    }

    #[test]
    fn grid_lines_split_the_density_into_equal_shares() {
        // A peak in the middle, a flat stretch of zero, and an even density.
        let peaked: Vec<f64> = (0..32)
            .map(|i| {
                if (12..16).contains(&i) {
                    400.0
                } else if i < 4 {
                    0.0
                } else {
                    10.0
                }
            })
            .collect();
        let even = vec![37.0; 32];
        let [u, v] = grid_lines(&[peaked.clone(), even.clone()], 1.0);
        for (lines, d) in [(&u, &peaked), (&v, &even)] {
            let total = integral(d, 0.0, 1.0);
            let n = lines.len() - 1;
            assert_eq!(n, total.ceil() as usize);
            assert_eq!((lines[0], lines[n]), (0.0, 1.0));
            for w in lines.windows(2) {
                assert!(w[1] > w[0], "{w:?}");
                // Each cell holds an equal share of the integral, so at most one cell.
                let share = integral(d, w[0], w[1]);
                assert!((share - total / n as f64).abs() < 1e-9 * total, "{share}");
            }
        }
        // An even density gives evenly spaced lines.
        for (i, x) in v.iter().enumerate() {
            assert!((x - i as f64 / (v.len() - 1) as f64).abs() < 1e-12);
        }
        // Nothing asked: the fewest cells, evenly; over the most: the most.
        assert_eq!(
            grid_lines(&[vec![0.0; 32], vec![0.0; 32]], 1.0)[0],
            vec![0.0, 0.5, 1.0]
        );
        assert_eq!(
            grid_lines(&[vec![1e6; 32], even], 1.0)[0].len(),
            MAX_CELLS + 1
        );
    }
}
