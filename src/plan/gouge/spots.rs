//! Where a ball placed by its contact normal may cut into the surface elsewhere: near spots
//! where the surface is concave (towards the tool) tighter than the ball, where it creases,
//! or where its normal is undefined. Balls far from every spot touch one smooth sheet no
//! tighter than themselves and cannot cut into it, so only balls near a spot are checked
//! (the same reading of the surface as [`super::needed`] makes for the whole model).
//!
//! Owns sampling the surface for such spots and answering "may a ball centred here cut
//! in?"; must not measure or move anything.

use std::collections::HashSet;

use super::nearest::Nearest;
use crate::geom::{Point3, Vector3};
use crate::model::Model;
use crate::surface::{DiffGeom, FaceForm};

/// Largest 3-D spacing of the samples, as a share of the ball radius.
const SPACING_SHARE: f64 = 0.5;
/// Samples per side of a Bézier cell: at least (a cell curving a quarter turn is still
/// sampled every 22°) and at most (bounds the cost for a tiny ball on a large model).
const MIN_SAMPLES: usize = 4;
const MAX_SAMPLES: usize = 128;
/// Distance within which two cells' side points are the same point, as a share of the
/// gouge tolerance.
const SAME_POINT_SHARE: f64 = 0.01;

/// Grid cells (of the ball radius) a ball centre may lie in and cut in.
pub(super) struct Spots {
    cell: f64,
    marked: HashSet<[i64; 3]>,
}

impl Spots {
    /// The spots of `model`'s surface for a ball of radius `r` cutting in by more than `tol`
    /// mm; `near` finds the other faces at a face's side (creases between faces).
    pub(super) fn new(model: &Model, near: &Nearest, r: f64, tol: f64) -> Spots {
        let mut spots = Spots {
            cell: r.max(f64::MIN_POSITIVE),
            marked: HashSet::new(),
        };
        let side = model.tool_side();
        // The margin [`super::needed`] uses: the curvature peaks between samples.
        let tight = 1.0 / (r * (1.0 + super::TIGHT_MARGIN));
        // A concave crease whose normals differ by `a` lets a ball touching one side cut
        // the other by up to r (1 − cos a).
        let crease_cos = 1.0 - 0.5 * tol / r;
        let creases = super::may_crease(&model.mesh);
        let same = SAME_POINT_SHARE * tol;
        for (f, face) in model.surface.faces().iter().enumerate() {
            let (ub, vb) = face.breaks();
            let grid = matches!(face.form, FaceForm::Grid { .. });
            let nu = ub.len() - 1;
            let mut k = 0;
            face.for_each_cell(&mut |rect, cell| {
                let at = [k % nu.max(1), k / nu.max(1)];
                k += 1;
                // Samples per side from the cell's size (its control points hold it).
                let mut lo = Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
                let mut hi = -lo;
                for c in cell.cp.iter().flatten().filter(|c| c.w > 0.0) {
                    let p = Point3::new(c.x / c.w, c.y / c.w, c.z / c.w);
                    lo = lo.inf(&p);
                    hi = hi.sup(&p);
                }
                let size = (hi - lo).norm();
                let n =
                    ((size / (SPACING_SHARE * r)).ceil() as usize).clamp(MIN_SAMPLES, MAX_SAMPLES);
                let spacing = size / n as f64;
                let reach = r + spacing;
                for i in 0..=n {
                    for j in 0..=n {
                        let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                        let d = cell.derivs(s, t);
                        let Some(g) = DiffGeom::try_from_derivs(&d) else {
                            // No normal: an extraordinary point's limit, or a pinched cell.
                            spots.mark(&d.point, reach);
                            continue;
                        };
                        let g = if side < 0.0 { g.flipped() } else { g };
                        let (_, k_hi) = g.principal();
                        if !(k_hi < tight) {
                            spots.mark(&d.point, reach);
                            continue;
                        }
                        let on_side = i == 0 || i == n || j == 0 || j == n;
                        // Face parameters of the sample, and the normal on the other side
                        // of the cell's side: the next cell of the face, or another face.
                        let (u, v) = (
                            rect[0] + (rect[1] - rect[0]) * s,
                            rect[2] + (rect[3] - rect[2]) * t,
                        );
                        // A subdivision face may crease only along its own sides (tagged
                        // edges of the cage).
                        let on_face_side = u == 0.0 || u == 1.0 || v == 0.0 || v == 1.0;
                        if !(creases && if grid { on_side } else { on_face_side }) {
                            continue;
                        }
                        let mut others: Vec<Vector3> = Vec::new();
                        let mut beyond = |k: usize, dir: isize| {
                            let b = if k == 0 { ub } else { vb };
                            let n = at[k] as isize + dir;
                            if n >= 0 && (n as usize) + 1 < b.len() {
                                let mut c = at;
                                c[k] = n as usize;
                                if let Some(g) = DiffGeom::try_from_derivs(&face.derivs_in(c, u, v))
                                {
                                    others.push(g.normal);
                                }
                                false
                            } else {
                                true
                            }
                        };
                        // (A subdivision face's side always borders another face.)
                        let mut outer = !grid;
                        if grid {
                            if i == 0 {
                                outer |= beyond(0, -1);
                            }
                            if i == n {
                                outer |= beyond(0, 1);
                            }
                            if j == 0 {
                                outer |= beyond(1, -1);
                            }
                            if j == n {
                                outer |= beyond(1, 1);
                            }
                        }
                        if outer {
                            for o in near.faces_near(&d.point, same) {
                                let o = o as usize;
                                if o == f {
                                    continue;
                                }
                                let (su, sv) = near.nearest_start(o, &d.point);
                                let foot = near.foot(o, &d.point, su, sv);
                                if foot.dist > same {
                                    continue;
                                }
                                let other = &model.surface.faces()[o];
                                let [fu, fv] = foot.uv;
                                if let Some(g) =
                                    DiffGeom::try_from_derivs(&other.derivs_in(foot.cell, fu, fv))
                                {
                                    others.push(g.normal);
                                }
                            }
                        }
                        // (Faces of a valid T-mesh agree on their orientation; where one
                        // did not, its side is taken as a crease.)
                        if others.iter().any(|o| o.dot(&g.normal) < crease_cos) {
                            spots.mark(&d.point, reach);
                        }
                    }
                }
            });
        }
        spots
    }

