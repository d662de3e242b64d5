//! What the tool cannot reach, and the path without it.
//!
//! A cut point is left out when no tool axis the machine allows both comes from the side
//! the surface faces and keeps the shank and holder clear, or when the tool cannot leave or
//! reach it through the air; it is kept but leaves rest material where the surface is
//! tighter than the ball. The cuts are split where points are left out (the tool retracts
//! and comes down again beyond them), and the footprints of the points left out, merged
//! into connected regions per patch, are the rest area: what a smaller tool or another
//! set-up must finish.
//!
//! Owns: the reasons, the split, the rest regions. Must not: choose axes or route air moves.

use super::draft::{Draft, Footprint, Footprints};
use super::toolpath::{Move, MoveKind, PatchRun, Toolpath};
use crate::error::Result;
use crate::geom::{Point3, Vector3};
use crate::model::Model;
use crate::surface::diffgeom::unit_normal;
use crate::verify::capsule::Capsule;
use crate::verify::index::CapsuleIndex;
use crate::verify::probe::{Material, Probe, Reading};
use crate::verify::CutterPath;
use serde::{Deserialize, Serialize};

/// Why a part of the surface is not machined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Why {
    /// The surface faces away from every tool axis the machine allows (three-axis: from
    /// +Z; the tool would come from behind it).
    FacesAway,
    /// Every allowed axis puts the shank or holder into the model.
    ToolHits,
    /// The surface is tighter than the ball (a concave radius below the tool radius, a
    /// concave crease or corner): the ball, lifted clear, leaves more than the scallop.
    TooTight,
    /// No clear way for the ball from the safe plane to the point or back.
    NoWayOut,
}

impl Why {
    /// What it means for the user, as a phrase.
    pub fn phrase(self) -> &'static str {
        match self {
            Why::FacesAway => "the surface faces away from every tool axis the machine allows",
            Why::ToolHits => "the shank or holder would hit the model",
            Why::TooTight => "the surface is tighter than the ball",
            Why::NoWayOut => "the ball finds no clear way there from the safe plane or back",
        }
    }
}

/// A connected part of one patch that is not machined.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RestRegion {
    pub patch: u32,
    pub why: Why,
    /// Its area (mm²): of footprints left too tight, the share measured above the scallop
    /// (see [`tight_near_lifts`]); of the others, the whole footprint.
    pub area_mm2: f64,
    /// A point of it on the surface (mm): the middle of its piece nearest its area-weighted
    /// mean.
    pub centre_mm: [f64; 3],
    /// Cut points it stands for.
    pub points: usize,
    /// The move of the final path whose contact point is nearest its middle, if any: where
    /// a viewer puts the tool to show it.
    pub near_move: Option<usize>,
}

/// The rest area of a plan.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rest {
    /// Footprints not machined, with the reason.
    pub footprints: Vec<(Footprint, Why)>,
    /// The same, merged into connected regions per patch and reason, largest first.
    pub regions: Vec<RestRegion>,
    /// Their total area (mm²).
    pub area_mm2: f64,
}

/// The draft's path without the on-surface moves flagged in `skip` (which must have one
/// entry per move): wherever moves are left out of a cut, the tool retracts to the safe
/// plane after the last one kept and comes down onto the next one kept. Air moves are
/// rebuilt the same way (straight up and down; [`super::air`] routes them afterwards).
/// Returns the path and, per move, the draft move it cuts (`u32::MAX` for air moves).
pub fn split(draft: &Draft, skip: &[Option<Why>]) -> (Toolpath, Vec<u32>) {
    let (moves, params) = (&draft.toolpath.moves, &draft.toolpath.params);
    split_taking(moves.clone(), params.clone(), draft, skip)
}

/// [`split`] with the draft's moves and params given apart (`moves`, `params`;
/// `draft.toolpath.moves` and `params` are not read): the path's are written over them, so
/// the path's largest vectors are not held twice (the draft's moves and the path's side by
/// side were the head five-axis plan's peak, 34 of 66 MB; the params' grew its wasm memory
/// by 3 MB).
pub fn split_taking(
    mut moves: Vec<Move>,
    mut params: Vec<[f64; 2]>,
    draft: &Draft,
    skip: &[Option<Why>],
) -> (Toolpath, Vec<u32>) {
    let old = &draft.toolpath;
    let n = moves.len();
    let has_params = params.len() == n;
    if !has_params {
        params = Vec::new();
    }
    // The param of kept move `k` once the kept moves are at the front.
    let param = |params: &[[f64; 2]], k: usize| params.get(k).copied().unwrap_or_default();
    // The kept moves (and their params) to the front, in order (each lands at or before
    // where it was), with the draft move each is.
    let keep = |m: &Move, i: usize| m.kind.on_surface() && skip[i].is_none();
    let mut cut: Vec<u32> = Vec::with_capacity(
        moves
            .iter()
            .enumerate()
            .filter(|&(i, m)| keep(m, i))
            .count(),
    );
    for i in 0..n {
        if keep(&moves[i], i) {
            moves[cut.len()] = moves[i];
            if has_params {
                params[cut.len()] = params[i];
            }
            cut.push(i as u32);
        }
    }
    let kept = cut.len();
    // Kept move `k` starts a cut where its draft predecessor was not kept.
    let starts = |k: usize| k == 0 || cut[k - 1] + 1 != cut[k];
    let cuts = (0..kept).filter(|&k| starts(k)).count();
    // Each cut comes down from above its first point and goes back up after its last.
    let len = kept + 2 * cuts;
    let mut origin = vec![u32::MAX; len];
    moves.truncate(kept);
    moves.reserve_exact(len - kept);
    if let Some(&filler) = moves.first() {
        moves.resize(len, filler);
    }
    if has_params {
        params.truncate(kept);
        params.reserve_exact(len - kept);
        params.resize(len, [0.0; 2]);
    }
    // From the end back, each kept move to its place, the air moves round each cut beside
    // it: the places written lie above every kept move not yet moved.
    let safe = |m: &Move, kind: MoveKind| Move {
        kind,
        cl_point: Point3::new(m.cl_point.x, m.cl_point.y, draft.safe_z),
        ..*m
    };
    let mut w = len;
    let mut put = |moves: &mut [Move], params: &mut [[f64; 2]], m: Move, q: [f64; 2], o: u32| {
        w -= 1;
        moves[w] = m;
        if has_params {
            params[w] = q;
        }
        origin[w] = o;
    };
    if kept > 0 {
        let (up, q) = (
            safe(&moves[kept - 1], MoveKind::Retract),
            param(&params, kept - 1),
        );
        put(&mut moves, &mut params, up, q, u32::MAX);
    }
    for k in (0..kept).rev() {
        let m = moves[k];
        let (i, q) = (cut[k], param(&params, k));
        if !starts(k) {
            put(&mut moves, &mut params, m, q, i);
            continue;
        }
        let plunge = Move {
            kind: MoveKind::Plunge,
            ..m
        };
        let above = safe(&m, MoveKind::Rapid);
        put(&mut moves, &mut params, plunge, q, i);
        put(&mut moves, &mut params, above, q, u32::MAX);
        if k > 0 {
            let (up, q) = (
                safe(&moves[k - 1], MoveKind::Retract),
                param(&params, k - 1),
            );
            put(&mut moves, &mut params, up, q, u32::MAX);
        }
    }
    debug_assert_eq!(w, 0);
    let runs = split_runs(&old.runs, &moves, &origin);
    (
        Toolpath {
            tool_radius_mm: old.tool_radius_mm,
            moves,
            max_predicted_scallop_mm: old.max_predicted_scallop_mm,
            runs,
            params,
        },
        origin,
    )
}

/// What the planner needs of a draft move once the path holds the moves it kept: how it
/// moves and which pass it is on (12 bytes of a move's 88).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Along {
    pub kind: MoveKind,
    pub patch: u32,
    pub line: u32,
}

impl Along {
    /// Of each move.
    pub fn of(moves: &[Move]) -> Vec<Along> {
        moves
            .iter()
            .map(|m| Along {
                kind: m.kind,
                patch: m.patch,
                line: m.line,
            })
            .collect()
    }
}

/// The draft's moves again, for another [`split_taking`] with more moves left out, from a
/// `path` it split (`origin` its origins) and `along` (of the draft's moves): each kept move
/// as the path holds it, its kind as it was; the others only stand in (their kind is theirs;
/// a split reads no more of a move it does not keep). None from a path without moves, which
/// kept none.
pub fn unsplit(path: &Toolpath, origin: &[u32], along: &[Along]) -> Vec<Move> {
    let Some(&filler) = path.moves.first() else {
        return Vec::new();
    };
    let mut moves: Vec<Move> = along
        .iter()
        .map(|a| Move {
            kind: a.kind,
            patch: a.patch,
            line: a.line,
            ..filler
        })
        .collect();
    for (m, &o) in path.moves.iter().zip(origin) {
        if let Some(d) = moves.get_mut(o as usize) {
            *d = Move { kind: d.kind, ..*m };
        }
    }
    moves
}

/// The draft's params again, as [`unsplit`] gives its moves: each kept move's from the path
/// (the others are zero: a split reads the params of the moves it keeps only).
pub fn unsplit_params(path: &Toolpath, origin: &[u32], n: usize) -> Vec<[f64; 2]> {
    if path.params.len() != path.moves.len() {
        return Vec::new();
    }
    let mut params = vec![[0.0; 2]; n];
    for (q, &o) in path.params.iter().zip(origin) {
        if let Some(d) = params.get_mut(o as usize) {
            *d = *q;
        }
    }
    params
}

