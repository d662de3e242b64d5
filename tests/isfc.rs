//! The improved space-filling curve (Gan et al. 2014; issue 14): one closed loop through
//! every grid vertex on parts with holes, a tree that is a minimum spanning tree, corner
//! detours as eq. 10–13 state them, and the cut checked by the cutting simulation — with
//! the plain curve as the baseline the paper improves on.

use crate::support;

use std::collections::{HashMap, HashSet};
use support::{holed_samples, isfc_opts as opts, public_tsm};
use tspath::machine::{self, Dialect, JobInfo, Units};
use tspath::model::samples;
use tspath::plan::isfc::cells::{edge, Link};
use tspath::plan::isfc::{corner, curve, tree};
use tspath::plan::{self, MoveKind, PlanOptions, Strategy};
use tspath::verify;
use tspath::Model;

/// The models of the loop test: two samples with holes and the two .tsm fixtures.
fn loop_models() -> Vec<(&'static str, Model, PlanOptions)> {
    let mut m = holed_samples();
    m.push(("mouse.tsm", public_tsm("mouse.tsm"), opts(1.0, 0.1)));
    m.push(("face.tsm", public_tsm("face.tsm"), opts(1.0, 0.1)));
    m
}

#[test]
fn one_closed_loop_through_every_grid_vertex_with_no_retraction() {
    for (name, m, o) in loop_models() {
        let c = curve(&m, &o, &mut |_| true).unwrap();
        // One loop, through every vertex of every cell once, and nothing else.
        assert_eq!(c.loops.len(), 1, "{name}: {} loops", c.loops.len());
        let ring = &c.loops[0];
        let in_cells: HashSet<u32> = c.cells.iter().flat_map(|k| k.corners).collect();
        let visited: HashSet<u32> = ring.iter().copied().collect();
        assert_eq!(
            visited.len(),
            ring.len(),
            "{name}: a vertex is visited twice"
        );
        assert_eq!(
            visited, in_cells,
            "{name}: the loop misses vertices or adds some"
        );
        assert_eq!(
            in_cells.len(),
            c.vertices.len(),
            "{name}: floating vertices"
        );
        // Each step is a grid edge within a patch, or a bridge between patches whose sides
        // meet in space: no longer than the longest grid edge of the loop, twice over.
        let len = |k: usize| {
            let (a, b) = (
                &c.vertices[ring[k] as usize],
                &c.vertices[ring[(k + 1) % ring.len()] as usize],
            );
            (a.patch == b.patch, (a.cc - b.cc).norm())
        };
        let longest_edge = (0..ring.len())
            .filter(|&k| len(k).0)
            .map(|k| len(k).1)
            .fold(0.0, f64::max);
        let mut across = 0;
        for k in 0..ring.len() {
            let (a, b) = (
                &c.vertices[ring[k] as usize],
                &c.vertices[ring[(k + 1) % ring.len()] as usize],
            );
            if a.patch == b.patch {
                let step = (a.i as i64 - b.i as i64).abs() + (a.j as i64 - b.j as i64).abs();
                assert_eq!(step, 1, "{name}: a step of the loop skips grid lines");
            } else {
                let d = (a.cc - b.cc).norm();
                assert!(
                    d <= 2.0 * longest_edge,
                    "{name}: a bridge of {d} mm between patches {} and {} (grid edges up to {longest_edge} mm)",
                    a.patch,
                    b.patch
                );
                across += 1;
            }
        }
        assert_eq!(
            c.tree.len(),
            c.cells.len() - 1,
            "{name}: the tree spans the cells"
        );
        // The plan: one approach, one exit, no retraction between; every contact point in
        // its patch's parameter square.
        let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
        let report = planned.report(&o);
        let kinds: Vec<MoveKind> = planned.toolpath.moves.iter().map(|x| x.kind).collect();
        let plunges = kinds.iter().filter(|&&k| k == MoveKind::Plunge).count();
        assert_eq!(
            report.retractions, 0,
            "{name}: {} retractions",
            report.retractions
        );
        assert_eq!(plunges, 1, "{name}: {plunges} approaches");
        assert_eq!(kinds.last(), Some(&MoveKind::Retract));
        for q in &planned.toolpath.params {
            assert!((0.0..=1.0).contains(&q[0]) && (0.0..=1.0).contains(&q[1]));
        }
        println!(
            "{name}: {} vertices in {} cells, one loop ({} steps across patch sides), {} CL points, {} corners compensated, {} mm",
            c.vertices.len(),
            c.cells.len(),
            across,
            report.cl_points,
            report.compensated_corners.unwrap(),
            report.length_mm.round()
        );
    }
}

