//! The tool path: ordered moves, each with its cutter-contact point, cutter-location point
//! (the ball centre), tool axis, patch and iso-line, and the report computed from them.

use super::corners::Crossfeed;
use crate::geom::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// What a move does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[repr(u8)]
pub enum MoveKind {
    /// Cutting along the surface at the cutting feed.
    Feed = 0,
    /// Staying on the surface between two cuts (step-over, patch transit) at cutting feed.
    Link = 1,
    /// Leaving the surface (straight up, or backing out first) towards the safe plane, or
    /// only as high as the clearance over what the rapid to the next cut passes above.
    Retract = 2,
    /// Rapid move in the air (at least the clearance over the model), or down to the feed
    /// height above the next cut.
    Rapid = 3,
    /// Feed move from the approach point onto the surface, at the plunge feed.
    Plunge = 4,
    /// Feed move in the air, at the plunge feed, from the feed height down towards the next
    /// cut (the ways round the model that lead onto it); a plunge follows.
    Approach = 5,
}

impl MoveKind {
    /// True for moves that end with the ball on the surface (cutting, linking, plunging).
    pub fn on_surface(self) -> bool {
        matches!(self, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge)
    }

    /// True for moves at the rapid rate (retracts and rapids); the others run at a feed.
    pub fn rapid(self) -> bool {
        matches!(self, MoveKind::Retract | MoveKind::Rapid)
    }

    /// True for the feed moves that bring the tool down onto a cut (the in-air approach
    /// and the plunge), run at the plunge feed.
    pub fn at_plunge_feed(self) -> bool {
        matches!(self, MoveKind::Approach | MoveKind::Plunge)
    }
}

/// One position of the tool; the move *ends* here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    pub kind: MoveKind,
    /// Cutter-contact point on the surface (mm); for moves off the surface, the last one.
    pub cc_point: Point3,
    /// Ball centre (mm).
    pub cl_point: Point3,
    /// Unit tool axis, from the tip towards the spindle.
    pub tool_axis: Vector3,
    /// Patch (domain face) being cut.
    pub patch: u32,
    /// Index of the iso-line within its patch.
    pub line: u32,
}

/// How one patch was cut.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatchRun {
    pub patch: u32,
    /// Corners 0: `(0,0)`, 1: `(1,0)`, 2: `(1,1)`, 3: `(0,1)` of the patch.
    pub start_corner: u8,
    pub finish_corner: u8,
    pub crossfeed: Crossfeed,
    pub passes: usize,
    /// Scallop height the passes were spaced for (tuned below the request to finish at the
    /// chosen corner) (mm).
    pub scallop_used_mm: f64,
    /// True if the tool comes down from the safe plane for this patch.
    pub retract_before: bool,
    /// Moves of this patch (indices into the path, inclusive).
    pub first_move: usize,
    pub last_move: usize,
}

/// A complete tool path for one ball-end tool.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Toolpath {
    pub tool_radius_mm: f64,
    pub moves: Vec<Move>,
    /// Largest scallop predicted between adjacent lines by the step-over formula (mm).
    pub max_predicted_scallop_mm: f64,
    /// The patches in the order cut.
    pub runs: Vec<PatchRun>,
    /// Patch parameters `(u, v)` of each move's contact point (empty for paths not made
    /// by a planner).
    pub params: Vec<[f64; 2]>,
}

/// The moves a [`Toolpath::rebuild`] replaces, with their patch parameters (empty where
/// the path has none).
#[derive(Clone, Copy)]
pub struct OldMoves<'a> {
    pub moves: &'a [Move],
    pub params: &'a [[f64; 2]],
}

impl OldMoves<'_> {
    /// Patch parameters of old move `i` (zero where the path has none).
    pub fn param(&self, i: usize) -> [f64; 2] {
        self.params.get(i).copied().unwrap_or_default()
    }
}

/// Interval at which the tool axis is sampled in time for its angular acceleration (s).
pub const ACCELERATION_SAMPLE_S: f64 = 0.05;

