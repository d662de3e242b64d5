//! The patch-ordered non-retraction isoparametric planner (Shang et al. 2020): paths without
//! retractions on the sample models, zig-zags ending at their chosen corners, chords within
//! the tolerance, the patch order against brute force, transit corners through a corner
//! connection, side steps against eq. 5 on exact planes and cylinders, and collision-free
//! tool axes checked by an independent distance test, also while the axis turns between cut
//! points.

use crate::support;

use support::{cylinder_distance, dense_samples, tool_clearance, SampleGrid};
use tspath::geom::{Point3, Vector3};
use tspath::model::samples;
use tspath::plan::corners::{self, corner_uv, Crossfeed};
use tspath::plan::isoparametric::{self, patch_costs, ParamSurface, PatchView};
use tspath::plan::order::{self, CostMatrix};
use tspath::plan::{MoveKind, PlanOptions, Toolpath};
use tspath::Model;

fn paper() -> PlanOptions {
    PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.005)
        .with_chordal(0.001)
}

/// Checks the path's structure on `model`; returns (CL points, retractions).
fn check_structure(name: &str, model: &Model, path: &Toolpath, opts: &PlanOptions) {
    let report = path.report("isoparametric", opts.feed_mm_min, opts.plunge_feed_mm_min);
    assert_eq!(report.retractions, 0, "{name}: retractions");
    // Every patch once.
    let mut seen: Vec<u32> = path.runs.iter().map(|r| r.patch).collect();
    seen.sort_unstable();
    assert_eq!(
        seen,
        (0..model.layout.len() as u32).collect::<Vec<_>>(),
        "{name}: every patch once"
    );
    let size = model.surface.bbox().diagonal();
    for (k, run) in path.runs.iter().enumerate() {
        let view = PatchView {
            index: run.patch as usize,
            patch: &model.layout.patches[run.patch as usize],
            surface: &model.surface,
            side: model.tool_side(),
        };
        let corner = |c: u8| {
            let (u, v) = corner_uv(c);
            view.subs(u as f64, v as f64)
        };
        let first = path.moves[run.first_move];
        let last = path.moves[run.last_move];
        assert!(
            (first.cc_point - corner(run.start_corner)).norm() < 1e-9 * size,
            "{name}: run {k} starts at its corner"
        );
        assert!(
            (last.cc_point - corner(run.finish_corner)).norm() < 1e-9 * size,
            "{name}: run {k} ends at its corner"
        );
        assert_ne!(run.start_corner, run.finish_corner);
        if k + 1 < path.runs.len() {
            // Joined at the shared transit corner: the next run starts where this one ended.
            let next = path.moves[path.runs[k + 1].first_move];
            assert!(
                (next.cc_point - last.cc_point).norm() < 1e-9 * size,
                "{name}: transit {k}"
            );
            assert!(!path.runs[k + 1].retract_before);
        }
        assert!(
            run.scallop_used_mm <= opts.scallop_mm && run.scallop_used_mm > 0.5 * opts.scallop_mm
        );
    }
    // Chords within the tolerance: the surface half-way (in parameters) between consecutive
    // cutting points lies within the chordal tolerance of the chord.
    let mut worst: f64 = 0.0;
    for i in 1..path.moves.len() {
        let (a, b) = (&path.moves[i - 1], &path.moves[i]);
        if b.kind != MoveKind::Feed || a.patch != b.patch || a.line != b.line {
            continue;
        }
        let (pa, pb) = (path.params[i - 1], path.params[i]);
        let patch = &model.layout.patches[b.patch as usize];
        let mid = patch.subs(&model.surface, 0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]));
        let ab = b.cc_point - a.cc_point;
        let t = ((mid - a.cc_point).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
        worst = worst.max((mid - (a.cc_point + ab * t)).norm());
    }
    println!(
        "{name}: {} CL points, {} patches, max predicted scallop {:.5} mm, worst mid-chord deviation {:.5} mm, length {:.1} mm",
        report.cl_points, report.patches, report.max_predicted_scallop_mm, worst, report.length_mm
    );
    assert!(
        worst <= opts.chordal_mm * (1.0 + 1e-6),
        "{name}: chord deviation {worst}"
    );
    assert!(
        report.max_predicted_scallop_mm <= opts.scallop_mm * (1.0 + 1e-9),
        "{name}: predicted scallop"
    );
}

#[test]
fn keycaps_at_the_papers_settings_need_no_retraction() {
    for name in ["keycap-convex", "keycap-concave"] {
        let m = samples::load_sample(name).unwrap();
        let planned = isoparametric::plan(&m, &paper(), &mut |_| true).unwrap();
        assert_eq!(planned.forced_retractions, 0);
        check_structure(name, &m, &planned.toolpath, &paper());
    }
}

