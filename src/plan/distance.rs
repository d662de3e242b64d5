//! Distance from segments (a ball's centre moving in a straight line) to the surface,
//! exactly against a tessellation within a known tolerance of it, through a bounding-volume
//! hierarchy of its triangles.
//!
//! Owns: the hierarchy, the segment–triangle distance and the cylinder–triangle test (the
//! shank and holder). Must not: know what the segments or cylinders are for (air moves,
//! lifted points, tool axes); callers add the tessellation's tolerance to their margins.

use crate::geom::{least, most, Point3, Vector3};
use crate::model::Model;
use std::sync::{Arc, Mutex};

/// Triangles per leaf of the hierarchy.
const LEAF: usize = 8;

/// A node of the binary hierarchy as built: its box, and either two children or a range of
/// triangles.
#[derive(Debug, Clone, Copy)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Children (`left`, `left + 1`) when `count` is 0, else the first triangle.
    first: u32,
    count: u32,
}

/// Children of a node of the query hierarchy.
const WIDE: usize = 4;

/// A node of the query hierarchy: the binary hierarchy with every second level folded into
/// its parent, so a node holds up to four children (its children's children, or a child
/// that is a leaf), left to right as in the binary one. The boxes lie coordinate by
/// coordinate, one lane a child, so one test runs over all four side by side.
#[derive(Debug, Clone, Copy)]
struct Wide {
    lo: [[f64; WIDE]; 3],
    hi: [[f64; WIDE]; 3],
    /// Per child: the node's index, or the leaf's first triangle.
    link: [u32; WIDE],
    /// Per child: 0 for a node, else the leaf's triangle count.
    count: [u32; WIDE],
    /// Children in use (the first `len`).
    len: u32,
}

impl Wide {
    const EMPTY: Wide = Wide {
        lo: [[0.0; WIDE]; 3],
        hi: [[0.0; WIDE]; 3],
        link: [0; WIDE],
        count: [0; WIDE],
        len: 0,
    };
}

/// The surface's triangles in a hierarchy of boxes.
pub struct SurfaceDistance {
    /// The triangles in the leaves' order, in single precision: the tessellation's
    /// positions are single precision, so this holds them exactly in half the memory.
    tris: Vec<Tri>,
    nodes: Vec<Wide>,
    /// Largest distance between the triangles and the surface (mm).
    pub tolerance_mm: f64,
}

/// Margin on the measured deviation (the triangles are measured at a few points each).
const MEASURE_MARGIN: f64 = 1.25;

/// Distance sets a model keeps after a plan: a plan asks for up to three (shank, holder,
/// air moves), and the next plan of the same model (a slider moved on the page) asks for
/// the same ones unless the tool changed.
const KEPT_SETS: usize = 3;

/// The distance sets a [`Model`] has built, by the chordal tolerance asked for, newest
/// last; each is built once and then only read. A copy of the model starts with none.
#[derive(Default)]
pub struct DistanceSets(Mutex<Vec<(u64, Arc<SurfaceDistance>)>>);

impl Clone for DistanceSets {
    fn clone(&self) -> Self {
        DistanceSets::default()
    }
}

impl std::fmt::Debug for DistanceSets {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.0.lock().map(|v| v.len()).unwrap_or(0);
        write!(f, "DistanceSets({n} kept)")
    }
}

impl Model {
    /// The model's [`SurfaceDistance`] for `chordal_mm`: the one built for an earlier plan
    /// at the same tolerance, else a new one (kept for the plans after).
    pub fn surface_distance(&self, chordal_mm: f64) -> Arc<SurfaceDistance> {
        let key = chordal_mm.to_bits();
        let kept = self.distance_sets.0.lock().ok().and_then(|v| {
            v.iter()
                .find(|(k, _)| *k == key)
                .map(|(_, d)| Arc::clone(d))
        });
        if let Some(d) = kept {
            return d;
        }
        let d = Arc::new(SurfaceDistance::new(self, chordal_mm));
        if let Ok(mut v) = self.distance_sets.0.lock() {
            v.retain(|(k, _)| *k != key);
            v.push((key, d.clone()));
            if v.len() > KEPT_SETS {
                v.remove(0);
            }
        }
        d
    }
}

impl SurfaceDistance {
    /// Tessellates `model` within about `tolerance_mm` and builds the hierarchy. The
    /// result's `tolerance_mm` is the deviation measured at each triangle's middle and edge
    /// midpoints, with a margin, and at least the one asked for.
    pub fn new(model: &Model, tolerance_mm: f64) -> Self {
        Self::with_tessellation(model, tolerance_mm)
    }

    fn with_tessellation(model: &Model, chordal_mm: f64) -> Self {
        let t = model.tessellate(chordal_mm);
        let p = |i: u32| {
            let k = 3 * i as usize;
            Point3::new(
                t.positions[k] as f64,
                t.positions[k + 1] as f64,
                t.positions[k + 2] as f64,
            )
        };
        let tris: Vec<[Point3; 3]> = t
            .indices
            .chunks(3)
            .map(|c| [p(c[0]), p(c[1]), p(c[2])])
            .collect();
        // Single-precision positions round by up to half an ulp of the coordinates.
        let reach = tris
            .iter()
            .flatten()
            .map(|q| q.x.abs().max(q.y.abs()).max(q.z.abs()))
            .fold(0.0, f64::max);
        // The deviation: the surface at the middle and the edge midpoints of each triangle
        // (in the parameters of a face that holds all three corners) from the triangle.
        let mut measured: f64 = 0.0;
        for (k, c) in t.indices.chunks(3).enumerate() {
            let [a, b, e] = [0, 1, 2].map(|i| t.params[c[i] as usize]);
            if a.0 != b.0 || a.0 != e.0 {
                continue;
            }
            let face = a.0 as usize;
            for (x, y) in [
                ((a.1 + b.1 + e.1) / 3.0, (a.2 + b.2 + e.2) / 3.0),
                (0.5 * (a.1 + b.1), 0.5 * (a.2 + b.2)),
                (0.5 * (b.1 + e.1), 0.5 * (b.2 + e.2)),
                (0.5 * (e.1 + a.1), 0.5 * (e.2 + a.2)),
            ] {
                let q = model.surface.subs(face, x, y);
                measured = measured.max(point_triangle_distance(&q, &tris[k]));
            }
        }
        let (nodes, tris) = Self::build(&tris);
        SurfaceDistance {
            tris,
            nodes,
            tolerance_mm: (MEASURE_MARGIN * measured).max(chordal_mm) + reach * f32::EPSILON as f64,
        }
    }

