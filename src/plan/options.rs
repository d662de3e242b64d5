//! Planning options: the tool, the accuracy asked for, and the feeds. One struct, each field
//! in the unit its name says, each default chosen to work on every sample model.

use super::corners::Crossfeed;
use super::toolpath::MoveKind;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Lead of the tool axis from the surface normal in Gan et al. (2014), the `isfc` paper's
/// machining tests (degrees).
pub const PAPER_LEAD_DEG: f64 = 10.0;

/// Range of the largest axis step between cut points (degrees): below 0.5° the poses in
/// between multiply past use; above 45° the tool between two points is far from both.
pub const MIN_AXIS_STEP_DEG: f64 = 0.5;
pub const MAX_AXIS_STEP_DEG: f64 = 45.0;

/// What the planner is asked for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlanOptions {
    /// Ball-end radius (mm). Default 1 mm: a 2 mm ball-end mill, common for finishing moulds.
    pub tool_radius_mm: f64,
    /// Largest scallop (cusp) height left between adjacent passes (mm). Default 0.01 mm,
    /// a fine finish.
    pub scallop_mm: f64,
    /// Largest distance between a straight feed move and the surface curve it replaces
    /// (mm). Default 0.005 mm, half the default scallop.
    pub chordal_mm: f64,
    /// Gap kept between the tool (ball, shank and holder) and the model on rapids (mm):
    /// rapids between cuts run this high over what lies beneath them, and the safe plane
    /// (the first approach, the last retract, and every rapid with `full_retract`) lies this
    /// far above the model's highest point and its stock, and a ball diameter more. Default 5 mm.
    pub clearance_mm: f64,
    /// Every rapid between cuts at the safe plane, as high as the first and the last,
    /// instead of only as high as the clearance over what the tool passes above (the
    /// model beneath the ball, shank and holder, and the stock where it stands above the
    /// part). Default false: the shorter way, "minimum retraction".
    pub full_retract: bool,
    /// Cutting feed (mm/min). Default 1000 mm/min.
    pub feed_mm_min: f64,
    /// Feed for plunging into the first cut (mm/min). Default 300 mm/min.
    pub plunge_feed_mm_min: f64,
    /// Feed height: how far above the first point of a cut (measured along the way down
    /// to it) the rapid approach stops and the tool goes on at the plunge feed (mm).
    /// Default 2 mm, room for a stock allowance or a mis-set tool length to meet the tool
    /// at a feed, not at the rapid rate.
    pub feed_height_mm: f64,
    /// Most CL points a plan may have, estimated before planning
    /// ([`super::budget::estimate`]); settings estimated beyond it are refused with the
    /// estimate. Default 2 000 000: about 1.2 GB at the page's cost per point, what a
    /// browser tab can hold.
    pub max_cl_points: u64,
    /// Spindle speed (rev/min). Default 12000 rpm.
    pub spindle_rpm: f64,
    /// Work offset the program runs in: 54 to 59 for G54–G59 (Heidenhain: preset 1–6,
    /// Siemens G54–G57 and G505/G506 for the last two). Default 54: the program's zero is
    /// where the operator set G54.
    pub work_offset: u8,
    /// Patch the path starts on. Default patch 0.
    pub start_patch: Option<u32>,
    /// Patch the path should finish on. Default: wherever the shortest order ends.
    pub finish_patch: Option<u32>,
    /// Crossfeed direction for every patch (`U`: passes are lines u = const). Default: per
    /// patch, the one with fewer, longer passes.
    pub crossfeed: Option<Crossfeed>,
    /// Lead angle: the tool axis tilted forward along the feed (degrees). Default 0°.
    pub lead_deg: f64,
    /// Tilt angle: the tool axis tilted sideways, across the feed (degrees). Default 0°.
    pub tilt_deg: f64,
    /// Radius of the shank above the ball (mm). Default: the ball radius.
    pub shank_radius_mm: Option<f64>,
    /// Cutting length above the ball centre: the fluted part of radius `tool_radius_mm`,
    /// which cuts and so may touch steep walls (mm). Default: four ball radii.
    pub flute_length_mm: Option<f64>,
    /// Length of the shank from the ball centre to the holder (mm). Default 20 mm.
    pub shank_length_mm: f64,
    /// Radius of the holder (mm). Default 10 mm.
    pub holder_radius_mm: f64,
    /// Length of the holder (mm). Default 40 mm.
    pub holder_length_mm: f64,
    /// Largest tilt of the tool axis from +Z the planner may use to clear the shank and
    /// holder (degrees). Default 60°; 0° plans three-axis (the axis stays +Z).
    pub max_tilt_deg: f64,
    /// Largest turn of the tool axis from one cut point to the next (degrees): larger
    /// turns are first spread over the points around them, then split by poses in
    /// between. Default 5°: the machine interpolates its rotary axes linearly between
    /// points, so the tool between them stays close to the poses checked for clearance.
    pub max_axis_step_deg: f64,
    /// Which strategy decides what to cut. Default `isoparametric` (patch-ordered zig-zags,
    /// Shang et al. 2020); `isfc`: one closed space-filling curve over the whole surface
    /// (Gan et al. 2014).
    pub strategy: Strategy,
    /// `isfc` only: the plain space-filling curve, without the parity repair and the corner
    /// compensation, to measure what they bring. Default false.
    pub isfc_plain: bool,
    /// `isfc` only: weight of the length change in a link's cost (eq. 9, per mm).
    /// Default 1.
    pub isfc_length_weight: f64,
    /// `isfc` only: weight of the tool-axis change in a link's cost (eq. 9, per unit of
    /// `‖ΔV‖`). Default 1.
    pub isfc_axis_weight: f64,
    /// `isoplanar` only: direction of the slicing planes' normal in the XY plane (degrees
    /// from +X). Default 0°: planes parallel to YZ, passes running roughly along Y.
    pub slice_angle_deg: f64,
    /// `isoplanar` only: deform the CL surface so that constant plane spacing leaves
    /// near-constant scallop (Yuan & Shao 2012). Default true; false: the constant-spacing
    /// baseline, planes `2 sqrt(2 r h − h²)` apart in plan view.
    pub isoplanar_deform: bool,
    /// `isoplanar` only: the paper's shear form of the deformation ratio (eq. 9) instead of
    /// the exact plane form. Default false.
    pub isoplanar_shear: bool,
    /// `isoplanar` only, five-axis: the tool axis along the area-weighted normal of the CL
    /// mesh's facets within a tool radius of the ball centre (Yuan & Shao 2012, eq. 12),
    /// where that axis keeps the shank and holder clear and tilts no more than
    /// `max_tilt_deg`; elsewhere the usual axis. Default false.
    pub facet_normal_axis: bool,
}

