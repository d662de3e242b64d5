//! Iso-planar slicing with CL-surface deformation (Yuan & Shao 2012): parallel planes, the
//! cut every shop knows, spaced so that the scallop stays near the limit on steep and
//! concave areas too.
//!
//! The ball-centre (CL) surface is meshed from the exact limit surface ([`clmesh`]) and
//! deformed along the planes' normal so that constant spacing in the deformed space means
//! the spacing the scallop allows in the original ([`deform`]); the deformed mesh is sliced by planes at the flat-floor spacing `d_w`
//! ([`slice`]), every slice point kept as the mesh edge and parameter it lies at, so that
//! it maps back exactly; its contact point is then evaluated on the surface at that
//! parameter. Pieces of a slice meeting at a patch seam are joined; the pieces are cut in a
//! zig-zag over the planes, joined on the surface where the next one starts close by,
//! else with a retraction. With [`PlanOptions::isoplanar_deform`] off the planes are
//! spaced `d_w` apart in plan view (the constant-spacing baseline). Where the cusp
//! predicted between neighbouring passes (eq. 5 from the contact points' distance and the
//! curvature across) would exceed the scallop, a pass half-way between is added over that
//! stretch (`added_planes`), up to [`MAX_SPLITS`] times; last, a pass runs along the free
//! boundary, which the planes' last passes may end short of where it is slanted or curved,
//! and one along each concave crease's groove ([`crease`]; convex creases are pivot strips
//! of the CL mesh, see [`clmesh`]).
//!
//! The shared pipeline does the rest: tool axes (the project's collision-free axis, or the
//! paper's normal with [`PlanOptions::lead_deg`]), lifting balls clear of creases and
//! concave spots tighter than the ball, air moves, what cannot be reached.
//!
//! Owns: the slices and their order. Must not: choose tool axes or route air moves.

pub mod clmesh;
pub mod crease;
pub mod deform;
pub mod slice;

use self::clmesh::ClMesh;
use self::deform::{Deformation, Frame, RatioForm};
use super::draft::{Draft, DraftBuilder, Footprint, SurfacePoint};
use super::pipeline::Planned;
use super::stepover;
use super::PlanOptions;
use crate::error::{Error, Result};
use crate::geom::{dist_to_segment, nearest_on_segment, Aabb, Point3, Vector3};
use crate::model::Model;
use crate::surface::{DiffGeom, SurfaceDerivs};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Share of the scallop reserved for the material the straight moves leave over concave
/// stretches (as the other planners reserve it).
const CHORD_SCALLOP_SHARE: f64 = 0.15;
/// Most slabs of `x` the deformation ratio is taken over.
const MAX_SLABS: usize = 4096;
/// Narrowest slab, as a share of the flat-floor slice spacing.
const SLAB_SHARE: f64 = 0.25;
/// Pass points closer than this share of the slice spacing to the last one checked are not
/// checked for the cusp beside them (their neighbours' cusps stand for theirs).
const CHECK_EVERY_SHARE: f64 = 0.5;
/// How far the neighbouring pass is looked for, in flat-floor spacings.
const CHECK_REACH_SPACINGS: f64 = 3.0;
/// Most halvings of a stretch between two slice points while meeting the chordal tolerance.
const CHORD_DEPTH: usize = 12;
/// Slice ends at patch seams closer than this share of the slice spacing are joined.
const SEAM_SHARE: f64 = 0.5;
/// Pieces are joined on the surface (a link) when the next starts within this many slice
/// spacings of where the last ended, on the same patch; else the tool retracts.
const LINK_SPACINGS: f64 = 3.0;
/// Cosine of the angle from square to the feed within which a neighbouring pass counts as
/// beside a point (60°).
const BESIDE_COS: f64 = 0.5;
/// Relative widening of a [`SegmentIndex`] query's window along its axis, for rounding.
const SEGMENT_WINDOW_SLACK: f64 = 1e-9;
/// Most times the planes between two neighbours are halved where the predicted cusp is
/// over the scallop.
pub const MAX_SPLITS: usize = 3;
/// Mesh edges whose extent in x is below this share of their length are not taken as
/// secants for the deformation ratio (they run along a plane; an edge from a point where the
/// surface faces along x spans about half its angle, a few hundredths).
const SECANT_MIN_DX: f64 = 1e-3;
/// A vertex of a side listed as shared lies on the other side when within this many chordal
/// tolerances of its polyline of contact points (which strays from the curve by up to one).
const SHARED_SIDE_CHORDALS: f64 = 4.0;
/// Patch corners closer than this share of the model's diagonal are the same point.
const BOUNDARY_JOIN_REL: f64 = 1e-7;
/// Share of the overcut a thinned chord may leave at the slice points it passes over: the
/// points lie only a few per chord, and midway between them the chord dips further
/// (keycap-concave, r 0.5 mm, h 0.005 mm: 0.0027 mm cut in with the whole 0.002 mm allowed
/// at the points, 0.0016 mm with half).
const THIN_SHARE: f64 = 0.5;
/// The same share for the points added between neighbours: where the mesh is coarse the
/// neighbours lie far apart and a chord checked at a few points dips deeper between them
/// (keycap-concave at those settings: 0.00100 mm cut in with the whole allowed, 0.00055
/// with half).
const SPLIT_SHARE: f64 = 0.5;
/// Where neighbouring slice points lie farther apart than this many flat spacings, the chord
/// over them is checked against the curve every so far (see [`Emit::split`]), at most
/// [`MAX_GAP_CHECKS`] times per gap.
const GAP_CHECK_SPACINGS: f64 = 0.5;
const MAX_GAP_CHECKS: usize = 256;
/// Longest CL-mesh cell side, in flat spacings, however gently the surface curves: the
/// deformation ratio is taken at the mesh's vertices and over its edges.
const MESH_CELL_SPACINGS: f64 = 1.0;
/// Most slice points one chord may stand for when thinning.
const THIN_LOOKAHEAD: usize = 64;
/// How far on from the plane being cut (in slice steps) a piece that starts close enough
/// to be joined on the surface is cut next: from a plane of the even spacing, the next one
/// and those added before it (from an added plane, a step on from it). Two steps gave
/// Bike.tsm 150 retractions where one gave 203, but the head 2.7 % longer machining and
/// keycap-concave 3 more retractions; the plane alone: 364.
const NEAR_PLANES_STEPS: f64 = 1.01;
/// Share of the chord limits (the smaller of the overcut and the scallop's share) within
/// which the slice points' mesh chords must pass for the points between to be left out
/// before the surface is evaluated (half of it picked 5 % more CL points in the end, the
/// thinning having fewer ends to choose from).
const PRESELECT_SHARE: f64 = 1.0;
/// Share of the slicing's progress the pass checks take (after 0.6 of it).
const CHECK_PROGRESS_SHARE: f64 = 0.3;
/// Share of the progress bar the slicing takes (the pipeline the rest).
const DRAFT_SHARE: f64 = 0.5;

/// What the iso-planar plan is made of, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct IsoplanarStats {
    /// Planes with at least one pass (of them added where the cusp needed it).
    pub planes: usize,
    pub added_planes: usize,
    /// Connected pieces of the slices cut (a plane may cut the surface in several), the
    /// passes along the boundary included.
    pub segments: usize,
    /// Spacing of the planes in the deformed space (mm): `d_w`.
    pub slice_spacing_mm: f64,
    /// The planes' normal in the XY plane (degrees from +X).
    pub slice_angle_deg: f64,
    /// Whether the CL surface was deformed (false: the constant-spacing baseline).
    pub deformed: bool,
    /// Largest deformation ratio.
    pub max_ratio: f64,
    /// Slabs of `x` the ratio is taken over, and their width (mm).
    pub slabs: usize,
    pub slab_mm: f64,
    /// Joins between pieces on the surface, and retractions between them.
    pub links: usize,
    pub retractions: usize,
    /// Largest scallop eq. 5 predicts between neighbouring passes (mm).
    pub max_predicted_scallop_mm: f64,
}

/// A point of a slice: where on the CL mesh (the edge and parameter), its patch parameters,
/// and its place in the deformed frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlicePoint {
    pub hit: slice::Hit,
    pub patch: u32,
    pub uv: [f64; 2],
    /// The point of the CL mesh (mm).
    pub mesh_cl: Point3,
    /// `(x', y, z)` in the deformed slicing frame (mm): `x'` is the plane's value.
    pub deformed: [f64; 3],
}

