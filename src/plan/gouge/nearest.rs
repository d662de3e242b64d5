//! Nearest points on the surface to a ball centre: per face a box and a few samples to start
//! from, then Newton steps on the squared distance across the face's Bézier cells.
//!
//! Owns the search only; must not decide what a distance means for the tool.

use crate::geom::{Aabb, Point3};
use crate::surface::Surface;

/// Samples per face side for the nearest-point start.
const START_SAMPLES: usize = 6;
/// Samples of a face Newton starts from (the nearest ones).
const NEAREST_STARTS: usize = 3;
/// Newton steps of the nearest-point search on one face.
const NEWTON_STEPS: usize = 30;
/// Parameter step (of a face's unit square) below which the search has converged.
const NEWTON_CONVERGED: f64 = 1e-12;
/// Most steps from one Bézier cell of a face into the next during one descent, besides
/// the Newton steps.
const MAX_CELL_CROSSINGS: usize = 16;

/// Nearest-point queries against the surface: per face its box (from the Bézier control
/// points, which contain it) and a few samples to start Newton from.
pub(super) struct Nearest<'a> {
    surface: &'a Surface,
    boxes: Vec<Aabb>,
    starts: Vec<Vec<(f64, f64, Point3)>>,
    /// The faces' boxes in a hierarchy: `nodes[0]` is the root.
    nodes: Vec<Node>,
    /// Faces in the order the leaves list them.
    order: Vec<u32>,
}

/// Faces per leaf of the hierarchy.
const LEAF_FACES: usize = 4;

/// A node of the hierarchy: its box, and either two children or a range of faces.
struct Node {
    bounds: Aabb,
    /// The first child (the second follows it) when `count` is 0, else the first of
    /// `count` faces in `order`.
    first: u32,
    count: u32,
}

impl Node {
    /// A node with nothing in it (and a placeholder while building).
    const EMPTY: Node = Node {
        bounds: Aabb {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        },
        first: 0,
        count: 0,
    };
}

/// An entry of the nearest-first search: a node or a face, by the distance to its box.
#[derive(PartialEq)]
struct Queued {
    bound: f64,
    face: bool,
    index: u32,
}

impl Eq for Queued {}

