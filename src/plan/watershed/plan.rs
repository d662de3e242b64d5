//! The watershed strategies: the domain cut into rectangles (feature boxes and maximal
//! rectangles of the rest, or for the baseline the rest alone), each rectangle a patch cut
//! by the patch-ordered zig-zags, along its longer side (eq. 21–22) or, for the baseline,
//! all in one direction. Everything after the rectangles (side and forward steps, order,
//! links, axes, lifting, air moves, rest area) is the isoparametric draft and the shared
//! pipeline.

use super::layer::{FillKind, Layer};
use super::rects::{ChartRect, Merge};
use super::{features, map, rects, FeatureKind, DEFAULT_TOR};
use crate::error::{Error, Result};
use crate::layout::PatchLayout;
use crate::model::Model;
use crate::plan::corners::Crossfeed;
use crate::plan::draft::Footprint;
use crate::plan::isoparametric;
use crate::plan::pipeline::{self, Planned};
use crate::plan::{stepover, PlanOptions};
use serde::{Deserialize, Serialize};

/// A feature region as the report gives it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegionReport {
    pub kind: FeatureKind,
    /// Area of its rectangles on the surface (mm²).
    pub area_mm2: f64,
    /// Boxes PolyBoundingBox made of it that are cut as the feature's (those holding less
    /// than [`SMALL_BOX_SHARE`] of its largest box are cut with the rest).
    pub boxes: usize,
}

/// What the watershed strategies found and made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WatershedStats {
    /// Feature regions, and the grid points of the curvature map they were found on (none
    /// for the multi-rectangle baseline, which has no map).
    pub regions: Option<Vec<RegionReport>>,
    pub map_points: Option<[usize; 2]>,
    /// Per rectangle (patch), the feature region it belongs to (index into `regions`).
    pub rectangle_regions: Vec<Option<u32>>,
}

/// Share of the progress bar the draft takes (the pipeline takes the rest).
const DRAFT_SHARE: f64 = 0.7;
/// A feature box holding less than this share of its region's largest box (area on the
/// surface) is cut with the rest of the domain.
pub const SMALL_BOX_SHARE: f64 = 0.05;
/// A strip between a feature box and the domain's edge, a hole or another box's side
/// narrower than this many flat side steps (`sqrt(8 r h)`) is given to the box: as a
/// rectangle of its own it would take at least two passes of the box's length.
pub const STRIP_SIDE_STEPS: f64 = 4.0;
/// Samples along a seam for the normals on its two sides.
const SEAM_SAMPLES: usize = 16;
/// A pass on a seam serves the rectangles on both sides when the balls on it set by the
/// two sides' normals stand at most this share of the scallop height apart: the cusp
/// beside the seam is then at most that much higher than the side step was made for.
/// Smooth seams give 1e-15 mm, seams next to an extraordinary point's patches up to
/// 0.0025 h (bumps-hole, r 1, h 0.05 mm: 1.3e-4 mm), creases 0.017 mm and more (the .tsm
/// models at r 0.5 mm: 0.35 h at h 0.05 mm).
pub const SEAM_BALL_SHARE: f64 = 0.01;
/// Samples per side of a rectangle for its area.
const AREA_SAMPLES: usize = 16;

/// The domain cut into rectangles, ready to plan: the rectangles, their layout, their
/// sides on the surface and the crossfeed each is cut with.
struct Cut {
    rects: Vec<ChartRect>,
    layout: PatchLayout,
    /// Per rectangle, `[along u, along v]` (mm, [`isoparametric::side_lengths_mm`]).
    sides_mm: Vec<[f64; 2]>,
    crossfeeds: Vec<Crossfeed>,
}