#[test]
fn face_and_bike_plan_without_a_forced_retraction() {
    // Issue 20: at the page's defaults face.tsm was laid out in 135 patches and forced into
    // retractions (2 on main before the cut at concave corners; 3 when the issue was filed),
    // Bike.tsm in 81 and forced into 1. Their 13 and 5 patches now meet corner to corner and
    // the patch order links them all on the surface.
    for file in ["face.tsm", "Bike.tsm"] {
        let m = support::public_tsm(file);
        let opts = PlanOptions::default();
        let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
        let report = planned.report(&opts);
        println!(
            "{file}: {} patches, {} retractions, {} reversals, cutting {:.0} mm, {:.2} min",
            report.patches,
            report.retractions,
            report.reversals,
            report.cutting_length_mm,
            report.machining_time_min
        );
        assert_eq!(planned.forced_retractions, 0, "{file}");
        assert_eq!(report.retractions, 0, "{file}");
    }
}

#[test]
fn t_junction_sample_needs_no_retraction_and_the_three_axis_head_leaves_its_underside() {
    // The closed head planned three-axis: its underside cannot be reached from above. The
    // plan leaves it out, says so as a problem with the area and why, and the path cuts
    // only what a vertical tool reaches (issue 13).
    let mut opts = PlanOptions::default()
        .with_tool_radius(2.0)
        .with_scallop(0.05)
        .with_chordal(0.005);
    opts.max_tilt_deg = 0.0;
    let head = samples::load_sample("head").unwrap();
    let planned = isoparametric::plan(&head, &opts, &mut |_| true).unwrap();
    assert!(
        planned.axes.blocked > 0,
        "the holder hits the head from below"
    );
    let report = planned.report(&opts);
    assert_eq!(report.status, tspath::plan::PlanStatus::PlannedWithProblems);
    let area = |kind: &str| -> f64 {
        report
            .rest
            .iter()
            .filter(|g| {
                format!(
                    "rest_{}",
                    serde_json::to_value(g.why).unwrap().as_str().unwrap()
                ) == kind
            })
            .map(|g| g.area_mm2)
            .sum()
    };
    let (away, hits) = (area("rest_faces_away"), area("rest_tool_hits"));
    println!(
        "head three-axis: {} CL points, rest {:.0} mm² (faces away {away:.0}, tool hits {hits:.0}) in {} regions, {} retractions",
        report.cl_points,
        report.unreachable_area_mm2,
        report.rest.len(),
        report.retractions
    );
    assert!(report.problems.iter().any(|p| p.kind == "rest_faces_away"));
    assert!(away > 1000.0 && hits > 0.0);
    assert!((away + hits - report.unreachable_area_mm2).abs() < 1e-6 * report.unreachable_area_mm2);
    // Every cut point kept has a usable vertical tool: its surface faces up.
    for m in &planned.toolpath.moves {
        if m.kind.on_surface() {
            let n = (m.cl_point - m.cc_point).normalize();
            assert!(n.z > 0.0, "a cut point facing down is still cut: {n}");
        }
    }
    let t = samples::load_sample("tjunction").unwrap();
    let opts = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.01);
    let planned = isoparametric::plan(&t, &opts, &mut |_| true).unwrap();
    check_structure("tjunction", &t, &planned.toolpath, &opts);
    assert_eq!(
        planned.report(&opts).status,
        tspath::plan::PlanStatus::Planned
    );
}

fn brute_force(m: &CostMatrix, start: usize, finish: Option<usize>) -> f64 {
    fn rec(
        m: &CostMatrix,
        order: &mut Vec<usize>,
        used: &mut Vec<bool>,
        finish: Option<usize>,
        best: &mut f64,
    ) {
        if order.len() == m.n {
            if finish.is_none_or(|f| *order.last().unwrap() == f) {
                *best = best.min(m.path_cost(order));
            }
            return;
        }
        for j in 0..m.n {
            if !used[j] {
                used[j] = true;
                order.push(j);
                rec(m, order, used, finish, best);
                order.pop();
                used[j] = false;
            }
        }
    }
    let mut used = vec![false; m.n];
    used[start] = true;
    let mut best = f64::INFINITY;
    rec(m, &mut vec![start], &mut used, finish, &mut best);
    best
}

/// Patch adjacency of a set of unit squares on a grid (boundary and corner connections).
fn squares(cells: &[(i32, i32)]) -> CostMatrix {
    let mut m = CostMatrix::new(cells.len());
    for (i, a) in cells.iter().enumerate() {
        for (j, b) in cells.iter().enumerate().skip(i + 1) {
            let (dx, dy) = ((a.0 - b.0).abs(), (a.1 - b.1).abs());
            if dx + dy == 1 {
                m.connect(i, j, order::BOUNDARY_COST);
            } else if dx == 1 && dy == 1 {
                m.connect(i, j, order::CORNER_COST);
            }
        }
    }
    m
}

