//! Watershed feature regions and optimised multi-rectangles (Liu et al. 2020; issue 15):
//! plans on the feature samples checked by the cutting simulation, the direction rule,
//! the baseline's single direction, determinism, and the error on a domain that does not
//! lie flat.

use crate::support;

use support::public_tsm;
use tspath::model::samples;
use tspath::plan::corners::Crossfeed;
use tspath::plan::distance::SurfaceDistance;
use tspath::plan::isoparametric::ParamSurface;
use tspath::plan::{self, isoparametric, PlanOptions, Strategy};
use tspath::verify;
use tspath::Model;

fn opts(strategy: Strategy) -> PlanOptions {
    PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.05)
        .with_strategy(strategy)
}

/// A patch's sides on the surface (mm), along its middle iso-lines: `[along u, along v]`.
fn sides_mm(view: &isoparametric::PatchView) -> [f64; 2] {
    [true, false].map(|along_u| {
        let at = |t: f64| {
            if along_u {
                view.subs(t, 0.5)
            } else {
                view.subs(0.5, t)
            }
        };
        (1..=64)
            .map(|k| (at(k as f64 / 64.0) - at((k - 1) as f64 / 64.0)).norm())
            .sum::<f64>()
    })
}

/// The cut of `planned` (from `m` with `o`) simulated from 200 000 samples up, until the
/// error bound is a quarter of the scallop.
fn simulated(m: &Model, planned: &plan::Planned, o: &PlanOptions) -> verify::Verification {
    verify::verify_plan(
        m,
        planned,
        o,
        Some(200_000),
        verify::PLAN_VERIFY_MAX_SAMPLES,
    )
    .unwrap()
}

fn reversals(m: &Model, o: &PlanOptions) -> usize {
    plan::plan(m, o, &mut |_| true).unwrap().report(o).reversals
}

/// Both strategies on `bumps`, `bumps-hole` and `waves`: the cutting simulation (error
/// bound a quarter of the scallop) finds the scallop kept, nothing uncut outside the rest
/// area and no gouge; the report lists the regions and one rectangle per patch.
#[test]
fn watershed_and_multi_rectangle_plans_keep_the_scallop_without_gouges() {
    for name in ["bumps", "bumps-hole", "waves"] {
        let m = samples::load_sample(name).unwrap();
        for strategy in [Strategy::Watershed, Strategy::MultiRectangle] {
            let o = opts(strategy);
            let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
            let mut report = planned.report(&o);
            let v = simulated(&m, &planned, &o);
            report.add_verification(&v);
            let rects = report.rectangles.clone().unwrap();
            println!(
                "{name} {}: {} rectangles, {} regions, cut {:.0} mm, {} reversals, {} retractions; max scallop {:.4} mm (bound {:.4} mm), uncut {:.5}, gouges {}",
                strategy.name(),
                rects.len(),
                report.regions.as_ref().map_or(0, |r| r.len()),
                report.cutting_length_mm,
                report.reversals,
                report.retractions,
                v.max_scallop_mm,
                v.error_bound_mm,
                v.uncut_fraction,
                v.gouge_count
            );
            assert_eq!(report.strategy, strategy.name());
            assert_eq!(rects.len(), report.patches);
            assert!(v.error_bound_mm <= 0.25 * o.scallop_mm);
            assert_eq!(v.gouge_count, 0, "{name} {}", strategy.name());
            assert!(
                v.max_scallop_mm <= o.scallop_mm,
                "{name} {}: {}",
                strategy.name(),
                v.max_scallop_mm
            );
            assert!(v.uncut_fraction - v.rest_fraction < 1e-3);
            match strategy {
                Strategy::Watershed => {
                    let regions = report.regions.clone().unwrap();
                    assert!(!regions.is_empty());
                    assert!(rects.iter().any(|r| r.region.is_some()));
                }
                _ => {
                    // One direction for every rectangle, no regions.
                    assert!(report.regions.is_none());
                    assert!(rects
                        .iter()
                        .all(|r| r.crossfeed == rects[0].crossfeed && r.region.is_none()));
                }
            }
        }
    }
    // bumps-hole's domain without feature boxes: the four rectangles round the hole.
    let m = samples::load_sample("bumps-hole").unwrap();
    let o = opts(Strategy::MultiRectangle);
    assert_eq!(
        plan::plan(&m, &o, &mut |_| true)
            .unwrap()
            .report(&o)
            .patches,
        4
    );
}