impl SlicePoint {
    /// Mesh vertex `id` as a point of a pass along vertices (the boundary's, a groove's),
    /// which belongs to no plane: `x'` is +∞.
    fn at_vertex(mesh: &ClMesh, id: u32) -> Self {
        let v = mesh.vertex(id);
        SlicePoint {
            hit: slice::Hit {
                a: id,
                b: id,
                t: 0.0,
            },
            patch: v.patch,
            uv: v.uv,
            mesh_cl: v.cl,
            deformed: [f64::INFINITY, 0.0, 0.0],
        }
    }

    /// Its contact point on the mesh (mm): between those of its edge's ends.
    fn mesh_cc(&self, mesh: &ClMesh) -> Point3 {
        let (a, b) = (mesh.vertex(self.hit.a).cc, mesh.vertex(self.hit.b).cc);
        a + (b - a) * self.hit.t
    }
}

/// A connected piece of one plane's slice.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    /// The plane's `x'` (mm).
    pub plane: f64,
    pub points: Vec<SlicePoint>,
    pub closed: bool,
}

/// The slices before they become moves.
#[derive(Debug, Clone)]
pub struct Slices {
    pub mesh: ClMesh,
    pub frame: Frame,
    pub deformation: Deformation,
    /// `x'` of every mesh vertex (mm; NaN at vertices the mesh lacks).
    pub x_prime: Vec<f64>,
    pub passes: Vec<Pass>,
    pub stats: IsoplanarStats,
}

