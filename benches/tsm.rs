//! Loading real models and building everything evaluation needs (`io::load`: parse, mesh,
//! validation, Bézier extraction or subdivision trees, patch layout).
//! Targets: face.tsm (282 control points) in 20 ms or less; OpenSubdiv's car body cage
//! (1 575 faces, 346 extraordinary points, sharpness-6 creases) within twice OpenSubdiv's
//! patch-table time for it (0.17 s, issue 20), so 0.34 s; a generated 10 000-face cage with
//! extraordinary points, 1 s in wasm (`scripts/bench-wasm.mjs`).

use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn read(path: &str) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

fn load_models(c: &mut Criterion) {
    let mut group = c.benchmark_group("load");
    group.sample_size(10);
    for (path, name) in [
        ("www/models/grapetec/face.tsm", "face"),
        ("tests/fixtures/opensubdiv/catmark_car.obj", "catmark_car"),
        ("tests/fixtures/opensubdiv/catmark_rook.obj", "catmark_rook"),
    ] {
        let bytes = read(path);
        group.bench_function(format!("{name} to evaluable surface"), |b| {
            b.iter(|| tspath::io::load(black_box(&bytes), name).expect("loads"))
        });
    }
    let cage = cube_sphere_obj(41);
    group.bench_function("generated 10 086-face cage to evaluable surface", |b| {
        b.iter(|| tspath::io::load(black_box(cage.as_bytes()), "cage").expect("loads"))
    });
    group.finish();
}

/// A cube of `n` × `n` quads per side blown onto a sphere of radius 50 mm, as OBJ text (the
/// same cage `scripts/bench-wasm.mjs` generates; 8 extraordinary points).
fn cube_sphere_obj(n: i64) -> String {
    let mut ids: std::collections::HashMap<[i64; 3], usize> = Default::default();
    let mut vs = String::new();
    let mut faces = String::new();
    let mut vid = |p: [i64; 3], vs: &mut String| -> usize {
        let next = ids.len() + 1;
        *ids.entry(p).or_insert_with(|| {
            let q = p.map(|c| c as f64 - n as f64 / 2.0);
            let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            vs.push_str(&format!(
                "v {:.6} {:.6} {:.6}\n",
                50.0 * q[0] / l,
                50.0 * q[1] / l,
                50.0 * q[2] / l
            ));
            next
        })
    };
    for a in 0..3 {
        for side in [0, n] {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            for u in 0..n {
                for v in 0..n {
                    let mut quad =
                        [(u, v), (u + 1, v), (u + 1, v + 1), (u, v + 1)].map(|(x, y)| {
                            let mut p = [0; 3];
                            p[a] = side;
                            p[b] = x;
                            p[c] = y;
                            vid(p, &mut vs)
                        });
                    if side == 0 {
                        quad.reverse();
                    }
                    faces.push_str(&format!(
                        "f {} {} {} {}\n",
                        quad[0], quad[1], quad[2], quad[3]
                    ));
                }
            }
        }
    }
    vs + &faces
}

criterion_group!(benches, load_models);
criterion_main!(benches);