/// Strips between a feature box and the domain's edge or another box's side narrower than
/// `STRIP_SIDE_STEPS` side steps go to the box: at r 1, h 0.05 mm no rectangle of bumps,
/// bumps-hole or waves is narrower than that (4 × 0.63 mm). Before, bumps had a 0.9 ×
/// 48 mm strip along its left edge, cut in 3 passes of its length, and bumps-hole a
/// 1.3 mm one.
#[test]
fn no_rectangle_is_a_thin_strip_beside_a_feature_box() {
    for name in ["bumps", "bumps-hole", "waves"] {
        let m = samples::load_sample(name).unwrap();
        let o = opts(Strategy::Watershed);
        let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
        let cut = m.with_layout(planned.layout.clone().unwrap());
        // STRIP_SIDE_STEPS (4) flat side steps.
        let least = 4.0 * (8.0 * o.tool_radius_mm * o.scallop_mm).sqrt();
        for view in isoparametric::patch_views(&cut) {
            let [a, b] = sides_mm(&view);
            assert!(
                a.min(b) >= least,
                "{name}: rectangle {} is {a:.2} x {b:.2} mm",
                view.index
            );
        }
    }
}

/// Bike.tsm and its watershed and multi-rectangle plans at r 0.5, h 0.01 mm (the page's
/// tool and scallop).
fn bike_plans() -> (Model, Vec<(Strategy, PlanOptions, plan::Planned)>) {
    let m = public_tsm("Bike.tsm");
    let plans = [Strategy::Watershed, Strategy::MultiRectangle]
        .map(|strategy| {
            let o = opts(strategy).with_tool_radius(0.5).with_scallop(0.01);
            let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
            (strategy, o, planned)
        })
        .into();
    (m, plans)
}

/// Bike.tsm's domain is slit from one side to a third of the way: merged largest first,
/// its rest came in two full-height halves and a sliver below the slit, cut in 2 passes,
/// and the plan was 16 % longer (3 741 against 3 220 mm at r 0.5, h 0.01 mm). The merge
/// whose rectangles need the shorter cut is taken: no rectangle there is narrower than the
/// ball.
#[test]
fn a_slit_domain_is_cut_without_a_sliver() {
    let (m, plans) = bike_plans();
    for (strategy, o, planned) in plans {
        let cut = m.with_layout(planned.layout.clone().unwrap());
        for view in isoparametric::patch_views(&cut) {
            let [a, b] = sides_mm(&view);
            println!(
                "Bike.tsm {}: rectangle {} is {a:.2} x {b:.2} mm",
                strategy.name(),
                view.index
            );
            assert!(
                a.min(b) >= 2.0 * o.tool_radius_mm,
                "{}: rectangle {} is {a:.2} x {b:.2} mm",
                strategy.name(),
                view.index
            );
        }
    }
}

/// Eq. 21–22: each rectangle cut along its longer side reverses no more often in total than
/// the same rectangles all cut one way.
#[test]
fn the_direction_rule_reverses_least() {
    for name in ["bumps", "bumps-hole", "waves"] {
        let m = samples::load_sample(name).unwrap();
        let o = opts(Strategy::Watershed);
        let own = reversals(&m, &o);
        let mut all_u = o.clone();
        all_u.crossfeed = Some(Crossfeed::U);
        let mut all_v = o.clone();
        all_v.crossfeed = Some(Crossfeed::V);
        let (u, v) = (reversals(&m, &all_u), reversals(&m, &all_v));
        println!("{name}: reversals {own} per rectangle, {u} all-U, {v} all-V");
        assert!(own <= u && own <= v, "{name}: {own} vs {u} / {v}");
    }
}