/// Plans `model` with iso-planar passes and hands them to the shared pipeline. `progress`
/// receives the fraction done and returns `false` to cancel.
pub fn plan(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Planned> {
    super::pipeline::plan_with(model, opts, progress, DRAFT_SHARE, |p| {
        draft(model, opts, p)
    })
}

/// The scallop the planes are spaced for: the request less the chords' share, and eq. 5's
/// small-h form made exact (it runs low by about h / 2r).
pub fn side_scallop(opts: &PlanOptions) -> f64 {
    let h = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
    h / (1.0 + h / (2.0 * opts.tool_radius_mm))
}

/// Derivatives and tool-side fundamental forms of `model` at patch `patch`, `uv`.
/// `None` where it has no normal, and for a pivot strip's `patch` (beyond the layout's).
fn geometry(model: &Model, patch: u32, uv: [f64; 2]) -> Option<(SurfaceDerivs, DiffGeom)> {
    let p = model.layout.patches.get(patch as usize)?;
    let d = p.derivs(&model.surface, uv[0], uv[1]);
    let g = tool_side_geom(model, &d)?;
    Some((d, g))
}

/// The fundamental forms of derivatives `d` of `model`, seen from the tool's side.
fn tool_side_geom(model: &Model, d: &SurfaceDerivs) -> Option<DiffGeom> {
    let g = DiffGeom::try_from_derivs(d)?;
    Some(if model.tool_side() < 0.0 {
        g.flipped()
    } else {
        g
    })
}

/// The deformation ratio at a CL-mesh vertex whose contact point has patch derivatives `d`
/// (from its exact normal and the curvature across the plane through it), and how much
/// denser the curvature there asks the planes to be; `None` where there is no normal.
fn vertex_ratio(
    model: &Model,
    frame: &Frame,
    form: RatioForm,
    r: f64,
    d: &SurfaceDerivs,
) -> Option<(f64, f64)> {
    let g = tool_side_geom(model, d)?;
    let n = [g.normal.dot(&frame.x), g.normal.dot(&frame.y), g.normal.z];
    // Slopes of the CL surface (its normal is the design surface's at the contact), from +Z
    // or, on an underside, from −Z: the plane spacing depends only on how steeply the
    // surface climbs in x.
    let (p, q) = if n[2].abs() > 0.0 {
        (-n[0] / n[2], -n[1] / n[2])
    } else {
        (f64::INFINITY, 0.0)
    };
    let (kx, ky) = match feed_frame(&g.normal, &frame.x) {
        Some((t, across)) => (curvature_along(&g, d, &across), curvature_along(&g, d, &t)),
        None => (0.0, 0.0),
    };
    Some((
        deform::ratio(form, p, q, r, kx, ky),
        deform::curvature_factor(r, kx),
    ))
}

/// The parameter step `(du, dv)` whose tangent `S_u du + S_v dv` is the tangent-plane
/// projection of `dir` (the metric's inverse); zero where the metric degenerates.
fn tangent_params(su: &Vector3, sv: &Vector3, dir: &Vector3) -> [f64; 2] {
    let (e, f, g) = (su.dot(su), su.dot(sv), sv.dot(sv));
    let (a, b) = (su.dot(dir), sv.dot(dir));
    let det = e * g - f * f;
    if !(det > 0.0) {
        return [0.0, 0.0];
    }
    [(g * a - f * b) / det, (e * b - f * a) / det]
}

/// Normal curvature of `g` in the tangent direction closest to `dir` (1/mm).
fn curvature_along(g: &DiffGeom, d: &SurfaceDerivs, dir: &Vector3) -> f64 {
    let [du, dv] = tangent_params(&d.su, &d.sv, dir);
    if du == 0.0 && dv == 0.0 {
        return 0.0;
    }
    g.normal_curvature(du, dv)
}

/// The feed direction on the surface along a plane with normal `x` (unit tangent of the
/// plane's cut), and the direction across it, at a point with unit normal `n`; `None`
/// where the surface faces along `x` (the plane is tangent).
fn feed_frame(n: &Vector3, x: &Vector3) -> Option<(Vector3, Vector3)> {
    let t = n.cross(x).try_normalize(1e-9)?;
    let c = t.cross(n);
    Some((t, c))
}

/// The slices of `model`: the CL mesh, its deformation, and every plane's passes, with the
/// passes added where the cusp needed them. `progress` receives the fraction done.
pub fn slices(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Slices> {
    opts.validate()?;
    if model.layout.is_empty() {
        return Err(Error::InvalidMesh(
            "the model has no patches to machine".into(),
        ));
    }
    let r = opts.tool_radius_mm;
    let h = side_scallop(opts);
    let spacing = deform::flat_spacing(r, h);
    let form = if opts.isoplanar_shear {
        RatioForm::Shear
    } else {
        RatioForm::ExactPlane
    };
    let frame = Frame::new(opts.slice_angle_deg);
    // With the deformation, the ratio at every vertex of the mesh, from its exact normal and
    // the curvature across the plane through it, and how much denser the curvature asks
    // for: `(ratio, need)`, from the derivatives the mesh is made from.
    let mut at_vertex: Vec<Option<(f64, f64)>> = Vec::new();
    let mesh = if opts.isoplanar_deform {
        // The mesh hands over its vertices in order.
        ClMesh::new_with(
            model,
            r,
            opts.chordal_mm,
            MESH_CELL_SPACINGS * spacing,
            &mut |k, d| {
                debug_assert_eq!(k, at_vertex.len(), "vertices in order");
                at_vertex.push(vertex_ratio(model, &frame, form, r, d));
            },
        )?
    } else {
        ClMesh::new(model, r, opts.chordal_mm, MESH_CELL_SPACINGS * spacing)?
    };
    if !progress(0.2) {
        return Err(Error::Cancelled);
    }
    let coords: Vec<[f64; 3]> = mesh
        .vertices
        .iter()
        .map(|v| v.map_or([f64::NAN; 3], |v| frame.coords(&v.cl)))
        .collect();
    let (mut x_lo, mut x_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for c in coords.iter().filter(|c| c[0].is_finite()) {
        x_lo = x_lo.min(c[0]);
        x_hi = x_hi.max(c[0]);
    }
    let deformation = if opts.isoplanar_deform {
        let mut intervals = Vec::with_capacity(4 * mesh.vertices.len());
        let mut need = vec![1.0; mesh.vertices.len()];
        for (k, (v, c)) in mesh.vertices.iter().zip(&coords).enumerate() {
            let (Some(_), Some(&Some((ratio, n)))) = (v, at_vertex.get(k)) else {
                continue;
            };
            need[k] = n;
            intervals.push((c[0], c[0], ratio));
        }
        // The edges as secants: their length across the planes (along the surface gradient
        // of x at their middle) over their extent in x, times the curvature's need.
        if form == RatioForm::ExactPlane {
            let cap = deform::max_ratio();
            for t in &mesh.triangles {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    if a > b {
                        continue;
                    }
                    let (va, vb) = (mesh.vertex(a), mesh.vertex(b));
                    // A pivot strip's edges turn about one contact point, where the balls
                    // leave no cusp between them: the planes need not crowd there.
                    if mesh.strip(va.patch).is_some() {
                        continue;
                    }
                    let (xa, xb) = (coords[a as usize][0], coords[b as usize][0]);
                    let n = (va.normal + vb.normal)
                        .try_normalize(1e-12)
                        .unwrap_or(va.normal);
                    let edge = vb.cl - va.cl;
                    let grad = frame.x - n * frame.x.dot(&n);
                    let across = match grad.try_normalize(1e-9) {
                        Some(c) => edge.dot(&c).abs(),
                        None => edge.norm(),
                    };
                    // Edges (nearly) along a plane cross no planes: left out, where the
                    // ratio would be rounding over rounding.
                    let dx = (xb - xa).abs();
                    if dx <= SECANT_MIN_DX * edge.norm() {
                        continue;
                    }
                    let e = need[a as usize].max(need[b as usize]) * across / dx;
                    intervals.push((xa, xb, e.min(cap)));
                }
            }
        }
        Deformation::new(&intervals, x_lo, x_hi, SLAB_SHARE * spacing, MAX_SLABS)
    } else {
        Deformation::identity(x_lo, x_hi)
    };
    if !progress(0.4) {
        return Err(Error::Cancelled);
    }
    let seam = SEAM_SHARE * spacing;
    let x_prime: Vec<f64> = coords
        .iter()
        .map(|c| {
            if c[0].is_finite() {
                deformation.at(c[0])
            } else {
                f64::NAN
            }
        })
        .collect();
    // Each triangle's range of x'.
    let tri_range: Vec<(f64, f64)> = mesh
        .triangles
        .iter()
        .map(|t| {
            let f = t.map(|v| x_prime[v as usize]);
            (f[0].min(f[1]).min(f[2]), f[0].max(f[1]).max(f[2]))
        })
        .collect();
    let (mut passes, step) = slice_all(&mesh, &frame, &x_prime, &tri_range, spacing, seam);
    if !progress(0.6) {
        return Err(Error::Cancelled);
    }
    let tris_at = |c: f64| -> Vec<u32> {
        tri_range
            .iter()
            .enumerate()
            .filter(|(_, &(a, b))| a < c && b >= c)
            .map(|(i, _)| i as u32)
            .collect()
    };
    let cut = |c: f64, tris: &[u32]| cut_plane(&mesh, &frame, &x_prime, c, tris, seam);
    // What is still too wide: passes added half-way between neighbours over that stretch.
    // Each pass's check points are found once, when the pass is made.
    crate::sort::sort_by(&mut passes, |a, b| a.plane.total_cmp(&b.plane));
    let mut checks: Vec<PassChecks> = passes
        .iter()
        .map(|p| PassChecks::new(model, &mesh, opts, &frame, p))
        .collect();
    let mut added_planes = 0;
    let mut gap = step;
    let mut predicted: f64 = 0.0;
    for round in 0..=MAX_SPLITS {
        // Each round's check reports over its share of 0.6 to 0.9.
        let span = CHECK_PROGRESS_SHARE / (MAX_SPLITS + 1) as f64;
        let lo = 0.6 + span * round as f64;
        let (needs, worst) = too_wide(opts, &frame, &passes, &checks, gap, &mut |f| {
            progress(lo + span * f);
        });
        if !progress(lo + span) {
            return Err(Error::Cancelled);
        }
        predicted = predicted.max(worst);
        if needs.is_empty() {
            break;
        }
        if round == MAX_SPLITS {
            // Left as it is: the report says the predicted scallop is over.
            predicted = predicted.max(needs.iter().map(|n| n.2).fold(0.0, f64::max));
            break;
        }
        gap *= 0.5;
        for (c, near, _) in needs {
            let tris = tris_at(c);
            let mut kept: Vec<Pass> = Vec::new();
            for p in cut(c, &tris) {
                kept.extend(keep_near(p, &near, &frame.y, LINK_SPACINGS * spacing));
            }
            if !kept.is_empty() {
                added_planes += 1;
            }
            checks.extend(
                kept.iter()
                    .map(|p| PassChecks::new(model, &mesh, opts, &frame, p)),
            );
            passes.extend(kept);
        }
        // Sorted by plane, the checks kept beside their passes (a stable sort, as before).
        let mut both: Vec<(Pass, PassChecks)> = passes.into_iter().zip(checks).collect();
        crate::sort::sort_by(&mut both, |a, b| a.0.plane.total_cmp(&b.0.plane));
        (passes, checks) = both.into_iter().unzip();
    }
    let planes = {
        let mut v: Vec<f64> = passes.iter().map(|p| p.plane).collect();
        v.dedup();
        v.len()
    };
    // Last, a pass along the surface's free boundary: where a boundary runs slanted to the
    // planes, or curves, the last pass of a plane ends short of it.
    passes.extend(boundary_passes(
        model,
        &mesh,
        SHARED_SIDE_CHORDALS * opts.chordal_mm,
    ));
    passes.extend(crease::groove_passes(&mesh));
    let max_ratio = deformation.ratio.iter().copied().fold(1.0, f64::max);
    let stats = IsoplanarStats {
        planes,
        added_planes,
        segments: passes.len(),
        slice_spacing_mm: step,
        slice_angle_deg: opts.slice_angle_deg,
        deformed: opts.isoplanar_deform,
        max_ratio,
        slabs: deformation.ratio.len(),
        slab_mm: deformation.step,
        links: 0,
        retractions: 0,
        max_predicted_scallop_mm: predicted,
    };
    Ok(Slices {
        mesh,
        frame,
        deformation,
        x_prime,
        passes,
        stats,
    })
}

/// The passes of every plane over the mesh whose vertices have deformed coordinate
/// `x_prime` (each triangle's range of it `tri_range`): planes evenly over its extent, at
/// most `spacing` apart, the first and last half a spacing in; and their spacing (mm).
fn slice_all(
    mesh: &ClMesh,
    frame: &Frame,
    x_prime: &[f64],
    tri_range: &[(f64, f64)],
    spacing: f64,
    seam: f64,
) -> (Vec<Pass>, f64) {
    let (f_lo, f_hi) = tri_range
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(a, b)| {
            (lo.min(a), hi.max(b))
        });
    let n_planes = ((f_hi - f_lo) / spacing).ceil().max(1.0) as usize;
    let step = (f_hi - f_lo) / n_planes as f64;
    let first = f_lo + 0.5 * step;
    // Triangles per plane: those whose range of x' holds it.
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); n_planes];
    for (i, &(a, b)) in tri_range.iter().enumerate() {
        let k0 = ((a - first) / step).ceil().max(0.0) as usize;
        let k1 = ((b - first) / step).floor();
        if k1 < 0.0 {
            continue;
        }
        for bucket in buckets.iter_mut().take(k1 as usize + 1).skip(k0) {
            bucket.push(i as u32);
        }
    }
    let passes = buckets
        .iter()
        .enumerate()
        .flat_map(|(k, tris)| cut_plane(mesh, frame, x_prime, first + k as f64 * step, tris, seam))
        .collect();
    (passes, step)
}

/// The passes of plane `x' = c` over `tris`, joined at patch seams.
fn cut_plane(
    mesh: &ClMesh,
    frame: &Frame,
    x_prime: &[f64],
    c: f64,
    tris: &[u32],
    seam: f64,
) -> Vec<Pass> {
    let chains = slice::slice(&mesh.triangles, tris, x_prime, c);
    let passes: Vec<Pass> = chains
        .into_iter()
        .map(|ch| Pass {
            plane: c,
            points: ch
                .hits
                .iter()
                .map(|h| slice_point(mesh, frame, c, *h))
                .collect(),
            closed: ch.closed,
        })
        .collect();
    join_at_seams(mesh, passes, seam)
}