    /// Marks every grid cell a ball centre within `reach` of `p` may lie in.
    fn mark(&mut self, p: &Point3, reach: f64) {
        let lo = self.key(&p.map(|x| x - reach));
        let hi = self.key(&p.map(|x| x + reach));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.marked.insert([x, y, z]);
                }
            }
        }
    }

    fn key(&self, p: &Point3) -> [i64; 3] {
        [p.x, p.y, p.z].map(|x| (x / self.cell).floor() as i64)
    }

    /// True if a ball centred at `c` may cut into the surface away from its contact point.
    pub(super) fn near(&self, c: &Point3) -> bool {
        self.marked.contains(&self.key(c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Balls touching the surface at a grid of points, placed by the contact normal: every
    /// one the full search finds cutting in by more than the tolerance lies near a spot, and
    /// the spots leave most balls unchecked where the surface is mostly smooth. Public files
    /// with tight spots (mouse, face), with creases and micro-folds all over (Bike), and the
    /// concave keycap with a ball too large for most of it.
    #[test]
    fn every_ball_that_cuts_in_lies_near_a_spot() {
        let tsm = |name: &str| {
            let path = format!("{}/www/models/grapetec/{name}", env!("CARGO_MANIFEST_DIR"));
            crate::io::load(&std::fs::read(&path).unwrap(), name).unwrap()
        };
        let cases = [
            ("mouse.tsm", tsm("mouse.tsm"), 1.0, true),
            ("face.tsm", tsm("face.tsm"), 0.5, true),
            ("Bike.tsm", tsm("Bike.tsm"), 0.5, false),
            (
                "keycap-concave",
                crate::model::samples::load_sample("keycap-concave").unwrap(),
                2.0,
                false,
            ),
        ];
        let tol = 0.001;
        const N: usize = 24;
        for (name, model, r, mostly_smooth) in cases {
            let near = Nearest::new(&model.surface);
            let spots = Spots::new(&model, &near, r, tol);
            let side = model.tool_side();
            let (mut balls, mut checked, mut cut_in) = (0, 0, 0);
            for face in model.surface.faces() {
                for i in 0..=N {
                    for j in 0..=N {
                        let (u, v) = (i as f64 / N as f64, j as f64 / N as f64);
                        let (p, Some(n)) = face.point_normal(u, v) else {
                            continue;
                        };
                        let c = p + n * (side * r);
                        balls += 1;
                        let d = near.nearest(&c, r).map_or(f64::INFINITY, |x| x.0);
                        if spots.near(&c) {
                            checked += 1;
                            cut_in += usize::from(d < r - tol);
                        } else {
                            assert!(
                                d >= r - tol,
                                "{name}: the ball at ({:.3}, {:.3}, {:.3}) mm cuts in {:.4} mm away from every spot",
                                c.x,
                                c.y,
                                c.z,
                                r - d
                            );
                        }
                    }
                }
            }
            assert!(
                cut_in > 0,
                "{name}: no ball cuts in, the case proves nothing"
            );
            assert!(
                !mostly_smooth || 2 * checked < balls,
                "{name}: {checked} of {balls} balls near spots"
            );
        }
    }
}
