//! The domain cut into rectangles (seed 003, §3.3; the rule the paper leaves to its
//! reference, A7): the feature boxes, and the rest of the domain in maximal rectangles.
//!
//! Every face side and box side is extended into a line across the domain's chart; the
//! cells between the lines are classed by the box holding them (or none), and cells of one
//! class are merged ([`Merge`]) so that a box inside the domain comes out whole. Cells
//! outside every face (holes, notches) are left out.

/// How cells of one class are merged into rectangles. Neither is best on every domain:
/// row by row ran the column between bumps' two boxes up through the strip above them
/// (8 rectangles where largest first makes 7), largest first cut Bike.tsm's slit domain
/// into two full-height halves and a sliver beside the slit (its plan 16 % longer); the
/// planner takes the one whose rectangles need the shorter path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Merge {
    /// From the lowest row up, leftmost first: as wide as the class runs, then as high as
    /// the whole width stays in the class.
    Rows,
    /// Of all rectangles of one class's free cells, the one with the most chart area (the
    /// lowest, then leftmost, then narrowest of equal ones), again and again.
    Largest,
}

/// A rectangle of the domain's chart and the feature region it belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartRect {
    /// `[s0, s1, t0, t1]` in knot units.
    pub chart: [f64; 4],
    /// The feature region's label, `None` for the rest of the domain.
    pub feature: Option<u32>,
}

/// The rectangles of the domain made of `faces` (chart rectangles) with the feature
/// `boxes` (label, chart rectangle; not overlapping) in it, cells merged by `merge`; `tol`
/// is the distance (knot units) within which two lines are one.
pub fn rectangles(
    faces: &[[f64; 4]],
    boxes: &[(u32, [f64; 4])],
    tol: f64,
    merge: Merge,
) -> Vec<ChartRect> {
    let mut lines = [Vec::new(), Vec::new()];
    for r in faces.iter().chain(boxes.iter().map(|b| &b.1)) {
        lines[0].extend([r[0], r[1]]);
        lines[1].extend([r[2], r[3]]);
    }
    // Box sides outside the domain's extent are clipped to it.
    let lo = [0, 2].map(|k| faces.iter().map(|f| f[k]).fold(f64::INFINITY, f64::min));
    let hi = [1, 3].map(|k| faces.iter().map(|f| f[k]).fold(f64::NEG_INFINITY, f64::max));
    for k in 0..2 {
        for x in lines[k].iter_mut() {
            *x = x.clamp(lo[k], hi[k]);
        }
        crate::sort::sort_floats(&mut lines[k]);
        lines[k].dedup_by(|a, b| (*a - *b).abs() <= tol);
    }
    let (ns, nt) = (
        lines[0].len().saturating_sub(1),
        lines[1].len().saturating_sub(1),
    );
    // Class of each cell: None outside the domain, Some(label) (0 for the rest) inside.
    let mut class = vec![None; ns * nt];
    for j in 0..nt {
        for i in 0..ns {
            let c = [
                0.5 * (lines[0][i] + lines[0][i + 1]),
                0.5 * (lines[1][j] + lines[1][j + 1]),
            ];
            let inside =
                |r: &[f64; 4]| c[0] >= r[0] && c[0] <= r[1] && c[1] >= r[2] && c[1] <= r[3];
            if faces.iter().any(inside) {
                class[j * ns + i] = Some(boxes.iter().find(|b| inside(&b.1)).map_or(0, |b| b.0));
            }
        }
    }
    let picked = match merge {
        Merge::Rows => by_rows(ns, nt, &class),
        Merge::Largest => largest_first(&lines, ns, nt, &class),
    };
    picked
        .into_iter()
        .map(|[i0, i1, j0, j1]| {
            let c = class[j0 * ns + i0].unwrap_or(0);
            ChartRect {
                chart: [
                    lines[0][i0],
                    lines[0][i1 + 1],
                    lines[1][j0],
                    lines[1][j1 + 1],
                ],
                feature: (c != 0).then_some(c),
            }
        })
        .collect()
}