/// Passes along the free sides of the layout's patches (sides, or the parts of sides, no
/// other patch shares: a side's vertex farther than `tol` (mm) from every side it is listed
/// as sharing is free), through the CL mesh's vertices on them, joined where sides meet into
/// loops round the boundary and its holes; `plane` is +∞ (they are cut after the planes).
fn boundary_passes(model: &Model, mesh: &ClMesh, tol: f64) -> Vec<Pass> {
    let shared = &mesh.shared;
    let mut passes: Vec<Pass> = Vec::new();
    let layout_patches = &mesh.patches[..mesh.patches.len() - mesh.strips.len()];
    // A side's vertices, in order round its patch.
    let side_vertices = |p: usize, side: u8| -> Vec<u32> {
        let (first, [nu, nv]) = layout_patches[p];
        let ij: Vec<(usize, usize)> = match side {
            0 => (0..=nu).map(|i| (i, 0)).collect(),
            1 => (0..=nv).map(|j| (nu, j)).collect(),
            2 => (0..=nu).rev().map(|i| (i, nv)).collect(),
            _ => (0..=nv).rev().map(|j| (0, j)).collect(),
        };
        ij.into_iter()
            .map(|(i, j)| first + (j * (nu + 1) + i) as u32)
            .filter(|&id| mesh.vertices[id as usize].is_some())
            .collect()
    };
    for p in 0..layout_patches.len() {
        for side in 0..4u8 {
            // The sides this one is listed as sharing (wholly or in part), as polylines of
            // contact points.
            let partners: Vec<Vec<Point3>> = shared
                .iter()
                .filter_map(|&(a, sa, b, sb)| {
                    if (a as usize, sa) == (p, side) {
                        Some((b, sb))
                    } else if (b as usize, sb) == (p, side) {
                        Some((a, sa))
                    } else {
                        None
                    }
                })
                .map(|(q, sq)| {
                    side_vertices(q as usize, sq)
                        .iter()
                        .map(|&id| mesh.vertex(id).cc)
                        .collect()
                })
                .collect();
            let ids = side_vertices(p, side);
            let free: Vec<bool> = ids
                .iter()
                .map(|&id| {
                    let c = mesh.vertex(id).cc;
                    partners.iter().all(|line| {
                        line.windows(2)
                            .all(|w| dist_to_segment(&c, &w[0], &w[1]) > tol)
                    })
                })
                .collect();
            // Each run of free vertices with the shared vertex on either side of it.
            let mut k = 0;
            while k < ids.len() {
                if !free[k] {
                    k += 1;
                    continue;
                }
                let mut end = k;
                while end + 1 < ids.len() && free[end + 1] {
                    end += 1;
                }
                let run = &ids[k.saturating_sub(1)..(end + 2).min(ids.len())];
                let points: Vec<SlicePoint> = run
                    .iter()
                    .map(|&id| SlicePoint::at_vertex(mesh, id))
                    .collect();
                if points.len() >= 2 {
                    passes.push(Pass {
                        plane: f64::INFINITY,
                        points,
                        closed: false,
                    });
                }
                k = end + 1;
            }
        }
    }
    // Join sides whose ends meet (patch corners: the same point, up to rounding), each
    // side keeping its corner: the move from one patch to the next stays at the corner,
    // where the refining, which works within a patch, has nothing to check (from the
    // corner to the next side's second vertex a long cell's chord went unchecked).
    let bbox = model.surface.bbox();
    let tol = BOUNDARY_JOIN_REL * bbox.diagonal().max(1.0);
    let mut out: Vec<Pass> = Vec::new();
    while let Some(mut cur) = passes.pop() {
        loop {
            let tail = cur.points.last().expect("points").mesh_cl;
            let head = cur.points[0].mesh_cl;
            if cur.points.len() > 2 && (tail - head).norm() <= tol {
                cur.closed = true;
                break;
            }
            let next = passes.iter().enumerate().find_map(|(k, q)| {
                let (a, b) = (
                    q.points[0].mesh_cl,
                    q.points.last().expect("points").mesh_cl,
                );
                if (a - tail).norm() <= tol {
                    Some((k, false))
                } else if (b - tail).norm() <= tol {
                    Some((k, true))
                } else {
                    None
                }
            });
            let Some((k, rev)) = next else { break };
            let mut q = passes.swap_remove(k);
            if rev {
                q.points.reverse();
            }
            cur.points.extend(q.points);
        }
        out.push(cur);
    }
    out
}

/// The CL mesh's facets for the tool axis of eq. 12: area-weighted unit normals (on the
/// tool's side) of the facets whose centre lies within `xi` of a ball centre.
struct Facets {
    /// Centre, area (mm²) and unit normal of each facet.
    facets: Vec<(Point3, f64, Vector3)>,
    xi: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl Facets {
    fn new(mesh: &ClMesh, xi: f64) -> Self {
        let xi = xi.max(1e-9);
        let mut facets = Vec::with_capacity(mesh.triangles.len());
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for t in &mesh.triangles {
            let v = t.map(|k| mesh.vertex(k));
            let cross = (v[1].cl - v[0].cl).cross(&(v[2].cl - v[0].cl));
            let side = v[0].normal + v[1].normal + v[2].normal;
            let Some(n) = cross.try_normalize(1e-300) else {
                continue;
            };
            let n = if n.dot(&side) < 0.0 { -n } else { n };
            let centre = Point3::from((v[0].cl.coords + v[1].cl.coords + v[2].cl.coords) / 3.0);
            cells
                .entry([centre.x, centre.y, centre.z].map(|x| (x / xi).floor() as i64))
                .or_default()
                .push(facets.len() as u32);
            facets.push((centre, 0.5 * cross.norm(), n));
        }
        Facets { facets, xi, cells }
    }

    /// Eq. 12 at ball centre `c`: the area-weighted mean normal of the facets within `xi`,
    /// normalised; `None` if there are none.
    fn normal_near(&self, c: &Point3) -> Option<Vector3> {
        let k = [c.x, c.y, c.z].map(|x| (x / self.xi).floor() as i64);
        let mut sum = Vector3::zeros();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &i in self
                        .cells
                        .get(&[k[0] + dx, k[1] + dy, k[2] + dz])
                        .into_iter()
                        .flatten()
                    {
                        let (centre, area, n) = self.facets[i as usize];
                        if (centre - c).norm() <= self.xi {
                            sum += n * area;
                        }
                    }
                }
            }
        }
        sum.try_normalize(1e-300)
    }
}

/// The slice point of `hit` on plane `c`.
fn slice_point(mesh: &ClMesh, frame: &Frame, c: f64, hit: slice::Hit) -> SlicePoint {
    let (a, b) = (mesh.vertex(hit.a), mesh.vertex(hit.b));
    let t = hit.t;
    let lerp = |x: f64, y: f64| x + (y - x) * t;
    let mesh_cl = Point3::from(a.cl.coords + (b.cl.coords - a.cl.coords) * t);
    let f = frame.coords(&mesh_cl);
    SlicePoint {
        hit,
        patch: a.patch,
        uv: [lerp(a.uv[0], b.uv[0]), lerp(a.uv[1], b.uv[1])],
        mesh_cl,
        deformed: [c, f[1], f[2]],
    }
}

/// True if mesh edge `(a, b)` lies on its patch grid's boundary.
fn on_patch_side(mesh: &ClMesh, p: &SlicePoint) -> bool {
    let (first, [nu, nv]) = mesh.patches[p.patch as usize];
    let ij = |v: u32| {
        let k = (v - first) as usize;
        (k % (nu + 1), k / (nu + 1))
    };
    let ((ia, ja), (ib, jb)) = (ij(p.hit.a), ij(p.hit.b));
    (ia == ib && (ia == 0 || ia == nu)) || (ja == jb && (ja == 0 || ja == nv))
}

/// Whether slice point `m` lies within `tol` (mm) of the chord from `a` to `b` (all of one
/// patch), on the CL mesh and in the patch's parameters (its distance from the straight
/// parameter line from `a` to `b`, at that line's parameter speed on the mesh).
fn skippable(a: &SlicePoint, b: &SlicePoint, m: &SlicePoint, tol: f64) -> bool {
    if dist_to_segment(&m.mesh_cl, &a.mesh_cl, &b.mesh_cl) > tol {
        return false;
    }
    let uv = |p: &SlicePoint| Point3::new(p.uv[0], p.uv[1], 0.0);
    let (ua, ub) = (uv(a), uv(b));
    let span = (ub - ua).norm();
    if !(span > 0.0) {
        return false;
    }
    let speed = (b.mesh_cl - a.mesh_cl).norm() / span;
    dist_to_segment(&uv(m), &ua, &ub) * speed <= tol
}