#[test]
fn patch_order_equals_brute_force() {
    let grid = |w: i32, h: i32| (0..w * h).map(|k| (k % w, k / w)).collect::<Vec<_>>();
    let mut layouts: Vec<(String, CostMatrix)> = vec![
        ("grid 2x2".into(), squares(&grid(2, 2))),
        ("grid 3x3".into(), squares(&grid(3, 3))),
        ("grid 4x2".into(), squares(&grid(4, 2))),
        (
            "L".into(),
            squares(&[(0, 0), (1, 0), (2, 0), (0, 1), (0, 2), (0, 3)]),
        ),
        (
            "ring".into(),
            squares(&[
                (0, 0),
                (1, 0),
                (2, 0),
                (2, 1),
                (2, 2),
                (1, 2),
                (0, 2),
                (0, 1),
            ]),
        ),
        (
            "plus".into(),
            squares(&[(1, 0), (0, 1), (1, 1), (2, 1), (1, 2)]),
        ),
        (
            "diagonal".into(),
            squares(&[(0, 0), (1, 1), (2, 2), (2, 1), (0, 1)]),
        ),
    ];
    for name in ["keycap-convex", "keycap-concave", "head", "bumps-hole"] {
        layouts.push((
            name.into(),
            patch_costs(&samples::load_sample(name).unwrap()),
        ));
    }
    let v5 = tspath::io::load(valence5().as_bytes(), "v5").unwrap();
    layouts.push(("valence 5".into(), patch_costs(&v5)));
    for (name, m) in &layouts {
        assert!(m.n <= 9);
        for start in 0..m.n.min(3) {
            for finish in [None, Some(m.n - 1)] {
                if finish == Some(start) {
                    continue;
                }
                let got = order::patch_order(m, start, finish);
                assert_eq!(got[0], start);
                if let Some(f) = finish {
                    assert_eq!(*got.last().unwrap(), f);
                }
                let mut sorted = got.clone();
                sorted.sort_unstable();
                assert_eq!(
                    sorted,
                    (0..m.n).collect::<Vec<_>>(),
                    "{name}: a permutation"
                );
                let bf = brute_force(m, start, finish);
                assert!(
                    (m.path_cost(&got) - bf).abs() < 1e-9,
                    "{name} from {start} to {finish:?}: {} vs brute force {bf}",
                    m.path_cost(&got)
                );
            }
        }
    }
}

fn valence5() -> String {
    let mut s = String::from("v 0 0 0\n");
    for k in 0..5 {
        let a = k as f64 * std::f64::consts::TAU / 5.0;
        let b = a + std::f64::consts::TAU / 10.0;
        s += &format!(
            "v {} {} 0\nv {} {} 0\n",
            a.cos(),
            a.sin(),
            1.8 * b.cos(),
            1.8 * b.sin()
        );
    }
    for k in 0..5 {
        s += &format!(
            "f 1 {} {} {}\n",
            2 + 2 * k,
            3 + 2 * k,
            2 + 2 * ((k + 1) % 5)
        );
    }
    s
}

#[test]
fn a_corner_connection_is_used_when_the_layout_demands_it() {
    // The paper's fig. 5(c)(d) kind: a centre patch with three arms (left, top, right);
    // no order visits all four through shared sides, so one move goes through a shared
    // corner, and the transit corners must put both patches' ends on that corner.
    let cells = [(0, 1), (1, 1), (1, 2), (2, 1)];
    let m = squares(&cells);
    let order = order::patch_order(&m, 0, None);
    let corner_moves = order
        .windows(2)
        .filter(|w| m.get(w[0], w[1]) == order::CORNER_COST)
        .count();
    assert_eq!(corner_moves, 1, "{order:?}");
    let id = |x: i32, y: i32| (y * 4 + x) as u32;
    let ids: Vec<[u32; 4]> = cells
        .iter()
        .map(|&(x, y)| [id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)])
        .collect();
    let (transits, retractions) =
        corners::select(&order, &ids, &[Crossfeed::U; 4], false, None, None);
    assert_eq!(retractions, 0);
    for w in transits.windows(2) {
        assert_eq!(
            ids[w[0].patch][w[0].finish_corner as usize],
            ids[w[1].patch][w[1].start_corner as usize]
        );
        assert_ne!(w[0].start_corner, w[0].finish_corner);
    }
    // Strict: every patch keeps the crossfeed given, so its ends differ across its passes
    // (in u for crossfeed U, in v for V), and the tool retracts exactly where a patch's
    // start is not the previous finish: once with crossfeed U on this order, never with V.
    for (given, expected) in [(Crossfeed::U, 1), (Crossfeed::V, 0)] {
        let (transits, retractions) = corners::select(&order, &ids, &[given; 4], true, None, None);
        for t in &transits {
            assert_eq!(t.crossfeed, given);
            assert!(corners::crossfeeds(t.start_corner, t.finish_corner).contains(&given));
        }
        let apart = transits
            .windows(2)
            .filter(|w| {
                ids[w[0].patch][w[0].finish_corner as usize]
                    != ids[w[1].patch][w[1].start_corner as usize]
            })
            .count();
        assert_eq!(apart, retractions, "{given:?}");
        assert_eq!(retractions, expected, "{given:?}");
        assert_eq!(
            transits.iter().filter(|t| t.retract_before).count(),
            retractions
        );
        println!("strict {given:?}: {retractions} retraction(s)");
    }
}

