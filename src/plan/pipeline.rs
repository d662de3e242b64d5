//! The shared half of planning: from a strategy's [`Draft`] (what to cut, in order) to a
//! tool path a machine can run, and its report. Every strategy ends here, so every plan
//! gets the same tool axes, crease lifting, turn checks, air moves, rest area and problems.
//!
//! Steps: CL points whose ball cuts into the surface are lifted clear ([`super::gouge`]);
//! tool axes are chosen ([`super::axis`]); points no allowed axis can cut are left out and
//! the cuts split there ([`super::reach`]); retracts and approaches are routed around the
//! model, leaving out cut points the ball cannot get to or away from ([`super::air`]);
//! turns of the axis between cut points are split where the shank or holder would touch;
//! what is left undone becomes the rest area and the report's problems.
//!
//! Owns: the order of those steps and the report's notes and problems. Must not: decide
//! what to cut (the strategies do) or measure the result (that is `verify`'s).

use super::air::{self, AirStats, Routed};
use super::axis::{self, AxisStats};
use super::clearance::Clearance;
use super::draft::{Draft, Footprint};
use super::gouge::{self, GougeStats};
use super::reach::{self, Rest, Why};
use super::smooth;
use super::toolpath::{PlanReport, PlanStatus, Problem, Toolpath};
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::verify::{RestRect, Verification};

/// Share of the overcut limit by which a ball may cut into the surface at a CL point before
/// the point is lifted (the rest is left to the straight moves between points).
const GOUGE_LIFT_SHARE: f64 = 0.2;
/// Share of the pipeline's progress the gouge lifting reports over (it is most of the
/// work where much of the surface is tighter than the ball).
const GOUGE_PROGRESS: f64 = 0.1;
/// Share of the pipeline's progress the measuring of footprints near lifted balls reports
/// over, after the lifting (on gearbox2-9 sliced it took 70 s).
const TIGHT_PROGRESS: f64 = 0.05;
/// Tolerance of the tessellation the air moves are checked against, as a share of the tool
/// radius (at least the overcut allowed): air moves that do not go straight up lead off
/// the surface by about twice this first ([`super::air`]).
const AIR_TESSELLATION_SHARE: f64 = 0.04;
/// The air moves are checked against the shank's tessellation when it was asked for a
/// tolerance at most this many times theirs (one tessellation fewer; their lead-off grows
/// with the tolerance).
const AIR_SHARED_SET: f64 = 1.5;
/// Rounds of leaving out cut points whose retract or approach finds no clear way, before
/// the plan gives up.
const MAX_ROUTE_ROUNDS: usize = 64;

/// A planned path with what the planning found.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The strategy that chose the cuts.
    pub strategy: &'static str,
    pub toolpath: Toolpath,
    /// Retractions the strategy could not avoid.
    pub forced_retractions: usize,
    /// What the tool-axis assignment found.
    pub axes: AxisStats,
    /// CL points lifted where the ball cut into the surface (a crease, a tight concave).
    pub gouge: GougeStats,
    /// How retracts and approaches were routed.
    pub air: AirStats,
    /// What is not machined, and why.
    pub rest: Rest,
    /// Share of the model's area the rest area is (0 to 1).
    pub rest_fraction: f64,
    /// What the space-filling curve is made of (`isfc` only).
    pub isfc: Option<super::isfc::IsfcStats>,
    /// The space-filling curve's cells and tree as segments, for drawing (`isfc` only; the
    /// strategy sets it after the pipeline).
    pub isfc_layer: Option<super::isfc::layer::Layer>,
    /// The patches the plan's patch numbers refer to, where the strategy cut the surface
    /// into its own (the watershed rectangles); the model's layout otherwise.
    pub layout: Option<crate::layout::PatchLayout>,
    /// The watershed strategies' regions and rectangles.
    pub watershed: Option<super::watershed::plan::WatershedStats>,
    /// The watershed rectangles as triangles and segments, for drawing (the watershed
    /// strategies only; set after the pipeline).
    pub watershed_layer: Option<super::watershed::layer::Layer>,
    /// What the slices are made of (`isoplanar` only).
    pub isoplanar: Option<super::isoplanar::IsoplanarStats>,
    /// The model's reader warnings, listed among the report's problems.
    pub model_warnings: Vec<String>,
}

