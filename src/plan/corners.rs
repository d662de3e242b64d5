//! Transit corners (Shang et al. 2020, §3.4): for each patch in order, where its zig-zag
//! starts and finishes, so that every patch finishes at a corner it shares with the next one
//! and the next starts there — a path without retractions.
//!
//! A zig-zag can finish at any corner but the one it started from: at the corner across the
//! crossfeed side with an even number of passes, diagonally with an odd number. The search
//! walks the order choosing finishing corners among those shared with the next patch (two
//! along a shared side, one at a shared corner: the paper's five situations), preferring the
//! one that suits the patch's preferred crossfeed direction, and backtracks when a patch has
//! no usable corner left. When no choice avoids a retraction, the fewest retractions are used
//! instead and the caller says so. A strict preference is never traded: where the given
//! crossfeeds cannot meet at shared corners, the tool retracts instead of turning a patch
//! across (a long narrow rectangle turned across costs many more passes than one
//! retraction). With the crossfeeds kept and each patch's natural pass-count parity given,
//! a dynamic programme over the order chooses instead: the fewest retractions, then the
//! fewest patches that need a pass more to finish where the links want them.
//!
//! Corners are numbered 0: `(0,0)`, 1: `(1,0)`, 2: `(1,1)`, 3: `(0,1)` of each patch.

use serde::{Deserialize, Serialize};

/// Which way the passes step (the crossfeed): `U` means passes are lines `u = const`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Crossfeed {
    U,
    V,
}

/// One patch's place in the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Transit {
    pub patch: usize,
    pub start_corner: u8,
    pub finish_corner: u8,
    pub crossfeed: Crossfeed,
    /// True if the tool retracts before this patch (no shared corner could be used).
    pub retract_before: bool,
}

/// `(u, v)` of a corner.
pub fn corner_uv(c: u8) -> (u8, u8) {
    match c {
        0 => (0, 0),
        1 => (1, 0),
        2 => (1, 1),
        _ => (0, 1),
    }
}

/// Crossfeeds a zig-zag from `s` to `f` can use (empty if `s == f`).
pub fn crossfeeds(s: u8, f: u8) -> &'static [Crossfeed] {
    let (a, b) = (corner_uv(s), corner_uv(f));
    match (a.0 != b.0, a.1 != b.1) {
        (true, false) => &[Crossfeed::U],
        (false, true) => &[Crossfeed::V],
        (true, true) => &[Crossfeed::U, Crossfeed::V],
        (false, false) => &[],
    }
}

/// True if a zig-zag with crossfeed `c` from corner `s` to `f` has an odd number of passes:
/// it then ends on the far side along its passes (crossfeed U: passes u = const, cut along
/// v, so the far side in v).
pub fn finishes_odd(s: u8, f: u8, c: Crossfeed) -> bool {
    let ((su, sv), (fu, fv)) = (corner_uv(s), corner_uv(f));
    match c {
        Crossfeed::U => fv != sv,
        Crossfeed::V => fu != su,
    }
}

fn pick_crossfeed(s: u8, f: u8, preferred: Crossfeed) -> Crossfeed {
    let c = crossfeeds(s, f);
    if c.contains(&preferred) {
        preferred
    } else {
        c[0]
    }
}

/// Most steps of the backtracking search before it gives up and minimises retractions.
const SEARCH_LIMIT: usize = 1_000_000;

