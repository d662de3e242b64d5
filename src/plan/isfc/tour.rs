//! The closed curve round the tree (Gan et al. 2014, §4.4): start from every cell's loop and,
//! for each tree link, remove the two facing edges and add the two bridges. Each swap merges
//! two loops into one, so a spanning tree leaves one closed curve through every vertex of the
//! cells, each once.
//!
//! Owns: the swaps and walking the loops. Must not: choose links or place moves.

use super::cells::{Cell, Link};
use crate::error::{Error, Result};

/// No neighbour (a slot of the adjacency not yet filled).
const NONE: u32 = u32::MAX;

/// The loops round the tree: for each connected part of the cells, its vertices in the order
/// the curve visits them, starting at the vertex `start` picks among them (the first vertex
/// is not repeated at the end; the curve closes back to it).
pub fn loops(
    vertices: usize,
    cells: &[Cell],
    links: &[Link],
    tree: &[usize],
    start: &dyn Fn(&[u32]) -> u32,
) -> Result<Vec<Vec<u32>>> {
    let mut adj = vec![[NONE; 2]; vertices];
    let mut in_cell = vec![false; vertices];
    let add = |adj: &mut Vec<[u32; 2]>, a: u32, b: u32| -> Result<()> {
        for (x, y) in [(a, b), (b, a)] {
            let slot = adj[x as usize]
                .iter_mut()
                .find(|s| **s == NONE)
                .ok_or_else(|| internal(format!("vertex {x} would get a third neighbour")))?;
            *slot = y;
        }
        Ok(())
    };
    let remove = |adj: &mut Vec<[u32; 2]>, a: u32, b: u32| -> Result<()> {
        for (x, y) in [(a, b), (b, a)] {
            let slot = adj[x as usize]
                .iter_mut()
                .find(|s| **s == y)
                .ok_or_else(|| internal(format!("edge {x}–{y} is not on the curve")))?;
            *slot = NONE;
        }
        Ok(())
    };
    for c in cells {
        for &(a, b) in &c.edges() {
            add(&mut adj, a, b)?;
        }
        for &k in &c.corners {
            in_cell[k as usize] = true;
        }
    }
    for &k in tree {
        let l = &links[k];
        remove(&mut adj, l.edge_a.0, l.edge_a.1)?;
        remove(&mut adj, l.edge_b.0, l.edge_b.1)?;
        for &(a, b) in &l.bridges {
            add(&mut adj, a, b)?;
        }
    }
    // Walk each loop once.
    let mut seen = vec![false; vertices];
    let mut out = Vec::new();
    for v0 in 0..vertices as u32 {
        if !in_cell[v0 as usize] || seen[v0 as usize] {
            continue;
        }
        // Collect the loop from v0, then restart it at the chosen vertex.
        let mut ring = vec![v0];
        seen[v0 as usize] = true;
        let (mut prev, mut cur) = (v0, adj[v0 as usize][0]);
        while cur != v0 {
            if cur == NONE || seen[cur as usize] {
                return Err(internal(format!("the curve breaks at vertex {prev}")));
            }
            seen[cur as usize] = true;
            ring.push(cur);
            let [a, b] = adj[cur as usize];
            let next = if a == prev { b } else { a };
            (prev, cur) = (cur, next);
        }
        let s = start(&ring);
        let at = ring.iter().position(|&x| x == s).unwrap_or(0);
        ring.rotate_left(at);
        out.push(ring);
    }
    Ok(out)
}

fn internal(message: String) -> Error {
    Error::Degenerate {
        location: "space-filling curve".into(),
        message,
    }
}