/// Joins open passes of one plane whose ends meet at a patch seam (within `tol` mm; at a
/// concave crease, within `tol` of the two sides' offsets there), into longer passes (a pass
/// whose ends meet becomes closed).
fn join_at_seams(mesh: &ClMesh, mut passes: Vec<Pass>, tol: f64) -> Vec<Pass> {
    let concave = |p: u32, q: u32| {
        mesh.strips
            .iter()
            .any(|s| !s.convex && ((s.a, s.b) == (p, q) || (s.a, s.b) == (q, p)))
    };
    // A slice point's offset from its contact point (on the mesh).
    let offset = |p: &SlicePoint| p.mesh_cl - p.mesh_cc(mesh);
    loop {
        let mut best: Option<(f64, usize, bool, usize, bool)> = None;
        for i in 0..passes.len() {
            if passes[i].closed {
                continue;
            }
            for j in i..passes.len() {
                if passes[j].closed {
                    continue;
                }
                // End of i (tail or head) to end of j.
                for (ei, ej) in [(true, false), (true, true), (false, false), (false, true)] {
                    if i == j && ei == ej {
                        continue;
                    }
                    let end = |p: &Pass, tail: bool| {
                        if tail {
                            *p.points.last().expect("a pass has points")
                        } else {
                            p.points[0]
                        }
                    };
                    let (a, b) = (end(&passes[i], ei), end(&passes[j], ej));
                    if i == j && passes[i].points.len() < 3 {
                        continue;
                    }
                    if !on_patch_side(mesh, &a) || !on_patch_side(mesh, &b) {
                        continue;
                    }
                    if i != j && a.patch == b.patch {
                        continue;
                    }
                    // Across a concave crease the two sides' offsets end apart by the turn of
                    // the normal (the draft ends each at the groove).
                    let mut d = (a.mesh_cl - b.mesh_cl).norm();
                    if d > tol && concave(a.patch, b.patch) {
                        d -= (offset(&a) - offset(&b)).norm();
                    }
                    if d <= tol && best.is_none_or(|x| d < x.0) {
                        best = Some((d, i, ei, j, ej));
                    }
                }
            }
        }
        let Some((_, i, ei, j, ej)) = best else {
            return passes;
        };
        if i == j {
            passes[i].closed = true;
            continue;
        }
        // Orient i to end at the join and j to start there, then append.
        let mut b = passes.swap_remove(j);
        let a = &mut passes[i];
        if !ei {
            a.points.reverse();
        }
        if ej {
            b.points.reverse();
        }
        a.points.extend(b.points);
    }
}

/// Where a pass is checked for the cusp beside it: every point a quarter spacing on from the
/// last checked, and the last; each with its contact point, CL point, the curvature across
/// the feed and the feed direction; and the contact polyline through them. A pivot strip's
/// points are not checked (their balls all touch the crease, which has no curvature across)
/// but their contact points (on the crease) are on the polyline, for the neighbours'
/// checks.
struct PassChecks {
    points: Vec<(Point3, Point3, f64, Vector3)>,
    segments: Vec<(Point3, Point3)>,
}

impl PassChecks {
    fn new(model: &Model, mesh: &ClMesh, opts: &PlanOptions, frame: &Frame, p: &Pass) -> Self {
        let r = opts.tool_radius_mm;
        let h = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
        let mut out = PassChecks {
            points: Vec::new(),
            segments: Vec::new(),
        };
        let (mut last, mut last_cc): (Option<Point3>, Option<Point3>) = (None, None);
        let every = CHECK_EVERY_SHARE * (8.0 * r * h).sqrt();
        let n = p.points.len();
        for (i, s) in p.points.iter().enumerate() {
            // Every point a quarter spacing on from the last checked, and the last.
            if last.is_some_and(|l| (s.mesh_cl - l).norm() < every) && i + 1 < n {
                continue;
            }
            if mesh.strip(s.patch).is_some() {
                let cc = s.mesh_cc(mesh);
                if let Some(a) = last_cc {
                    out.segments.push((a, cc));
                }
                last = Some(s.mesh_cl);
                last_cc = Some(cc);
                continue;
            }
            let Some((d, g)) = geometry(model, s.patch, s.uv) else {
                continue;
            };
            // The pass's own direction here (from its neighbours: a boundary pass's too),
            // and the curvature across it.
            let (before, after) = (
                p.points.get(i.wrapping_sub(1)).unwrap_or(s),
                p.points.get(i + 1).unwrap_or(s),
            );
            let along = after.mesh_cl - before.mesh_cl;
            let along = along - g.normal * along.dot(&g.normal);
            let Some(t) = along
                .try_normalize(1e-12)
                .or_else(|| feed_frame(&g.normal, &frame.x).map(|f| f.0))
            else {
                continue;
            };
            let c = g.normal.cross(&t);
            let kappa = curvature_along(&g, &d, &c);
            out.points.push((g.point, s.mesh_cl, kappa, t));
            if let Some(a) = last_cc {
                out.segments.push((a, g.point));
            }
            last = Some(s.mesh_cl);
            last_cc = Some(g.point);
        }
        out
    }
}

/// Planes to add half-way between neighbours `gap` (mm, deformed) apart, with the CL points
/// near which the cusp eq. 5 predicts from the contact points' distance to the other pass
/// and the curvature across the feed is over the scallop, and the largest predicted there;
/// and the largest predicted where it is not over. `checks` are the passes' own.
#[allow(clippy::type_complexity)]
fn too_wide(
    opts: &PlanOptions,
    frame: &Frame,
    passes: &[Pass],
    checks: &[PassChecks],
    gap: f64,
    tick: &mut dyn FnMut(f64),
) -> (Vec<(f64, Vec<Point3>, f64)>, f64) {
    let r = opts.tool_radius_mm;
    let h = opts.scallop_mm * (1.0 - CHORD_SCALLOP_SHARE);
    // Per plane: the check points of its passes, and the pieces' contact polylines.
    struct Plane {
        c: f64,
        points: Vec<(Point3, Point3, f64, Vector3)>,
        segments: Vec<(Point3, Point3)>,
    }
    debug_assert_eq!(passes.len(), checks.len(), "a pass without its checks");
    let mut planes: Vec<Plane> = Vec::new();
    let n_passes = passes.len().max(1) as f64;
    for (k, (p, check)) in passes.iter().zip(checks).enumerate() {
        tick(0.5 * k as f64 / n_passes);
        if planes.last().is_none_or(|x| x.c != p.plane) {
            planes.push(Plane {
                c: p.plane,
                points: Vec::new(),
                segments: Vec::new(),
            });
        }
        let plane = planes.last_mut().expect("pushed");
        plane.points.extend_from_slice(&check.points);
        plane.segments.extend_from_slice(&check.segments);
    }
    let reach = CHECK_REACH_SPACINGS * (8.0 * r * h).sqrt();
    let mut out = Vec::new();
    let mut worst_ok: f64 = 0.0;
    let n_pairs = planes.len().max(2) as f64 - 1.0;
    for (k, w) in planes.windows(2).enumerate() {
        tick(0.5 + 0.5 * k as f64 / n_pairs);
        let (a, b) = (&w[0], &w[1]);
        if (b.c - a.c - gap).abs() > 1e-6 * gap.max(1.0) {
            continue;
        }
        let (mut near, mut worst) = (Vec::new(), 0.0f64);
        for (from, to) in [(a, b), (b, a)] {
            let index = SegmentIndex::new(&to.segments, &frame.y, reach);
            for &(p, cl, kappa, t) in &from.points {
                // The neighbouring pass beside the point, not beyond its end (where the
                // surface ends before the next plane, nothing lies between them).
                let Some(d) = index.nearest_beside(&p, &t) else {
                    continue;
                };
                let k = kappa.min(stepover::MAX_CONCAVE_RK / r);
                let predicted = stepover::predicted_scallop(d, r, k);
                if predicted > h {
                    near.push(cl);
                    worst = worst.max(predicted);
                } else {
                    worst_ok = worst_ok.max(predicted);
                }
            }
        }
        if !near.is_empty() {
            out.push((0.5 * (a.c + b.c), near, worst));
        }
    }
    (out, worst_ok)
}