/// Spacing (mm, along the surface) between the first passes of a single-patch model, and
/// the scallop the planner used.
fn first_spacing(m: &Model, r: f64, h: f64) -> (f64, f64) {
    let mut opts = PlanOptions::default()
        .with_tool_radius(r)
        .with_scallop(h)
        .with_chordal(0.002);
    opts.crossfeed = Some(Crossfeed::U);
    let path = isoparametric::plan_zigzag(m, &opts, &mut |_| true).unwrap();
    let run = path.runs[0];
    // The passes are lines u = const; find two adjacent ones by their params.
    let mut us: Vec<f64> = path.params[run.first_move..=run.last_move]
        .iter()
        .map(|p| p[0])
        .collect();
    us.sort_by(f64::total_cmp);
    us.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let p = &m.layout.patches[0];
    let w0 = us[0];
    let w1 = us[1];
    // Arc length across at v = 0.5 between the first two passes.
    let mut len = 0.0;
    let steps = 200;
    let mut prev = p.subs(&m.surface, w0, 0.5);
    for k in 1..=steps {
        let w = w0 + (w1 - w0) * k as f64 / steps as f64;
        let q = p.subs(&m.surface, w, 0.5);
        len += (q - prev).norm();
        prev = q;
    }
    (len, run.scallop_used_mm)
}

#[test]
fn side_step_matches_eq5_on_plane_and_cylinders() {
    let (r, h) = (1.0, 0.01);
    let rr: f64 = 10.0;
    let plane = Model::try_new("plane", "test", "mm", samples::plane_patch(20.0).unwrap()).unwrap();
    let convex = Model::try_new(
        "cyl",
        "test",
        "mm",
        samples::cylinder_patch(rr, 20.0, 90.0, false).unwrap(),
    )
    .unwrap();
    let concave = Model::try_new(
        "trough",
        "test",
        "mm",
        samples::cylinder_patch(rr, 20.0, 90.0, true).unwrap(),
    )
    .unwrap();
    // Eq. 5: g = sqrt(8 h r R / (R + sign·r)), sign 0 flat, +1 convex, −1 concave.
    for (m, sign) in [(&plane, 0.0), (&convex, 1.0), (&concave, -1.0)] {
        let (g, h_used) = first_spacing(m, r, h);
        // On a cylinder the planner's step is an arc across; eq. 5 gives the chord-like
        // side step between contact points, the same to O(g³/R²).
        let want = if sign == 0.0 {
            (8.0 * h_used * r).sqrt()
        } else {
            (8.0 * h_used * r * rr / (rr + sign * r)).sqrt()
        };
        println!(
            "{}: side step {g:.6} mm, eq. 5 gives {want:.6} mm at h = {h_used:.6} mm",
            m.name
        );
        // The planner takes the smallest step needed on this pass, half-way and at the next
        // (the rational patch's speed varies across), so it may be a little shorter, never
        // longer.
        assert!(
            g <= want * (1.0 + 1e-6) && g >= 0.98 * want,
            "{}: {g} vs {want}",
            m.name
        );
    }
}

/// Smallest clearance (mm) of the shank above the flutes and the holder from dense surface
/// samples, computed here without the planner's index.
fn clearance(samples: &[Point3], c: &Point3, axis: &Vector3, o: &PlanOptions) -> f64 {
    let (f, ls, lh) = (o.flute_length(), o.shank_length_mm, o.holder_length_mm);
    let mut best = f64::INFINITY;
    for p in samples {
        for (a0, a1, rad) in [(f, ls, o.shank_radius()), (ls, ls + lh, o.holder_radius_mm)] {
            let dist = cylinder_distance(p, &(c + axis * a0), axis, a1 - a0, rad);
            best = best.min(dist);
        }
    }
    best
}

#[test]
fn tool_axis_clears_shank_and_holder_and_is_vertical_where_it_can_be() {
    let m = samples::load_sample("keycap-concave").unwrap();
    // A fat shank close above a short flute: near the cavity walls it must lean away.
    let mut opts = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.05)
        .with_chordal(0.005);
    opts = opts.with_holder(1.0, 15.0, 6.0, 30.0);
    opts.flute_length_mm = Some(1.0);
    // The point-by-point rule; spreading large turns along the passes leans the axis
    // earlier on purpose (tests/axis_steps.rs), so it is out of the way here.
    opts.max_axis_step_deg = 45.0;
    let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
    let path = &planned.toolpath;
    let t = m.tessellate(0.002);
    let mut samples: Vec<Point3> = t
        .positions
        .chunks(3)
        .map(|p| Point3::new(p[0] as f64, p[1] as f64, p[2] as f64))
        .collect();
    // Densify: triangle centres and edge midpoints.
    for tri in t.indices.chunks(3) {
        let q: Vec<Point3> = tri.iter().map(|&i| samples[i as usize]).collect();
        samples.push(Point3::from(
            (q[0].coords + q[1].coords + q[2].coords) / 3.0,
        ));
        samples.push(Point3::from((q[0].coords + q[1].coords) / 2.0));
    }
    let mut tilted = 0;
    let mut min_clear = f64::INFINITY;
    let stride = 7;
    for (i, mv) in path.moves.iter().enumerate() {
        if !matches!(mv.kind, MoveKind::Feed | MoveKind::Link) || i % stride != 0 {
            continue;
        }
        let c = clearance(&samples, &mv.cl_point, &mv.tool_axis, &opts);
        min_clear = min_clear.min(c);
        assert!(c > 0.0, "move {i}: the tool hits the model ({c} mm)");
        if (mv.tool_axis - Vector3::z()).norm() > 1e-12 {
            tilted += 1;
            // Only where +Z would not have been clear (within the planner's sampling margin).
            let cz = clearance(&samples, &mv.cl_point, &Vector3::z(), &opts);
            assert!(cz < 0.2, "move {i}: tilted although +Z clears by {cz} mm");
        }
    }
    let report = planned.report(&opts);
    println!(
        "keycap-concave, shank r 1 mm: {tilted} sampled points tilted, least clearance {min_clear:.4} mm, largest axis step {:.2}°",
        report.max_axis_step_deg
    );
    assert!(tilted > 0, "the fat shank needs tilting near the walls");
    assert_eq!(report.retractions, 0);
}

