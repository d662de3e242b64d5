//! Patch order as a travelling-salesman path (Shang et al. 2020, §3.3): patches are cities,
//! a boundary connection is a short road, a corner connection a long one, no connection a
//! very long one (it would cost a retraction). The path starts at the chosen patch and, if one
//! is suggested, finishes at the suggested patch (the paper's zero-weight closing link).
//!
//! Exact by dynamic programming (Held–Karp) up to [`EXACT_LIMIT`] patches; beyond that a
//! deterministic nearest-neighbour start improved by 2-opt and Or-opt moves.

/// Cost of moving between patches that share a side.
pub const BOUNDARY_COST: f64 = 1.0;
/// Cost of moving between patches that share only a corner (much less wanted: fewer transit
/// corners are possible there).
pub const CORNER_COST: f64 = 20.0;
/// Cost of moving between patches that do not touch (a retraction).
pub const JUMP_COST: f64 = 1000.0;
/// Largest patch count solved exactly.
pub const EXACT_LIMIT: usize = 15;

/// Symmetric cost matrix of moving between patches.
#[derive(Debug, Clone, PartialEq)]
pub struct CostMatrix {
    pub n: usize,
    pub cost: Vec<f64>,
}

impl CostMatrix {
    /// All pairs at [`JUMP_COST`] until connections are added.
    pub fn new(n: usize) -> Self {
        let mut cost = vec![JUMP_COST; n * n];
        for i in 0..n {
            cost[i * n + i] = 0.0;
        }
        CostMatrix { n, cost }
    }

    /// Sets the cost between `a` and `b` (both ways) if lower than what is there.
    pub fn connect(&mut self, a: usize, b: usize, c: f64) {
        let n = self.n;
        if c < self.cost[a * n + b] {
            self.cost[a * n + b] = c;
            self.cost[b * n + a] = c;
        }
    }

    #[inline]
    pub fn get(&self, a: usize, b: usize) -> f64 {
        self.cost[a * self.n + b]
    }

    /// Cost of visiting `order` in turn.
    pub fn path_cost(&self, order: &[usize]) -> f64 {
        order.windows(2).map(|w| self.get(w[0], w[1])).sum()
    }
}

/// The cheapest order visiting every patch once, starting at `start` and ending at `finish`
/// if given. Deterministic: ties go to the lexicographically smallest order found.
pub fn patch_order(m: &CostMatrix, start: usize, finish: Option<usize>) -> Vec<usize> {
    if m.n <= 1 {
        return (0..m.n).collect();
    }
    if m.n <= EXACT_LIMIT {
        held_karp(m, start, finish)
    } else {
        heuristic(m, start, finish)
    }
}

fn held_karp(m: &CostMatrix, start: usize, finish: Option<usize>) -> Vec<usize> {
    let n = m.n;
    let full = (1usize << n) - 1;
    let idx = |set: usize, last: usize| set * n + last;
    let mut best = vec![f64::INFINITY; (1 << n) * n];
    let mut parent = vec![u8::MAX; (1 << n) * n];
    best[idx(1 << start, start)] = 0.0;
    for set in 1..=full {
        if set & (1 << start) == 0 {
            continue;
        }
        for last in 0..n {
            if set & (1 << last) == 0 {
                continue;
            }
            let cur = best[idx(set, last)];
            if !cur.is_finite() {
                continue;
            }
            for next in 0..n {
                if set & (1 << next) != 0 {
                    continue;
                }
                // The suggested finish is visited last.
                if finish == Some(next) && (set | (1 << next)) != full {
                    continue;
                }
                let ns = set | (1 << next);
                let c = cur + m.get(last, next);
                if c < best[idx(ns, next)] {
                    best[idx(ns, next)] = c;
                    parent[idx(ns, next)] = last as u8;
                }
            }
        }
    }
    let end = match finish {
        Some(f) => f,
        None => (0..n)
            .min_by(|&a, &b| {
                best[idx(full, a)]
                    .total_cmp(&best[idx(full, b)])
                    .then(a.cmp(&b))
            })
            .unwrap_or(start),
    };
    let mut order = vec![end];
    let mut set = full;
    let mut last = end;
    while last != start || set != 1 << start {
        let p = parent[idx(set, last)] as usize;
        set &= !(1 << last);
        last = p;
        order.push(last);
    }
    order.reverse();
    order
}

