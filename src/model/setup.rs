//! How a model file is placed for machining: the unit its numbers are in (for files that do
//! not say), a scale, which of its axes points up, a turn about the vertical in 90° steps,
//! whether its lowest point is put on the table (Z 0), the stock block around it and where
//! on that block the program's zero is.
//!
//! Every step is a similarity (a uniform scale and a rotation, then a shift), applied to the
//! control points: T-spline and subdivision surfaces are affine invariant, so the surface
//! moves exactly with them and nothing is re-approximated.
//!
//! Owns: the set-up options and applying them to a T-mesh. Must not: parse files.

use crate::error::{Error, Result};
use crate::geom::{Aabb, Point3, Vector3};
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

/// Where the program's zero (X0 Y0 Z0 of the work offset) is put: the model is moved so that
/// this point is at the origin.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProgramZero {
    /// The model's own origin, as modelled and placed (nothing moves).
    #[default]
    Model,
    /// The centre of the stock's top face: the usual zero for a part probed from above.
    StockTopCentre,
    /// The front-left corner of the stock's top face (least X, least Y).
    StockTopCorner,
    /// The centre of the stock's bottom face (on the table).
    StockBottomCentre,
    /// The front-left corner of the stock's bottom face.
    StockBottomCorner,
    /// A point typed in the placed model's coordinates (mm).
    At([f64; 3]),
}

impl ProgramZero {
    /// The names the CLI and the page use (a typed point is `x,y,z` on the CLI).
    pub const NAMED: [(&'static str, ProgramZero); 5] = [
        ("model", ProgramZero::Model),
        ("stock-top-centre", ProgramZero::StockTopCentre),
        ("stock-top-corner", ProgramZero::StockTopCorner),
        ("stock-bottom-centre", ProgramZero::StockBottomCentre),
        ("stock-bottom-corner", ProgramZero::StockBottomCorner),
    ];

    /// The zero called `text`: a name, or three numbers `x,y,z` (mm).
    pub fn parse(text: &str) -> Result<ProgramZero> {
        if let Some((_, z)) = ProgramZero::NAMED.iter().find(|(n, _)| *n == text) {
            return Ok(*z);
        }
        let v: Vec<f64> = text
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .unwrap_or_default();
        match v[..] {
            [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(ProgramZero::At([x, y, z])),
            _ => Err(Error::param(
                "zero",
                format!(
                    "`{text}` is not a program zero; use {} or a point x,y,z in mm",
                    ProgramZero::NAMED.map(|(n, _)| n).join(", ")
                ),
            )),
        }
    }

    /// Where the zero is, in the placed model's coordinates, given the stock box.
    pub fn point(self, stock: &Aabb) -> Point3 {
        let centre = |k: usize| 0.5 * (stock.min[k] + stock.max[k]);
        let [lo, hi] = [stock.min, stock.max];
        match self {
            ProgramZero::Model => Point3::origin(),
            ProgramZero::StockTopCentre => Point3::new(centre(0), centre(1), hi[2]),
            ProgramZero::StockTopCorner => Point3::new(lo[0], lo[1], hi[2]),
            ProgramZero::StockBottomCentre => Point3::new(centre(0), centre(1), lo[2]),
            ProgramZero::StockBottomCorner => Point3::new(lo[0], lo[1], lo[2]),
            ProgramZero::At(p) => Point3::from(p),
        }
    }

    /// Where it is, in words (summary, program header).
    pub fn describe(self) -> String {
        match self {
            ProgramZero::Model => "the model's origin".into(),
            ProgramZero::StockTopCentre => "the centre of the stock's top".into(),
            ProgramZero::StockTopCorner => "the stock's top front-left corner (least X, Y)".into(),
            ProgramZero::StockBottomCentre => "the centre of the stock's bottom".into(),
            ProgramZero::StockBottomCorner => {
                "the stock's bottom front-left corner (least X, Y)".into()
            }
            ProgramZero::At([x, y, z]) => {
                format!("the model's point ({x}, {y}, {z}) mm as placed")
            }
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
    /// Stock beyond the part's box on each side, in X and Y (mm); 0: the stock is as wide
    /// as the part.
    pub stock_side_mm: f64,
    /// Stock above the part's highest point (mm). The stock's bottom is the part's lowest
    /// point.
    pub stock_top_mm: f64,
    /// Where the program's zero is; the model is moved to put it at the origin.
    pub zero: ProgramZero,
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
            stock_side_mm: 0.0,
            stock_top_mm: 0.0,
            zero: ProgramZero::Model,
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
        for (name, v) in [
            ("stock_side_mm", self.stock_side_mm),
            ("stock_top_mm", self.stock_top_mm),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::param(
                    name,
                    format!("stock beyond the part must be 0 mm or more, got {v}"),
                ));
            }
        }
        if let ProgramZero::At(p) = self.zero {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(Error::param(
                    "zero",
                    format!("the program zero {p:?} mm is not a point"),
                ));
            }
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
        if self.stock_side_mm > 0.0 || self.stock_top_mm > 0.0 {
            parts.push(format!(
                "stock {} mm beyond the sides, {} mm above",
                self.stock_side_mm, self.stock_top_mm
            ));
        }
        if self.zero != ProgramZero::Model {
            parts.push(format!("program zero at {}", self.zero.describe()));
        }
        if parts.is_empty() {
            "as modelled".into()
        } else {
            parts.join(", ")
        }
    }
}

/// The stock box around a part whose surface has the box `part` (mm).
pub fn stock_box(part: &Aabb, setup: &ImportSetup) -> Aabb {
    let s = setup.stock_side_mm;
    Aabb {
        min: [part.min[0] - s, part.min[1] - s, part.min[2]],
        max: [
            part.max[0] + s,
            part.max[1] + s,
            part.max[2] + setup.stock_top_mm,
        ],
    }
}

/// `mesh` moved by `shift` (mm).
pub fn shifted(mesh: &TMesh, shift: Vector3) -> Result<TMesh> {
    mesh.map_points(|p| ControlPoint {
        point: p.point + shift,
        weight: p.weight,
    })
}
