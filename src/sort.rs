//! Stable sorting that costs little code per call.
//!
//! The standard library's sorts are fast, but each comparison they are called with compiles
//! to its own 3–8 KB of WebAssembly: the module held 187 KB of sorting code. None of the
//! sorts with a comparison of their own is on a hot path (none shows in profiles of the
//! head's five-axis plan or the keycap's re-plan), so one merge sort of item indices,
//! compiled once, serves them; each call adds only its comparison and the permutation. The
//! order is the standard library's stable order, the same on every platform. Plain
//! `sort_unstable()` of integers stays with the standard library: one copy per type serves
//! every call, and it is on hot paths (the report counts a path's patches by sorting them).
//!
//! Owns: sorting slices by a comparison. Must not be used where a sort is hot (it calls the
//! comparison through a pointer and sorts indices, about twice the standard library's time).

use std::cmp::Ordering;

/// Runs at most this long are sorted by insertion before merging.
const INSERTION_RUN: usize = 12;

/// Sorts `v` stably by `cmp`, which must be a total order.
pub fn sort_by<T>(v: &mut [T], mut cmp: impl FnMut(&T, &T) -> Ordering) {
    if v.len() < 2 {
        return;
    }
    let order = stable_order(v.len(), &mut |i, j| cmp(&v[i], &v[j]));
    permute(v, order);
}

/// Sorts `v` stably by the key `key` gives each item.
pub fn sort_by_key<T, K: Ord>(v: &mut [T], mut key: impl FnMut(&T) -> K) {
    sort_by(v, |a, b| key(a).cmp(&key(b)));
}

/// Sorts floats ascending by their total order (`f64::total_cmp`).
pub fn sort_floats(v: &mut [f64]) {
    sort_by(v, f64::total_cmp);
}

/// The indices of `n` items in the stable order `cmp` (on indices) gives: a merge sort that
/// keeps equal items in their order.
fn stable_order(n: usize, cmp: &mut dyn FnMut(usize, usize) -> Ordering) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    for run in order.chunks_mut(INSERTION_RUN) {
        for k in 1..run.len() {
            let item = run[k];
            let mut j = k;
            while j > 0 && cmp(run[j - 1], item) == Ordering::Greater {
                run[j] = run[j - 1];
                j -= 1;
            }
            run[j] = item;
        }
    }
    let mut spare = vec![0; n];
    let mut width = INSERTION_RUN;
    while width < n {
        for (out, from) in spare.chunks_mut(2 * width).zip(order.chunks(2 * width)) {
            let (left, right) = from.split_at(width.min(from.len()));
            let (mut a, mut b) = (0, 0);
            for slot in out.iter_mut() {
                // Equal items come from the left run first: the sort is stable.
                let take_left = b == right.len()
                    || (a < left.len() && cmp(left[a], right[b]) != Ordering::Greater);
                if take_left {
                    *slot = left[a];
                    a += 1;
                } else {
                    *slot = right[b];
                    b += 1;
                }
            }
        }
        std::mem::swap(&mut order, &mut spare);
        width *= 2;
    }
    order
}

/// Puts `v[order[k]]` at `k` for every `k`, by following the permutation's cycles; `order`
/// is used up as the record of what is placed.
fn permute<T>(v: &mut [T], mut order: Vec<usize>) {
    for start in 0..v.len() {
        // Along a cycle, the item first at `start` is carried to each place in turn, and the
        // place it leaves takes the item that belongs there.
        let mut k = start;
        while order[k] != k {
            let from = order[k];
            order[k] = k;
            if from == start {
                break;
            }
            v.swap(k, from);
            k = from;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random slices with many equal keys, sorted here and by the standard library's stable
    /// sort: the same order, equal keys kept in their order (told apart by their index).
    #[test]
    fn equals_the_standard_stable_sort() {
        let mut rnd = crate::testing::uniform(11u64);
        for n in [0, 1, 2, 3, 11, 12, 13, 24, 25, 47, 100, 257, 1000, 4099] {
            for distinct in [1.0, 3.0, 50.0, 1e6] {
                let items: Vec<(u32, usize)> =
                    (0..n).map(|i| ((rnd() * distinct) as u32, i)).collect();
                let mut ours = items.clone();
                sort_by_key(&mut ours, |x| x.0);
                let mut theirs = items.clone();
                theirs.sort_by_key(|x| x.0);
                assert_eq!(ours, theirs, "n {n}, {distinct} distinct keys");
            }
        }
    }

    /// Items that are not `Copy` (owning a vector) are moved, not cloned, into their order.
    #[test]
    fn moves_owned_items_into_order() {
        let mut rnd = crate::testing::uniform(12u64);
        let items: Vec<Vec<f64>> = (0..300).map(|i| vec![rnd(), i as f64]).collect();
        let mut ours = items.clone();
        sort_by(&mut ours, |a, b| a[0].total_cmp(&b[0]));
        let mut theirs = items;
        theirs.sort_by(|a, b| a[0].total_cmp(&b[0]));
        assert_eq!(ours, theirs);
        let mut floats: Vec<f64> = (0..500).map(|_| rnd() - 0.5).collect();
        floats.push(-0.0);
        floats.push(0.0);
        let mut sorted = floats.clone();
        sort_floats(&mut floats);
        sorted.sort_by(f64::total_cmp);
        assert_eq!(
            floats.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            sorted.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
}