/// One run of cutting moves sampled for [`Toolpath::max_axis_acceleration`]: the tool axis
/// at times `k × ACCELERATION_SAMPLE_S` from the run's start, turning at a steady rate
/// (spherical interpolation) through each move, the last three samples, and the largest
/// acceleration so far.
#[derive(Default)]
struct RunSamples {
    /// Time (s) and axis of the run's last point; `None` between runs.
    last: Option<(f64, Vector3)>,
    /// Index of the next sample: the samples the run has had.
    next: usize,
    /// The last samples, newest last (the run's first `next` of them, up to three).
    window: [Vector3; 3],
    /// Largest angular acceleration found (deg/s²).
    largest: f64,
}

impl RunSamples {
    /// A move of the run from axis `from` (the run's first point, if it has none yet) to
    /// `to`, lasting `took` seconds (none when 0: the next move starts at the same time).
    fn add(&mut self, from: Vector3, took: f64, to: Vector3) {
        let (s0, u) = *self.last.get_or_insert((0.0, from));
        if took > 0.0 {
            let s1 = s0 + took;
            // The samples within [s0, s1).
            loop {
                let t = self.next as f64 * ACCELERATION_SAMPLE_S;
                if t >= s1 {
                    break;
                }
                self.sample(slerp(&u, &to, (t - s0) / (s1 - s0)));
            }
            self.last = Some((s1, to));
        }
    }

    /// Ends the run: the samples up to its end take its last axis.
    fn finish(&mut self) {
        if let Some((end, v)) = self.last.take() {
            while self.next as f64 * ACCELERATION_SAMPLE_S <= end {
                self.sample(v);
            }
        }
        self.next = 0;
    }

    fn sample(&mut self, axis: Vector3) {
        self.next += 1;
        self.window.rotate_left(1);
        self.window[2] = axis;
        if self.next < 3 {
            return;
        }
        let w = &self.window;
        self.largest = self.largest.max(angular_acceleration(w));
    }
}

/// The angular acceleration (deg/s²) of an axis sampled at `w`, [`ACCELERATION_SAMPLE_S`]
/// apart: the change of its angular velocity from the first interval to the second.
fn angular_acceleration(w: &[Vector3; 3]) -> f64 {
    let dt = ACCELERATION_SAMPLE_S;
    let velocity = |u: &Vector3, v: &Vector3| {
        u.cross(v)
            .try_normalize(f64::MIN_POSITIVE)
            .map_or(Vector3::zeros(), |k| k * (u.angle(v).to_degrees() / dt))
    };
    (velocity(&w[1], &w[2]) - velocity(&w[0], &w[1])).norm() / dt
}

/// The unit vector a share `f` of the way from `u` to `v` on the great circle through them.
fn slerp(u: &Vector3, v: &Vector3, f: f64) -> Vector3 {
    let angle = u.angle(v);
    if angle < 1e-12 {
        return *u;
    }
    let sin = angle.sin();
    if sin < 1e-12 {
        // Opposite axes: no defined way round; the nearer end.
        return if f < 0.5 { *u } else { *v };
    }
    u * (((1.0 - f) * angle).sin() / sin) + v * ((f * angle).sin() / sin)
}

