//! Bézier extraction: the blending functions covering a face, cut at every knot line that
//! crosses it, summed into rational bicubic Bézier cells.

use super::basis::bspline_bernstein;
use super::bezier::BezierPatch;
use super::FaceSurface;
use crate::error::{Error, Result};
use crate::tmesh::{Scheme, TMesh, KNOT_MATCH_REL};

pub(super) fn extract(mesh: &TMesh) -> Result<Vec<FaceSurface>> {
    if mesh.scheme() == Scheme::CatmullClark {
        return Err(Error::Unsupported(
            "Catmull–Clark evaluation is not available in this build".into(),
        ));
    }
    let nv = mesh.vertex_count();
    let extraordinary: Vec<bool> = (0..nv as u32).map(|v| mesh.is_extraordinary(v)).collect();
    if let Some(v) = extraordinary.iter().position(|&e| e) {
        return Err(Error::Unsupported(format!(
            "vertex {v} is an extraordinary point; T-spline evaluation near extraordinary points is not available in this build"
        )));
    }
    let blends = mesh.face_blends(&extraordinary, &extraordinary);
    let mut out = Vec::new();
    for (f, face) in mesh.faces().iter().enumerate() {
        if !face.is_domain() {
            continue;
        }
        let fb = &blends[f];
        if fb.is_empty() {
            return Err(Error::InvalidMesh(format!(
                "face {f} is covered by no blending function"
            )));
        }
        let u_breaks = breaks(fb.iter().flat_map(|b| b.u_knots), face.width);
        let v_breaks = breaks(fb.iter().flat_map(|b| b.v_knots), face.height);
        let mut cells = Vec::with_capacity((u_breaks.len() - 1) * (v_breaks.len() - 1));
        for j in 0..v_breaks.len() - 1 {
            let (v0, v1) = (v_breaks[j] * face.height, v_breaks[j + 1] * face.height);
            for i in 0..u_breaks.len() - 1 {
                let (u0, u1) = (u_breaks[i] * face.width, u_breaks[i + 1] * face.width);
                let mut cell = BezierPatch::zero();
                for b in fb {
                    let cu = bspline_bernstein(&b.u_knots, u0, u1);
                    let cv = bspline_bernstein(&b.v_knots, v0, v1);
                    if cu.iter().all(|&c| c == 0.0) || cv.iter().all(|&c| c == 0.0) {
                        continue;
                    }
                    let p = mesh.points()[b.vertex as usize].homogeneous();
                    for (jj, &cvj) in cv.iter().enumerate() {
                        for (ii, &cui) in cu.iter().enumerate() {
                            cell.cp[jj][ii] += p * (cui * cvj);
                        }
                    }
                }
                if cell.cp.iter().flatten().any(|c| !(c.w > 0.0)) {
                    return Err(Error::InvalidMesh(format!(
                        "face {f}: the blending functions do not cover the whole face (a gap in the T-mesh's knot lines?)"
                    )));
                }
                cells.push(cell);
            }
        }
        out.push(FaceSurface {
            mesh_face: f as u32,
            width: face.width,
            height: face.height,
            u_breaks,
            v_breaks,
            cells,
        });
    }
    Ok(out)
}

/// Sorted distinct knot values strictly inside `(0, len)`, normalised to `[0,1]`, with 0 and 1.
fn breaks(knots: impl Iterator<Item = f64>, len: f64) -> Vec<f64> {
    let tol = KNOT_MATCH_REL * len;
    let mut inner: Vec<f64> = knots.filter(|&k| k > tol && k < len - tol).collect();
    inner.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let mut out = vec![0.0];
    let mut last = 0.0;
    for k in inner {
        if k - last > tol {
            out.push(k / len);
            last = k;
        }
    }
    out.push(1.0);
    out
}