/// The runs of the draft over the split path: each keeps the moves it had that were kept;
/// a run with none is dropped (its patch is all rest area). The runs follow one another
/// along the draft, so one walk over the split path finds each run's first and last kept
/// move (a search per run from the start of the path took runs × moves: the iso-planar
/// strategy's hundreds of runs on paths of tens of thousands of moves).
fn split_runs(runs: &[PatchRun], moves: &[Move], origin: &[u32]) -> Vec<PatchRun> {
    debug_assert!(runs.windows(2).all(|w| w[0].last_move < w[1].first_move));
    // First and last kept move of each run.
    let mut kept: Vec<Option<(usize, usize)>> = vec![None; runs.len()];
    for (k, &o) in origin.iter().enumerate().take(moves.len()) {
        if o == u32::MAX {
            continue;
        }
        let o = o as usize;
        let j = runs.partition_point(|r| r.last_move < o);
        if runs.get(j).is_some_and(|r| r.first_move <= o) {
            let span = kept[j].get_or_insert((k, k));
            span.1 = k;
        }
    }
    runs.iter()
        .zip(kept)
        .filter_map(|(run, kept)| {
            let (first, last) = kept?;
            // The air moves before a run's first cut belong to it, as in the draft.
            let mut start = first;
            while start > 0 && !moves[start - 1].kind.on_surface() && origin[start - 1] == u32::MAX
            {
                start -= 1;
            }
            if start > 0 && moves[start].kind == MoveKind::Retract {
                // The previous run's retract stays with the previous run.
                start += 1;
            }
            Some(PatchRun {
                first_move: start.min(first),
                last_move: last,
                retract_before: moves[first].kind == MoveKind::Plunge,
                ..*run
            })
        })
        .collect()
}

/// Samples per side of a footprint where the material left around lifted points is measured
/// (corners and sides included) before the search for its highest point. The peak between
/// two lifted balls along a pass can be narrower than a quarter of the footprint: at 5 the
/// search missed a 1.034 h cusp on face.tsm (r 0.5, h 0.01 mm); 9 holds the 5 × 5 points too.
const TIGHT_SAMPLES: usize = 9;
/// Halvings of a grid cell whose corners disagree on whether more than the scallop is left,
/// before the part above it is read off the corners' bilinear interpolant: the edge of the
/// material left is located to 1/64 of the footprint. Cells on a footprint side along a
/// crease hold a strip of rest much narrower than the cell (mouse.tsm, r 0.5 mm, h 0.01 mm:
/// the 9 × 9 samples alone counted 0.68 mm² where 200 × 200 find 0.21 mm²).
const SHARE_HALVINGS: usize = 3;
/// Points per side of the bilinear interpolant sampled in a finest cell for the share of it
/// above the scallop (no surface evaluations).
const BILINEAR_SAMPLES: usize = 8;
/// The least share of a footprint counted where more than the scallop is left in it: one
/// finest cell's worth, where only the search for the peak found it.
pub const LEAST_SHARE: f64 = 1.0 / ((TIGHT_SAMPLES - 1) << SHARE_HALVINGS).pow(2) as f64;
/// How the share of a footprint left is measured: samples per side of its first grid and
/// halvings of the cells whose corners disagree.
#[derive(Debug, Clone, Copy)]
struct ShareGrid {
    samples: usize,
    halvings: usize,
}
/// Footprints kept but left too tight: the material left peaks between passes, so the grid
/// is the one that found the peak; the edge is located to 1/64 of the footprint.
const TIGHT_GRID: ShareGrid = ShareGrid {
    samples: TIGHT_SAMPLES,
    halvings: SHARE_HALVINGS,
};
/// Footprints of points left out: left whole but for the strips the balls beside them cut,
/// which run in from the footprint's sides, so a coarse grid finds them; their edge, smooth
/// at this scale, is located to 1/8 of the footprint (gearbox2-9.tsm three-axis, r 1 mm,
/// h 0.05 mm: 990.75 mm² against 989.80 mm² at 1/32 and 989.64 mm² simulated at 8 M
/// samples; 70 ms against 170 ms).
const LEFT_OUT_GRID: ShareGrid = ShareGrid {
    samples: 3,
    halvings: 2,
};
/// What a swept point reads in the grid and pattern search for the highest material left
/// in a footprint (mm): its measured value would be the cut's depth below the surface, at
/// most 0, and those searches compare a point's value only with values above
/// [`TIGHT_SEARCH_FROM`] times the scallop and with the scallop, so any value not above 0
/// decides the same.
const SWEPT_OVER: f64 = 0.0;
/// Halvings of the pattern search for the highest material left in a footprint: it starts
/// at half the grid step and ends at 1/1024 of the footprint.
const TIGHT_SEARCH_HALVINGS: usize = 9;
/// Most grid peaks the pattern search starts from (peaks may be several).
const TIGHT_SEARCH_STARTS: usize = 3;
/// Grid peaks lower than this share of the scallop are not searched further: a peak of the
/// material left is a cusp whose height its neighbourhood shows within a cell.
const TIGHT_SEARCH_FROM: f64 = 0.6;
/// Samples along a footprint side on the patch boundary before refining the highest.
const EDGE_SAMPLES: usize = 17;
/// Golden-section steps refining the highest material along such a side.
const EDGE_REFINE_STEPS: usize = 24;
/// Relative slack on whether two footprints' spheres meet (dimensionless).
const TOUCH_SLACK: f64 = 0.05;
/// A footprint's focus ball ([`Probe::focus`]) round its contact point, as a multiple of
/// the distance to its farthest corner (dimensionless): room for a surface bulging between
/// the corners; a sample outside it is measured through the index all the same.
const FOCUS_GROWTH: f64 = 1.25;
/// The pattern search's directions (steps in `u` and `v`).
const PATTERN: [(f64, f64); 8] = [
    (1.0, 0.0),
    (-1.0, 0.0),
    (0.0, 1.0),
    (0.0, -1.0),
    (1.0, 1.0),
    (-1.0, -1.0),
    (1.0, -1.0),
    (-1.0, 1.0),
];

/// Footprints measured between two progress reports (and checks for cancellation).
const PROGRESS_EVERY: usize = 32;
/// Cut points looked at between two checks for cancellation while finding those near lifted
/// ones.
const CANCEL_EVERY: usize = 4096;
/// Most lifted points a cut point is compared with on average in a grid of cells a reach
/// wide before a finer grid is used (where many lifted balls leave wide footprints).
const COARSE_WORK_PER_MOVE: usize = 64;
/// The finer grid's cells: twice the median footprint reach of the lifted points, and no
/// fewer than 1/this of the reach (so one footprint spans a bounded number of cells).
const FINE_CELLS_PER_REACH: f64 = 32.0;
/// Relative widening of a footprint sphere's box in the finer grid, so that rounding cannot
/// keep two spheres that meet out of a shared cell (dimensionless).
const ROUNDING_WIDENING: f64 = 1e-9;