/// Nearest-segment queries among segments within a reach: the segments sorted by where they
/// begin along an axis (the planes' horizontal direction, along which passes run), so that
/// a query tests only those whose extent along it comes within the reach of its own.
struct SegmentIndex<'a> {
    segments: &'a [(Point3, Point3)],
    axis: Vector3,
    reach: f64,
    /// Each segment's lowest coordinate along the axis, its index and its box, in order.
    order: Vec<(f64, u32, Aabb)>,
    /// The largest extent of a segment along the axis (mm).
    longest: f64,
}

impl<'a> SegmentIndex<'a> {
    /// The index of `segments` along the unit vector `axis`. A segment is listed as pieces
    /// no longer than half the reach, so that one long segment does not widen every query's
    /// window; a query tests the whole segment of every piece that passes.
    fn new(segments: &'a [(Point3, Point3)], axis: &Vector3, reach: f64) -> Self {
        let reach = reach.max(1e-9);
        let mut longest: f64 = 0.0;
        let mut order: Vec<(f64, u32, Aabb)> = Vec::with_capacity(segments.len());
        for (i, (a, b)) in segments.iter().enumerate() {
            let pieces = ((b - a).norm() / (0.5 * reach)).ceil().max(1.0) as usize;
            for k in 0..pieces {
                let (p, q) = (
                    a + (b - a) * (k as f64 / pieces as f64),
                    a + (b - a) * ((k + 1) as f64 / pieces as f64),
                );
                let (x, y) = (p.coords.dot(axis), q.coords.dot(axis));
                longest = longest.max((x - y).abs());
                let mut bounds = Aabb::empty();
                bounds.grow(&p);
                bounds.grow(&q);
                order.push((x.min(y), i as u32, bounds));
            }
        }
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        SegmentIndex {
            segments,
            axis: *axis,
            reach,
            order,
            longest,
        }
    }

    /// Distance (mm) to the nearest segment, if one lies within the reach.
    fn nearest(&self, q: &Point3) -> Option<f64> {
        self.nearest_where(q, |_, _| true)
    }

    /// Distance (mm) to the nearest point of a segment within the reach that lies beside
    /// `q` as seen along the unit direction `t` (within 60° of square to it).
    fn nearest_beside(&self, q: &Point3, t: &Vector3) -> Option<f64> {
        self.nearest_where(q, |v: &Vector3, d: f64| v.dot(t).abs() <= BESIDE_COS * d)
    }

    /// Distance (mm) to the nearest point of a segment within the reach whose offset from
    /// `q` passes `keep` (given the offset and its length).
    fn nearest_where(&self, q: &Point3, keep: impl Fn(&Vector3, f64) -> bool) -> Option<f64> {
        // A point within the reach lies within it along the axis too; its segment begins at
        // most the longest extent before it (the slack covers rounding). The search runs
        // out from the query both ways along the axis, and the window narrows to the
        // nearest found so far.
        let y = q.coords.dot(&self.axis);
        let slack = SEGMENT_WINDOW_SLACK * (self.reach + y.abs() + self.longest);
        let mid = self.order.partition_point(|e| e.0 < y);
        let mut best: Option<f64> = None;
        let bound = |best: Option<f64>| best.map_or(self.reach, |b| b.min(self.reach)) + slack;
        let test = |e: &(f64, u32, Aabb), best: &mut Option<f64>| {
            let r = bound(*best);
            // Where walls run across the axis many segments share a window: their boxes,
            // grown by the reach, turn most away cheaply.
            let (_, i, bounds) = e;
            if (0..3).any(|k| q[k] < bounds.min[k] - r || q[k] > bounds.max[k] + r) {
                return;
            }
            let (a, b) = self.segments[*i as usize];
            let v = nearest_on_segment(q, &a, &b) - q;
            let d = v.norm();
            // `keep` last: it is asked only of a point that would be the nearest so far.
            if d <= self.reach && best.is_none_or(|x| d < x) && keep(&v, d) {
                *best = Some(d);
            }
        };
        for e in &self.order[mid..] {
            if e.0 > y + bound(best) {
                break;
            }
            test(e, &mut best);
        }
        for e in self.order[..mid].iter().rev() {
            if e.0 < y - bound(best) - self.longest {
                break;
            }
            test(e, &mut best);
        }
        best
    }
}

