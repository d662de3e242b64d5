//! Planning time of the keycap at the paper's settings (ball r = 0.5 mm, scallop 0.005 mm,
//! chordal 0.001 mm, tool axis with collision checks): the patch-by-patch zig-zag's passes,
//! the space-filling curve's (issue 14; target 150 ms for the convex keycap), and the whole
//! plan of each (the shared pipeline included). `cargo bench --bench plan`.
//!
//! `cargo bench --bench plan -- scaling`: how the whole plan grows with the area (bumps at
//! 1, 2 and 4 times its size: 16 times the area) and with the patches (face.tsm in 13
//! patches, Bike.tsm in 5, at the page's defaults); each prints its area, patches and moves
//! (air moves included) so that time per move and per mm² can be read off (issue 20).

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use tspath::model::samples;
use tspath::plan::{self, isfc, isoparametric, PlanOptions, Strategy};

/// The moves of a whole plan of `m` with `o` (the shared pipeline included).
fn whole_plan(m: &tspath::Model, o: &PlanOptions) -> usize {
    plan::plan(m, o, &mut |_| true)
        .unwrap()
        .toolpath
        .moves
        .len()
}

fn bench_plan(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    let opts = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.005)
        .with_chordal(0.001);
    for name in ["keycap-convex", "keycap-concave"] {
        let m = samples::load_sample(name).unwrap();
        let n = isoparametric::plan_zigzag(&m, &opts, &mut |_| true)
            .unwrap()
            .moves
            .len();
        println!("{name}: {n} CL points");
        group.bench_function(name, |b| {
            b.iter(|| {
                black_box(
                    isoparametric::plan_zigzag(&m, &opts, &mut |_| true)
                        .unwrap()
                        .moves
                        .len(),
                )
            })
        });
    }
    // The space-filling curve: its draft (grid, cells, tree, loop, corner detours, steps),
    // and the whole plan with either strategy.
    for name in ["keycap-convex", "keycap-concave"] {
        let m = samples::load_sample(name).unwrap();
        let curve = opts.clone().with_strategy(Strategy::Isfc);
        let n = isfc::draft(&m, &curve, &mut |_| true)
            .unwrap()
            .toolpath
            .moves
            .len();
        println!("{name}: space-filling curve {n} CL points");
        group.bench_function(format!("{name} isfc draft"), |b| {
            b.iter(|| {
                black_box(
                    isfc::draft(&m, &curve, &mut |_| true)
                        .unwrap()
                        .toolpath
                        .moves
                        .len(),
                )
            })
        });
        for (label, o) in [("isoparametric", &opts), ("isfc", &curve)] {
            group.bench_function(format!("{name} whole plan {label}"), |b| {
                b.iter(|| black_box(whole_plan(&m, o)))
            });
        }
    }
    // The watershed strategy (issue 15): bumps-hole at r 1, h 0.01 mm (target 300 ms).
    let m = samples::load_sample("bumps-hole").unwrap();
    for strategy in [Strategy::Watershed, Strategy::MultiRectangle] {
        let o = PlanOptions::default()
            .with_tool_radius(1.0)
            .with_scallop(0.01)
            .with_strategy(strategy);
        group.bench_function(format!("bumps-hole whole plan {}", strategy.name()), |b| {
            b.iter(|| black_box(whole_plan(&m, &o)))
        });
    }
    // Iso-planar slicing (issue 16): the convex keycap at the paper's settings (target
    // 200 ms), three-axis.
    let m = samples::load_sample("keycap-convex").unwrap();
    let mut o = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.005)
        .with_chordal(0.001)
        .with_strategy(Strategy::Isoplanar);
    o.max_tilt_deg = 0.0;
    group.bench_function("keycap-convex whole plan isoplanar", |b| {
        b.iter(|| black_box(whole_plan(&m, &o)))
    });
    group.finish();
}

fn bench_scaling(c: &mut Criterion) {
    let mut group = c.benchmark_group("scaling");
    group.sample_size(10);
    let area = tspath::plan::compare::area_mm2;
    let say = |label: &str, m: &tspath::Model, o: &PlanOptions| {
        let n = whole_plan(m, o);
        println!(
            "{label}: {:.0} mm², {} patches, {n} moves",
            area(m),
            m.layout.len()
        );
    };
    let o = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.05);
    for scale in [1.0, 2.0, 4.0] {
        let setup = tspath::model::setup::ImportSetup {
            scale,
            ..Default::default()
        };
        let m = samples::load_sample_with("bumps", &setup).unwrap();
        let label = format!("bumps x{scale} whole plan");
        say(&label, &m, &o);
        group.bench_function(label, |b| b.iter(|| black_box(whole_plan(&m, &o))));
    }
    let o = PlanOptions::default();
    for file in ["face.tsm", "Bike.tsm"] {
        let path = format!("{}/www/models/grapetec/{file}", env!("CARGO_MANIFEST_DIR"));
        let m = tspath::io::load(&std::fs::read(&path).unwrap(), file).unwrap();
        let label = format!("{file} whole plan");
        say(&label, &m, &o);
        group.bench_function(label, |b| b.iter(|| black_box(whole_plan(&m, &o))));
    }
    group.finish();
}

criterion_group!(benches, bench_plan, bench_scaling);
criterion_main!(benches);
