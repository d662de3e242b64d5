//! Improved space-filling curve (Gan et al. 2014, §4): the whole surface — irregular
//! boundary, holes and all — cut in one closed curve with no retraction.
//!
//! Each patch of the layout gets a scallop-limited grid in its own `(u, v)`
//! ([`grid`]); its vertices are grouped into disjoint 2 × 2 cells, each a small closed loop
//! ([`cells`]); a minimum spanning tree over side-adjacent cells, with the cost of eq. 9
//! ([`tree`]), says which loops to merge, and merging them along the tree gives one closed
//! curve through every vertex ([`tour`]). Cells of patches that share a side are linked
//! across it, so a connected layout becomes one loop (the paper has one domain; holes and
//! notches of a T-mesh lie between the layout's patches, so the curve traces them). At
//! every turn, a detour of two Hermite curves reaches into the square outside the turn far
//! enough that the scallop holds there ([`corner`]). The curve's straight stretches (along
//! grid lines, across shared sides) and the detours are cut with forward steps that keep
//! the chords within the chordal tolerance; the shared pipeline does the rest (tool axes,
//! lifting, air moves, what cannot be reached).
//!
//! With [`PlanOptions::isfc_plain`] the plain curve the paper improves on is planned
//! instead: no parity repair (an odd last grid line belongs to no cell and is not cut) and
//! no corner detours.
//!
//! Owns: the curve. Must not: choose tool axes or route air moves (the pipeline does).

pub mod cells;
pub mod corner;
pub mod grid;
pub mod layer;
pub mod tour;
pub mod tree;

use self::cells::{Cell, Link, PatchGrid, Vertex, Weights};
use super::draft::{Draft, DraftBuilder, Footprint, SurfacePoint};
use super::isoparametric::{patch_views, predicted, ParamSurface, PatchView, CHORD_SCALLOP_SHARE};
use super::pipeline::Planned;
use super::stepover::FeedDir;
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::geom::{dist_to_segment, Aabb, Point3, Vector3};
use crate::layout::ConnectionKind;
use crate::model::Model;
use serde::{Deserialize, Serialize};

/// The curve before it becomes moves (see [`curve`]).
#[derive(Debug, Clone)]
pub struct Curve {
    pub grids: Vec<PatchGrid>,
    pub vertices: Vec<Vertex>,
    pub cells: Vec<Cell>,
    pub links: Vec<Link>,
    /// The tree's links: indices into `links`; those from `within` on join patches across a
    /// shared side.
    pub tree: Vec<usize>,
    pub within: usize,
    /// Vertex ids of each closed loop, from its start (not repeated at the end).
    pub loops: Vec<Vec<u32>>,
    /// Largest scallop eq. 5 predicts between the grid lines (mm).
    pub predicted_mm: f64,
}

/// What the curve is made of, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct IsfcStats {
    /// Lines `u = const` and `v = const` over all patches, and their crossings.
    pub s_lines: usize,
    pub t_lines: usize,
    pub vertices: usize,
    /// 2 × 2 cells, and the links of the tree (of which across patch sides).
    pub cells: usize,
    pub tree_links: usize,
    pub cross_patch_links: usize,
    /// Cells with a line the parity repair added.
    pub repaired_cells: usize,
    /// Turns with a detour, and of those where the corner needed it to hold the scallop
    /// (elsewhere the detour only rounds the corner).
    pub compensated_corners: usize,
    pub needed_corners: usize,
    /// Closed loops (one per connected part of the layout).
    pub loops: usize,
    /// Grid vertices in no cell (the plain curve's odd lines): not cut.
    pub floating_vertices: usize,
    /// Where the first loop starts (mm).
    pub start_mm: [f64; 3],
}

