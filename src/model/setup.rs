//! How a model file is placed for machining: the unit its numbers are in (for files that do
//! not say), a scale, which of its axes points up, a turn about the vertical in 90° steps,
//! and whether its lowest point is put on the table (Z 0).
//!
//! Every step is a similarity (a uniform scale and a rotation, then a shift), applied to the
//! control points: T-spline and subdivision surfaces are affine invariant, so the surface
//! moves exactly with them and nothing is re-approximated.
//!
//! Owns: the set-up options and applying them to a T-mesh. Must not: parse files.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::tmesh::{ControlPoint, TMesh};
use serde::{Deserialize, Serialize};

/// A unit of length a file's numbers may be in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    Mm,
    Cm,
    M,
    Inch,
}

impl LengthUnit {
    /// Every unit, as the CLI and the page list them.
    pub const ALL: [LengthUnit; 4] = [
        LengthUnit::Mm,
        LengthUnit::Cm,
        LengthUnit::M,
        LengthUnit::Inch,
    ];

    /// Millimetres in one of it.
    pub fn mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::Cm => 10.0,
            LengthUnit::M => 1000.0,
            LengthUnit::Inch => 25.4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            LengthUnit::Mm => "mm",
            LengthUnit::Cm => "cm",
            LengthUnit::M => "m",
            LengthUnit::Inch => "inch",
        }
    }

    /// The unit called `name`; the error lists the names.
    pub fn parse(name: &str) -> Result<LengthUnit> {
        LengthUnit::ALL
            .into_iter()
            .find(|u| u.name() == name)
            .ok_or_else(|| {
                Error::param(
                    "model_units",
                    format!("`{name}` is not a unit; use mm, cm, m or inch"),
                )
            })
    }
}

/// Which of the file's axes points up (becomes +Z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Up {
    /// +Z up, as machines have it (nothing changes).
    #[default]
    Z,
    /// +Y up, as most modelling and games tools write (OBJ from Blender, Maya, ...): the
    /// file's (x, y, z) becomes (x, −z, y), a quarter turn about X.
    Y,
}

impl Up {
    pub fn name(self) -> &'static str {
        match self {
            Up::Z => "z",
            Up::Y => "y",
        }
    }

    /// The up axis called `name`; the error lists the names.
    pub fn parse(name: &str) -> Result<Up> {
        match name {
            "z" | "Z" => Ok(Up::Z),
            "y" | "Y" => Ok(Up::Y),
            other => Err(Error::param(
                "up",
                format!(
                    "`{other}` is not an up axis; use z (machines) or y (most modelling tools)"
                ),
            )),
        }
    }
}

/// How a model is placed. The default changes nothing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImportSetup {
    /// The unit the file's numbers are in, for files that do not say (OBJ); `None`: as the
    /// file says, or mm.
    pub model_units: Option<LengthUnit>,
    /// Factor on top of the unit (1: as modelled).
    pub scale: f64,
    /// The file's up axis.
    pub up: Up,
    /// Turn about +Z after the up axis, counter-clockwise seen from above (0, 90, 180 or
    /// 270 degrees).
    pub rotate_deg: u32,
    /// Moves the model along Z so its lowest point is at Z 0 (the table).
    pub on_table: bool,
    /// A `model_units` other than what the file says is an error (the CLI, where it was
    /// typed for this file); otherwise it is left unused for such files (the page, where
    /// one setting serves every file opened).
    pub strict_units: bool,
}

impl Default for ImportSetup {
    fn default() -> Self {
        ImportSetup {
            model_units: None,
            scale: 1.0,
            up: Up::Z,
            rotate_deg: 0,
            on_table: false,
            strict_units: false,
        }
    }
}

impl ImportSetup {
    /// Checks the values; errors name the field.
    pub fn validate(&self) -> Result<()> {
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(Error::param(
                "scale",
                format!("must be a positive number, got {}", self.scale),
            ));
        }
        if self.rotate_deg % 90 != 0 || self.rotate_deg >= 360 {
            return Err(Error::param(
                "rotate_deg",
                format!(
                    "turns in quarter turns: 0, 90, 180 or 270, got {}",
                    self.rotate_deg
                ),
            ));
        }
        Ok(())
    }

    /// The factor from the file's numbers (as its reader gives them) to millimetres, given
    /// what the file said about its unit (`declared_mm`: millimetres per unit, `None` for a
    /// file that does not say, whose numbers are then mm unless `model_units` says
    /// otherwise). Readers of files that say their unit convert to mm themselves; a
    /// `model_units` other than what such a file says is an error naming both.
    pub fn factor(&self, declared_mm: Option<f64>) -> Result<f64> {
        self.validate()?;
        match (declared_mm, self.model_units) {
            (Some(d), Some(u)) if self.strict_units && (d - u.mm()).abs() > 1e-12 * d => {
                Err(Error::param(
                    "model_units",
                    format!(
                        "the file says its numbers are in units of {d} mm, not {}: the model unit is for files that do not say (OBJ); use the scale to resize it",
                        u.name()
                    ),
                ))
            }
            (Some(_), _) => Ok(self.scale),
            (None, u) => Ok(u.map_or(1.0, LengthUnit::mm) * self.scale),
        }
    }

    /// The rotation part: up axis, then the turn about Z.
    fn rotate(&self, v: Vector3) -> Vector3 {
        let v = match self.up {
            Up::Z => v,
            Up::Y => Vector3::new(v.x, -v.z, v.y),
        };
        match self.rotate_deg {
            90 => Vector3::new(-v.y, v.x, v.z),
            180 => Vector3::new(-v.x, -v.y, v.z),
            270 => Vector3::new(v.y, -v.x, v.z),
            _ => v,
        }
    }

    /// `mesh` scaled by `factor` (from [`ImportSetup::factor`]) and rotated; the shift onto
    /// the table needs the surface and is [`shifted`]'s.
    pub fn apply(&self, mesh: &TMesh, factor: f64) -> Result<TMesh> {
        mesh.map_points(|p| ControlPoint {
            point: Point3::from(self.rotate(p.point.coords * factor)),
            weight: p.weight,
        })
    }

    /// Text for the model summary: what was done to a file that said its unit or not
    /// (`declared`), or "as modelled".
    pub fn describe(&self, declared: bool) -> String {
        let mut parts = Vec::new();
        match self.model_units {
            Some(u) if !declared => parts.push(format!("numbers in {}", u.name())),
            _ => {}
        }
        if self.scale != 1.0 {
            parts.push(format!("scaled × {}", self.scale));
        }
        if self.up == Up::Y {
            parts.push("Y up turned to Z up".into());
        }
        if self.rotate_deg != 0 {
            parts.push(format!("turned {}° about Z", self.rotate_deg));
        }
        if self.on_table {
            parts.push("lowest point on the table (Z 0)".into());
        }
        if parts.is_empty() {
            "as modelled".into()
        } else {
            parts.join(", ")
        }
    }
}

/// `mesh` moved by `shift` (mm).
pub fn shifted(mesh: &TMesh, shift: Vector3) -> Result<TMesh> {
    mesh.map_points(|p| ControlPoint {
        point: p.point + shift,
        weight: p.weight,
    })
}