#[test]
fn lead_and_tilt_incline_the_axis_from_the_normal() {
    let m = samples::load_sample("dome").unwrap();
    for (lead, tilt) in [(10.0f64, 0.0f64), (0.0, 15.0), (5.0, 5.0)] {
        let mut opts = PlanOptions::default()
            .with_tool_radius(2.0)
            .with_scallop(0.05)
            .with_lead_tilt(lead, tilt);
        // Room for the lead and tilt on the dome's steep rim: an axis past the largest tilt
        // is not used (tests/max_tilt.rs).
        opts.max_tilt_deg = 120.0;
        // The lead flips with the feed at each pass's end; poses splitting that turn into
        // steps of at most max_axis_step_deg take the halfway axis (tests/axis_steps.rs),
        // so the step limit is out of the way here.
        opts.max_axis_step_deg = 45.0;
        let path = isoparametric::plan_zigzag(&m, &opts, &mut |_| true).unwrap();
        // Angle between axis and normal: lead and tilt are rotations about perpendicular
        // axes, so cos = cos(lead)·cos(tilt).
        let want = (lead.to_radians().cos() * tilt.to_radians().cos()).acos();
        let mut n = 0;
        for mv in path.moves.iter().filter(|mv| mv.kind == MoveKind::Feed) {
            let normal = (mv.cl_point - mv.cc_point).normalize();
            let got = mv.tool_axis.dot(&normal).clamp(-1.0, 1.0).acos();
            assert!(
                (got - want).abs() < 1e-9,
                "lead {lead} tilt {tilt}: {got} vs {want}"
            );
            n += 1;
        }
        assert!(n > 100);
    }
}