/// Part of the chordal tolerances the chords aim for (the chord is checked at a few points).
const CHORD_MARGIN: f64 = 0.9;
/// Most halvings of a stretch while meeting the chordal tolerance.
const CHORD_DEPTH: usize = 20;
/// The check point's tolerance, as a share of the scallop (ε of the bisection).
const CHECK_POINT_EPS: f64 = 0.01;
/// Most bisection steps locating the cusp between two balls.
const CUSP_STEPS: usize = 30;
/// The cusp's height is wanted to this share of the scallop: the bisection stops when the
/// cusp's place is known well enough for that (the two balls' profiles cross there with
/// slopes of about `d / 2r` for contacts `d` apart).
const CUSP_HEIGHT_SHARE: f64 = 1e-3;
/// Share of the progress bar the curve takes (the pipeline the rest).
const DRAFT_SHARE: f64 = 0.6;

/// Plans `model` with one closed space-filling curve per connected part of its layout and
/// hands it to the shared pipeline. `progress` receives the fraction done and returns
/// `false` to cancel.
pub fn plan(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Planned> {
    let mut layer = None;
    let mut planned = super::pipeline::plan_with(model, opts, progress, DRAFT_SHARE, |p| {
        let (d, l) = draft_and_layer(model, opts, p)?;
        layer = Some(l);
        Ok(d)
    })?;
    planned.isfc_layer = layer;
    Ok(planned)
}

/// The curve before it becomes moves: grids, vertices, cells, the candidate links, the tree
/// and the loops round it. `progress` receives the fraction done and returns `false` to
/// cancel.
pub fn curve(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Curve> {
    opts.validate()?;
    let np = model.layout.len();
    if np == 0 {
        return Err(Error::InvalidMesh(
            "the model has no patches to machine".into(),
        ));
    }
    let r = opts.tool_radius_mm;
    let plain = opts.isfc_plain;
    let h_target = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
    // Eq. 5 is the small-h form and runs low by about h/2r: ask it for correspondingly less.
    let h_side = h_target / (1.0 + h_target / (2.0 * r));
    let views = patch_views(model);

    // Sides a patch shares with another (0: v = 0, 1: u = 1, 2: v = 1, 3: u = 0).
    let shared = shared_sides(model, &views);
    let mut free = vec![[true; 4]; np];
    for &(a, sa, b, sb) in &shared {
        free[a as usize][sa as usize] = false;
        free[b as usize][sb as usize] = false;
    }

    // 1. The grids and their vertices.
    let mut grids: Vec<PatchGrid> = Vec::with_capacity(np);
    let mut vertices: Vec<Vertex> = Vec::new();
    let mut worst: f64 = 0.0;
    for (p, view) in views.iter().enumerate() {
        let f = free[p];
        let us = grid::lines(view, FeedDir::AlongV, h_side, r, [f[3], f[1]], !plain)?;
        let vs = grid::lines(view, FeedDir::AlongU, h_side, r, [f[0], f[2]], !plain)?;
        worst = worst
            .max(predicted(view, FeedDir::AlongV, &us.at, r))
            .max(predicted(view, FeedDir::AlongU, &vs.at, r));
        let g = PatchGrid {
            patch: p as u32,
            us,
            vs,
            first: vertices.len() as u32,
        };
        for j in 0..g.nv() {
            for i in 0..g.nu() {
                let uv = [g.us.at[i], g.vs.at[j]];
                let (cc, normal) = point(view, uv)?;
                vertices.push(Vertex {
                    patch: p as u32,
                    i: i as u32,
                    j: j as u32,
                    uv,
                    cc,
                    normal,
                });
            }
        }
        grids.push(g);
        if !progress(0.8 * (p + 1) as f64 / np as f64) {
            return Err(Error::Cancelled);
        }
    }

    // 2. Cells and the links that may join them, within patches and across shared sides.
    let cell_list = cells::cells(&grids);
    let first = cells::first_cells(&grids);
    let w = Weights {
        length: opts.isfc_length_weight,
        axis: opts.isfc_axis_weight,
    };
    let mut links = cells::links_within(&grids, &cell_list, &first, &vertices, w);
    let within = links.len();
    for &(a, sa, b, sb) in &shared {
        let (a, b) = (a as usize, b as usize);
        let outer_a = cells::outer_cells(&grids[a], first[a], &cell_list, sa);
        let outer_b = cells::outer_cells(&grids[b], first[b], &cell_list, sb);
        links.extend(cells::links_across(&outer_a, &outer_b, &vertices, w));
    }
    if !progress(0.9) {
        return Err(Error::Cancelled);
    }

    // 3. The tree and the loops round it.
    let tree = tree::kruskal(cell_list.len(), &links);
    let on_free_side = |v: &Vertex| {
        let g = &grids[v.patch as usize];
        let f = free[v.patch as usize];
        (v.j == 0 && f[0])
            || (v.i as usize + 1 == g.nu() && f[1])
            || (v.j as usize + 1 == g.nv() && f[2])
            || (v.i == 0 && f[3])
    };
    // Start on the free boundary where the surface is highest (nearest the safe plane the
    // tool comes down from), the lowest vertex id among equals.
    let start = |ring: &[u32]| -> u32 {
        let pick = |only_free: bool| {
            ring.iter()
                .copied()
                .filter(|&k| !only_free || on_free_side(&vertices[k as usize]))
                .max_by(|&a, &b| {
                    vertices[a as usize]
                        .cc
                        .z
                        .total_cmp(&vertices[b as usize].cc.z)
                        .then(b.cmp(&a))
                })
        };
        pick(true).or_else(|| pick(false)).unwrap_or(ring[0])
    };
    let loops = tour::loops(vertices.len(), &cell_list, &links, &tree, &start)?;
    Ok(Curve {
        grids,
        vertices,
        cells: cell_list,
        links,
        tree,
        within,
        loops,
        predicted_mm: worst,
    })
}

/// The curve as a draft for the pipeline.
pub fn draft(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Draft> {
    draft_and_layer(model, opts, progress).map(|(d, _)| d)
}

/// The curve as a draft for the pipeline, and its cells and tree as drawn.
fn draft_and_layer(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<(Draft, layer::Layer)> {
    let kept = curve(model, opts, &mut |f| progress(0.5 * f))?;
    // The cells and tree as drawn, kept with the plan (the page shows them as a layer).
    let layer = layer::Layer::of(&kept);
    let Curve {
        grids,
        vertices,
        cells: cell_list,
        tree,
        within,
        loops,
        predicted_mm,
        ..
    } = kept;
    let r = opts.tool_radius_mm;
    let plain = opts.isfc_plain;
    let h_target = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
    let views = patch_views(model);
    let mut worst = predicted_mm;

    // 4. Moves: each loop from its start round and back, with the corner detours.
    let mut stats = IsfcStats {
        s_lines: grids.iter().map(|g| g.nu()).sum(),
        t_lines: grids.iter().map(|g| g.nv()).sum(),
        vertices: vertices.len(),
        cells: cell_list.len(),
        tree_links: tree.len(),
        cross_patch_links: tree.iter().filter(|&&k| k >= within).count(),
        repaired_cells: repaired(&grids, &cell_list),
        loops: loops.len(),
        floating_vertices: vertices.len() - 4 * cell_list.len(),
        start_mm: loops
            .first()
            .map(|l| {
                let c = vertices[l[0] as usize].cc;
                [c.x, c.y, c.z]
            })
            .unwrap_or_default(),
        ..IsfcStats::default()
    };
    let footprints: Vec<Footprint> = vertices.iter().map(|v| footprint(&grids, v)).collect();
    let ctx = Ctx {
        views: &views,
        vertices: &vertices,
        grids: &grids,
        r,
        chordal: CHORD_MARGIN * opts.chordal_mm,
        overcut: CHORD_MARGIN * opts.overcut_mm(),
    };
    let mut out = DraftBuilder::new(model, opts);
    let total: usize = loops.iter().map(|l| l.len()).sum::<usize>().max(1);
    let mut done = 0usize;
    for ring in &loops {
        let n = ring.len();
        let s0 = ctx.surface_point(ring[0], ctx.vertices[ring[0] as usize].uv)?;
        out.approach(&s0, 0, footprints[ring[0] as usize]);
        for k in 0..n {
            let (q, h) = (ring[k], ring[(k + 1) % n]);
            if !plain {
                let g = ring[(k + n - 1) % n];
                if let Some(d) = ctx.turn_detour(g, q, h, h_target)? {
                    stats.compensated_corners += 1;
                    if d.h_pq_mm > h_target {
                        stats.needed_corners += 1;
                    }
                    worst = worst.max(d.h_pk_mm);
                    let patch = ctx.vertices[q as usize].patch;
                    for curve in [d.out, d.back] {
                        ctx.emit_curve(&mut out, patch, &|t| curve.at(t), Footprint::NONE)?;
                    }
                }
            }
            ctx.emit_edge(&mut out, q, h, footprints[h as usize])?;
            done += 1;
            if done % 64 == 0 && !progress(0.5 + 0.5 * done as f64 / total as f64) {
                return Err(Error::Cancelled);
            }
        }
    }
    let forced = loops.len().saturating_sub(1);
    let mut d = out.finish("isfc", Vec::new(), worst, forced);
    d.isfc = Some(stats);
    Ok((d, layer))
}

/// Samples along a patch side, and golden-section steps after them, finding the point of
/// the side facing a point of the neighbouring patch's side.
const SIDE_SEARCH_SAMPLES: usize = 32;
const SIDE_SEARCH_STEPS: usize = 40;

/// Samples along a patch side deciding whether it lies on another patch's side.
const SIDE_SAMPLES: usize = 9;
/// Samples of the other side's curve it is compared with.
const SIDE_CURVE_SAMPLES: usize = 64;
/// Distance (as a share of the model's size) within which two sides coincide.
const SIDE_MATCH_REL: f64 = 1e-6;

/// The sides two patches share, as `(patch, side, patch, side)` (sides 0: `v = 0`,
/// 1: `u = 1`, 2: `v = 1`, 3: `u = 0`): the layout's side connections, and sides that lie on
/// each other in space although the layout has a strip of zero width between them (a
/// crease's repeated knots), wholly or in part.
pub(crate) fn shared_sides(model: &Model, views: &[PatchView]) -> Vec<(u32, u8, u32, u8)> {
    let mut out: Vec<(u32, u8, u32, u8)> = model
        .layout
        .connections
        .iter()
        .filter_map(|c| match (c.kind, c.sides) {
            (ConnectionKind::Boundary, Some((sa, sb))) => Some((c.a, sa, c.b, sb)),
            _ => None,
        })
        .collect();
    let bbox = model.surface.bbox();
    let size = (0..3)
        .map(|k| bbox.max[k] - bbox.min[k])
        .fold(0.0, f64::max);
    let tol = SIDE_MATCH_REL * size.max(1.0);
    // Each side as a polyline, with its box and its longest chord.
    let curves: Vec<[Vec<Point3>; 4]> = views
        .iter()
        .map(|v| {
            [0u8, 1, 2, 3].map(|side| {
                (0..=SIDE_CURVE_SAMPLES)
                    .map(|k| {
                        let [u, w] =
                            crate::layout::side_uv(side, k as f64 / SIDE_CURVE_SAMPLES as f64);
                        v.subs(u, w)
                    })
                    .collect()
            })
        })
        .collect();
    let boxes: Vec<[(Aabb, f64); 4]> = curves
        .iter()
        .map(|sides| {
            std::array::from_fn(|k| {
                let mut b = Aabb::empty();
                sides[k].iter().for_each(|p| b.grow(p));
                let chord = sides[k]
                    .windows(2)
                    .map(|w| (w[1] - w[0]).norm())
                    .fold(0.0, f64::max);
                (b, chord)
            })
        })
        .collect();
    let near_curve = |p: &Point3, c: &[Point3], within: f64| {
        c.windows(2)
            .any(|w| dist_to_segment(p, &w[0], &w[1]) <= within)
    };
    let np = views.len();
    for a in 0..np {
        for b in a + 1..np {
            for sa in 0..4u8 {
                for sb in 0..4u8 {
                    // Interior samples of a's side lying on b's side (the chords of b's
                    // polyline are within a twentieth of a chord of it): only where the
                    // sides' boxes come that close.
                    let ((box_a, chord_a), (box_b, chord_b)) =
                        (&boxes[a][sa as usize], &boxes[b][sb as usize]);
                    let within = tol + 0.05 * chord_a.max(*chord_b);
                    if (0..3).any(|k| {
                        box_a.min[k] > box_b.max[k] + within || box_b.min[k] > box_a.max[k] + within
                    }) {
                        continue;
                    }
                    if out.iter().any(|&(x, xs, y, ys)| {
                        (x as usize, xs, y as usize, ys) == (a, sa, b, sb)
                            || (x as usize, xs, y as usize, ys) == (b, sb, a, sa)
                    }) {
                        continue;
                    }
                    let ca = &curves[a][sa as usize];
                    let cb = &curves[b][sb as usize];
                    let step = SIDE_CURVE_SAMPLES / (SIDE_SAMPLES + 1);
                    let on = (1..=SIDE_SAMPLES)
                        .filter(|&k| near_curve(&ca[k * step], cb, within))
                        .count();
                    let back = (1..=SIDE_SAMPLES)
                        .filter(|&k| near_curve(&cb[k * step], ca, within))
                        .count();
                    if on >= 2 && back >= 2 {
                        out.push((a as u32, sa, b as u32, sb));
                    }
                }
            }
        }
    }
    out
}

/// Cells with a corner on a line the parity repair added.
fn repaired(grids: &[PatchGrid], cells: &[Cell]) -> usize {
    cells
        .iter()
        .filter(|c| {
            let g = &grids[c.patch as usize];
            let (i0, j0) = (2 * c.ci as usize, 2 * c.cj as usize);
            g.us.added.is_some_and(|k| k == i0 || k == i0 + 1)
                || g.vs.added.is_some_and(|k| k == j0 || k == j0 + 1)
        })
        .count()
}

/// The patch area a grid vertex stands for: half-way to the neighbouring lines, to the side
/// beyond the outermost ones.
fn footprint(grids: &[PatchGrid], v: &Vertex) -> Footprint {
    let g = &grids[v.patch as usize];
    let span = |at: &[f64], k: usize| {
        let lo = if k == 0 {
            0.0
        } else {
            0.5 * (at[k - 1] + at[k])
        };
        let hi = if k + 1 == at.len() {
            1.0
        } else {
            0.5 * (at[k] + at[k + 1])
        };
        (lo, hi)
    };
    let (u0, u1) = span(&g.us.at, v.i as usize);
    let (v0, v1) = span(&g.vs.at, v.j as usize);
    Footprint {
        patch: v.patch,
        rect: [u0, u1, v0, v1],
    }
}

/// Contact point and tool-side normal at patch parameters `uv`.
pub(crate) fn point(view: &PatchView, uv: [f64; 2]) -> Result<(Point3, Vector3)> {
    let (u, v) = (uv[0].clamp(0.0, 1.0), uv[1].clamp(0.0, 1.0));
    let (p, n) = view.point_normal(u, v);
    let n = n.ok_or_else(|| Error::Degenerate {
        location: format!("{} at (u, v) = ({u:.6}, {v:.6})", view.label()),
        message: "the surface has no tangent plane here or nearby".into(),
    })?;
    Ok((p, n))
}

/// Material left (mm) along the unit normal `n` from `q` by a ball of radius `r` centred at
/// `c`; infinity if the normal line misses it, negative if `q` is inside.
fn left_by_ball(q: &Point3, n: &Vector3, c: &Point3, r: f64) -> f64 {
    let d = c - q;
    let b = d.dot(n);
    let disc = b * b - (d.norm_squared() - r * r);
    if disc < 0.0 {
        f64::INFINITY
    } else {
        b - disc.sqrt()
    }
}

/// What placing moves needs.
struct Ctx<'a> {
    views: &'a [PatchView<'a>],
    vertices: &'a [Vertex],
    grids: &'a [PatchGrid],
    r: f64,
    /// Chord limits of the contact curve and of the ball-centre curve (mm).
    chordal: f64,
    overcut: f64,
}

impl Ctx<'_> {
    /// The surface point of patch `patch` at `uv`.
    fn surface_point(&self, vertex_or_patch: u32, uv: [f64; 2]) -> Result<SurfacePoint> {
        let patch = self.vertices[vertex_or_patch as usize].patch;
        self.patch_point(patch, uv)
    }

    fn patch_point(&self, patch: u32, uv: [f64; 2]) -> Result<SurfacePoint> {
        let (cc, normal) = point(&self.views[patch as usize], uv)?;
        Ok(SurfacePoint {
            patch,
            uv: [uv[0].clamp(0.0, 1.0), uv[1].clamp(0.0, 1.0)],
            cc,
            normal,
        })
    }

    /// Feed moves along `curve` (patch parameters, `t` from 0 to 1) on `patch`, from just
    /// after its start to its end, with forward steps keeping the chords of the contact and
    /// ball-centre curves within their limits; the last move stands for `last`.
    fn emit_curve(
        &self,
        out: &mut DraftBuilder,
        patch: u32,
        curve: &dyn Fn(f64) -> [f64; 2],
        last: Footprint,
    ) -> Result<()> {
        let at = |t: f64| self.patch_point(patch, curve(t));
        let (pa, pb) = (at(0.0)?, at(1.0)?);
        let mut points = Vec::new();
        self.refine(&at, (0.0, &pa), (1.0, &pb), None, CHORD_DEPTH, &mut points)?;
        points.push(pb);
        let n = points.len();
        for (k, p) in points.iter().enumerate() {
            out.feed(p, 0, if k + 1 == n { last } else { Footprint::NONE });
        }
        Ok(())
    }

    /// Adds to `points`, in order, the points strictly between `a` and `b` splitting the
    /// stretch until every piece's chords are within the limits (or `depth` halvings are
    /// used up). `mid` is the middle point if known; every point evaluated is used.
    fn refine(
        &self,
        at: &dyn Fn(f64) -> Result<SurfacePoint>,
        (a, pa): (f64, &SurfacePoint),
        (b, pb): (f64, &SurfacePoint),
        mid: Option<SurfacePoint>,
        depth: usize,
        points: &mut Vec<SurfacePoint>,
    ) -> Result<()> {
        if depth == 0 {
            return Ok(());
        }
        let cl = |p: &SurfacePoint| p.cc + p.normal * self.r;
        let off = |pm: &SurfacePoint| {
            dist_to_segment(&pm.cc, &pa.cc, &pb.cc) > self.chordal
                || dist_to_segment(&cl(pm), &cl(pa), &cl(pb)) > self.overcut
        };
        let m = 0.5 * (a + b);
        let pm = match mid {
            Some(p) => p,
            None => at(m)?,
        };
        // The middle, then the quarters (kept as the halves' middles).
        let mut quarters = [None, None];
        let mut fine = !off(&pm);
        for (k, s) in [0.25, 0.75].into_iter().enumerate() {
            if !fine {
                break;
            }
            let q = at(a + (b - a) * s)?;
            fine = !off(&q);
            quarters[k] = Some(q);
        }
        if fine {
            return Ok(());
        }
        let [q1, q3] = quarters;
        self.refine(at, (a, pa), (m, &pm), q1, depth - 1, points)?;
        points.push(pm);
        self.refine(at, (m, &pm), (b, pb), q3, depth - 1, points)
    }

    /// Moves from grid vertex `a` to grid vertex `b` (the tool is at `a`): along the grid
    /// line within a patch, or across the side two patches share, through the side.
    fn emit_edge(&self, out: &mut DraftBuilder, a: u32, b: u32, last: Footprint) -> Result<()> {
        let (va, vb) = (&self.vertices[a as usize], &self.vertices[b as usize]);
        if va.patch == vb.patch {
            return self.emit_line(out, va.patch, va.uv, vb.uv, last);
        }
        // Across a shared side: from `a` to its foot on the side nearest `b`, then from the
        // foot of `b` on its patch's side nearest `a` to `b`.
        let fa = self.foot(va, &vb.cc)?;
        let fb = self.foot(vb, &va.cc)?;
        self.emit_line(out, va.patch, va.uv, fa, Footprint::NONE)?;
        // The feet need not meet (the grids of the two patches differ): along the side
        // from `a`'s foot to the point of it facing `b`'s, not straight across the surface.
        let side_b = self.patch_point(vb.patch, fb)?.cc;
        let facing = self.along_side(va.patch, fa, &side_b)?;
        self.emit_line(out, va.patch, fa, facing, Footprint::NONE)?;
        self.emit_line(out, vb.patch, fb, vb.uv, last)
    }

    /// [`Ctx::emit_curve`] along the straight parameter line from `x` to `y`.
    fn emit_line(
        &self,
        out: &mut DraftBuilder,
        patch: u32,
        x: [f64; 2],
        y: [f64; 2],
        last: Footprint,
    ) -> Result<()> {
        let line = move |t: f64| [x[0] + (y[0] - x[0]) * t, x[1] + (y[1] - x[1]) * t];
        self.emit_curve(out, patch, &line, last)
    }

    /// The point of `v`'s patch side straight out from `v` (along its grid line) that lies
    /// nearest `towards` (mm).
    fn foot(&self, v: &Vertex, towards: &Point3) -> Result<[f64; 2]> {
        let [u, w] = v.uv;
        let mut best: Option<(f64, [f64; 2])> = None;
        for f in [[u, 0.0], [1.0, w], [u, 1.0], [0.0, w]] {
            let p = self.patch_point(v.patch, f)?;
            let d = (p.cc - towards).norm();
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, f));
            }
        }
        Ok(best.expect("four sides").1)
    }

    /// The point of the patch side `foot` lies on nearest `target`: samples along the side,
    /// then golden-section steps between the nearest sample's neighbours.
    fn along_side(&self, patch: u32, foot: [f64; 2], target: &Point3) -> Result<[f64; 2]> {
        // The coordinate that runs along the side.
        let k = usize::from(foot[1] != 0.0 && foot[1] != 1.0);
        let at = |t: f64| {
            let mut q = foot;
            q[k] = t;
            q
        };
        let dist =
            |t: f64| -> Result<f64> { Ok((self.patch_point(patch, at(t))?.cc - target).norm()) };
        let n = SIDE_SEARCH_SAMPLES;
        let mut best = (f64::INFINITY, 0);
        for i in 0..=n {
            let d = dist(i as f64 / n as f64)?;
            if d < best.0 {
                best = (d, i);
            }
        }
        let (mut lo, mut hi) = (
            best.1.saturating_sub(1) as f64 / n as f64,
            (best.1 + 1).min(n) as f64 / n as f64,
        );
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..SIDE_SEARCH_STEPS {
            let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if dist(a)? < dist(b)? {
                hi = b;
            } else {
                lo = a;
            }
        }
        Ok(at(0.5 * (lo + hi)))
    }

    /// The detour at `q` if the curve turns there (coming from `g`, leaving to `h`, all of
    /// one patch and a grid step apart) and the square outside the turn is in the grid.
    fn turn_detour(&self, g: u32, q: u32, h: u32, scallop: f64) -> Result<Option<corner::Detour>> {
        let (vg, vq, vh) = (
            &self.vertices[g as usize],
            &self.vertices[q as usize],
            &self.vertices[h as usize],
        );
        if vg.patch != vq.patch || vh.patch != vq.patch {
            return Ok(None);
        }
        let idx = |v: &Vertex| [v.i as i64, v.j as i64];
        let (ig, iq, ih) = (idx(vg), idx(vq), idx(vh));
        let e_in = [iq[0] - ig[0], iq[1] - ig[1]];
        let e_out = [ih[0] - iq[0], ih[1] - iq[1]];
        let unit = |e: [i64; 2]| e[0].abs() + e[1].abs() == 1;
        if !(unit(e_in) && unit(e_out)) || e_in[0] * e_out[0] + e_in[1] * e_out[1] != 0 {
            return Ok(None);
        }
        let ip = [iq[0] + e_in[0] - e_out[0], iq[1] + e_in[1] - e_out[1]];
        let grid = &self.grids[vq.patch as usize];
        if ip[0] < 0 || ip[1] < 0 || ip[0] as usize >= grid.nu() || ip[1] as usize >= grid.nv() {
            return Ok(None);
        }
        let p = [grid.us.at[ip[0] as usize], grid.vs.at[ip[1] as usize]];
        let view = &self.views[vq.patch as usize];
        let r = self.r;
        let mut failed: Option<Error> = None;
        let mut cusp = |x: [f64; 2], y: [f64; 2]| -> f64 {
            match cusp_between(view, x, y, r, CUSP_HEIGHT_SHARE * scallop) {
                Ok(c) => c,
                Err(e) => {
                    failed.get_or_insert(e);
                    f64::INFINITY
                }
            }
        };
        let d = corner::detour(
            vg.uv,
            vq.uv,
            vh.uv,
            p,
            scallop,
            CHECK_POINT_EPS * scallop,
            &mut cusp,
        );
        match failed {
            Some(e) => Err(e),
            None => Ok(Some(d)),
        }
    }
}

