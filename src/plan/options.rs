//! Planning options: the tool, the accuracy asked for, and the feeds. One struct, each field
//! in the unit its name says, each default chosen to work on every sample model.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

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
    /// Height of the safe plane above the model's highest point, for rapids (mm).
    /// Default 5 mm.
    pub clearance_mm: f64,
    /// Cutting feed (mm/min). Default 1000 mm/min.
    pub feed_mm_min: f64,
    /// Feed for plunging into the first cut (mm/min). Default 300 mm/min.
    pub plunge_feed_mm_min: f64,
    /// Spindle speed (rev/min). Default 12000 rpm.
    pub spindle_rpm: f64,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            tool_radius_mm: 1.0,
            scallop_mm: 0.01,
            chordal_mm: 0.005,
            clearance_mm: 5.0,
            feed_mm_min: 1000.0,
            plunge_feed_mm_min: 300.0,
            spindle_rpm: 12000.0,
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
        positive("spindle_rpm", self.spindle_rpm, "rev/min")?;
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
