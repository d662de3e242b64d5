//! Verification speed: the convex keycap (the target: ≤ 2 s natively) and the dome,
//! planned at the paper's settings r = 0.5 mm, h = 0.005 mm and simulated with enough samples
//! for a stated error bound of 0.0005 mm.
//!
//! `cargo bench --bench verify`. The sample count is found first (and printed with the
//! bound reached), then the simulation at that count is timed.

use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Duration;
use tspath::model::samples;
use tspath::plan::{isoparametric, PlanOptions};
use tspath::verify::{self, CutterPath, VerifyOptions};

/// (sample, tool radius mm, scallop mm, error bound mm) to time.
const CASES: &[(&str, f64, f64, f64)] = &[
    ("keycap-convex", 0.5, 0.005, 0.0005),
    ("dome", 0.5, 0.005, 0.0005),
];

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("verify");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(60))
        .warm_up_time(Duration::from_secs(1));
    for &(name, r, h, bound) in CASES {
        let model = samples::load_sample(name).expect("sample loads");
        let opts = PlanOptions::default().with_tool_radius(r).with_scallop(h);
        let plan = isoparametric::plan_zigzag(&model, &opts, &mut |_| true).expect("plans");
        let path = CutterPath::from_toolpath(&plan).expect("valid path");
        let vopts = VerifyOptions::default()
            .with_samples(300_000)
            .with_scallop(h)
            .with_gouge_tolerance(opts.chordal_mm);
        let found = verify::verify_to_bound(&model.surface, &path, &vopts, bound).expect("runs");
        assert!(
            found.error_bound_mm <= bound,
            "{name}: bound {} not reached",
            found.error_bound_mm
        );
        println!(
            "{name} r={r} h={h}: {} moves, {} samples (spacing {:.4} mm) for error bound {:.6} mm \
             (scallop {:.6}, gouge {:.6}); max scallop {:.6} mm, max gouge {:.6} mm",
            found.moves,
            found.samples,
            found.sample_spacing_mm,
            found.error_bound_mm,
            found.scallop_error_bound_mm,
            found.gouge_error_bound_mm,
            found.max_scallop_mm,
            found.max_gouge_mm
        );
        let timed = vopts.clone().with_samples(found.samples);
        group.bench_function(format!("{name}_r{r}_h{h}_bound{bound}"), |b| {
            b.iter(|| verify::verify(&model.surface, &path, &timed).expect("runs"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
