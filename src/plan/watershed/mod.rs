//! Watershed feature regions and optimised multi-rectangles (Liu et al. 2020, seed 003):
//! the curvature map of the parameter domain ([`map`]), its segmentation into feature
//! regions grown down from curvature peaks ([`regions`]) and the boxes that cover each
//! region ([`boxes`]).
//!
//! Owns the feature analysis in the parameter domain; must not evaluate tool positions or
//! change the model (refinement belongs to [`crate::tmesh::refine`]).

pub mod boxes;
pub mod layer;
pub mod map;
pub mod plan;
pub mod rects;
pub mod regions;

pub use plan::plan;

/// Values on a uniform grid, `i` along the first parameter (`s`), `j` along the second
/// (`t`), stored row by row (`j * nx + i`).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid<T> {
    pub nx: usize,
    pub ny: usize,
    pub cells: Vec<T>,
}

impl<T: Copy> Grid<T> {
    /// A grid of `nx × ny` points, all `value`.
    pub fn filled(nx: usize, ny: usize, value: T) -> Self {
        Grid {
            nx,
            ny,
            cells: vec![value; nx * ny],
        }
    }

    /// The value at `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> T {
        self.cells[j * self.nx + i]
    }

    /// Sets the value at `(i, j)`.
    pub fn set(&mut self, i: usize, j: usize, value: T) {
        self.cells[j * self.nx + i] = value;
    }

    /// The 4-neighbours of `(i, j)` inside the grid.
    pub fn neighbours(&self, i: usize, j: usize) -> impl Iterator<Item = (usize, usize)> {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        [(-1isize, 0isize), (1, 0), (0, -1), (0, 1)]
            .into_iter()
            .map(move |(di, dj)| (i as isize + di, j as isize + dj))
            .filter(move |&(x, y)| x >= 0 && y >= 0 && x < nx && y < ny)
            .map(|(x, y)| (x as usize, y as usize))
    }
}

use crate::error::Result;
use crate::geom::Point3;
use crate::model::Model;
use crate::surface::Surface;

/// Which way a feature region curves, seen from the tool.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureKind {
    /// Bulging towards the tool (a boss): negative mean curvature at its marker.
    Convex,
    /// Hollow towards the tool (a dimple).
    Concave,
}

/// A feature region of a model's curvature map.
#[derive(Debug, Clone, PartialEq)]
pub struct Feature {
    pub region: regions::Region,
    pub kind: FeatureKind,
}

/// The feature regions of a model: its curvature map, the label of every grid point and
/// the regions with their kinds.
#[derive(Debug, Clone)]
pub struct Features {
    pub map: map::CurvatureMap,
    pub labels: Grid<u32>,
    pub features: Vec<Feature>,
    /// The background value used (1/mm).
    pub background: f64,
}

/// The map's reference curvature is this quantile of its values: a few points next to an
/// extraordinary point, where a Catmull–Clark surface's curvature runs away, do not set it.
pub const REFERENCE_QUANTILE: f64 = 0.995;
/// Share of the reference curvature below which grid points are background.
pub const BACKGROUND_SHARE: f64 = 0.2;
/// Regions whose marker (their highest point) stays below this share of the reference
/// curvature are dropped to the background: the ring of opposite curvature round a boss's
/// foot, and the rim of a dimple, rise only to about a third of the feature's own peak.
pub const MARKER_SHARE: f64 = 0.5;
/// Regions with fewer grid points than this share of the valid ones are dropped too.
pub const MIN_REGION_SHARE: f64 = 0.01;

