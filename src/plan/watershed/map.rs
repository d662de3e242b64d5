//! The 2-D curvature map (seed 003, §3.1.1, eq. 9–10): the surface sampled on a uniform
//! grid over its parameter domain, laid flat in one chart, with the curvature at each point.
//!
//! Convention: the map's value is `sqrt(k1² + k2²)` (1/mm), the paper's root of the sum of
//! the squared principal curvatures — a sphere of radius R gives `√2 / R`, a cylinder
//! `1 / R`, a plane 0 (Pulla et al.'s RMS curvature is this over √2). The mean curvature is
//! kept with the tool-side normal, negative where the surface is convex towards the tool.
//! Grid points outside every face (beyond the boundary, in a hole) are not valid.

use super::Grid;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::surface::DiffGeom;
use crate::surface::Surface;
use crate::tmesh::walk::{rot, Placement};
use crate::tmesh::TMesh;

/// Default map resolution: grid points per knot unit of the domain (the paper's first
/// example samples its one-unit domain 20 × 20).
pub const DEFAULT_PER_UNIT: f64 = 20.0;
/// Most grid points a map may have; a finer request is coarsened to this.
pub const MAX_POINTS: usize = 1 << 20;
/// Slack, as a share of a grid step, with which a grid point on a face's side counts as
/// on the face.
const SIDE_SLACK: f64 = 1e-9;

/// The curvature map of a model.
#[derive(Debug, Clone)]
pub struct CurvatureMap {
    /// Chart position of grid point `(0, 0)` and the step between points (knot units).
    pub origin: [f64; 2],
    pub step: [f64; 2],
    /// `sqrt(k1² + k2²)` (1/mm); NaN where not valid.
    pub curvature: Grid<f64>,
    /// Mean curvature with the tool-side normal (1/mm); NaN where not valid.
    pub mean: Grid<f64>,
    /// True where a face of the surface holds the point and has a tangent plane there.
    pub valid: Grid<bool>,
    /// Where each grid point lies on the surface: the face (index into the surface's
    /// faces) and its `(u, v)`.
    pub at: Grid<Option<(u32, [f64; 2])>>,
    /// The chart the map lies in.
    pub chart: Chart,
}

/// A domain laid flat in one parameter chart.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Every mesh face's placement in the chart.
    pub placements: Vec<Placement>,
    /// Every surface face's rectangle in the chart, `[s0, s1, t0, t1]`.
    pub face_rects: Vec<[f64; 4]>,
    /// The corners of the rectangle holding every face.
    pub lo: [f64; 2],
    pub hi: [f64; 2],
}

/// Lines of the chart closer than this share of its largest face are one.
const LINE_MATCH_REL: f64 = 1e-9;

impl Chart {
    /// Distance (knot units) within which two lines of the chart are one: a tiny share of
    /// its largest face.
    pub fn line_tol(&self) -> f64 {
        let size = self
            .face_rects
            .iter()
            .map(|r| (r[1] - r[0]).max(r[3] - r[2]))
            .fold(0.0f64, f64::max);
        LINE_MATCH_REL * size.max(1.0)
    }
}

/// The faces of `surface` (from `mesh`) laid flat in one chart, face 0 at the origin.
/// Errors where they do not lie flat (a closed surface, an extraordinary point inside the
/// domain): the paper's domain is one plane region.
pub fn chart(mesh: &TMesh, surface: &Surface) -> Result<Chart> {
    let placements = mesh
        .face_placements(Placement {
            face: 0,
            quarter_turns: 0,
            offset: [0.0, 0.0],
        })
        .ok_or_else(|| {
            Error::Unsupported(
                "the feature map needs a domain that lies flat in one parameter chart; this model closes on itself or has an extraordinary point inside its domain"
                    .into(),
            )
        })?;
    let face_rects: Vec<[f64; 4]> = surface
        .faces()
        .iter()
        .map(|f| {
            let pl = placements[f.mesh_face as usize];
            let (a, b) = (place(&pl, [0.0, 0.0]), place(&pl, [f.width, f.height]));
            [
                a[0].min(b[0]),
                a[0].max(b[0]),
                a[1].min(b[1]),
                a[1].max(b[1]),
            ]
        })
        .collect();
    let lo = [0, 2].map(|k| {
        face_rects
            .iter()
            .map(|r| r[k])
            .fold(f64::INFINITY, f64::min)
    });
    let hi = [1, 3].map(|k| {
        face_rects
            .iter()
            .map(|r| r[k])
            .fold(f64::NEG_INFINITY, f64::max)
    });
    Ok(Chart {
        placements,
        face_rects,
        lo,
        hi,
    })
}

