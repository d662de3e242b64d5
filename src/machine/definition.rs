//! Machine definitions: the JSON file users edit, and the built-in machines.
//!
//! Owns: reading, writing and validating `tspath-machine` JSON. Must not: compute
//! kinematics (that is [`super::kinematics`]).
//!
//! ```json
//! {
//!   "format": "tspath-machine", "version": 1,
//!   "name": "table-table-ac",
//!   "description": "trunnion A (about X) carrying a rotary table C (about Z)",
//!   "rotaries": [
//!     {"name": "A", "mount": "table", "axis": [1, 0, 0], "pivot_mm": [0, 0, -80],
//!      "direction": 1, "limits_deg": [-120, 120]},
//!     {"name": "C", "mount": "table", "axis": [0, 0, 1], "pivot_mm": [0, 0, 0],
//!      "direction": 1, "limits_deg": null}
//!   ],
//!   "linear_limits_mm": {"x": [-400, 400], "y": null, "z": null},
//!   "max_rotary_feed_deg_min": 5400,
//!   "safe_z_machine_mm": 0,
//!   "dynamics": {"rapid_mm_min": 12000, "linear_accel_mm_s2": 1500,
//!                "linear_jerk_mm_s3": 30000, "rotary_accel_deg_s2": 600,
//!                "rotary_jerk_deg_s3": 12000, "junction_deviation_mm": 0.01}
//! }
//! ```
//! The README's "Machines" section documents every field.

use super::kinematics::{LinearLimits, Machine, Mount, Rotary};
use super::motion::Dynamics;
use crate::error::{Error, Result};
use crate::geom::Vector3;
use serde::{Deserialize, Serialize};

const FORMAT: &str = "tspath-machine";
const VERSION: u32 = 1;

/// Default fastest rotary motion (degrees per minute): 15 rev/min, a common trunnion figure.
const DEFAULT_ROTARY_FEED_DEG_MIN: f64 = 5400.0;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RotaryFile {
    name: String,
    mount: Mount,
    axis: [f64; 3],
    #[serde(default)]
    pivot_mm: [f64; 3],
    #[serde(default = "one")]
    direction: f64,
    #[serde(default)]
    limits_deg: Option<[f64; 2]>,
}

fn one() -> f64 {
    1.0
}

#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LimitsFile {
    #[serde(default)]
    x: Option<[f64; 2]>,
    #[serde(default)]
    y: Option<[f64; 2]>,
    #[serde(default)]
    z: Option<[f64; 2]>,
}

fn default_rotary_feed() -> f64 {
    DEFAULT_ROTARY_FEED_DEG_MIN
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineFile {
    format: String,
    version: u32,
    name: String,
    #[serde(default)]
    description: String,
    #[serde(default)]
    rotaries: Vec<RotaryFile>,
    #[serde(default)]
    linear_limits_mm: Option<LimitsFile>,
    #[serde(default = "default_rotary_feed")]
    max_rotary_feed_deg_min: f64,
    #[serde(default)]
    safe_z_machine_mm: f64,
    /// Rates and limits for the machining time; each field defaults on its own.
    #[serde(default)]
    dynamics: Dynamics,
}

/// A built-in machine: its name and what it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineInfo {
    pub name: &'static str,
    pub description: &'static str,
}

/// The built-in machines.
pub const MACHINES: &[MachineInfo] = &[
    MachineInfo {
        name: "3-axis",
        description: "three linear axes, tool axis fixed at +Z",
    },
    MachineInfo {
        name: "table-table-ac",
        description: "swivelling trunnion A (about X, -120° to 120°, axis 80 mm below program zero) carrying an endless rotary table C (about Z through program zero)",
    },
    MachineInfo {
        name: "table-table-bc",
        description: "trunnion B (about Y, -110° to 110°, axis 60 mm below program zero) carrying an endless rotary table C (about Z through program zero)",
    },
    MachineInfo {
        name: "head-table-bc",
        description: "spindle head tilting about Y (B, -100° to 100°, pivot 150 mm above the tool tip) over an endless rotary table C (about Z through program zero)",
    },
];

fn rotary(
    name: char,
    mount: Mount,
    axis: [f64; 3],
    pivot: [f64; 3],
    limits: Option<(f64, f64)>,
) -> Rotary {
    Rotary {
        name,
        mount,
        axis: Vector3::from(axis),
        pivot_mm: Vector3::from(pivot),
        direction: 1.0,
        limits_deg: limits,
    }
}