/// Chooses start and finish corners along `order`. `corner_ids[p][k]` identifies corner `k`
/// of patch `p` (equal ids = the same point of the surface); `preferred[p]` is the patch's
/// preferred crossfeed, which a patch leaves to avoid a retraction unless `strict`;
/// `natural_odd[p]`, if given, says whether patch `p` cut with its preferred crossfeed
/// takes an odd number of passes at the scallop asked (it then finishes on the far side
/// along its passes): among corners equally good otherwise, those that need no pass more
/// come first. `first_start` fixes the first patch's start corner if given. Returns the
/// transits and the number of retractions needed.
pub fn select(
    order: &[usize],
    corner_ids: &[[u32; 4]],
    preferred: &[Crossfeed],
    strict: bool,
    natural_odd: Option<&[bool]>,
    first_start: Option<u8>,
) -> (Vec<Transit>, usize) {
    let pref = Preferences {
        preferred,
        strict,
        natural_odd,
    };
    if order.is_empty() {
        return (Vec::new(), 0);
    }
    // With parities to weigh, the dynamic programme finds the best of all corner choices;
    // the search below takes the first without retractions.
    if natural_odd.is_some() {
        return fewest_retractions(order, corner_ids, &pref, first_start);
    }
    let mut steps = 0;
    let starts: Vec<u8> = match first_start {
        Some(s) => vec![s],
        None => (0..4).collect(),
    };
    for &s0 in &starts {
        let mut chosen = Vec::with_capacity(order.len());
        if search(order, corner_ids, &pref, 0, s0, &mut chosen, &mut steps) {
            let transits = chosen
                .iter()
                .enumerate()
                .map(|(i, &(s, f))| Transit {
                    patch: order[i],
                    start_corner: s,
                    finish_corner: f,
                    crossfeed: pick_crossfeed(s, f, preferred[order[i]]),
                    retract_before: false,
                })
                .collect();
            return (transits, 0);
        }
        if steps > SEARCH_LIMIT {
            break;
        }
    }
    fewest_retractions(order, corner_ids, &pref, first_start)
}

/// The crossfeed each patch prefers, whether it must keep it, and the parity of its pass
/// count with it.
struct Preferences<'a> {
    preferred: &'a [Crossfeed],
    strict: bool,
    natural_odd: Option<&'a [bool]>,
}

impl Preferences<'_> {
    /// True if a zig-zag of patch `p` from corner `s` to `f` needs a pass count of the other
    /// parity than the patch's natural one (one pass more, at a smaller side step).
    fn against_parity(&self, p: usize, s: u8, f: u8) -> bool {
        let Some(natural) = self.natural_odd else {
            return false;
        };
        finishes_odd(s, f, pick_crossfeed(s, f, self.preferred[p])) != natural[p]
    }

    /// Whether a zig-zag of patch `p` from corner `s` to `f` is allowed, and whether it
    /// misses the patch's preferred crossfeed.
    fn allows(&self, p: usize, s: u8, f: u8) -> (bool, bool) {
        let suits = crossfeeds(s, f).contains(&self.preferred[p]);
        (f != s && (suits || !self.strict), !suits)
    }
}

/// Candidate finishing corners of patch `p` started at `s`, towards patch `next`, best first.
fn candidates(
    p: usize,
    s: u8,
    next: Option<usize>,
    ids: &[[u32; 4]],
    pref: &Preferences,
) -> Vec<(u8, Option<u8>)> {
    let preferred = pref.preferred;
    let mut out: Vec<(u8, Option<u8>)> = Vec::new();
    for f in 0..4u8 {
        if !pref.allows(p, s, f).0 {
            continue;
        }
        match next {
            Some(n) => {
                if let Some(k) = (0..4u8).find(|&k| ids[n][k as usize] == ids[p][f as usize]) {
                    out.push((f, Some(k)));
                }
            }
            None => out.push((f, None)),
        }
    }
    // Corners that suit the preferred crossfeed first (diagonal ones suit both), then those
    // its natural pass count reaches.
    crate::sort::sort_by_key(&mut out, |&(f, _)| {
        (
            !crossfeeds(s, f).contains(&preferred[p]),
            pref.against_parity(p, s, f),
            f,
        )
    });
    out
}