    /// The query hierarchy over `tris`, and the triangles in its leaves' order.
    fn build(tris: &[[Point3; 3]]) -> (Vec<Wide>, Vec<Tri>) {
        let (nodes, tris) = Self::build_binary(tris);
        (widen(&nodes), tris)
    }

    /// The binary hierarchy over `tris`, and the triangles in its leaves' order.
    fn build_binary(tris: &[[Point3; 3]]) -> (Vec<Node>, Vec<Tri>) {
        let n = tris.len();
        if n == 0 {
            return (Vec::new(), Vec::new());
        }
        let mut order: Vec<u32> = (0..n as u32).collect();
        let centre = |t: &[Point3; 3]| (t[0].coords + t[1].coords + t[2].coords) / 3.0;
        let centres: Vec<Vector3> = tris.iter().map(centre).collect();
        // Nodes built breadth-first so children sit next to each other.
        let mut nodes = vec![Node {
            lo: [0.0; 3],
            hi: [0.0; 3],
            first: 0,
            count: n as u32,
        }];
        let mut stack = vec![(0usize, 0usize, n, 0usize)];
        while let Some((node, a, b, depth)) = stack.pop() {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &t in &order[a..b] {
                for q in &tris[t as usize] {
                    for k in 0..3 {
                        lo[k] = least(lo[k], q[k]);
                        hi[k] = most(hi[k], q[k]);
                    }
                }
            }
            nodes[node].lo = lo;
            nodes[node].hi = hi;
            if b - a <= LEAF {
                nodes[node].first = a as u32;
                nodes[node].count = (b - a) as u32;
                continue;
            }
            // Beyond [`AREA_DEPTH`] halves at the median, so the depth stays bounded.
            let mid = if depth < AREA_DEPTH {
                a + split_by_area(&mut order[a..b], &centres, tris)
            } else {
                let axis = (0..3)
                    .max_by(|&i, &j| (hi[i] - lo[i]).total_cmp(&(hi[j] - lo[j])))
                    .unwrap_or(0);
                a + split_at_median(&mut order[a..b], &centres, axis)
            };
            let left = nodes.len();
            for _ in 0..2 {
                nodes.push(Node {
                    lo: [0.0; 3],
                    hi: [0.0; 3],
                    first: 0,
                    count: 0,
                });
            }
            nodes[node].first = left as u32;
            nodes[node].count = 0;
            stack.push((left, a, mid, depth + 1));
            stack.push((left + 1, mid, b, depth + 1));
        }
        // Leaves index the triangles in `order`: store them so.
        let tris = order
            .iter()
            .map(|&t| Tri::from(&tris[t as usize]))
            .collect();
        (nodes, tris)
    }

    /// True if the segment from `a` to `b` comes closer than `limit` (mm) to some triangle.
    pub fn segment_within(&self, a: &Point3, b: &Point3, limit: f64) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let probe = BoxProbe::new(a, b);
        self.leaves_meeting(
            |n: &Wide| probe.meets4(n, limit),
            |t: &Tri| (segment_triangle_distance(a, b, &t.corners()) < limit).then_some(()),
        )
        .is_some()
    }

    /// The highest corner (z, mm) of the triangles whose plan view (their box projected on
    /// XY) meets `rect`, or `None` where none does: what a vertical tool may pass over on a
    /// rapid whose plan view keeps within `rect` ([`PlanRect::spanned`]). Callers add
    /// [`Self::tolerance_mm`].
    pub fn highest_under(&self, rect: &PlanRect) -> Option<f64> {
        let best = std::cell::Cell::new(f64::NEG_INFINITY);
        self.leaves_meeting(
            |n: &Wide| {
                // Children whose plan view meets the rectangle and that reach above the
                // highest corner found so far.
                std::array::from_fn(|j| {
                    rect.meets([n.lo[0][j], n.lo[1][j]], [n.hi[0][j], n.hi[1][j]])
                        && n.hi[2][j] > best.get()
                })
            },
            |t: &Tri| {
                let c = t.corners();
                let (l, h) = (
                    [0, 1].map(|k| least(least(c[0][k], c[1][k]), c[2][k])),
                    [0, 1].map(|k| most(most(c[0][k], c[1][k]), c[2][k])),
                );
                let top = most(most(c[0].z, c[1].z), c[2].z);
                if top > best.get() && rect.meets(l, h) {
                    best.set(top);
                }
                None::<()>
            },
        );
        (best.get() > f64::NEG_INFINITY).then(|| best.get())
    }

    /// A point of a triangle inside the flat-ended cylinder of radius `rad` along unit
    /// `axis` from `c + axis·a0` to `c + axis·a1`, if there is one (exact against the
    /// triangles; callers grow the cylinder by [`Self::tolerance_mm`] for the surface).
    pub fn cylinder_hit(
        &self,
        c: &Point3,
        axis: &Vector3,
        (a0, a1): (f64, f64),
        rad: f64,
    ) -> Option<Point3> {
        if self.nodes.is_empty() {
            return None;
        }
        let cyl = Cylinder::new(c, axis, (a0, a1), rad);
        self.leaves_meeting(|n: &Wide| cyl.may_meet4(n), |t: &Tri| cyl.hit(&t.corners()))
    }

    /// The first `Some` of `test` over the triangles, in the leaves' order, of the leaves
    /// whose boxes and their nodes' boxes `meets` does not rule out (a lane false: the
    /// child's box surely holds no triangle `test` would take).
    #[inline]
    fn leaves_meeting<T>(
        &self,
        meets: impl Fn(&Wide) -> [bool; WIDE],
        test: impl Fn(&Tri) -> Option<T>,
    ) -> Option<T> {
        if self.nodes.is_empty() {
            return None;
        }
        // (link, count) as in [`Wide`]: a node, or a leaf's triangles.
        let mut stack = [(0u32, 0u32); STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (link, count) = stack[top];
            if count == 0 {
                let node = &self.nodes[link as usize];
                let ok = meets(node);
                // Pushed right to left, so the leftmost is taken first.
                for j in (0..node.len as usize).rev() {
                    if ok[j] {
                        stack[top] = (node.link[j], node.count[j]);
                        top += 1;
                    }
                }
                continue;
            }
            let first = link as usize;
            if let Some(p) = self.tris[first..first + count as usize]
                .iter()
                .find_map(&test)
            {
                return Some(p);
            }
        }
        None
    }
}