/// Summary of a tool path (keys as in the JSON report).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanReport {
    pub strategy: String,
    pub length_mm: f64,
    pub cutting_length_mm: f64,
    pub link_length_mm: f64,
    pub rapid_length_mm: f64,
    pub retractions: usize,
    pub reversals: usize,
    pub cl_points: usize,
    pub patches: usize,
    pub max_predicted_scallop_mm: f64,
    /// Largest turn of the tool axis from one cut point to the next while cutting (moves
    /// from a point on the surface to a cutting or linking one), degrees.
    pub max_axis_step_deg: f64,
    /// Largest angular acceleration of the tool axis while cutting (deg/s²), each move
    /// lasting its travel at the cutting feed or its turn at the fastest rotary feed of the
    /// machine timed (`time_machine`), whichever is longer; see
    /// [`Toolpath::max_axis_acceleration`].
    #[serde(default)]
    pub max_axis_acceleration_deg_s2: f64,
    /// The patches in the order cut, with their corners and passes.
    pub patch_order: Vec<PatchRun>,
    /// Things the user should know (retractions the layout forced, ...).
    pub notes: Vec<String>,
    /// Machining time on `time_machine` with its accelerations, jerk and corner speeds
    /// ([`crate::machine::motion`]) (min).
    pub machining_time_min: f64,
    /// Length over feed: feed and link moves at the feed, plunges at the plunge feed, rapids
    /// at `RAPID_MM_MIN` (min) — the time a machine with unlimited acceleration would take.
    pub feed_time_min: f64,
    /// The machine `machining_time_min` is for: the one the program is posted for, by
    /// default `3-axis` where the tool axis stays at +Z and `table-table-ac` otherwise.
    pub time_machine: String,
    /// Wall time of planning (ms); filled by the caller, which owns the clock.
    pub plan_ms: f64,
    /// `planned`, or `planned_with_problems` when anything in `problems` is left undone.
    pub status: PlanStatus,
    /// Area of the surface the plan does not machine to the scallop height (mm²): the
    /// rest area, which another tool or set-up must finish.
    pub unreachable_area_mm2: f64,
    /// The rest area's regions, largest first.
    pub rest: Vec<super::reach::RestRegion>,
    /// What the plan leaves undone or cannot promise; empty when it is done.
    pub problems: Vec<Problem>,
    /// `isfc`: the grid's lines (`u = const`, `v = const`) and vertices over all patches.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<GridSize>,
    /// `isfc`: 2 × 2 cells of grid vertices.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cells: Option<usize>,
    /// `isfc`: links of the spanning tree over the cells.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tree_links: Option<usize>,
    /// `isfc`: cells with a line the parity repair added.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repaired_cells: Option<usize>,
    /// `isfc`: turns with a corner detour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compensated_corners: Option<usize>,
    /// `watershed`: the feature regions (kind, area, boxes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub regions: Option<Vec<super::watershed::plan::RegionReport>>,
    /// `watershed`, `multi-rectangle`: every rectangle (patch), its feature region, the
    /// direction it is cut in and its passes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rectangles: Option<Vec<RectangleReport>>,
    /// `isoplanar`: slicing planes with a pass (of them added where the cusp needed one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planes: Option<usize>,
    /// `isoplanar`: connected pieces of the slices cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<usize>,
    /// `isoplanar`: spacing of the planes in the deformed space (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slice_spacing_mm: Option<f64>,
}

/// One rectangle of a watershed plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RectangleReport {
    /// The feature region (index into `regions`), none for the rest of the domain.
    pub region: Option<u32>,
    /// `U`: passes `u = const`, cutting along `v`; `V`: cutting along `u`.
    pub crossfeed: Crossfeed,
    pub passes: usize,
}

/// Size of a space-filling curve's grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct GridSize {
    pub s_lines: usize,
    pub t_lines: usize,
    pub vertices: usize,
}

/// Whether a plan did everything asked of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanStatus {
    #[default]
    Planned,
    /// Something is left undone: see the report's problems.
    PlannedWithProblems,
}

impl PlanStatus {
    /// The status a list of problems gives.
    pub fn of(problems: &[Problem]) -> Self {
        if problems.is_empty() {
            PlanStatus::Planned
        } else {
            PlanStatus::PlannedWithProblems
        }
    }
}

/// Something a plan leaves undone or cannot promise, with where to look.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Problem {
    /// What kind: `rest_faces_away`, `rest_tool_hits`, `rest_no_way_out`, `rest_too_tight`,
    /// `turn_margin`, `scallop`, `gouge`, `unproven`.
    pub kind: String,
    /// What it is and what to do about it, for a person.
    pub message: String,
    /// How many cut points, moves or samples it concerns.
    pub count: usize,
    /// Where it is (mm), if it has one place.
    pub at_mm: Option<[f64; 3]>,
    /// A move of the path near it, where a viewer puts the tool.
    pub near_move: Option<usize>,
}

/// Rapid traverse rate assumed for time estimates (mm/min).
pub const RAPID_MM_MIN: f64 = 5000.0;

/// How the note on an approximate machining time starts.
const TIME_NOTE: &str = "machining time:";

impl PlanReport {
    /// Sets `machining_time_min` to the time `machine` takes to run `path` at `opts`' feeds
    /// ([`crate::machine::motion`]), naming the machine; notes where the machine cannot take
    /// the path's tool axes and the tool axis' turn stood in for its rotaries.
    pub fn set_machining_time(
        &mut self,
        path: &Toolpath,
        opts: &super::PlanOptions,
        machine: &crate::machine::Machine,
    ) {
        self.max_axis_acceleration_deg_s2 =
            path.max_axis_acceleration(opts.feed_mm_min, machine.max_rotary_feed_deg_min);
        let t = crate::machine::path_times(path, opts, machine);
        self.machining_time_min = t.total_min();
        self.time_machine = machine.name.clone();
        self.notes.retain(|n| !n.starts_with(TIME_NOTE));
        if !t.from_joints {
            self.notes.push(format!(
                "{TIME_NOTE} machine `{}` cannot take every tool axis of the path, so its rotaries were timed by the tool axis' own turn",
                machine.name
            ));
        }
    }
}