fn search(
    order: &[usize],
    ids: &[[u32; 4]],
    pref: &Preferences,
    i: usize,
    s: u8,
    chosen: &mut Vec<(u8, u8)>,
    steps: &mut usize,
) -> bool {
    *steps += 1;
    if *steps > SEARCH_LIMIT {
        return false;
    }
    let p = order[i];
    let next = order.get(i + 1).copied();
    for (f, ns) in candidates(p, s, next, ids, pref) {
        chosen.push((s, f));
        match ns {
            None => return true,
            Some(ns) => {
                if search(order, ids, pref, i + 1, ns, chosen, steps) {
                    return true;
                }
            }
        }
        chosen.pop();
    }
    false
}

/// Dynamic programme over the order with the start corner as state: the fewest retractions,
/// then the most crossfeed preferences met, then the fewest patches against their parity.
fn fewest_retractions(
    order: &[usize],
    ids: &[[u32; 4]],
    pref: &Preferences,
    first_start: Option<u8>,
) -> (Vec<Transit>, usize) {
    let preferred = pref.preferred;
    let n = order.len();
    // cost[i][s]: (retractions, missed preferences, patches against their parity) to reach
    // patch i starting at corner s.
    let inf = (usize::MAX, usize::MAX, usize::MAX);
    let mut cost = vec![[inf; 4]; n];
    let mut back: Vec<[(u8, u8, bool); 4]> = vec![[(0, 0, false); 4]; n];
    for s in 0..4u8 {
        if first_start.is_none_or(|f| f == s) {
            cost[0][s as usize] = (0, 0, 0);
        }
    }
    for i in 0..n - 1 {
        let (p, q) = (order[i], order[i + 1]);
        for s in 0..4u8 {
            let c = cost[i][s as usize];
            if c == inf {
                continue;
            }
            for f in 0..4u8 {
                let (allowed, miss) = pref.allows(p, s, f);
                if !allowed {
                    continue;
                }
                let miss = usize::from(miss);
                let parity = usize::from(pref.against_parity(p, s, f));
                let shared = (0..4u8).find(|&k| ids[q][k as usize] == ids[p][f as usize]);
                let options: Vec<(u8, bool)> = match shared {
                    Some(k) => vec![(k, false)],
                    None => (0..4u8).map(|k| (k, true)).collect(),
                };
                for (ns, retract) in options {
                    let nc = (c.0 + usize::from(retract), c.1 + miss, c.2 + parity);
                    if nc < cost[i + 1][ns as usize] {
                        cost[i + 1][ns as usize] = nc;
                        back[i + 1][ns as usize] = (s, f, retract);
                    }
                }
            }
        }
    }
    // Last patch: any finish but its start.
    let (mut s_last, mut best) = (0u8, inf);
    for s in 0..4u8 {
        if cost[n - 1][s as usize] < best {
            best = cost[n - 1][s as usize];
            s_last = s;
        }
    }
    let mut out = vec![
        Transit {
            patch: 0,
            start_corner: 0,
            finish_corner: 0,
            crossfeed: Crossfeed::U,
            retract_before: false
        };
        n
    ];
    let p_last = order[n - 1];
    let f_last = candidates(p_last, s_last, None, ids, pref)[0].0;
    out[n - 1] = Transit {
        patch: p_last,
        start_corner: s_last,
        finish_corner: f_last,
        crossfeed: pick_crossfeed(s_last, f_last, preferred[p_last]),
        retract_before: false,
    };
    let mut s = s_last;
    for i in (1..n).rev() {
        let (ps, pf, retract) = back[i][s as usize];
        out[i].retract_before = retract;
        out[i - 1] = Transit {
            patch: order[i - 1],
            start_corner: ps,
            finish_corner: pf,
            crossfeed: pick_crossfeed(ps, pf, preferred[order[i - 1]]),
            retract_before: false,
        };
        s = ps;
    }
    (out, best.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Corner ids of a `w × h` grid of unit patches, all oriented alike.
    fn grid_ids(w: usize, h: usize) -> Vec<[u32; 4]> {
        let id = |x: usize, y: usize| (y * (w + 1) + x) as u32;
        (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                [id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)]
            })
            .collect()
    }

    #[test]
    fn a_row_of_patches_needs_no_retraction() {
        let ids = grid_ids(4, 1);
        let (t, r) = select(
            &[0, 1, 2, 3],
            &ids,
            &[Crossfeed::U; 4],
            false,
            None,
            Some(0),
        );
        assert_eq!(r, 0);
        for w in t.windows(2) {
            assert_eq!(
                ids[w[0].patch][w[0].finish_corner as usize],
                ids[w[1].patch][w[1].start_corner as usize]
            );
        }
        assert!(t.iter().all(|x| x.start_corner != x.finish_corner));
    }

    #[test]
    fn a_corner_connection_forces_backtracking() {
        // Patches 0 and 1 share only corner id 4: patch 0 must finish there, so it must not
        // start there; starting patch 0 at its corner 2 (= id 4) must fail and backtrack.
        let ids = vec![[0, 1, 4, 3], [4, 5, 6, 7]];
        let (t, r) = select(&[0, 1], &ids, &[Crossfeed::U; 2], false, None, None);
        assert_eq!(r, 0);
        assert_eq!(ids[0][t[0].finish_corner as usize], 4);
        let (_, r) = select(&[0, 1], &ids, &[Crossfeed::U; 2], false, None, Some(2));
        assert_eq!(
            r, 1,
            "starting at the only shared corner leaves a retraction"
        );
    }

    #[test]
    fn a_strict_crossfeed_is_kept_at_the_price_of_a_retraction() {
        // Patch 0 starts at corner 1, (1, 0), and meets patch 1 only at its corner 2,
        // (1, 1): finishing there means passes along u (crossfeed V).
        let ids = vec![[0, 1, 4, 3], [4, 5, 6, 7]];
        let (t, r) = select(&[0, 1], &ids, &[Crossfeed::U; 2], false, None, Some(1));
        assert_eq!(
            (r, t[0].crossfeed, t[0].finish_corner),
            (0, Crossfeed::V, 2)
        );
        let (t, r) = select(&[0, 1], &ids, &[Crossfeed::U; 2], true, None, Some(1));
        assert_eq!(r, 1);
        assert!(t.iter().all(|x| x.crossfeed == Crossfeed::U
            && crossfeeds(x.start_corner, x.finish_corner).contains(&Crossfeed::U)));
        assert!(t[1].retract_before);
    }

    #[test]
    fn kept_crossfeeds_finish_where_the_natural_pass_count_leads_unless_that_retracts() {
        // Two patches side by side, passes along v (crossfeed U): each may finish on
        // either end of its last pass at no retraction, so each takes its natural parity
        // (odd: the far side in v).
        let ids = grid_ids(2, 1);
        for natural in [[true, false], [false, true], [true, true], [false, false]] {
            let (t, r) = select(
                &[0, 1],
                &ids,
                &[Crossfeed::U; 2],
                true,
                Some(&natural),
                Some(0),
            );
            assert_eq!(r, 0);
            for x in &t {
                let ((_, sv), (_, fv)) = (corner_uv(x.start_corner), corner_uv(x.finish_corner));
                assert_eq!(fv != sv, natural[x.patch], "{natural:?}: {t:?}");
            }
        }
        // Patches meeting at one corner only: patch 0 started at (0, 0) must finish at
        // (1, 1), an odd count, to go on without a retraction; an even natural count does
        // not buy a retraction.
        let ids = vec![[0, 1, 4, 3], [4, 5, 6, 7]];
        let (t, r) = select(
            &[0, 1],
            &ids,
            &[Crossfeed::U; 2],
            true,
            Some(&[false, false]),
            Some(0),
        );
        assert_eq!((r, t[0].finish_corner), (0, 2));
    }
}