/// A rectangle in plan view (XY, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanRect {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
}

impl PlanRect {
    /// The rectangle spanned by `a` and `b` grown by `grow` on every side (mm): where a
    /// vertical tool `grow` wide may pass on a rapid from above `a` to above `b`, on a control
    /// that moves each axis at its own rate (the tool then keeps within it, not on the line).
    pub fn spanned(a: [f64; 2], b: [f64; 2], grow: f64) -> Self {
        PlanRect {
            lo: [0, 1].map(|k| least(a[k], b[k]) - grow),
            hi: [0, 1].map(|k| most(a[k], b[k]) + grow),
        }
    }

    /// Whether the box from `lo` to `hi` (plan view) meets the rectangle (touching counts).
    pub fn meets(&self, lo: [f64; 2], hi: [f64; 2]) -> bool {
        (0..2).all(|k| lo[k] <= self.hi[k] && hi[k] >= self.lo[k])
    }
}

/// The query hierarchy of the binary one `nodes` (root first): each node's children are its
/// binary node's grandchildren, or a child where that is a leaf; the root is the binary
/// root's node (its own box is not tested: its children's are).
fn widen(nodes: &[Node]) -> Vec<Wide> {
    if nodes.is_empty() {
        return Vec::new();
    }
    let mut wide = vec![Wide::EMPTY];
    // (wide node, the binary node it stands for)
    let mut todo = vec![(0usize, 0usize)];
    while let Some((w, b)) = todo.pop() {
        let node = nodes[b];
        let mut kids = [0usize; WIDE];
        let mut len = 0;
        if node.count != 0 {
            // A root that is a leaf.
            kids[0] = b;
            len = 1;
        } else {
            for c in [node.first as usize, node.first as usize + 1] {
                if nodes[c].count != 0 {
                    kids[len] = c;
                    len += 1;
                } else {
                    kids[len] = nodes[c].first as usize;
                    kids[len + 1] = nodes[c].first as usize + 1;
                    len += 2;
                }
            }
        }
        wide[w].len = len as u32;
        for (j, &k) in kids[..len].iter().enumerate() {
            let child = nodes[k];
            for q in 0..3 {
                wide[w].lo[q][j] = child.lo[q];
                wide[w].hi[q][j] = child.hi[q];
            }
            if child.count != 0 {
                wide[w].link[j] = child.first;
                wide[w].count[j] = child.count;
            } else {
                wide[w].link[j] = wide.len() as u32;
                wide.push(Wide::EMPTY);
                todo.push((wide.len() - 1, k));
            }
        }
    }
    wide
}

/// A triangle's corners in single precision (mm).
#[derive(Debug, Clone, Copy)]
struct Tri([[f32; 3]; 3]);

impl Tri {
    /// The corners in double precision.
    #[inline]
    fn corners(&self) -> [Point3; 3] {
        self.0
            .map(|q| Point3::new(q[0] as f64, q[1] as f64, q[2] as f64))
    }
}

impl From<&[Point3; 3]> for Tri {
    /// Rounds to single precision: exact for corners that came from single precision.
    fn from(t: &[Point3; 3]) -> Self {
        Tri(t.map(|q| [q.x as f32, q.y as f32, q.z as f32]))
    }
}

/// Bins of the surface-area split.
const AREA_BINS: usize = 16;