/// An independent minimum spanning tree by Prim's algorithm: its total cost.
fn prim(cells: usize, links: &[Link]) -> f64 {
    let mut adj: Vec<Vec<(u32, f64)>> = vec![Vec::new(); cells];
    for l in links {
        adj[l.a as usize].push((l.b, l.cost));
        adj[l.b as usize].push((l.a, l.cost));
    }
    let mut inside = vec![false; cells];
    let mut best = vec![f64::INFINITY; cells];
    best[0] = 0.0;
    let mut total = 0.0;
    for _ in 0..cells {
        let v = (0..cells)
            .filter(|&v| !inside[v])
            .min_by(|&a, &b| best[a].total_cmp(&best[b]))
            .unwrap();
        inside[v] = true;
        total += best[v];
        for &(w, c) in &adj[v] {
            if !inside[w as usize] && c < best[w as usize] {
                best[w as usize] = c;
            }
        }
    }
    total
}

#[test]
fn the_tree_is_a_minimum_spanning_tree() {
    // Generated cell grids with holes (cells missing), random costs (ties included): the
    // tree has cells − 1 links and Prim's algorithm finds no cheaper one.
    let mut seed = 12345u64;
    let mut rand = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for case in 0..20 {
        let (w, h) = (6 + case % 5, 5 + case % 7);
        // Holes: a block in the middle and a notch at a corner, kept connected.
        let hole = |x: usize, y: usize| {
            ((2..=3).contains(&x) && (2..=2 + case % 2).contains(&y)) || (x == w - 1 && y == h - 1)
        };
        let mut id: HashMap<(usize, usize), u32> = HashMap::new();
        for y in 0..h {
            for x in 0..w {
                if !hole(x, y) {
                    let n = id.len() as u32;
                    id.insert((x, y), n);
                }
            }
        }
        let mut links = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let Some(&a) = id.get(&(x, y)) else { continue };
                for (nx, ny, side) in [(x + 1, y, 0u32), (x, y + 1, 1u32)] {
                    if let Some(&b) = id.get(&(nx, ny)) {
                        // Edge ids unique per cell side, so no two links share an edge.
                        let e = |c: u32, s: u32| edge(4 * c + s, 4 * c + s + 1_000_000);
                        let cost = (rand() % 7) as f64 - 3.0
                            + (rand() % 1000) as f64 * 1e-3 * (case % 2) as f64;
                        links.push(Link {
                            a,
                            b,
                            edge_a: e(a, side),
                            edge_b: e(b, side + 2),
                            bridges: [(0, 1), (2, 3)],
                            cost,
                        });
                    }
                }
            }
        }
        let cells = id.len();
        let t = tree::kruskal(cells, &links);
        assert_eq!(t.len(), cells - 1, "case {case}: not spanning");
        let total: f64 = t.iter().map(|&k| links[k].cost).sum();
        let want = prim(cells, &links);
        assert!(
            (total - want).abs() < 1e-9,
            "case {case}: Kruskal {total}, Prim {want}"
        );
    }
}

/// The cusp (mm) between two balls of radius `r` on a plane whose parameters are mm, a
/// parameter distance `d` apart: `r − sqrt(r² − d²/4)`.
fn flat_cusp(r: f64) -> impl FnMut([f64; 2], [f64; 2]) -> f64 {
    move |x, y| {
        let d = ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2)).sqrt();
        r - (r * r - 0.25 * d * d).max(0.0).sqrt()
    }
}

