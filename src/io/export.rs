//! Writers of tessellated surfaces: binary STL (what CAM and slicers read) and Wavefront OBJ
//! with normals and one group per patch. Millimetres; deterministic bytes.

use crate::surface::tessellate::Tessellation;
use std::fmt::Write;

/// Binary STL: 80-byte header, triangle count, then per triangle its facet normal (from the
/// vertex order), three vertices and a zero attribute.
pub fn stl(t: &Tessellation, name: &str) -> Vec<u8> {
    let n = t.indices.len() / 3;
    let mut out = Vec::with_capacity(84 + 50 * n);
    let mut header = format!("tspath {} {name} (mm)", env!("CARGO_PKG_VERSION")).into_bytes();
    header.resize(80, b' ');
    out.extend_from_slice(&header);
    out.extend_from_slice(&(n as u32).to_le_bytes());
    let p = |i: u32| {
        let k = 3 * i as usize;
        [t.positions[k], t.positions[k + 1], t.positions[k + 2]]
    };
    for tri in t.indices.chunks(3) {
        let (a, b, c) = (p(tri[0]), p(tri[1]), p(tri[2]));
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let mut nrm = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
        if len > 0.0 {
            nrm = nrm.map(|x| x / len);
        }
        for v in [nrm, a, b, c] {
            for x in v {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// Wavefront OBJ with vertex normals, one group `patch_N` per patch.
pub fn obj(t: &Tessellation, name: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# tspath {} — {name}, millimetres",
        env!("CARGO_PKG_VERSION")
    );
    for p in t.positions.chunks(3) {
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    for n in t.normals.chunks(3) {
        let _ = writeln!(s, "vn {} {} {}", n[0], n[1], n[2]);
    }
    let mut order: Vec<usize> = (0..t.patch_ids.len()).collect();
    crate::sort::sort_by_key(&mut order, |&i| (t.patch_ids[i], i));
    let mut current = None;
    for i in order {
        if current != Some(t.patch_ids[i]) {
            current = Some(t.patch_ids[i]);
            let _ = writeln!(s, "g patch_{}", t.patch_ids[i]);
        }
        let f = &t.indices[3 * i..3 * i + 3];
        let _ = writeln!(
            s,
            "f {0}//{0} {1}//{1} {2}//{2}",
            f[0] + 1,
            f[1] + 1,
            f[2] + 1
        );
    }
    s
}