/// Issue 15: the order's transit corners turned rectangles across to link them without a
/// retraction, against the direction rule: on bumps-hole (r 1, h 0.01 mm) a 3 × 43 mm
/// background strip was cut in 174 passes across instead of 14 along, and the plan
/// reversed 1 013 times against the multi-rectangle baseline's 628. Every rectangle now
/// keeps the rule's direction (a retraction where the corners cannot meet), which reverses
/// less than the baseline there (472 against 623; at h 0.05 mm 216 against 286) with the
/// path within 5 % of the baseline's (issue 15's target; +1.0 % and +3.2 %). Merged
/// largest first, the baseline's rest would reverse 357 and 166 times; both strategies
/// take the merge whose rectangles need the shorter cut, and for the baseline that is row
/// by row here (8 545 against 8 588 mm at h 0.05 mm).
#[test]
fn rectangles_keep_the_rule_direction_and_bumps_hole_reverses_less_than_the_baseline() {
    let m = samples::load_sample("bumps-hole").unwrap();
    let plan_with = |strategy| {
        let o = opts(strategy).with_scallop(0.01);
        let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
        let report = planned.report(&o);
        (planned, report)
    };
    let (planned, report) = plan_with(Strategy::Watershed);
    let cut = m.with_layout(planned.layout.clone().unwrap());
    let rects = report.rectangles.clone().unwrap();
    let views = isoparametric::patch_views(&cut);
    assert_eq!(rects.len(), views.len());
    for (view, rect) in views.iter().zip(&rects) {
        let [along_u, along_v] = sides_mm(view);
        // Passes along the longer side (crossfeed V: passes along u), where the sides differ
        // by more than the planner's three-line estimate can blur.
        if (along_u - along_v).abs() > 0.01 * along_u.max(along_v) {
            let longer_u = along_u > along_v;
            assert_eq!(
                rect.crossfeed == Crossfeed::V,
                longer_u,
                "rectangle {}: {along_u} x {along_v} mm",
                view.index
            );
        }
        // No feature rectangle is narrower than the ball (PolyBoundingBox left two
        // 0.9 x 0.5 mm boxes where the convex region juts out of its main box; with them the
        // region was cut in three, a 0.9 mm wide strip between two halves, and the domain
        // in 18 rectangles with 5 retractions and 19 569 mm of path).
        let shorter = along_u.min(along_v);
        if rect.region.is_some() {
            assert!(
                shorter >= 2.0,
                "feature rectangle {}: {shorter} mm",
                view.index
            );
        }
    }
    let (_, baseline) = plan_with(Strategy::MultiRectangle);
    println!(
        "bumps-hole r 1 h 0.01: watershed {} rectangles, {} reversals, {} retractions, {:.0} mm; multi-rectangle {} reversals, {} retractions, {:.0} mm",
        rects.len(),
        report.reversals,
        report.retractions,
        report.length_mm,
        baseline.reversals,
        baseline.retractions,
        baseline.length_mm
    );
    assert!(report.reversals < baseline.reversals);
    assert!(report.length_mm <= 1.05 * baseline.length_mm);
    let at_005 = |strategy| {
        let o = opts(strategy);
        plan::plan(&m, &o, &mut |_| true).unwrap().report(&o)
    };
    let (own, base) = (
        at_005(Strategy::Watershed),
        at_005(Strategy::MultiRectangle),
    );
    println!(
        "h 0.05: watershed {} reversals, {:.0} mm; multi-rectangle {} reversals, {:.0} mm",
        own.reversals, own.length_mm, base.reversals, base.length_mm
    );
    assert!(own.reversals < base.reversals);
    assert!(own.length_mm <= 1.05 * base.length_mm);
}

#[test]
fn the_same_input_gives_the_same_plan() {
    let m = samples::load_sample("bumps-hole").unwrap();
    let o = opts(Strategy::Watershed);
    let a = plan::plan(&m, &o, &mut |_| true).unwrap();
    let b = plan::plan(&m, &o, &mut |_| true).unwrap();
    assert_eq!(a.toolpath.moves, b.toolpath.moves);
    let (mut ra, mut rb) = (a.report(&o), b.report(&o));
    (ra.plan_ms, rb.plan_ms) = (0.0, 0.0);
    assert_eq!(
        serde_json::to_string(&ra).unwrap(),
        serde_json::to_string(&rb).unwrap()
    );
}

/// A model whose faces do not lie flat in one chart (the convex keycap: a cage round a
/// box, extraordinary points inside its domain) is refused with a message saying so; a
/// real file whose layout does lie flat (mouse.tsm) plans.
#[test]
fn a_domain_that_does_not_lie_flat_is_refused_with_the_reason() {
    let m = samples::load_sample("keycap-convex").unwrap();
    match plan::plan(&m, &opts(Strategy::Watershed), &mut |_| true) {
        Ok(_) => panic!("the keycap planned"),
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains("one parameter chart"), "{msg}");
        }
    }
    let mouse = public_tsm("mouse.tsm");
    let o = opts(Strategy::Watershed);
    let planned = plan::plan(&mouse, &o, &mut |_| true).unwrap();
    let r = planned.report(&o);
    assert!(r.regions.is_some_and(|x| !x.is_empty()));
    assert!(r.cl_points > 0);
}

