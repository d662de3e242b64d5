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

use super::clmesh::{along_side, ClMesh, Strip};
use super::{slice, Pass, SlicePoint};
use crate::geom::{Point3, Vector3};
use crate::model::Model;

/// Ball centres farther than this many tool radii from the crease point beside them are not
/// held against it (they lie on the patch's far side, or past the crease's end).
const REACH_RADII: f64 = 2.0;

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

    /// How far (mm) the CL point `cl` at patch parameter `s` along crease side `c` lies on
    /// its own side of the groove (negative: past it), if the crease runs there and the point
    /// is within reach of it.
    fn own_side(&self, model: &Model, c: &Strip, s: f64, cl: &Point3, r: f64) -> Option<f64> {
        let (lo, hi) = (c.cols[0].0, c.cols[c.cols.len() - 1].0);
        if !(lo..=hi).contains(&s) {
            return None;
        }
        let (q, n_own, n_other) = c.ends(model, s)?;
        let off = cl - q;
        if off.norm() > REACH_RADII * r {
            return None;
        }
        let w: Vector3 = (n_other - n_own).try_normalize(0.0)?;
        Some(off.dot(&w))
    }

    /// The crease side and parameter along it past whose groove slice point `p` lies.
    fn past(&self, model: &Model, p: &SlicePoint, r: f64) -> Option<(usize, f64)> {
        self.sides.iter().enumerate().find_map(|(k, c)| {
            if c.a != p.patch {
                return None;
            }
            let s = along_side(c.side, p.uv);
            let d = self.own_side(model, c, s, &p.mesh_cl, r)?;
            (d < 0.0).then_some((k, s))
        })
    }

    /// Where between `inside` and `out` (slice points of one patch, `out` past the groove of
    /// crease side `k` at `s`) the CL mesh crosses the groove, as a slice point between
    /// them (linear in the patch parameters and on the mesh).
    fn crossing(
        &self,
        model: &Model,
        (k, s): (usize, f64),
        inside: &SlicePoint,
        out: &SlicePoint,
        r: f64,
    ) -> SlicePoint {
        let c = &self.sides[k];
        let d_out = self.own_side(model, c, s, &out.mesh_cl, r).unwrap_or(0.0);
        let d_in = self
            .own_side(model, c, s, &inside.mesh_cl, r)
            .unwrap_or(0.0);
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
            let past = |p: &SlicePoint| self.past(model, p, r);
            let Some(lo) = run.iter().position(|p| past(p).is_none()) else {
                continue;
            };
            let hi = run.iter().rposition(|p| past(p).is_none()).unwrap_or(lo);
            if lo > 0 {
                let at = past(&run[lo - 1]).expect("past");
                out.push(self.crossing(model, at, &run[lo], &run[lo - 1], r));
            }
            out.extend_from_slice(&run[lo..=hi]);
            if hi + 1 < run.len() {
                let at = past(&run[hi + 1]).expect("past");
                out.push(self.crossing(model, at, &run[hi], &run[hi + 1], r));
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
                .filter_map(|id| {
                    let v = mesh.vertices[id as usize]?;
                    Some(SlicePoint {
                        hit: slice::Hit {
                            a: id,
                            b: id,
                            t: 0.0,
                        },
                        patch: pi as u32,
                        uv: v.uv,
                        mesh_cl: v.cl,
                        deformed: [f64::INFINITY, 0.0, 0.0],
                    })
                })
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
