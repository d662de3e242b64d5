//! Reduction of every domain face to Bézier cells.
//!
//! T-spline faces: the blending functions covering a face, cut at every knot line that
//! crosses it, summed into rational bicubic cells (Bézier extraction). Faces at and next to
//! extraordinary points, and all faces of a Catmull–Clark cage: local subdivision
//! ([`super::subdiv`]). Knot intervals around extraordinary points must be uniform; that is
//! checked here and reported, never approximated.

use super::basis::bspline_bernstein;
use super::bezier::BezierPatch;
use super::sharpness::INFINITELY_SHARP;
use super::subdiv::{LocalMap, LocalMesh};
use super::{FaceForm, FaceSurface};
use crate::error::{Error, Result};
use crate::tmesh::{BoundaryInterpolation, Scheme, TMesh, KNOT_MATCH_REL};
use std::collections::{HashMap, HashSet};

pub(super) fn extract(mesh: &TMesh) -> Result<Vec<FaceSurface>> {
    let nv = mesh.vertex_count();
    let extraordinary: Vec<bool> = (0..nv as u32).map(|v| mesh.is_extraordinary(v)).collect();
    let by_subdivision = subdivision_faces(mesh, &extraordinary)?;
    let blends = if by_subdivision.len() < mesh.faces().len() {
        mesh.face_blends(&extraordinary, &extraordinary)
    } else {
        vec![Vec::new(); mesh.faces().len()]
    };
    let mut out = Vec::new();
    for (f, face) in mesh.faces().iter().enumerate() {
        if !mesh.carries_surface(f as u32) {
            continue;
        }
        let form = if by_subdivision.contains(&(f as u32)) {
            let (local, q) = local_one_ring(mesh, f as u32)?;
            FaceForm::Tree(local.face_tree(q))
        } else {
            grid_form(mesh, f, &blends[f])?
        };
        out.push(FaceSurface {
            mesh_face: f as u32,
            width: face.width,
            height: face.height,
            form,
        });
    }
    Ok(out)
}

/// Faces evaluated by subdivision: all of a Catmull–Clark cage; in a T-spline, the faces
/// touching an extraordinary point and their neighbours (whose knot walks pass through it).
/// Checks the conditions under which that is exact.
fn subdivision_faces(mesh: &TMesh, extraordinary: &[bool]) -> Result<HashSet<u32>> {
    let nf = mesh.faces().len() as u32;
    match mesh.scheme() {
        Scheme::CatmullClark => {
            let first = mesh.half_edges().first().map(|h| h.knot).unwrap_or(1.0);
            for f in 0..nf {
                let hs = mesh.face_half_edges(f);
                if hs.len() != 4 {
                    return Err(Error::InvalidMesh(format!(
                        "face {f} has {} vertices: a Catmull–Clark cage needs quadrilaterals without T-junctions",
                        hs.len()
                    )));
                }
                for h in hs {
                    let k = mesh.he(h).knot;
                    if (k - first).abs() > KNOT_MATCH_REL * first || k <= 0.0 {
                        return Err(Error::Unsupported(format!(
                            "face {f} has knot interval {k}, others {first}: Catmull–Clark cages need uniform knot intervals"
                        )));
                    }
                }
            }
            Ok((0..nf).collect())
        }
        Scheme::TSpline => {
            let eps: Vec<u32> = (0..extraordinary.len() as u32)
                .filter(|&v| extraordinary[v as usize])
                .collect();
            let mut set = HashSet::new();
            for &ep in &eps {
                let ring0 = faces_at(mesh, &[ep]);
                let ring1 = grow(mesh, &ring0);
                let ring2 = grow(mesh, &ring1);
                check_uniform_region(mesh, ep, &ring2)?;
                set.extend(ring1);
            }
            Ok(set)
        }
    }
}

/// Faces having one of `verts` as a vertex.
fn faces_at(mesh: &TMesh, verts: &[u32]) -> HashSet<u32> {
    verts
        .iter()
        .flat_map(|&v| mesh.outgoing(v).into_iter().map(|h| mesh.he(h).face))
        .collect()
}

/// `faces` and every face sharing a vertex with one of them.
fn grow(mesh: &TMesh, faces: &HashSet<u32>) -> HashSet<u32> {
    let verts: Vec<u32> = faces
        .iter()
        .flat_map(|&f| {
            mesh.face_half_edges(f)
                .into_iter()
                .map(|h| mesh.he(h).origin)
        })
        .collect();
    faces_at(mesh, &verts)
}

/// Around an extraordinary point of a T-spline: quadrilaterals only, one knot interval,
/// no boundary (T-NURCC subdivision is exact there and only there).
fn check_uniform_region(mesh: &TMesh, ep: u32, region: &HashSet<u32>) -> Result<()> {
    let mut faces: Vec<u32> = region.iter().copied().collect();
    faces.sort_unstable();
    let mut interval: Option<f64> = None;
    for f in faces {
        let hs = mesh.face_half_edges(f);
        if hs.len() != 4 {
            return Err(Error::Unsupported(format!(
                "face {f} near extraordinary point {ep} has a T-junction; T-junctions must be at least three faces away from extraordinary points"
            )));
        }
        for h in hs {
            let e = mesh.he(h);
            if e.twin.is_none() {
                return Err(Error::Unsupported(format!(
                    "extraordinary point {ep} is within two faces of the boundary; use the catmull-clark scheme for such models"
                )));
            }
            let d = *interval.get_or_insert(e.knot);
            if (e.knot - d).abs() > KNOT_MATCH_REL * d.max(e.knot) || e.knot <= 0.0 {
                return Err(Error::Unsupported(format!(
                    "knot intervals around extraordinary point {ep} are not uniform ({} and {d}); non-uniform T-NURCC evaluation is not supported",
                    e.knot
                )));
            }
        }
    }
    Ok(())
}