/// Eq. 13–20: the T-mesh refined along every feature box side keeps its surface (1e-9 of
/// the model's size on a 41 × 41 grid of the chart) and every box side then runs along
/// face sides of the refined mesh (no face straddles it).
#[test]
fn refinement_along_the_boxes_keeps_the_surface_and_makes_box_sides_mesh_edges() {
    use tspath::plan::watershed::{features, map, DEFAULT_TOR};
    use tspath::surface::Surface;
    let m = samples::load_sample("bumps").unwrap();
    let f = features(&m, map::DEFAULT_PER_UNIT).unwrap();
    let (refined, refused) = f.refined_mesh(&m, DEFAULT_TOR).unwrap();
    assert!(refused.is_empty(), "refused {refused:?}");
    assert!(refined.vertex_count() > m.mesh.vertex_count());
    let surface = Surface::try_from_tmesh(&refined).unwrap();
    let size = m.surface.bbox().diagonal();
    let (lo, hi) = (
        f.map.origin,
        [
            f.map.origin[0] + (f.map.valid.nx - 1) as f64 * f.map.step[0],
            f.map.origin[1] + (f.map.valid.ny - 1) as f64 * f.map.step[1],
        ],
    );
    let (mut worst, mut n) = (0.0f64, 0);
    for i in 0..=40 {
        for j in 0..=40 {
            let s = lo[0] + (hi[0] - lo[0]) * (i as f64 + 0.5) / 41.0;
            let t = lo[1] + (hi[1] - lo[1]) * (j as f64 + 0.5) / 41.0;
            if let (Some(a), Some(b)) = (
                support::chart_point(&m.mesh, &m.surface, s, t),
                support::chart_point(&refined, &surface, s, t),
            ) {
                worst = worst.max((a - b).norm());
                n += 1;
            }
        }
    }
    assert!(n > 1000);
    assert!(worst <= 1e-9 * size, "surface moved {worst} mm");
    // Face rectangles of the refined mesh in the chart (face 0 placed as before).
    let rects = map::chart(&refined, &surface).unwrap().face_rects;
    let eps = 1e-9;
    let boxes = f.boxes(DEFAULT_TOR);
    for (_, _, b) in &boxes {
        for r in &rects {
            let overlaps_t = r[2] < b[3] - eps && r[3] > b[2] + eps;
            let overlaps_s = r[0] < b[1] - eps && r[1] > b[0] + eps;
            for x in [b[0], b[1]] {
                assert!(
                    !(overlaps_t && r[0] < x - eps && r[1] > x + eps),
                    "face {r:?} straddles s = {x}"
                );
            }
            for y in [b[2], b[3]] {
                assert!(
                    !(overlaps_s && r[2] < y - eps && r[3] > y + eps),
                    "face {r:?} straddles t = {y}"
                );
            }
        }
    }
    println!(
        "bumps: {} boxes, {} → {} control points, surface unchanged to {:.1e} of its size",
        boxes.len(),
        m.mesh.vertex_count(),
        refined.vertex_count(),
        worst / size
    );
}

/// Sum of the areas of flat triangles, `x y z` per corner (mm²).
fn triangles_area(t: &[f32]) -> f64 {
    t.chunks_exact(9)
        .map(|c| {
            let p = |k: usize| {
                tspath::geom::Vector3::new(
                    c[3 * k] as f64,
                    c[3 * k + 1] as f64,
                    c[3 * k + 2] as f64,
                )
            };
            0.5 * (p(1) - p(0)).cross(&(p(2) - p(0))).norm()
        })
        .sum()
}