/// Plans with a strategy: `draft` makes its draft, reporting on the first `draft_share` of
/// `progress`, and the pipeline finishes it on the rest.
pub fn plan_with(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
    draft_share: f64,
    draft: impl FnOnce(&mut dyn FnMut(f64) -> bool) -> Result<Draft>,
) -> Result<Planned> {
    let d = draft(&mut |f| progress(draft_share * f))?;
    finish(model, d, opts, &mut |f| {
        progress(draft_share + (1.0 - draft_share) * f)
    })
}

/// Significant digits of an area under 1 mm² in a message.
const AREA_DIGITS: i32 = 3;

/// An area in mm² for a message: two decimals from 1 mm² up, else [`AREA_DIGITS`]
/// significant digits (a rest area of a few thousandths of a mm² read "0.00 mm²").
fn area_text(mm2: f64) -> String {
    let decimals = |x: f64| (AREA_DIGITS - 1 - x.log10().floor() as i32).max(2);
    if !(mm2 > 0.0) || mm2 >= 1.0 {
        return format!("{mm2:.2}");
    }
    // The digits of the value as rounded (0.9996 is "1.00", 0.0099996 "0.0100").
    let scale = 10f64.powi(decimals(mm2));
    let rounded = (mm2 * scale).round() / scale;
    if rounded >= 1.0 {
        return format!("{rounded:.2}");
    }
    let d = decimals(rounded) as usize;
    format!("{rounded:.d$}")
}