/// The feature regions of `model` on a map of `per_unit` grid points per knot unit:
/// regions grown from curvature peaks down to [`BACKGROUND_SHARE`] of the reference
/// curvature ([`REFERENCE_QUANTILE`]), without those whose peak is below [`MARKER_SHARE`]
/// of it or smaller than [`MIN_REGION_SHARE`] of the map, each classed by the sign of the
/// mean curvature at its marker; the rest is background (label 0).
pub fn features(model: &Model, per_unit: f64) -> Result<Features> {
    let map = map::curvature_map(model, per_unit)?;
    let mut values: Vec<f64> = map
        .curvature
        .cells
        .iter()
        .copied()
        .filter(|c| c.is_finite())
        .collect();
    crate::sort::sort_floats(&mut values);
    let reference = values
        .get(((values.len() as f64 - 1.0) * REFERENCE_QUANTILE).round() as usize)
        .copied()
        .unwrap_or(0.0);
    let background = (BACKGROUND_SHARE * reference).max(f64::MIN_POSITIVE);
    let (mut labels, regions) = regions::watershed(&map.curvature, &map.valid, background);
    let min_points = (MIN_REGION_SHARE * values.len() as f64).ceil() as usize;
    let mut relabel = vec![regions::BACKGROUND; regions.len() + 1];
    let mut features = Vec::new();
    for region in regions {
        let (i, j) = region.marker;
        if map.curvature.at(i, j) < MARKER_SHARE * reference || region.points < min_points {
            continue;
        }
        let label = features.len() as u32 + 1;
        relabel[region.label as usize] = label;
        let kind = if map.mean.at(i, j) < 0.0 {
            FeatureKind::Convex
        } else {
            FeatureKind::Concave
        };
        features.push(Feature {
            region: regions::Region { label, ..region },
            kind,
        });
    }
    for l in labels.cells.iter_mut() {
        *l = relabel[*l as usize];
    }
    Ok(Features {
        map,
        labels,
        features,
        background,
    })
}

/// Default fill tolerance of the feature boxes (the paper's experiments use 0.5).
pub const DEFAULT_TOR: f64 = 0.5;

impl Features {
    /// Every feature region's boxes at fill tolerance `tor`, expanded by half a grid step
    /// and clipped to the map: the region's label and the box in the chart. Boxes of one
    /// region do not overlap; boxes of two regions may, and the rectangles then give the
    /// overlap to the region found first (the higher curvature peak).
    pub fn boxes(&self, tor: f64) -> Vec<(u32, boxes::GridBox, [f64; 4])> {
        let m = &self.map;
        let (lo, hi) = (m.chart.lo, m.chart.hi);
        let mut out = Vec::new();
        for f in &self.features {
            let label = f.region.label;
            let region = Grid {
                nx: self.labels.nx,
                ny: self.labels.ny,
                cells: self.labels.cells.iter().map(|&l| l == label).collect(),
            };
            for b in boxes::poly_bounding_boxes(&region, tor) {
                let e = b.expanded(m.origin, m.step);
                let clipped = [
                    e[0].max(lo[0]),
                    e[1].min(hi[0]),
                    e[2].max(lo[1]),
                    e[3].min(hi[1]),
                ];
                out.push((label, b, clipped));
            }
        }
        out
    }

    /// Lengths (mm) on the surface of grid box `b`'s sides once expanded by half a grid
    /// step (along `s`, along `t`): the grid step's length on the surface, averaged along
    /// the box's middle row (column) and the point beyond each end, times the steps the
    /// expanded box spans.
    pub fn box_sides_mm(&self, surface: &Surface, b: &boxes::GridBox) -> [f64; 2] {
        let at = &self.map.at;
        let point = |i: usize, j: usize| {
            at.at(i, j)
                .map(|(f, [u, v])| surface.subs(f as usize, u, v))
        };
        let along = |n: usize, lo: usize, hi: usize, p: &dyn Fn(usize) -> Option<Point3>| {
            let (a, z) = (lo.saturating_sub(1), (hi + 1).min(n - 1));
            let (mut sum, mut steps) = (0.0, 0usize);
            for k in a..z {
                if let (Some(x), Some(y)) = (p(k), p(k + 1)) {
                    sum += (y - x).norm();
                    steps += 1;
                }
            }
            if steps == 0 {
                0.0
            } else {
                sum / steps as f64 * (hi - lo + 1) as f64
            }
        };
        let (im, jm) = ((b.i0 + b.i1) / 2, (b.j0 + b.j1) / 2);
        [
            along(at.nx, b.i0, b.i1, &|i| point(i, jm)),
            along(at.ny, b.j0, b.j1, &|j| point(im, j)),
        ]
    }

    /// The domain in rectangles: the feature `boxes` (from [`Features::boxes`]) and maximal
    /// rectangles of the rest, merged by `merge` (see [`rects`]).
    pub fn rectangles(
        &self,
        boxes: &[(u32, boxes::GridBox, [f64; 4])],
        merge: rects::Merge,
    ) -> Vec<rects::ChartRect> {
        let boxes: Vec<(u32, [f64; 4])> = boxes.iter().map(|&(l, _, r)| (l, r)).collect();
        let chart = &self.map.chart;
        rects::rectangles(&chart.face_rects, &boxes, chart.line_tol(), merge)
    }