/// Points listed in the cells of a hash grid, each with a radius (mm): every cell within its
/// radius of a point lists it.
struct PointGrid {
    points: Vec<Point3>,
    radii: Vec<f64>,
    /// Edge of a cell (mm).
    cell: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl PointGrid {
    /// Lists `points` in cells `cell` mm wide (positive), each in its own cell and the 26
    /// round it: its radius is a cell's size.
    fn new(points: Vec<Point3>, cell: f64) -> Self {
        let mut grid = PointGrid {
            radii: vec![cell; points.len()],
            points,
            cell,
            cells: Default::default(),
        };
        for k in 0..grid.points.len() {
            let c = grid.key(&grid.points[k]);
            for x in c[0] - 1..=c[0] + 1 {
                for y in c[1] - 1..=c[1] + 1 {
                    for z in c[2] - 1..=c[2] + 1 {
                        grid.cells.entry([x, y, z]).or_default().push(k as u32);
                    }
                }
            }
        }
        grid
    }

    /// Lists `points` with their `radii` (mm) in cells `cell` mm wide (positive): each in the
    /// cells its ball's box meets (widened a little for rounding).
    fn with_radii(points: Vec<Point3>, radii: Vec<f64>, cell: f64) -> Self {
        let mut grid = PointGrid {
            points,
            radii,
            cell,
            cells: Default::default(),
        };
        for k in 0..grid.points.len() {
            let at: Vec<[i64; 3]> = grid
                .box_cells(&grid.points[k], grid.radii[k] * (1.0 + ROUNDING_WIDENING))
                .collect();
            for c in at {
                grid.cells.entry(c).or_default().push(k as u32);
            }
        }
        grid
    }

    fn key(&self, p: &Point3) -> [i64; 3] {
        [p.x, p.y, p.z].map(|x| (x / self.cell).floor() as i64)
    }

    /// The cells the box from `lo` to `hi` meets.
    fn cells_between(&self, lo: &Point3, hi: &Point3) -> impl Iterator<Item = [i64; 3]> {
        let (lo, hi) = (self.key(lo), self.key(hi));
        (lo[0]..=hi[0]).flat_map(move |x| {
            (lo[1]..=hi[1]).flat_map(move |y| (lo[2]..=hi[2]).map(move |z| [x, y, z]))
        })
    }

    /// The cells the box of the ball of radius `r` round `c` meets.
    fn box_cells(&self, c: &Point3, r: f64) -> impl Iterator<Item = [i64; 3]> {
        let g = Vector3::repeat(r);
        self.cells_between(&(c - g), &(c + g))
    }

    /// The points listed in cell `at`, by index.
    fn in_cell(&self, at: &[i64; 3]) -> &[u32] {
        self.cells.get(at).map_or(&[], Vec::as_slice)
    }

    /// The point with index `k`.
    fn point(&self, k: u32) -> &Point3 {
        &self.points[k as usize]
    }

    /// The points listed in the cell of `p` (every one within its radius of it, and maybe
    /// others), by index.
    fn listed(&self, p: &Point3) -> &[u32] {
        self.in_cell(&self.key(p))
    }

    /// Whether a point lies within its radius of the segment of move `c`: such a point is
    /// listed in the cell of the segment's nearest point, which lies in the segment's box;
    /// where that box spans more cells than there are points, each point is tested instead.
    fn any_within(&self, c: &Capsule) -> bool {
        let (a, b) = (c.start, c.end());
        let near = |k: usize| {
            let p = &self.points[k];
            (c.closest_on_axis(p) - p).norm_squared() <= self.radii[k] * self.radii[k]
        };
        let (lo, hi) = (a.inf(&b), a.sup(&b));
        let (klo, khi) = (self.key(&lo), self.key(&hi));
        let span = (0..3).fold(1u64, |n, k| {
            n.saturating_mul(khi[k].abs_diff(klo[k]).saturating_add(1))
        });
        if span > self.points.len() as u64 {
            return (0..self.points.len()).any(near);
        }
        self.cells_between(&lo, &hi)
            .any(|at| self.in_cell(&at).iter().any(|&k| near(k as usize)))
    }
}

/// The cut points whose footprints may touch a lifted point's, each with its footprint's
/// `extent` (mm): contacts within `reach` of a lifted point's contact whose footprints'
/// spheres (round the contact points, through the far corners; the lifted ones' radii
/// `lifted_extent`) meet. A hash grid of cells a reach wide lists every lifted contact in its
/// cell and the 26 around it, so a cut point needs one look-up; where that would compare each
/// cut point with many lifted ones (a ball larger than much of the model: most of its cuts
/// are lifted, some of their footprints far from their contacts), each lifted footprint's
/// sphere is listed in the cells of a finer grid its box meets, and each cut point looks in
/// the cells its own sphere's box meets (two spheres that meet have boxes that share a
/// cell). `keep_going` is asked every few thousand cut points; false cancels (`None`).
#[allow(clippy::too_many_arguments)]
fn touching_lifted(
    coarse_work_per_move: usize,
    path: &Toolpath,
    footprints: &Footprints,
    lifted: &[usize],
    lifted_extent: &[f64],
    reach: f64,
    extent: &dyn Fn(usize) -> f64,
    keep_going: &mut dyn FnMut() -> bool,
) -> Option<Vec<(usize, f64)>> {
    let contact = |k: usize| path.moves[lifted[k]].cc_point;
    let touches = |c: &Point3, own: f64, k: usize| {
        let d = (contact(k) - c).norm();
        d <= reach && d <= (own + lifted_extent[k]) * (1.0 + TOUCH_SLACK)
    };
    let cuts = || {
        path.moves
            .iter()
            .enumerate()
            .filter(|(i, m)| m.kind.on_surface() && !footprints.get(*i).is_none())
    };
    let mut out = Vec::new();
    // Each lifted contact in its cell (a reach wide) and the 26 around it.
    // The reach is at least the tool radius, which the options hold positive.
    let grid = PointGrid::new((0..lifted.len()).map(contact).collect(), reach);
    let listed = |m: &Move| grid.listed(&m.cc_point);
    let work: usize = cuts().map(|(_, m)| listed(m).len()).sum();
    if work <= coarse_work_per_move.saturating_mul(path.moves.len()) {
        for (n, (i, m)) in cuts().enumerate() {
            if n % CANCEL_EVERY == 0 && !keep_going() {
                return None;
            }
            let ks = listed(m);
            // The extent only where a lifted contact lies within reach.
            let c = m.cc_point;
            if !ks.iter().any(|&k| (grid.point(k) - c).norm() <= reach) {
                continue;
            }
            let own = extent(i);
            if ks.iter().any(|&k| touches(&c, own, k as usize)) {
                out.push((i, own));
            }
        }
        return Some(out);
    }
    drop(grid);
    // The finer grid: each lifted footprint's sphere in the cells its box meets (widened by
    // a little for rounding).
    let radius = |e: f64| e * (1.0 + TOUCH_SLACK);
    let mut spheres: Vec<f64> = lifted_extent
        .iter()
        .map(|&e| radius(e) * (1.0 + ROUNDING_WIDENING))
        .collect();
    let mid = spheres.len() / 2;
    let median = *spheres.select_nth_unstable_by(mid, f64::total_cmp).1;
    let fine = (2.0 * median).max(reach / FINE_CELLS_PER_REACH);
    let grid = PointGrid::with_radii(
        (0..lifted.len()).map(contact).collect(),
        lifted_extent.iter().map(|&e| radius(e)).collect(),
        fine,
    );
    for (n, (i, m)) in cuts().enumerate() {
        if n % CANCEL_EVERY == 0 && !keep_going() {
            return None;
        }
        let (c, own) = (m.cc_point, extent(i));
        let hit = grid
            .box_cells(&c, (radius(own) * (1.0 + ROUNDING_WIDENING)).min(reach))
            .any(|at| {
                grid.in_cell(&at)
                    .iter()
                    .any(|&k| touches(&c, own, k as usize))
            });
        if hit {
            out.push((i, own));
        }
    }
    Some(out)
}

/// Which cut points leave more than `scallop_mm` in their footprint because balls were lifted
/// near them: a ball lifted clear of a crease or a tight concave spot leaves more at its
/// contact point (`left`) and widens the cusps to the passes beside it, which the side steps
/// did not foresee. Every footprint touching a lifted point's is measured at a few points
/// with the swept balls of `path` (the draft after lifting: the cuts as moves on the surface),
/// as the cutting simulation measures them. Returns per move whether more than the scallop
/// is left in its footprint ([`shares_left`] measures how much, on the final path).
/// `progress` is told the share of the footprints measured every few dozen; false cancels
/// (`None`).
pub fn tight_near_lifts(
    model: &Model,
    path: &Toolpath,
    footprints: &Footprints,
    left: &[f64],
    scallop_mm: f64,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Option<Vec<bool>> {
    let n = path.moves.len();
    let mut tight = vec![false; n];
    let r = path.tool_radius_mm;
    let lifted: Vec<usize> = (0..n)
        .filter(|&i| left.get(i).is_some_and(|&l| l > 0.0) && path.moves[i].kind.on_surface())
        .collect();
    if lifted.is_empty() {
        return Some(tight);
    }
    // How far a footprint reaches from its contact point (mm).
    let extent = |i: usize| -> f64 {
        let f = footprints.get(i);
        if f.is_none() {
            return 0.0;
        }
        let p = &model.layout.patches[f.patch as usize];
        let [u0, u1, v0, v1] = f.rect;
        let c = path.moves[i].cc_point;
        [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
            .iter()
            .map(|&(u, v)| (p.subs(&model.surface, u, v) - c).norm())
            .fold(0.0, f64::max)
    };
    let lifted_extent: Vec<f64> = lifted.iter().map(|&i| extent(i)).collect();
    let reach = 2.0 * lifted_extent.iter().fold(0.0f64, |a, &b| a.max(b)) + r;
    let candidates = touching_lifted(
        COARSE_WORK_PER_MOVE,
        path,
        footprints,
        &lifted,
        &lifted_extent,
        reach,
        &extent,
        &mut || progress(0.0),
    )?;
    // The swept balls near the candidates, in the index's box round them: the moves that
    // come within reach of a sample's look. A sample lies within FOCUS_GROWTH times its
    // footprint's extent of the contact (as the focus takes it) and looks at most 2r along
    // its normal (the probe's reach and depth below) for balls of radius r. Where lifted
    // points lie apart, the box holds most of the path.
    let mut region = crate::geom::Aabb::empty();
    for &(i, _) in &candidates {
        region.grow(&path.moves[i].cc_point);
    }
    let grow = reach + 2.0 * r;
    let (lo, hi) = (region.min.map(|x| x - grow), region.max.map(|x| x + grow));
    let contacts = PointGrid::with_radii(
        candidates
            .iter()
            .map(|&(i, _)| path.moves[i].cc_point)
            .collect(),
        candidates
            .iter()
            .map(|&(_, own)| grow.max(FOCUS_GROWTH * own + 3.0 * r))
            .collect(),
        grow,
    );
    let meets_box =
        |a: &Point3, b: &Point3| (0..3).all(|k| a[k].min(b[k]) <= hi[k] && a[k].max(b[k]) >= lo[k]);
    let capsules: Vec<Capsule> = path
        .moves
        .windows(2)
        .filter(|w| w[1].kind.on_surface())
        .map(|w| {
            let a = if w[0].kind.on_surface() {
                w[0].cl_point
            } else {
                w[1].cl_point
            };
            Capsule::new(a, w[1].cl_point)
        })
        .filter(|c| meets_box(&c.start, &c.end()) && contacts.any_within(c))
        .collect();
    if capsules.is_empty() {
        return Some(tight);
    }
    let box_ = crate::geom::Aabb { min: lo, max: hi };
    let index = CapsuleIndex::build(&capsules, r, &box_, 0.5 * r);
    let mut probe = FootprintProbe {
        model,
        probe: Probe::new(&capsules, &index, r, 2.0 * r, 2.0 * r),
        side: model.tool_side(),
        unreached_mm: f64::NEG_INFINITY,
    };
    let near_mm = probe.probe.near_mm();
    let share = 1.0 / candidates.len().max(1) as f64;
    'footprints: for (k, (i, own)) in candidates.into_iter().enumerate() {
        if k % PROGRESS_EVERY == 0 && !progress(share * k as f64) {
            return None;
        }
        let f = footprints.get(i);
        // Every sample of the footprint tests only the balls near it.
        probe
            .probe
            .focus(&path.moves[i].cc_point, FOCUS_GROWTH * own + near_mm);
        let [u0, u1, v0, v1] = f.rect;
        // A grid, then a pattern search from its highest sample: where a crease meets the
        // cusp between two passes the material left peaks sharply.
        let (du, dv) = grid_step(&f, TIGHT_SAMPLES);
        // Any sample with more than the scallop left decides.
        let mut grid = Vec::with_capacity(TIGHT_SAMPLES * TIGHT_SAMPLES);
        for (u, v) in grid_points(&f, TIGHT_SAMPLES) {
            let over = probe.over_read(&f, u, v, scallop_mm);
            if over > scallop_mm {
                tight[i] = true;
                continue 'footprints;
            }
            grid.push((over, u, v));
        }
        // The search starts from the grid's local maxima high enough to matter, highest first.
        let at_grid = |a: usize, b: usize| grid[a * TIGHT_SAMPLES + b].0;
        let mut starts: Vec<(f64, f64, f64)> = Vec::new();
        for a in 0..TIGHT_SAMPLES {
            for b in 0..TIGHT_SAMPLES {
                let x = at_grid(a, b);
                let peak = (a.saturating_sub(1)..(a + 2).min(TIGHT_SAMPLES)).all(|p| {
                    (b.saturating_sub(1)..(b + 2).min(TIGHT_SAMPLES)).all(|q| at_grid(p, q) <= x)
                });
                if peak && x > TIGHT_SEARCH_FROM * scallop_mm {
                    starts.push(grid[a * TIGHT_SAMPLES + b]);
                }
            }
        }
        crate::sort::sort_by(&mut starts, |a, b| b.0.total_cmp(&a.0));
        let mut top = grid.iter().map(|g| g.0).fold(f64::NEG_INFINITY, f64::max);
        let focus_at = |probe: &mut FootprintProbe, (u, v): (f64, f64), (hu, hv): (f64, f64)| {
            let patch = &model.layout.patches[f.patch as usize];
            let at = |u: f64, v: f64| patch.subs(&model.surface, u.clamp(u0, u1), v.clamp(v0, v1));
            let c = at(u, v);
            let far = [(-hu, -hv), (hu, -hv), (-hu, hv), (hu, hv)]
                .iter()
                .map(|&(a, b)| (at(u + a, v + b) - c).norm())
                .fold(0.0, f64::max);
            probe.probe.focus(&c, FOCUS_GROWTH * far + near_mm);
        };
        let searched = starts.len().min(TIGHT_SEARCH_STARTS) > 0;
        for &start in starts.iter().take(TIGHT_SEARCH_STARTS) {
            let mut best = start;
            let (mut su, mut sv) = (0.5 * du, 0.5 * dv);
            // The search stays within (du, dv) of its start.
            focus_at(&mut probe, (start.1, start.2), (du, dv));
            for _ in 0..TIGHT_SEARCH_HALVINGS {
                if best.0 > scallop_mm {
                    break;
                }
                let (_, u, v) = best;
                for (a, b) in PATTERN {
                    let (x, y) = ((u + a * su).clamp(u0, u1), (v + b * sv).clamp(v0, v1));
                    let l = probe.over_read(&f, x, y, scallop_mm);
                    if l > best.0 {
                        best = (l, x, y);
                    }
                }
                (su, sv) = (0.5 * su, 0.5 * sv);
            }
            top = top.max(best.0);
            if top > scallop_mm {
                break;
            }
        }
        // Along the footprint's sides on the patch boundary (where pass ends meet a crease,
        // the cusp between two lifted ends peaks within a sliver of the boundary line).
        if top <= scallop_mm {
            if searched {
                probe
                    .probe
                    .focus(&path.moves[i].cc_point, FOCUS_GROWTH * own + near_mm);
            }
            let mut left_at = |u: f64, v: f64| probe.sample(&f, u, v).over;
            let sides = [
                (u0 <= 0.0, (u0, v0), (u0, v1)),
                (u1 >= 1.0, (u1, v0), (u1, v1)),
                (v0 <= 0.0, (u0, v0), (u1, v0)),
                (v1 >= 1.0, (u0, v1), (u1, v1)),
            ];
            for (on_boundary, a, b) in sides {
                if !on_boundary || top > scallop_mm {
                    continue;
                }
                let at_x = |x: f64| (a.0 + (b.0 - a.0) * x, a.1 + (b.1 - a.1) * x);
                let n = EDGE_SAMPLES - 1;
                let mut best = (f64::NEG_INFINITY, 0usize);
                for k in 0..=n {
                    let (u, v) = at_x(k as f64 / n as f64);
                    let l = left_at(u, v);
                    if l > scallop_mm {
                        tight[i] = true;
                        continue 'footprints;
                    }
                    if l > best.0 {
                        best = (l, k);
                    }
                }
                // Golden-section search between the best sample's neighbours.
                let (mut lo, mut hi) = (
                    best.1.saturating_sub(1) as f64 / n as f64,
                    (best.1 + 1).min(n) as f64 / n as f64,
                );
                let phi = 0.5 * (5f64.sqrt() - 1.0);
                let f = |x: f64, left_at: &mut dyn FnMut(f64, f64) -> f64| {
                    let (u, v) = at_x(x);
                    left_at(u, v)
                };
                let (mut x1, mut x2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
                let (mut f1, mut f2) = (f(x1, &mut left_at), f(x2, &mut left_at));
                for _ in 0..EDGE_REFINE_STEPS {
                    if f1 < f2 {
                        lo = x1;
                        (x1, f1) = (x2, f2);
                        x2 = lo + phi * (hi - lo);
                        f2 = f(x2, &mut left_at);
                    } else {
                        hi = x2;
                        (x2, f2) = (x1, f1);
                        x1 = hi - phi * (hi - lo);
                        f1 = f(x1, &mut left_at);
                    }
                    if f1.max(f2) > scallop_mm {
                        tight[i] = true;
                        continue 'footprints;
                    }
                }
                top = top.max(best.0).max(f1).max(f2);
            }
        }
        tight[i] = top > scallop_mm;
    }
    Some(tight)
}

/// Measures the material swept balls leave at points of footprints.
struct FootprintProbe<'a> {
    model: &'a Model,
    probe: Probe<'a>,
    /// The tool side of the surface normal (±1).
    side: f64,
    /// The material counted where no ball comes near (mm).
    unreached_mm: f64,
}

impl FootprintProbe<'_> {
    /// The surface point at `(u, v)` (clamped into footprint `f`), the area element there
    /// (mm² per unit of u and v) and the tool-side unit normal, if the surface has one.
    fn surface_at(&self, f: &Footprint, u: f64, v: f64) -> (Point3, f64, Option<Vector3>) {
        let [u0, u1, v0, v1] = f.rect;
        let (u, v) = (u.clamp(u0, u1), v.clamp(v0, v1));
        let (model, p) = (self.model, &self.model.layout.patches[f.patch as usize]);
        let (point, su, sv) = p.first_derivs(&model.surface, u, v);
        let area = su.cross(&sv).norm();
        let nrm = unit_normal(&su, &sv).or_else(|| p.normal(&model.surface, u, v));
        (point, area, nrm.map(|n| n * self.side))
    }

    /// The material left at `(u, v)` (clamped into footprint `f`) above the surface, and
    /// the area element there (mm² per unit of u and v); −∞ left where the surface has no
    /// normal.
    fn sample(&mut self, f: &Footprint, u: f64, v: f64) -> Corner {
        let (point, area, nrm) = self.surface_at(f, u, v);
        let over = match nrm.map(|n| self.probe.measure(&point, &n)) {
            None => f64::NEG_INFINITY,
            Some(Material::Left { left_mm, .. }) => left_mm,
            Some(Material::Unreached) => self.unreached_mm,
        };
        Corner { over, area }
    }

    /// As [`FootprintProbe::sample`]'s `over`, read against `scallop_mm`
    /// ([`Probe::read_against`]): a swept point reads [`SWEPT_OVER`] instead of how deep,
    /// and a point with more than the scallop left may read +∞ instead of how much.
    fn over_read(&mut self, f: &Footprint, u: f64, v: f64, scallop_mm: f64) -> f64 {
        let (point, _, nrm) = self.surface_at(f, u, v);
        let Some(n) = nrm else {
            return f64::NEG_INFINITY;
        };
        match self.probe.read_against(&point, &n, scallop_mm) {
            Reading::Swept => SWEPT_OVER,
            Reading::Left(left_mm) => left_mm,
            Reading::Over => f64::INFINITY,
            Reading::Unreached => self.unreached_mm,
        }
    }

    /// A grid of `n`² samples of `f` (corners included, row by row in u): the material left
    /// as `over` (mm), and where.
    fn grid(&mut self, f: &Footprint, n: usize) -> Vec<(Corner, f64, f64)> {
        grid_points(f, n)
            .map(|(u, v)| (self.sample(f, u, v), u, v))
            .collect()
    }
}

/// The `n`² points of a grid over footprint `f` (corners included, row by row in u).
fn grid_points(f: &Footprint, n: usize) -> impl Iterator<Item = (f64, f64)> {
    let (du, dv) = grid_step(f, n);
    let (u0, v0) = (f.rect[0], f.rect[2]);
    (0..n).flat_map(move |a| (0..n).map(move |b| (u0 + du * a as f64, v0 + dv * b as f64)))
}

/// The share of each footprint's area that `path` (the final tool path, air moves
/// included) leaves more than `scallop_mm` on, as the cutting simulation measures it: what
/// no ball comes near counts as left. The edge of that part is located to 1/64 of a tight
/// footprint, 1/8 of a left-out one (see [`Cell::area_over`]); a footprint is counted with at least
/// [`LEAST_SHARE`]. Left-out points' footprints are partly cut by the passes beside them
/// (gearbox2-9.tsm three-axis, r 1 mm, h 0.05 mm: 1 073 mm² of whole footprints, 991 mm²
/// simulated uncut).
pub fn shares_left(
    model: &Model,
    path: &Toolpath,
    footprints: &[(Footprint, Why)],
    scallop_mm: f64,
) -> Result<Vec<f64>> {
    if footprints.iter().all(|f| f.0.is_none()) {
        return Ok(vec![0.0; footprints.len()]);
    }
    let r = path.tool_radius_mm;
    let mut region = crate::geom::Aabb::empty();
    for (f, _) in footprints.iter().filter(|f| !f.0.is_none()) {
        let p = &model.layout.patches[f.patch as usize];
        let [u0, u1, v0, v1] = f.rect;
        for (u, v) in [(u0, v0), (u1, v0), (u0, v1), (u1, v1)] {
            region.grow(&p.subs(&model.surface, u, v));
        }
    }
    let grow = 3.0 * r;
    let (lo, hi) = (region.min.map(|x| x - grow), region.max.map(|x| x + grow));
    let inside = |p: &Point3| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]);
    // Every straight move of the path near them, as the simulation sweeps it.
    let capsules: Vec<Capsule> = CutterPath::from_toolpath(path)?
        .capsules()
        .into_iter()
        .filter(|c| inside(&c.start) || inside(&c.end()))
        .collect();
    let box_ = crate::geom::Aabb { min: lo, max: hi };
    let index = CapsuleIndex::build(&capsules, r, &box_, r);
    let mut probe = FootprintProbe {
        model,
        probe: Probe::new(&capsules, &index, r, r, 2.0 * r),
        side: model.tool_side(),
        unreached_mm: f64::INFINITY,
    };
    let near_mm = probe.probe.near_mm();
    Ok(footprints
        .iter()
        .map(|(f, why)| {
            if f.is_none() {
                return 0.0;
            }
            let grid = if *why == Why::TooTight {
                TIGHT_GRID
            } else {
                LEFT_OUT_GRID
            };
            // The samples' first looks lie round the footprint: the capsules near it listed
            // once (as the search for its peak does).
            let patch = &model.layout.patches[f.patch as usize];
            let [u0, u1, v0, v1] = f.rect;
            let c = patch.subs(&model.surface, 0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let far = [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
                .iter()
                .map(|&(u, v)| (patch.subs(&model.surface, u, v) - c).norm())
                .fold(0.0, f64::max);
            probe.probe.focus(&c, FOCUS_GROWTH * far + near_mm);
            let corners: Vec<Corner> = probe
                .grid(f, grid.samples)
                .into_iter()
                .map(|(mut c, ..)| {
                    c.over -= scallop_mm;
                    c
                })
                .collect();
            let share = share_over(f.rect, grid, &corners, &mut |u, v| {
                let mut c = probe.sample(f, u, v);
                c.over -= scallop_mm;
                c
            });
            share.max(LEAST_SHARE)
        })
        .collect())
}

/// The parameter step of a grid of `n`² samples over footprint `f`.
fn grid_step(f: &Footprint, n: usize) -> (f64, f64) {
    let [u0, u1, v0, v1] = f.rect;
    let k = (n - 1) as f64;
    ((u1 - u0) / k, (v1 - v0) / k)
}

/// The share of the footprint rectangle `rect` (`[u0, u1, v0, v1]`) where the material left
/// is above the scallop, from its grid `corners` (`grid.samples`², row by row in u) and
/// `over_at` for further samples.
fn share_over(
    rect: [f64; 4],
    grid: ShareGrid,
    corners: &[Corner],
    over_at: &mut dyn FnMut(f64, f64) -> Corner,
) -> f64 {
    let [u0, u1, v0, v1] = rect;
    let n = grid.samples;
    let k = (n - 1) as f64;
    let (du, dv) = ((u1 - u0) / k, (v1 - v0) / k);
    let at = |a: usize, b: usize| corners[a * n + b];
    let (mut above, mut all) = (0.0, 0.0);
    for a in 0..n - 1 {
        for b in 0..n - 1 {
            let cell = Cell {
                lo: [u0 + du * a as f64, v0 + dv * b as f64],
                size: [du, dv],
                corners: [at(a, b), at(a + 1, b), at(a, b + 1), at(a + 1, b + 1)],
            };
            let (x, y) = cell.area_over(over_at, grid.halvings);
            above += x;
            all += y;
        }
    }
    if all > 0.0 {
        above / all
    } else {
        0.0
    }
}

/// A sample at a cell corner: how far the material left is above the scallop (mm, negative
/// below) and the area element there (mm² per unit of u and v).
#[derive(Debug, Clone, Copy)]
struct Corner {
    over: f64,
    area: f64,
}

/// A rectangle of a footprint's parameters with its corner samples, in the order
/// `(u0, v0), (u1, v0), (u0, v1), (u1, v1)`.
struct Cell {
    lo: [f64; 2],
    size: [f64; 2],
    corners: [Corner; 4],
}

impl Cell {
    /// Its area above the scallop and its whole area (mm², the corners' mean area element
    /// times the parameter area). A cell whose corners agree is wholly above or below; one
    /// whose corners disagree is halved both ways `halvings` times (`over_at` samples the
    /// new corners), then the share of its corners' bilinear interpolant above zero is taken.
    fn area_over(
        &self,
        over_at: &mut dyn FnMut(f64, f64) -> Corner,
        halvings: usize,
    ) -> (f64, f64) {
        let c = &self.corners;
        let all = 0.25 * c.iter().map(|k| k.area).sum::<f64>() * self.size[0] * self.size[1];
        let above = c.iter().filter(|k| k.over > 0.0).count();
        if above == 0 {
            return (0.0, all);
        }
        if above == 4 {
            return (all, all);
        }
        if halvings == 0 {
            return (
                all * bilinear_share_above([c[0].over, c[1].over, c[2].over, c[3].over]),
                all,
            );
        }
        let [u, v] = self.lo;
        let [hu, hv] = self.size.map(|x| 0.5 * x);
        let bottom = over_at(u + hu, v);
        let left = over_at(u, v + hv);
        let middle = over_at(u + hu, v + hv);
        let right = over_at(u + 2.0 * hu, v + hv);
        let top = over_at(u + hu, v + 2.0 * hv);
        let quarters = [
            ([u, v], [c[0], bottom, left, middle]),
            ([u + hu, v], [bottom, c[1], middle, right]),
            ([u, v + hv], [left, middle, c[2], top]),
            ([u + hu, v + hv], [middle, right, top, c[3]]),
        ];
        quarters.iter().fold((0.0, 0.0), |(x, y), &(lo, corners)| {
            let (a, b) = Cell {
                lo,
                size: [hu, hv],
                corners,
            }
            .area_over(over_at, halvings - 1);
            (x + a, y + b)
        })
    }
}

/// The share of the unit square where the bilinear interpolant of corner values `f`
/// (`f00, f10, f01, f11`) is positive, from a grid of its midpoints.
fn bilinear_share_above(f: [f64; 4]) -> f64 {
    let n = BILINEAR_SAMPLES;
    let mut count = 0;
    for a in 0..n {
        for b in 0..n {
            let (x, y) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
            let value = f[0] * (1.0 - x) * (1.0 - y)
                + f[1] * x * (1.0 - y)
                + f[2] * (1.0 - x) * y
                + f[3] * x * y;
            count += usize::from(value > 0.0);
        }
    }
    count as f64 / (n * n) as f64
}

/// Relative size below which two footprint edges touch.
const TOUCH_REL: f64 = 1e-9;

/// Union–find over footprints.
struct Sets(Vec<usize>);

impl Sets {
    fn find(&mut self, mut a: usize) -> usize {
        while self.0[a] != a {
            self.0[a] = self.0[self.0[a]];
            a = self.0[a];
        }
        a
    }
    fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            // The smaller index stays the root: the result does not depend on the order of
            // the joins.
            let (lo, hi) = (a.min(b), a.max(b));
            self.0[hi] = lo;
        }
    }
}