/// Splits `order` (triangle indices) in two and returns the first part's length (neither
/// part empty): binned by centre along the longest side of the centres' box, cut where the
/// parts' box areas times their counts sum least (the surface-area heuristic: the likely cost
/// of a query that reaches this node); at the median centre where the centres do not spread.
fn split_by_area(order: &mut [u32], centres: &[Vector3], tris: &[[Point3; 3]]) -> usize {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &t in order.iter() {
        for k in 0..3 {
            lo[k] = least(lo[k], centres[t as usize][k]);
            hi[k] = most(hi[k], centres[t as usize][k]);
        }
    }
    let axis = (0..3)
        .max_by(|&i, &j| (hi[i] - lo[i]).total_cmp(&(hi[j] - lo[j])))
        .unwrap_or(0);
    let extent = hi[axis] - lo[axis];
    let bin = |t: u32| {
        (((centres[t as usize][axis] - lo[axis]) / extent * AREA_BINS as f64) as usize)
            .min(AREA_BINS - 1)
    };
    let mut best = None;
    if extent > 0.0 {
        let mut boxes = [([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]); AREA_BINS];
        let mut counts = [0usize; AREA_BINS];
        for &t in order.iter() {
            let b = bin(t);
            counts[b] += 1;
            for q in &tris[t as usize] {
                for k in 0..3 {
                    boxes[b].0[k] = least(boxes[b].0[k], q[k]);
                    boxes[b].1[k] = most(boxes[b].1[k], q[k]);
                }
            }
        }
        let area = |(l, h): &([f64; 3], [f64; 3])| {
            let e = [0, 1, 2].map(|k| (h[k] - l[k]).max(0.0));
            e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
        };
        let merge = |x: &([f64; 3], [f64; 3]), y: &([f64; 3], [f64; 3])| {
            (
                [0, 1, 2].map(|k| least(x.0[k], y.0[k])),
                [0, 1, 2].map(|k| most(x.1[k], y.1[k])),
            )
        };
        // Cost of cutting after bin `i`, from the left and right sweeps.
        let mut left = vec![(0.0, 0); AREA_BINS - 1];
        let (mut acc, mut n) = (boxes[0], 0);
        for i in 0..AREA_BINS - 1 {
            acc = merge(&acc, &boxes[i]);
            n += counts[i];
            left[i] = (area(&acc), n);
        }
        let (mut acc, mut n) = (boxes[AREA_BINS - 1], 0);
        let mut lowest = f64::INFINITY;
        for i in (0..AREA_BINS - 1).rev() {
            acc = merge(&acc, &boxes[i + 1]);
            n += counts[i + 1];
            let (la, ln) = left[i];
            let cost = la * ln as f64 + area(&acc) * n as f64;
            if ln > 0 && n > 0 && cost <= lowest {
                lowest = cost;
                best = Some(i);
            }
        }
    }
    match best {
        Some(cut) => {
            // Stable partition: the order within each part is kept.
            let (first, second): (Vec<u32>, Vec<u32>) = order.iter().partition(|&&t| bin(t) <= cut);
            let m = first.len();
            order[..m].copy_from_slice(&first);
            order[m..].copy_from_slice(&second);
            m
        }
        None => split_at_median(order, centres, axis),
    }
}

/// Splits `order` at its median centre along coordinate `axis`; returns the first half's
/// length.
fn split_at_median(order: &mut [u32], centres: &[Vector3], axis: usize) -> usize {
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&x, &y| {
        centres[x as usize][axis].total_cmp(&centres[y as usize][axis])
    });
    mid
}

/// Depth to which nodes are split by area; below it, at the median (at most 30 levels more
/// for 2³² triangles, eight a leaf).
const AREA_DEPTH: usize = 30;
/// Deepest the binary hierarchy gets.
const MAX_DEPTH: usize = AREA_DEPTH + 34;
/// The query stack's size: a query holds at most the untaken children (`WIDE − 1`) of each
/// level of the query hierarchy (half the binary one's) and the one node it takes.
const STACK: usize = (WIDE - 1) * (MAX_DEPTH / 2 + 1) + 1;

/// A flat-ended cylinder in its own frame: the axis through `c` along unit `axis`, `e1` and
/// `e2` across it.
struct Cylinder {
    c: Point3,
    axis: Vector3,
    e1: Vector3,
    e2: Vector3,
    a0: f64,
    a1: f64,
    rad: f64,
    /// The axis' components' sizes, for the boxes' reach along it.
    axis_abs: [f64; 3],
    /// `(2·rad)²`, for the sphere test.
    four_rad2: f64,
    /// The axis segment from `c + axis·a0` to `c + axis·a1`, for box tests.
    axis_probe: BoxProbe,
}

/// Most corners of a triangle clipped by two parallel planes.
const CLIPPED: usize = 5;

impl Cylinder {
    fn new(c: &Point3, axis: &Vector3, (a0, a1): (f64, f64), rad: f64) -> Self {
        let other = if axis.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1 = axis.cross(&other).normalize();
        Cylinder {
            axis_probe: BoxProbe::new(&(c + axis * a0), &(c + axis * a1)),
            c: *c,
            axis: *axis,
            e2: axis.cross(&e1),
            e1,
            a0,
            a1,
            rad,
            axis_abs: [axis.x.abs(), axis.y.abs(), axis.z.abs()],
            four_rad2: 4.0 * rad * rad,
        }
    }

    /// Per child of `n`: false if its box surely misses the cylinder: it lies beyond an end
    /// plane, its bounding sphere is farther than `rad` from the axis, or the axis segment
    /// misses the box grown by `rad`. The four lanes side by side (the compiler pairs them).
    #[inline]
    fn may_meet4(&self, n: &Wide) -> [bool; WIDE] {
        let (mut mid, mut half, mut r2) = ([0.0; WIDE], [0.0; WIDE], [0.0; WIDE]);
        let mut d = [[0.0; WIDE]; 3];
        for k in 0..3 {
            for j in 0..WIDE {
                d[k][j] = 0.5 * (n.lo[k][j] + n.hi[k][j]) - self.c[k];
                let e = 0.5 * (n.hi[k][j] - n.lo[k][j]);
                mid[j] += d[k][j] * self.axis[k];
                half[j] += e * self.axis_abs[k];
                r2[j] += e * e;
            }
        }
        let mut d2 = [0.0; WIDE];
        for k in 0..3 {
            for j in 0..WIDE {
                let x = d[k][j] - mid[j] * self.axis[k];
                d2[j] += x * x;
            }
        }
        let mut ok = [false; WIDE];
        for j in 0..WIDE {
            let beyond = (mid[j] + half[j] < self.a0) | (mid[j] - half[j] > self.a1);
            // Within `rad` plus the box's half diagonal of the axis: d² ≤ (rad + √r2)².
            let over = d2[j] - self.rad * self.rad - r2[j];
            let far = (over > 0.0) & (over * over > self.four_rad2 * r2[j]);
            ok[j] = !beyond & !far;
        }
        // The axis segment against the boxes grown by the radius, unless all are out.
        if ok != [false; WIDE] {
            let probe = self.axis_probe.meets4(n, self.rad);
            for j in 0..WIDE {
                ok[j] &= probe[j];
            }
        }
        ok
    }

