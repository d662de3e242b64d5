//! Loading a real .tsm model and building everything evaluation needs: parse, T-mesh with its
//! grip blocks, validation, local knot vectors and Bézier extraction (`io::load`).
//! Target: face.tsm (135 patches, 282 control points) in 20 ms or less.

use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn load_face(c: &mut Criterion) {
    let path = "www/models/grapetec/face.tsm";
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
    c.bench_function("tsm/face.tsm load to evaluable surface", |b| {
        b.iter(|| tspath::io::load(black_box(&bytes), "face").expect("face.tsm loads"))
    });
}

criterion_group!(benches, load_face);
criterion_main!(benches);