/// [`Merge::Rows`] on an `ns × nt` grid of cell classes (row-major): the rectangles as
/// `[i0, i1, j0, j1]` cell ranges.
fn by_rows(ns: usize, nt: usize, class: &[Option<u32>]) -> Vec<[usize; 4]> {
    let mut taken = vec![false; ns * nt];
    let mut out = Vec::new();
    for j in 0..nt {
        for i in 0..ns {
            let Some(c) = class[j * ns + i] else { continue };
            if taken[j * ns + i] {
                continue;
            }
            let free = |a: usize, b: usize, taken: &[bool]| {
                class[b * ns + a] == Some(c) && !taken[b * ns + a]
            };
            let mut i1 = i;
            while i1 + 1 < ns && free(i1 + 1, j, &taken) {
                i1 += 1;
            }
            let mut j1 = j;
            while j1 + 1 < nt && (i..=i1).all(|a| free(a, j1 + 1, &taken)) {
                j1 += 1;
            }
            for b in j..=j1 {
                for a in i..=i1 {
                    taken[b * ns + a] = true;
                }
            }
            out.push([i, i1, j, j1]);
        }
    }
    out
}

/// [`Merge::Largest`] on the `ns × nt` cells between `lines` (`[s lines, t lines]`) of
/// classes `class` (row-major): the rectangles as `[i0, i1, j0, j1]` cell ranges.
fn largest_first(
    lines: &[Vec<f64>; 2],
    ns: usize,
    nt: usize,
    class: &[Option<u32>],
) -> Vec<[usize; 4]> {
    let width = |i: usize| lines[0][i + 1] - lines[0][i];
    let mut taken = vec![false; ns * nt];
    let mut out = Vec::new();
    loop {
        // Free cells of one class straight above each cell, itself included.
        let mut up = vec![0usize; ns * nt];
        for j in (0..nt).rev() {
            for i in 0..ns {
                let c = j * ns + i;
                if class[c].is_some() && !taken[c] {
                    let above = j + 1 < nt && class[c + ns] == class[c] && !taken[c + ns];
                    up[c] = 1 + if above { up[c + ns] } else { 0 };
                }
            }
        }
        // (area, i0, i1, j0, j1) of the best so far.
        let mut best: Option<(f64, [usize; 4])> = None;
        for j in 0..nt {
            for i in 0..ns {
                let c = j * ns + i;
                if up[c] == 0 {
                    continue;
                }
                let (mut rows, mut w) = (usize::MAX, 0.0);
                for i1 in i..ns {
                    let c1 = j * ns + i1;
                    if up[c1] == 0 || class[c1] != class[c] {
                        break;
                    }
                    rows = rows.min(up[c1]);
                    w += width(i1);
                    let h = lines[1][j + rows] - lines[1][j];
                    if best.is_none_or(|b| w * h > b.0) {
                        best = Some((w * h, [i, i1, j, j + rows - 1]));
                    }
                }
            }
        }
        let Some((_, r)) = best else {
            break;
        };
        for b in r[2]..=r[3] {
            for a in r[0]..=r[1] {
                taken[b * ns + a] = true;
            }
        }
        out.push(r);
    }
    out
}