/// A built-in machine by name.
pub fn builtin(name: &str) -> Result<Machine> {
    let info = MACHINES.iter().find(|m| m.name == name).ok_or_else(|| {
        Error::param(
            "machine",
            format!(
                "`{name}` is neither a built-in machine ({}) nor a machine JSON file",
                MACHINES
                    .iter()
                    .map(|m| m.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
    })?;
    let rotaries = match name {
        "table-table-ac" => vec![
            rotary(
                'A',
                Mount::Table,
                [1.0, 0.0, 0.0],
                [0.0, 0.0, -80.0],
                Some((-120.0, 120.0)),
            ),
            rotary('C', Mount::Table, [0.0, 0.0, 1.0], [0.0; 3], None),
        ],
        "table-table-bc" => vec![
            rotary(
                'B',
                Mount::Table,
                [0.0, 1.0, 0.0],
                [0.0, 0.0, -60.0],
                Some((-110.0, 110.0)),
            ),
            rotary('C', Mount::Table, [0.0, 0.0, 1.0], [0.0; 3], None),
        ],
        "head-table-bc" => vec![
            rotary(
                'B',
                Mount::Head,
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 150.0],
                Some((-100.0, 100.0)),
            ),
            rotary('C', Mount::Table, [0.0, 0.0, 1.0], [0.0; 3], None),
        ],
        _ => Vec::new(),
    };
    // A trunnion carries the part: heavier to swing than a head, and its linear axes carry
    // less; the defaults are a mid-size machining centre's.
    let dynamics = match name {
        "table-table-ac" | "table-table-bc" => Dynamics {
            rapid_mm_min: 12_000.0,
            linear_accel_mm_s2: 1_500.0,
            linear_jerk_mm_s3: 30_000.0,
            rotary_accel_deg_s2: 600.0,
            rotary_jerk_deg_s3: 12_000.0,
            ..Dynamics::default()
        },
        "head-table-bc" => Dynamics {
            rotary_accel_deg_s2: 900.0,
            rotary_jerk_deg_s3: 18_000.0,
            ..Dynamics::default()
        },
        _ => Dynamics::default(),
    };
    let m = Machine {
        name: info.name.to_string(),
        description: info.description.to_string(),
        rotaries,
        linear_limits_mm: LinearLimits::default(),
        max_rotary_feed_deg_min: DEFAULT_ROTARY_FEED_DEG_MIN,
        safe_z_machine_mm: 0.0,
        dynamics,
    };
    m.validate()?;
    Ok(m)
}

/// Reads a machine JSON file (see the module docs); errors name the line or field.
pub fn from_json(text: &str) -> Result<Machine> {
    let f: MachineFile = serde_json::from_str(text).map_err(|e| {
        Error::parse(
            "machine JSON",
            format!("line {} column {}", e.line(), e.column()),
            e.to_string(),
        )
    })?;
    if f.format != FORMAT {
        return Err(Error::parse(
            "machine JSON",
            "format",
            format!("expected \"{FORMAT}\", got \"{}\"", f.format),
        ));
    }
    if f.version != VERSION {
        return Err(Error::parse(
            "machine JSON",
            "version",
            format!("this tspath reads version {VERSION}, got {}", f.version),
        ));
    }
    let mut rotaries = Vec::new();
    for (i, r) in f.rotaries.iter().enumerate() {
        let mut chars = r.name.chars();
        let (Some(name), None) = (chars.next(), chars.next()) else {
            return Err(Error::parse(
                "machine JSON",
                format!("rotaries[{i}].name"),
                format!("must be one letter A, B or C, got \"{}\"", r.name),
            ));
        };
        let axis = Vector3::from(r.axis);
        let len = axis.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(Error::parse(
                "machine JSON",
                format!("rotaries[{i}].axis"),
                format!("must be a non-zero direction, got {:?}", r.axis),
            ));
        }
        rotaries.push(Rotary {
            name: name.to_ascii_uppercase(),
            mount: r.mount,
            axis: axis / len,
            pivot_mm: Vector3::from(r.pivot_mm),
            direction: r.direction,
            limits_deg: r.limits_deg.map(|[a, b]| (a, b)),
        });
    }
    let l = f.linear_limits_mm.unwrap_or_default();
    let pair = |p: Option<[f64; 2]>| p.map(|[a, b]| (a, b));
    let m = Machine {
        name: f.name,
        description: f.description,
        rotaries,
        linear_limits_mm: LinearLimits {
            x: pair(l.x),
            y: pair(l.y),
            z: pair(l.z),
        },
        max_rotary_feed_deg_min: f.max_rotary_feed_deg_min,
        safe_z_machine_mm: f.safe_z_machine_mm,
        dynamics: f.dynamics,
    };
    m.validate()?;
    Ok(m)
}

/// Writes a machine as JSON in the format [`from_json`] reads (pretty, stable key order).
pub fn to_json(m: &Machine) -> String {
    let pair = |p: Option<(f64, f64)>| p.map(|(a, b)| [a, b]);
    let f = MachineFile {
        format: FORMAT.into(),
        version: VERSION,
        name: m.name.clone(),
        description: m.description.clone(),
        rotaries: m
            .rotaries
            .iter()
            .map(|r| RotaryFile {
                name: r.name.to_string(),
                mount: r.mount,
                axis: [r.axis.x, r.axis.y, r.axis.z],
                pivot_mm: [r.pivot_mm.x, r.pivot_mm.y, r.pivot_mm.z],
                direction: r.direction,
                limits_deg: pair(r.limits_deg),
            })
            .collect(),
        linear_limits_mm: Some(LimitsFile {
            x: pair(m.linear_limits_mm.x),
            y: pair(m.linear_limits_mm.y),
            z: pair(m.linear_limits_mm.z),
        }),
        max_rotary_feed_deg_min: m.max_rotary_feed_deg_min,
        safe_z_machine_mm: m.safe_z_machine_mm,
        dynamics: m.dynamics,
    };
    serde_json::to_string_pretty(&f).expect("a machine serialises") + "\n"
}

/// A built-in machine by name, or a machine JSON text (anything starting with `{`).
pub fn resolve(name_or_json: &str) -> Result<Machine> {
    if name_or_json.trim_start().starts_with('{') {
        from_json(name_or_json)
    } else {
        builtin(name_or_json)
    }
}