/// The faces sharing a vertex with face `f`, as a local quad mesh for subdivision.
pub(super) fn local_one_ring(mesh: &TMesh, f: u32) -> Result<(LocalMesh, u32)> {
    let corners: Vec<u32> = mesh
        .face_half_edges(f)
        .into_iter()
        .map(|h| mesh.he(h).origin)
        .collect();
    let mut faces: Vec<u32> = faces_at(mesh, &corners).into_iter().collect();
    faces.sort_unstable();
    let mut map: HashMap<u32, u32> = HashMap::new();
    let mut pts = Vec::new();
    let mut quads = Vec::with_capacity(faces.len());
    let mut creases = LocalMap::default();
    for &g in &faces {
        let hs = mesh.face_half_edges(g);
        if hs.len() != 4 {
            return Err(Error::Unsupported(format!(
                "face {g} next to subdivided face {f} is not a plain quadrilateral"
            )));
        }
        let mut quad = [0u32; 4];
        for (k, &h) in hs.iter().enumerate() {
            let v = mesh.he(h).origin;
            quad[k] = *map.entry(v).or_insert_with(|| {
                pts.push(mesh.points()[v as usize].homogeneous());
                (pts.len() - 1) as u32
            });
        }
        for (k, &h) in hs.iter().enumerate() {
            let e = mesh.he(h);
            let s = if e.twin.is_none() {
                INFINITELY_SHARP
            } else {
                mesh.edge_sharpness(e.origin, mesh.he(e.next).origin)
            };
            if s > 0.0 {
                let (a, b) = (quad[k], quad[(k + 1) % 4]);
                creases.insert((a.min(b), a.max(b)), s);
            }
        }
        quads.push(quad);
    }
    // Tagged corners, and with edge-and-corner interpolation every boundary vertex with one
    // face.
    let corner_rule = mesh.tags().boundary == BoundaryInterpolation::EdgeAndCorner;
    let corners = map
        .iter()
        .filter_map(|(&v, &local)| {
            let one_face = corner_rule && mesh.is_boundary_vertex(v) && mesh.outgoing(v).len() == 1;
            let s = if one_face {
                INFINITELY_SHARP
            } else {
                mesh.tags().corners.get(&v).copied().unwrap_or(0.0)
            };
            (s > 0.0).then_some((local, s))
        })
        .collect();
    let q = faces
        .binary_search(&f)
        .expect("the face is in its own ring") as u32;
    let origin = crate::geom::Vector3::zeros();
    Ok((
        LocalMesh {
            pts,
            origin,
            quads,
            creases,
            corners,
        },
        q,
    ))
}

/// Bézier extraction of a T-spline face.
fn grid_form(mesh: &TMesh, f: usize, fb: &[crate::tmesh::walk::FaceBlend]) -> Result<FaceForm> {
    let face = &mesh.faces()[f];
    if fb.is_empty() {
        return Err(Error::InvalidMesh(format!(
            "face {f} is covered by no blending function"
        )));
    }
    let u_breaks = breaks(fb.iter().flat_map(|b| b.u_knots), face.width);
    let v_breaks = breaks(fb.iter().flat_map(|b| b.v_knots), face.height);
    let mut cells = Vec::with_capacity((u_breaks.len() - 1) * (v_breaks.len() - 1));
    for j in 0..v_breaks.len() - 1 {
        let (v0, v1) = (v_breaks[j] * face.height, v_breaks[j + 1] * face.height);
        for i in 0..u_breaks.len() - 1 {
            let (u0, u1) = (u_breaks[i] * face.width, u_breaks[i + 1] * face.width);
            let mut cell = BezierPatch::zero();
            for b in fb {
                let cu = bspline_bernstein(&b.u_knots, u0, u1);
                let cv = bspline_bernstein(&b.v_knots, v0, v1);
                if cu.iter().all(|&c| c == 0.0) || cv.iter().all(|&c| c == 0.0) {
                    continue;
                }
                let p = mesh.points()[b.vertex as usize].homogeneous();
                for (jj, &cvj) in cv.iter().enumerate() {
                    for (ii, &cui) in cu.iter().enumerate() {
                        cell.cp[jj][ii] += p * (cui * cvj);
                    }
                }
            }
            if !cell.factor_vanishing_edges() || cell.cp.iter().flatten().any(|c| !(c.w > 0.0)) {
                return Err(Error::InvalidMesh(format!(
                    "face {f}: the blending functions vanish on part of the face, so the surface is undefined there \
                     (a gap in the knot lines, or an unclamped boundary next to a concave corner: give such \
                     boundaries Bézier end conditions with a ring of zero knot intervals)"
                )));
            }
            cells.push(cell);
        }
    }
    Ok(FaceForm::Grid {
        u_breaks,
        v_breaks,
        cells,
    })
}

/// Sorted distinct knot values strictly inside `(0, len)`, normalised to `[0,1]`, with 0 and 1.
fn breaks(knots: impl Iterator<Item = f64>, len: f64) -> Vec<f64> {
    let tol = KNOT_MATCH_REL * len;
    let mut inner: Vec<f64> = knots.filter(|&k| k > tol && k < len - tol).collect();
    crate::sort::sort_floats(&mut inner);
    let mut out = vec![0.0];
    let mut last = 0.0;
    for k in inner {
        if k - last > tol {
            out.push(k / len);
            last = k;
        }
    }
    out.push(1.0);
    out
}