#[test]
fn corner_detours_are_g1_at_q_cross_the_diagonal_square_and_stay_in_their_square() {
    let (r, w): (f64, f64) = (1.0, 0.4);
    let h_flat = r - (r * r - 0.25 * w * w).sqrt();
    for (g, q, hh) in [
        ([0.0, 0.0], [w, 0.0], [w, w]),
        ([w, w], [w, 0.0], [0.0, 0.0]),
        ([0.0, w], [0.0, 0.0], [w, 0.0]),
    ] {
        let gq = [q[0] - g[0], q[1] - g[1]];
        let qh = [hh[0] - q[0], hh[1] - q[1]];
        let p = [q[0] + gq[0] - qh[0], q[1] + gq[1] - qh[1]];
        // Needed: the diagonal's cusp is twice the scallop.
        let eps = 0.01 * h_flat;
        let d = corner::detour(g, q, hh, p, h_flat, eps, &mut flat_cusp(r));
        assert!(d.h_pq_mm > h_flat);
        assert!(
            d.h_pk_mm <= h_flat && h_flat - d.h_pk_mm <= eps,
            "{}",
            d.h_pk_mm
        );
        // The flat value: K where |PK| = w, that is λ = |PK| / |PQ| = 1/√2.
        assert!((d.lambda - 0.5f64.sqrt()).abs() < 0.01, "λ {}", d.lambda);
        let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-12;
        // G¹ at Q: leaves along G→Q, returns along Q→H; at K both curves have −(GQ+QH)/2.
        assert!(near(d.out.at(0.0), q) && near(d.back.at(1.0), q));
        assert!(near(d.out.tangent(0.0), gq) && near(d.back.tangent(1.0), qh));
        let tk = [-0.5 * (gq[0] + qh[0]), -0.5 * (gq[1] + qh[1])];
        assert!(near(d.out.tangent(1.0), tk) && near(d.back.tangent(0.0), tk));
        assert!(near(d.out.at(1.0), d.k) && near(d.back.at(0.0), d.k));
        // Inside the square Q, Q+GQ, P, Q−QH (a hair of overshoot allowed).
        let lo = [q[0].min(p[0]), q[1].min(p[1])];
        let hi = [q[0].max(p[0]), q[1].max(p[1])];
        for t in 0..=100 {
            for c in [d.out.at(t as f64 / 100.0), d.back.at(t as f64 / 100.0)] {
                for k in 0..2 {
                    assert!(
                        c[k] >= lo[k] - 0.02 * w && c[k] <= hi[k] + 0.02 * w,
                        "{c:?} leaves the square"
                    );
                }
            }
        }
        // Not needed (a scallop above the diagonal's cusp): K at the diagonal's middle.
        let easy = corner::detour(g, q, hh, p, 3.0 * h_flat, eps, &mut flat_cusp(r));
        assert_eq!(easy.lambda, 0.5);
    }
}

/// Plans with `o`, verifies to a bound of h/4 and returns the report with the findings.
fn verified(m: &Model, o: &PlanOptions) -> (tspath::plan::PlanReport, verify::Verification) {
    let planned = plan::plan(m, o, &mut |_| true).unwrap();
    let mut report = planned.report(o);
    let v = verify::verify_plan(m, &planned, o, Some(200_000), 4_000_000).unwrap();
    report.add_verification(&v);
    (report, v)
}