    /// True if the whole cylinder lies strictly to one side of the plane of the triangle
    /// with corners `q` (in the cylinder's frame), so it cannot meet the triangle: a wall
    /// running beside the shank a little more than its radius away is told so without
    /// clipping. Both end discs are on the same side when the plane's value at their
    /// centres exceeds the disc's reach across, `rad·|n⊥|` for the plane's normal `n` (its
    /// part across the axis `n⊥`); compared squared. A triangle without area (`n` zero)
    /// fails the comparison and is left to the full test.
    fn beside_plane(&self, q: &[[f64; 3]; 3]) -> bool {
        let (u, v) = (sub3(&q[1], &q[0]), sub3(&q[2], &q[0]));
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let across2 = n[1] * n[1] + n[2] * n[2];
        let base = n[0] * q[0][0] + n[1] * q[0][1] + n[2] * q[0][2];
        let (s0, s1) = (n[0] * self.a0 - base, n[0] * self.a1 - base);
        let reach2 = self.rad * self.rad * across2;
        (s0 > 0.0) == (s1 > 0.0) && s0 * s0 > reach2 && s1 * s1 > reach2
    }

    /// A point of triangle `t` inside the cylinder, if there is one: the triangle clipped to
    /// the slab between the end planes, seen along the axis, comes within `rad` of it.
    fn hit(&self, t: &[Point3; 3]) -> Option<Point3> {
        // Corners as (along, across 1, across 2).
        let q = t.map(|p| {
            let d = p - self.c;
            [d.dot(&self.axis), d.dot(&self.e1), d.dot(&self.e2)]
        });
        if q.iter().all(|v| v[0] < self.a0) || q.iter().all(|v| v[0] > self.a1) {
            return None;
        }
        if q.iter().all(|v| v[1] > self.rad)
            || q.iter().all(|v| v[1] < -self.rad)
            || q.iter().all(|v| v[2] > self.rad)
            || q.iter().all(|v| v[2] < -self.rad)
        {
            return None;
        }
        if self.beside_plane(&q) {
            return None;
        }
        let mut poly = [[0.0; 3]; CLIPPED];
        poly[..3].copy_from_slice(&q);
        let mut n = 3;
        n = clip(&mut poly, n, |v| v[0] - self.a0);
        n = clip(&mut poly, n, |v| self.a1 - v[0]);
        if n == 0 {
            return None;
        }
        let at = |v: [f64; 3]| self.c + self.axis * v[0] + self.e1 * v[1] + self.e2 * v[2];
        // The axis passes through the polygon (seen along it) when the origin is on the same
        // side of every edge of a polygon with area.
        let (mut pos, mut neg) = (false, false);
        for i in 0..n {
            let (u, v) = (poly[i], poly[(i + 1) % n]);
            let cross = u[1] * v[2] - u[2] * v[1];
            pos |= cross > 0.0;
            neg |= cross < 0.0;
        }
        if pos != neg {
            // Where the axis pierces it (in the fan triangle from the first corner that holds
            // it, by barycentric weights; the corners' mean height where rounding leaves it in
            // none), moved towards the polygon's middle by up to half the radius: a point of
            // the triangle inside the cylinder that also says on which side the triangle lies
            // (the tool leans away from it).
            let mut along = poly[..n].iter().map(|v| v[0]).sum::<f64>() / n as f64;
            let u = poly[0];
            for i in 1..n - 1 {
                let (v, w) = (poly[i], poly[i + 1]);
                let cross = |p: [f64; 3], q: [f64; 3]| p[1] * q[2] - p[2] * q[1];
                let area = cross(
                    [0.0, v[1] - u[1], v[2] - u[2]],
                    [0.0, w[1] - u[1], w[2] - u[2]],
                );
                if area == 0.0 {
                    continue;
                }
                let (bu, bv, bw) = (cross(v, w) / area, cross(w, u) / area, cross(u, v) / area);
                if bu >= 0.0 && bv >= 0.0 && bw >= 0.0 {
                    along = u[0] * bu + v[0] * bv + w[0] * bw;
                    break;
                }
            }
            let mean = poly[..n]
                .iter()
                .fold([0.0; 3], |s, v| [s[0] + v[0], s[1] + v[1], s[2] + v[2]])
                .map(|x| x / n as f64);
            let off = (mean[1] * mean[1] + mean[2] * mean[2]).sqrt();
            let t = if off > 0.5 * self.rad {
                0.5 * self.rad / off
            } else {
                1.0
            };
            return Some(at([
                along + (mean[0] - along) * t,
                mean[1] * t,
                mean[2] * t,
            ]));
        }
        let rad2 = self.rad * self.rad;
        (0..n).find_map(|i| {
            let (u, v) = (poly[i], poly[(i + 1) % n]);
            let (dx, dy) = (v[1] - u[1], v[2] - u[2]);
            let len2 = dx * dx + dy * dy;
            let s = if len2 > 0.0 {
                (-(u[1] * dx + u[2] * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let w = [0, 1, 2].map(|k| u[k] + (v[k] - u[k]) * s);
            (w[1] * w[1] + w[2] * w[2] < rad2).then(|| at(w))
        })
    }
}

/// `a − b`.
#[inline]
fn sub3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Clips the convex polygon `poly[..n]` to where `side` is not negative (Sutherland–Hodgman);
/// returns the new corner count.
fn clip(poly: &mut [[f64; 3]; CLIPPED], n: usize, side: impl Fn(&[f64; 3]) -> f64) -> usize {
    if (0..n).all(|i| side(&poly[i]) >= 0.0) {
        return n;
    }
    let mut out = [[0.0; 3]; CLIPPED];
    let mut m = 0;
    for i in 0..n {
        let (u, v) = (poly[i], poly[(i + 1) % n]);
        let (su, sv) = (side(&u), side(&v));
        if su >= 0.0 && m < CLIPPED {
            out[m] = u;
            m += 1;
        }
        if (su >= 0.0) != (sv >= 0.0) && m < CLIPPED {
            let s = su / (su - sv);
            out[m] = [0, 1, 2].map(|k| u[k] + (v[k] - u[k]) * s);
            m += 1;
        }
    }
    *poly = out;
    m
}

/// A segment set up for many box tests: its start and the reciprocals of its extent
/// (infinite along a coordinate it does not change), so a test multiplies instead of
/// dividing.
struct BoxProbe {
    a: Point3,
    inv: [f64; 3],
}

impl BoxProbe {
    fn new(a: &Point3, b: &Point3) -> Self {
        let d = b - a;
        BoxProbe {
            a: *a,
            inv: [0, 1, 2].map(|k| {
                if d[k].abs() < f64::MIN_POSITIVE {
                    f64::INFINITY
                } else {
                    1.0 / d[k]
                }
            }),
        }
    }

    /// Per child of `n`: true if the segment comes within `grow` of its box (tested against
    /// the box grown by `grow` on every side, which contains that neighbourhood).
    #[inline]
    fn meets4(&self, n: &Wide, grow: f64) -> [bool; WIDE] {
        let (mut t0, mut t1) = ([0.0f64; WIDE], [1.0f64; WIDE]);
        let mut ok = [true; WIDE];
        for k in 0..3 {
            for j in 0..WIDE {
                let (l, h) = (n.lo[k][j] - grow, n.hi[k][j] + grow);
                if self.inv[k].is_infinite() {
                    ok[j] &= (self.a[k] >= l) & (self.a[k] <= h);
                } else {
                    let (u, v) = ((l - self.a[k]) * self.inv[k], (h - self.a[k]) * self.inv[k]);
                    t0[j] = most(t0[j], least(u, v));
                    t1[j] = least(t1[j], most(u, v));
                }
            }
        }
        for j in 0..WIDE {
            ok[j] &= t0[j] <= t1[j];
        }
        ok
    }
}

/// Distance between point `p` and triangle `t`.
fn point_triangle_distance(p: &Point3, t: &[Point3; 3]) -> f64 {
    (p - closest_on_triangle(p, t)).norm()
}

/// The point of triangle `t` nearest to `p` (by the regions of its plane).
fn closest_on_triangle(p: &Point3, t: &[Point3; 3]) -> Point3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        return a;
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// Distance between segments `p0 p1` and `q0 q1`.
fn segment_segment_distance(p0: &Point3, p1: &Point3, q0: &Point3, q1: &Point3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t);
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return r.norm();
    }
    if a <= f64::MIN_POSITIVE {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= f64::MIN_POSITIVE {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut ss = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut tt = (b * ss + f) / e;
            if tt < 0.0 {
                tt = 0.0;
                ss = (-c / a).clamp(0.0, 1.0);
            } else if tt > 1.0 {
                tt = 1.0;
                ss = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = ss;
            t = tt;
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

/// Distance between segment `a b` and triangle `t`: zero if the segment crosses it, else
/// the least of the endpoints' distances to it and the segment's to its edges.
pub fn segment_triangle_distance(a: &Point3, b: &Point3, t: &[Point3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let (da, db) = ((a - t[0]).dot(&n), (b - t[0]).dot(&n));
    if da * db <= 0.0 && n.norm_squared() > 0.0 && da != db {
        // The segment meets the plane: inside the triangle is distance zero.
        let x = a + (b - a) * (da / (da - db));
        if point_triangle_distance(&x, t) <= f64::EPSILON * (1.0 + x.coords.norm()) {
            return 0.0;
        }
    }
    let mut best = point_triangle_distance(a, t).min(point_triangle_distance(b, t));
    for k in 0..3 {
        best = best.min(segment_segment_distance(a, b, &t[k], &t[(k + 1) % 3]));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_triangle_distances_match_hand_computed_ones() {
        let t = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 2.0, 0.0),
        ];
        let d = |a: [f64; 3], b: [f64; 3]| {
            segment_triangle_distance(&Point3::from(a), &Point3::from(b), &t)
        };
        // Above the inside, parallel to the plane.
        assert!((d([0.2, 0.2, 1.0], [0.5, 0.5, 1.0]) - 1.0).abs() < 1e-15);
        // Through the triangle.
        assert_eq!(d([0.5, 0.5, -1.0], [0.5, 0.5, 1.0]), 0.0);
        // Beside the hypotenuse, crossing the plane outside: distance to the edge.
        let q = 3.0 / 2f64.sqrt() - 2f64.sqrt();
        assert!((d([1.5, 1.5, -1.0], [1.5, 1.5, 1.0]) - q).abs() < 1e-14);
        // Skew to an edge: the segment x = 1, z = 1 runs over the edge y = 0, z = 0.
        assert!((d([1.0, -1.0, 1.0], [1.0, -3.0, 1.0]) - 2f64.sqrt()).abs() < 1e-14);
    }

    /// A random point over the box's footprint, from a quarter of its height below it to a
    /// quarter above.
    fn around(bb: &crate::geom::Aabb, r: &mut dyn FnMut() -> f64) -> Point3 {
        Point3::new(
            bb.min[0] + (bb.max[0] - bb.min[0]) * r(),
            bb.min[1] + (bb.max[1] - bb.min[1]) * r(),
            bb.min[2] + (bb.max[2] - bb.min[2]) * (1.5 * r() - 0.25),
        )
    }

    #[test]
    fn the_hierarchy_finds_what_brute_force_finds() {
        let m = crate::model::samples::load_sample("keycap-convex").unwrap();
        let dist = SurfaceDistance::new(&m, 0.01);
        let bb = m.surface.bbox();
        let mut rnd = crate::testing::uniform(12345u64);
        let mut agree = 0;
        for _ in 0..200 {
            let (a, b) = (around(&bb, &mut rnd), around(&bb, &mut rnd));
            let limit = 0.5 * rnd();
            let brute = dist
                .tris
                .iter()
                .any(|t| segment_triangle_distance(&a, &b, &t.corners()) < limit);
            assert_eq!(dist.segment_within(&a, &b, limit), brute);
            agree += brute as usize;
        }
        assert!(
            agree > 10,
            "some segments must come near the surface: {agree}"
        );
    }

    #[test]
    fn the_highest_point_under_a_level_move_bounds_the_surface_beneath_it() {
        let m = crate::model::samples::load_sample("keycap-convex").unwrap();
        let dist = SurfaceDistance::new(&m, 0.01);
        let bb = m.surface.bbox();
        // The surface itself, sampled densely (independent of the triangles).
        let n = 120;
        let below: Vec<Point3> = (0..m.surface.faces().len())
            .flat_map(|f| {
                let m = &m;
                (0..=n).flat_map(move |i| {
                    (0..=n)
                        .map(move |j| m.surface.subs(f, i as f64 / n as f64, j as f64 / n as f64))
                })
            })
            .collect();
        let mut rnd = crate::testing::uniform(777u64);
        let (mut met, mut missed) = (0, 0);
        for k in 0..60 {
            let (p, q) = (around(&bb, &mut rnd), around(&bb, &mut rnd));
            // Every fifth beside the model, a millimetre or two from its box.
            let aside = if k % 5 == 4 {
                bb.max[0] - bb.min[0] + 1.0 + 2.0 * rnd()
            } else {
                0.0
            };
            let (a, b) = ([p.x + aside, p.y], [q.x + aside, q.y]);
            let rho = if k % 2 == 0 { 0.3 * rnd() } else { 3.0 * rnd() };
            let rect = PlanRect::spanned(a, b, rho);
            let got = dist.highest_under(&rect);
            // The hierarchy prunes nothing it should not: every triangle tested finds the same.
            let brute = dist
                .tris
                .iter()
                .map(|t| t.corners())
                .filter(|c| {
                    let (l, h) = (
                        [0, 1].map(|k| c[0][k].min(c[1][k]).min(c[2][k])),
                        [0, 1].map(|k| c[0][k].max(c[1][k]).max(c[2][k])),
                    );
                    rect.meets(l, h)
                })
                .map(|c| c[0].z.max(c[1].z).max(c[2].z))
                .fold(None, |acc: Option<f64>, z| {
                    Some(acc.map_or(z, |x| x.max(z)))
                });
            assert_eq!(got, brute);
            // No surface point in the rectangle lies above it, within the tessellation's
            // tolerance (a point that far inside the rectangle lies on a triangle that meets it).
            let tol = dist.tolerance_mm;
            let inner = PlanRect::spanned(a, b, rho - tol);
            let near: Vec<&Point3> = below
                .iter()
                .filter(|x| inner.meets([x.x, x.y], [x.x, x.y]))
                .collect();
            match got {
                Some(top) => {
                    met += 1;
                    for x in &near {
                        assert!(x.z <= top + tol, "{} over {top}", x.z);
                    }
                }
                None => {
                    missed += 1;
                    assert!(
                        near.is_empty(),
                        "{} surface points under a move over nothing",
                        near.len()
                    );
                }
            }
        }
        assert!(
            met > 20 && missed > 0,
            "{met} moves over the surface, {missed} beside it"
        );
    }

    /// True if some point of a fine barycentric lattice on `t` lies inside the cylinder.
    fn lattice_hit(cyl: &Cylinder, t: &[Point3; 3], n: usize) -> bool {
        (0..=n).any(|i| {
            (0..=n - i).any(|j| {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                let p = t[0] + (t[1] - t[0]) * x + (t[2] - t[0]) * y;
                let d = p - cyl.c;
                let along = d.dot(&cyl.axis);
                along >= cyl.a0 && along <= cyl.a1 && (d - cyl.axis * along).norm() < cyl.rad
            })
        })
    }

    #[test]
    fn cylinder_triangle_tests_agree_with_a_dense_lattice_of_the_triangle() {
        // Random triangles and cylinders in a 4 mm box: a hit must return a point of the
        // triangle inside the cylinder, and a lattice point inside must mean a hit.
        let mut rnd = crate::testing::uniform(777u64);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..3000 {
            let mut p = || Point3::new(4.0 * rnd() - 2.0, 4.0 * rnd() - 2.0, 4.0 * rnd() - 2.0);
            let t = [p(), p(), p()];
            let c = p();
            let axis = (p() - Point3::origin()).normalize();
            let a0 = 2.0 * rnd() - 1.0;
            let cyl = Cylinder::new(&c, &axis, (a0, a0 + 3.0 * rnd()), 0.05 + rnd());
            match cyl.hit(&t) {
                Some(q) => {
                    hits += 1;
                    let d = q - cyl.c;
                    let along = d.dot(&axis);
                    assert!(along >= cyl.a0 - 1e-9 && along <= cyl.a1 + 1e-9);
                    assert!((d - axis * along).norm() <= cyl.rad + 1e-9);
                    assert!(point_triangle_distance(&q, &t) < 1e-9);
                }
                None => {
                    misses += 1;
                    assert!(!lattice_hit(&cyl, &t, 60), "missed {t:?} {c} {axis}");
                }
            }
        }
        assert!(hits > 300 && misses > 300, "{hits} hits, {misses} misses");
    }

    #[test]
    fn cylinder_triangle_tests_match_hand_computed_cases() {
        let t = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 2.0, 0.0),
        ];
        let z = Vector3::z();
        let cyl = |c: [f64; 3], axis: Vector3, ends: (f64, f64), rad: f64| {
            Cylinder::new(&Point3::from(c), &axis, ends, rad).hit(&t)
        };
        // Standing on the triangle's inside, flat end on it: a hit.
        assert!(cyl([0.5, 0.5, 0.0], z, (0.0, 1.0), 0.1).is_some());
        // Lifted by 0.01 mm: the flat end clears it (a capsule would not).
        assert!(cyl([0.5, 0.5, 0.0], z, (0.01, 1.0), 0.1).is_none());
        // Upright beside the hypotenuse x + y = 2, 0.1 / √2 mm off: hit only when wider.
        let off = 1.0 + 0.1;
        assert!(cyl([off, off, 0.0], z, (-1.0, 1.0), 0.14).is_none());
        assert!(cyl([off, off, 0.0], z, (-1.0, 1.0), 0.15).is_some());
        // Lying along +X at height 0.5 above the triangle: its side touches at radius 0.5.
        let x = Vector3::x();
        assert!(cyl([-1.0, 0.5, 0.5], x, (0.0, 5.0), 0.49).is_none());
        assert!(cyl([-1.0, 0.5, 0.5], x, (0.0, 5.0), 0.51).is_some());
        // Ending before the triangle starts (x < 0): no hit however wide.
        assert!(cyl([-3.0, 0.5, 0.0], x, (0.0, 2.9), 5.0).is_none());
        // Leaning 10° over the triangle, its lower end `h` above it: the end disc reaches
        // down by `rad·cos 10°` = 0.29544 mm at a point over the triangle (a wall beside a
        // tilted shank, which the plane test tells apart without clipping).
        let lean = Vector3::new(10f64.to_radians().cos(), 0.0, 10f64.to_radians().sin());
        assert!(cyl([0.2, 0.5, 0.2953], lean, (0.0, 1.0), 0.3).is_some());
        assert!(cyl([0.2, 0.5, 0.2956], lean, (0.0, 1.0), 0.3).is_none());
    }

    #[test]
    fn the_hierarchy_finds_the_cylinder_hits_brute_force_finds() {
        let m = crate::model::samples::load_sample("keycap-convex").unwrap();
        let dist = SurfaceDistance::new(&m, 0.01);
        let bb = m.surface.bbox();
        let mut rnd = crate::testing::uniform(4242u64);
        let mut agree = 0;
        for _ in 0..400 {
            let c = around(&bb, &mut rnd);
            let axis = Vector3::new(rnd() - 0.5, rnd() - 0.5, rnd()).normalize();
            let ends = (2.0 * rnd(), 2.0 + 10.0 * rnd());
            let rad = 0.1 + 3.0 * rnd();
            let cyl = Cylinder::new(&c, &axis, ends, rad);
            // The hit the hierarchy returns is the first in the leaves' order (callers lean
            // the tool away from it, so the order decides the plan).
            let brute = dist.tris.iter().find_map(|t| cyl.hit(&t.corners()));
            assert_eq!(dist.cylinder_hit(&c, &axis, ends, rad), brute);
            agree += brute.is_some() as usize;
        }
        assert!(agree > 40 && agree < 360, "{agree} of 400 cylinders hit");
    }

    #[test]
    fn a_model_keeps_its_distance_sets_for_the_next_plan_and_a_copy_starts_without() {
        let m = crate::model::samples::load_sample("keycap-convex").unwrap();
        let opts = crate::plan::PlanOptions {
            tool_radius_mm: 0.5,
            scallop_mm: 0.01,
            ..Default::default()
        };
        let first = crate::plan::plan(&m, &opts, &mut |_| true).unwrap();
        let kept = m.distance_sets.0.lock().unwrap().len();
        assert!((1..=KEPT_SETS).contains(&kept), "{kept} sets kept");
        // The second plan finds them, and plans the same path.
        let again = crate::plan::plan(&m, &opts, &mut |_| true).unwrap();
        assert_eq!(m.distance_sets.0.lock().unwrap().len(), kept);
        assert_eq!(first.toolpath, again.toolpath);
        let a = m.surface_distance(0.02);
        assert!(Arc::ptr_eq(&a, &m.surface_distance(0.02)));
        // A copy starts with none and builds its own, equal to the first.
        let copy = m.clone();
        assert_eq!(copy.distance_sets.0.lock().unwrap().len(), 0);
        let b = copy.surface_distance(0.02);
        assert!(!Arc::ptr_eq(&a, &b));
        assert_eq!(
            (a.tris.len(), a.tolerance_mm),
            (b.tris.len(), b.tolerance_mm)
        );
        // Only the newest few are kept.
        for k in 0..2 * KEPT_SETS {
            m.surface_distance(0.03 + 0.001 * k as f64);
        }
        let sets = m.distance_sets.0.lock().unwrap();
        assert_eq!(sets.len(), KEPT_SETS);
        assert_eq!(
            sets[KEPT_SETS - 1].0,
            (0.03 + 0.001 * (2 * KEPT_SETS - 1) as f64).to_bits()
        );
    }
}
