//! libFuzzer target: any bytes given to `io::load` give a model or a typed error, never a
//! panic, and a model that loads evaluates to finite numbers.

#![no_main]

use libfuzzer_sys::fuzz_target;
use tspath::error::Error;

/// Face and patch parameters checked on every model that loads.
const PARAMS: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 1.0), (0.5, 0.5), (0.3, 0.7)];

fuzz_target!(|bytes: &[u8]| {
    match tspath::io::load(bytes, "fuzz") {
        Ok(m) => {
            let finite = |d: &tspath::surface::SurfaceDerivs| {
                d.point.iter().all(|x| x.is_finite())
                    && [d.su, d.sv, d.suu, d.suv, d.svv]
                        .iter()
                        .all(|v| v.iter().all(|x| x.is_finite()))
            };
            for f in 0..m.surface.faces().len() {
                for (u, v) in PARAMS {
                    let d = m.surface.derivs(f, u, v);
                    assert!(finite(&d), "face {f} at ({u}, {v}): {d:?}");
                }
            }
            for (k, p) in m.layout.patches.iter().enumerate() {
                for (u, v) in PARAMS {
                    let d = p.derivs(&m.surface, u, v);
                    assert!(finite(&d), "patch {k} at ({u}, {v}): {d:?}");
                }
            }
            let _ = m.summary();
        }
        Err(Error::Parse {
            location, message, ..
        }) => assert!(!location.is_empty() && !message.is_empty()),
        Err(Error::InvalidMesh(m)) | Err(Error::Unsupported(m)) => assert!(!m.is_empty()),
        Err(e) => panic!("unexpected error kind {e:?}"),
    }
});
