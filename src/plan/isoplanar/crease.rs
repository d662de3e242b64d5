//! Concave creases: a pass along each groove, and the planes' passes ended where they reach
//! it.
//!
//! At a concave crease the two sides' offsets cross. A plane's pass over one side runs on
//! past the groove to that side's edge, its balls there cutting into the other side; lifted
//! clear by the pipeline, each then touches the other side only (over a crease of 13° with
//! r 0.5 mm, 0.0136 mm above the crease), and the straight move to it rises over its whole
//! chord. So each run of a pass on one patch ends where its ball centres reach the groove:
//! the plane through the crease half-way between the two sides' normals, on which a ball
//! centre is a radius from both sides' tangent planes. The groove itself gets a pass of its
//! own, whichever way the planes run.
//!
//! Owns: the concave creases' passes and the trimming at them. Must not: slice, or place
//! moves.

use super::clmesh::{ClMesh, Strip};
use super::{Pass, SlicePoint};
use crate::geom::{Point3, Vector3};
use crate::layout::side_param;
use crate::model::Model;

/// Ball centres farther than this many tool radii from the crease point beside them are not
/// held against it (they lie on the patch's far side, or past the crease's end).
const REACH_RADII: f64 = 2.0;

/// A concave crease's groove at one place: the crease point, and the unit normal of the
/// plane through it half-way between the two sides' normals, towards one side.
#[derive(Debug, Clone, Copy)]
struct Groove {
    q: Point3,
    w: Vector3,
}

impl Groove {
    /// How far (mm) CL point `cl` lies on the groove's side of its half-way plane (negative:
    /// past it), if within reach of the crease point.
    fn own_side(&self, cl: &Point3, r: f64) -> Option<f64> {
        let off = cl - self.q;
        (off.norm() <= REACH_RADII * r).then(|| off.dot(&self.w))
    }
}

/// The concave creases of a CL mesh, each seen from both of its patches.
pub struct Creases {
    sides: Vec<Strip>,
}

impl Creases {
    /// The concave strips of `mesh`, from both sides.
    pub fn new(mesh: &ClMesh) -> Self {
        let sides = mesh
            .strips
            .iter()
            .filter(|s| !s.convex)
            .flat_map(|s| [s.clone(), s.reversed()])
            .collect();
        Creases { sides }
    }

    /// The groove of crease side `c` at patch parameter `s` along it, if the crease runs
    /// there: the crease point and the unit normal of the plane half-way between the two
    /// sides' normals, pointing to `c`'s own side.
    fn groove(&self, model: &Model, c: &Strip, s: f64) -> Option<Groove> {
        let (lo, hi) = (c.cols[0].0, c.cols[c.cols.len() - 1].0);
        if !(lo..=hi).contains(&s) {
            return None;
        }
        let (q, n_own, n_other) = c.ends(model, s)?;
        let w: Vector3 = (n_other - n_own).try_normalize(0.0)?;
        Some(Groove { q, w })
    }

    /// The groove past which slice point `p` lies (its CL point within reach of the crease
    /// point beside it, on the other side of the half-way plane), and how far past (mm,
    /// negative).
    fn past(&self, model: &Model, p: &SlicePoint, r: f64) -> Option<(Groove, f64)> {
        self.sides.iter().find_map(|c| {
            if c.a != p.patch {
                return None;
            }
            let g = self.groove(model, c, side_param(c.side, p.uv))?;
            let d = g.own_side(&p.mesh_cl, r)?;
            (d < 0.0).then_some((g, d))
        })
    }

    /// Where between `inside` and `out` (slice points of one patch, `out` past groove `g`
    /// by `d_out`) the CL mesh crosses the groove, as a slice point between them (linear in
    /// the patch parameters and on the mesh).
    fn crossing(
        (g, d_out): (Groove, f64),
        inside: &SlicePoint,
        out: &SlicePoint,
        r: f64,
    ) -> SlicePoint {
        let d_in = g.own_side(&inside.mesh_cl, r).unwrap_or(0.0);
        let f = if d_in > 0.0 && d_out < 0.0 {
            d_in / (d_in - d_out)
        } else {
            0.0
        };
        let lerp = |a: f64, b: f64| a + (b - a) * f;
        SlicePoint {
            hit: inside.hit,
            patch: inside.patch,
            uv: [lerp(inside.uv[0], out.uv[0]), lerp(inside.uv[1], out.uv[1])],
            mesh_cl: inside.mesh_cl + (out.mesh_cl - inside.mesh_cl) * f,
            deformed: [0, 1, 2].map(|i| lerp(inside.deformed[i], out.deformed[i])),
        }
    }

    /// `pts` (a pass) with each run on one patch ended where it reaches the groove of a
    /// concave crease on that patch's sides: its points past the groove left out, and the
    /// crossing put in their place; runs wholly past it left out.
    pub fn trim(&self, model: &Model, pts: Vec<SlicePoint>, r: f64) -> Vec<SlicePoint> {
        if self.sides.is_empty() {
            return pts;
        }
        let mut out = Vec::with_capacity(pts.len());
        let mut i = 0;
        while i < pts.len() {
            let mut j = i;
            while j + 1 < pts.len() && pts[j + 1].patch == pts[i].patch {
                j += 1;
            }
            let run = &pts[i..=j];
            i = j + 1;
            if !self.sides.iter().any(|c| c.a == run[0].patch) {
                out.extend_from_slice(run);
                continue;
            }
            // From either end, the points past a groove, and the groove of the last of them.
            let from = |order: &mut dyn Iterator<Item = usize>| {
                let mut last = None;
                for k in order {
                    match self.past(model, &run[k], r) {
                        Some(at) => last = Some((k, at)),
                        None => return Some((k, last)),
                    }
                }
                None
            };
            let Some((lo, before)) = from(&mut (0..run.len())) else {
                continue;
            };
            let (hi, after) = from(&mut (0..run.len()).rev()).expect("a point is not past");
            if let Some((k, at)) = before {
                out.push(Self::crossing(at, &run[lo], &run[k], r));
            }
            out.extend_from_slice(&run[lo..=hi]);
            if let Some((k, at)) = after {
                out.push(Self::crossing(at, &run[hi], &run[k], r));
            }
        }
        out
    }
}

/// Passes along the concave creases' grooves: through the one row of each concave strip
/// (balls pivoted half-way about the crease, which the pipeline lifts until they touch both
/// sides); `plane` is +∞ (they are cut after the planes).
pub fn groove_passes(mesh: &ClMesh) -> Vec<Pass> {
    let first_strip = mesh.patches.len() - mesh.strips.len();
    mesh.strips
        .iter()
        .enumerate()
        .filter(|(_, strip)| !strip.convex)
        .map(|(k, _)| {
            let pi = first_strip + k;
            let (first, [nu, _]) = mesh.patches[pi];
            let points = (first..=first + nu as u32)
                .filter(|&id| mesh.vertices[id as usize].is_some())
                .map(|id| SlicePoint::at_vertex(mesh, id))
                .collect();
            Pass {
                plane: f64::INFINITY,
                points,
                closed: false,
            }
        })
        .filter(|p| p.points.len() >= 2)
        .collect()
}