impl Toolpath {
    /// Rebuilds the moves: `f(old, i, add)` adds, through `add(move, params)`, the moves
    /// that replace old move `i` (`old` holds the old moves and their params, the latter
    /// empty where the path has none; at least one move each, the last standing for it).
    /// Keeps `runs` and `params` in step.
    ///
    /// In place: the old moves stay where they are while `f` reads them, only the moves
    /// that differ from them are kept aside, and the path then grows by the moves added and
    /// is rewritten from its end (the path is the plan's largest allocation: a second copy
    /// of it doubled a five-axis plan's peak memory).
    pub fn rebuild(&mut self, mut f: impl FnMut(OldMoves, usize, &mut dyn FnMut(Move, [f64; 2]))) {
        let n = self.moves.len();
        let has_params = self.params.len() == n;
        // Old moves whose replacement is not the move itself: (index, where its moves start
        // in `added`), and those moves.
        let mut changed: Vec<(usize, usize)> = Vec::new();
        let mut added: Vec<(Move, [f64; 2])> = Vec::new();
        {
            let old = OldMoves {
                moves: &self.moves,
                params: if has_params { &self.params } else { &[] },
            };
            for i in 0..n {
                let first = added.len();
                f(old, i, &mut |m, q| added.push((m, q)));
                debug_assert!(added.len() > first, "move {i} was dropped");
                // Where `f` added nothing (against its contract: the debug build stops
                // there), the old move stays, so the path never shrinks (each old move
                // lands at or after where it was, as the rewrite below needs).
                let same = added.len() == first
                    || added.len() == first + 1
                        && added[first].0 == old.moves[i]
                        && (!has_params || added[first].1 == old.params[i]);
                if same {
                    added.truncate(first);
                } else {
                    changed.push((i, first));
                }
            }
        }
        if changed.is_empty() {
            return;
        }
        // Moves standing for old move `k` of `changed`.
        let span = |k: usize| {
            let end = changed.get(k + 1).map_or(added.len(), |c| c.1);
            changed[k].1..end
        };
        let grown = n + added.len() - changed.len();
        // First and last new index of each old move.
        let new_index = |i: usize| {
            // Moves added by the changed old moves before `i`, beyond one each.
            let k = changed.partition_point(|c| c.0 < i);
            let before = if k == 0 {
                0
            } else {
                changed[k - 1].1 + span(k - 1).len() - k
            };
            let first = i + before;
            let own = if changed.get(k).is_some_and(|c| c.0 == i) {
                span(k).len()
            } else {
                1
            };
            (first, first + own - 1)
        };
        for run in &mut self.runs {
            run.first_move = new_index(run.first_move).0;
            run.last_move = new_index(run.last_move).1;
        }
        // Exactly (a vector that outgrows its room doubles it); the allocator can grow a
        // block this large where it lies.
        let filler = self.moves[0];
        self.moves.reserve_exact(grown - n);
        self.moves.resize(grown, filler);
        if has_params {
            self.params.reserve_exact(grown - n);
            self.params.resize(grown, [0.0; 2]);
        }
        // From the end: each old move lands at or after where it was, so nothing is
        // overwritten before it is moved.
        let mut to = grown;
        let mut k = changed.len();
        for i in (0..n).rev() {
            if k > 0 && changed[k - 1].0 == i {
                k -= 1;
                for j in span(k).rev() {
                    to -= 1;
                    self.moves[to] = added[j].0;
                    if has_params {
                        self.params[to] = added[j].1;
                    }
                }
            } else {
                to -= 1;
                self.moves[to] = self.moves[i];
                if has_params {
                    self.params[to] = self.params[i];
                }
            }
        }
        debug_assert_eq!(to, 0);
    }

    /// A path of `moves` for a ball of radius `tool_radius_mm`, without planner details.
    pub fn new(tool_radius_mm: f64, moves: Vec<Move>) -> Self {
        Toolpath {
            tool_radius_mm,
            moves,
            ..Default::default()
        }
    }