impl Cut {
    /// `rects` of `model`'s `chart` as patches, each with the crossfeed of the watershed
    /// (`with_features`: along its longer side, eq. 21–22) or of the baseline (one way for
    /// all, the way most of the area prefers), unless `opts` gives one.
    fn new(
        model: &Model,
        chart: &map::Chart,
        rects: Vec<ChartRect>,
        opts: &PlanOptions,
        with_features: bool,
    ) -> Result<Self> {
        let rect_charts: Vec<[f64; 4]> = rects.iter().map(|r| r.chart).collect();
        let layout = PatchLayout::from_chart_rects(&model.surface, &chart.placements, &rect_charts)
            .ok_or_else(|| Error::Degenerate {
                location: "the domain's rectangles".into(),
                message: "a rectangle of the domain is not filled by faces".into(),
            })?;
        let sides_mm: Vec<[f64; 2]> = isoparametric::layout_views(model, &layout)
            .iter()
            .map(isoparametric::side_lengths_mm)
            .collect();
        let own: Vec<Crossfeed> = sides_mm
            .iter()
            .map(|&s| isoparametric::longer_side_crossfeed(s))
            .collect();
        let crossfeeds: Vec<Crossfeed> = match (opts.crossfeed, with_features) {
            (Some(c), _) => vec![c; own.len()],
            (None, true) => own,
            (None, false) => {
                let area = |k: usize| {
                    let r = &rect_charts[k];
                    (r[1] - r[0]) * (r[3] - r[2])
                };
                let along_u: f64 = (0..own.len())
                    .filter(|&k| own[k] == Crossfeed::V)
                    .map(area)
                    .sum();
                let total: f64 = (0..own.len()).map(area).sum();
                let c = if 2.0 * along_u >= total {
                    Crossfeed::V
                } else {
                    Crossfeed::U
                };
                vec![c; own.len()]
            }
        };
        Ok(Cut {
            rects,
            layout,
            sides_mm,
            crossfeeds,
        })
    }