/// The strategies: what to cut, in which order. The shared pipeline decides how.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Strategy {
    /// Patch-ordered, non-retraction isoparametric zig-zags (Shang et al. 2020).
    #[default]
    Isoparametric,
    /// Improved space-filling curve (Gan et al. 2014).
    Isfc,
    /// Watershed feature regions and optimised multi-rectangles (Liu et al. 2020): a
    /// rectangle per feature box and maximal rectangles of the rest, each cut along its
    /// longer side.
    Watershed,
    /// The baseline of Liu et al.: the domain's maximal rectangles without feature regions,
    /// all cut in one direction.
    #[serde(rename = "multi-rectangle")]
    MultiRectangle,
    /// Iso-planar slicing of the deformed CL surface (Yuan & Shao 2012): parallel planes,
    /// denser where the surface is steep or concave.
    Isoplanar,
}

impl Strategy {
    /// Every strategy, in the order the CLI and the page list them.
    pub const ALL: [Strategy; 5] = [
        Strategy::Isoparametric,
        Strategy::Isfc,
        Strategy::Watershed,
        Strategy::MultiRectangle,
        Strategy::Isoplanar,
    ];

    /// Its name in options, the CLI and the report.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Isoparametric => "isoparametric",
            Strategy::Isfc => "isfc",
            Strategy::Watershed => "watershed",
            Strategy::MultiRectangle => "multi-rectangle",
            Strategy::Isoplanar => "isoplanar",
        }
    }

    /// The strategy called `name`; the error lists the names.
    pub fn parse(name: &str) -> Result<Self> {
        Strategy::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| {
                Error::param(
                    "strategy",
                    format!(
                        "unknown strategy `{name}`; the strategies are {}",
                        Strategy::ALL.map(|s| s.name()).join(", ")
                    ),
                )
            })
    }
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            tool_radius_mm: 1.0,
            scallop_mm: 0.01,
            chordal_mm: 0.005,
            clearance_mm: 5.0,
            full_retract: false,
            feed_mm_min: 1000.0,
            plunge_feed_mm_min: 300.0,
            feed_height_mm: 2.0,
            max_cl_points: 2_000_000,
            spindle_rpm: 12000.0,
            work_offset: 54,
            start_patch: None,
            finish_patch: None,
            crossfeed: None,
            lead_deg: 0.0,
            tilt_deg: 0.0,
            shank_radius_mm: None,
            flute_length_mm: None,
            shank_length_mm: 20.0,
            holder_radius_mm: 10.0,
            holder_length_mm: 40.0,
            max_tilt_deg: 60.0,
            max_axis_step_deg: 5.0,
            strategy: Strategy::Isoparametric,
            isfc_plain: false,
            isfc_length_weight: 1.0,
            isfc_axis_weight: 1.0,
            slice_angle_deg: 0.0,
            isoplanar_deform: true,
            isoplanar_shear: false,
            facet_normal_axis: false,
        }
    }
}

