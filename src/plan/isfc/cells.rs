//! Grid vertices, 2 × 2 cells and the links that may join two cells (Gan et al. 2014, §4.3–4.4,
//! eq. 9).
//!
//! A cell is a disjoint block of 2 × 2 grid vertices of one patch; its four edges are a small
//! closed loop. Two side-adjacent cells may be linked: the two edges they face each other with
//! are removed and two bridges join their ends, which merges the two loops into one. Cells of
//! two patches sharing a side face each other across it (their grids sit half a step inside
//! each patch) and may be linked the same way. A link costs the change of length plus the
//! change of tool axis it brings (eq. 9).
//!
//! Owns: vertices, cells, link candidates and their costs. Must not: choose the links (that is
//! [`super::tree`]) or walk the loop.

use super::grid::Lines;
use crate::geom::{Point3, Vector3};

/// A grid vertex: patch, grid indices, patch parameters, contact point and tool-side normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    pub patch: u32,
    pub i: u32,
    pub j: u32,
    pub uv: [f64; 2],
    pub cc: Point3,
    pub normal: Vector3,
}

/// The grid of one patch.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchGrid {
    pub patch: u32,
    /// Lines `u = const` and `v = const`.
    pub us: Lines,
    pub vs: Lines,
    /// Id of vertex `(0, 0)`; vertex `(i, j)` is `first + j·nu + i`.
    pub first: u32,
}

impl PatchGrid {
    pub fn nu(&self) -> usize {
        self.us.at.len()
    }
    pub fn nv(&self) -> usize {
        self.vs.at.len()
    }
    /// Id of vertex `(i, j)`.
    pub fn id(&self, i: usize, j: usize) -> u32 {
        self.first + (j * self.nu() + i) as u32
    }
    /// Cells across `u` and `v` (a last odd line belongs to none).
    pub fn cells(&self) -> (usize, usize) {
        (self.nu() / 2, self.nv() / 2)
    }
}

/// A cell: its patch, its indices and its corners in loop order
/// `(2I, 2J), (2I+1, 2J), (2I+1, 2J+1), (2I, 2J+1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    pub patch: u32,
    pub ci: u32,
    pub cj: u32,
    pub corners: [u32; 4],
}

impl Cell {
    /// The four edges of its loop, each as `(smaller id, larger id)`.
    pub fn edges(&self) -> [(u32, u32); 4] {
        let c = self.corners;
        [0, 1, 2, 3].map(|k| edge(c[k], c[(k + 1) % 4]))
    }
}

/// An undirected edge as `(smaller id, larger id)`.
pub fn edge(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// A possible link between cells `a` and `b`: the edge of each that faces the other, the two
/// bridges that replace them, and the cost of eq. 9.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    pub a: u32,
    pub b: u32,
    pub edge_a: (u32, u32),
    pub edge_b: (u32, u32),
    pub bridges: [(u32, u32); 2],
    pub cost: f64,
}

impl Link {
    /// The link of cells `a` and `b` whose edges `p`–`q` and `r`–`s` face each other, `p`
    /// opposite `r` (the bridges `p`–`r` and `q`–`s` do not cross).
    pub fn facing(
        v: &[Vertex],
        w: Weights,
        (a, [p, q]): (u32, [u32; 2]),
        (b, [r, s]): (u32, [u32; 2]),
    ) -> Link {
        Link {
            a,
            b,
            edge_a: edge(p, q),
            edge_b: edge(r, s),
            bridges: [edge(p, r), edge(q, s)],
            cost: link_cost(v, p, q, r, s, w),
        }
    }
}

/// Weights of eq. 9: length change and tool-axis change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    /// Weight of the length change (per mm).
    pub length: f64,
    /// Weight of the tool-axis change (per unit of `‖ΔV‖`).
    pub axis: f64,
}

/// Cost of replacing edges `(p2, p4)` and `(p5, p7)` by bridges `(p4, p7)` and `(p2, p5)`
/// (eq. 9): `(w_L·L + w_A·A) / (w_L + w_A)` with `L = |c| + |d| − |a| − |b|` in mm and
/// `A` the same sums of `‖V_j − V_i‖` over the tool-side normals.
pub fn link_cost(v: &[Vertex], p2: u32, p4: u32, p5: u32, p7: u32, w: Weights) -> f64 {
    let at = |k: u32| &v[k as usize];
    let len = |x: u32, y: u32| (at(x).cc - at(y).cc).norm();
    let turn = |x: u32, y: u32| (at(x).normal - at(y).normal).norm();
    let l = len(p4, p7) + len(p2, p5) - len(p2, p4) - len(p5, p7);
    let a = turn(p4, p7) + turn(p5, p2) - turn(p4, p2) - turn(p5, p7);
    (w.length * l + w.axis * a) / (w.length + w.axis)
}

/// The cells of every patch grid, in patch order and row-major within a patch.
pub fn cells(grids: &[PatchGrid]) -> Vec<Cell> {
    let mut out = Vec::new();
    for g in grids {
        let (ni, nj) = g.cells();
        for cj in 0..nj {
            for ci in 0..ni {
                let (i, j) = (2 * ci, 2 * cj);
                out.push(Cell {
                    patch: g.patch,
                    ci: ci as u32,
                    cj: cj as u32,
                    corners: [
                        g.id(i, j),
                        g.id(i + 1, j),
                        g.id(i + 1, j + 1),
                        g.id(i, j + 1),
                    ],
                });
            }
        }
    }
    out
}

