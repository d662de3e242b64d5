//! Marker-based watershed on a grid of values (seed 003, §3.1.2, eq. 11): every local
//! maximum above the background is a marker, and its region grows downhill from it.
//!
//! A point at offset `(di, dj)` from its marker joins the marker's region when its value is
//! at most the mean of its neighbours towards the marker — `(i − sᵢ, j)`, `(i, j − sⱼ)` and
//! `(i − sᵢ, j − sⱼ)` with `s` the signs of the offset (one neighbour on the marker's own row
//! or column) — that already carry the label, and at least the background value. Markers
//! grow highest first, breadth first, and a labelled point keeps its first label. Regions
//! with fewer than [`MIN_REGION_POINTS`] points go back to the background (a ring of small
//! maxima round a bump's foot would otherwise make regions of their own).

use super::Grid;
use std::collections::VecDeque;

/// Regions smaller than this many grid points are dropped to the background.
pub const MIN_REGION_POINTS: usize = 4;

/// The background label: no region.
pub const BACKGROUND: u32 = 0;

/// One region: its marker and size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    /// Its label in the label grid (from 1).
    pub label: u32,
    /// The grid point of its marker (a local maximum).
    pub marker: (usize, usize),
    /// Grid points in it.
    pub points: usize,
}

/// Regions of `values` (where `valid`), grown from their maxima down to `background`:
/// the label grid ([`BACKGROUND`] outside every region and where not valid) and the
/// regions, labelled 1, 2, … in order of falling marker value.
pub fn watershed(
    values: &Grid<f64>,
    valid: &Grid<bool>,
    background: f64,
) -> (Grid<u32>, Vec<Region>) {
    let (nx, ny) = (values.nx, values.ny);
    let ok = |i: usize, j: usize| valid.at(i, j) && values.at(i, j).is_finite();
    // Markers: not below any valid neighbour; on a plateau, the first point in grid order.
    let mut markers: Vec<(usize, usize)> = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let x = values.at(i, j);
            if !ok(i, j) || !(x >= background) {
                continue;
            }
            let top = values
                .neighbours(i, j)
                .filter(|&(a, b)| ok(a, b))
                .all(|(a, b)| {
                    let y = values.at(a, b);
                    x > y || (x == y && (j, i) < (b, a))
                });
            if top {
                markers.push((i, j));
            }
        }
    }
    crate::sort::sort_by(&mut markers, |a, b| {
        values
            .at(b.0, b.1)
            .total_cmp(&values.at(a.0, a.1))
            .then((a.1, a.0).cmp(&(b.1, b.0)))
    });
    let mut labels = Grid::filled(nx, ny, BACKGROUND);
    let mut tried = Grid::filled(nx, ny, 0u32);
    let mut regions = Vec::new();
    for (k, &(mi, mj)) in markers.iter().enumerate() {
        if labels.at(mi, mj) != BACKGROUND {
            continue;
        }
        let label = k as u32 + 1;
        labels.set(mi, mj, label);
        tried.set(mi, mj, label);
        let mut queue: VecDeque<(usize, usize)> = VecDeque::new();
        let mut points = 1;
        let outward =
            |i: usize, j: usize, queue: &mut VecDeque<(usize, usize)>, tried: &mut Grid<u32>| {
                for (a, b) in values.neighbours(i, j) {
                    // Away from the marker in each coordinate, not back towards it.
                    let away = a.abs_diff(mi) >= i.abs_diff(mi) && b.abs_diff(mj) >= j.abs_diff(mj);
                    if away && tried.at(a, b) != label {
                        tried.set(a, b, label);
                        queue.push_back((a, b));
                    }
                }
            };
        outward(mi, mj, &mut queue, &mut tried);
        while let Some((i, j)) = queue.pop_front() {
            if !ok(i, j) || labels.at(i, j) != BACKGROUND {
                continue;
            }
            let x = values.at(i, j);
            if !(x >= background) {
                continue;
            }
            let si = (i as isize - mi as isize).signum();
            let sj = (j as isize - mj as isize).signum();
            let step = |c: usize, s: isize| (c as isize - s) as usize;
            let mut inner = vec![];
            if si != 0 {
                inner.push((step(i, si), j));
            }
            if sj != 0 {
                inner.push((i, step(j, sj)));
            }
            if si != 0 && sj != 0 {
                inner.push((step(i, si), step(j, sj)));
            }
            let own: Vec<f64> = inner
                .iter()
                .filter(|&&(a, b)| ok(a, b) && labels.at(a, b) == label)
                .map(|&(a, b)| values.at(a, b))
                .collect();
            if own.is_empty() {
                continue;
            }
            let mean = own.iter().sum::<f64>() / own.len() as f64;
            if x <= mean {
                labels.set(i, j, label);
                points += 1;
                outward(i, j, &mut queue, &mut tried);
            }
        }
        regions.push(Region {
            label,
            marker: (mi, mj),
            points,
        });
    }
    // Small regions back to the background; the rest relabelled 1, 2, … in order.
    let mut relabel = vec![BACKGROUND; markers.len() + 1];
    let mut kept = Vec::new();
    for r in regions {
        if r.points >= MIN_REGION_POINTS {
            let label = kept.len() as u32 + 1;
            relabel[r.label as usize] = label;
            kept.push(Region { label, ..r });
        }
    }
    for l in labels.cells.iter_mut() {
        *l = relabel[*l as usize];
    }
    (labels, kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bumps(nx: usize, ny: usize, peaks: &[(f64, f64, f64, f64)]) -> Grid<f64> {
        let mut g = Grid::filled(nx, ny, 0.0);
        for j in 0..ny {
            for i in 0..nx {
                let v = peaks
                    .iter()
                    .map(|&(cx, cy, h, w)| {
                        h * (-((i as f64 - cx).powi(2) + (j as f64 - cy).powi(2)) / (w * w)).exp()
                    })
                    .sum();
                g.set(i, j, v);
            }
        }
        g
    }

    /// Every labelled point other than a marker passes eq. 11 against its inner neighbours
    /// of the same label, lies at or above the background, and regions are 4-connected.
    fn check_descent(values: &Grid<f64>, labels: &Grid<u32>, regions: &[Region], background: f64) {
        for r in regions {
            let (mi, mj) = r.marker;
            assert_eq!(labels.at(mi, mj), r.label);
            let mut count = 0;
            for j in 0..values.ny {
                for i in 0..values.nx {
                    if labels.at(i, j) != r.label {
                        continue;
                    }
                    count += 1;
                    assert!(values.at(i, j) >= background);
                    if (i, j) == (mi, mj) {
                        continue;
                    }
                    let si = (i as isize - mi as isize).signum();
                    let sj = (j as isize - mj as isize).signum();
                    let back = |c: usize, s: isize| (c as isize - s) as usize;
                    let inner: Vec<(usize, usize)> = [
                        (si != 0).then(|| (back(i, si), j)),
                        (sj != 0).then(|| (i, back(j, sj))),
                        (si != 0 && sj != 0).then(|| (back(i, si), back(j, sj))),
                    ]
                    .into_iter()
                    .flatten()
                    .filter(|&(a, b)| labels.at(a, b) == r.label)
                    .collect();
                    assert!(
                        !inner.is_empty(),
                        "({i}, {j}) has no inner neighbour of its region"
                    );
                    let mean = inner.iter().map(|&(a, b)| values.at(a, b)).sum::<f64>()
                        / inner.len() as f64;
                    assert!(
                        values.at(i, j) <= mean,
                        "({i}, {j}) rises towards its marker"
                    );
                }
            }
            assert_eq!(count, r.points);
        }
    }

    #[test]
    fn two_peaks_give_two_regions_split_between_them() {
        let values = bumps(40, 30, &[(10.0, 15.0, 1.0, 5.0), (29.0, 14.0, 0.8, 4.0)]);
        let valid = Grid::filled(40, 30, true);
        let (labels, regions) = watershed(&values, &valid, 0.05);
        assert_eq!(regions.len(), 2, "{regions:?}");
        assert_eq!(regions[0].marker, (10, 15));
        assert_eq!(regions[1].marker, (29, 14));
        check_descent(&values, &labels, &regions, 0.05);
        // Far corners are background.
        assert_eq!(labels.at(0, 0), BACKGROUND);
        assert_eq!(labels.at(39, 29), BACKGROUND);
    }

    #[test]
    fn four_peaks_around_a_hole_give_four_regions() {
        let (nx, ny) = (41, 41);
        let values = bumps(
            nx,
            ny,
            &[
                (10.0, 10.0, 1.0, 4.0),
                (30.0, 10.0, 1.0, 4.0),
                (10.0, 30.0, 1.0, 4.0),
                (30.0, 30.0, 1.0, 4.0),
            ],
        );
        let mut valid = Grid::filled(nx, ny, true);
        for j in 16..25 {
            for i in 16..25 {
                valid.set(i, j, false);
            }
        }
        let (labels, regions) = watershed(&values, &valid, 0.05);
        assert_eq!(regions.len(), 4, "{regions:?}");
        check_descent(&values, &labels, &regions, 0.05);
        for j in 16..25 {
            for i in 16..25 {
                assert_eq!(labels.at(i, j), BACKGROUND);
            }
        }
    }

    #[test]
    fn a_flat_map_has_no_region() {
        let values = Grid::filled(10, 10, 0.0);
        let valid = Grid::filled(10, 10, true);
        let (_, regions) = watershed(&values, &valid, 1e-6);
        assert!(regions.is_empty());
    }
}
