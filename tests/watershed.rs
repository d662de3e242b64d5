//! Watershed feature regions and optimised multi-rectangles (Liu et al. 2020; issue 15):
//! plans on the feature samples checked by the cutting simulation, the direction rule,
//! the baseline's single direction, determinism, and the error on a domain that does not
//! lie flat.

mod support;

use support::public_tsm;
use tspath::model::samples;
use tspath::plan::corners::Crossfeed;
use tspath::plan::{self, PlanOptions, Strategy};
use tspath::verify;
use tspath::Model;

fn opts(strategy: Strategy) -> PlanOptions {
    PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.05)
        .with_strategy(strategy)
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
            let v = verify::verify_plan(
                &m,
                &planned,
                &o,
                Some(200_000),
                verify::PLAN_VERIFY_MAX_SAMPLES,
            )
            .unwrap();
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