/// The page's layer of regions and rectangles on `bumps-hole`: the fills tile the surface
/// (their area equals the model's tessellated area, which comes from the model's own
/// layout, not the rectangles), each region kind's fills equal the report's region areas,
/// and every rectangle's arrow points along the passes the plan cut there.
#[test]
fn the_rectangles_layer_tiles_the_surface_and_points_along_the_passes() {
    let m = samples::load_sample("bumps-hole").unwrap();
    let o = opts(Strategy::Watershed);
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let report = planned.report(&o);
    let layer = planned.watershed_layer.clone().unwrap();
    let rects = report.rectangles.clone().unwrap();
    assert_eq!(layer.rectangle_count(), rects.len());
    assert_eq!(layer.fill_kinds.len() * 9, layer.fills.len());
    let size = m.surface.bbox().diagonal();
    let t = m.tessellate(1e-4 * size);
    let model_area = triangles_area(
        &t.indices
            .iter()
            .flat_map(|&i| t.positions[3 * i as usize..3 * i as usize + 3].to_vec())
            .collect::<Vec<f32>>(),
    );
    let fills_area = triangles_area(&layer.fills);
    println!("fills {fills_area:.3} mm² vs the model's {model_area:.3} mm²");
    assert!((fills_area - model_area).abs() <= 2e-3 * model_area);
    let regions = report.regions.clone().unwrap();
    for (kind, code) in [
        (tspath::plan::watershed::FeatureKind::Convex, 1u8),
        (tspath::plan::watershed::FeatureKind::Concave, 2u8),
    ] {
        let reported: f64 = regions
            .iter()
            .filter(|r| r.kind == kind)
            .map(|r| r.area_mm2)
            .sum();
        let drawn: Vec<f32> = layer
            .fills
            .chunks_exact(9)
            .zip(&layer.fill_kinds)
            .filter(|(_, &k)| k == code)
            .flat_map(|(c, _)| c.to_vec())
            .collect();
        let drawn = triangles_area(&drawn);
        println!("{kind:?}: drawn {drawn:.3} mm², reported {reported:.3} mm²");
        assert!(reported > 0.0);
        assert!((drawn - reported).abs() <= 5e-3 * reported);
    }
    // Each arrow's shaft against the feed moves of its rectangle: the length-weighted mean
    // |cos| of the angle between them (1 along the passes; cutting across would give the
    // step-over's small share).
    let moves = &planned.toolpath.moves;
    for (k, shaft) in layer.arrows.chunks_exact(18).enumerate() {
        let a = tspath::geom::Vector3::new(
            (shaft[3] - shaft[0]) as f64,
            (shaft[4] - shaft[1]) as f64,
            (shaft[5] - shaft[2]) as f64,
        )
        .normalize();
        let (mut along, mut total) = (0.0, 0.0);
        for w in moves.windows(2) {
            if w[1].kind == tspath::plan::toolpath::MoveKind::Feed
                && w[0].patch == k as u32
                && w[1].patch == k as u32
            {
                let d = w[1].cc_point - w[0].cc_point;
                along += d.dot(&a).abs();
                total += d.norm();
            }
        }
        assert!(total > 0.0, "rectangle {k} has no cuts");
        println!(
            "rectangle {k}: {:?}, along the arrow {:.3}",
            rects[k].crossfeed,
            along / total
        );
        assert!(along / total > 0.8, "rectangle {k}: {}", along / total);
    }
}

/// Passes running past an extraordinary point keep the scallop: bumps-hole cut in four
/// rectangles whose long sides run through the hole's corners (the multi-rectangle
/// baseline's layout when its rest is merged largest first). The side step, sampled
/// evenly along the passes and densely only near their ends, missed the stretch next to
/// the corners, and the cut left 0.085 mm where 0.05 mm was asked; each patch's singular
/// points now add samples round them.
#[test]
fn passes_past_an_extraordinary_point_keep_the_scallop() {
    use tspath::layout::PatchLayout;
    use tspath::plan::watershed::map;
    let m = samples::load_sample("bumps-hole").unwrap();
    let chart = map::chart(&m.mesh, &m.surface).unwrap();
    // The chart is 14 × 12 knot units with the hole at [6, 8] × [5, 7].
    assert_eq!((chart.lo, chart.hi), ([0.0, 0.0], [14.0, 12.0]));
    let rects = [
        [0.0, 6.0, 0.0, 12.0],
        [8.0, 14.0, 0.0, 12.0],
        [6.0, 8.0, 0.0, 5.0],
        [6.0, 8.0, 7.0, 12.0],
    ];
    let layout = PatchLayout::from_chart_rects(&m.surface, &chart.placements, &rects).unwrap();
    // The long rectangles hold the hole's corners on their sides facing it; the short
    // ones at their corners.
    for (k, expected) in [
        (0, [[1.0, 5.0 / 12.0], [1.0, 7.0 / 12.0]]),
        (1, [[0.0, 5.0 / 12.0], [0.0, 7.0 / 12.0]]),
        (2, [[0.0, 1.0], [1.0, 1.0]]),
        (3, [[0.0, 0.0], [1.0, 0.0]]),
    ] {
        let mut got = layout.patches[k].singular_points(&m.surface);
        got.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        assert_eq!(got.len(), 2, "patch {k}: {got:?}");
        for (g, e) in got.iter().zip(expected) {
            assert!(
                (g[0] - e[0]).abs() < 1e-12 && (g[1] - e[1]).abs() < 1e-12,
                "patch {k}: {got:?}"
            );
        }
    }
    let cut = m.with_layout(layout);
    let mut o = opts(Strategy::Isoparametric);
    o.crossfeed = Some(Crossfeed::U);
    let planned = plan::plan(&cut, &o, &mut |_| true).unwrap();
    let v = simulated(&cut, &planned, &o);
    println!(
        "bumps-hole in four rectangles: max scallop {:.4} mm (bound {:.4} mm) at {:?}",
        v.max_scallop_mm, v.error_bound_mm, v.max_scallop_at_mm
    );
    assert!(v.error_bound_mm <= 0.25 * o.scallop_mm);
    assert!(v.max_scallop_mm <= o.scallop_mm, "{}", v.max_scallop_mm);
    assert_eq!(v.gouge_count, 0);
}

