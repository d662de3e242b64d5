//! Planning time of the keycap at the paper's settings (ball r = 0.5 mm, scallop 0.005 mm,
//! chordal 0.001 mm, tool axis with collision checks). `cargo bench --bench plan`.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use tspath::model::samples;
use tspath::plan::{isoparametric, PlanOptions};

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
    group.finish();
}

criterion_group!(benches, bench_plan);
criterion_main!(benches);