/// The curvature map of `model` with `per_unit` grid points per knot unit. Errors where
/// the faces do not lie flat in one parameter chart (a closed surface, an extraordinary
/// point inside the domain): the paper's domain is one plane region.
pub fn curvature_map(model: &Model, per_unit: f64) -> Result<CurvatureMap> {
    if !(per_unit.is_finite() && per_unit > 0.0) {
        return Err(Error::param(
            "map resolution",
            format!("{per_unit} points per knot unit; give a positive number"),
        ));
    }
    let chart = chart(&model.mesh, &model.surface)?;
    let faces = model.surface.faces();
    let (lo, hi) = (chart.lo, chart.hi);
    let mut per_unit = per_unit;
    let count = |p: f64, k: usize| ((hi[k] - lo[k]) * p).ceil().max(1.0) as usize + 1;
    while count(per_unit, 0) * count(per_unit, 1) > MAX_POINTS {
        per_unit *= 0.8;
    }
    let (nx, ny) = (count(per_unit, 0), count(per_unit, 1));
    let step = [
        (hi[0] - lo[0]) / (nx - 1) as f64,
        (hi[1] - lo[1]) / (ny - 1) as f64,
    ];
    let mut at: Grid<Option<(u32, [f64; 2])>> = Grid::filled(nx, ny, None);
    for (fi, (f, r)) in faces.iter().zip(&chart.face_rects).enumerate() {
        let pl = chart.placements[f.mesh_face as usize];
        let range = |k: usize, a: f64, b: f64, n: usize| {
            let s = step[k].max(f64::MIN_POSITIVE);
            let first = ((a - lo[k]) / s - SIDE_SLACK).ceil().max(0.0) as usize;
            let last = (((b - lo[k]) / s + SIDE_SLACK).floor().max(0.0) as usize).min(n - 1);
            first..=last
        };
        for j in range(1, r[2], r[3], ny) {
            for i in range(0, r[0], r[1], nx) {
                if at.at(i, j).is_some() {
                    continue;
                }
                let c = [lo[0] + i as f64 * step[0], lo[1] + j as f64 * step[1]];
                let l = unplace(&pl, c);
                let (u, v) = (
                    (l[0] / f.width).clamp(0.0, 1.0),
                    (l[1] / f.height).clamp(0.0, 1.0),
                );
                at.set(i, j, Some((fi as u32, [u, v])));
            }
        }
    }
    let side = model.tool_side();
    let mut curvature = Grid::filled(nx, ny, f64::NAN);
    let mut mean = Grid::filled(nx, ny, f64::NAN);
    let mut valid = Grid::filled(nx, ny, false);
    for j in 0..ny {
        for i in 0..nx {
            let Some((fi, [u, v])) = at.at(i, j) else {
                continue;
            };
            let Some(g) = DiffGeom::try_from_derivs(&faces[fi as usize].derivs(u, v)) else {
                continue;
            };
            let g = if side < 0.0 { g.flipped() } else { g };
            let (k1, k2) = g.principal();
            curvature.set(i, j, k1.hypot(k2));
            mean.set(i, j, g.mean());
            valid.set(i, j, true);
        }
    }
    Ok(CurvatureMap {
        origin: lo,
        step,
        curvature,
        mean,
        valid,
        at,
        chart,
    })
}

