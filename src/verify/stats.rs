//! Area-weighted statistics of sampled values: the weighted quantile in linear time
//! (a histogram finds the bin, a sort of that bin alone finds the value).

/// Bins of the histogram that narrows the search.
const BINS: usize = 4096;

/// The smallest value `v` such that values `≤ v` carry at least the fraction `q` of the total
/// weight, over `(value, weight)` pairs given in chunks. `None` for no positive weight.
pub fn weighted_quantile(chunks: &[Vec<(f64, f64)>], q: f64) -> Option<f64> {
    let values = || chunks.iter().flatten();
    let total: f64 = values().map(|&(_, w)| w).sum();
    if !(total > 0.0) {
        return None;
    }
    let target = q.clamp(0.0, 1.0) * total;
    let (lo, hi) = values().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &(v, _)| {
        (a.min(v), b.max(v))
    });
    if !(hi > lo) {
        return Some(lo);
    }
    let scale = BINS as f64 / (hi - lo);
    let bin = |v: f64| (((v - lo) * scale) as usize).min(BINS - 1);
    let mut weights = vec![0.0; BINS];
    for &(v, w) in values() {
        weights[bin(v)] += w;
    }
    let mut below = 0.0;
    let mut pick = BINS - 1;
    for (b, &w) in weights.iter().enumerate() {
        if below + w >= target {
            pick = b;
            break;
        }
        below += w;
    }
    let mut inside: Vec<(f64, f64)> = values().copied().filter(|&(v, _)| bin(v) == pick).collect();
    // The standard library's sort: the simulation's summary, where a sharp peak of values
    // can put most of a million samples in one bin (`crate::sort` is for cold sorts).
    inside.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(v, w) in &inside {
        below += w;
        if below >= target {
            return Some(v);
        }
    }
    inside.last().map(|&(v, _)| v).or(Some(hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_sorting() {
        let mut rnd = crate::testing::uniform(7u64);
        let values: Vec<(f64, f64)> = (0..20_000).map(|_| (rnd().powi(3), rnd())).collect();
        let mut sorted = values.clone();
        sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
        let total: f64 = values.iter().map(|v| v.1).sum();
        for q in [0.0, 0.1, 0.5, 0.95, 0.999, 1.0] {
            let mut acc = 0.0;
            let mut expect = sorted.last().unwrap().0;
            for &(v, w) in &sorted {
                acc += w;
                if acc >= q * total {
                    expect = v;
                    break;
                }
            }
            let chunks: Vec<Vec<(f64, f64)>> = values.chunks(777).map(|c| c.to_vec()).collect();
            let got = weighted_quantile(&chunks, q).unwrap();
            assert!((got - expect).abs() <= 1e-12, "q {q}: {got} vs {expect}");
        }
        assert_eq!(
            weighted_quantile(&[vec![(2.0, 1.0)], vec![(2.0, 3.0)]], 0.95),
            Some(2.0)
        );
        assert_eq!(weighted_quantile(&[], 0.5), None);
    }
}