impl Ord for Queued {
    /// Reversed, so that the standard (max-)heap pops the nearest box first; ties by faces
    /// before nodes and by index.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other
            .bound
            .total_cmp(&self.bound)
            .then(self.face.cmp(&other.face))
            .then(other.index.cmp(&self.index))
    }
}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl<'a> Nearest<'a> {
    pub(super) fn new(surface: &'a Surface) -> Self {
        let n = surface.faces().len();
        let mut boxes = Vec::with_capacity(n);
        let mut starts = Vec::with_capacity(n);
        for (f, face) in surface.faces().iter().enumerate() {
            let mut b = Aabb::empty();
            face.for_each_cell(&mut |_, cell| {
                for c in cell.cp.iter().flatten() {
                    if c.w > 0.0 {
                        b.grow(&Point3::new(c.x / c.w, c.y / c.w, c.z / c.w));
                    }
                }
            });
            let mut s = Vec::with_capacity((START_SAMPLES + 1) * (START_SAMPLES + 1));
            for i in 0..=START_SAMPLES {
                for j in 0..=START_SAMPLES {
                    let (u, v) = (
                        i as f64 / START_SAMPLES as f64,
                        j as f64 / START_SAMPLES as f64,
                    );
                    let p = surface.subs(f, u, v);
                    b.grow(&p);
                    s.push((u, v, p));
                }
            }
            boxes.push(b);
            starts.push(s);
        }
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = vec![Node::EMPTY];
        if !boxes.is_empty() {
            build(&boxes, &mut order, 0, 0, &mut nodes);
        }
        Nearest {
            surface,
            boxes,
            starts,
            nodes,
            order,
        }
    }

    /// Faces whose box comes within `reach` of `c`, in order.
    pub(super) fn faces_near(&self, c: &Point3, reach: f64) -> Vec<u32> {
        self.faces_within(c, reach)
            .into_iter()
            .map(|(_, f)| f)
            .collect()
    }

    /// Faces whose box comes within `reach` of `c`, each with the distance from `c` to its
    /// box (mm; a bound below the distance to any point of the face), in face order.
    fn faces_within(&self, c: &Point3, reach: f64) -> Vec<(f64, u32)> {
        let mut out = Vec::new();
        let mut stack = vec![0u32];
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k as usize];
            if box_distance(&node.bounds, c) > reach {
                continue;
            }
            if node.count == 0 {
                stack.extend([node.first, node.first + 1]);
                continue;
            }
            let at = node.first as usize..(node.first + node.count) as usize;
            for &f in &self.order[at] {
                let d = box_distance(&self.boxes[f as usize], c);
                if d <= reach {
                    out.push((d, f));
                }
            }
        }
        out.sort_unstable_by_key(|e| e.1);
        out
    }

    /// The start sample of face `f` nearest `c`: its parameters.
    pub(super) fn nearest_start(&self, f: usize, c: &Point3) -> (f64, f64) {
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for &(u, v, p) in &self.starts[f] {
            let d = (p - c).norm_squared();
            if d < best.0 {
                best = (d, u, v);
            }
        }
        (best.1, best.2)
    }

    /// Nearest point to `c` on faces whose box comes within `reach` of it, and its distance.
    #[cfg(test)]
    pub(super) fn nearest(&self, c: &Point3, reach: f64) -> Option<(f64, Point3)> {
        self.nearest_from(c, reach, &[])
    }

    /// As [`Nearest::nearest`], also searching from `hints` (face, parameters in its unit
    /// square): the samples nearest `c` may lie in another valley of the distance than the
    /// nearest point (a face folded or creased inside).
    ///
    /// The faces are searched nearest box first, and a face whose box lies farther than the
    /// nearest point found so far is not searched: no point of it can be nearer. The answer
    /// is the one a search of every face in order would give: the least distance, on a tie
    /// the first face (and start) in face order, then the hints in order.
    pub(super) fn nearest_from(
        &self,
        c: &Point3,
        reach: f64,
        hints: &[(u32, [f64; 2])],
    ) -> Option<(f64, Point3)> {
        // The best so far: distance, point, and its place in the order of a full search.
        type Best = Option<(f64, Point3, (u32, usize))>;
        let offer = |best: &mut Best, d: f64, p: Point3, key: (u32, usize)| match *best {
            Some((bd, _, bk)) if bd < d || (bd == d && bk <= key) => {}
            _ => *best = Some((d, p, key)),
        };
        let mut best: Best = None;
        // Boxes nearest first: nodes open into their children, faces are searched.
        let mut queue = std::collections::BinaryHeap::new();
        if let Some(root) = self.nodes.first() {
            queue.push(Queued {
                bound: box_distance(&root.bounds, c),
                face: false,
                index: 0,
            });
        }
        while let Some(Queued { bound, face, index }) = queue.pop() {
            if bound > reach || best.is_some_and(|b| bound > b.0) {
                break;
            }
            if !face {
                let node = &self.nodes[index as usize];
                let (kids, faces) = if node.count == 0 {
                    (node.first..node.first + 2, &[][..])
                } else {
                    let at = node.first as usize..(node.first + node.count) as usize;
                    (0..0, &self.order[at])
                };
                for k in kids {
                    queue.push(Queued {
                        bound: box_distance(&self.nodes[k as usize].bounds, c),
                        face: false,
                        index: k,
                    });
                }
                for &f in faces {
                    queue.push(Queued {
                        bound: box_distance(&self.boxes[f as usize], c),
                        face: true,
                        index: f,
                    });
                }
                continue;
            }
            let fi = index as usize;
            // Newton from the nearest few samples: on a tightly folded face the nearest
            // sample may lie on the wrong side of the fold.
            let mut starts = [(f64::INFINITY, 0.0, 0.0); NEAREST_STARTS];
            for &(u, v, p) in &self.starts[fi] {
                let d = (p - c).norm_squared();
                // Kept in order, nearest first (ties: the earlier sample).
                if d < starts[NEAREST_STARTS - 1].0 {
                    let at = starts.iter().position(|s| d < s.0).unwrap_or(0);
                    starts.copy_within(at..NEAREST_STARTS - 1, at + 1);
                    starts[at] = (d, u, v);
                }
            }
            for (k, &(d, u, v)) in starts.iter().enumerate() {
                if !d.is_finite() {
                    break;
                }
                let (d, p) = self.descend(fi, c, u, v);
                offer(&mut best, d, p, (index, k));
            }
        }
        // The hints come after every face; one whose box lies beyond the best cannot win.
        for (k, &(f, [u, v])) in hints.iter().enumerate() {
            if best.is_some_and(|b| box_distance(&self.boxes[f as usize], c) > b.0) {
                continue;
            }
            let (d, p) = self.descend(f as usize, c, u, v);
            offer(&mut best, d, p, (u32::MAX, k));
        }
        best.map(|(d, p, _)| (d, p))
    }

    /// Local nearest point to `c` on face `f` from `(u, v)`: Newton steps on the squared
    /// distance within one Bézier cell of the face at a time. A coordinate that reaches a
    /// side while the distance still falls outwards goes on into the next cell if the
    /// distance falls that way there too; otherwise (the face's own side, or a crease the
    /// distance has its kink on) it stays on the side and the other one goes on alone.
    pub(super) fn descend(&self, f: usize, c: &Point3, u: f64, v: f64) -> (f64, Point3) {
        let foot = self.foot(f, c, u, v);
        (foot.dist, foot.point)
    }

    /// As [`Nearest::descend`], with where on the face the search ended.
    pub(super) fn foot(&self, f: usize, c: &Point3, mut u: f64, mut v: f64) -> Foot {
        let face = &self.surface.faces()[f];
        let breaks = face.breaks();
        let breaks = [breaks.0, breaks.1];
        let cell_of = |b: &[f64], x: f64| b[1..b.len() - 1].partition_point(|&k| k <= x);
        let mut cell = [cell_of(breaks[0], u), cell_of(breaks[1], v)];
        // The gradient of the squared distance from cell `k`.
        let grad = |k: [usize; 2], u: f64, v: f64| {
            let d = face.derivs_in(k, u, v);
            let r = d.point - c;
            (d.su.dot(&r), d.sv.dot(&r), d, r)
        };
        let mut steps = 0;
        while steps < NEWTON_STEPS + MAX_CELL_CROSSINGS {
            steps += 1;
            let (gu, gv, d, r) = grad(cell, u, v);
            // A side the gradient pushes out of: the next cell's, or stay on it.
            let mut fixed = [false, false];
            let mut crossed = false;
            for (k, (x, g)) in [(u, gu), (v, gv)].into_iter().enumerate() {
                let b = breaks[k];
                let (lo, hi) = (b[cell[k]], b[cell[k] + 1]);
                let out = if x <= lo && g > 0.0 {
                    (cell[k] > 0).then(|| cell[k] - 1)
                } else if x >= hi && g < 0.0 {
                    (cell[k] + 2 < b.len()).then(|| cell[k] + 1)
                } else {
                    continue;
                };
                let next = out.filter(|&n| {
                    let mut nc = cell;
                    nc[k] = n;
                    let (nu, nv, _, _) = grad(nc, u, v);
                    let gn = if k == 0 { nu } else { nv };
                    gn * g > 0.0
                });
                match next {
                    Some(n) => {
                        cell[k] = n;
                        crossed = true;
                    }
                    _ => fixed[k] = true,
                }
            }
            if crossed {
                continue;
            }
            // Gauss–Newton (the metric) plus the curvature terms where that stays positive.
            let (mut a, mut b, mut cc) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
            let (fa, fb, fc) = (a + d.suu.dot(&r), b + d.suv.dot(&r), cc + d.svv.dot(&r));
            if fa > 0.0 && fc > 0.0 && fa * fc - fb * fb > 0.0 {
                (a, b, cc) = (fa, fb, fc);
            }
            let (du, dv) = match fixed {
                [true, true] => break,
                [true, false] => (0.0, if cc > 0.0 { -gv / cc } else { 0.0 }),
                [false, true] => (if a > 0.0 { -gu / a } else { 0.0 }, 0.0),
                [false, false] => {
                    let det = a * cc - b * b;
                    if det.is_nan() || det <= 0.0 {
                        break;
                    }
                    (-(cc * gu - b * gv) / det, -(a * gv - b * gu) / det)
                }
            };
            if !(du.is_finite() && dv.is_finite()) {
                break;
            }
            let (bu, bv) = (breaks[0], breaks[1]);
            let nu = (u + du).clamp(bu[cell[0]], bu[cell[0] + 1]);
            let nv = (v + dv).clamp(bv[cell[1]], bv[cell[1] + 1]);
            let moved = (nu - u).abs().max((nv - v).abs());
            (u, v) = (nu, nv);
            if moved < NEWTON_CONVERGED {
                break;
            }
        }
        let p = face.derivs_in(cell, u, v).point;
        Foot {
            dist: (p - c).norm(),
            point: p,
            cell,
            uv: [u, v],
        }
    }
}