/// Chart position of face-local knot coordinates `l` under placement `pl`.
fn place(pl: &Placement, l: [f64; 2]) -> [f64; 2] {
    let r = rot(pl.quarter_turns, l);
    [r[0] + pl.offset[0], r[1] + pl.offset[1]]
}

/// Face-local knot coordinates of chart position `c` under placement `pl`.
pub(crate) fn unplace(pl: &Placement, c: [f64; 2]) -> [f64; 2] {
    rot(
        (4 - pl.quarter_turns % 4) % 4,
        [c[0] - pl.offset[0], c[1] - pl.offset[1]],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::samples;

    fn model(name: &str, mesh: crate::tmesh::TMesh) -> Model {
        Model::try_new(name, "test", "mm", mesh).unwrap()
    }

    /// Closed forms on every valid grid point: a plane 0, a sphere of radius R `√2 / R`
    /// (convex towards the tool: mean `−1 / R`), a cylinder `1 / R` (mean `∓1 / 2R` outside
    /// and inside).
    #[test]
    fn plane_sphere_and_cylinder_give_their_closed_forms() {
        let r = 40.0;
        let cases = [
            (
                model("plane", samples::plane_patch(20.0).unwrap()),
                0.0,
                0.0,
            ),
            (
                model("dome", samples::dome(r).unwrap()),
                2f64.sqrt() / r,
                -1.0 / r,
            ),
            (
                model(
                    "cylinder",
                    samples::cylinder_patch(r, 30.0, 90.0, false).unwrap(),
                ),
                1.0 / r,
                -0.5 / r,
            ),
            (
                model(
                    "cylinder inside",
                    samples::cylinder_patch(r, 30.0, 90.0, true).unwrap(),
                ),
                1.0 / r,
                0.5 / r,
            ),
        ];
        for (m, k, h) in cases {
            let map = curvature_map(&m, DEFAULT_PER_UNIT).unwrap();
            let mut n = 0;
            for j in 0..map.valid.ny {
                for i in 0..map.valid.nx {
                    assert!(map.valid.at(i, j), "{}: ({i}, {j}) not valid", m.name);
                    let (c, hh) = (map.curvature.at(i, j), map.mean.at(i, j));
                    assert!(
                        (c - k).abs() < 1e-9 * (1.0 + k * r),
                        "{}: {c} vs {k}",
                        m.name
                    );
                    assert!(
                        (hh - h).abs() < 1e-9 * (1.0 + k * r),
                        "{}: mean {hh} vs {h}",
                        m.name
                    );
                    n += 1;
                }
            }
            assert!(n >= 400, "{}: {n} points", m.name);
        }
    }

    /// `bumps-hole` is a grid of 14 × 12 unit faces with a hole of 2 × 2 faces: at 4 points
    /// per unit the map is 57 × 49 points and exactly the 7 × 7 inside the hole have no
    /// face (its rim is on faces). Valid points lie on a face; the few on a face without a
    /// tangent plane are the hole corners' extraordinary limits.
    #[test]
    fn a_hole_is_masked() {
        let m = samples::load_sample("bumps-hole").unwrap();
        let map = curvature_map(&m, 4.0).unwrap();
        assert_eq!((map.valid.nx, map.valid.ny), (57, 49));
        let faceless: Vec<(usize, usize)> = (0..map.at.ny)
            .flat_map(|j| (0..map.at.nx).map(move |i| (i, j)))
            .filter(|&(i, j)| map.at.at(i, j).is_none())
            .collect();
        assert_eq!(faceless.len(), 49, "{faceless:?}");
        let (i0, j0) = faceless[0];
        assert!(faceless
            .iter()
            .all(|&(i, j)| (i0..i0 + 7).contains(&i) && (j0..j0 + 7).contains(&j)));
        let singular = (0..map.valid.cells.len())
            .filter(|&k| map.at.cells[k].is_some() && !map.valid.cells[k])
            .count();
        for (k, v) in map.valid.cells.iter().enumerate() {
            assert!(!*v || map.at.cells[k].is_some());
        }
        assert!(singular <= 4, "{singular} singular points");
    }
}