/// Runs the pipeline on `draft`. `progress` receives the fraction of this part done and
/// returns `false` to cancel.
pub fn finish(
    model: &Model,
    mut draft: Draft,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Planned> {
    let r = opts.tool_radius_mm;
    // 1. Balls that cut into the surface away from their contact point are lifted clear
    //    (and cut points added where straight moves between them would cut in); what they
    //    then leave at the contact point is measured.
    let mut left = vec![0.0; draft.toolpath.moves.len()];
    let gouge = if gouge::needed(model, r) {
        let (stats, origin) = gouge::lift(
            model,
            &mut draft.toolpath,
            r,
            GOUGE_LIFT_SHARE * opts.overcut_mm(),
            &mut left,
            &mut |f| progress(GOUGE_PROGRESS * f),
        )?;
        if !origin.is_empty() {
            let at = |o: u32| (o != u32::MAX).then_some(o as usize);
            draft.footprints = origin
                .iter()
                .map(|&o| at(o).map_or(Footprint::NONE, |i| draft.footprints.get(i)))
                .collect();
            left = origin
                .iter()
                .map(|&o| at(o).map_or(0.0, |i| left[i]))
                .collect();
        }
        stats
    } else {
        GougeStats::default()
    };
    let n = draft.toolpath.moves.len();
    // Where balls were lifted, the material left around them, measured.
    let mut tight = reach::tight_near_lifts(
        model,
        &draft.toolpath,
        &draft.footprints,
        &left,
        opts.scallop_mm,
        &mut |f| progress(GOUGE_PROGRESS + TIGHT_PROGRESS * f),
    )
    .ok_or(Error::Cancelled)?;
    // And points whose lifted ball leaves more than the scallop there: the material left is
    // not needed past this.
    for (t, l) in tight.iter_mut().zip(left) {
        *t |= l > opts.scallop_mm;
    }
    if !progress(GOUGE_PROGRESS + TIGHT_PROGRESS) {
        return Err(Error::Cancelled);
    }
    // 2. Tool axes; points no allowed axis can cut are left out.
    let obs = Clearance::new(model, opts);
    if !progress(0.3) {
        return Err(Error::Cancelled);
    }
    let (mut axes, mut why) = axis::choose(&obs, &mut draft.toolpath, opts, &mut |f| {
        progress(0.3 + 0.5 * f)
    })?;
    // Large turns between neighbouring cut points spread over the points around them.
    axes.spread = smooth::spread_turns(&obs, &mut draft.toolpath, opts, &why);
    // 3. Split the cuts there and route the air moves; where the ball cannot get to a cut or
    //    away from it, leave those points out too and split again.
    // The shank's tessellation serves where it is about as fine (a thin tool's shank).
    let air_chordal = (AIR_TESSELLATION_SHARE * r).max(opts.overcut_mm());
    let own_air_set;
    let dist = match obs.shank_set_within(air_chordal, AIR_SHARED_SET) {
        Some(d) => d,
        None => {
            own_air_set = model.surface_distance(air_chordal);
            &own_air_set
        }
    };
    let mut rounds = 0;
    // The draft's moves and params become the path's (what the end halves need of the
    // draft's moves is kept apart, and the params of the points left out); another round
    // takes them back from the path.
    let along = reach::Along::of(&draft.toolpath.moves);
    let mut moves = std::mem::take(&mut draft.toolpath.moves);
    let mut params = std::mem::take(&mut draft.toolpath.params);
    let mut left_out = reach::left_out_params(&params, &along, &why);
    let (mut path, air, end_halves) = loop {
        let (mut path, origin) = reach::split_taking(moves, params, &draft, &why);
        // The half footprints at the cuts' ends, while the path is as split.
        let end_halves =
            reach::cut_end_halves(&path, &origin, &draft.footprints, &along, &why, &left_out);
        axis::fill_air_axes(&mut path);
        match air::route(model, &mut path, opts, dist) {
            Routed::Done(stats) => break (path, stats, end_halves),
            Routed::LeaveOut(cuts) => {
                // The path is as split: its kept moves are the draft's.
                moves = reach::unsplit(&path, &origin, &along);
                params = reach::unsplit_params(&path, &origin, n);
                rounds += 1;
                if rounds > MAX_ROUTE_ROUNDS {
                    let p = path.moves[cuts[0]].cl_point;
                    return Err(Error::Degenerate {
                        location: format!(
                            "ball centre ({:.3}, {:.3}, {:.3}) mm",
                            p.x, p.y, p.z
                        ),
                        message: "no clear way for the ball from the safe plane to the cut or back was found by leaving cut points out".into(),
                    });
                }
                for k in cuts {
                    if let Some(&o) = origin.get(k).filter(|&&o| o != u32::MAX) {
                        why[o as usize] = Some(Why::NoWayOut);
                        if let Some(&q) = path.params.get(k) {
                            left_out.push((o, q));
                        }
                    }
                }
                crate::sort::sort_by_key(&mut left_out, |l| l.0);
            }
        }
    };
    if !progress(0.85) {
        return Err(Error::Cancelled);
    }
    drop((along, left_out));
    // 4. Turns of the axis between cut points, checked for the shank and holder.
    axis::bridge_turns(&mut path, &obs, opts, &mut axes);
    // 5. The rest area: points left out, and points kept whose lifted ball leaves more than
    //    the scallop near their contact point; of each footprint, the share the final path
    //    leaves above the scallop.
    let mut rest_fps: Vec<(Footprint, Why)> = (0..n)
        .filter_map(|i| {
            why[i]
                .or(tight[i].then_some(Why::TooTight))
                .map(|w| (draft.footprints.get(i), w))
        })
        .collect();
    let points = rest_fps.len();
    rest_fps.extend(end_halves);
    let shares = reach::shares_left(model, &path, &rest_fps, opts.scallop_mm)?;
    let rest = reach::rest(model, rest_fps, shares, points, &path);
    let area = model_area(model);
    progress(1.0);
    Ok(Planned {
        model_warnings: model.warnings.clone(),
        isfc: draft.isfc,
        isoplanar: draft.isoplanar,
        isfc_layer: None,
        layout: None,
        watershed: None,
        watershed_layer: None,
        strategy: draft.strategy,
        toolpath: path,
        forced_retractions: draft.forced_retractions,
        axes,
        gouge,
        air,
        rest_fraction: if area > 0.0 {
            (rest.area_mm2 / area).min(1.0)
        } else {
            0.0
        },
        rest,
    })
}

/// Samples per side of a patch for its area.
const AREA_SAMPLES: usize = 24;

/// The model's area (mm²), from its patches.
fn model_area(model: &Model) -> f64 {
    (0..model.layout.len())
        .map(|p| {
            Footprint {
                patch: p as u32,
                rect: [0.0, 1.0, 0.0, 1.0],
            }
            .area_mm2_fine(model, AREA_SAMPLES)
        })
        .sum()
}

/// Largest patch-parameter extent of one drawn cell of the rest area.
const REST_CELL: f64 = 1.0 / 16.0;
/// Most cells per side of one footprint when drawn.
const REST_CELLS_MAX: usize = 8;

impl Planned {
    /// The rest area as rectangles of the surface's faces, for the verification's mask.
    pub fn rest_rects(&self, model: &Model) -> Vec<RestRect> {
        let mut out = Vec::new();
        let layout = self.layout.as_ref().unwrap_or(&model.layout);
        for (f, _) in &self.rest.footprints {
            let patch = &layout.patches[f.patch as usize];
            for (face, rect) in patch.face_rects(&model.surface, f.rect) {
                out.push(RestRect { face, rect });
            }
        }
        out
    }

    /// The rest area as triangles on the surface, for drawing: `x y z` per vertex (mm),
    /// three vertices per triangle, and per triangle the reason (the [`Why`] in declaration
    /// order, 0 to 3).
    pub fn rest_triangles(&self, model: &Model) -> (Vec<f32>, Vec<u8>) {
        let mut pos = Vec::new();
        let mut why = Vec::new();
        let layout = self.layout.as_ref().unwrap_or(&model.layout);
        for (f, w) in &self.rest.footprints {
            let patch = &layout.patches[f.patch as usize];
            let [u0, u1, v0, v1] = f.rect;
            let cells = |d: f64| ((d / REST_CELL).ceil() as usize).clamp(1, REST_CELLS_MAX);
            let (nu, nv) = (cells(u1 - u0), cells(v1 - v0));
            let at = |i: usize, j: usize| {
                let p = patch.subs(
                    &model.surface,
                    u0 + (u1 - u0) * i as f64 / nu as f64,
                    v0 + (v1 - v0) * j as f64 / nv as f64,
                );
                [p.x as f32, p.y as f32, p.z as f32]
            };
            for j in 0..nv {
                for i in 0..nu {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    for tri in [[a, b, c], [a, c, d]] {
                        for p in tri {
                            pos.extend_from_slice(&p);
                        }
                        why.push(*w as u8);
                    }
                }
            }
        }
        (pos, why)
    }

    /// The report: the path's lengths and counts, notes, the rest area and the problems.
    pub fn report(&self, opts: &PlanOptions) -> PlanReport {
        let mut r = self
            .toolpath
            .report(self.strategy, opts.feed_mm_min, opts.plunge_feed_mm_min);
        r.set_machining_time(
            &self.toolpath,
            opts,
            &crate::machine::default_machine(&self.toolpath),
        );
        if let Some(w) = &self.watershed {
            r.regions = w.regions.clone();
            // Each rectangle's direction and passes: its first run (the pipeline splits a
            // run where it leaves cut points out).
            let mut rects: Vec<super::toolpath::RectangleReport> = w
                .rectangle_regions
                .iter()
                .map(|&region| super::toolpath::RectangleReport {
                    region,
                    crossfeed: super::corners::Crossfeed::V,
                    passes: 0,
                })
                .collect();
            for run in r.patch_order.iter().rev() {
                if let Some(x) = rects.get_mut(run.patch as usize) {
                    (x.crossfeed, x.passes) = (run.crossfeed, run.passes);
                }
            }
            let regions = match (&w.regions, w.map_points) {
                (Some(regions), Some([nx, ny])) => {
                    let convex = regions
                        .iter()
                        .filter(|x| x.kind == super::watershed::FeatureKind::Convex)
                        .count();
                    format!(
                        "{} feature region(s) ({convex} convex, {} concave) on a {nx} × {ny} curvature map, ",
                        regions.len(),
                        regions.len() - convex
                    )
                }
                _ => String::new(),
            };
            r.notes.push(format!(
                "{}: {regions}{} rectangles",
                self.strategy,
                rects.len()
            ));
            r.rectangles = Some(rects);
        }
        if let Some(s) = &self.isfc {
            r.grid = Some(super::toolpath::GridSize {
                s_lines: s.s_lines,
                t_lines: s.t_lines,
                vertices: s.vertices,
            });
            r.cells = Some(s.cells);
            r.tree_links = Some(s.tree_links);
            r.repaired_cells = Some(s.repaired_cells);
            r.compensated_corners = Some(s.compensated_corners);
            r.notes.push(format!(
                "space-filling curve: {} closed loop(s) through {} grid vertices in {} cells ({} tree links, {} across patch sides), starting at ({:.3}, {:.3}, {:.3}) mm; {} corners with a detour ({} needed to hold the scallop), {} cells repaired for parity",
                s.loops, s.vertices, s.cells, s.tree_links, s.cross_patch_links,
                s.start_mm[0], s.start_mm[1], s.start_mm[2],
                s.compensated_corners, s.needed_corners, s.repaired_cells
            ));
            if s.floating_vertices > 0 {
                r.notes.push(format!(
                    "{} grid vertices belong to no cell (the plain curve's odd lines) and are not cut",
                    s.floating_vertices
                ));
            }
        }
        if let Some(s) = &self.isoplanar {
            r.planes = Some(s.planes);
            r.segments = Some(s.segments);
            r.slice_spacing_mm = Some(s.slice_spacing_mm);
            r.notes.push(format!(
                "iso-planar: {} planes ({} added where the cusp needed a pass between), normal at {}° from +X in XY, {} mm apart in the {} space; {} pieces, {} joined on the surface, {} with a retraction; deformation ratio up to {:.2} over {} slabs of {:.3} mm",
                s.planes,
                s.added_planes,
                s.slice_angle_deg,
                fmt_mm(s.slice_spacing_mm),
                if s.deformed { "deformed" } else { "plan-view (constant-spacing baseline)" },
                s.segments,
                s.links,
                s.retractions,
                s.max_ratio,
                s.slabs,
                s.slab_mm
            ));
        }
        if self.forced_retractions > 0 {
            r.notes.push(format!(
                "{}: {} retraction(s) used",
                if self.isoplanar.is_some() {
                    "pieces of the slices too far apart to join on the surface"
                } else if self.isfc.is_some() {
                    "the layout falls into parts no curve can join across a shared side"
                } else if self.watershed.is_some() {
                    "the rectangles, each kept to its cutting direction, do not all meet at shared corners"
                } else {
                    "no patch order and transit corners avoid retractions on this layout"
                },
                self.forced_retractions
            ));
        }
        if let Some(p) = self.gouge.worst_at {
            r.notes.push(format!(
                "at {} points the ball, placed by its own face's normal, cut into the surface elsewhere (a crease, or a concave radius below the ball's) by up to {:.4} mm, the deepest at ball centre ({:.3}, {:.3}, {:.3}) mm: they were lifted to touch it without cutting in",
                self.gouge.lifted, self.gouge.worst_mm, p.x, p.y, p.z
            ));
        }
        if self.gouge.inserted > 0 {
            r.notes.push(format!(
                "{} cut points added between cut points where the ball, moving straight, would have cut into a fold or crease of the surface",
                self.gouge.inserted
            ));
        }
        if self.axes.tilted > 0 {
            r.notes.push(format!(
                "the tool axis tilts away from +Z at {} points to keep the shank and holder clear",
                self.axes.tilted
            ));
        }
        if self.axes.bridged > 0 {
            r.notes.push(format!(
                "at {} moves the tool axis turns in smaller steps through added cut points, so that the shank and holder stay clear while it turns",
                self.axes.bridged
            ));
        }
        if self.air.escaped > 0 {
            r.notes.push(format!(
                "{} retract(s) or approach(es) back away from the surface (along the tool axis or the surface normal) before rising, to keep the ball out of the model",
                self.air.escaped
            ));
        }
        if self.air.lowered > 0 {
            r.notes.push(format!(
                "{} rapid(s) between cuts run the clearance ({} mm) over what the ball, shank and holder pass above, not at the safe plane: {:.1} mm less air (--full-retract keeps them at the safe plane)",
                self.air.lowered, opts.clearance_mm, self.air.lowered_saving_mm
            ));
        }
        // What is left undone.
        r.unreachable_area_mm2 = self.rest.area_mm2;
        r.rest = self.rest.regions.clone();
        for why in [Why::FacesAway, Why::ToolHits, Why::NoWayOut, Why::TooTight] {
            let regions: Vec<&reach::RestRegion> =
                self.rest.regions.iter().filter(|g| g.why == why).collect();
            let Some(largest) = regions.first() else {
                continue;
            };
            let area: f64 = regions.iter().map(|g| g.area_mm2).sum();
            let points: usize = regions.iter().map(|g| g.points).sum();
            let advice = match why {
                Why::FacesAway => "use a five-axis machine or allow more tilt (a table tilting past upright reaches undersides)",
                Why::ToolHits => "use a longer shank or a smaller holder, or allow more tilt",
                Why::NoWayOut => "allow more tilt, or machine this area in another set-up",
                Why::TooTight => "finish it with a smaller ball (see the model's smallest concave radius)",
            };
            let c = largest.centre_mm;
            let what = if why == Why::TooTight {
                "left with more than the scallop height"
            } else {
                "not machined"
            };
            r.problems.push(Problem {
                kind: format!("rest_{}", serde_json::to_value(why).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default()),
                message: format!(
                    "{} mm² of the surface ({points} cut points, {} region(s); the largest {} mm² around ({:.2}, {:.2}, {:.2}) mm on patch {}) {what}: {}; {advice}",
                    area_text(area),
                    regions.len(),
                    area_text(largest.area_mm2),
                    c[0],
                    c[1],
                    c[2],
                    largest.patch,
                    why.phrase()
                ),
                count: points,
                at_mm: Some(c),
                near_move: largest.near_move,
            });
        }
        if self.gouge.residual > 0 {
            r.problems.push(Problem {
                kind: "gouge".into(),
                message: format!(
                    "{} cut points stay up to {:.4} mm inside the surface after lifting",
                    self.gouge.residual, self.gouge.residual_mm
                ),
                count: self.gouge.residual,
                at_mm: None,
                near_move: None,
            });
        }
        if let Some(p) = self.axes.first_sweep_hit {
            let near = self.toolpath.moves.iter().position(|m| m.cl_point == p);
            r.problems.push(Problem {
                kind: "turn_margin".into(),
                message: format!(
                    "at {} moves the shank or holder comes within the {:.2} mm safety margin of the model (and may touch it) as the tool moves (and its axis turns) from one cut point to the next, the first such move ending at ball centre ({:.3}, {:.3}, {:.3}) mm: allow more tilt, use a longer shank or a smaller holder",
                    self.axes.sweep_hits, self.axes.margin_mm, p.x, p.y, p.z
                ),
                count: self.axes.sweep_hits,
                at_mm: Some([p.x, p.y, p.z]),
                near_move: near,
            });
        }
        if r.max_predicted_scallop_mm > opts.scallop_mm * (1.0 + SCALLOP_SLACK) {
            r.problems.push(Problem {
                kind: "scallop_predicted".into(),
                message: format!(
                    "the passes leave cusps up to {:.4} mm (predicted), above the requested {} mm",
                    r.max_predicted_scallop_mm, opts.scallop_mm
                ),
                count: 1,
                at_mm: None,
                near_move: None,
            });
        }
        for w in &self.model_warnings {
            r.problems.push(Problem {
                kind: "model_not_as_modelled".into(),
                message: w.clone(),
                count: 1,
                at_mm: None,
                near_move: None,
            });
        }
        r.status = PlanStatus::of(&r.problems);
        r
    }
}

/// Relative slack on the scallop comparison (rounding).
const SCALLOP_SLACK: f64 = 1e-9;

impl PlanReport {
    /// Adds what a cutting simulation of this plan found wrong to the problems (gouges,
    /// material above the requested scallop outside the rest area, an error bound too wide
    /// to prove the scallop) and updates the status. A simulation that proves the scallop
    /// within the request drops the planner's own prediction of cusps above it.
    pub fn add_verification(&mut self, v: &Verification) {
        let h = v.requested_scallop_mm;
        // A simulation that proves the scallop (its maximum within h, its error bound within
        // the target) supersedes the planner's prediction.
        let proven = v
            .error_bound_target_mm
            .is_some_and(|t| v.error_bound_mm <= t);
        if proven && v.max_scallop_mm <= h * (1.0 + SCALLOP_SLACK) {
            self.problems.retain(|p| p.kind != "scallop_predicted");
        }
        let at = |p: Option<[f64; 3]>| {
            p.map(|c| format!(" at ({:.3}, {:.3}, {:.3}) mm", c[0], c[1], c[2]))
                .unwrap_or_default()
        };
        if v.gouge_count > 0 {
            self.problems.push(Problem {
                kind: "gouge".into(),
                message: format!(
                    "the simulated cut goes up to {:.4} mm into the surface{} ({} samples deeper than the {} mm gouge tolerance)",
                    v.max_gouge_mm,
                    at(v.max_gouge_at_mm),
                    v.gouge_count,
                    v.gouge_tolerance_mm
                ),
                count: v.gouge_count,
                at_mm: v.max_gouge_at_mm,
                near_move: None,
            });
        }
        if v.max_scallop_mm > h * (1.0 + SCALLOP_SLACK) {
            self.problems.push(Problem {
                kind: "scallop".into(),
                message: format!(
                    "the simulated cut leaves up to {:.4} mm{} outside the rest area, above the requested scallop {} mm",
                    v.max_scallop_mm,
                    at(v.max_scallop_at_mm),
                    h
                ),
                count: 1,
                at_mm: v.max_scallop_at_mm,
                near_move: None,
            });
        }
        if let Some(target) = v.error_bound_target_mm.filter(|&t| v.error_bound_mm > t) {
            self.problems.push(Problem {
                kind: "unproven".into(),
                message: format!(
                    "the simulation's error bound {} is above the {:.4} mm (a quarter of the scallop) it aimed for with {} samples: the scallop and gouges are measured, not proven; simulate with more samples",
                    if v.error_bound_mm.is_finite() {
                        format!("{:.4} mm", v.error_bound_mm)
                    } else {
                        "(not bounded: a ball only grazes the surface somewhere)".to_string()
                    },
                    target,
                    v.samples
                ),
                count: 1,
                at_mm: None,
                near_move: None,
            });
        }
        self.status = PlanStatus::of(&self.problems);
    }
}

/// A length for a note: four decimals (mm).
fn fmt_mm(mm: f64) -> String {
    format!("{mm:.4}")
}

#[cfg(test)]
mod tests {
    use super::area_text;

    /// Small rest areas keep three significant digits; from 1 mm² up, two decimals.
    #[test]
    fn areas_in_messages_keep_their_digits() {
        for (mm2, text) in [
            (0.0, "0.00"),
            (0.000412, "0.000412"),
            (0.0031, "0.00310"),
            (0.95, "0.950"),
            (1.0, "1.00"),
            (12.3456, "12.35"),
            (663.31, "663.31"),
            (0.9996, "1.00"),
            (0.0099996, "0.0100"),
        ] {
            assert_eq!(area_text(mm2), text);
        }
    }
}