fn heuristic(m: &CostMatrix, start: usize, finish: Option<usize>) -> Vec<usize> {
    let n = m.n;
    // Nearest neighbour, keeping the suggested finish for last.
    let mut order = vec![start];
    let mut used = vec![false; n];
    used[start] = true;
    if let Some(f) = finish {
        used[f] = true;
    }
    while order.len() < n - finish.map_or(0, |_| 1) {
        let last = *order.last().unwrap();
        let next = (0..n)
            .filter(|&j| !used[j])
            .min_by(|&a, &b| m.get(last, a).total_cmp(&m.get(last, b)).then(a.cmp(&b)))
            .unwrap();
        used[next] = true;
        order.push(next);
    }
    if let Some(f) = finish {
        if f != start {
            order.push(f);
        }
    }
    // Improve: 2-opt reversals and Or-opt moves of 1–3 patches, keeping both ends fixed
    // when a finish is given (only the start otherwise). Each move's change of cost is
    // found from the links it breaks and makes (the matrix is symmetric, so a reversed
    // stretch costs what it did), and only a move that saves is made.
    let fixed_end = finish.is_some();
    let last_movable = if fixed_end { n - 2 } else { n - 1 };
    let mut improved = true;
    let mut rounds = 0;
    while improved && rounds < 100 {
        improved = false;
        rounds += 1;
        for i in 1..=last_movable {
            for j in i + 1..=last_movable {
                if two_opt_change(m, &order, i, j) < -IMPROVEMENT {
                    order[i..=j].reverse();
                    improved = true;
                }
            }
        }
        for len in 1..=3 {
            for i in 1..=last_movable {
                if i + len - 1 > last_movable {
                    break;
                }
                for j in 1..=last_movable + 1 - len {
                    if j == i {
                        continue;
                    }
                    // The stretch is taken out and put back before what is then at `at`.
                    let rest_len = order.len() - len;
                    let at = j.min(rest_len);
                    if fixed_end && at > rest_len - 1 {
                        continue;
                    }
                    if or_opt_change(m, &order, i, len, at) < -IMPROVEMENT {
                        let seg: Vec<usize> = order.drain(i..i + len).collect();
                        for (k, s) in seg.into_iter().enumerate() {
                            order.insert(at + k, s);
                        }
                        improved = true;
                    }
                }
            }
        }
    }
    order
}

/// Smallest saving a move must make to be taken (the costs are whole multiples of
/// [`BOUNDARY_COST`], so any real saving is far above it).
const IMPROVEMENT: f64 = 1e-9;

/// Change of `order`'s cost when its stretch `i..=j` (`i ≥ 1`) is reversed.
fn two_opt_change(m: &CostMatrix, order: &[usize], i: usize, j: usize) -> f64 {
    let mut change = m.get(order[i - 1], order[j]) - m.get(order[i - 1], order[i]);
    if let Some(&after) = order.get(j + 1) {
        change += m.get(order[i], after) - m.get(order[j], after);
    }
    change
}

/// Change of `order`'s cost when its stretch of `len` patches from `i` (`i ≥ 1`) is taken
/// out and put back at index `at` of what remains (`1 ≤ at ≤` the remaining length).
fn or_opt_change(m: &CostMatrix, order: &[usize], i: usize, len: usize, at: usize) -> f64 {
    let n = order.len();
    let (first, last) = (order[i], order[i + len - 1]);
    // What remains after taking the stretch out, by index.
    let rest = |k: usize| if k < i { order[k] } else { order[k + len] };
    let rest_len = n - len;
    let mut change = -m.get(order[i - 1], first);
    if i + len < n {
        change += m.get(order[i - 1], order[i + len]) - m.get(last, order[i + len]);
    }
    change += m.get(rest(at - 1), first);
    if at < rest_len {
        change += m.get(last, rest(at)) - m.get(rest(at - 1), rest(at));
    }
    change
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(w: usize, h: usize) -> CostMatrix {
        let mut m = CostMatrix::new(w * h);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if x + 1 < w {
                    m.connect(i, i + 1, BOUNDARY_COST);
                }
                if y + 1 < h {
                    m.connect(i, i + w, BOUNDARY_COST);
                }
                if x + 1 < w && y + 1 < h {
                    m.connect(i, i + w + 1, CORNER_COST);
                }
                if x > 0 && y + 1 < h {
                    m.connect(i, i + w - 1, CORNER_COST);
                }
            }
        }
        m
    }

    #[test]
    fn exact_and_heuristic_agree_on_a_grid() {
        let m = grid(4, 3);
        let a = held_karp(&m, 0, None);
        let b = heuristic(&m, 0, None);
        assert_eq!(m.path_cost(&a), 11.0, "a snake through 12 patches");
        assert_eq!(m.path_cost(&b), 11.0);
        let c = patch_order(&m, 0, Some(11));
        assert_eq!((c[0], c[11]), (0, 11));
    }

    /// The cost changes computed from the links a move breaks and makes equal the whole
    /// path's cost after the move minus before, for every move on a scrambled grid.
    #[test]
    fn move_changes_equal_the_recomputed_costs() {
        let m = grid(5, 4);
        let n = m.n;
        let order: Vec<usize> = (0..n).map(|k| (k * 7) % n).collect();
        let before = m.path_cost(&order);
        for i in 1..n {
            for j in i + 1..n {
                let mut cand = order.clone();
                cand[i..=j].reverse();
                assert_eq!(
                    two_opt_change(&m, &order, i, j),
                    m.path_cost(&cand) - before
                );
            }
            for len in 1..=3 {
                if i + len > n {
                    break;
                }
                for at in 1..=n - len {
                    let mut cand = order.clone();
                    let seg: Vec<usize> = cand.drain(i..i + len).collect();
                    for (k, s) in seg.into_iter().enumerate() {
                        cand.insert(at + k, s);
                    }
                    assert_eq!(
                        or_opt_change(&m, &order, i, len, at),
                        m.path_cost(&cand) - before,
                        "stretch {i}+{len} to {at}"
                    );
                }
            }
        }
    }
}