    /// Largest angular acceleration of the tool axis while cutting (deg/s²): along each run
    /// of cutting moves, each lasting its travel at `feed_mm_min` or its turn at
    /// `rotary_feed_deg_min` (the machine's fastest rotary feed), whichever is longer, the
    /// axis is sampled every [`ACCELERATION_SAMPLE_S`] and the change of its angular
    /// velocity between samples taken over that time (so a jump in turning rate counts as
    /// spread over one sample interval, as a machine's servo ramps it).
    ///
    /// The samples are taken as the moves come, three kept at a time: a run's points and
    /// samples held whole took 6 MB on the head five-axis, enough to grow the page's wasm
    /// memory by 8 MB.
    pub fn max_axis_acceleration(&self, feed_mm_min: f64, rotary_feed_deg_min: f64) -> f64 {
        let mut run = RunSamples::default();
        for i in 1..self.moves.len() {
            let (a, b) = (&self.moves[i - 1], &self.moves[i]);
            if !(a.kind.on_surface() && matches!(b.kind, MoveKind::Feed | MoveKind::Link)) {
                run.finish();
                continue;
            }
            let turn = a.tool_axis.angle(&b.tool_axis).to_degrees();
            let took = ((b.cl_point - a.cl_point).norm() / feed_mm_min)
                .max(turn / rotary_feed_deg_min)
                * 60.0;
            run.add(a.tool_axis, took, b.tool_axis);
        }
        run.finish();
        run.largest
    }

    /// Lengths, counts and time estimate. `feed` and `plunge_feed` in mm/min.
    pub fn report(&self, strategy: &str, feed: f64, plunge_feed: f64) -> PlanReport {
        let mut r = PlanReport {
            strategy: strategy.to_string(),
            length_mm: 0.0,
            cutting_length_mm: 0.0,
            link_length_mm: 0.0,
            rapid_length_mm: 0.0,
            retractions: 0,
            reversals: 0,
            cl_points: self.moves.len(),
            patches: 0,
            max_predicted_scallop_mm: self.max_predicted_scallop_mm,
            max_axis_step_deg: 0.0,
            max_axis_acceleration_deg_s2: 0.0,
            patch_order: self.runs.clone(),
            notes: Vec::new(),
            machining_time_min: 0.0,
            feed_time_min: 0.0,
            time_machine: String::new(),
            plan_ms: 0.0,
            status: PlanStatus::Planned,
            unreachable_area_mm2: 0.0,
            rest: Vec::new(),
            problems: Vec::new(),
            grid: None,
            cells: None,
            tree_links: None,
            repaired_cells: None,
            compensated_corners: None,
            regions: None,
            rectangles: None,
            planes: None,
            segments: None,
            slice_spacing_mm: None,
        };
        let mut patches: Vec<u32> = self.moves.iter().map(|m| m.patch).collect();
        patches.sort_unstable();
        patches.dedup();
        r.patches = patches.len();
        let mut last_dir: Option<Vector3> = None;
        for w in self.moves.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let d = b.cl_point - a.cl_point;
            let len = d.norm();
            r.length_mm += len;
            match b.kind {
                MoveKind::Feed => {
                    r.cutting_length_mm += len;
                    r.feed_time_min += len / feed;
                }
                MoveKind::Link => {
                    r.link_length_mm += len;
                    r.feed_time_min += len / feed;
                }
                MoveKind::Plunge | MoveKind::Approach => {
                    r.link_length_mm += len;
                    r.feed_time_min += len / plunge_feed;
                }
                MoveKind::Retract | MoveKind::Rapid => {
                    r.rapid_length_mm += len;
                    r.feed_time_min += len / RAPID_MM_MIN;
                }
            }
            match b.kind {
                MoveKind::Feed if len > 0.0 => {
                    let dir = d / len;
                    if last_dir.is_some_and(|p: Vector3| p.dot(&dir) < REVERSAL_COS) {
                        r.reversals += 1;
                    }
                    last_dir = Some(dir);
                }
                MoveKind::Retract | MoveKind::Rapid => last_dir = None,
                _ => {}
            }
            if a.kind.on_surface() && matches!(b.kind, MoveKind::Feed | MoveKind::Link) {
                let turn = a.tool_axis.angle(&b.tool_axis).to_degrees();
                r.max_axis_step_deg = r.max_axis_step_deg.max(turn);
            }
        }
        // Retractions between cuts; the final one, after the last cut, does not count.
        let last_cut = self.moves.iter().rposition(|m| m.kind == MoveKind::Feed);
        r.retractions = self
            .moves
            .iter()
            .enumerate()
            .filter(|(i, m)| {
                m.kind == MoveKind::Retract
                    && (*i == 0 || self.moves[i - 1].kind != MoveKind::Retract)
                    && last_cut.is_some_and(|l| *i < l)
            })
            .count();
        r
    }
}

