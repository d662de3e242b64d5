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

use super::draft::{Draft, Footprint};
use super::toolpath::{Move, MoveKind, PatchRun, Toolpath};
use crate::geom::Point3;
use crate::model::Model;
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
    /// Its area (mm²).
    pub area_mm2: f64,
    /// Its area-weighted middle (mm); may lie off a curved region.
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
    let old = &draft.toolpath;
    let n = old.moves.len();
    let mut out = Emitted {
        has_params: old.params.len() == n,
        safe_z: draft.safe_z,
        moves: Vec::with_capacity(n),
        params: Vec::with_capacity(n),
        origin: Vec::with_capacity(n),
    };
    // Whether the tool is on the surface at the last move emitted and may go on from there.
    let mut joined = false;
    for (i, m) in old.moves.iter().enumerate() {
        if !m.kind.on_surface() || skip[i].is_some() {
            joined = false;
            continue;
        }
        let q = old.params.get(i).copied().unwrap_or_default();
        if joined {
            out.push(*m, q, i as u32);
            continue;
        }
        // Come down onto this move from the safe plane, leaving the last cut first.
        out.retract();
        let above = Move {
            kind: MoveKind::Rapid,
            cl_point: Point3::new(m.cl_point.x, m.cl_point.y, draft.safe_z),
            ..*m
        };
        out.push(above, q, u32::MAX);
        let plunge = Move {
            kind: MoveKind::Plunge,
            ..*m
        };
        out.push(plunge, q, i as u32);
        joined = true;
    }
    out.retract();
    let runs = split_runs(&old.runs, &out.moves, &out.origin);
    (
        Toolpath {
            tool_radius_mm: old.tool_radius_mm,
            moves: out.moves,
            max_predicted_scallop_mm: old.max_predicted_scallop_mm,
            runs,
            params: if out.has_params {
                out.params
            } else {
                Vec::new()
            },
        },
        out.origin,
    )
}

/// The moves [`split`] emits, with their params and origins.
struct Emitted {
    has_params: bool,
    safe_z: f64,
    moves: Vec<Move>,
    params: Vec<[f64; 2]>,
    origin: Vec<u32>,
}

impl Emitted {
    fn push(&mut self, m: Move, q: [f64; 2], origin: u32) {
        self.moves.push(m);
        self.params.push(q);
        self.origin.push(origin);
    }

    /// Straight up to the safe plane from the last move, if it is on the surface.
    fn retract(&mut self) {
        let Some(last) = self.moves.last().copied().filter(|m| m.kind.on_surface()) else {
            return;
        };
        let q = self.params.last().copied().unwrap_or_default();
        let up = Move {
            kind: MoveKind::Retract,
            cl_point: Point3::new(last.cl_point.x, last.cl_point.y, self.safe_z),
            ..last
        };
        self.push(up, q, u32::MAX);
    }
}

/// The runs of the draft over the split path: each keeps the moves it had that were kept;
/// a run with none is dropped (its patch is all rest area).
fn split_runs(runs: &[PatchRun], moves: &[Move], origin: &[u32]) -> Vec<PatchRun> {
    runs.iter()
        .filter_map(|run| {
            let within = |k: usize| {
                let o = origin[k];
                o != u32::MAX && (run.first_move..=run.last_move).contains(&(o as usize))
            };
            let first = (0..moves.len()).find(|&k| within(k))?;
            let last = (first..moves.len()).rev().find(|&k| within(k))?;
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

/// The rest area of `footprints` on `model`, its regions located against the final `path`.
pub fn rest(model: &Model, footprints: Vec<(Footprint, Why)>, path: &Toolpath) -> Rest {
    let fps: Vec<(Footprint, Why)> = footprints
        .into_iter()
        .filter(|(f, _)| !f.is_none())
        .collect();
    let n = fps.len();
    let mut sets = Sets((0..n).collect());
    // Footprints of one patch and reason touching each other join: bucketed by patch and
    // reason, then swept in u.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
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
    for i in 0..n {
        let root = sets.find(i);
        if index_of_root[root] == usize::MAX {
            index_of_root[root] = acc.len();
            acc.push((fps[i].0.patch, fps[i].1, 0.0, [0.0; 3], 0));
        }
        let a = fps[i].0.area_mm2(model);
        let c = fps[i].0.centre(model);
        let e = &mut acc[index_of_root[root]];
        e.2 += a;
        for (k, x) in [c.x, c.y, c.z].into_iter().enumerate() {
            e.3[k] += a * x;
        }
        e.4 += 1;
        total += a;
    }
    let mut regions: Vec<RestRegion> = acc
        .into_iter()
        .map(|(patch, why, area, sum, points)| {
            let centre = if area > 0.0 {
                sum.map(|s| s / area)
            } else {
                [0.0; 3]
            };
            let c = Point3::from(centre);
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
    regions.sort_by(|a, b| {
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
            footprints: vec![Footprint::NONE; n],
            safe_z: 10.0,
            forced_retractions: 0,
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
        let fps = vec![
            (fp(0.0, 0.1, 0.0, 0.1), Why::ToolHits),
            (fp(0.1, 0.2, 0.0, 0.1), Why::ToolHits),
            (fp(0.15, 0.3, 0.1, 0.2), Why::ToolHits),
            (fp(0.5, 0.6, 0.5, 0.6), Why::ToolHits),
            (fp(0.6, 0.7, 0.5, 0.6), Why::FacesAway),
            (Footprint::NONE, Why::ToolHits),
        ];
        let whole = fp(0.0, 1.0, 0.0, 1.0).area_mm2(&m);
        let rest = rest(&m, fps, &Toolpath::default());
        assert_eq!(rest.regions.len(), 3);
        assert_eq!(rest.regions[0].points, 3);
        let sum: f64 = rest.regions.iter().map(|r| r.area_mm2).sum();
        assert!((sum - rest.area_mm2).abs() < 1e-9);
        assert!(rest.area_mm2 > 0.0 && rest.area_mm2 < whole);
    }
}