/// A seam between two rectangles whose passes both run along it is cut once where the
/// surface is smooth across it: the rectangle whose side lies within its neighbours' leaves
/// its pass there to them (`rects::shared_seams`), and its first pass is a side step in.
/// Across a crease each side keeps its own, as the balls on it set by the two sides'
/// normals stand apart. On bumps, bumps-hole, waves (r 1, h 0.05 mm) and mouse.tsm (r 0.5,
/// h 0.01 mm) every seam one of whose sides lies within the other's has feed moves of
/// exactly one of the two (on the samples, with a pass of each, as before, the cut was
/// 139, 184 and 80 mm longer); face.tsm (r 0.5, h 0.05 mm) has creased ones too, cut from
/// both sides. The smoothness here is measured afresh: points of one side located on the
/// other by a search along it, and their normals compared. The
/// simulation of `watershed_and_multi_rectangle_plans_keep_the_scallop_without_gouges`
/// checks the scallop beside the seams.
#[test]
fn a_smooth_seam_between_rectangles_cut_the_same_way_is_cut_once() {
    use tspath::geom::Point3;
    use tspath::layout::{ConnectionKind, Patch};
    use tspath::plan::toolpath::MoveKind;
    use tspath::plan::watershed::plan::SEAM_BALL_SHARE;
    // Point of `side` (0 v = 0, 1 u = 1, 2 v = 1, 3 u = 0) at `x` along it.
    fn on_side(side: u8, x: f64) -> (f64, f64) {
        match side {
            0 => (x, 0.0),
            1 => (1.0, x),
            2 => (x, 1.0),
            _ => (0.0, x),
        }
    }
    let cases = [
        ("bumps", samples::load_sample("bumps").unwrap(), 1.0, 0.05),
        (
            "bumps-hole",
            samples::load_sample("bumps-hole").unwrap(),
            1.0,
            0.05,
        ),
        ("waves", samples::load_sample("waves").unwrap(), 1.0, 0.05),
        ("mouse.tsm", public_tsm("mouse.tsm"), 0.5, 0.01),
        ("face.tsm", public_tsm("face.tsm"), 0.5, 0.05),
    ];
    for (name, m, r, h) in cases {
        let o = opts(Strategy::Watershed)
            .with_tool_radius(r)
            .with_scallop(h);
        let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
        let report = planned.report(&o);
        let rects = report.rectangles.clone().unwrap();
        let layout = planned.layout.clone().unwrap();
        let path = &planned.toolpath;
        let cut_on = |k: u32, side: u8| {
            let (axis, at) = match side {
                0 => (1, 0.0),
                1 => (0, 1.0),
                2 => (1, 1.0),
                _ => (0, 0.0),
            };
            path.moves
                .iter()
                .zip(&path.params)
                .any(|(mv, p)| mv.kind == MoveKind::Feed && mv.patch == k && p[axis] == at)
        };
        // Sides 0 and 2 run along u: the passes of a rectangle stepping across v.
        let along =
            |k: u32, side: u8| (rects[k as usize].crossfeed == Crossfeed::V) == (side % 2 == 0);
        // Where `a`'s side `sa`, at `x` along it, lies on `b`'s side `sb`: the point of
        // `b`'s side nearest it (from 64 samples and a ternary search), if within 1e-6 mm.
        let locate = |pa: &Patch, sa: u8, pb: &Patch, sb: u8, x: f64| -> Option<f64> {
            let (u, v) = on_side(sa, x);
            let p: Point3 = pa.subs(&m.surface, u, v);
            let d = |y: f64| {
                let (u, v) = on_side(sb, y);
                (pb.subs(&m.surface, u, v) - p).norm()
            };
            let k = (0..=64)
                .min_by(|&i, &j| d(i as f64 / 64.0).total_cmp(&d(j as f64 / 64.0)))
                .unwrap();
            let (mut lo, mut hi) = (
                (k as f64 - 1.0).max(0.0) / 64.0,
                (k as f64 + 1.0).min(64.0) / 64.0,
            );
            for _ in 0..100 {
                let (y1, y2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                if d(y1) < d(y2) {
                    hi = y2;
                } else {
                    lo = y1;
                }
            }
            let y = 0.5 * (lo + hi);
            (d(y) <= 1e-6).then_some(y)
        };
        // Largest difference of the unit normals across the seam, at points of `a`'s side
        // that lie on `b`'s.
        let kink = |pa: &Patch, sa: u8, pb: &Patch, sb: u8| -> f64 {
            let mut worst: f64 = 0.0;
            for i in 0..=8 {
                let x = i as f64 / 8.0;
                let Some(y) = locate(pa, sa, pb, sb, x) else {
                    continue;
                };
                let ((ua, va), (ub, vb)) = (on_side(sa, x), on_side(sb, y));
                let (na, nb) = (
                    pa.normal(&m.surface, ua, va).unwrap(),
                    pb.normal(&m.surface, ub, vb).unwrap(),
                );
                worst = worst.max((na - nb).norm());
            }
            worst
        };
        // Whether `a`'s side lies within `b`'s: both its ends lie on it.
        let within = |pa: &Patch, sa: u8, pb: &Patch, sb: u8| {
            [0.0, 1.0]
                .iter()
                .all(|&x| locate(pa, sa, pb, sb, x).is_some())
        };
        let (mut once, mut partial, mut creased) = (0, 0, 0);
        for c in &layout.connections {
            let Some((sa, sb)) = c.sides.filter(|_| c.kind == ConnectionKind::Boundary) else {
                continue;
            };
            if !(along(c.a, sa) && along(c.b, sb)) {
                continue;
            }
            let (pa, pb) = (&layout.patches[c.a as usize], &layout.patches[c.b as usize]);
            let k = kink(pa, sa, pb, sb).max(kink(pb, sb, pa, sa));
            let (a, b) = (cut_on(c.a, sa), cut_on(c.b, sb));
            let seam = format!(
                "{name}: rectangles {} and {} (kink {k:.3}): {a} {b}",
                c.a, c.b
            );
            // Smooth seams differ by 1e-15, creases on face.tsm by 0.035 and more; the
            // planner's rule is on the balls set by the two normals.
            if r * k > SEAM_BALL_SHARE * h {
                creased += 1;
                assert!(a && b, "a creased seam is cut from both sides: {seam}");
            } else if within(pa, sa, pb, sb) || within(pb, sb, pa, sa) {
                // (A rectangle of two passes between two such seams leaves one of them.)
                let narrow = rects[c.a as usize].passes.min(rects[c.b as usize].passes) <= 2;
                once += usize::from(!narrow);
                assert!(a != b || narrow, "a smooth seam is cut once: {seam}");
            } else {
                // Each side runs on past the other: one or both keep their passes.
                partial += 1;
                assert!(a || b, "a seam is cut: {seam}");
            }
        }
        println!(
            "{name}: seams between passes the same way: {once} smooth, one within the other, \
             cut once; {partial} smooth, overlapping; {creased} creased, cut from both sides"
        );
        assert!(once >= 2, "{name}: {once}");
        if name == "face.tsm" {
            assert!(creased >= 1);
        }
    }
}

/// Where a rectangle leaves the pass on its starting seam to a neighbour, the transit from
/// the previous rectangle's finishing corner runs along the side to the first pass, a side
/// step in, with the chordal tolerance of the links between passes; and where it leaves
/// the pass on its finishing seam, the path runs along the side to the finishing corner.
/// Straight, that transit cut 0.0032 mm into face.tsm's convex surface at (8.34, 27.52,
/// 7.21) mm (r 1, h 0.05 mm; the page showed the gouge). The simulation finds no gouge
/// beyond its tolerance.
#[test]
fn transits_past_a_shared_seam_follow_the_side() {
    let m = public_tsm("face.tsm");
    let o = opts(Strategy::Watershed);
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let v = simulated(&m, &planned, &o);
    println!(
        "face.tsm watershed: max gouge {:.4} mm at {:?} (tolerance {:.4} mm, bound {:.4} mm), {} samples beyond",
        v.max_gouge_mm, v.max_gouge_at_mm, v.gouge_tolerance_mm, v.gouge_error_bound_mm, v.gouge_count
    );
    assert!(v.error_bound_mm <= 0.25 * o.scallop_mm);
    assert_eq!(v.gouge_count, 0);
    assert!(v.max_scallop_mm <= o.scallop_mm, "{}", v.max_scallop_mm);
}

/// face.tsm's watershed plan at r 0.5 mm, h 0.01 mm: a move left a point on a convex crease
/// (its centre set by one side's normal) for one 0.95 mm along the other side, and cut the
/// crease 0.0029 mm deep a little way along (the simulation: 7 samples beyond the 0.002 mm
/// tolerance); a 0.45 mm move across a crease between two faces cut it 0.0021 mm deep. The
/// end normals turned too little for the pivot estimate to split either. The gouge check
/// now measures each move against its ends' contact points and the points where it passes
/// from one face to another. Checked here on every move, exactly, against a tessellation
/// (not the gouge check's own search): no move comes nearer its triangles than the radius
/// less the overcut limit and the tessellation's deviation, so none cuts the surface deeper
/// than the limit and twice that deviation (0.00042 mm). Before, one move did (and three
/// cut 0.0015 mm and more).
#[test]
fn moves_leaving_or_crossing_a_crease_do_not_cut_it() {
    let m = public_tsm("face.tsm");
    let o = opts(Strategy::Watershed)
        .with_tool_radius(0.5)
        .with_scallop(0.01);
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let triangles = SurfaceDistance::new(&m, 2e-4);
    let near = o.tool_radius_mm - o.overcut_mm() - triangles.tolerance_mm;
    let moves = &planned.toolpath.moves;
    let cutting_in: Vec<usize> = (1..moves.len())
        .filter(|&i| {
            let (a, b) = (&moves[i - 1], &moves[i]);
            a.kind.on_surface()
                && b.kind.on_surface()
                && triangles.segment_within(&a.cl_point, &b.cl_point, near)
        })
        .collect();
    println!(
        "face.tsm watershed r 0.5 h 0.01: {} moves, {} cut points added by the gouge check; \
         tessellation within {:.5} mm; {} moves nearer the triangles than {near:.5} mm",
        moves.len(),
        planned.gouge.inserted,
        triangles.tolerance_mm,
        cutting_in.len()
    );
    assert!(triangles.tolerance_mm < 0.25 * o.overcut_mm());
    assert!(
        cutting_in.is_empty(),
        "{:?}",
        &cutting_in[..cutting_in.len().min(5)]
    );
}

/// The simulation proves Bike.tsm's watershed and multi-rectangle plans at r 0.5, h 0.01 mm:
/// their layout has a rectangle 0.017-0.024 mm wide and 3.9 mm long, and its face grid had
/// two samples across it (its two sides) at any sample count, which held the plans' error
/// bound at 0.0066 mm (the sliver's own 0.0075 mm) with 8 M samples, the most a plan asks:
/// unproven. Faces with a side of two samples now take the spacing of the rest across and
/// along; the bound is a quarter of the scallop within the plan's samples, and the scallop
/// and gouges are within the request and the tolerance.
#[test]
fn a_sliver_rectangle_is_sampled_across_and_the_plan_is_proven() {
    let (m, plans) = bike_plans();
    for (strategy, o, planned) in plans {
        let v = simulated(&m, &planned, &o);
        println!(
            "Bike.tsm {strategy:?} r 0.5 h 0.01: {} samples, error bound {:.5} mm (target \
             {:.5}), max scallop {:.5} mm, max gouge {:.5} mm",
            v.samples,
            v.error_bound_mm,
            verify::PLAN_BOUND_SHARE * o.scallop_mm,
            v.max_scallop_mm,
            v.max_gouge_mm
        );
        assert!(v.error_bound_mm <= verify::PLAN_BOUND_SHARE * o.scallop_mm);
        assert!(v.max_scallop_mm <= o.scallop_mm);
        assert!(v.max_gouge_mm <= o.overcut_mm());
        assert_eq!(v.gouge_count, 0);
    }
}