/// The parts of `pass` whose CL points lie within `reach` (mm) of a point of `near`, as
/// separate open passes.
fn keep_near(pass: Pass, near: &[Point3], axis: &Vector3, reach: f64) -> Vec<Pass> {
    let segments: Vec<(Point3, Point3)> = near.iter().map(|&p| (p, p)).collect();
    let index = SegmentIndex::new(&segments, axis, reach);
    let mut out = Vec::new();
    let mut run: Vec<SlicePoint> = Vec::new();
    for s in &pass.points {
        if index.nearest(&s.mesh_cl).is_some() {
            run.push(*s);
        } else if !run.is_empty() {
            out.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        out.push(run);
    }
    out.into_iter()
        .filter(|r| r.len() >= 2)
        .map(|points| Pass {
            plane: pass.plane,
            points,
            closed: false,
        })
        .collect()
}

/// The passes as a draft for the pipeline.
pub fn draft(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<Draft> {
    let s = slices(model, opts, &mut |f| progress(0.8 * f))?;
    let mut stats = s.stats;
    let r = opts.tool_radius_mm;
    let spacing = deform::flat_spacing(r, side_scallop(opts));
    let mut out = DraftBuilder::new(model, opts);
    let ctx = Emit {
        model,
        mesh: &s.mesh,
        views: super::isoparametric::patch_views(model),
        r,
        chordal: opts.chordal_mm,
        overcut: opts.overcut_mm(),
        leave: CHORD_SCALLOP_SHARE * opts.scallop_mm,
        spacing,
        h: side_scallop(opts),
    };
    let creases = crease::Creases::new(&s.mesh);
    // Zig-zag: plane by plane, the nearest remaining piece of the plane next.
    let mut remaining: Vec<Option<&Pass>> = s.passes.iter().map(Some).collect();
    let mut at: Option<SurfacePoint> = None;
    let mut line = 0u32;
    let mut k = 0;
    while k < remaining.len() {
        let Some(first) = remaining[k] else {
            k += 1;
            continue;
        };
        // The pieces of this plane not yet cut: the one starting nearest the tool next;
        // but first any piece of this plane or of those up to the next even step on that
        // starts close enough to be joined on the surface (pieces added between planes
        // near where one of them ends are cut on the way, not each after a retraction from
        // the far end of its plane).
        let plane = first.plane;
        let window = plane + NEAR_PLANES_STEPS * s.stats.slice_spacing_mm;
        let here = at.map(|a| a.cc);
        let here_cl = at.map(|a| a.cc + a.normal * r);
        let mut best: Option<(f64, usize, bool)> = None;
        let mut near: Option<(f64, usize, bool)> = None;
        for (j, p) in remaining.iter().enumerate().skip(k) {
            let Some(p) = p else { continue };
            if p.plane > window {
                break;
            }
            let ends: &[bool] = if p.closed { &[false] } else { &[false, true] };
            for &rev in ends {
                let e = if rev {
                    p.points.last().expect("points")
                } else {
                    &p.points[0]
                };
                let d = here.map_or(0.0, |h| (e.mesh_cl - h).norm());
                if p.plane == plane && best.is_none_or(|b| d < b.0) {
                    best = Some((d, j, rev));
                }
                if let (Some(a), Some(c)) = (at, here_cl) {
                    let dl = (e.mesh_cl - c).norm();
                    if e.patch == a.patch
                        && dl <= LINK_SPACINGS * spacing
                        && near.is_none_or(|b| dl < b.0)
                    {
                        near = Some((dl, j, rev));
                    }
                }
            }
        }
        let Some((_, j, rev)) = near.or(best) else {
            k += 1;
            continue;
        };
        let pass = remaining[j].take().expect("remaining");
        let mut pts: Vec<SlicePoint> = pass.points.clone();
        if rev {
            pts.reverse();
        }
        if pass.closed {
            // Start a loop where it comes nearest the tool, and close it.
            if let Some(a) = at {
                let s0 = (0..pts.len())
                    .min_by(|&x, &y| {
                        (pts[x].mesh_cl - a.cc)
                            .norm()
                            .total_cmp(&(pts[y].mesh_cl - a.cc).norm())
                    })
                    .unwrap_or(0);
                pts.rotate_left(s0);
            }
            pts.push(pts[0]);
        }
        let pts = creases.trim(model, pts, r);
        let points = ctx.refine(&pts)?;
        let Some(start) = points.first().copied() else {
            continue;
        };
        let joined = at.is_some_and(|a| ctx.can_link(&a, &start));
        if joined {
            ctx.link(&mut out, &at.expect("joined"), &start, line)?;
            stats.links += 1;
        } else {
            if at.is_some() {
                stats.retractions += 1;
            }
            out.approach(&ctx.on_layout(&start), line, ctx.footprint(&points, 0));
        }
        for i in 1..points.len() {
            out.feed(&ctx.on_layout(&points[i]), line, ctx.footprint(&points, i));
        }
        at = points.last().copied();
        line += 1;
    }
    if !progress(1.0) {
        return Err(Error::Cancelled);
    }
    let mut d = out.finish(
        "isoplanar",
        Vec::new(),
        stats.max_predicted_scallop_mm,
        stats.retractions,
    );
    if opts.facet_normal_axis {
        let facets = Facets::new(&s.mesh, r);
        for m in d.toolpath.moves.iter_mut().filter(|m| m.kind.on_surface()) {
            if let Some(n) = facets.normal_near(&m.cl_point) {
                m.tool_axis = n;
            }
        }
    }
    d.isoplanar = Some(stats);
    Ok(d)
}

/// Points of a pass's contact curve and, per gap between neighbours, the curve points its
/// chord was checked against when the gap was made (evaluated once, for the refining and
/// the thinning both).
#[derive(Default)]
struct Curve {
    points: Vec<SurfacePoint>,
    checked: Vec<SurfacePoint>,
    /// Per point, where the checks of the gap it begins start in `checked`.
    starts: Vec<usize>,
}

impl Curve {
    fn push(&mut self, p: SurfacePoint) {
        self.points.push(p);
        self.starts.push(self.checked.len());
    }
}

/// What placing moves needs.
struct Emit<'a> {
    model: &'a Model,
    /// The CL mesh, for its pivot strips.
    mesh: &'a ClMesh,
    views: Vec<super::isoparametric::PatchView<'a>>,
    r: f64,
    chordal: f64,
    overcut: f64,
    /// Most a ball-centre chord may pass above its curve (mm): the scallop's share for
    /// chords.
    leave: f64,
    /// Flat-floor slice spacing (mm).
    spacing: f64,
    /// The scallop the planes were spaced for (mm).
    h: f64,
}

impl Emit<'_> {
    /// The surface point of patch `patch` at `uv` (of a pivot strip: its contact point on
    /// the crease and its turned normal).
    fn point(&self, patch: u32, uv: [f64; 2]) -> Result<SurfacePoint> {
        if let Some(strip) = self.mesh.strip(patch) {
            let (cc, normal) = strip.at(self.model, uv).ok_or_else(|| Error::Degenerate {
                location: format!(
                    "the crease between patches {} and {} at {:.6}",
                    strip.a, strip.b, uv[0]
                ),
                message: "a patch has no tangent plane at the crease".into(),
            })?;
            return Ok(SurfacePoint {
                patch,
                uv: [uv[0].clamp(0.0, 1.0), uv[1].clamp(0.0, 1.0)],
                cc,
                normal,
            });
        }
        let (cc, normal) = super::isfc::point(&self.views[patch as usize], uv)?;
        Ok(SurfacePoint {
            patch,
            uv: [uv[0].clamp(0.0, 1.0), uv[1].clamp(0.0, 1.0)],
            cc,
            normal,
        })
    }

    /// The slice's contact points, with points added between neighbours of one patch until
    /// the chords of the contact and ball-centre curves are within their limits.
    fn refine(&self, pts: &[SlicePoint]) -> Result<Vec<SurfacePoint>> {
        let picked = self.preselect(pts);
        let mut curve = Curve {
            points: Vec::with_capacity(picked.len()),
            checked: Vec::with_capacity(picked.len()),
            starts: Vec::with_capacity(picked.len()),
        };
        let mut prev: Option<SurfacePoint> = None;
        for s in picked.iter().map(|&k| &pts[k]) {
            let p = self.point(s.patch, s.uv)?;
            if let Some(pp) = prev.filter(|pp| pp.patch == p.patch) {
                self.split(&pp, &p, CHORD_DEPTH, &mut curve)?;
            }
            // Drop repeats (a slice through a mesh vertex crosses its edges there twice).
            if curve
                .points
                .last()
                .is_none_or(|q: &SurfacePoint| (q.cc - p.cc).norm() > 1e-9)
            {
                curve.push(p);
            }
            prev = Some(p);
        }
        self.thin(curve)
    }

    /// The slice points worth evaluating on the surface: from each one picked, the farthest
    /// on the same patch (every point between too), at most a flat spacing on, whose chord
    /// passes within [`PRESELECT_SHARE`] of the chord limits of every point between, both
    /// on the mesh (its CL points) and in the patch's parameters (the distance from the
    /// straight parameter line the refining follows, at the chord's parameter speed): no
    /// surface is evaluated. The slice points lie at every mesh edge the plane crosses,
    /// several per chord the thinning keeps; the refining then checks the picked points'
    /// chords against the surface (at their middles, and every half flat spacing on long
    /// ones), which is where the final path's safety comes from.
    fn preselect(&self, pts: &[SlicePoint]) -> Vec<usize> {
        let n = pts.len();
        if n < 3 {
            return (0..n).collect();
        }
        let tol = PRESELECT_SHARE * self.overcut.min(self.leave);
        let reach = self.spacing;
        let mut picked = vec![0];
        let mut i = 0;
        while i + 1 < n {
            let a = &pts[i];
            let mut held = i + 1;
            if pts[held].patch == a.patch {
                for j in i + 2..n.min(i + 1 + THIN_LOOKAHEAD) {
                    let b = &pts[j];
                    if b.patch != a.patch
                        || (b.mesh_cl - a.mesh_cl).norm() > reach
                        || !pts[i + 1..j].iter().all(|m| skippable(a, b, m, tol))
                    {
                        break;
                    }
                    held = j;
                }
            }
            picked.push(held);
            i = held;
        }
        picked
    }

    /// The points of `curve` without those the chords of their neighbours already hold:
    /// from each point kept, the next kept is one whose chord passes within the limits of
    /// every point between, and of the curve points each gap between was checked against
    /// (where a chord dips furthest from the curve), while the next one's does not, found by
    /// doubling then halving: the farthest such point wherever holding does not come back
    /// farther on. The points picked from the slice ([`Emit::preselect`]) and those the
    /// refining added lie denser than the chordal tolerance asks for on gently curved
    /// stretches.
    fn thin(&self, curve: Curve) -> Result<Vec<SurfacePoint>> {
        let Curve {
            points,
            checked,
            mut starts,
        } = curve;
        let n = points.len();
        if n < 3 {
            return Ok(points);
        }
        starts.push(checked.len());
        let holds = |i: usize, j: usize| {
            let (a, b) = (&points[i], &points[j]);
            let on = |m: &SurfacePoint| m.patch == a.patch && self.chord_holds(a, b, m, THIN_SHARE);
            // A gap checked against nothing lies across patches.
            a.patch == b.patch
                && points[i + 1..j].iter().all(on)
                && (i..j).all(|g| starts[g + 1] > starts[g])
                && checked[starts[i]..starts[j]].iter().all(on)
        };
        let mut keep = vec![0];
        let mut i = 0;
        while i + 1 < n {
            // The farthest end that holds, found by doubling the reach and then halving the
            // gap between the last end that held and the first that did not (each test
            // checks every point between, so this is a few tests where one by one was up
            // to THIN_LOOKAHEAD of them).
            let last = (n - 1).min(i + THIN_LOOKAHEAD);
            let (mut held, mut failed) = (i + 1, last + 1);
            let mut step = 1;
            while held < last {
                let j = (held + step).min(last);
                if !holds(i, j) {
                    failed = j;
                    break;
                }
                held = j;
                step *= 2;
            }
            while failed - held > 1 {
                let j = held + (failed - held) / 2;
                if holds(i, j) {
                    held = j;
                } else {
                    failed = j;
                }
            }
            keep.push(held);
            i = held;
        }
        Ok(keep.into_iter().map(|k| points[k]).collect())
    }

    /// Into how many equal parts the chord from `a` to `b` is cut where it is checked
    /// against the curve: two (its middle), more where it is longer than
    /// [`GAP_CHECK_SPACINGS`] flat spacings (at most [`MAX_GAP_CHECKS`]).
    fn gap_checks(&self, a: &SurfacePoint, b: &SurfacePoint) -> usize {
        ((b.cc - a.cc).norm() / (GAP_CHECK_SPACINGS * self.spacing))
            .ceil()
            .clamp(2.0, MAX_GAP_CHECKS as f64) as usize
    }

    /// Adds to `curve` the points strictly between `pa` and `pb` (same patch, `pa` its last)
    /// on the straight parameter line between them that bring the chords within the limits,
    /// and the curve points each chord that holds was checked against.
    fn split(
        &self,
        pa: &SurfacePoint,
        pb: &SurfacePoint,
        depth: usize,
        curve: &mut Curve,
    ) -> Result<()> {
        if depth == 0 {
            return Ok(());
        }
        let (ua, ub) = (pa.uv, pb.uv);
        let at = |t: f64| [ua[0] + t * (ub[0] - ua[0]), ua[1] + t * (ub[1] - ua[1])];
        let pm = self.point(pa.patch, at(0.5))?;
        // The middle, and on a long chord (neighbours far apart where the mesh is coarse)
        // points every half flat spacing: where the curvature is uneven along the chord its
        // middle alone can hold while it dips in elsewhere.
        let parts = self.gap_checks(pa, pb);
        let mark = curve.checked.len();
        curve.checked.push(pm);
        let mut holds = self.chord_holds(pa, pb, &pm, SPLIT_SHARE);
        for k in (1..parts).filter(|&k| 2 * k != parts) {
            if !holds {
                break;
            }
            let q = self.point(pa.patch, at(k as f64 / parts as f64))?;
            curve.checked.push(q);
            holds = self.chord_holds(pa, pb, &q, SPLIT_SHARE);
        }
        if holds {
            return Ok(());
        }
        curve.checked.truncate(mark);
        self.split(pa, &pm, depth - 1, curve)?;
        curve.push(pm);
        self.split(&pm, pb, depth - 1, curve)
    }

    /// Whether the straight move from `a` to `b` passes within the limits of `m`, a point of
    /// the curve it replaces: the contact chord within the chordal tolerance, the ball-centre
    /// chord below the curve (cutting in) by at most `share` of the overcut, above it
    /// (leaving material, which adds to the scallop) by at most `share` of the scallop's
    /// share for chords.
    fn chord_holds(
        &self,
        a: &SurfacePoint,
        b: &SurfacePoint,
        m: &SurfacePoint,
        share: f64,
    ) -> bool {
        let cl = |p: &SurfacePoint| p.cc + p.normal * self.r;
        if dist_to_segment(&m.cc, &a.cc, &b.cc) > self.chordal {
            return false;
        }
        let c = cl(m);
        let off = c - nearest_on_segment(&c, &cl(a), &cl(b));
        let limit = if off.dot(&m.normal) >= 0.0 {
            self.overcut
        } else {
            self.leave
        };
        off.norm() <= share * limit
    }

    /// `p` as the pipeline takes it: a pivot strip's point as its contact point on the
    /// strip's first patch, keeping its turned normal.
    fn on_layout(&self, p: &SurfacePoint) -> SurfacePoint {
        match self.mesh.strip(p.patch) {
            Some(strip) => SurfacePoint {
                patch: strip.a,
                uv: crate::layout::side_uv(strip.side, p.uv[0]),
                ..*p
            },
            None => *p,
        }
    }

    /// Whether the tool may go from `a` to `b` on the surface: the same patch, and close.
    fn can_link(&self, a: &SurfacePoint, b: &SurfacePoint) -> bool {
        a.patch == b.patch && (a.cc - b.cc).norm() <= LINK_SPACINGS * self.spacing
    }

    /// Moves on the surface from `a` to `b` along the straight parameter line, with the
    /// chordal forward steps.
    fn link(
        &self,
        out: &mut DraftBuilder,
        a: &SurfacePoint,
        b: &SurfacePoint,
        line: u32,
    ) -> Result<()> {
        let mut curve = Curve::default();
        self.split(a, b, CHORD_DEPTH, &mut curve)?;
        for p in &curve.points {
            out.link(&self.on_layout(p), line, Footprint::NONE);
        }
        out.link(&self.on_layout(b), line, Footprint::NONE);
        Ok(())
    }

    /// The part of its patch point `i` of a pass stands for: half-way to its neighbours
    /// along the pass and half a side step across, as a rectangle of patch parameters.
    /// A pivot strip's point stands for none (its contact is the crease, a line).
    fn footprint(&self, pts: &[SurfacePoint], i: usize) -> Footprint {
        let p = &pts[i];
        let Some(patch) = self.model.layout.patches.get(p.patch as usize) else {
            return Footprint::NONE;
        };
        // First derivatives are all it takes (the same as those of `Patch::derivs`).
        let (_, su, sv) = patch.first_derivs(&self.model.surface, p.uv[0], p.uv[1]);
        let Some(normal) = crate::surface::diffgeom::unit_normal(&su, &sv) else {
            return Footprint::NONE;
        };
        let same = |j: Option<usize>| j.and_then(|j| pts.get(j)).filter(|q| q.patch == p.patch);
        let (prev, next) = (same(i.checked_sub(1)), same(Some(i + 1)));
        let half = |q: Option<&SurfacePoint>| {
            q.map(|q| [0.5 * (q.uv[0] - p.uv[0]), 0.5 * (q.uv[1] - p.uv[1])])
        };
        let (a, b) = match (half(prev), half(next)) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => (a, [-a[0], -a[1]]),
            (None, Some(b)) => ([-b[0], -b[1]], b),
            (None, None) => ([0.0; 2], [0.0; 2]),
        };
        // Across: half the allowed side step, in parameters (the metric's inverse).
        let along = su * (b[0] - a[0]) + sv * (b[1] - a[1]);
        let across = normal
            .cross(&along)
            .try_normalize(1e-12)
            .unwrap_or_else(|| su.normalize());
        let step = 0.5 * (8.0 * self.r * self.h).sqrt();
        let c = tangent_params(&su, &sv, &(across * step));
        let mut lo = p.uv;
        let mut hi = p.uv;
        for corner in [a, b] {
            for s in [-1.0, 1.0] {
                for k in 0..2 {
                    let v = p.uv[k] + corner[k] + s * c[k];
                    lo[k] = lo[k].min(v);
                    hi[k] = hi[k].max(v);
                }
            }
        }
        Footprint {
            patch: p.patch,
            rect: [
                lo[0].max(0.0),
                hi[0].min(1.0),
                lo[1].max(0.0),
                hi[1].min(1.0),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::samples;

    /// A boundary pass crosses from one patch to the next only at their common corner: the
    /// refining checks chords within a patch, so a pass that went on from one side's corner
    /// to the next side's second vertex left that cell's chord unchecked (Bike.tsm, planes
    /// at 90°, r 0.5, h 0.01 mm, a coarser CL mesh: a 2.6 mm chord cut 0.0124 mm in).
    #[test]
    fn boundary_passes_change_patch_only_at_a_shared_corner() {
        let m = samples::load_sample("keycap-convex").unwrap();
        let mesh = ClMesh::new(&m, 0.5, 0.01, 0.5).unwrap();
        let tol = BOUNDARY_JOIN_REL * m.surface.bbox().diagonal().max(1.0);
        let passes = boundary_passes(&m, &mesh, 0.01);
        let mut crossings = 0;
        for pass in &passes {
            let mut pts = pass.points.clone();
            if pass.closed {
                pts.push(pts[0]);
            }
            for w in pts.windows(2) {
                if w[0].patch != w[1].patch {
                    crossings += 1;
                    let gap = (w[0].mesh_cl - w[1].mesh_cl).norm();
                    assert!(
                        gap <= tol,
                        "{gap} mm from patch {} to {}",
                        w[0].patch,
                        w[1].patch
                    );
                }
            }
        }
        // The keycap's four walls meet at four corners round its free bottom edge.
        assert!(
            crossings >= 4,
            "{crossings} crossings in {} passes",
            passes.len()
        );
    }
}