/// The parts of kept points' footprints the ball does not sweep. Where a cut stops because
/// the next point along it is left out, the ball ends at the kept point, so the half of its
/// footprint towards the left-out point (which the feed on to that point would have cut) is
/// rest area too, with that point's reason: over it the ball's sphere alone leaves material
/// growing with the distance from the point (head, three-axis, r 0.5 mm: 0.17 mm at the far
/// corner of such a half, for a 0.05 mm scallop).
///
/// Of the `path` as [`split_taking`] left it with `origin`: `footprints`, `along` ([`Along::of`]
/// the draft's moves) and `skip` have one entry per draft move, `left_out` the params of the
/// on-surface draft moves `skip` leaves out, by draft index (ascending).
pub fn cut_end_halves(
    path: &Toolpath,
    origin: &[u32],
    footprints: &Footprints,
    along: &[Along],
    skip: &[Option<Why>],
    left_out: &[(u32, [f64; 2])],
) -> Vec<(Footprint, Why)> {
    if path.params.len() != path.moves.len() || skip.len() != along.len() {
        return Vec::new();
    }
    let mut out = Vec::new();
    // The kept moves, in draft order.
    for (&o, &p) in origin.iter().zip(&path.params) {
        let i = o as usize;
        let Some(m) = along.get(i) else {
            continue;
        };
        let fp = footprints.get(i);
        if skip[i].is_some() || !m.kind.on_surface() || fp.is_none() {
            continue;
        }
        for j in [i.wrapping_sub(1), i + 1] {
            let (Some(n), Some(Some(why))) = (along.get(j), skip.get(j)) else {
                continue;
            };
            // Only the neighbour along the same pass (links between passes stand for no area).
            if !n.kind.on_surface()
                || n.patch != m.patch
                || n.line != m.line
                || footprints.get(j).is_none()
            {
                continue;
            }
            let Ok(at) = left_out.binary_search_by_key(&(j as u32), |l| l.0) else {
                debug_assert!(false, "left-out move {j} without its params");
                continue;
            };
            let half = half_towards(&fp, p, left_out[at].1);
            if !half.is_none() {
                out.push((half, *why));
            }
        }
    }
    out
}

