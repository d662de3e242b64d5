//! Evaluation throughput: point + first and second derivatives per second, on the keycap
//! (Catmull–Clark with extraordinary points) and the T-junction sample, at parameters spread
//! over every face. `cargo bench --bench eval`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use tspath::model::samples;

/// Parameters per face: a 16 × 16 grid, shifted off the cell lines.
const GRID: usize = 16;

fn bench_eval(c: &mut Criterion) {
    let mut group = c.benchmark_group("derivs");
    for name in ["keycap-convex", "tjunction"] {
        let m = samples::load_sample(name).unwrap();
        let faces = m.surface.faces().len();
        let params: Vec<(usize, f64, f64)> = (0..faces)
            .flat_map(|f| {
                (0..GRID * GRID).map(move |k| {
                    let (i, j) = (k % GRID, k / GRID);
                    (
                        f,
                        (i as f64 + 0.37) / GRID as f64,
                        (j as f64 + 0.61) / GRID as f64,
                    )
                })
            })
            .collect();
        group.throughput(Throughput::Elements(params.len() as u64));
        group.bench_with_input(BenchmarkId::from_parameter(name), &params, |b, params| {
            b.iter(|| {
                let mut acc = 0.0;
                for &(f, u, v) in params {
                    let d = m.surface.derivs(f, u, v);
                    acc += d.point.x + d.suu.y + d.svv.z;
                }
                black_box(acc)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_eval);
criterion_main!(benches);