impl PlanOptions {
    /// Sets the ball-end radius (mm).
    pub fn with_tool_radius(mut self, mm: f64) -> Self {
        self.tool_radius_mm = mm;
        self
    }
    /// Sets the scallop height limit (mm).
    pub fn with_scallop(mut self, mm: f64) -> Self {
        self.scallop_mm = mm;
        self
    }
    /// Sets the chordal tolerance (mm).
    pub fn with_chordal(mut self, mm: f64) -> Self {
        self.chordal_mm = mm;
        self
    }
    /// Sets the clearance above the model (mm).
    pub fn with_clearance(mut self, mm: f64) -> Self {
        self.clearance_mm = mm;
        self
    }
    /// Sets the cutting feed (mm/min).
    pub fn with_feed(mut self, mm_min: f64) -> Self {
        self.feed_mm_min = mm_min;
        self
    }
    /// Sets the feed height above the first point of each cut (mm).
    pub fn with_feed_height(mut self, mm: f64) -> Self {
        self.feed_height_mm = mm;
        self
    }

    /// The feed a move of this kind runs at (mm/min); `None` for rapid moves.
    pub fn feed_for(&self, kind: MoveKind) -> Option<f64> {
        if kind.rapid() {
            None
        } else if kind.at_plunge_feed() {
            Some(self.plunge_feed_mm_min)
        } else {
            Some(self.feed_mm_min)
        }
    }

    /// Sets the shank and holder (mm).
    pub fn with_holder(
        mut self,
        shank_radius: f64,
        shank_length: f64,
        holder_radius: f64,
        holder_length: f64,
    ) -> Self {
        self.shank_radius_mm = Some(shank_radius);
        self.shank_length_mm = shank_length;
        self.holder_radius_mm = holder_radius;
        self.holder_length_mm = holder_length;
        self
    }
    /// Sets lead and tilt (degrees).
    pub fn with_lead_tilt(mut self, lead_deg: f64, tilt_deg: f64) -> Self {
        self.lead_deg = lead_deg;
        self.tilt_deg = tilt_deg;
        self
    }
    /// The tool axis of Gan et al. (2014): inclined [`PAPER_LEAD_DEG`] from the surface
    /// normal, forward along the feed (a five-axis machine; where that axis would collide,
    /// the collision-free one closest to +Z as usual).
    pub fn with_paper_axis(self) -> Self {
        self.with_lead_tilt(PAPER_LEAD_DEG, 0.0)
    }
    /// Sets the strategy.
    pub fn with_strategy(mut self, strategy: Strategy) -> Self {
        self.strategy = strategy;
        self
    }
    /// Sets the start and suggested finish patches.
    pub fn with_patches(mut self, start: Option<u32>, finish: Option<u32>) -> Self {
        self.start_patch = start;
        self.finish_patch = finish;
        self
    }

    /// The cutting length above the ball centre, defaulting to four ball radii (mm).
    pub fn flute_length(&self) -> f64 {
        self.flute_length_mm.unwrap_or(4.0 * self.tool_radius_mm)
    }

    /// How deep a straight move may cut into the surface (mm): the chordal tolerance, but
    /// never more than [`MAX_OVERCUT_MM`], so that plans pass a verification whose gouge
    /// tolerance is that much.
    pub fn overcut_mm(&self) -> f64 {
        self.chordal_mm.min(MAX_OVERCUT_MM)
    }

    /// The shank radius, defaulting to the ball radius (mm).
    pub fn shank_radius(&self) -> f64 {
        self.shank_radius_mm.unwrap_or(self.tool_radius_mm)
    }