/// Grows feature boxes over the thin strips their sides leave: each side (in the order
/// left, right, bottom, top; boxes in order) moves outward to the nearest line that ends
/// a strip — the domain's edge, a hole's edge or another box's parallel side — when that
/// line lies within `reach[k]` (knot units: `[along s, along t]` for box `k`) and the strip
/// it sweeps is inside the domain and outside every other box. Such a strip would
/// otherwise be a rectangle of its own, narrower than a few side steps yet as long as the
/// box, cut in passes of its full length (or, against another box's side, a step in the
/// rectangles round it). `tol` is the distance (knot units) within which two lines are one.
pub fn grow_over_strips(
    faces: &[[f64; 4]],
    boxes: &mut [(u32, [f64; 4])],
    reach: &[[f64; 2]],
    tol: f64,
) {
    let area = |r: &[f64; 4]| (r[1] - r[0]).max(0.0) * (r[3] - r[2]).max(0.0);
    let meet = |a: &[f64; 4], b: &[f64; 4]| {
        [
            a[0].max(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].min(b[3]),
        ]
    };
    for k in 0..boxes.len() {
        // Sides: index into the box (0 s0, 1 s1, 2 t0, 3 t1); the axis; the outward sign.
        for side in 0..4 {
            let axis = side / 2;
            let out = if side % 2 == 0 { -1.0 } else { 1.0 };
            let b = boxes[k].1;
            let at = b[side];
            let limit = reach[k][axis];
            // The box's extent across the side.
            let (c0, c1) = if axis == 0 {
                (b[2], b[3])
            } else {
                (b[0], b[1])
            };
            // Whether the domain ends at line `x` somewhere along the box: the faces that
            // start at `x` on the far side do not cover the box's extent.
            let ends_at = |x: f64| {
                let far = if out > 0.0 { 2 * axis } else { 2 * axis + 1 };
                let covered: f64 = faces
                    .iter()
                    .filter(|f| (f[far] - x).abs() <= tol)
                    .map(|f| {
                        let (f0, f1) = if axis == 0 {
                            (f[2], f[3])
                        } else {
                            (f[0], f[1])
                        };
                        (f1.min(c1) - f0.max(c0)).max(0.0)
                    })
                    .sum();
                covered < (c1 - c0) - tol
            };
            // Lines beyond the side within reach: face sides where the domain ends beyond
            // them (its bound, a hole's or a notch's edge), and other boxes' sides along the
            // same axis.
            let mut lines: Vec<f64> = Vec::new();
            for f in faces {
                let x = f[2 * axis + usize::from(out > 0.0)];
                if out * (x - at) > tol && out * (x - at) <= limit && ends_at(x) {
                    lines.push(x);
                }
            }
            for (j, o) in boxes.iter().enumerate() {
                if j != k {
                    lines.extend([o.1[2 * axis], o.1[2 * axis + 1]]);
                }
            }
            let Some(to) = lines
                .into_iter()
                .filter(|&x| out * (x - at) > tol && out * (x - at) <= limit)
                .min_by(|a, b| (out * (a - at)).total_cmp(&(out * (b - at))))
            else {
                continue;
            };
            let mut strip = b;
            strip[side ^ 1] = at;
            strip[side] = to;
            // An area thinner than `tol` across the strip counts as none.
            let slack = tol * ((strip[1] - strip[0]) + (strip[3] - strip[2]));
            let inside: f64 = faces.iter().map(|f| area(&meet(f, &strip))).sum();
            let taken = boxes
                .iter()
                .enumerate()
                .any(|(j, o)| j != k && area(&meet(&o.1, &strip)) > slack);
            if !taken && area(&strip) - inside <= slack {
                boxes[k].1[side] = to;
            }
        }
    }
}