/// Index of the first cell of each patch grid in [`cells`]' order.
pub fn first_cells(grids: &[PatchGrid]) -> Vec<u32> {
    let mut first = Vec::with_capacity(grids.len());
    let mut n = 0u32;
    for g in grids {
        first.push(n);
        let (ni, nj) = g.cells();
        n += (ni * nj) as u32;
    }
    first
}

/// Links between side-adjacent cells of one patch: to the right (`+u`) and above (`+v`).
pub fn links_within(
    grids: &[PatchGrid],
    cells: &[Cell],
    first: &[u32],
    v: &[Vertex],
    w: Weights,
) -> Vec<Link> {
    let mut out = Vec::new();
    for (gi, g) in grids.iter().enumerate() {
        let (ni, nj) = g.cells();
        let cell = |ci: usize, cj: usize| first[gi] + (cj * ni + ci) as u32;
        let link = |a, b, pq, rs| Link::facing(v, w, (a, pq), (b, rs));
        for cj in 0..nj {
            for ci in 0..ni {
                let a = cell(ci, cj);
                let c = cells[a as usize].corners;
                if ci + 1 < ni {
                    let b = cell(ci + 1, cj);
                    let d = cells[b as usize].corners;
                    // A's right edge c1–c2 faces B's left edge d0–d3.
                    out.push(link(a, b, [c[1], c[2]], [d[0], d[3]]));
                }
                if cj + 1 < nj {
                    let b = cell(ci, cj + 1);
                    let d = cells[b as usize].corners;
                    // A's top edge c3–c2 faces B's bottom edge d0–d1.
                    out.push(link(a, b, [c[3], c[2]], [d[0], d[1]]));
                }
            }
        }
    }
    out
}

/// The cells of a patch grid along its side `side` (0: `v = 0`, 1: `u = 1`, 2: `v = 1`,
/// 3: `u = 0`) with the edge of each on the line nearest that side.
pub fn outer_cells(g: &PatchGrid, first: u32, cells: &[Cell], side: u8) -> Vec<(u32, (u32, u32))> {
    let (ni, nj) = g.cells();
    let cell = |ci: usize, cj: usize| first + (cj * ni + ci) as u32;
    let mut out = Vec::new();
    if ni == 0 || nj == 0 {
        return out;
    }
    match side {
        0 => (0..ni).for_each(|ci| {
            let k = cell(ci, 0);
            let c = cells[k as usize].corners;
            out.push((k, (c[0], c[1])));
        }),
        1 => (0..nj).for_each(|cj| {
            let k = cell(ni - 1, cj);
            let c = cells[k as usize].corners;
            out.push((k, (c[1], c[2])));
        }),
        2 => (0..ni).for_each(|ci| {
            let k = cell(ci, nj - 1);
            let c = cells[k as usize].corners;
            out.push((k, (c[3], c[2])));
        }),
        _ => (0..nj).for_each(|cj| {
            let k = cell(0, cj);
            let c = cells[k as usize].corners;
            out.push((k, (c[0], c[3])));
        }),
    }
    out
}

/// Least overlap of two facing edges, as a share of the shorter, for a link across a side.
const FACING_OVERLAP: f64 = 0.25;
/// Farthest two facing edges may lie apart, in lengths of the longer one.
const FACING_REACH: f64 = 2.0;

/// Links across a side two patches share: every pair of outer cells whose outer edges face
/// each other (overlapping along the side, about a step apart), the bridges paired so that
/// they do not cross.
pub fn links_across(
    outer_a: &[(u32, (u32, u32))],
    outer_b: &[(u32, (u32, u32))],
    v: &[Vertex],
    w: Weights,
) -> Vec<Link> {
    let mut out = Vec::new();
    for &(a, (p1, p2)) in outer_a {
        let (x1, x2) = (v[p1 as usize].cc, v[p2 as usize].cc);
        let da = x2 - x1;
        let la2 = da.norm_squared();
        if la2 <= 0.0 {
            continue;
        }
        for &(b, (q1, q2)) in outer_b {
            let (y1, y2) = (v[q1 as usize].cc, v[q2 as usize].cc);
            let lb = (y2 - y1).norm();
            // Overlap along A's edge.
            let (s1, s2) = ((y1 - x1).dot(&da) / la2, (y2 - x1).dot(&da) / la2);
            let (lo, hi) = (s1.min(s2).max(0.0), s1.max(s2).min(1.0));
            let la = la2.sqrt();
            let overlap = (hi - lo) * la;
            if overlap < FACING_OVERLAP * la.min(lb) {
                continue;
            }
            let gap = ((x1 + da * 0.5) - (y1 + (y2 - y1) * 0.5)).norm();
            if gap > FACING_REACH * la.max(lb) {
                continue;
            }
            // Pair the ends so the bridges do not cross.
            let straight = (x1 - y1).norm() + (x2 - y2).norm();
            let crossed = (x1 - y2).norm() + (x2 - y1).norm();
            let (r1, r2) = if straight <= crossed {
                (q1, q2)
            } else {
                (q2, q1)
            };
            out.push(Link::facing(v, w, (a, [p1, p2]), (b, [r1, r2])));
        }
    }
    out
}