/// Where a nearest-point search on one face ended.
pub(super) struct Foot {
    /// Distance from the query point (mm).
    pub dist: f64,
    pub point: Point3,
    /// The Bézier cell of the face (of its breaks) and the face parameters.
    pub cell: [usize; 2],
    pub uv: [f64; 2],
}

/// Distance from `c` to the box `b` (mm; zero inside it).
fn box_distance(b: &Aabb, c: &Point3) -> f64 {
    (0..3)
        .map(|k| (b.min[k] - c[k]).max(c[k] - b.max[k]).max(0.0))
        .fold(0.0f64, |a, x| a.hypot(x))
}

/// Fills `nodes[slot]` with the hierarchy's node over `order` (faces with boxes `boxes`,
/// reordered in place; the first at index `offset` of the whole order) and appends its
/// descendants, splitting at the median of the boxes' middles along their widest spread.
fn build(boxes: &[Aabb], order: &mut [u32], offset: usize, slot: usize, nodes: &mut Vec<Node>) {
    let mut bounds = Aabb::empty();
    let mut middles = Aabb::empty();
    for &f in order.iter() {
        let b = &boxes[f as usize];
        bounds.grow(&Point3::from(b.min));
        bounds.grow(&Point3::from(b.max));
        middles.grow(&Point3::from(middle(b)));
    }
    if order.len() <= LEAF_FACES {
        nodes[slot] = Node {
            bounds,
            first: offset as u32,
            count: order.len() as u32,
        };
        return;
    }
    let spread = middles.size();
    let axis = (0..3).fold(0, |a, k| if spread[k] > spread[a] { k } else { a });
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        let (ma, mb) = (middle(&boxes[a as usize]), middle(&boxes[b as usize]));
        ma[axis].total_cmp(&mb[axis]).then(a.cmp(&b))
    });
    // The two children side by side, each subtree after them.
    let first = nodes.len();
    nodes.extend([Node::EMPTY, Node::EMPTY]);
    nodes[slot] = Node {
        bounds,
        first: first as u32,
        count: 0,
    };
    let (lo, hi) = order.split_at_mut(mid);
    build(boxes, lo, offset, first, nodes);
    build(boxes, hi, offset + mid, first + 1, nodes);
}