/// The boundary passes a neighbour cuts. A rectangle's zig-zag has a pass on each of its
/// two sides along the passes; where rectangles whose passes run the same way meet along
/// such sides, one pass along the seam serves both, as the pass one side step in from it
/// is as far from it as from a pass of the rectangle's own there. For rectangles `rects`
/// (chart `[s0, s1, t0, t1]`, passes along s where `along_s[k]`, else along t), per
/// rectangle whether its pass on the low side (t0, or s0) and on the high side is left
/// to neighbours: the side lies within the opposite sides of neighbours with passes the
/// same way, on its line, that keep their passes. Rectangles are taken in order, the low
/// side first; `tol` is the distance (knot units) within which two lines are one.
pub fn shared_seams(
    rects: &[[f64; 4]],
    along_s: &[bool],
    tol: f64,
    smooth: &dyn Fn(usize, usize, f64, [f64; 2]) -> bool,
) -> Vec<[bool; 2]> {
    let n = rects.len().min(along_s.len());
    let mut left = vec![[false; 2]; n];
    let mut kept = vec![[false; 2]; n];
    // Side `e` of rectangle `k` (0 low, 1 high): its line, and its extent along the line.
    let side = |k: usize, e: usize| -> (f64, f64, f64) {
        let r = &rects[k];
        if along_s[k] {
            (r[2 + e], r[0], r[1])
        } else {
            (r[e], r[2], r[3])
        }
    };
    for k in 0..n {
        for e in 0..2 {
            if kept[k][e] {
                continue;
            }
            let (x, a, b) = side(k, e);
            // Neighbours beyond this side, with passes the same way and their pass on it.
            let mut cover: Vec<(f64, f64, usize)> = (0..n)
                .filter(|&j| j != k && along_s[j] == along_s[k] && !left[j][1 - e])
                .filter_map(|j| {
                    let (y, c, d) = side(j, 1 - e);
                    ((y - x).abs() <= tol
                        && d > a + tol
                        && c < b - tol
                        && smooth(k, j, x, [a.max(c), b.min(d)]))
                    .then_some((c, d, j))
                })
                .collect();
            crate::sort::sort_by(&mut cover, |p, q| p.0.total_cmp(&q.0));
            let mut reach = a;
            for &(c, d, _) in &cover {
                if c > reach + tol {
                    break;
                }
                reach = reach.max(d);
            }
            if reach >= b - tol {
                left[k][e] = true;
                for &(_, _, j) in &cover {
                    kept[j][1 - e] = true;
                }
            }
        }
    }
    left
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plate of `ns × nt` unit faces.
    fn plate(ns: usize, nt: usize) -> Vec<[f64; 4]> {
        (0..nt)
            .flat_map(|j| {
                (0..ns).map(move |i| [i as f64, i as f64 + 1.0, j as f64, j as f64 + 1.0])
            })
            .collect()
    }

    fn charts(rects: &[ChartRect]) -> Vec<([f64; 4], Option<u32>)> {
        rects.iter().map(|r| (r.chart, r.feature)).collect()
    }

    /// Two boxes side by side in an 11 × 8 plate: the strips below and above them run the
    /// whole width, and the rest is three rectangles (seven in all). The row-by-row merge
    /// gave eight: the column between the boxes ran up through the strip above them.
    #[test]
    fn the_rest_comes_in_few_broad_rectangles() {
        let boxes = [(1, [0.0, 5.0, 2.0, 6.0]), (2, [7.0, 10.0, 3.0, 6.0])];
        let r = rectangles(&plate(11, 8), &boxes, 1e-9, Merge::Largest);
        assert_eq!(
            charts(&r),
            vec![
                ([0.0, 11.0, 0.0, 2.0], None),
                ([0.0, 11.0, 6.0, 8.0], None),
                ([0.0, 5.0, 2.0, 6.0], Some(1)),
                ([7.0, 10.0, 3.0, 6.0], Some(2)),
                ([5.0, 7.0, 2.0, 6.0], None),
                ([7.0, 11.0, 2.0, 3.0], None),
                ([10.0, 11.0, 3.0, 6.0], None),
            ]
        );
    }

    /// Row by row, the same plate comes in eight rectangles: the column between the boxes
    /// runs up through the strip above them.
    #[test]
    fn row_by_row_the_column_runs_up_through_the_strip() {
        let boxes = [(1, [0.0, 5.0, 2.0, 6.0]), (2, [7.0, 10.0, 3.0, 6.0])];
        let r = rectangles(&plate(11, 8), &boxes, 1e-9, Merge::Rows);
        assert_eq!(r.len(), 8, "{:?}", charts(&r));
        assert!(charts(&r).contains(&([5.0, 7.0, 3.0, 8.0], None)));
    }

    /// A plate slit from the top down to a third of its height (Bike.tsm's domain): row by
    /// row, a strip below the slit and the two sides above it; largest first, the two
    /// full-height sides and a sliver as wide as the slit below it.
    #[test]
    fn largest_first_leaves_a_sliver_below_a_slit() {
        let faces: Vec<[f64; 4]> = [[0.0, 4.9], [4.9, 5.1], [5.1, 10.0]]
            .iter()
            .flat_map(|s| [[0.0, 3.0], [3.0, 10.0]].map(|t| [s[0], s[1], t[0], t[1]]))
            .filter(|f| !(f[0] == 4.9 && f[2] == 3.0))
            .collect();
        let rows = rectangles(&faces, &[], 1e-9, Merge::Rows);
        assert_eq!(
            charts(&rows),
            vec![
                ([0.0, 10.0, 0.0, 3.0], None),
                ([0.0, 4.9, 3.0, 10.0], None),
                ([5.1, 10.0, 3.0, 10.0], None),
            ]
        );
        let largest = rectangles(&faces, &[], 1e-9, Merge::Largest);
        assert_eq!(
            charts(&largest),
            vec![
                ([0.0, 4.9, 0.0, 10.0], None),
                ([5.1, 10.0, 0.0, 10.0], None),
                ([4.9, 5.1, 0.0, 3.0], None),
            ]
        );
    }

    /// A hole's cells are left out: the plate round a 2 × 2 hole comes in four rectangles.
    #[test]
    fn holes_are_left_out() {
        let faces: Vec<[f64; 4]> = plate(6, 6)
            .into_iter()
            .filter(|f| !(f[0] >= 2.0 && f[1] <= 4.0 && f[2] >= 2.0 && f[3] <= 4.0))
            .collect();
        for merge in [Merge::Rows, Merge::Largest] {
            let r = rectangles(&faces, &[], 1e-9, merge);
            let area: f64 = r
                .iter()
                .map(|x| (x.chart[1] - x.chart[0]) * (x.chart[3] - x.chart[2]))
                .sum();
            assert_eq!(r.len(), 4, "{merge:?}: {:?}", charts(&r));
            assert_eq!(area, 32.0);
        }
    }

    /// Sides move over strips narrower than the reach to the domain's edge and to another
    /// box's side, never into a hole or another box, and not over wider strips.
    #[test]
    fn boxes_grow_over_thin_strips_only() {
        let faces: Vec<[f64; 4]> = plate(11, 8)
            .into_iter()
            .filter(|f| !(f[0] == 5.0 && f[2] == 0.0))
            .collect();
        let mut boxes = vec![
            // 0.2 from the left edge, 0.3 above the hole's top (t 1), its top 0.1 above
            // the second box's.
            (1, [0.2, 4.5, 1.3, 6.0]),
            // 0.5 from the right edge (wider than the reach), 0.6 below the top.
            (2, [6.0, 10.5, 3.0, 5.9]),
        ];
        grow_over_strips(&faces, &mut boxes, &[[0.4, 0.4], [0.4, 0.4]], 1e-9);
        // The first box's bottom stays: the strip below it reaches the hole's top only
        // at s 5, outside its extent, and the plate's bottom (t 0) is beyond reach.
        assert_eq!(boxes[0].1, [0.0, 4.5, 1.3, 6.0]);
        assert_eq!(boxes[1].1, [6.0, 10.5, 3.0, 6.0]);
        // A box whose strip below reaches into a hole does not grow over it.
        let mut over_hole = vec![(1, [4.5, 5.5, 1.2, 3.0])];
        grow_over_strips(&faces, &mut over_hole, &[[0.0, 2.0]], 1e-9);
        assert_eq!(over_hole[0].1, [4.5, 5.5, 1.0, 3.0]);
        // Nor into another box.
        let mut pair = vec![(1, [1.0, 3.0, 1.0, 3.0]), (2, [1.0, 3.0, 3.2, 5.0])];
        grow_over_strips(&faces, &mut pair, &[[0.0, 0.5], [0.0, 0.5]], 1e-9);
        assert_eq!(pair[0].1, [1.0, 3.0, 1.0, 3.2]);
        assert_eq!(pair[1].1, [1.0, 3.0, 3.2, 5.0]);
    }

    /// bumps' layout at r 1, h 0.05 mm as it was written down (seven rectangles, chart
    /// units of mm): the pass along each seam
    /// between rectangles cut the same way is cut once; seams where the passes meet a side
    /// end-on, and sides only partly against a neighbour cut the same way, keep theirs.
    #[test]
    fn a_seam_between_passes_the_same_way_is_cut_once() {
        let rects = [
            [-40.0, -1.27, -18.56, 18.56],
            [-40.0, 40.0, -30.0, -18.56],
            [-40.0, 40.0, 18.56, 30.0],
            [8.91, 34.0, -12.19, 18.56],
            [-1.27, 8.91, -18.56, 18.56],
            [34.0, 40.0, -18.56, 18.56],
            [8.91, 34.0, -18.56, -12.19],
        ];
        let along_s = [true, true, true, false, false, false, true];
        let left = shared_seams(&rects, &along_s, 1e-9, &|_, _, _, _| true);
        assert_eq!(
            left,
            vec![
                // Both sides: the strips below and above it run the whole width.
                [true, true],
                [false, false],
                // Its bottom is only partly against the first box.
                [false, false],
                // Both sides within the columns beside it.
                [true, true],
                [false, false],
                [false, false],
                // Its top meets the second box's passes end-on.
                [true, false],
            ]
        );
    }

    /// Two rectangles of equal sides, cut the same way: the first leaves the seam to the
    /// second, which keeps it; cut different ways, or across a crease, both keep it.
    #[test]
    fn one_of_two_equal_sides_keeps_the_seam() {
        let rects = [[0.0, 4.0, 0.0, 2.0], [0.0, 4.0, 2.0, 3.0]];
        assert_eq!(
            shared_seams(&rects, &[true, true], 1e-9, &|_, _, _, _| true),
            vec![[false, true], [false, false]]
        );
        assert_eq!(
            shared_seams(&rects, &[true, false], 1e-9, &|_, _, _, _| true),
            vec![[false, false], [false, false]]
        );
        // Across a crease neither leaves its pass to the other.
        assert_eq!(
            shared_seams(&rects, &[true, true], 1e-9, &|_, _, _, _| false),
            vec![[false, false], [false, false]]
        );
        // With a gap between the two above it (a hole), the long side keeps its pass, and
        // the short ones leave theirs to it.
        let split = [
            [0.0, 4.0, 0.0, 2.0],
            [0.0, 1.5, 2.0, 3.0],
            [2.5, 4.0, 2.0, 3.0],
        ];
        assert_eq!(
            shared_seams(&split, &[true, true, true], 1e-9, &|_, _, _, _| true),
            vec![[false, false], [true, false], [true, false]]
        );
    }
}