/// The params of the on-surface draft moves `skip` leaves out, by draft index (ascending), as
/// [`cut_end_halves`] needs them: none where the draft has no params. `along` is
/// [`Along::of`] the draft's moves.
pub fn left_out_params(
    params: &[[f64; 2]],
    along: &[Along],
    skip: &[Option<Why>],
) -> Vec<(u32, [f64; 2])> {
    if params.len() != along.len() {
        return Vec::new();
    }
    (0..params.len())
        .filter(|&i| skip[i].is_some() && along[i].kind.on_surface())
        .map(|i| (i as u32, params[i]))
        .collect()
}

/// The half of footprint `fp` of a point at params `p` towards a neighbour at `q` along its
/// pass: cut at `p` across the parameter in which the neighbour lies farther.
fn half_towards(fp: &Footprint, p: [f64; 2], q: [f64; 2]) -> Footprint {
    let [u0, u1, v0, v1] = fp.rect;
    let rect = if (q[0] - p[0]).abs() >= (q[1] - p[1]).abs() {
        let pu = p[0].clamp(u0, u1);
        if q[0] < p[0] {
            [u0, pu, v0, v1]
        } else {
            [pu, u1, v0, v1]
        }
    } else {
        let pv = p[1].clamp(v0, v1);
        if q[1] < p[1] {
            [u0, u1, v0, pv]
        } else {
            [u0, u1, pv, v1]
        }
    };
    Footprint {
        patch: fp.patch,
        rect,
    }
}