    /// Checks every field; the error names the field and the range it must be in.
    pub fn validate(&self) -> Result<()> {
        fn positive(name: &'static str, v: f64, unit: &str) -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::param(
                    name,
                    format!("must be a positive number of {unit}, got {v}"),
                ))
            }
        }
        positive("tool_radius_mm", self.tool_radius_mm, "mm")?;
        positive("scallop_mm", self.scallop_mm, "mm")?;
        positive("chordal_mm", self.chordal_mm, "mm")?;
        positive("clearance_mm", self.clearance_mm, "mm")?;
        positive("feed_mm_min", self.feed_mm_min, "mm/min")?;
        positive("plunge_feed_mm_min", self.plunge_feed_mm_min, "mm/min")?;
        if self.max_cl_points == 0 {
            return Err(Error::param(
                "max_cl_points",
                "must be at least 1 (the most CL points a plan may have)",
            ));
        }
        if !(self.feed_height_mm.is_finite() && self.feed_height_mm >= 0.0) {
            return Err(Error::param(
                "feed_height_mm",
                format!(
                    "must be 0 mm or more (the height above a cut where the rapid approach \
                     stops), got {}",
                    self.feed_height_mm
                ),
            ));
        }
        positive("spindle_rpm", self.spindle_rpm, "rev/min")?;
        self.check_work_offset()?;
        positive("shank_length_mm", self.shank_length_mm, "mm")?;
        positive("holder_radius_mm", self.holder_radius_mm, "mm")?;
        positive("holder_length_mm", self.holder_length_mm, "mm")?;
        positive("shank_radius_mm", self.shank_radius(), "mm")?;
        if !(self.flute_length().is_finite()
            && self.flute_length() >= 0.0
            && self.flute_length() < self.shank_length_mm)
        {
            // Unset, the flute is four ball radii: a big ball outgrows the default shank.
            let why = if self.flute_length_mm.is_none() {
                format!(
                    "by default four ball radii, {} mm, it must be shorter than the shank length {} mm: give a longer shank (`--shank-length`, the page's shank length) or a shorter flute",
                    self.flute_length(),
                    self.shank_length_mm
                )
            } else {
                format!(
                    "{} mm must be at least 0 and shorter than the shank length {} mm",
                    self.flute_length(),
                    self.shank_length_mm
                )
            };
            return Err(Error::param("flute_length_mm", why));
        }
        for (name, v) in [("lead_deg", self.lead_deg), ("tilt_deg", self.tilt_deg)] {
            if !(v.is_finite() && v.abs() < 80.0) {
                return Err(Error::param(
                    name,
                    format!("must be between -80° and 80°, got {v}"),
                ));
            }
        }
        if !(self.max_axis_step_deg.is_finite()
            && (MIN_AXIS_STEP_DEG..=MAX_AXIS_STEP_DEG).contains(&self.max_axis_step_deg))
        {
            return Err(Error::param(
                "max_axis_step_deg",
                format!(
                    "must be from {MIN_AXIS_STEP_DEG}° to {MAX_AXIS_STEP_DEG}° (the largest \
                     turn of the tool axis between two cut points), got {}°",
                    self.max_axis_step_deg
                ),
            ));
        }
        if !(self.max_tilt_deg.is_finite() && (0.0..=MAX_TILT_DEG).contains(&self.max_tilt_deg)) {
            return Err(Error::param(
                "max_tilt_deg",
                format!(
                    "must be between 0° and {MAX_TILT_DEG}°, got {}",
                    self.max_tilt_deg
                ),
            ));
        }
        if self.holder_radius_mm < self.shank_radius() {
            return Err(Error::param(
                "holder_radius_mm",
                format!(
                    "{} mm is smaller than the shank radius {} mm",
                    self.holder_radius_mm,
                    self.shank_radius()
                ),
            ));
        }
        for (name, v) in [
            ("isfc_length_weight", self.isfc_length_weight),
            ("isfc_axis_weight", self.isfc_axis_weight),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::param(name, format!("must be a number ≥ 0, got {v}")));
            }
        }
        if !(self.slice_angle_deg.is_finite() && self.slice_angle_deg.abs() <= 360.0) {
            return Err(Error::param(
                "slice_angle_deg",
                format!(
                    "must be between -360° and 360°, got {}",
                    self.slice_angle_deg
                ),
            ));
        }
        if self.isfc_length_weight + self.isfc_axis_weight <= 0.0 {
            return Err(Error::param(
                "isfc_length_weight",
                "the length and axis weights of a link's cost cannot both be 0",
            ));
        }
        if self.scallop_mm >= self.tool_radius_mm {
            return Err(Error::param(
                "scallop_mm",
                format!(
                    "{} mm is not smaller than the tool radius {} mm",
                    self.scallop_mm, self.tool_radius_mm
                ),
            ));
        }
        Ok(())
    }
}

/// Deepest a straight move may cut into the surface whatever the chordal tolerance (mm):
/// two micrometres, the gouge tolerance a plan is verified with (`verify::MAX_GOUGE_TOLERANCE_MM`).
pub const MAX_OVERCUT_MM: f64 = 0.002;

/// Largest tool-axis tilt from +Z a plan may ask for (degrees): beyond 90° the tool comes
/// from below the horizontal, as a swivelling table tilted past upright presents a part's
/// underside; the machine's own limits then decide (its post says which axis overruns).
pub const MAX_TILT_DEG: f64 = 135.0;

impl PlanOptions {
    /// Checks the work offset alone (the post writes programs from options it does not
    /// otherwise re-check).
    pub fn check_work_offset(&self) -> Result<()> {
        if (54..=59).contains(&self.work_offset) {
            Ok(())
        } else {
            Err(Error::param(
                "work_offset",
                format!(
                    "must be one of 54 to 59 (G54–G59), got {}",
                    self.work_offset
                ),
            ))
        }
    }
}