/// Two consecutive cutting directions (links between them ignored) with a cosine below this
/// are a reversal: turning by more than 120°, as at the end of a zig-zag line.
const REVERSAL_COS: f64 = -0.5;

#[cfg(test)]
mod tests {
    use super::*;

    /// What [`Toolpath::rebuild`] must give: new vectors built from the old ones, each old
    /// move's first and last new index for the runs.
    #[allow(clippy::type_complexity)]
    fn rebuilt_by_copy(
        path: &Toolpath,
        f: &mut dyn FnMut(OldMoves, usize, &mut dyn FnMut(Move, [f64; 2])),
    ) -> (Vec<Move>, Vec<[f64; 2]>, Vec<(usize, usize)>) {
        let old = OldMoves {
            moves: &path.moves,
            params: &path.params,
        };
        let (mut moves, mut params, mut runs) = (Vec::new(), Vec::new(), Vec::new());
        let mut index = Vec::new();
        for i in 0..path.moves.len() {
            let first = moves.len();
            f(old, i, &mut |m, q| {
                moves.push(m);
                params.push(q);
            });
            index.push((first, moves.len() - 1));
        }
        for r in &path.runs {
            runs.push((index[r.first_move].0, index[r.last_move].1));
        }
        (moves, params, runs)
    }

