//! Patch layout: a partition of the surface into rectangular patches, each with its own
//! `(u, v)` in `[0,1]²`, and which patches meet along a side or only at a corner.
//!
//! Patch boundaries are knot lines traced from extraordinary points (along every edge) and
//! from concave corners of the domain (holes, notches: along the edges that continue the
//! boundary), straight on through regular vertices and across faces at T-junction stems,
//! until they reach the boundary, an extraordinary point, or a vertex another line has
//! passed. The faces are cut along those lines into cells; cells joined across uncut edges
//! form the patches. A model whose cells all lie in one chart without filling a rectangle
//! is instead cut only where its concave corners and creases need it ([`cuts`]): the
//! fewest rectangles meeting corner to corner.
//!
//! Owns: tracing, cells, patch charts and connections, and patch evaluation. Must not:
//! change the mesh or the surface.

pub mod cuts;

use crate::geom::{Point3, Vector3};
use crate::surface::diffgeom::unit_normal;
use crate::surface::{FaceLine, FaceSurface, Held, Surface, SurfaceDerivs};
use crate::tmesh::walk::{rot, unit, LineStep};
use crate::tmesh::{TMesh, KNOT_MATCH_REL};
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};

/// A rectangle of one domain face inside a patch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Index of the face in [`Surface::faces`].
    pub face: u32,
    /// `[x0, x1, y0, y1]` in the face's knot coordinates.
    pub local: [f64; 4],
    /// Placement in the patch chart: `chart = rot(quarter_turns)·local + offset`.
    pub quarter_turns: u8,
    pub offset: [f64; 2],
}

/// One rectangular patch.
#[derive(Debug, Clone)]
pub struct Patch {
    pub pieces: Vec<Piece>,
    /// Size of the chart in knot units (`u` spans `width`, `v` spans `height`).
    pub width: f64,
    pub height: f64,
    s_breaks: Vec<f64>,
    t_breaks: Vec<f64>,
    /// Piece of each chart cell, row-major over `(t, s)`.
    cell_piece: Vec<u32>,
}

/// How two patches touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ConnectionKind {
    /// Along a stretch of their sides.
    Boundary,
    /// At a single point only.
    Corner,
}

/// Two patches that touch. Sides are numbered 0: `v = 0`, 1: `u = 1`, 2: `v = 1`,
/// 3: `u = 0`; corners 0: `(0,0)`, 1: `(1,0)`, 2: `(1,1)`, 3: `(0,1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Connection {
    pub a: u32,
    pub b: u32,
    pub kind: ConnectionKind,
    /// For boundary connections the sides of `a` and `b` that touch.
    pub sides: Option<(u8, u8)>,
}

/// The layout of a model.
#[derive(Debug, Clone)]
pub struct PatchLayout {
    pub patches: Vec<Patch>,
    pub connections: Vec<Connection>,
}

/// A cell: a rectangle of a domain face between cut lines.
#[derive(Debug, Clone, Copy)]
struct Cell {
    face: u32,
    rect: [f64; 4],
}

struct Cells {
    cells: Vec<Cell>,
    /// Per domain face: its first cell, and its cut positions `xs`, `ys` (0 and the size
    /// included).
    first: Vec<usize>,
    xs: Vec<Vec<f64>>,
    ys: Vec<Vec<f64>>,
}

impl Cells {
    fn id(&self, face: usize, i: usize, j: usize) -> usize {
        self.first[face] + j * (self.xs[face].len() - 1) + i
    }