    /// Per rectangle, whether its boundary pass at across-parameter 0 and 1 is left to a
    /// neighbour ([`rects::shared_seams`]); `tol` is the chart's line tolerance.
    fn seams(&self, model: &Model, opts: &PlanOptions, tol: f64) -> Vec<[bool; 2]> {
        let rect_charts: Vec<[f64; 4]> = self.rects.iter().map(|r| r.chart).collect();
        let along_s: Vec<bool> = self.crossfeeds.iter().map(|&c| c == Crossfeed::V).collect();
        // One pass serves both sides of a seam where the surface is smooth across it: the
        // ball on the seam set by either side's normal is the same ball. (Across a crease
        // the two balls stand apart by r times the normals' difference.)
        let surface = &model.surface;
        let smooth = |k: usize, j: usize, x: f64, [a, b]: [f64; 2]| {
            let mut worst: f64 = 0.0;
            for i in 0..=SEAM_SAMPLES {
                let y = a + (b - a) * i as f64 / SEAM_SAMPLES as f64;
                let n = [k, j].map(|q| {
                    let r = &rect_charts[q];
                    let (s, t) = if along_s[k] { (y, x) } else { (x, y) };
                    let (u, v) = ((s - r[0]) / (r[1] - r[0]), (t - r[2]) / (r[3] - r[2]));
                    self.layout.patches[q].normal(surface, u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
                });
                match n {
                    [Some(p), Some(q)] => worst = worst.max((p - q).norm()),
                    _ => return false,
                }
            }
            opts.tool_radius_mm * worst <= SEAM_BALL_SHARE * opts.scallop_mm
        };
        rects::shared_seams(&rect_charts, &along_s, tol, &smooth)
    }

    /// Estimated cutting length (mm): per rectangle, passes `step` (mm) apart across it and
    /// one more, each as long as the side it runs along.
    fn estimated_path_mm(&self, step: f64) -> f64 {
        self.sides_mm
            .iter()
            .zip(&self.crossfeeds)
            .map(|(&[along_u, along_v], c)| {
                // Crossfeed V: passes along u, stepping across v.
                let (along, across) = match c {
                    Crossfeed::V => (along_u, along_v),
                    Crossfeed::U => (along_v, along_u),
                };
                ((across / step).ceil() + 1.0) * along
            })
            .sum()
    }
}

/// Plans `model` with the watershed strategy (`with_features`) or its multi-rectangle
/// baseline. Errors on a model whose domain does not lie flat in one chart.
pub fn plan(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
    with_features: bool,
) -> Result<Planned> {
    opts.validate()?;
    // The flat side step (mm), the unit of the strips given to boxes and of the estimate
    // that picks the merge.
    let step = stepover::side_step_clamped(opts.scallop_mm, opts.tool_radius_mm, 0.0);
    // The feature boxes grown over thin strips, or for the baseline none.
    let (chart, boxes, regions, map_points) = if with_features {
        let found = features(model, map::DEFAULT_PER_UNIT)?;
        // A region's boxes that hold less than SMALL_BOX_SHARE of its largest box are cut
        // with the rest: PolyBoundingBox boxes the few grid steps where a region juts out
        // of its main box, and their lines split the main box and the rest into more
        // rectangles (more reversals, retractions where the directions do not meet) for a
        // sliver of the feature.
        let mut boxes = found.boxes(DEFAULT_TOR);
        let areas: Vec<f64> = boxes
            .iter()
            .map(|(_, b, _)| {
                let [s, t] = found.box_sides_mm(&model.surface, b);
                s * t
            })
            .collect();
        let mut largest = vec![0.0f64; found.features.len() + 1];
        for ((label, _, _), &a) in boxes.iter().zip(&areas) {
            largest[*label as usize] = largest[*label as usize].max(a);
        }
        // (A box whose area is not a number is kept.)
        let mut small = boxes
            .iter()
            .zip(&areas)
            .map(|((label, _, _), &a)| a < SMALL_BOX_SHARE * largest[*label as usize])
            .collect::<Vec<bool>>()
            .into_iter();
        boxes.retain(|_| !small.next().unwrap_or(false));
        // Strips narrower than STRIP_SIDE_STEPS flat side steps between a box and the
        // domain's edge, a hole or another box's side go to the box.
        let reach: Vec<[f64; 2]> = boxes
            .iter()
            .map(|(_, g, c)| {
                let mm = found.box_sides_mm(&model.surface, g);
                [0, 1].map(|a| {
                    let knots = c[2 * a + 1] - c[2 * a];
                    // Knot units per mm along the side, times the strip's width in mm.
                    if mm[a] > 0.0 {
                        STRIP_SIDE_STEPS * step * knots / mm[a]
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        let mut charts: Vec<(u32, [f64; 4])> = boxes.iter().map(|&(l, _, c)| (l, c)).collect();
        rects::grow_over_strips(
            &found.map.chart.face_rects,
            &mut charts,
            &reach,
            found.map.chart.line_tol(),
        );
        let regions: Vec<RegionReport> = found
            .features
            .iter()
            .map(|f| RegionReport {
                kind: f.kind,
                area_mm2: 0.0,
                boxes: boxes.iter().filter(|b| b.0 == f.region.label).count(),
            })
            .collect();
        let points = [found.map.valid.nx, found.map.valid.ny];
        (found.map.chart, charts, Some(regions), Some(points))
    } else {
        let chart = map::chart(&model.mesh, &model.surface)?;
        (chart, Vec::new(), None, None)
    };
    // The rest merged both ways; the merge whose rectangles need the shorter path (passes
    // a flat side step apart, as long as the side they run along) is cut.
    let candidate = |merge| {
        let rects = rects::rectangles(&chart.face_rects, &boxes, chart.line_tol(), merge);
        Cut::new(model, &chart, rects, opts, with_features)
    };
    let (largest, rows) = (candidate(Merge::Largest)?, candidate(Merge::Rows)?);
    // (An estimate that is not a number is no better than the other.)
    let chosen = if rows.estimated_path_mm(step) < largest.estimated_path_mm(step) {
        rows
    } else {
        largest
    };
    let seams = chosen.seams(model, opts, chart.line_tol());
    let Cut {
        rects,
        layout,
        crossfeeds,
        ..
    } = chosen;
    let cut = model.with_layout(layout);
    let name = if with_features {
        "watershed"
    } else {
        "multi-rectangle"
    };
    let mut planned = pipeline::plan_with(&cut, opts, progress, DRAFT_SHARE, |p| {
        isoparametric::draft_with(&cut, opts, p, Some(&crossfeeds), &seams, name)
    })?;
    let kinds: Vec<FillKind> = rects
        .iter()
        .map(|r| {
            match r
                .feature
                .and_then(|l| regions.as_ref()?.get(l as usize - 1))
                .map(|x| x.kind)
            {
                Some(FeatureKind::Convex) => FillKind::Convex,
                Some(FeatureKind::Concave) => FillKind::Concave,
                None => FillKind::Background,
            }
        })
        .collect();
    // Each region's area: its rectangles' on the surface.
    let regions = regions.map(|mut regions| {
        for (k, r) in rects.iter().enumerate() {
            if let Some(x) = r.feature.and_then(|l| regions.get_mut(l as usize - 1)) {
                x.area_mm2 += Footprint {
                    patch: k as u32,
                    rect: [0.0, 1.0, 0.0, 1.0],
                }
                .area_mm2_fine(&cut, AREA_SAMPLES);
            }
        }
        regions
    });
    // Each rectangle was cut the way given (the transit corners keep a given direction).
    planned.watershed_layer = Some(Layer::of(&cut, &kinds, &crossfeeds));
    planned.watershed = Some(WatershedStats {
        regions,
        map_points,
        rectangle_regions: rects.iter().map(|r| r.feature.map(|l| l - 1)).collect(),
    });
    planned.layout = Some(cut.layout.clone());
    Ok(planned)
}