    /// [`Toolpath::max_axis_acceleration`] as it was first written, the second method: each
    /// run's points held whole, and the axis at each sample time found among them.
    fn max_axis_acceleration_whole_runs(path: &Toolpath, feed: f64, rotary: f64) -> f64 {
        let dt = ACCELERATION_SAMPLE_S;
        let axis_at = |run: &[(f64, Vector3)], t: f64| {
            let k = run.partition_point(|&(s, _)| s <= t);
            if k == run.len() {
                return run[k - 1].1;
            }
            let ((s0, u), (s1, v)) = (run[k - 1], run[k]);
            slerp(&u, &v, (t - s0) / (s1 - s0))
        };
        let mut largest: f64 = 0.0;
        let mut runs: Vec<Vec<(f64, Vector3)>> = vec![Vec::new()];
        for w in path.moves.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if !(a.kind.on_surface() && matches!(b.kind, MoveKind::Feed | MoveKind::Link)) {
                runs.push(Vec::new());
                continue;
            }
            let run = runs.last_mut().unwrap();
            let took = ((b.cl_point - a.cl_point).norm() / feed)
                .max(a.tool_axis.angle(&b.tool_axis).to_degrees() / rotary)
                * 60.0;
            if run.is_empty() {
                run.push((0.0, a.tool_axis));
            }
            if took > 0.0 {
                run.push((run.last().unwrap().0 + took, b.tool_axis));
            }
        }
        for run in runs.iter().filter(|r| !r.is_empty()) {
            let end = run.last().unwrap().0;
            let samples: Vec<Vector3> = (0..=(end / dt).floor() as usize)
                .map(|k| axis_at(run, k as f64 * dt))
                .collect();
            for w in samples.windows(3) {
                largest = largest.max(angular_acceleration(&[w[0], w[1], w[2]]));
            }
        }
        largest
    }

    #[test]
    fn axis_acceleration_sampled_as_the_moves_come_equals_sampling_whole_runs() {
        // Random paths: cutting runs broken by rapids and plunges, moves of random length
        // (some none) and turn, some turns slowed by the rotary feed.
        let mut rnd = crate::testing::uniform(19u64);
        let mut seen = 0;
        for trial in 0..200 {
            let n = 2 + (rnd() * 120.0) as usize;
            let mut p = Point3::origin();
            let mut moves = Vec::with_capacity(n);
            for _ in 0..n {
                let kind = match rnd() {
                    x if x < 0.05 => MoveKind::Rapid,
                    x if x < 0.1 => MoveKind::Plunge,
                    x if x < 0.2 => MoveKind::Link,
                    _ => MoveKind::Feed,
                };
                if trial % 2 == 1 {
                    // Moves of whole sample intervals at 600 mm/min (0.5 mm: 0.05 s), so
                    // that sample times meet the points' times.
                    p.x += 0.5 * (rnd() * 4.0).floor();
                } else if rnd() > 0.1 {
                    p += Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.1 * rnd()) * 3.0;
                }
                let (tilt, turn) = (rnd() * 0.6, rnd() * std::f64::consts::TAU);
                moves.push(Move {
                    kind,
                    cc_point: p,
                    cl_point: p,
                    tool_axis: Vector3::new(
                        tilt.sin() * turn.cos(),
                        tilt.sin() * turn.sin(),
                        tilt.cos(),
                    ),
                    patch: 0,
                    line: 0,
                });
            }
            let path = Toolpath::new(1.0, moves);
            let (feed, rotary) = match trial % 2 {
                1 => (600.0, 1e9),
                _ => (600.0 + 2000.0 * rnd(), [1200.0, 6000.0, 36000.0][trial % 3]),
            };
            let a = path.max_axis_acceleration(feed, rotary);
            let b = max_axis_acceleration_whole_runs(&path, feed, rotary);
            assert_eq!(a.to_bits(), b.to_bits(), "trial {trial}: {a} against {b}");
            seen += usize::from(a > 0.0);
        }
        assert!(seen > 150, "only {seen} paths accelerate the axis");
    }

    #[test]
    fn rebuilding_in_place_gives_what_building_a_copy_gives() {
        // Paths of random length whose moves are kept, changed, or given up to three moves
        // before them (some paths none changed, some all), runs over them: the same moves,
        // params and runs as a rebuild into new vectors.
        let mut rnd = crate::testing::uniform(5u64);
        for trial in 0..60 {
            let n = 1 + (rnd() * 300.0) as usize;
            let mv = |k: usize| Move {
                kind: MoveKind::Feed,
                cc_point: Point3::new(k as f64, 0.0, 0.0),
                cl_point: Point3::new(k as f64, 0.0, 1.0),
                tool_axis: Vector3::z(),
                patch: 0,
                line: k as u32,
            };
            let mut path = Toolpath::new(1.0, (0..n).map(mv).collect());
            path.params = (0..n).map(|k| [k as f64, 0.5]).collect();
            let mut cut = 0;
            while cut < n {
                let last = (cut + (rnd() * 40.0) as usize).min(n - 1);
                path.runs.push(PatchRun {
                    patch: 0,
                    start_corner: 0,
                    finish_corner: 1,
                    crossfeed: Crossfeed::U,
                    passes: 1,
                    scallop_used_mm: 0.01,
                    retract_before: false,
                    first_move: cut,
                    last_move: last,
                });
                cut = last + 1;
            }
            let share = [0.0, 1.0, 0.1, 0.5][trial % 4];
            let plan: Vec<(usize, bool)> = (0..n)
                .map(|_| {
                    let more = if rnd() < share {
                        1 + (rnd() * 3.0) as usize
                    } else {
                        0
                    };
                    (more, rnd() < share)
                })
                .collect();
            let mut f = |old: OldMoves, i: usize, add: &mut dyn FnMut(Move, [f64; 2])| {
                let (more, change) = plan[i];
                for j in 0..more {
                    let mut m = old.moves[i];
                    m.cl_point.y = 10.0 + j as f64;
                    add(m, [old.param(i)[0] - 0.5, j as f64]);
                }
                let mut m = old.moves[i];
                if change {
                    m.cl_point.z += 1.0;
                }
                add(m, old.param(i));
            };
            let (moves, params, runs) = rebuilt_by_copy(&path, &mut f);
            path.rebuild(&mut f);
            assert_eq!(path.moves, moves, "trial {trial}");
            assert_eq!(path.params, params, "trial {trial}");
            let got: Vec<(usize, usize)> = path
                .runs
                .iter()
                .map(|r| (r.first_move, r.last_move))
                .collect();
            assert_eq!(got, runs, "trial {trial}");
        }
    }
}
