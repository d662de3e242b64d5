//! The rest area: parts of the surface a plan says it leaves for another tool (where the
//! ball cannot reach). The simulation still measures them (their material left counts as
//! uncut, gouges there count as gouges), but their material left is not a scallop, so they
//! stay out of the scallop statistics and the scallop error bound.
//!
//! Owns: the rectangles' lookup by face and parameter. Must not: know how a plan found them.

use serde::{Deserialize, Serialize};

/// A rectangle of one surface face, `[u0, u1, v0, v1]` in that face's parameters (within
/// `[0, 1]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RestRect {
    /// Index of the face in [`crate::surface::Surface::faces`].
    pub face: u32,
    pub rect: [f64; 4],
}

/// Bins per face side of the lookup grid.
const BINS: usize = 32;

/// Rectangles binned per face, for point queries.
pub(super) struct RestMask {
    rects: Vec<[f64; 4]>,
    /// Per face: `BINS × BINS` lists of rectangle indices, empty for faces without any.
    bins: Vec<Vec<Vec<u32>>>,
}

/// Bin index of parameter `x` in `[0, 1]`.
fn bin(x: f64) -> usize {
    ((x.clamp(0.0, 1.0) * BINS as f64) as usize).min(BINS - 1)
}

impl RestMask {
    /// The mask of `rects` over a surface of `faces` faces (rectangles of other faces are
    /// ignored).
    pub(super) fn new(rects: &[RestRect], faces: usize) -> Self {
        let mut bins: Vec<Vec<Vec<u32>>> = vec![Vec::new(); faces];
        let mut kept = Vec::new();
        for r in rects {
            let Some(face_bins) = bins.get_mut(r.face as usize) else {
                continue;
            };
            if face_bins.is_empty() {
                *face_bins = vec![Vec::new(); BINS * BINS];
            }
            let [u0, u1, v0, v1] = r.rect;
            let id = kept.len() as u32;
            kept.push(r.rect);
            for j in bin(v0)..=bin(v1) {
                for i in bin(u0)..=bin(u1) {
                    face_bins[j * BINS + i].push(id);
                }
            }
        }
        RestMask { rects: kept, bins }
    }

    /// True if `(u, v)` of face `face` lies in a rectangle (edges included).
    pub(super) fn contains(&self, face: usize, u: f64, v: f64) -> bool {
        let Some(face_bins) = self.bins.get(face).filter(|b| !b.is_empty()) else {
            return false;
        };
        face_bins[bin(v) * BINS + bin(u)].iter().any(|&k| {
            let [u0, u1, v0, v1] = self.rects[k as usize];
            u >= u0 && u <= u1 && v >= v0 && v <= v1
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_found_in_their_rectangles_only() {
        let rects = [
            RestRect {
                face: 1,
                rect: [0.1, 0.3, 0.2, 0.9],
            },
            RestRect {
                face: 1,
                rect: [0.95, 1.0, 0.0, 0.05],
            },
            RestRect {
                face: 7,
                rect: [0.0, 1.0, 0.0, 1.0],
            },
        ];
        let m = RestMask::new(&rects, 3);
        assert!(m.contains(1, 0.2, 0.5));
        assert!(m.contains(1, 0.1, 0.9), "edges are inside");
        assert!(m.contains(1, 1.0, 0.0));
        assert!(!m.contains(1, 0.31, 0.5));
        assert!(!m.contains(0, 0.2, 0.5), "another face");
        assert!(!m.contains(7, 0.5, 0.5), "a face the surface does not have");
    }
}