/// Least distance (mm) from the segment `a`–`b` to any of `samples`.
fn segment_clearance(samples: &[Point3], a: &Point3, b: &Point3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    samples
        .iter()
        .map(|q| {
            let t = if len2 > 0.0 {
                ((q - a).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a + d * t - q).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The head with coarse five-axis settings (r 1 mm, h 0.3 mm) tilting up to `max_tilt_deg`.
fn coarse_head(max_tilt_deg: f64) -> (Model, PlanOptions) {
    let mut opts = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.3);
    opts.max_tilt_deg = max_tilt_deg;
    (samples::load_sample("head").unwrap(), opts)
}

#[test]
fn air_moves_keep_the_ball_out_of_the_closed_head() {
    // Starting on patch 1 the first cut lies under the head's overhang: coming straight down
    // onto it would pass through the head. The approach must go round (the final retract
    // after a last cut under the overhang is `verify.rs`'s head test), and every air move's
    // ball must stay clear of the surface (checked against dense surface samples, without
    // the planner's index).
    let (m, mut opts) = coarse_head(120.0);
    opts.start_patch = Some(1);
    let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
    let path = &planned.toolpath;
    let air = planned.air;
    assert_eq!(air.blocked, 0);
    // Rapids down beside the head (and in under it), the approach from the feed height,
    // then the plunge onto the cut.
    let plunge = path
        .moves
        .iter()
        .position(|m| m.kind == MoveKind::Plunge)
        .unwrap();
    assert!(
        plunge >= 2
            && path.moves[..plunge]
                .iter()
                .all(|m| matches!(m.kind, MoveKind::Rapid | MoveKind::Approach)),
        "the approach comes down beside the head and plunges from there: {:?}",
        path.moves[..=plunge]
            .iter()
            .map(|m| m.kind)
            .collect::<Vec<_>>()
    );
    assert!(air.escaped >= 1);
    let t = m.tessellate(0.01);
    let samples: Vec<Point3> = t
        .positions
        .chunks(3)
        .map(|p| Point3::new(p[0] as f64, p[1] as f64, p[2] as f64))
        .collect();
    let r = opts.tool_radius_mm;
    let mut least = f64::INFINITY;
    let mut checked = 0;
    for (i, w) in path.moves.windows(2).enumerate() {
        let air_move = matches!(
            w[1].kind,
            MoveKind::Retract | MoveKind::Rapid | MoveKind::Approach
        ) || (w[1].kind == MoveKind::Plunge && !w[0].kind.on_surface());
        if !air_move {
            continue;
        }
        let c = segment_clearance(&samples, &w[0].cl_point, &w[1].cl_point);
        least = least.min(c);
        checked += 1;
        // The ball touches the surface where it lands (within the chordal tolerance).
        assert!(
            c > r - opts.chordal_mm - 1e-3,
            "move {}: the ball passes {c} mm from the surface (radius {r} mm)",
            i + 1
        );
    }
    println!(
        "head from patch 1: {} air moves routed round the head, {checked} checked, least ball-centre clearance {least:.4} mm (r {r} mm)",
        air.escaped
    );
}

#[test]
fn the_tool_always_comes_from_the_side_the_surface_faces() {
    // The head's flat bottom faces straight down: no axis within 90° of +Z comes from below
    // it (a vertical tool there would run up through the part, its shank inside the head
    // where no surface sample can see it), so planning within 90° leaves it out and says
    // where and why.
    let (m, mut opts) = coarse_head(90.0);
    let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
    let report = planned.report(&opts);
    let away = report
        .problems
        .iter()
        .find(|p| p.kind == "rest_faces_away")
        .expect("the bottom is reported");
    assert!(away.message.contains("allow more tilt"), "{}", away.message);
    let err = away.message.clone();
    // No cut point left faces down.
    assert!(planned
        .toolpath
        .moves
        .iter()
        .filter(|m| m.kind.on_surface())
        .all(|m| m.tool_axis.dot(&(m.cl_point - m.cc_point)) > 0.0));
    // A table tilting past upright presents the bottom: then every cut point's axis lies
    // on the side of its contact normal (from the contact to the ball centre).
    opts.max_tilt_deg = 120.0;
    let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
    let mut least: f64 = 1.0;
    let mut below_horizontal = 0;
    for mv in &planned.toolpath.moves {
        if !matches!(mv.kind, MoveKind::Feed | MoveKind::Link) {
            continue;
        }
        let n = (mv.cl_point - mv.cc_point).normalize();
        least = least.min(mv.tool_axis.dot(&n));
        if mv.tool_axis.z < 0.0 {
            below_horizontal += 1;
        }
    }
    println!("head, tilt ≤ 120°: least axis·normal {least:.4}, {below_horizontal} cut points with the tool below the horizontal; 90°: {err}");
    assert!(least > 0.0, "a tool axis points into the surface: {least}");
    assert!(below_horizontal > 0, "the bottom needs the tool from below");
}

#[test]
fn the_turning_tool_between_cut_points_stays_out_of_the_head() {
    // The planner checks the poses between neighbouring cut points (as close together as its margin needs) with
    // its own obstacle index. Here every turn between two cutting moves is checked again,
    // every 1°, against dense surface samples: the shank (above the flutes) and the holder
    // must not enter the part, except at turns the planner itself reports as blocked.
    let (m, opts) = coarse_head(120.0);
    let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
    let samples = dense_samples(&m);
    let grid = SampleGrid::new(&samples, 2.0);
    let tol = 0.02;
    let step = 1f64.to_radians();
    let (mut turns, mut poses, mut hits) = (0, 0, 0);
    let reach = 1.0;
    let mut least = reach;
    let moves = &planned.toolpath.moves;
    let clearance = |c: Point3, axis: Vector3| tool_clearance(&grid, &opts, c, axis, reach);
    for (i, w) in moves.windows(2).enumerate() {
        let cutting = |k: MoveKind| matches!(k, MoveKind::Feed | MoveKind::Link);
        if !(w[0].kind.on_surface() && cutting(w[1].kind)) {
            continue;
        }
        let turn = w[0].tool_axis.angle(&w[1].tool_axis);
        if turn <= step {
            continue;
        }
        turns += 1;
        let n = (turn / step).ceil() as usize;
        let mut worst = reach;
        for k in 1..n {
            let s = k as f64 / n as f64;
            let c = w[0].cl_point + (w[1].cl_point - w[0].cl_point) * s;
            let axis = (w[0].tool_axis * (1.0 - s) + w[1].tool_axis * s).normalize();
            poses += 1;
            worst = worst.min(clearance(c, axis));
        }
        least = least.min(worst);
        if worst < -tol {
            hits += 1;
            println!(
                "move {}: the turning tool enters the head by {:.3} mm near {}",
                i + 1,
                -worst,
                w[1].cl_point
            );
        }
    }
    // The check sees a tool that does enter: the same poses with the axis reversed put the
    // shank into the closed head.
    let inside = moves
        .iter()
        .filter(|m| m.kind == MoveKind::Feed)
        .step_by(97)
        .filter(|m| clearance(m.cl_point, -m.tool_axis) < -tol)
        .count();
    assert!(inside > 0, "reversed axes are not seen inside the part");
    let stats = planned.axes;
    println!(
        "head, tilt ≤ 120°, {} surface samples: {turns} turns over 1° checked at {poses} poses; {hits} enter the part by more than {tol} mm (least clearance {least:.4} mm); the planner split {} turns and reports {} blocked; reversed axes seen inside at {inside} poses",
        samples.len(),
        stats.bridged,
        stats.sweep_hits
    );
    assert!(turns > 100, "the head's axes turn");
    assert!(
        hits <= stats.sweep_hits,
        "{hits} turns hit the part, the planner reports {} blocked",
        stats.sweep_hits
    );
}

#[test]
fn air_moves_keep_shank_and_holder_out_of_the_head() {
    // The air moves (approach, retract, escapes round the model) checked for the whole tool,
    // not only the ball: every 0.5 mm along each, axis interpolated, against dense samples.
    for start in [None, Some(1)] {
        let (m, mut opts) = coarse_head(120.0);
        opts.start_patch = start;
        let planned = isoparametric::plan(&m, &opts, &mut |_| true).unwrap();
        let grid = SampleGrid::new(&dense_samples(&m), 2.0);
        let reach: f64 = 5.0;
        let mut least = reach;
        let mut checked = 0;
        for w in planned.toolpath.moves.windows(2) {
            let air = matches!(
                w[1].kind,
                MoveKind::Retract | MoveKind::Rapid | MoveKind::Approach
            ) || (w[1].kind == MoveKind::Plunge && !w[0].kind.on_surface());
            if !air {
                continue;
            }
            checked += 1;
            let n = ((w[1].cl_point - w[0].cl_point).norm() / 0.5)
                .ceil()
                .max(1.0) as usize;
            for k in 0..=n {
                let s = k as f64 / n as f64;
                let c = w[0].cl_point + (w[1].cl_point - w[0].cl_point) * s;
                let axis = (w[0].tool_axis * (1.0 - s) + w[1].tool_axis * s).normalize();
                least = least.min(tool_clearance(&grid, &opts, c, axis, reach));
            }
        }
        println!("head from patch {start:?}: {checked} air moves, least shank/holder clearance {least:.4} mm");
        assert!(checked >= 2, "an approach and a retract at least");
        assert!(
            least > -0.02,
            "from patch {start:?}: the shank or holder enters the head by {} mm on an air move",
            -least
        );
    }
}

/// Progress moves while balls are lifted off the surface: on catmark_car.obj (scaled 20
/// times, r 1 mm) the lifting took minutes at one value, so the page's bar stood still.
/// On the keycap (lifted where it is tighter than the ball) the isoparametric plan's
/// progress rises through the lifting's share (0.70 to 0.73 of the whole) and the
/// measuring of the footprints near lifted balls (to 0.745), never falls, and ends at 1.
#[test]
fn progress_rises_while_balls_are_lifted() {
    let m = samples::load_sample("keycap-convex").unwrap();
    let opts = PlanOptions::default();
    assert!(tspath::plan::gouge::needed(&m, opts.tool_radius_mm));
    let mut seen = Vec::new();
    tspath::plan::plan(&m, &opts, &mut |f| {
        seen.push(f);
        true
    })
    .unwrap();
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
    assert_eq!(seen.last(), Some(&1.0));
    // Distinct values strictly inside (lo, hi).
    let inside = |lo: f64, hi: f64| {
        let mut v: Vec<f64> = seen
            .iter()
            .copied()
            .filter(|&f| f > lo + 1e-9 && f < hi - 1e-9)
            .collect();
        v.dedup();
        v
    };
    let lifting = inside(0.7, 0.73);
    println!("{} progress values while lifting", lifting.len());
    assert!(lifting.len() >= 5, "{lifting:?}");
    // Then the footprints near lifted balls are measured (0.73 to 0.745).
    let measuring = inside(0.73, 0.745);
    println!("{} while measuring near them", measuring.len());
    assert!(measuring.len() >= 2, "{measuring:?}");
}

/// The side-step profile is refined where the required step changes fast: sampled on 256
/// points across a patch only, it missed dips between them next to a hole's corners (on
/// bumps-hole's 60 mm multi-rectangle strip the step needed there was 36 % below both
/// neighbouring points), and the passes left up to 0.0119 mm (eq. 5) where 0.01 was asked:
/// plate-hole 0.0119, bumps-hole 0.0104 (isoparametric) and 0.0119 (multi-rectangle), each
/// "planned with problems".
#[test]
fn passes_keep_the_predicted_scallop_next_to_hole_corners() {
    let opts = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.01);
    for (name, strategy) in [
        ("plate-hole", tspath::plan::Strategy::Isoparametric),
        ("bumps-hole", tspath::plan::Strategy::Isoparametric),
        ("bumps-hole", tspath::plan::Strategy::MultiRectangle),
    ] {
        let m = samples::load_sample(name).unwrap();
        let o = opts.clone().with_strategy(strategy);
        let report = tspath::plan::plan(&m, &o, &mut |_| true)
            .unwrap()
            .report(&o);
        println!(
            "{name} {}: predicted {:.5} mm",
            strategy.name(),
            report.max_predicted_scallop_mm
        );
        assert!(
            report.max_predicted_scallop_mm <= o.scallop_mm * (1.0 + 1e-9),
            "{name} {}: {}",
            strategy.name(),
            report.max_predicted_scallop_mm
        );
    }
}

/// Rapids between cuts run the clearance over what lies beneath them ("minimum
/// retraction"), not at the safe plane: the whole tool (ball, flutes, shank, holder) keeps
/// the gap (the clearance, or the feed height where that is more) from the surface on every
/// level rapid, checked every 0.5 mm against dense surface samples, and over the stock's
/// top where stock is declared; `full_retract` keeps every level rapid at the safe plane
/// with the cuts unchanged. Bumps-hole's watershed plan (r 1 mm, h 0.05 mm) retracts four
/// times; with a wide holder 1 mm above the ball centre, which leaves walls unreached, 25
/// times.
#[test]
fn rapids_between_cuts_keep_the_clearance_over_what_lies_beneath() {
    let plain = samples::load_sample("bumps-hole").unwrap();
    let grid = SampleGrid::new(&dense_samples(&plain), 2.0);
    let base = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.05)
        .with_strategy(tspath::plan::Strategy::Watershed);
    // (holder radius, shank length, flute length, clearance, stock above the part) in mm.
    for (holder, shank, flutes, clearance, stock) in [
        (10.0, 20.0, None, 5.0, 0.0),
        (25.0, 1.0, Some(0.5), 1.0, 0.0),
        (10.0, 20.0, None, 5.0, 4.0),
    ] {
        let mut m = plain.clone();
        m.stock.max[2] += stock;
        let mut opts = base.clone().with_clearance(clearance);
        (opts.holder_radius_mm, opts.shank_length_mm) = (holder, shank);
        opts.flute_length_mm = flutes;
        let run = |full: bool| {
            let o = PlanOptions {
                full_retract: full,
                ..opts.clone()
            };
            tspath::plan::plan(&m, &o, &mut |_| true).unwrap().toolpath
        };
        let (low, full) = (run(false), run(true));
        let cuts = |p: &Toolpath| -> Vec<Point3> {
            p.moves
                .iter()
                .filter(|x| x.kind.on_surface())
                .map(|x| x.cl_point)
                .collect()
        };
        assert_eq!(cuts(&low), cuts(&full));
        let safe = full
            .moves
            .iter()
            .map(|x| x.cl_point.z)
            .fold(f64::MIN, f64::max);
        // Level air moves: both ends in the air at one height.
        let level = |p: &Toolpath| -> Vec<(Point3, Point3)> {
            p.moves
                .windows(2)
                .filter(|w| {
                    w.iter().all(|x| x.kind.rapid())
                        && (w[0].cl_point.z - w[1].cl_point.z).abs() < 1e-9
                        && (w[0].cl_point - w[1].cl_point).norm() > 1e-6
                })
                .map(|w| (w[0].cl_point, w[1].cl_point))
                .collect()
        };
        assert!(level(&full).iter().all(|(a, _)| (a.z - safe).abs() < 1e-9));
        let lowered: Vec<(Point3, Point3)> = level(&low)
            .into_iter()
            .filter(|(a, _)| a.z < safe - 1e-6)
            .collect();
        let what = format!(
            "holder r {holder} mm at {shank} mm, clearance {clearance} mm, stock {stock} mm above"
        );
        // Four transits with the usual holder; the wide one leaves walls unreached, and
        // the cuts split round them retract more.
        assert!(
            lowered.len() >= 4,
            "{what}: {} transits lowered",
            lowered.len()
        );
        let r = opts.tool_radius_mm;
        let gap = clearance.max(opts.feed_height_mm);
        // Distances looked for: up to 1 mm past the gap from the ball (its centre r more).
        let reach = gap + r + 1.0;
        // Least clearance of the ball and flutes, and of the shank and holder.
        let (mut ball_least, mut holder_least) = (reach, reach);
        for (a, b) in &lowered {
            let n = ((b - a).norm() / 0.5).ceil() as usize;
            for k in 0..=n {
                let p = a + (b - a) * (k as f64 / n as f64);
                let ball = grid.nearest(&p, reach) - r;
                let flutes = grid.clearance_to_cylinder(
                    &p,
                    &(p + Vector3::z() * opts.flute_length()),
                    r,
                    reach,
                );
                ball_least = ball_least.min(ball).min(flutes);
                holder_least =
                    holder_least.min(tool_clearance(&grid, &opts, p, Vector3::z(), reach));
            }
            // Over the stock's top by the gap.
            if stock > 0.0 {
                assert!(a.z - r >= m.stock.max[2] + gap - 1e-9, "{what}: {}", a.z);
            }
        }
        let least = ball_least.min(holder_least);
        let lengths = [&low, &full].map(|p| {
            p.moves
                .windows(2)
                .map(|w| (w[1].cl_point - w[0].cl_point).norm())
                .sum::<f64>()
        });
        println!(
            "{what}: {} transits at {:?} mm (safe plane {safe:.3}), least clearance {ball_least:.4} mm (ball, flutes), {holder_least:.4} mm (shank, holder; {reach} mm: none nearer), path {:.1} mm against {:.1}",
            lowered.len(),
            lowered.iter().map(|(a, _)| format!("{:.3}", a.z)).collect::<Vec<_>>(),
            lengths[0],
            lengths[1]
        );
        // Dense samples stand 0.3 mm apart: between them the surface may lie 0.011 mm
        // nearer a 1 mm ball; 0.02 mm covers that and the tessellation's 0.01 mm.
        assert!(least >= gap - 0.02, "{what}: {least} mm");
        assert!(lengths[0] < lengths[1] - 1.0);
    }
}