/// The middle of box `b`.
fn middle(b: &Aabb) -> [f64; 3] {
    [0, 1, 2].map(|k| 0.5 * (b.min[k] + b.max[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vector3;

    /// Every face searched from its nearest starts, in face order (the search before the
    /// hierarchy and the pruning): the least distance, the first on a tie.
    fn every_face(near: &Nearest, c: &Point3, reach: f64) -> Option<(f64, Point3)> {
        let mut best: Option<(f64, Point3)> = None;
        for f in 0..near.boxes.len() {
            if box_distance(&near.boxes[f], c) > reach {
                continue;
            }
            let mut starts: Vec<(f64, usize)> = near.starts[f]
                .iter()
                .enumerate()
                .map(|(k, s)| ((s.2 - c).norm_squared(), k))
                .collect();
            starts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(_, k) in starts.iter().take(NEAREST_STARTS) {
                let (u, v, _) = near.starts[f][k];
                let (d, p) = near.descend(f, c, u, v);
                if best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, p));
                }
            }
        }
        best
    }

    /// The hierarchy searched nearest box first, and faces beyond the best found left out,
    /// give what searching every face gives, to the bit: on a subdivision cage of 1 575
    /// faces (OpenSubdiv's car, the ball as large as a wheel) and on a T-spline with
    /// creases, from points near and far from the surface.
    #[test]
    fn the_pruned_search_finds_what_every_face_finds() {
        let root = env!("CARGO_MANIFEST_DIR");
        let load = |path: &str| {
            let bytes = std::fs::read(format!("{root}/{path}")).unwrap();
            crate::io::load(&bytes, path).unwrap()
        };
        let cases = [
            (load("tests/fixtures/opensubdiv/catmark_car.obj"), 0.5),
            (load("www/models/grapetec/face.tsm"), 0.5),
        ];
        let mut next = crate::testing::uniform(0x9e37_79b9_7f4a_7c15);
        for (model, r) in cases {
            let near = Nearest::new(&model.surface);
            let faces = model.surface.faces().len();
            let (mut found, mut pruned_to) = (0, 0);
            for _ in 0..300 {
                let f = ((next() * faces as f64) as usize).min(faces - 1);
                let p = model.surface.subs(f, next(), next());
                let off = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5) * (3.0 * r);
                let c = p + off;
                let want = every_face(&near, &c, r);
                let got = near.nearest(&c, r);
                assert_eq!(
                    got.map(|(d, p)| (d.to_bits(), p.coords.map(f64::to_bits))),
                    want.map(|(d, p)| (d.to_bits(), p.coords.map(f64::to_bits))),
                    "{}: nearest to ({:.4}, {:.4}, {:.4}) mm",
                    model.name,
                    c.x,
                    c.y,
                    c.z
                );
                found += usize::from(got.is_some());
                pruned_to += near.faces_near(&c, r).len();
            }
            println!(
                "{}: {found} of 300 points within {r} mm of the surface; {:.1} faces within reach on average",
                model.name,
                pruned_to as f64 / 300.0
            );
            assert!(
                found > 100,
                "{}: too few points near the surface",
                model.name
            );
        }
    }
}
