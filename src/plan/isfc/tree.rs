//! The minimum spanning tree over the cells (Gan et al. 2014, §4.4): Kruskal's algorithm with
//! union–find over the candidate links, cheapest first. Ties are broken by the cells' indices
//! and then the edges', so the tree does not depend on the order links were found in.
//!
//! A cell edge can be removed by one link only (it is gone after the first): a link whose
//! edge another chosen link already uses is passed over. Within one patch's regular grid
//! every edge faces one cell, so this never happens there and the tree is a true minimum
//! spanning tree; across a side two patches' cells may face one edge with two.
//!
//! Owns: the choice of links. Must not: know where cells lie.

use super::cells::Link;
use std::collections::HashSet;

/// Union–find with path halving; the smaller index stays the root.
pub struct Sets(Vec<u32>);

impl Sets {
    /// `n` singletons.
    pub fn new(n: usize) -> Self {
        Sets((0..n as u32).collect())
    }
    /// The root of `a`'s set.
    pub fn find(&mut self, mut a: u32) -> u32 {
        while self.0[a as usize] != a {
            self.0[a as usize] = self.0[self.0[a as usize] as usize];
            a = self.0[a as usize];
        }
        a
    }
    /// Joins the sets of `a` and `b`; false if they were one already.
    pub fn join(&mut self, a: u32, b: u32) -> bool {
        let (a, b) = (self.find(a), self.find(b));
        if a == b {
            return false;
        }
        let (lo, hi) = (a.min(b), a.max(b));
        self.0[hi as usize] = lo;
        true
    }
}

/// The links of a minimum spanning tree (a forest where the cells are not connected) over
/// `cells` cells: indices into `links`, in the order chosen.
pub fn kruskal(cells: usize, links: &[Link]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..links.len()).collect();
    crate::sort::sort_by(&mut order, |&x, &y| {
        let (p, q) = (&links[x], &links[y]);
        p.cost
            .total_cmp(&q.cost)
            .then((p.a.min(p.b), p.a.max(p.b)).cmp(&(q.a.min(q.b), q.a.max(q.b))))
            .then(p.edge_a.cmp(&q.edge_a))
            .then(p.edge_b.cmp(&q.edge_b))
    });
    let mut sets = Sets::new(cells);
    let mut used: HashSet<(u32, u32)> = HashSet::new();
    let mut tree = Vec::new();
    for k in order {
        let l = &links[k];
        if used.contains(&l.edge_a) || used.contains(&l.edge_b) {
            continue;
        }
        if sets.join(l.a, l.b) {
            used.insert(l.edge_a);
            used.insert(l.edge_b);
            tree.push(k);
        }
    }
    tree
}
