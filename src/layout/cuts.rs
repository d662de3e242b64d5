//! A domain laid flat in one chart that does not fill a rectangle (a notch in its outline, a
//! hole) cut into rectangles where its concave corners need it: at each concave corner the
//! two boundary sides meeting there are carried on into the domain until they reach its
//! boundary again. Sides between faces the mesh does not join (a crease's zero-width strip)
//! are boundary too: they are cut, and carried on past their ends the same way. Between
//! those lines every region is a rectangle, and a line ends only on the boundary, so
//! neighbouring regions meet side to side and corner to corner: the patch order can always
//! pass from a patch to the next at a corner they share. Knot lines and T-junctions
//! elsewhere cut nothing.
//!
//! Owns: the cut, in chart coordinates. Must not: evaluate the surface or read the mesh.

/// The rectangles `[s0, s1, t0, t1]` (knot units) the domain made of `faces` (chart
/// rectangles, not overlapping) falls into when cut at its concave corners and along the
/// sides between faces `i` and `j` for which `joined(i, j)` is false, in the order of their
/// lower-left corners (by `t`, then `s`). `tol` is the distance (knot units) within which
/// two face sides lie on one line. `None` if a region is not a rectangle.
pub fn cut_at_concave_corners(
    faces: &[[f64; 4]],
    joined: &dyn Fn(usize, usize) -> bool,
    tol: f64,
) -> Option<Vec<[f64; 4]>> {
    let mut lines = [Vec::new(), Vec::new()];
    for r in faces {
        lines[0].extend([r[0], r[1]]);
        lines[1].extend([r[2], r[3]]);
    }
    for l in lines.iter_mut() {
        crate::sort::sort_floats(l);
        l.dedup_by(|a, b| (*a - *b).abs() <= tol);
    }
    let [s, t] = &lines;
    let (ns, nt) = (s.len().checked_sub(1)?, t.len().checked_sub(1)?);
    // The face holding each cell of the grid of all face sides, if any: each face fills the
    // cells between the lines its sides lie on (found by bisection, within `tol`).
    let line_at = |l: &[f64], x: f64| l.partition_point(|&y| y < x - tol).min(l.len() - 1);
    let mut face_of = vec![None; ns * nt];
    for (f, r) in faces.iter().enumerate() {
        let (i0, i1) = (line_at(s, r[0]), line_at(s, r[1]));
        let (j0, j1) = (line_at(t, r[2]), line_at(t, r[3]));
        for j in j0..j1 {
            for i in i0..i1 {
                face_of[j * ns + i].get_or_insert(f);
            }
        }
    }
    let at = |i: isize, j: isize| -> Option<usize> {
        if i >= 0 && j >= 0 && (i as usize) < ns && (j as usize) < nt {
            face_of[j as usize * ns + i as usize]
        } else {
            None
        }
    };
    // Cut cell sides: `vcut[j * (ns + 1) + a]` on line `s[a]` in row `j`, `hcut[b * ns + i]`
    // on line `t[b]` in column `i`. A side is open when both its cells are inside and their
    // faces are one or joined; a side between faces not joined is cut from the start.
    let open = |x: (isize, isize), y: (isize, isize)| match (at(x.0, x.1), at(y.0, y.1)) {
        (Some(f), Some(g)) => f == g || joined(f, g),
        _ => false,
    };
    let inside_pair =
        |x: (isize, isize), y: (isize, isize)| at(x.0, x.1).is_some() && at(y.0, y.1).is_some();
    let mut vcut = vec![false; nt * (ns + 1)];
    let mut hcut = vec![false; (nt + 1) * ns];
    for j in 0..nt as isize {
        for a in 1..ns as isize {
            if inside_pair((a - 1, j), (a, j)) && !open((a - 1, j), (a, j)) {
                vcut[j as usize * (ns + 1) + a as usize] = true;
            }
        }
    }
    for b in 1..nt as isize {
        for i in 0..ns as isize {
            if inside_pair((i, b - 1), (i, b)) && !open((i, b - 1), (i, b)) {
                hcut[b as usize * ns + i as usize] = true;
            }
        }
    }
    let (walls_v, walls_h) = (vcut.clone(), hcut.clone());
    // A side is boundary when one of its cells is outside, or it is a wall.
    let h_boundary = |i: isize, b: isize| {
        (at(i, b - 1).is_some() != at(i, b).is_some())
            || (i >= 0
                && (i as usize) < ns
                && b >= 1
                && (b as usize) < nt
                && walls_h[b as usize * ns + i as usize])
    };
    let v_boundary = |a: isize, j: isize| {
        (at(a - 1, j).is_some() != at(a, j).is_some())
            || (j >= 0
                && (j as usize) < nt
                && a >= 1
                && (a as usize) < ns
                && walls_v[j as usize * (ns + 1) + a as usize])
    };
    // At every grid point, a boundary side that ends there while the line runs on between
    // two inside cells is carried on until it meets the boundary.
    for b in 0..=nt as isize {
        for a in 0..=ns as isize {
            // Along t[b]: the side to the left (column a − 1) and to the right (column a).
            for (from, step) in [(a - 1, 1isize), (a, -1isize)] {
                let ahead = from + step;
                if !h_boundary(from, b) || h_boundary(ahead, b) {
                    continue;
                }
                let mut i = ahead;
                while inside_pair((i, b - 1), (i, b)) && !walls_h[b as usize * ns + i as usize] {
                    hcut[b as usize * ns + i as usize] = true;
                    i += step;
                }
            }
            // Along s[a]: the side below (row b − 1) and above (row b).
            for (from, step) in [(b - 1, 1isize), (b, -1isize)] {
                let ahead = from + step;
                if !v_boundary(a, from) || v_boundary(a, ahead) {
                    continue;
                }
                let mut j = ahead;
                while inside_pair((a - 1, j), (a, j))
                    && !walls_v[j as usize * (ns + 1) + a as usize]
                {
                    vcut[j as usize * (ns + 1) + a as usize] = true;
                    j += step;
                }
            }
        }
    }
    // Regions: inside cells joined across uncut sides, found in row-major order.
    let mut region = vec![usize::MAX; ns * nt];
    let mut out = Vec::new();
    for start in 0..ns * nt {
        if face_of[start].is_none() || region[start] != usize::MAX {
            continue;
        }
        let id = out.len();
        region[start] = id;
        let mut stack = vec![start];
        let (mut lo, mut hi) = ([ns, nt], [0, 0]);
        let mut count = 0;
        while let Some(c) = stack.pop() {
            let (i, j) = (c % ns, c / ns);
            count += 1;
            lo = [lo[0].min(i), lo[1].min(j)];
            hi = [hi[0].max(i + 1), hi[1].max(j + 1)];
            let mut next = |ok: bool, n: usize| {
                if ok && face_of[n].is_some() && region[n] == usize::MAX {
                    region[n] = id;
                    stack.push(n);
                }
            };
            next(i > 0 && !vcut[j * (ns + 1) + i], c.wrapping_sub(1));
            next(i + 1 < ns && !vcut[j * (ns + 1) + i + 1], c + 1);
            next(j > 0 && !hcut[j * ns + i], c.wrapping_sub(ns));
            next(j + 1 < nt && !hcut[(j + 1) * ns + i], c + ns);
        }
        if count != (hi[0] - lo[0]) * (hi[1] - lo[1]) {
            return None;
        }
        out.push([s[lo[0]], s[hi[0]], t[lo[1]], t[hi[1]]]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit squares at the given integer positions.
    fn squares(at: &[(i32, i32)]) -> Vec<[f64; 4]> {
        at.iter()
            .map(|&(i, j)| [i as f64, i as f64 + 1.0, j as f64, j as f64 + 1.0])
            .collect()
    }

    fn grid_without(n: i32, holes: &[(i32, i32)]) -> Vec<[f64; 4]> {
        let at: Vec<(i32, i32)> = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .filter(|p| !holes.contains(p))
            .collect();
        squares(&at)
    }

    #[test]
    fn an_l_shape_is_cut_once_at_its_concave_corner() {
        // 2 × 2 less the top-right square: the corner (1, 1) carries both sides on, the
        // regions are the three squares.
        let r = cut_at_concave_corners(&grid_without(2, &[(1, 1)]), &|_, _| true, 1e-9).unwrap();
        assert_eq!(r, squares(&[(0, 0), (1, 0), (0, 1)]));
    }

    #[test]
    fn a_hole_cuts_the_lines_through_its_sides_and_nothing_else() {
        // 5 × 5 with a hole at (2, 2): the lines s = 2, 3 and t = 2, 3 run across; the knot
        // lines s = 1, 4 and t = 1, 4 cut nothing: 3 × 3 regions less the hole.
        let r = cut_at_concave_corners(&grid_without(5, &[(2, 2)]), &|_, _| true, 1e-9).unwrap();
        let spans = [(0.0, 2.0), (2.0, 3.0), (3.0, 5.0)];
        let mut want = Vec::new();
        for (k, &(t0, t1)) in spans.iter().enumerate() {
            for (l, &(s0, s1)) in spans.iter().enumerate() {
                if (k, l) != (1, 1) {
                    want.push([s0, s1, t0, t1]);
                }
            }
        }
        assert_eq!(r, want);
    }

    #[test]
    fn lines_stop_at_the_boundary_they_reach() {
        // A notch from the top, (2, 3) and (2, 4) out of 5 × 5: its two bottom corners carry
        // t = 3 outwards and s = 2, 3 down; above t = 3 nothing crosses s = 1 or s = 4.
        let r = cut_at_concave_corners(&grid_without(5, &[(2, 3), (2, 4)]), &|_, _| true, 1e-9)
            .unwrap();
        assert_eq!(
            r,
            vec![
                [0.0, 2.0, 0.0, 3.0],
                [2.0, 3.0, 0.0, 3.0],
                [3.0, 5.0, 0.0, 3.0],
                [0.0, 2.0, 3.0, 5.0],
                [3.0, 5.0, 3.0, 5.0],
            ]
        );
        // Every corner of a region inside the domain is a corner of each region it touches
        // (no T-junction between regions).
        assert_corner_to_corner(&r, 23.0);
    }

    #[test]
    fn a_crease_is_cut_and_carried_on_past_its_ends() {
        // 3 × 3 squares (face j * 3 + i at (i, j)); the faces either side of s = 1 are not
        // joined in the rows `rows`: a crease there, whether it starts on the boundary or
        // lies inside. It is cut and carried on to the boundary, and nothing else is cut.
        let faces = grid_without(3, &[]);
        for rows in [&[0, 1][..], &[1][..]] {
            let joined = |f: usize, g: usize| {
                let (a, b) = (f.min(g), f.max(g));
                !rows.iter().any(|&j| a == 3 * j && b == 3 * j + 1)
            };
            let r = cut_at_concave_corners(&faces, &joined, 1e-9).unwrap();
            assert_eq!(
                r,
                vec![[0.0, 1.0, 0.0, 3.0], [1.0, 3.0, 0.0, 3.0]],
                "{rows:?}"
            );
        }
        // Joined everywhere: one region.
        let r = cut_at_concave_corners(&faces, &|_, _| true, 1e-9).unwrap();
        assert_eq!(r, vec![[0.0, 3.0, 0.0, 3.0]]);
    }

    #[test]
    fn a_large_chart_is_cut_by_its_holes_lines_only() {
        // 200 × 200 faces with two one-face holes: the lines through the holes' sides run
        // across, 5 × 5 regions less the holes (every face is placed by bisection on the
        // lines, not tested against every cell).
        let faces = grid_without(200, &[(50, 50), (120, 80)]);
        let r = cut_at_concave_corners(&faces, &|_, _| true, 1e-9).unwrap();
        assert_eq!(r.len(), 23);
        assert_corner_to_corner(&r, faces.len() as f64);
        assert!(r.contains(&[51.0, 120.0, 51.0, 80.0]));
    }

    /// No region's corner lies inside another region's side, and the regions cover
    /// `area` once.
    fn assert_corner_to_corner(r: &[[f64; 4]], area: f64) {
        for a in r {
            for corner in [[a[0], a[2]], [a[1], a[2]], [a[0], a[3]], [a[1], a[3]]] {
                for b in r {
                    let on_s = (corner[0] == b[0] || corner[0] == b[1])
                        && corner[1] > b[2]
                        && corner[1] < b[3];
                    let on_t = (corner[1] == b[2] || corner[1] == b[3])
                        && corner[0] > b[0]
                        && corner[0] < b[1];
                    assert!(
                        !on_s && !on_t,
                        "{a:?}'s corner {corner:?} inside {b:?}'s side"
                    );
                }
            }
        }
        let total: f64 = r.iter().map(|q| (q[1] - q[0]) * (q[3] - q[2])).sum();
        assert_eq!(total, area);
    }

    #[test]
    fn regions_meet_corner_to_corner() {
        // Two holes in one column and a notch.
        let faces = grid_without(7, &[(3, 1), (3, 4), (0, 6), (1, 6)]);
        let r = cut_at_concave_corners(&faces, &|_, _| true, 1e-9).unwrap();
        assert_corner_to_corner(&r, faces.len() as f64);
    }
}