    /// The model's T-mesh refined so that every feature box edge at `tor` is a T-mesh
    /// edge (eq. 13–20): a knot line along each box side, inserted across the whole domain
    /// (the refinement this project has adds whole lines; a local one would stop at the
    /// box), the surface unchanged. Returns the refined mesh and the lines refused because
    /// they would need further knots (left out, never approximated). Errors on a model
    /// that is not a T-spline laid flat in one chart.
    pub fn refined_mesh(
        &self,
        model: &Model,
        tor: f64,
    ) -> Result<(crate::tmesh::TMesh, Vec<crate::tmesh::refine::KnotLine>)> {
        use crate::tmesh::refine::KnotLine;
        let mut lines: Vec<KnotLine> = Vec::new();
        let tol = self.map.chart.line_tol();
        let mut add = |l: KnotLine| {
            let same = |a: &KnotLine| match (a, &l) {
                (KnotLine::S(x), KnotLine::S(y)) | (KnotLine::T(x), KnotLine::T(y)) => {
                    (x - y).abs() <= tol
                }
                _ => false,
            };
            if !lines.iter().any(same) {
                lines.push(l);
            }
        };
        for (_, _, b) in self.boxes(tor) {
            add(KnotLine::S(b[0]));
            add(KnotLine::S(b[1]));
            add(KnotLine::T(b[2]));
            add(KnotLine::T(b[3]));
        }
        if model.mesh.scheme() != crate::tmesh::Scheme::TSpline {
            return Err(crate::error::Error::Unsupported(
                "exact refinement along the feature boxes works on T-spline meshes; this model is a subdivision cage (its rectangles are planned without it)".into(),
            ));
        }
        let mut mesh = model.mesh.clone();
        let mut refused = Vec::new();
        for line in lines {
            match mesh.insert_knot_line(line) {
                Ok(m) => mesh = m,
                Err(_) => refused.push(line),
            }
        }
        Ok((mesh, refused))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use crate::model::samples;

    /// The surface point of a feature's marker.
    fn marker_point(m: &Model, f: &Features, k: usize) -> Point3 {
        let (i, j) = f.features[k].region.marker;
        let (face, [u, v]) = f.map.at.at(i, j).unwrap();
        m.surface.subs(face as usize, u, v)
    }

    /// `bumps` (T-spline) and `bumps-hole` (Catmull–Clark, a hole between the two): one
    /// convex region on the bump and one concave region on the dimple, markers on them; no
    /// grid point of the hole is in a region.
    #[test]
    fn bumps_give_one_convex_and_one_concave_region() {
        for name in ["bumps", "bumps-hole"] {
            let m = samples::load_sample(name).unwrap();
            let f = features(&m, map::DEFAULT_PER_UNIT).unwrap();
            let kinds: Vec<FeatureKind> = f.features.iter().map(|x| x.kind).collect();
            assert_eq!(kinds.len(), 2, "{name}: {kinds:?}");
            for (k, feature) in f.features.iter().enumerate() {
                let p = marker_point(&m, &f, k);
                match feature.kind {
                    // The bump's control points rise 4 mm round (−20, 0), the dimple's sink
                    // 3 mm round (20, 2); the limit surface rises and sinks less.
                    FeatureKind::Convex => {
                        assert!(
                            p.z > 2.0 && (p.x + 20.0).hypot(p.y) < 5.0,
                            "{name}: convex at {p}"
                        )
                    }
                    FeatureKind::Concave => {
                        assert!(
                            p.z < -1.5 && (p.x - 20.0).hypot(p.y - 2.0) < 5.0,
                            "{name}: concave at {p}"
                        )
                    }
                }
            }
            assert!(kinds.contains(&FeatureKind::Convex) && kinds.contains(&FeatureKind::Concave));
            for (k, l) in f.labels.cells.iter().enumerate() {
                if !f.map.valid.cells[k] {
                    assert_eq!(*l, regions::BACKGROUND);
                }
            }
        }
    }

    /// The rectangles partition the domain (their areas add up to the faces', none
    /// overlaps), each is filled by faces (a patch can be made of it, so none reaches into
    /// the hole), the surface through each patch is the surface at the same chart point,
    /// and every feature box is covered by rectangles of its feature.
    #[test]
    fn rectangles_partition_the_domain_into_patches() {
        for (name, merge) in ["bumps", "bumps-hole"]
            .into_iter()
            .flat_map(|n| [rects::Merge::Rows, rects::Merge::Largest].map(|m| (n, m)))
        {
            let m = samples::load_sample(name).unwrap();
            let f = features(&m, map::DEFAULT_PER_UNIT).unwrap();
            let boxes = f.boxes(DEFAULT_TOR);
            let rects = f.rectangles(&boxes, merge);
            let area = |r: &[f64; 4]| (r[1] - r[0]) * (r[3] - r[2]);
            let domain: f64 = f.map.chart.face_rects.iter().map(area).sum();
            let total: f64 = rects.iter().map(|r| area(&r.chart)).sum();
            assert!(
                (total - domain).abs() < 1e-9 * domain,
                "{name}: {total} vs {domain}"
            );
            for (a, ra) in rects.iter().enumerate() {
                for rb in &rects[a + 1..] {
                    let (x, y) = (&ra.chart, &rb.chart);
                    let w = x[1].min(y[1]) - x[0].max(y[0]);
                    let h = x[3].min(y[3]) - x[2].max(y[2]);
                    assert!(w <= 1e-9 || h <= 1e-9, "{name}: {x:?} overlaps {y:?}");
                }
            }
            for f_ in &f.features {
                let label = f_.region.label;
                let covered: f64 = rects
                    .iter()
                    .filter(|r| r.feature == Some(label))
                    .map(|r| area(&r.chart))
                    .sum();
                let boxed: f64 = boxes
                    .iter()
                    .filter(|b| b.0 == label)
                    .map(|b| area(&b.2))
                    .sum();
                // All of it where the boxes lie inside the domain (bumps); a box reaching
                // into the hole loses that part.
                assert!(covered <= boxed * (1.0 + 1e-9), "{name}: feature {label}");
                if name == "bumps" {
                    assert!(covered >= boxed * (1.0 - 1e-9), "{name}: feature {label}");
                }
            }
            let featured = rects.iter().filter(|r| r.feature.is_some()).count();
            assert!(
                featured >= f.features.len(),
                "{name}: {featured} feature rectangles"
            );
            for r in &rects {
                let patch = crate::layout::Patch::from_chart_rect(
                    &m.surface,
                    &f.map.chart.placements,
                    r.chart,
                )
                .unwrap_or_else(|| panic!("{name}: {:?} is not filled by faces", r.chart));
                for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.5, 1.0)] {
                    let c = [
                        r.chart[0] + u * (r.chart[1] - r.chart[0]),
                        r.chart[2] + v * (r.chart[3] - r.chart[2]),
                    ];
                    let p = patch.subs(&m.surface, u, v);
                    // The face holding the chart point, evaluated directly.
                    let q = m
                        .surface
                        .faces()
                        .iter()
                        .enumerate()
                        .find_map(|(fi, face)| {
                            let fr = f.map.chart.face_rects[fi];
                            let inside = c[0] >= fr[0] - 1e-12
                                && c[0] <= fr[1] + 1e-12
                                && c[1] >= fr[2] - 1e-12
                                && c[1] <= fr[3] + 1e-12;
                            inside.then(|| {
                                let pl = f.map.chart.placements[face.mesh_face as usize];
                                let l = map::unplace(&pl, c);
                                m.surface.subs(
                                    fi,
                                    (l[0] / face.width).clamp(0.0, 1.0),
                                    (l[1] / face.height).clamp(0.0, 1.0),
                                )
                            })
                        })
                        .unwrap();
                    assert!(
                        (p - q).norm() < 1e-9 * m.surface.bbox().diagonal(),
                        "{name}: {p} vs {q}"
                    );
                }
            }
            println!(
                "{name} ({merge:?}): {} features, {} boxes, {} rectangles ({featured} of features)",
                f.features.len(),
                boxes.len(),
                rects.len()
            );
        }
    }

    /// Four bosses round a hole (seed 003's third surface): four convex regions, one on
    /// each boss.
    #[test]
    fn four_bosses_give_four_convex_regions() {
        let m = Model::try_new(
            "four bosses",
            "test",
            "mm",
            samples::four_bosses_hole().unwrap(),
        )
        .unwrap();
        let f = features(&m, map::DEFAULT_PER_UNIT).unwrap();
        assert_eq!(f.features.len(), 4, "{:?}", f.features);
        let mut centres: Vec<(i64, i64)> = (0..4)
            .map(|k| {
                assert_eq!(f.features[k].kind, FeatureKind::Convex);
                let p = marker_point(&m, &f, k);
                assert!(p.z > 1.5, "boss top at {p}");
                ((p.x / 20.0).round() as i64, (p.y / 20.0).round() as i64)
            })
            .collect();
        centres.sort();
        assert_eq!(centres, vec![(-1, -1), (-1, 1), (1, -1), (1, 1)]);
    }
}