#[test]
fn the_cut_keeps_the_scallop_without_gouging_and_the_plain_curve_does_not() {
    let mut cases: Vec<(String, Model)> = samples::SAMPLES
        .iter()
        .map(|s| (s.name.to_string(), samples::load_sample(s.name).unwrap()))
        .collect();
    for f in ["simple.tsm", "mouse.tsm", "face.tsm"] {
        cases.push((f.into(), public_tsm(f)));
    }
    for (name, m) in &cases {
        let o = opts(1.0, 0.1);
        let (report, v) = verified(m, &o);
        println!(
            "{name}: {} CL points, {:.0} mm, {} retractions; simulated max scallop {:.4} mm (bound {:.4} mm, {} samples), uncut outside the rest area {:.5} %, {} gouges; {:?}",
            report.cl_points,
            report.length_mm,
            report.retractions,
            v.max_scallop_mm,
            v.error_bound_mm,
            v.samples,
            100.0 * (v.uncut_fraction - v.rest_fraction).max(0.0),
            v.gouge_count,
            report.problems.iter().map(|p| p.kind.as_str()).collect::<Vec<_>>()
        );
        assert_eq!(
            v.gouge_count, 0,
            "{name}: gouges up to {} mm",
            v.max_gouge_mm
        );
        assert!(
            v.max_scallop_mm <= o.scallop_mm + v.error_bound_mm,
            "{name}: {} mm left",
            v.max_scallop_mm
        );
        assert!(
            v.uncut_fraction - v.rest_fraction < 1e-4,
            "{name}: uncut area"
        );
    }
    // The plain curve (no parity repair, no corner detours) on a part with a hole leaves
    // area above the scallop; the improved one none.
    let m = samples::load_sample("bumps-hole").unwrap();
    let mut o = opts(1.0, 0.1);
    let (_, improved) = verified(&m, &o);
    o.isfc_plain = true;
    let (plain_report, plain) = verified(&m, &o);
    println!(
        "bumps-hole: improved curve uncut {:.4} %, max {:.4} mm; plain curve uncut {:.4} %, max {:.4} mm ({:?})",
        100.0 * improved.uncut_fraction,
        improved.max_scallop_mm,
        100.0 * plain.uncut_fraction,
        plain.max_scallop_mm,
        plain_report.notes.iter().find(|n| n.contains("no cell"))
    );
    assert!(improved.uncut_fraction < 1e-4);
    assert!(plain.uncut_fraction > 100.0 * improved.uncut_fraction.max(1e-5));
    assert!(plain.max_scallop_mm > 1.5 * o.scallop_mm);
}

#[test]
fn same_input_same_program() {
    let m = samples::load_sample("plate-hole").unwrap();
    let o = opts(1.0, 0.1);
    let mach = machine::builtin("3-axis").unwrap();
    let job = JobInfo {
        model: "plate-hole".into(),
        strategy: "isfc".into(),
        program_zero: "the model's origin".into(),
    };
    let program = || {
        let p = plan::plan(&m, &o, &mut |_| true).unwrap();
        machine::post(&p.toolpath, &o, &job, &mach, Dialect::LinuxCnc, Units::Mm).unwrap()
    };
    let (a, b) = (program(), program());
    assert!(a == b, "two plans of the same input differ");
    assert!(a.contains("(strategy: isfc)") || a.contains("isfc"));
}

/// The paper's tool axis as a preset: 10° from the surface normal along the feed, on a
/// five-axis machine; on a three-axis one the CLI refuses it with a message saying why.
#[test]
fn the_papers_ten_degree_incline_is_a_preset() {
    let m = samples::load_sample("dome").unwrap();
    let o = PlanOptions::default()
        .with_tool_radius(2.0)
        .with_scallop(0.1)
        .with_strategy(Strategy::Isfc)
        .with_paper_axis();
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let mut angles: Vec<f64> = planned
        .toolpath
        .moves
        .iter()
        .filter(|x| x.kind == MoveKind::Feed)
        .map(|x| {
            let normal = (x.cl_point - x.cc_point).normalize();
            x.tool_axis.angle(&normal).to_degrees()
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    let median = angles[angles.len() / 2];
    assert!((median - 10.0).abs() < 0.5, "median incline {median}°");
    let args = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let e = tspath::cli::run(&args(&["plan", "dome", "--axis-preset", "gan2014"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("three-axis"), "{e}");
    let e = tspath::cli::run(&args(&["plan", "dome", "--axis-preset", "tilted"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("gan2014"), "{e}");
}
