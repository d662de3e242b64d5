//! The domain cut into rectangles (seed 003, §3.3; the rule the paper leaves to its
//! reference, A7): the feature boxes, and the rest of the domain in maximal rectangles.
//!
//! Every face side and box side is extended into a line across the domain's chart; the
//! cells between the lines are classed by the box holding them (or none), and cells of one
//! class are merged greedily — from the lowest row up, leftmost first, as wide as the class
//! runs, then as high as the whole width stays in the class — so that a box inside the
//! domain comes out whole. Cells outside every face (holes, notches) are left out.

/// A rectangle of the domain's chart and the feature region it belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartRect {
    /// `[s0, s1, t0, t1]` in knot units.
    pub chart: [f64; 4],
    /// The feature region's label, `None` for the rest of the domain.
    pub feature: Option<u32>,
}

/// The rectangles of the domain made of `faces` (chart rectangles) with the feature
/// `boxes` (label, chart rectangle; not overlapping) in it; `tol` is the distance (knot
/// units) within which two lines are one.
pub fn rectangles(faces: &[[f64; 4]], boxes: &[(u32, [f64; 4])], tol: f64) -> Vec<ChartRect> {
    let mut lines = [Vec::new(), Vec::new()];
    for r in faces.iter().chain(boxes.iter().map(|b| &b.1)) {
        lines[0].extend([r[0], r[1]]);
        lines[1].extend([r[2], r[3]]);
    }
    // Box sides outside the domain's extent are clipped to it.
    let lo = [0, 2].map(|k| faces.iter().map(|f| f[k]).fold(f64::INFINITY, f64::min));
    let hi = [1, 3].map(|k| faces.iter().map(|f| f[k]).fold(f64::NEG_INFINITY, f64::max));
    for k in 0..2 {
        for x in lines[k].iter_mut() {
            *x = x.clamp(lo[k], hi[k]);
        }
        crate::sort::sort_floats(&mut lines[k]);
        lines[k].dedup_by(|a, b| (*a - *b).abs() <= tol);
    }
    let (ns, nt) = (
        lines[0].len().saturating_sub(1),
        lines[1].len().saturating_sub(1),
    );
    // Class of each cell: None outside the domain, Some(label) (0 for the rest) inside.
    let mut class = vec![None; ns * nt];
    for j in 0..nt {
        for i in 0..ns {
            let c = [
                0.5 * (lines[0][i] + lines[0][i + 1]),
                0.5 * (lines[1][j] + lines[1][j + 1]),
            ];
            let inside =
                |r: &[f64; 4]| c[0] >= r[0] && c[0] <= r[1] && c[1] >= r[2] && c[1] <= r[3];
            if faces.iter().any(inside) {
                class[j * ns + i] = Some(boxes.iter().find(|b| inside(&b.1)).map_or(0, |b| b.0));
            }
        }
    }
    let mut taken = vec![false; ns * nt];
    let mut out = Vec::new();
    for j in 0..nt {
        for i in 0..ns {
            let Some(c) = class[j * ns + i] else { continue };
            if taken[j * ns + i] {
                continue;
            }
            let free = |a: usize, b: usize, taken: &[bool]| {
                class[b * ns + a] == Some(c) && !taken[b * ns + a]
            };
            let mut i1 = i;
            while i1 + 1 < ns && free(i1 + 1, j, &taken) {
                i1 += 1;
            }
            let mut j1 = j;
            while j1 + 1 < nt && (i..=i1).all(|a| free(a, j1 + 1, &taken)) {
                j1 += 1;
            }
            for b in j..=j1 {
                for a in i..=i1 {
                    taken[b * ns + a] = true;
                }
            }
            out.push(ChartRect {
                chart: [lines[0][i], lines[0][i1 + 1], lines[1][j], lines[1][j1 + 1]],
                feature: (c != 0).then_some(c),
            });
        }
    }
    out
}