/// The cusp (mm) between balls touching the surface at patch parameters `x` and `y`: the
/// most material the two leave on the straight parameter line between them, to within about
/// `tol_mm`.
pub fn cusp_between(
    view: &PatchView,
    x: [f64; 2],
    y: [f64; 2],
    r: f64,
    tol_mm: f64,
) -> Result<f64> {
    let (px, nx) = point(view, x)?;
    let (py, ny) = point(view, y)?;
    let (cx, cy) = (px + nx * r, py + ny * r);
    // Bisect until the interval is shorter than `tol_mm` over the profiles' slope.
    let d = (py - px).norm();
    let slope = (d / (2.0 * r)).max(f64::EPSILON);
    let enough = tol_mm / slope / d.max(f64::MIN_POSITIVE);
    let left = |s: f64| -> Result<(f64, f64)> {
        let (q, n) = point(view, [x[0] + (y[0] - x[0]) * s, x[1] + (y[1] - x[1]) * s])?;
        Ok((left_by_ball(&q, &n, &cx, r), left_by_ball(&q, &n, &cy, r)))
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut best: f64 = 0.0;
    for _ in 0..CUSP_STEPS {
        if hi - lo < enough {
            break;
        }
        let mid = 0.5 * (lo + hi);
        let (a, b) = left(mid)?;
        let m = a.min(b);
        if m.is_finite() {
            best = best.max(m);
        }
        if a < b {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(best)
}
