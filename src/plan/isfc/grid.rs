//! The scallop-limited grid of one patch (Gan et al. 2014, §4.2, eq. 7–8): lines `u = const`
//! stepped across `u` by the ball-end side step from the normal curvature across them, and
//! lines `v = const` the same way across `v`. The grid vertices are their crossings.
//!
//! The lines are the passes a zig-zag would take, from side to side. On a free side (the
//! surface's boundary, a hole's edge) the outermost line lies on the side, so the curve
//! traces the boundary as the paper's repaired cells do. On a side shared with another
//! patch it is pulled in by a quarter of its step: the two patches' outermost lines then
//! lie half a step apart across the side, where cells are linked, and where several
//! patches meet at a corner (an extraordinary point) no spot is farther than a step from
//! a line. Each direction needs an even number of lines for the 2 × 2 cells; where the
//! count comes out odd the widest interval is split (the paper's parity repair, which only
//! narrows steps).
//!
//! Owns: line positions and the parity repair. Must not: form cells or choose the order.

use crate::error::Result;
use crate::plan::isoparametric::{ParamSurface, StepProfile};
use crate::plan::stepover::FeedDir;

/// The lines of one patch in one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Lines {
    /// Positions in `[0, 1]`, increasing.
    pub at: Vec<f64>,
    /// Index of the line the parity repair added, if any.
    pub added: Option<usize>,
}

/// Share of its step by which the outermost line is pulled in from a shared side.
const SHARED_INSET: f64 = 0.25;

/// Lines across `dir`'s side-step parameter for scallop `h` and ball radius `r`: the passes
/// a zig-zag would take (each step the smallest the surface needs on the line, half-way and
/// on the next), the end ones on the sides where `free` (low side, high side) and pulled in
/// a quarter step where not; made even in number when `repair` (else an odd count stays,
/// and the last line belongs to no cell: the paper's plain curve).
pub fn lines(
    s: &dyn ParamSurface,
    dir: FeedDir,
    h: f64,
    r: f64,
    free: [bool; 2],
    repair: bool,
) -> Result<Lines> {
    let mut at = StepProfile::new(s, dir, h, r)?.passes(h);
    let n = at.len();
    if n >= 2 {
        if !free[0] {
            at[0] += SHARED_INSET * (at[1] - at[0]);
        }
        if !free[1] {
            at[n - 1] -= SHARED_INSET * (at[n - 1] - at[n - 2]);
        }
    }
    let mut added = None;
    if repair && at.len() % 2 == 1 {
        let k = (0..at.len() - 1)
            .max_by(|&a, &b| (at[a + 1] - at[a]).total_cmp(&(at[b + 1] - at[b])))
            .expect("three lines at least");
        at.insert(k + 1, 0.5 * (at[k] + at[k + 1]));
        added = Some(k + 1);
    }
    Ok(Lines { at, added })
}
