//! Slicing a triangle mesh by a level of a piecewise-linear function: the deformed CL mesh
//! cut by a plane `x' = c` is the original mesh cut where its vertices' `x'` (linear across
//! each triangle) equals `c`. Every point of a slice is kept as the mesh edge it lies on and
//! its parameter along that edge, so that it maps back to the original mesh exactly (eq. 11
//! done without interpolation error: the same `t` on the original edge).
//!
//! Owns: the crossings and their chaining by mesh adjacency. Must not: know what the
//! function means.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Hashes an edge key (two vertex indices) by one multiplication: the keys are distinct
/// integers, not input an adversary chooses, and the default hasher's rounds were a good
/// part of slicing.
#[derive(Default)]
struct EdgeHasher(u64);

impl Hasher for EdgeHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }

    fn finish(&self) -> u64 {
        // The table picks buckets by the low bits, which the multiplication fills only
        // from the key's low bits: bring the high ones down.
        self.0.rotate_left(26)
    }
}

/// Where a slice crosses a mesh edge: the edge's vertices `a < b`, and `t ∈ [0, 1]` from `a`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub a: u32,
    pub b: u32,
    pub t: f64,
}

/// A connected piece of a slice: its crossings in order; `closed` if it returns to its
/// first (not repeated at the end). An open chain ends on the mesh's boundary.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    pub hits: Vec<Hit>,
    pub closed: bool,
}

/// The edge key of vertices `a`, `b`.
fn key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

/// The pieces of the level `value[v] = c` over `triangles` (indices into `all`), chained
/// through shared edges. A vertex exactly at `c` counts as above it, so every triangle is
/// crossed by zero or two of its edges. Chains come in a fixed order (of their first
/// triangle), whatever the hashing.
pub fn slice(all: &[[u32; 3]], triangles: &[u32], value: &[f64], c: f64) -> Vec<Chain> {
    let above = |v: u32| value[v as usize] >= c;
    // Per crossed triangle, its two crossed edges.
    let mut segments: Vec<[u64; 2]> = Vec::new();
    for &t in triangles {
        let [p, q, r] = all[t as usize];
        let mut crossed = [0u64; 2];
        let mut n = 0;
        for (a, b) in [(p, q), (q, r), (r, p)] {
            if above(a) != above(b) {
                crossed[n.min(1)] = key(a, b);
                n += 1;
            }
        }
        if n == 2 {
            segments.push(crossed);
        }
    }
    // Which segments each edge belongs to (one at the mesh boundary, else two).
    let mut by_edge: HashMap<u64, [u32; 2], BuildHasherDefault<EdgeHasher>> =
        HashMap::with_capacity_and_hasher(2 * segments.len(), Default::default());
    for (s, edges) in segments.iter().enumerate() {
        for &e in edges {
            by_edge
                .entry(e)
                .and_modify(|x| x[1] = s as u32)
                .or_insert([s as u32, u32::MAX]);
        }
    }
    let hit = |e: u64| -> Hit {
        let (a, b) = ((e >> 32) as u32, e as u32);
        let (fa, fb) = (value[a as usize], value[b as usize]);
        Hit {
            a,
            b,
            t: ((c - fa) / (fb - fa)).clamp(0.0, 1.0),
        }
    };
    let other = |s: u32, e: u64| -> Option<u32> {
        let [x, y] = by_edge[&e];
        let o = if x == s { y } else { x };
        (o != u32::MAX && o != s).then_some(o)
    };
    let mut used = vec![false; segments.len()];
    let mut chains = Vec::new();
    // Walks from segment `s` entering through edge `from`.
    let walk = |s0: u32, from: u64, used: &mut Vec<bool>| -> Chain {
        let mut hits = vec![hit(from)];
        let (mut s, mut entered) = (s0, from);
        loop {
            used[s as usize] = true;
            let [e0, e1] = segments[s as usize];
            let out = if e0 == entered { e1 } else { e0 };
            match other(s, out) {
                Some(n) if n == s0 => {
                    return Chain { hits, closed: true };
                }
                Some(n) if !used[n as usize] => {
                    hits.push(hit(out));
                    (s, entered) = (n, out);
                }
                _ => {
                    hits.push(hit(out));
                    return Chain {
                        hits,
                        closed: false,
                    };
                }
            }
        }
    };
    // Open chains first, from their boundary ends, then the loops.
    for s in 0..segments.len() {
        if used[s] {
            continue;
        }
        let [e0, e1] = segments[s];
        let start = if other(s as u32, e0).is_none() {
            Some(e0)
        } else if other(s as u32, e1).is_none() {
            Some(e1)
        } else {
            None
        };
        if let Some(e) = start {
            chains.push(walk(s as u32, e, &mut used));
        }
    }
    for s in 0..segments.len() {
        if !used[s] {
            let e = segments[s][0];
            chains.push(walk(s as u32, e, &mut used));
        }
    }
    chains
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n × n` cells over the unit square, two triangles per cell.
    fn grid(n: usize) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
        let mut pts = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                pts.push([i as f64 / n as f64, j as f64 / n as f64]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (pts, tris)
    }

    fn at(pts: &[[f64; 2]], h: &Hit) -> [f64; 2] {
        let (a, b) = (pts[h.a as usize], pts[h.b as usize]);
        [a[0] + (b[0] - a[0]) * h.t, a[1] + (b[1] - a[1]) * h.t]
    }

    #[test]
    fn a_line_across_a_grid_is_one_open_chain_on_the_level() {
        let (pts, tris) = grid(8);
        let f: Vec<f64> = pts.iter().map(|p| p[0] + 0.3 * p[1]).collect();
        let all: Vec<u32> = (0..tris.len() as u32).collect();
        let chains = slice(&tris, &all, &f, 0.55);
        assert_eq!(chains.len(), 1);
        let c = &chains[0];
        assert!(!c.closed);
        for h in &c.hits {
            let p = at(&pts, h);
            assert!((p[0] + 0.3 * p[1] - 0.55).abs() < 1e-12);
        }
        // From one side of the square to the other, each step within one cell.
        let (first, last) = (at(&pts, &c.hits[0]), at(&pts, c.hits.last().unwrap()));
        assert!(first[1].min(last[1]) < 1e-12 && first[1].max(last[1]) > 1.0 - 1e-12);
        for w in c.hits.windows(2) {
            let (p, q) = (at(&pts, &w[0]), at(&pts, &w[1]));
            assert!(((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt() < 0.2);
        }
    }

    #[test]
    fn a_circle_is_one_closed_chain_and_two_bumps_two() {
        let (pts, tris) = grid(40);
        let all: Vec<u32> = (0..tris.len() as u32).collect();
        let f: Vec<f64> = pts
            .iter()
            .map(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2))
            .collect();
        let chains = slice(&tris, &all, &f, 0.09);
        assert_eq!(chains.len(), 1);
        assert!(chains[0].closed);
        for h in &chains[0].hits {
            let p = at(&pts, h);
            let r = ((p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2)).sqrt();
            assert!((r - 0.3).abs() < 2e-3, "{r}");
        }
        let f: Vec<f64> = pts
            .iter()
            .map(|p| {
                let d = |cx: f64| (p[0] - cx).powi(2) + (p[1] - 0.5).powi(2);
                d(0.25).min(d(0.75))
            })
            .collect();
        let chains = slice(&tris, &all, &f, 0.01);
        assert_eq!(chains.len(), 2);
        assert!(chains.iter().all(|c| c.closed));
    }
}