/// The rest area of `footprints` — the first `points` of them cut points left out or kept
/// but leaving too much, the others parts of kept points' footprints (see
/// [`cut_end_halves`]: area, but no cut points of their own) — each counting `shares` of its
/// area ([`shares_left`]), on `model`, its regions located against the final `path`.
pub fn rest(
    model: &Model,
    footprints: Vec<(Footprint, Why)>,
    shares: Vec<f64>,
    points: usize,
    path: &Toolpath,
) -> Rest {
    let ((fps, share), is_point): ((Vec<_>, Vec<f64>), Vec<bool>) = footprints
        .into_iter()
        .zip(shares)
        .enumerate()
        .filter(|(_, (f, _))| !f.0.is_none())
        .map(|(k, (f, s))| ((f, s), k < points))
        .unzip();
    let n = fps.len();
    let mut sets = Sets((0..n).collect());
    // Footprints of one patch and reason touching each other join: bucketed by patch and
    // reason, then swept in u.
    let mut order: Vec<usize> = (0..n).collect();
    crate::sort::sort_by(&mut order, |&a, &b| {
        (fps[a].0.patch, fps[a].1)
            .cmp(&(fps[b].0.patch, fps[b].1))
            .then(fps[a].0.rect[0].total_cmp(&fps[b].0.rect[0]))
    });
    let mut k = 0;
    while k < n {
        let key = (fps[order[k]].0.patch, fps[order[k]].1);
        let mut end = k;
        while end < n && (fps[order[end]].0.patch, fps[order[end]].1) == key {
            end += 1;
        }
        let group = &order[k..end];
        // Sweep: footprints sorted by u0; a later one can touch an earlier one only while
        // its u0 is within that one's u1.
        let mut active: Vec<usize> = Vec::new();
        for &a in group {
            let ra = fps[a].0.rect;
            let eps = TOUCH_REL * (1.0 + ra[1].abs());
            active.retain(|&b| fps[b].0.rect[1] + eps >= ra[0]);
            for &b in &active {
                let rb = fps[b].0.rect;
                if ra[2] <= rb[3] + eps && rb[2] <= ra[3] + eps {
                    sets.join(a, b);
                }
            }
            active.push(a);
        }
        k = end;
    }
    // Sum each set.
    let mut index_of_root: Vec<usize> = vec![usize::MAX; n];
    let mut acc: Vec<(u32, Why, f64, [f64; 3], usize)> = Vec::new();
    let mut total = 0.0;
    let centres: Vec<Point3> = fps.iter().map(|(f, _)| f.centre(model)).collect();
    let mut members: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        let root = sets.find(i);
        if index_of_root[root] == usize::MAX {
            index_of_root[root] = acc.len();
            acc.push((fps[i].0.patch, fps[i].1, 0.0, [0.0; 3], 0));
            members.push(Vec::new());
        }
        members[index_of_root[root]].push(i);
        let a = fps[i].0.area_mm2(model) * share[i];
        let c = centres[i];
        let e = &mut acc[index_of_root[root]];
        e.2 += a;
        for (k, x) in [c.x, c.y, c.z].into_iter().enumerate() {
            e.3[k] += a * x;
        }
        e.4 += usize::from(is_point[i]);
        total += a;
    }
    let mut regions: Vec<RestRegion> = acc
        .into_iter()
        .zip(&members)
        .map(|((patch, why, area, sum, points), member)| {
            let mean = Point3::from(if area > 0.0 {
                sum.map(|s| s / area)
            } else {
                [0.0; 3]
            });
            // On the surface: the middle of the region's footprint nearest its mean (which
            // may lie off a curved region, inside the part).
            let c = member
                .iter()
                .map(|&k| centres[k])
                .min_by(|a, b| {
                    (a - mean)
                        .norm_squared()
                        .total_cmp(&(b - mean).norm_squared())
                })
                .unwrap_or(mean);
            let centre = [c.x, c.y, c.z];
            let near_move = path
                .moves
                .iter()
                .enumerate()
                .filter(|(_, m)| m.kind.on_surface())
                .min_by(|a, b| {
                    (a.1.cc_point - c)
                        .norm_squared()
                        .total_cmp(&(b.1.cc_point - c).norm_squared())
                })
                .map(|(i, _)| i);
            RestRegion {
                patch,
                why,
                area_mm2: area,
                centre_mm: centre,
                points,
                near_move,
            }
        })
        .collect();
    crate::sort::sort_by(&mut regions, |a, b| {
        b.area_mm2
            .total_cmp(&a.area_mm2)
            .then(a.patch.cmp(&b.patch))
            .then(a.why.cmp(&b.why))
    });
    Rest {
        footprints: fps,
        regions,
        area_mm2: total,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vector3;

    /// The moves near listed points are those that comparing every pair finds: 300 points
    /// in a 10 mm cube, each within a cell's size (0.7 mm), and again with a twentieth of
    /// them within up to 3.7 mm; 3 000 moves up to 0.5, 3 or 8 mm long (the 3 mm ones walk
    /// several cells, the 8 mm ones span more cells than there are points and test each
    /// point), some near a point only between their ends; both answers occur.
    #[test]
    fn point_grid_finds_the_moves_every_pair_finds() {
        let mut next = crate::testing::uniform(4_242);
        let points: Vec<Point3> = (0..300)
            .map(|_| Point3::new(10.0 * next(), 10.0 * next(), 10.0 * next()))
            .collect();
        let cell = 0.7;
        let radii: Vec<f64> = (0..points.len())
            .map(|k| {
                if k % 20 == 0 {
                    cell + 3.0 * next()
                } else {
                    cell
                }
            })
            .collect();
        let grids = [
            PointGrid::new(points.clone(), cell),
            PointGrid::with_radii(points.clone(), radii, cell),
        ];
        for grid in &grids {
            let mut next = crate::testing::uniform(99);
            let (mut yes, mut no) = (0, 0);
            for k in 0..3000 {
                let a = Point3::new(10.0 * next(), 10.0 * next(), 10.0 * next());
                let d = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                let len = match k % 10 {
                    0 => 8.0,
                    1 => 3.0,
                    _ => 0.5,
                } * next();
                let c = Capsule::new(a, a + d.normalize() * len);
                let brute = (0..points.len())
                    .any(|j| (c.closest_on_axis(&points[j]) - points[j]).norm() <= grid.radii[j]);
                assert_eq!(grid.any_within(&c), brute, "move {k}");
                if brute {
                    yes += 1;
                } else {
                    no += 1;
                }
            }
            assert!(yes > 300 && no > 300, "{yes} near, {no} not");
        }
    }

    /// The cut points found near lifted ones by the grid a reach wide and by the finer grid
    /// of footprint spheres are the same, and the same as comparing every pair: on 4 000 cut
    /// points scattered over a 20 mm cube, a fifth lifted, with footprints mostly 0.2 mm
    /// across and a few up to 6 mm (a ball lifted far from its footprint), and with the
    /// footprints all small.
    #[test]
    fn both_grids_find_the_cut_points_touching_lifted_footprints() {
        let mut next = crate::testing::uniform(12_345);
        for wide in [true, false] {
            let n = 4000;
            let moves: Vec<Move> = (0..n)
                .map(|_| {
                    let mut m = mv(MoveKind::Feed, 0.0);
                    m.cc_point = Point3::new(20.0 * next(), 20.0 * next(), 20.0 * next());
                    m
                })
                .collect();
            let extents: Vec<f64> = (0..n)
                .map(|_| {
                    let e = 0.1 + 0.1 * next();
                    if wide && next() < 0.02 {
                        6.0 * next()
                    } else {
                        e
                    }
                })
                .collect();
            let footprints: Footprints = (0..n)
                .map(|i| {
                    if i % 7 == 3 {
                        Footprint::NONE
                    } else {
                        Footprint {
                            patch: 0,
                            rect: [0.0, 1.0, 0.0, 1.0],
                        }
                    }
                })
                .collect();
            let lifted: Vec<usize> = (0..n).filter(|i| i % 5 == 0 && i % 7 != 3).collect();
            let lifted_extent: Vec<f64> = lifted.iter().map(|&i| extents[i]).collect();
            let reach = 2.0 * lifted_extent.iter().fold(0.0f64, |a, &b| a.max(b)) + 0.5;
            let path = Toolpath {
                tool_radius_mm: 0.5,
                moves,
                max_predicted_scallop_mm: 0.0,
                runs: Vec::new(),
                params: Vec::new(),
            };
            let extent = |i: usize| extents[i];
            let find = |work: usize| {
                touching_lifted(
                    work,
                    &path,
                    &footprints,
                    &lifted,
                    &lifted_extent,
                    reach,
                    &extent,
                    &mut || true,
                )
                .unwrap()
            };
            let (coarse, fine) = (find(usize::MAX), find(0));
            let every_pair: Vec<(usize, f64)> = (0..n)
                .filter(|&i| !footprints.get(i).is_none())
                .filter(|&i| {
                    lifted.iter().zip(&lifted_extent).any(|(&k, &e)| {
                        let d = (path.moves[k].cc_point - path.moves[i].cc_point).norm();
                        d <= reach && d <= (extents[i] + e) * (1.0 + TOUCH_SLACK)
                    })
                })
                .map(|i| (i, extents[i]))
                .collect();
            println!(
                "wide footprints {wide}: {} of {n} cut points touch a lifted footprint",
                every_pair.len()
            );
            assert!(every_pair.len() > 100 && every_pair.len() < n / 2);
            assert_eq!(coarse, every_pair, "the grid a reach wide");
            assert_eq!(fine, every_pair, "the finer grid");
        }
    }

    fn mv(kind: MoveKind, x: f64) -> Move {
        Move {
            kind,
            cc_point: Point3::new(x, 0.0, 0.0),
            cl_point: Point3::new(x, 0.0, 1.0),
            tool_axis: Vector3::z(),
            patch: 0,
            line: 0,
        }
    }

    /// The split as first written, move by move in path order (the second method for
    /// [`split_taking`], which works in place from the end back).
    fn split_in_order(draft: &Draft, skip: &[Option<Why>]) -> (Toolpath, Vec<u32>) {
        let old = &draft.toolpath;
        let has_params = old.params.len() == old.moves.len();
        let (mut moves, mut params, mut origin) = (Vec::new(), Vec::new(), Vec::new());
        let mut push = |moves: &mut Vec<Move>, m: Move, q: [f64; 2], o: u32| {
            moves.push(m);
            if has_params {
                params.push(q);
            }
            origin.push(o);
        };
        let up = |last: Move| Move {
            kind: MoveKind::Retract,
            cl_point: Point3::new(last.cl_point.x, last.cl_point.y, draft.safe_z),
            ..last
        };
        let mut last_q = [0.0; 2];
        let mut joined = false;
        for (i, m) in old.moves.iter().enumerate() {
            if !m.kind.on_surface() || skip[i].is_some() {
                joined = false;
                continue;
            }
            let q = old.params.get(i).copied().unwrap_or_default();
            if joined {
                push(&mut moves, *m, q, i as u32);
                last_q = q;
                continue;
            }
            if let Some(&last) = moves.last() {
                push(&mut moves, up(last), last_q, u32::MAX);
            }
            let above = Move {
                kind: MoveKind::Rapid,
                cl_point: Point3::new(m.cl_point.x, m.cl_point.y, draft.safe_z),
                ..*m
            };
            push(&mut moves, above, q, u32::MAX);
            let plunge = Move {
                kind: MoveKind::Plunge,
                ..*m
            };
            push(&mut moves, plunge, q, i as u32);
            last_q = q;
            joined = true;
        }
        if let Some(&last) = moves.last() {
            push(&mut moves, up(last), last_q, u32::MAX);
        }
        let runs = split_runs(&old.runs, &moves, &origin);
        let path = Toolpath {
            tool_radius_mm: old.tool_radius_mm,
            moves,
            max_predicted_scallop_mm: old.max_predicted_scallop_mm,
            runs,
            params,
        };
        (path, origin)
    }

    /// A draft of `n` moves of every kind in random order over two patches' runs, with
    /// random params (or none) and random points left out.
    fn random_draft(next: &mut impl FnMut() -> f64, n: usize) -> (Draft, Vec<Option<Why>>) {
        use MoveKind::*;
        let kinds = [Feed, Feed, Feed, Link, Plunge, Retract, Rapid];
        let moves: Vec<Move> = (0..n)
            .map(|i| Move {
                kind: kinds[(next() * kinds.len() as f64) as usize],
                cc_point: Point3::new(next(), next(), next()),
                cl_point: Point3::new(next(), next(), next()),
                tool_axis: Vector3::new(next(), next(), 1.0).normalize(),
                patch: (2 * i / n.max(1)) as u32,
                line: (next() * 4.0) as u32,
            })
            .collect();
        let params = if next() < 0.8 {
            (0..n).map(|_| [next(), next()]).collect()
        } else {
            Vec::new()
        };
        let run = |patch: u32, first_move: usize, last_move: usize| PatchRun {
            patch,
            start_corner: 0,
            finish_corner: 2,
            crossfeed: crate::plan::corners::Crossfeed::U,
            passes: 3,
            scallop_used_mm: 0.01,
            retract_before: true,
            first_move,
            last_move,
        };
        let half = n / 2;
        let runs = if n > 1 {
            vec![run(0, 0, half - 1), run(1, half, n - 1)]
        } else {
            Vec::new()
        };
        let share = next() * 0.5;
        let skip = (0..n)
            .map(|_| (next() < share).then_some(Why::ToolHits))
            .collect();
        let draft = Draft {
            strategy: "test",
            toolpath: Toolpath {
                tool_radius_mm: 0.5,
                moves,
                max_predicted_scallop_mm: 0.004,
                runs,
                params,
            },
            footprints: (0..n).map(|_| Footprint::NONE).collect(),
            safe_z: 10.0,
            forced_retractions: 0,
            isfc: None,
            isoplanar: None,
        };
        (draft, skip)
    }

    /// The half footprints at the cuts' ends as first written: over the draft's moves, each
    /// kept one's neighbours looked up by index with the draft's own params (the second
    /// method for [`cut_end_halves`], which walks the split path).
    fn cut_end_halves_of_draft(draft: &Draft, skip: &[Option<Why>]) -> Vec<(Footprint, Why)> {
        let (moves, params) = (&draft.toolpath.moves, &draft.toolpath.params);
        let fps = &draft.footprints;
        let along_pass = |i: usize, j: usize| {
            let (a, b) = (&moves[i], &moves[j]);
            b.kind.on_surface() && (a.patch, a.line) == (b.patch, b.line) && !fps.get(j).is_none()
        };
        let kept = |i: usize| skip[i].is_none() && moves[i].kind.on_surface();
        let mut out = Vec::new();
        for i in (0..moves.len()).filter(|&i| params.len() == moves.len() && kept(i)) {
            for j in [i.wrapping_sub(1), i + 1]
                .into_iter()
                .filter(|&j| j < moves.len())
            {
                if let (Some(why), false) = (skip[j], fps.get(i).is_none()) {
                    let half = half_towards(&fps.get(i), params[i], params[j]);
                    if along_pass(i, j) && !half.is_none() {
                        out.push((half, why));
                    }
                }
            }
        }
        out
    }

    #[test]
    fn cut_end_halves_from_the_split_path_equal_those_from_the_draft() {
        // Random drafts with footprints round their params (some none), split; then split
        // again from the path with more points left out, their params taken from the path.
        let mut next = crate::testing::uniform(0xe4d_4a1f);
        let mut halves = 0;
        for case in 0..400 {
            let n = (next() * 60.0) as usize;
            let (mut draft, skip) = random_draft(&mut next, n);
            let params = draft.toolpath.params.clone();
            draft.footprints = (0..n)
                .map(|i| match params.get(i) {
                    Some(&[u, v]) if next() < 0.9 => Footprint {
                        patch: draft.toolpath.moves[i].patch,
                        rect: [u - next(), u + next(), v - next(), v + next()],
                    },
                    _ => Footprint::NONE,
                })
                .collect();
            let along = Along::of(&draft.toolpath.moves);
            let (path, origin) = split(&draft, &skip);
            let want = cut_end_halves_of_draft(&draft, &skip);
            let left_out = left_out_params(&draft.toolpath.params, &along, &skip);
            let got = cut_end_halves(&path, &origin, &draft.footprints, &along, &skip, &left_out);
            assert_eq!(got, want, "case {case}");
            halves += want.len();
            let mut more = skip.clone();
            let mut left_out = left_out;
            for (k, &o) in origin.iter().enumerate().filter(|(_, &o)| o != u32::MAX) {
                if next() < 0.3 {
                    more[o as usize] = Some(Why::NoWayOut);
                    if let Some(&q) = path.params.get(k) {
                        left_out.push((o, q));
                    }
                }
            }
            left_out.sort_by_key(|l| l.0);
            let moves = unsplit(&path, &origin, &along);
            let params = unsplit_params(&path, &origin, n);
            let (path2, origin2) = split_taking(moves, params, &draft, &more);
            let want2 = cut_end_halves_of_draft(&draft, &more);
            let got2 = cut_end_halves(
                &path2,
                &origin2,
                &draft.footprints,
                &along,
                &more,
                &left_out,
            );
            assert_eq!(got2, want2, "case {case} again");
            halves += want2.len();
        }
        assert!(halves > 500, "only {halves} halves");
    }

    /// Split in place equals split in path order on 400 random drafts (up to 60 moves, up to
    /// half of them left out, with and without params), and split again from the path
    /// ([`unsplit`]) with more points left out equals splitting the draft with all of them.
    #[test]
    fn split_in_place_equals_split_in_order_and_splits_again_from_its_path() {
        let mut next = crate::testing::uniform(0x5eed_5b11);
        for case in 0..400 {
            let n = (next() * 60.0) as usize;
            let (draft, skip) = random_draft(&mut next, n);
            let (want, want_origin) = split_in_order(&draft, &skip);
            let (got, origin) = split(&draft, &skip);
            assert_eq!(got.moves, want.moves, "case {case}: moves");
            assert_eq!(got.params, want.params, "case {case}: params");
            assert_eq!(got.runs, want.runs, "case {case}: runs");
            assert_eq!(origin, want_origin, "case {case}: origins");
            // More left out, among the points kept.
            let mut more = skip.clone();
            for &o in origin.iter().filter(|&&o| o != u32::MAX) {
                if next() < 0.3 {
                    more[o as usize] = Some(Why::NoWayOut);
                }
            }
            let again = unsplit(&got, &origin, &Along::of(&draft.toolpath.moves));
            let params = unsplit_params(&got, &origin, n);
            let (got2, origin2) = split_taking(again, params, &draft, &more);
            let (want2, want_origin2) = split_in_order(&draft, &more);
            assert_eq!(got2.moves, want2.moves, "case {case}: moves again");
            assert_eq!(got2.params, want2.params, "case {case}: params again");
            assert_eq!(got2.runs, want2.runs, "case {case}: runs again");
            assert_eq!(origin2, want_origin2, "case {case}: origins again");
        }
    }

    #[test]
    fn left_out_points_split_a_cut_into_two_with_a_retract_between() {
        // Rapid, plunge, five feeds, retract; the third and fourth feed left out.
        let mut moves = vec![mv(MoveKind::Rapid, 0.0), mv(MoveKind::Plunge, 0.0)];
        moves.extend((1..=5).map(|k| mv(MoveKind::Feed, k as f64)));
        moves.push(mv(MoveKind::Retract, 5.0));
        moves[0].cl_point.z = 10.0;
        moves[7].cl_point.z = 10.0;
        let n = moves.len();
        let draft = Draft {
            strategy: "test",
            toolpath: Toolpath {
                tool_radius_mm: 1.0,
                moves,
                max_predicted_scallop_mm: 0.0,
                runs: vec![PatchRun {
                    patch: 0,
                    start_corner: 0,
                    finish_corner: 1,
                    crossfeed: crate::plan::corners::Crossfeed::U,
                    passes: 1,
                    scallop_used_mm: 0.01,
                    retract_before: true,
                    first_move: 0,
                    last_move: 7,
                }],
                params: vec![[0.0, 0.0]; n],
            },
            footprints: (0..n).map(|_| Footprint::NONE).collect(),
            safe_z: 10.0,
            forced_retractions: 0,
            isfc: None,
            isoplanar: None,
        };
        let mut skip = vec![None; n];
        skip[4] = Some(Why::ToolHits);
        skip[5] = Some(Why::ToolHits);
        let (path, origin) = split(&draft, &skip);
        let kinds: Vec<MoveKind> = path.moves.iter().map(|m| m.kind).collect();
        use MoveKind::*;
        assert_eq!(
            kinds,
            [Rapid, Plunge, Feed, Feed, Retract, Rapid, Plunge, Retract]
        );
        assert_eq!(origin, [u32::MAX, 1, 2, 3, u32::MAX, u32::MAX, 6, u32::MAX]);
        // Up above the last kept point, over and down onto the next one.
        assert_eq!(path.moves[4].cl_point, Point3::new(2.0, 0.0, 10.0));
        assert_eq!(path.moves[5].cl_point, Point3::new(5.0, 0.0, 10.0));
        assert_eq!(path.moves[6].cl_point, Point3::new(5.0, 0.0, 1.0));
        assert_eq!((path.runs[0].first_move, path.runs[0].last_move), (0, 6));
        assert_eq!(path.params.len(), path.moves.len());
    }

    #[test]
    fn touching_footprints_form_one_region_per_patch_and_reason() {
        let m = crate::model::samples::load_sample("dome").unwrap();
        let fp = |u0: f64, u1: f64, v0: f64, v1: f64| Footprint {
            patch: 0,
            rect: [u0, u1, v0, v1],
        };
        let tight = fp(0.8, 0.9, 0.8, 0.9);
        let fps = vec![
            (fp(0.0, 0.1, 0.0, 0.1), Why::ToolHits),
            (fp(0.1, 0.2, 0.0, 0.1), Why::ToolHits),
            (fp(0.15, 0.3, 0.1, 0.2), Why::ToolHits),
            (fp(0.5, 0.6, 0.5, 0.6), Why::ToolHits),
            (fp(0.6, 0.7, 0.5, 0.6), Why::FacesAway),
            (Footprint::NONE, Why::ToolHits),
            // Kept, a quarter of it measured above the scallop.
            (tight, Why::TooTight),
        ];
        let shares = vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.25];
        let whole = fp(0.0, 1.0, 0.0, 1.0).area_mm2(&m);
        let rest = rest(&m, fps, shares, 7, &Toolpath::default());
        assert_eq!(rest.regions.len(), 4);
        assert_eq!(rest.regions[0].points, 3);
        let sum: f64 = rest.regions.iter().map(|r| r.area_mm2).sum();
        assert!((sum - rest.area_mm2).abs() < 1e-9);
        assert!(rest.area_mm2 > 0.0 && rest.area_mm2 < whole);
        let t = rest
            .regions
            .iter()
            .find(|r| r.why == Why::TooTight)
            .unwrap();
        assert!((t.area_mm2 - 0.25 * tight.area_mm2(&m)).abs() < 1e-12);
    }

    /// The share above the scallop of a flat unit footprint where `over` gives the height
    /// above it (area element 1), measured with `grid`.
    fn flat_share(grid: ShareGrid, over: &dyn Fn(f64, f64) -> f64) -> f64 {
        let n = grid.samples;
        let k = (n - 1) as f64;
        let corners: Vec<Corner> = (0..n)
            .flat_map(|a| (0..n).map(move |b| (a as f64 / k, b as f64 / k)))
            .map(|(u, v)| Corner {
                over: over(u, v),
                area: 1.0,
            })
            .collect();
        share_over([0.0, 1.0, 0.0, 1.0], grid, &corners, &mut |u, v| Corner {
            over: over(u, v),
            area: 1.0,
        })
    }

    #[test]
    fn the_share_above_the_scallop_locates_its_edge_within_a_finest_cell() {
        let tight = |over: &dyn Fn(f64, f64) -> f64| flat_share(TIGHT_GRID, over);
        // A disc of radius 0.2: π 0.2² of the footprint.
        let disc = tight(&|u, v| 0.04 - (u - 0.5).powi(2) - (v - 0.5).powi(2));
        assert!(
            (disc - std::f64::consts::PI * 0.04).abs() < 2e-3,
            "disc {disc}"
        );
        // A strip along a side narrower than a grid cell (1/8): 0.01 of the footprint, where
        // the grid's corner samples alone stand for 1/16.
        let strip = tight(&|u, _| 0.01 - u);
        assert!((strip - 0.01).abs() < 1.0 / 128.0, "strip {strip}");
        // A half plane, and nothing.
        assert!((tight(&|u, _| u - 0.3) - 0.7).abs() < 1.0 / 512.0);
        assert_eq!(tight(&|_, _| -1.0), 0.0);
        // A left-out footprint whose side a neighbouring pass cut 0.3 deep, on the coarse
        // grid: its edge within 1/8, read off the interpolant (0.7 + 0.05 / 2 left).
        let cut_side = flat_share(LEFT_OUT_GRID, &|u, v| u - 0.3 + 0.05 * v);
        assert!((cut_side - 0.725).abs() < 1.0 / 64.0, "cut side {cut_side}");
        assert_eq!(flat_share(LEFT_OUT_GRID, &|_, _| 1.0), 1.0);
    }
}