    /// Cells along side `side` of domain face `face`, with their ranges along that side
    /// (measured from the side's first corner, as half-edge offsets are).
    fn along_side(&self, face: usize, side: u8, w: f64, h: f64) -> Vec<(usize, f64, f64)> {
        let (xs, ys) = (&self.xs[face], &self.ys[face]);
        let (nx, ny) = (xs.len() - 1, ys.len() - 1);
        match side {
            0 => (0..nx)
                .map(|i| (self.id(face, i, 0), xs[i], xs[i + 1]))
                .collect(),
            1 => (0..ny)
                .map(|j| (self.id(face, nx - 1, j), ys[j], ys[j + 1]))
                .collect(),
            2 => (0..nx)
                .map(|i| (self.id(face, i, ny - 1), w - xs[i + 1], w - xs[i]))
                .collect(),
            _ => (0..ny)
                .map(|j| (self.id(face, 0, j), h - ys[j + 1], h - ys[j]))
                .collect(),
        }
    }
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Angles (quarter turns) of the sectors of surface-carrying faces round `v` (its outgoing
/// half-edges `out`, in order), split where `crease` says an edge is a crease and at faces
/// `is_domain` says carry no surface.
fn crease_sectors(
    mesh: &TMesh,
    v: u32,
    out: &[u32],
    crease: &dyn Fn(u32) -> bool,
    is_domain: &dyn Fn(u32) -> bool,
) -> Vec<u32> {
    // Between the faces of out[i - 1] and out[i] lies the edge out[i]. A boundary vertex's
    // list starts at the boundary and does not wrap; an interior one starts after a crease.
    let n = out.len();
    let start = if mesh.is_boundary_vertex(v) {
        0
    } else {
        (0..n).find(|&i| crease(out[i])).unwrap_or(0)
    };
    let mut sectors = Vec::new();
    let mut cur = 0;
    for k in 0..n {
        let h = out[(start + k) % n];
        if k > 0 && crease(h) {
            sectors.push(cur);
            cur = 0;
        }
        if is_domain(mesh.he(h).face) {
            cur += mesh.sector_quarters(h);
        } else if cur > 0 {
            sectors.push(cur);
            cur = 0;
        }
    }
    sectors.push(cur);
    sectors
}

/// Placement of a face in a chart: `chart = rot(k)·local + offset`.
type Placement = (u8, [f64; 2]);

impl PatchLayout {
    /// Computes the layout of a surface built from `mesh`.
    pub fn build(mesh: &TMesh, surface: &Surface) -> PatchLayout {
        let domain: HashMap<u32, usize> = surface
            .faces()
            .iter()
            .enumerate()
            .map(|(i, f)| (f.mesh_face, i))
            .collect();
        let is_domain = |f: u32| domain.contains_key(&f);
        let nv = mesh.vertex_count() as u32;
        // Infinitely sharp creases (tagged Catmull–Clark edges) bound patches like the
        // boundary does: the surface folds there.
        let crease = |h: u32| {
            let e = mesh.he(h);
            mesh.edge_sharpness(e.origin, mesh.he(e.next).origin) == f64::INFINITY
        };
        let creased: Vec<bool> = (0..nv)
            .map(|v| !mesh.tags().creases.is_empty() && mesh.outgoing(v).into_iter().any(crease))
            .collect();
        // Vertices on the domain's boundary: on the mesh boundary, next to a face that
        // carries no surface, or on a crease.
        let on_boundary: Vec<bool> = (0..nv)
            .map(|v| {
                creased[v as usize]
                    || mesh.is_boundary_vertex(v)
                    || mesh
                        .outgoing(v)
                        .iter()
                        .any(|&h| !is_domain(mesh.he(h).face))
            })
            .collect();
        let domain_angle = |v: u32| -> u32 {
            mesh.outgoing(v)
                .iter()
                .filter(|&&h| is_domain(mesh.he(h).face))
                .map(|&h| mesh.sector_quarters(h))
                .sum()
        };
        let extraordinary: Vec<bool> = (0..nv).map(|v| mesh.is_extraordinary(v)).collect();
        // Where lines start, and along which edges: every edge into the domain from an
        // extraordinary point or a concave corner (of the boundary or between creases); the
        // edge straight on from where a crease ends inside (a dart).
        let mut seeds: Vec<(u32, Vec<u32>)> = Vec::new();
        for v in 0..nv {
            let out = mesh.outgoing(v);
            let inward = |h: &&u32| {
                let e = mesh.he(**h);
                is_domain(e.face)
                    && e.twin.is_some_and(|t| is_domain(mesh.he(t).face))
                    && !crease(**h)
            };
            let all = || out.iter().filter(inward).copied().collect::<Vec<u32>>();
            let (x, b) = (extraordinary[v as usize], on_boundary[v as usize]);
            if x || (b && !creased[v as usize] && domain_angle(v) == 3) {
                seeds.push((v, all()));
            } else if creased[v as usize] {
                let creases: Vec<usize> = (0..out.len()).filter(|&i| crease(out[i])).collect();
                if creases.len() == 1 && !mesh.is_boundary_vertex(v) && out.len() == 4 {
                    seeds.push((v, vec![out[(creases[0] + 2) % 4]]));
                } else if crease_sectors(mesh, v, &out, &crease, &is_domain).contains(&3) {
                    seeds.push((v, all()));
                }
            }
        }

        // Trace the lines.
        let mut on_cut = vec![false; nv as usize];
        let mut cut_edges: HashSet<u32> = HashSet::new();
        let mut face_cuts: Vec<(Vec<f64>, Vec<f64>)> =
            vec![(Vec::new(), Vec::new()); surface.faces().len()];
        for (hi, h) in mesh.half_edges().iter().enumerate() {
            if creased[h.origin as usize] && crease(hi as u32) {
                cut_edges.insert(hi as u32);
            }
        }
        for &(v, _) in &seeds {
            on_cut[v as usize] = true;
        }
        for (_, edges) in &seeds {
            for &h in edges {
                if cut_edges.contains(&h) {
                    continue;
                }
                let steps = {
                    let on_cut_ref = &on_cut;
                    mesh.trace_line(h, &mut |w| {
                        extraordinary[w as usize]
                            || on_boundary[w as usize]
                            || on_cut_ref[w as usize]
                    })
                };
                for s in steps {
                    match s {
                        LineStep::Edge(e) => {
                            cut_edges.insert(e);
                            let he = mesh.he(e);
                            if let Some(t) = he.twin {
                                cut_edges.insert(t);
                            }
                            on_cut[he.origin as usize] = true;
                            on_cut[mesh.he(he.next).origin as usize] = true;
                        }
                        LineStep::Cross { face, side, pos } => {
                            let Some(&d) = domain.get(&face) else {
                                continue;
                            };
                            let f = &mesh.faces()[face as usize];
                            match side {
                                0 => face_cuts[d].0.push(pos),
                                2 => face_cuts[d].0.push(f.width - pos),
                                1 => face_cuts[d].1.push(pos),
                                _ => face_cuts[d].1.push(f.height - pos),
                            }
                        }
                    }
                }
            }
        }

        // Cells.
        let mut cells = Cells {
            cells: Vec::new(),
            first: Vec::new(),
            xs: Vec::new(),
            ys: Vec::new(),
        };
        for (d, f) in surface.faces().iter().enumerate() {
            let positions = |mut c: Vec<f64>, len: f64| {
                let tol = KNOT_MATCH_REL * len;
                c.retain(|&x| x > tol && x < len - tol);
                crate::sort::sort_floats(&mut c);
                c.dedup_by(|a, b| (*a - *b).abs() <= tol);
                let mut out = vec![0.0];
                out.extend(c);
                out.push(len);
                out
            };
            let xs = positions(face_cuts[d].0.clone(), f.width);
            let ys = positions(face_cuts[d].1.clone(), f.height);
            cells.first.push(cells.cells.len());
            for j in 0..ys.len() - 1 {
                for i in 0..xs.len() - 1 {
                    cells.cells.push(Cell {
                        face: d as u32,
                        rect: [xs[i], xs[i + 1], ys[j], ys[j + 1]],
                    });
                }
            }
            cells.xs.push(xs);
            cells.ys.push(ys);
        }

        // Join cells across uncut edges; remember the edges between cells for placement.
        let n = cells.cells.len();
        let mut parent: Vec<usize> = (0..n).collect();
        // (cell a, cell b, half-edge of a's face, half-edge of b's face, cut)
        let mut links: Vec<(usize, usize, u32, u32, bool)> = Vec::new();
        for (hi, h) in mesh.half_edges().iter().enumerate() {
            let hi = hi as u32;
            let Some(t) = h.twin else { continue };
            if hi > t {
                continue;
            }
            let o = mesh.he(t);
            let (Some(&da), Some(&db)) = (domain.get(&h.face), domain.get(&o.face)) else {
                continue;
            };
            if h.knot <= 0.0 {
                continue;
            }
            let (fa, fb) = (
                &mesh.faces()[h.face as usize],
                &mesh.faces()[o.face as usize],
            );
            let tol = KNOT_MATCH_REL * h.knot;
            let side_a = cells.along_side(da, h.side, fa.width, fa.height);
            let side_b = cells.along_side(db, o.side, fb.width, fb.height);
            let cut = cut_edges.contains(&hi);
            for &(ca, a0, a1) in &side_a {
                let lo = a0.max(h.offset);
                let hi_a = a1.min(h.offset + h.knot);
                if hi_a - lo <= tol {
                    continue;
                }
                for &(cb, b0, b1) in &side_b {
                    // b's position p maps to a's position h.offset + h.knot - (p - o.offset).
                    let m0 = h.offset + h.knot - (b1 - o.offset);
                    let m1 = h.offset + h.knot - (b0 - o.offset);
                    if m1.min(hi_a) - m0.max(lo) > tol {
                        links.push((ca, cb, hi, t, cut));
                        if !cut {
                            let (ra, rb) = (find(&mut parent, ca), find(&mut parent, cb));
                            parent[ra] = rb;
                        }
                    }
                }
            }
        }

        // Components in order of their first cell, placed in charts.
        let mut comp_of = vec![usize::MAX; n];
        let mut comps: Vec<Vec<usize>> = Vec::new();
        let mut root_comp: HashMap<usize, usize> = HashMap::new();
        for c in 0..n {
            let r = find(&mut parent, c);
            let k = *root_comp.entry(r).or_insert_with(|| {
                comps.push(Vec::new());
                comps.len() - 1
            });
            comps[k].push(c);
            comp_of[c] = k;
        }
        let mut adjacency: Vec<Vec<(usize, u32, u32)>> = vec![Vec::new(); n];
        for &(a, b, ha, hb, cut) in &links {
            if !cut {
                adjacency[a].push((b, ha, hb));
                adjacency[b].push((a, hb, ha));
            }
        }
        let placed: Vec<Option<Vec<(usize, Placement)>>> = comps
            .iter()
            .map(|comp| place_cells(mesh, &cells, comp, &adjacency))
            .collect();
        // Where each placed component's bounding box starts, if the cells fill it.
        let origins: Vec<Option<[f64; 2]>> = placed
            .iter()
            .map(|p| p.as_deref().and_then(|p| rectangle_origin(&cells, p)))
            .collect();
        // One component in one chart that is not a rectangle (face.tsm: two holes; Bike.tsm:
        // a slot in the outline): cut at its concave corners, not a patch per cell.
        if let ([Some(whole)], [None]) = (placed.as_slice(), origins.as_slice()) {
            // Cells the mesh joins along an edge of positive knot interval: side by side in
            // the chart without such a link, they meet across a crease.
            let linked: std::collections::HashSet<(usize, usize)> = links
                .iter()
                .map(|&(a, b, ..)| (a.min(b), a.max(b)))
                .collect();
            if let Some(layout) = chart_layout(surface, &cells, whole, &linked) {
                return layout;
            }
        }
        let mut patches: Vec<Patch> = Vec::new();
        let mut patch_of_cell = vec![0u32; n];
        for ((comp, placed), origin) in comps.iter().zip(placed).zip(origins) {
            let chunks: Vec<Vec<(usize, Placement)>> = match placed.zip(origin) {
                // The chart moved so that the rectangle starts at its origin.
                Some((mut p, lo)) => {
                    for (_, pl) in p.iter_mut() {
                        pl.1 = [pl.1[0] - lo[0], pl.1[1] - lo[1]];
                    }
                    vec![p]
                }
                // Not a rectangle (e.g. a band closing on itself): one patch per cell.
                None => comp.iter().map(|&c| vec![(c, (0, [0.0, 0.0]))]).collect(),
            };
            for chunk in chunks {
                let id = patches.len() as u32;
                for &(c, _) in &chunk {
                    patch_of_cell[c] = id;
                }
                patches.push(Patch::from_cells(&cells, &chunk));
            }
        }

        // Connections.
        let mut boundary: HashSet<(u32, u32)> = HashSet::new();
        let mut connections: Vec<Connection> = Vec::new();
        let mut add_boundary = |a: u32, b: u32, sa: u8, sb: u8, out: &mut Vec<Connection>| {
            if a == b {
                return;
            }
            let key = (a.min(b), a.max(b));
            if boundary.insert(key) {
                let sides = if a < b { (sa, sb) } else { (sb, sa) };
                out.push(Connection {
                    a: key.0,
                    b: key.1,
                    kind: ConnectionKind::Boundary,
                    sides: Some(sides),
                });
            }
        };
        // Every link between cells of different patches: cut edges, and the uncut edges
        // inside a component that could not be laid out as one rectangle.
        for &(ca, cb, ha, hb, _) in &links {
            let (pa, pb) = (patch_of_cell[ca], patch_of_cell[cb]);
            let sa = patches[pa as usize].side_of(mesh, &cells.cells[ca], ha);
            let sb = patches[pb as usize].side_of(mesh, &cells.cells[cb], hb);
            add_boundary(pa, pb, sa, sb, &mut connections);
        }
        // Cells of one face separated by a cut line inside it.
        for d in 0..surface.faces().len() {
            let (nx, ny) = (cells.xs[d].len() - 1, cells.ys[d].len() - 1);
            for j in 0..ny {
                for i in 0..nx {
                    let c = cells.id(d, i, j);
                    for (di, dj) in [(1usize, 0usize), (0, 1)] {
                        if i + di >= nx || j + dj >= ny {
                            continue;
                        }
                        let o = cells.id(d, i + di, j + dj);
                        let (pa, pb) = (patch_of_cell[c], patch_of_cell[o]);
                        let (x, y) = if di == 1 {
                            (
                                cells.xs[d][i + 1],
                                0.5 * (cells.ys[d][j] + cells.ys[d][j + 1]),
                            )
                        } else {
                            (
                                0.5 * (cells.xs[d][i] + cells.xs[d][i + 1]),
                                cells.ys[d][j + 1],
                            )
                        };
                        let sa = patches[pa as usize].side_at(d as u32, [x, y]);
                        let sb = patches[pb as usize].side_at(d as u32, [x, y]);
                        add_boundary(pa, pb, sa, sb, &mut connections);
                    }
                }
            }
        }
        // Corner connections: patches that share a mesh vertex but no side.
        let mut corner: HashSet<(u32, u32)> = HashSet::new();
        for v in 0..nv {
            let mut touching: Vec<u32> = Vec::new();
            for h in mesh.outgoing(v) {
                let e = mesh.he(h);
                let Some(&d) = domain.get(&e.face) else {
                    continue;
                };
                let f = &mesh.faces()[e.face as usize];
                let (lo, _) = mesh.local_frame(h);
                let p = [lo[0].clamp(0.0, f.width), lo[1].clamp(0.0, f.height)];
                for c in cells.first[d]
                    ..cells.first[d] + (cells.xs[d].len() - 1) * (cells.ys[d].len() - 1)
                {
                    let r = cells.cells[c].rect;
                    let tol = KNOT_MATCH_REL * f.width.max(f.height);
                    if p[0] >= r[0] - tol
                        && p[0] <= r[1] + tol
                        && p[1] >= r[2] - tol
                        && p[1] <= r[3] + tol
                    {
                        touching.push(patch_of_cell[c]);
                    }
                }
            }
            touching.sort_unstable();
            touching.dedup();
            for (i, &a) in touching.iter().enumerate() {
                for &b in &touching[i + 1..] {
                    if !boundary.contains(&(a, b)) && corner.insert((a, b)) {
                        connections.push(Connection {
                            a,
                            b,
                            kind: ConnectionKind::Corner,
                            sides: None,
                        });
                    }
                }
            }
        }
        crate::sort::sort_by_key(&mut connections, |c| (c.a, c.b));
        PatchLayout {
            patches,
            connections,
        }
    }

    /// A layout of the chart rectangles `rects` (`[s0, s1, t0, t1]`) of a domain laid flat
    /// under `placements` (see [`Patch::from_chart_rect`]): one patch per rectangle, in
    /// order, connected where rectangles share a stretch of side (boundary) or only a point
    /// (corner). `None` if faces do not fill a rectangle.
    pub fn from_chart_rects(
        surface: &Surface,
        placements: &[crate::tmesh::walk::Placement],
        rects: &[[f64; 4]],
    ) -> Option<PatchLayout> {
        let patches = rects
            .iter()
            .map(|r| Patch::from_chart_rect(surface, placements, *r))
            .collect::<Option<Vec<_>>>()?;
        let size = rects
            .iter()
            .map(|r| (r[1] - r[0]).max(r[3] - r[2]))
            .fold(0.0f64, f64::max);
        let tol = KNOT_MATCH_REL * size.max(1.0);
        let mut connections = Vec::new();
        for (a, ra) in rects.iter().enumerate() {
            for (b, rb) in rects.iter().enumerate().skip(a + 1) {
                // Overlap of the two along s and along t (negative: apart).
                let ds = ra[1].min(rb[1]) - ra[0].max(rb[0]);
                let dt = ra[3].min(rb[3]) - ra[2].max(rb[2]);
                if ds < -tol || dt < -tol {
                    continue;
                }
                // Which sides touch: 0 v = 0 (t0), 1 u = 1 (s1), 2 v = 1 (t1), 3 u = 0 (s0).
                let near = |x: f64, y: f64| (x - y).abs() <= tol;
                let sides = if near(ra[1], rb[0]) {
                    Some((1, 3))
                } else if near(ra[0], rb[1]) {
                    Some((3, 1))
                } else if near(ra[3], rb[2]) {
                    Some((2, 0))
                } else if near(ra[2], rb[3]) {
                    Some((0, 2))
                } else {
                    None
                };
                let Some(sides) = sides else { continue };
                let along = if sides.0 % 2 == 1 { dt } else { ds };
                let (kind, sides) = if along > tol {
                    (ConnectionKind::Boundary, Some(sides))
                } else {
                    (ConnectionKind::Corner, None)
                };
                connections.push(Connection {
                    a: a as u32,
                    b: b as u32,
                    kind,
                    sides,
                });
            }
        }
        Some(PatchLayout {
            patches,
            connections,
        })
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// True if there are no patches.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }
}

/// Places the cells of a component in one chart by walking across shared edges. `None` if
/// the placement is inconsistent.
fn place_cells(
    mesh: &TMesh,
    cells: &Cells,
    comp: &[usize],
    adjacency: &[Vec<(usize, u32, u32)>],
) -> Option<Vec<(usize, Placement)>> {
    let mut placed: HashMap<usize, Placement> = HashMap::new();
    let mut face_pl: HashMap<u32, Placement> = HashMap::new();
    let start = comp[0];
    placed.insert(start, (0, [0.0, 0.0]));
    face_pl.insert(cells.cells[start].face, (0, [0.0, 0.0]));
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(c) = queue.pop_front() {
        let (k, off) = placed[&c];
        for &(o, h, t) in &adjacency[c] {
            let cand = if cells.cells[o].face == cells.cells[c].face {
                (k, off)
            } else {
                let (lo, side) = mesh.local_frame(h);
                let knot = mesh.he(h).knot;
                let d = unit(side);
                let r = rot(k, [lo[0] + knot * d[0], lo[1] + knot * d[1]]);
                let pos = [r[0] + off[0], r[1] + off[1]];
                let dir = (k + side + 2) % 4;
                let (lo_t, side_t) = mesh.local_frame(t);
                let kk = (dir + 4 - side_t) % 4;
                let rt = rot(kk, lo_t);
                (kk, [pos[0] - rt[0], pos[1] - rt[1]])
            };
            let face = cells.cells[o].face;
            if let Some(&prev) = face_pl.get(&face) {
                let scale = 1.0 + prev.1[0].abs().max(prev.1[1].abs());
                if prev.0 != cand.0
                    || (prev.1[0] - cand.1[0]).abs() + (prev.1[1] - cand.1[1]).abs() > 1e-7 * scale
                {
                    return None;
                }
            } else {
                face_pl.insert(face, cand);
            }
            if let std::collections::hash_map::Entry::Vacant(e) = placed.entry(o) {
                e.insert(cand);
                queue.push_back(o);
            }
        }
    }
    if placed.len() != comp.len() {
        return None;
    }
    Some(comp.iter().map(|&c| (c, placed[&c])).collect())
}

/// Where the bounding box of the placed cells starts in the chart, if the cells fill it
/// (a rectangle).
fn rectangle_origin(cells: &Cells, placed: &[(usize, Placement)]) -> Option<[f64; 2]> {
    // Rectangle check: the cells' areas add up to their bounding box.
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut area = 0.0;
    for &(c, pl) in placed {
        let (a, b) = chart_rect(&cells.cells[c].rect, pl);
        lo = [lo[0].min(a[0]), lo[1].min(a[1])];
        hi = [hi[0].max(b[0]), hi[1].max(b[1])];
        area += (b[0] - a[0]) * (b[1] - a[1]);
    }
    let box_area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    (box_area > 0.0 && (area - box_area).abs() <= RECT_FILL_REL * box_area).then_some(lo)
}

/// The layout of a model whose cells (all of them, `placed` in one chart) do not fill a
/// rectangle (a notch in the outline, a hole without the lines that would cut round it):
/// the chart cut at its concave corners and along creases (sides between cells not in
/// `linked`) ([`cuts::cut_at_concave_corners`]), each region one patch. `None` if a region
/// is not a rectangle or a patch's faces do not fill it.
fn chart_layout(
    surface: &Surface,
    cells: &Cells,
    placed: &[(usize, Placement)],
    linked: &std::collections::HashSet<(usize, usize)>,
) -> Option<PatchLayout> {
    let mut placements = vec![
        crate::tmesh::walk::Placement {
            face: 0,
            quarter_turns: 0,
            offset: [0.0, 0.0],
        };
        surface
            .faces()
            .iter()
            .map(|f| f.mesh_face as usize + 1)
            .max()?
    ];
    let mut chart = Vec::with_capacity(placed.len());
    for &(c, (k, offset)) in placed {
        let mesh_face = surface.faces()[cells.cells[c].face as usize].mesh_face;
        placements[mesh_face as usize] = crate::tmesh::walk::Placement {
            face: mesh_face,
            quarter_turns: k,
            offset,
        };
        let (a, b) = chart_rect(&cells.cells[c].rect, (k, offset));
        chart.push([a[0], b[0], a[1], b[1]]);
    }
    let size = chart
        .iter()
        .map(|r| (r[1] - r[0]).max(r[3] - r[2]))
        .fold(0.0f64, f64::max);
    let joined = |i: usize, j: usize| {
        let (a, b) = (placed[i].0, placed[j].0);
        linked.contains(&(a.min(b), a.max(b)))
    };
    let rects = cuts::cut_at_concave_corners(&chart, &joined, KNOT_MATCH_REL * size.max(1.0))?;
    PatchLayout::from_chart_rects(surface, &placements, &rects)
}

/// `v` moved onto `lo` or `hi` if within `tol` of it.
fn snap_to(v: f64, lo: f64, hi: f64, tol: f64) -> f64 {
    if (v - lo).abs() <= tol {
        lo
    } else if (v - hi).abs() <= tol {
        hi
    } else {
        v
    }
}

/// Relative mismatch between a chart rectangle's area and the face parts inside it above
/// which faces do not fill it.
const RECT_FILL_REL: f64 = 1e-9;
/// Patch parameters closer than this are one point (dimensionless, a share of the patch).
const SAME_POINT_PARAM: f64 = 1e-9;

/// The chart rectangle `(min, max)` of a local rectangle under a placement.
fn chart_rect(r: &[f64; 4], (k, off): Placement) -> ([f64; 2], [f64; 2]) {
    let a = rot(k, [r[0], r[2]]);
    let b = rot(k, [r[1], r[3]]);
    (
        [a[0].min(b[0]) + off[0], a[1].min(b[1]) + off[1]],
        [a[0].max(b[0]) + off[0], a[1].max(b[1]) + off[1]],
    )
}

/// An iso-line of a patch, `v = const` or `u = const`: the numbers of [`Patch::derivs`],
/// [`Patch::derivs_normal`] and [`Patch::point_normal`] at its points, with each face's
/// contraction across the line done once per Bézier cell (see
/// [`crate::surface::FaceLine`]: bit for bit where the face holds its `u`, up to rounding
/// where it holds its `v`).
pub struct PatchLine<'a> {
    patch: &'a Patch,
    surface: &'a Surface,
    /// The line `v = at` (`u` runs), else `u = at`.
    along_u: bool,
    at: f64,
    /// The chart cell (row or column) holding the line.
    held_cell: usize,
    /// The chart cell last evaluated along the line, and the chart coordinates it covers
    /// (`[lo, hi)`, unbounded at the chart's ends: those [`chart_cell`] gives it).
    run_cell: Option<(usize, f64, f64)>,
    /// The piece last evaluated and its face's line.
    face_line: Option<(usize, FaceLine<'a>)>,
}

/// Chart cell of `x` along `breaks` (clamped to the first and last).
fn chart_cell(breaks: &[f64], x: f64) -> usize {
    let n = breaks.len() - 1;
    breaks[1..n].partition_point(|&b| b <= x).min(n - 1)
}

impl<'a> PatchLine<'a> {
    /// The piece at running parameter `x`, its face, the face's parameters there and its
    /// line through them with the running face parameter.
    fn at(&mut self, x: f64) -> (&'a Piece, &'a FaceSurface, [f64; 2], &mut FaceLine<'a>, f64) {
        let patch = self.patch;
        let (u, v) = if self.along_u {
            (x, self.at)
        } else {
            (self.at, x)
        };
        let (s, t) = (u * patch.width, v * patch.height);
        let (x_run, breaks) = if self.along_u {
            (s, &patch.s_breaks)
        } else {
            (t, &patch.t_breaks)
        };
        let cell = match self.run_cell {
            Some((c, lo, hi)) if lo <= x_run && x_run < hi => c,
            _ => {
                let c = chart_cell(breaks, x_run);
                let n = breaks.len() - 1;
                let lo = if c == 0 { f64::NEG_INFINITY } else { breaks[c] };
                let hi = if c + 1 == n {
                    f64::INFINITY
                } else {
                    breaks[c + 1]
                };
                self.run_cell = Some((c, lo, hi));
                c
            }
        };
        let (i, j) = if self.along_u {
            (cell, self.held_cell)
        } else {
            (self.held_cell, cell)
        };
        let (k, [x, y]) = patch.piece_in(i, j, s, t);
        let p = &patch.pieces[k];
        let face = &self.surface.faces()[p.face as usize];
        let ab = [x / face.width, y / face.height];
        // A quarter turn swaps the chart's axes in the face.
        let held = if self.along_u == (p.quarter_turns % 2 == 0) {
            Held::V
        } else {
            Held::U
        };
        let (fixed, run) = match held {
            Held::U => (ab[0], ab[1]),
            Held::V => (ab[1], ab[0]),
        };
        if self.face_line.as_ref().is_some_and(|(c, _)| *c != k) {
            self.face_line = None;
        }
        debug_assert!(self
            .face_line
            .as_ref()
            .is_none_or(|(_, line)| line.held_at() == (held, fixed)));
        let line = &mut self
            .face_line
            .get_or_insert_with(|| (k, face.line(held, fixed)))
            .1;
        (p, face, ab, line, run)
    }

    /// Point and derivatives at running parameter `x` (as [`Patch::derivs`]).
    pub fn derivs(&mut self, x: f64) -> SurfaceDerivs {
        let patch = self.patch;
        let (p, face, _, line, run) = self.at(x);
        let d = line.derivs(run);
        patch.to_patch(p, face, d)
    }

    /// Derivatives and unit normal at running parameter `x` (as [`Patch::derivs_normal`]).
    pub fn derivs_normal(&mut self, x: f64) -> (SurfaceDerivs, Option<Vector3>) {
        let patch = self.patch;
        let (p, face, [a, b], line, run) = self.at(x);
        let d = line.derivs(run);
        let normal = unit_normal(&d.su, &d.sv).or_else(|| face.normal(a, b));
        (patch.to_patch(p, face, d), normal)
    }

    /// Point and unit normal at running parameter `x` (as [`Patch::point_normal`]).
    pub fn point_normal(&mut self, x: f64) -> (Point3, Option<Vector3>) {
        let (_, face, [a, b], line, run) = self.at(x);
        let (point, su, sv) = line.first_derivs(run);
        (point, unit_normal(&su, &sv).or_else(|| face.normal(a, b)))
    }
}

/// Patch parameters at `t` along side `side` of a patch (0: `v = 0`, 1: `u = 1`, 2: `v = 1`,
/// 3: `u = 0`; `t` is the other parameter, increasing with it).
pub fn side_uv(side: u8, t: f64) -> [f64; 2] {
    match side {
        0 => [t, 0.0],
        1 => [1.0, t],
        2 => [t, 1.0],
        _ => [0.0, t],
    }
}

/// The parameter along side `side` (as [`side_uv`] takes it) of patch parameters `uv`.
pub fn side_param(side: u8, uv: [f64; 2]) -> f64 {
    if side % 2 == 0 {
        uv[0]
    } else {
        uv[1]
    }
}

impl Patch {
    fn from_cells(cells: &Cells, chunk: &[(usize, Placement)]) -> Patch {
        let mut pieces = Vec::with_capacity(chunk.len());
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for &(c, pl) in chunk {
            let cell = &cells.cells[c];
            let (a, b) = chart_rect(&cell.rect, pl);
            lo = [lo[0].min(a[0]), lo[1].min(a[1])];
            hi = [hi[0].max(b[0]), hi[1].max(b[1])];
            pieces.push(Piece {
                face: cell.face,
                local: cell.rect,
                quarter_turns: pl.0,
                offset: pl.1,
            });
        }
        // A single-cell patch from a non-rectangular component is placed at its own origin.
        for p in pieces.iter_mut() {
            p.offset = [p.offset[0] - lo[0], p.offset[1] - lo[1]];
        }
        Patch::from_pieces(pieces, hi[0] - lo[0], hi[1] - lo[1])
    }

    /// The patch covering the chart rectangle `rect` = `[s0, s1, t0, t1]` of a domain whose
    /// faces (indices into [`Surface::faces`]) lie in one chart under `placements` (by mesh
    /// face): the parts of the faces inside it as pieces (a face whose side lies on the
    /// rectangle's only to rounding gives no piece a few ulps wide). `None` if faces do not
    /// fill the rectangle (a hole or the boundary cuts into it) or it has no area.
    pub fn from_chart_rect(
        surface: &Surface,
        placements: &[crate::tmesh::walk::Placement],
        rect: [f64; 4],
    ) -> Option<Patch> {
        let (width, height) = (rect[1] - rect[0], rect[3] - rect[2]);
        if !(width > 0.0 && height > 0.0) {
            return None;
        }
        let mut pieces = Vec::new();
        let mut area = 0.0;
        let tol = KNOT_MATCH_REL * width.max(height).max(1.0);
        for (fi, f) in surface.faces().iter().enumerate() {
            let pl = placements.get(f.mesh_face as usize)?;
            let (k, off) = (pl.quarter_turns % 4, pl.offset);
            let (a, b) = chart_rect(&[0.0, f.width, 0.0, f.height], (k, off));
            let (lo, hi) = (
                [a[0].max(rect[0]), a[1].max(rect[2])],
                [b[0].min(rect[1]), b[1].min(rect[3])],
            );
            if !(hi[0] > lo[0] && hi[1] > lo[1]) {
                continue;
            }
            // A face whose side lies on the rectangle's side only to rounding would leave a
            // piece a few ulps wide (and its neighbour a few ulps short of its side); a face
            // that is itself that thin is kept.
            let clipped_thin = |k: usize| hi[k] - lo[k] <= tol && b[k] - a[k] > tol;
            if clipped_thin(0) || clipped_thin(1) {
                continue;
            }
            area += (hi[0] - lo[0]) * (hi[1] - lo[1]);
            let back = |c: [f64; 2]| rot((4 - k) % 4, [c[0] - off[0], c[1] - off[1]]);
            let (x, y) = (back(lo), back(hi));
            let snap = |v: f64, size: f64| snap_to(v, 0.0, size, tol).clamp(0.0, size);
            pieces.push(Piece {
                face: fi as u32,
                local: [
                    snap(x[0].min(y[0]), f.width),
                    snap(x[0].max(y[0]), f.width),
                    snap(x[1].min(y[1]), f.height),
                    snap(x[1].max(y[1]), f.height),
                ],
                quarter_turns: k,
                offset: [off[0] - rect[0], off[1] - rect[2]],
            });
        }
        let whole = width * height;
        if pieces.is_empty() || (area - whole).abs() > RECT_FILL_REL * whole {
            return None;
        }
        Some(Patch::from_pieces(pieces, width, height))
    }

    /// A patch of `width × height` knot units from pieces placed in its chart.
    fn from_pieces(pieces: Vec<Piece>, width: f64, height: f64) -> Patch {
        let tol = KNOT_MATCH_REL * width.max(height);
        let mut s_breaks: Vec<f64> = Vec::new();
        let mut t_breaks: Vec<f64> = Vec::new();
        for p in &pieces {
            let (a, b) = chart_rect(&p.local, (p.quarter_turns, p.offset));
            s_breaks.extend([a[0], b[0]]);
            t_breaks.extend([a[1], b[1]]);
        }
        for v in [&mut s_breaks, &mut t_breaks] {
            crate::sort::sort_floats(v);
            v.dedup_by(|a, b| (*a - *b).abs() <= tol);
        }
        let mut cell_piece = Vec::with_capacity((s_breaks.len() - 1) * (t_breaks.len() - 1));
        for j in 0..t_breaks.len() - 1 {
            for i in 0..s_breaks.len() - 1 {
                let m = [
                    0.5 * (s_breaks[i] + s_breaks[i + 1]),
                    0.5 * (t_breaks[j] + t_breaks[j + 1]),
                ];
                let k = pieces
                    .iter()
                    .position(|p| {
                        let (a, b) = chart_rect(&p.local, (p.quarter_turns, p.offset));
                        m[0] >= a[0] && m[0] <= b[0] && m[1] >= a[1] && m[1] <= b[1]
                    })
                    .unwrap_or(0);
                cell_piece.push(k as u32);
            }
        }
        Patch {
            pieces,
            width,
            height,
            s_breaks,
            t_breaks,
            cell_piece,
        }
    }

    /// The piece at chart point `(s, t)` and the face-knot coordinates there.
    fn locate(&self, s: f64, t: f64) -> (&Piece, [f64; 2]) {
        let (k, xy) = self.locate_index(s, t);
        (&self.pieces[k], xy)
    }

    /// [`Patch::locate`] with the piece's index.
    fn locate_index(&self, s: f64, t: f64) -> (usize, [f64; 2]) {
        let i = chart_cell(&self.s_breaks, s);
        let j = chart_cell(&self.t_breaks, t);
        self.piece_in(i, j, s, t)
    }

    /// The piece of chart cell `(i, j)` and the face-knot coordinates of `(s, t)` there.
    fn piece_in(&self, i: usize, j: usize, s: f64, t: f64) -> (usize, [f64; 2]) {
        let k = self.cell_piece[j * (self.s_breaks.len() - 1) + i] as usize;
        let p = &self.pieces[k];
        let local = rot(
            (4 - p.quarter_turns) % 4,
            [s - p.offset[0], t - p.offset[1]],
        );
        let x = local[0].clamp(p.local[0], p.local[1]);
        let y = local[1].clamp(p.local[2], p.local[3]);
        (k, [x, y])
    }

    /// Patch parameters `(u, v)` of the extraordinary points on the patch (inside it or on
    /// its sides and corners), each once.
    pub fn singular_points(&self, surface: &Surface) -> Vec<[f64; 2]> {
        let mut out: Vec<[f64; 2]> = Vec::new();
        for p in &self.pieces {
            let face = &surface.faces()[p.face as usize];
            for c in face.singular_corners() {
                let local = [c[0] * face.width, c[1] * face.height];
                let inside = local[0] >= p.local[0]
                    && local[0] <= p.local[1]
                    && local[1] >= p.local[2]
                    && local[1] <= p.local[3];
                if !inside {
                    continue;
                }
                let r = rot(p.quarter_turns, local);
                let uv = [
                    (r[0] + p.offset[0]) / self.width,
                    (r[1] + p.offset[1]) / self.height,
                ];
                // Pieces meeting at the point give it each (knot coordinates are exact
                // sums of knot intervals, so the copies agree to rounding).
                let same = |q: &[f64; 2]| {
                    (q[0] - uv[0]).abs() <= SAME_POINT_PARAM
                        && (q[1] - uv[1]).abs() <= SAME_POINT_PARAM
                };
                if !out.iter().any(same) {
                    out.push(uv);
                }
            }
        }
        out
    }

    /// The iso-line `v = at` (`along_u`) or `u = at` of the patch, for many evaluations along
    /// it: see [`PatchLine`].
    pub fn line<'a>(&'a self, surface: &'a Surface, along_u: bool, at: f64) -> PatchLine<'a> {
        let (breaks, size) = if along_u {
            (&self.t_breaks, self.height)
        } else {
            (&self.s_breaks, self.width)
        };
        PatchLine {
            patch: self,
            surface,
            along_u,
            at,
            held_cell: chart_cell(breaks, at * size),
            run_cell: None,
            face_line: None,
        }
    }

    /// Point and derivatives at patch parameters `(u, v)` in `[0,1]²`.
    pub fn derivs(&self, surface: &Surface, u: f64, v: f64) -> SurfaceDerivs {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        self.to_patch(p, face, face.derivs(x / face.width, y / face.height))
    }

    /// Face derivatives `d` of piece `p` in the patch's parameters.
    fn to_patch(
        &self,
        p: &Piece,
        face: &crate::surface::FaceSurface,
        d: SurfaceDerivs,
    ) -> SurfaceDerivs {
        let [j00, j10, j01, j11] = self.jacobian(p, face);
        SurfaceDerivs {
            point: d.point,
            su: d.su * j00 + d.sv * j10,
            sv: d.su * j01 + d.sv * j11,
            suu: d.suu * (j00 * j00) + d.suv * (2.0 * j00 * j10) + d.svv * (j10 * j10),
            suv: d.suu * (j00 * j01) + d.suv * (j00 * j11 + j10 * j01) + d.svv * (j10 * j11),
            svv: d.suu * (j01 * j01) + d.suv * (2.0 * j01 * j11) + d.svv * (j11 * j11),
        }
    }

    /// [`Patch::derivs`] and [`Patch::point_normal`]'s normal from one evaluation (the
    /// normal the face's own, as there, bit for bit).
    pub fn derivs_normal(
        &self,
        surface: &Surface,
        u: f64,
        v: f64,
    ) -> (SurfaceDerivs, Option<crate::geom::Vector3>) {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        let (a, b) = (x / face.width, y / face.height);
        let d = face.derivs(a, b);
        let normal =
            crate::surface::diffgeom::unit_normal(&d.su, &d.sv).or_else(|| face.normal(a, b));
        (self.to_patch(p, face, d), normal)
    }

    /// Point and first derivatives `(S, S_u, S_v)` at patch parameters `(u, v)`: those of
    /// [`Patch::derivs`], without the second derivatives.
    pub fn first_derivs(
        &self,
        surface: &Surface,
        u: f64,
        v: f64,
    ) -> (Point3, crate::geom::Vector3, crate::geom::Vector3) {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        let (point, su, sv) = face.first_derivs(x / face.width, y / face.height);
        let [j00, j10, j01, j11] = self.jacobian(p, face);
        (point, su * j00 + sv * j10, su * j01 + sv * j11)
    }

    /// `∂(a, b)/∂(u, v)` as `[∂a/∂u, ∂b/∂u, ∂a/∂v, ∂b/∂v]`: face parameters `(a, b)` of
    /// piece `p` from patch parameters, `a = x / W_f` with `(x, y) = rot(−k)(s − off)`,
    /// `s = u·W`, `t = v·H`.
    fn jacobian(&self, p: &Piece, face: &crate::surface::FaceSurface) -> [f64; 4] {
        let m = rot((4 - p.quarter_turns) % 4, [1.0, 0.0]);
        let n = rot((4 - p.quarter_turns) % 4, [0.0, 1.0]);
        [
            m[0] * self.width / face.width,
            m[1] * self.width / face.height,
            n[0] * self.height / face.width,
            n[1] * self.height / face.height,
        ]
    }

    /// Unit normal at patch parameters `(u, v)` (from nearby where the surface is singular).
    pub fn normal(&self, surface: &Surface, u: f64, v: f64) -> Option<crate::geom::Vector3> {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        face.normal(x / face.width, y / face.height)
    }

    /// The face rectangles a patch rectangle `[u0, u1, v0, v1]` covers: for each piece it
    /// meets, the face and the part of the rectangle in that face's parameters `[a0, a1, b0,
    /// b1]` (within `[0, 1]`). Pieces are placed by quarter turns, so the parts are
    /// rectangles too.
    pub fn face_rects(&self, surface: &Surface, rect: [f64; 4]) -> Vec<(u32, [f64; 4])> {
        let lo = [rect[0] * self.width, rect[2] * self.height];
        let hi = [rect[1] * self.width, rect[3] * self.height];
        let mut out = Vec::new();
        let tol = KNOT_MATCH_REL * self.width.max(self.height);
        for p in &self.pieces {
            let (a, b) = chart_rect(&p.local, (p.quarter_turns, p.offset));
            let (clo, chi) = (
                [lo[0].max(a[0]), lo[1].max(a[1])],
                [hi[0].min(b[0]), hi[1].min(b[1])],
            );
            if clo[0] > chi[0] || clo[1] > chi[1] {
                continue;
            }
            // Back to the face's knot coordinates, then to its unit square.
            let back = |c: [f64; 2]| {
                rot(
                    (4 - p.quarter_turns) % 4,
                    [c[0] - p.offset[0], c[1] - p.offset[1]],
                )
            };
            let (x, y) = (back(clo), back(chi));
            let face = &surface.faces()[p.face as usize];
            // A footprint reaching the piece's side reaches exactly the piece's own bound
            // (which the neighbouring patch's piece of the face shares bit for bit): the round
            // trip through the chart must not leave it a few ulps short, or a sample on that
            // line would fall outside the rest area of both.
            let snap = |v: f64, lo: f64, hi: f64| snap_to(v, lo, hi, tol);
            let (l0, l1) = (
                snap(x[0].min(y[0]), p.local[0], p.local[1]),
                snap(x[0].max(y[0]), p.local[0], p.local[1]),
            );
            let (m0, m1) = (
                snap(x[1].min(y[1]), p.local[2], p.local[3]),
                snap(x[1].max(y[1]), p.local[2], p.local[3]),
            );
            let unit = |v: f64, size: f64| (v / size).clamp(0.0, 1.0);
            out.push((
                p.face,
                [
                    unit(l0, face.width),
                    unit(l1, face.width),
                    unit(m0, face.height),
                    unit(m1, face.height),
                ],
            ));
        }
        out
    }

    /// The surface face (index into [`Surface::faces`]) at patch parameters `(u, v)` and the
    /// point's parameters in that face's unit square.
    pub fn face_param(&self, surface: &Surface, u: f64, v: f64) -> (u32, [f64; 2]) {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        (p.face, [x / face.width, y / face.height])
    }

    /// Point and unit normal (the face's, see [`crate::surface::FaceSurface::normal`]) at
    /// patch parameters `(u, v)`, from one evaluation.
    pub fn point_normal(
        &self,
        surface: &Surface,
        u: f64,
        v: f64,
    ) -> (Point3, Option<crate::geom::Vector3>) {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        face.point_normal(x / face.width, y / face.height)
    }

    /// Point at patch parameters `(u, v)`.
    pub fn subs(&self, surface: &Surface, u: f64, v: f64) -> Point3 {
        let (p, [x, y]) = self.locate(u * self.width, v * self.height);
        let face = &surface.faces()[p.face as usize];
        face.subs(x / face.width, y / face.height)
    }

    /// Which side of the patch a face-local point of piece face `face` lies on.
    fn side_at(&self, face: u32, local: [f64; 2]) -> u8 {
        let p = self
            .pieces
            .iter()
            .find(|p| {
                p.face == face
                    && local[0] >= p.local[0] - 1e-12
                    && local[0] <= p.local[1] + 1e-12
                    && local[1] >= p.local[2] - 1e-12
                    && local[1] <= p.local[3] + 1e-12
            })
            .unwrap_or(&self.pieces[0]);
        let r = rot(p.quarter_turns, local);
        let c = [r[0] + p.offset[0], r[1] + p.offset[1]];
        let d = [c[1], self.width - c[0], self.height - c[1], c[0]];
        (0..4)
            .min_by(|&a, &b| d[a].abs().total_cmp(&d[b].abs()))
            .unwrap_or(0) as u8
    }

    /// The side of the patch on which half-edge `h` (bounding `cell`) lies.
    fn side_of(&self, mesh: &TMesh, cell: &Cell, h: u32) -> u8 {
        let (lo, side) = mesh.local_frame(h);
        let e = mesh.he(h);
        let d = unit(side);
        let mid = [lo[0] + 0.5 * e.knot * d[0], lo[1] + 0.5 * e.knot * d[1]];
        let mid = [
            mid[0].clamp(cell.rect[0], cell.rect[1]),
            mid[1].clamp(cell.rect[2], cell.rect[3]),
        ];
        self.side_at(cell.face, mid)
    }
}
