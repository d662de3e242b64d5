//! The watershed strategies: the domain cut into rectangles (feature boxes and maximal
//! rectangles of the rest, or for the baseline the rest alone), each rectangle a patch cut
//! by the patch-ordered zig-zags, along its longer side (eq. 21–22) or, for the baseline,
//! all in one direction. Everything after the rectangles (side and forward steps, order,
//! links, axes, lifting, air moves, rest area) is the isoparametric draft and the shared
//! pipeline.

use super::{features, map, rects, FeatureKind, DEFAULT_TOR};
use crate::error::{Error, Result};
use crate::layout::PatchLayout;
use crate::model::Model;
use crate::plan::corners::Crossfeed;
use crate::plan::draft::Footprint;
use crate::plan::isoparametric::{self, PatchView};
use crate::plan::pipeline::{self, Planned};
use crate::plan::PlanOptions;
use serde::{Deserialize, Serialize};

/// A feature region as the report gives it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegionReport {
    pub kind: FeatureKind,
    /// Area of its rectangles on the surface (mm²).
    pub area_mm2: f64,
    /// Boxes PolyBoundingBox made of it.
    pub boxes: usize,
}

/// What the watershed strategies found and made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WatershedStats {
    /// Feature regions (none for the multi-rectangle baseline).
    pub regions: Vec<RegionReport>,
    /// Per rectangle (patch), the feature region it belongs to (index into `regions`).
    pub rectangle_regions: Vec<Option<u32>>,
    /// Grid points of the curvature map.
    pub map_points: [usize; 2],
}

/// Share of the progress bar the draft takes (the pipeline takes the rest).
const DRAFT_SHARE: f64 = 0.7;
/// Samples per side of a rectangle for its area.
const AREA_SAMPLES: usize = 16;

/// Plans `model` with the watershed strategy (`with_features`) or its multi-rectangle
/// baseline. Errors on a model whose domain does not lie flat in one chart.
pub fn plan(
    model: &Model,
    opts: &PlanOptions,
    progress: &mut dyn FnMut(f64) -> bool,
    with_features: bool,
) -> Result<Planned> {
    opts.validate()?;
    let found = features(model, map::DEFAULT_PER_UNIT)?;
    let rects: Vec<rects::ChartRect> = if with_features {
        found.rectangles(DEFAULT_TOR)
    } else {
        let size = found
            .map
            .face_rects
            .iter()
            .map(|r| (r[1] - r[0]).max(r[3] - r[2]))
            .fold(0.0f64, f64::max);
        rects::rectangles(&found.map.face_rects, &[], 1e-9 * size.max(1.0))
    };
    let chart: Vec<[f64; 4]> = rects.iter().map(|r| r.chart).collect();
    let layout = PatchLayout::from_chart_rects(&model.surface, &found.map.placements, &chart)
        .ok_or_else(|| Error::Degenerate {
            location: "the domain's rectangles".into(),
            message: "a rectangle of the domain is not filled by faces".into(),
        })?;
    let cut = model.with_layout(layout);
    let views: Vec<PatchView> = cut
        .layout
        .patches
        .iter()
        .enumerate()
        .map(|(index, patch)| PatchView {
            index,
            patch,
            surface: &cut.surface,
            side: cut.tool_side(),
        })
        .collect();
    // Along the longer side per rectangle (eq. 21–22); the baseline one way for all, the
    // way most of the area prefers.
    let own: Vec<Crossfeed> = views
        .iter()
        .map(isoparametric::preferred_crossfeed)
        .collect();
    let crossfeeds: Vec<Crossfeed> = match (opts.crossfeed, with_features) {
        (Some(c), _) => vec![c; views.len()],
        (None, true) => own,
        (None, false) => {
            let area = |k: usize| {
                let r = &chart[k];
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
            vec![c; views.len()]
        }
    };
    let name = if with_features {
        "watershed"
    } else {
        "multi-rectangle"
    };
    let mut planned = pipeline::plan_with(&cut, opts, progress, DRAFT_SHARE, |p| {
        isoparametric::draft_with(&cut, opts, p, Some(&crossfeeds), name)
    })?;
    let regions = found
        .features
        .iter()
        .filter(|_| with_features)
        .map(|f| {
            let label = f.region.label;
            let area_mm2 = rects
                .iter()
                .enumerate()
                .filter(|(_, r)| r.feature == Some(label))
                .map(|(k, _)| {
                    Footprint {
                        patch: k as u32,
                        rect: [0.0, 1.0, 0.0, 1.0],
                    }
                    .area_mm2_fine(&cut, AREA_SAMPLES)
                })
                .sum();
            RegionReport {
                kind: f.kind,
                area_mm2,
                boxes: 0,
            }
        })
        .collect::<Vec<_>>();
    let mut regions = regions;
    if with_features {
        for (label, _, _) in found.boxes(DEFAULT_TOR) {
            if let Some(r) = regions.get_mut(label as usize - 1) {
                r.boxes += 1;
            }
        }
    }
    planned.watershed = Some(WatershedStats {
        regions,
        rectangle_regions: rects.iter().map(|r| r.feature.map(|l| l - 1)).collect(),
        map_points: [found.map.valid.nx, found.map.valid.ny],
    });
    planned.layout = Some(cut.layout.clone());
    Ok(planned)
}
