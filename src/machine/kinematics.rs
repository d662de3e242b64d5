//! Machine kinematics: what joint values (X, Y, Z and up to two rotary angles) put the tool
//! tip at a point with a given tool axis, and back.
//!
//! Owns: the machine model (3-axis, table-table, head-table), forward kinematics and the
//! closed-form inverse kinematics of one pose (every branch, every turn within the limits).
//! Must not: choose between solutions along a path (that is [`super::joints`]) or format
//! anything.
//!
//! Frames. The *workpiece frame* is the program's frame (model coordinates, mm); it equals
//! the machine frame when every rotary angle is zero. The spindle points along machine +Z:
//! the tool axis, from the tip towards the spindle, is +Z in the machine frame. Linear joint
//! values X, Y, Z are the tool tip in the machine frame for table rotaries; on a head-table
//! machine they are where the tip would be with the head at zero.

use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use nalgebra::{Rotation3, Unit};
use serde::{Deserialize, Serialize};

/// Rotary axes within this angle of the inner axis are at the singular pose: the inner axis
/// (usually C) does not change the tool axis there and keeps its previous value. The tool
/// axis is then off by at most twice this angle (2e-6 rad ≈ 1.1e-4°).
pub const SINGULAR_CONE_RAD: f64 = 1e-6;

/// A tool axis whose inverse kinematics leaves this residual (rad) is not reachable.
const ORIENTATION_RESIDUAL_RAD: f64 = 1e-9;

/// A direction whose length differs from 1 by less than this is a unit vector.
pub const UNIT_TOL: f64 = 1e-9;

/// Two rotary axes closer to parallel than this (sine of the angle) cannot orient the tool.
const MIN_AXIS_SINE: f64 = 1e-3;

/// Where a rotary axis sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mount {
    /// Rotates the workpiece (a trunnion or a rotary table).
    Table,
    /// Rotates the spindle head (and the tool with it).
    Head,
}

/// One rotary axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Rotary {
    /// Address letter in the program: `A`, `B` or `C`.
    pub name: char,
    pub mount: Mount,
    /// Unit direction of the axis in the machine frame with every rotary at zero.
    pub axis: Vector3,
    /// Table: a point on the axis line in the workpiece frame with every rotary at zero (mm).
    /// Head: the vector from the tool tip to a point on the axis with the head at zero (mm),
    /// so it includes the tool's gauge length.
    pub pivot_mm: Vector3,
    /// +1 when a positive angle turns the table (or head) right-handed about `axis`, -1 when
    /// the machine turns it the other way.
    pub direction: f64,
    /// Travel (degrees, min < max); `None` for an axis that turns without end.
    pub limits_deg: Option<(f64, f64)>,
}

/// Travel of the linear axes in the program's coordinates (mm), each optional.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinearLimits {
    pub x: Option<(f64, f64)>,
    pub y: Option<(f64, f64)>,
    pub z: Option<(f64, f64)>,
}

/// What kind of machine the rotaries make.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kinematics {
    /// No rotaries: the tool axis is +Z.
    ThreeAxis,
    /// Two table rotaries; `rotaries[0]` is mounted on the bed and carries `rotaries[1]`.
    TableTable,
    /// One head rotary and one table rotary (in either order in `rotaries`).
    HeadTable,
}

/// Largest |z| of a rotary axis that tilts the tool (a horizontal axis; an axis nearer
/// vertical turns it about Z).
const TILT_AXIS_MAX_Z: f64 = 0.5;

/// A machine: its rotaries and travel.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    pub name: String,
    pub description: String,
    /// None, or two rotaries (see [`Kinematics`] for their order).
    pub rotaries: Vec<Rotary>,
    pub linear_limits_mm: LinearLimits,
    /// Fastest rotary motion (degrees per minute); bounds inverse-time feeds of moves that
    /// mostly turn.
    pub max_rotary_feed_deg_min: f64,
    /// Machine-coordinate Z (mm) of the safe spindle position at program start and end
    /// (G53 / SUPA / M91 blocks); 0 on machines homed at the top of Z.
    pub safe_z_machine_mm: f64,
    /// Rates, accelerations, jerk and corner rounding, for the machining time.
    pub dynamics: super::motion::Dynamics,
}

/// Joint values of one pose: linear axes (mm) and rotary angles (degrees) in the order of
/// [`Machine::rotaries`] (unused entries are zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joints {
    pub xyz_mm: [f64; 3],
    pub rotary_deg: [f64; 2],
}

/// Tool tip and axis in the workpiece frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    pub tip: Point3,
    /// Unit tool axis, from the tip towards the spindle.
    pub axis: Vector3,
}

/// One solution of the rotary angles for a tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotarySolution {
    pub rotary_deg: [f64; 2],
    /// Which of the two orientation branches (0 or 1; both are equal at the singular pose).
    pub branch: u8,
    /// True when the tool axis is along the inner axis and its angle was kept, not solved.
    pub singular: bool,
}

fn rot(axis: &Vector3, angle_rad: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_normalize(*axis), angle_rad)
}

/// Signed angle (rad) turning `p` to `q` about unit `b`, both projected on the plane
/// normal to `b`; `None` when either projection vanishes.
fn angle_about(b: &Vector3, p: &Vector3, q: &Vector3) -> Option<f64> {
    let pp = p - b * b.dot(p);
    let qq = q - b * b.dot(q);
    if pp.norm() < SINGULAR_CONE_RAD || qq.norm() < SINGULAR_CONE_RAD {
        return None;
    }
    Some(b.dot(&pp.cross(&qq)).atan2(pp.dot(&qq)))
}

/// Angle (rad) from unit vector `v` to the great-circle arc from `p` to `q` (the shorter
/// one; unit vectors): to its nearest point, which is an end or the foot of `v` on the great
/// circle when that lies between the ends.
pub fn angle_to_arc(p: &Vector3, q: &Vector3, v: &Vector3) -> f64 {
    let ends = v.angle(p).min(v.angle(q));
    let n = p.cross(q);
    if n.norm() <= SINGULAR_CONE_RAD {
        return ends;
    }
    let n = n.normalize();
    let foot = v - n * n.dot(v);
    if foot.norm() <= SINGULAR_CONE_RAD {
        return ends;
    }
    let foot = foot.normalize();
    if p.cross(&foot).dot(&n) >= 0.0 && foot.cross(q).dot(&n) >= 0.0 {
        n.dot(v).abs().min(1.0).asin().min(ends)
    } else {
        ends
    }
}

/// Wraps an angle (degrees) to the value `a + k·360` nearest `reference`.
pub fn nearest_turn(a: f64, reference: f64) -> f64 {
    a + 360.0 * ((reference - a) / 360.0).round()
}

impl Rotary {
    /// Right-handed rotation (rad) of the physical part for joint angle `deg`.
    fn phi(&self, deg: f64) -> f64 {
        self.direction * deg.to_radians()
    }

    /// True when `deg` is within this axis' travel (up to output rounding).
    pub fn within(&self, deg: f64) -> bool {
        match self.limits_deg {
            None => true,
            Some((lo, hi)) => deg >= lo - LIMIT_SLACK_DEG && deg <= hi + LIMIT_SLACK_DEG,
        }
    }
}

/// Angles this close outside a limit (degrees) still count as inside: output rounding.
const LIMIT_SLACK_DEG: f64 = 1e-9;

/// The orientation problem in one form for every kinematics: find φ1, φ2 with
/// `R(b1, φ1) · R(b2, φ2) · v = z`, where `v` is the tool axis in the workpiece frame and z
/// the spindle direction. `outer`/`inner` say which rotary each angle belongs to and `sign1`
/// maps φ1 back to that rotary's physical angle (head rotaries enter with the opposite sign).
struct OrientationForm {
    outer: usize,
    inner: usize,
    b1: Vector3,
    b2: Vector3,
    sign1: f64,
}

impl Machine {
    /// How far the machine can tilt the tool axis from +Z (degrees): 0 without rotaries;
    /// else the travel of the rotary that tilts (its axis horizontal) — the larger side of
    /// it when the other rotary turns the whole circle (either side then reaches every
    /// azimuth), the smaller side when that one is limited too; 180° for a tilting axis
    /// without limits. The planners' largest tilt must stay within it, so that every axis
    /// they choose can be posted.
    pub fn reachable_tilt_deg(&self) -> f64 {
        let horizontal = |r: &Rotary| r.axis.z.abs() < TILT_AXIS_MAX_Z;
        let Some(tilt) = self.rotaries.iter().find(|r| horizontal(r)) else {
            return 0.0;
        };
        let Some((lo, hi)) = tilt.limits_deg else {
            return 180.0;
        };
        let spin_full = self
            .rotaries
            .iter()
            .filter(|r| !horizontal(r))
            .all(|r| r.limits_deg.is_none_or(|(a, b)| b - a >= 360.0));
        let reach = if spin_full {
            lo.abs().max(hi.abs())
        } else {
            lo.abs().min(hi.abs())
        };
        reach.min(180.0)
    }

    /// The kinematics the rotaries make (checked by [`Machine::validate`]).
    pub fn kinematics(&self) -> Kinematics {
        match self.rotaries.len() {
            0 => Kinematics::ThreeAxis,
            _ if self.rotaries.iter().all(|r| r.mount == Mount::Table) => Kinematics::TableTable,
            _ => Kinematics::HeadTable,
        }
    }

    /// Checks the definition; errors name the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |loc: String, msg: String| Err(Error::parse("machine definition", loc, msg));
        if self.name.trim().is_empty() {
            return bad("name".into(), "must not be empty".into());
        }
        if !(self.max_rotary_feed_deg_min.is_finite() && self.max_rotary_feed_deg_min > 0.0) {
            return bad(
                "max_rotary_feed_deg_min".into(),
                format!(
                    "must be a positive number of degrees per minute, got {}",
                    self.max_rotary_feed_deg_min
                ),
            );
        }
        if let Some((name, v)) = self.dynamics.invalid_field() {
            return bad(
                format!("dynamics.{name}"),
                format!("must be a positive number, got {v}"),
            );
        }
        if !self.safe_z_machine_mm.is_finite() {
            return bad(
                "safe_z_machine_mm".into(),
                format!("must be a number of mm, got {}", self.safe_z_machine_mm),
            );
        }
        if !(self.rotaries.is_empty() || self.rotaries.len() == 2) {
            return bad(
                "rotaries".into(),
                format!(
                    "a machine has no rotary axis (3-axis) or two (5-axis), got {}",
                    self.rotaries.len()
                ),
            );
        }
        for (i, r) in self.rotaries.iter().enumerate() {
            let loc = |f: &str| format!("rotaries[{i}].{f}");
            if !matches!(r.name, 'A' | 'B' | 'C') {
                return bad(loc("name"), format!("must be A, B or C, got {}", r.name));
            }
            if !(r.axis.iter().all(|x| x.is_finite()) && (r.axis.norm() - 1.0).abs() < UNIT_TOL) {
                return bad(
                    loc("axis"),
                    format!("must be a unit vector, got {:?}", r.axis.as_slice()),
                );
            }
            if !r.pivot_mm.iter().all(|x| x.is_finite()) {
                return bad(loc("pivot_mm"), "must be three finite numbers (mm)".into());
            }
            if r.direction != 1.0 && r.direction != -1.0 {
                return bad(
                    loc("direction"),
                    format!("must be 1 or -1, got {}", r.direction),
                );
            }
            if let Some((lo, hi)) = r.limits_deg {
                if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                    return bad(
                        loc("limits_deg"),
                        format!("must be [min, max] in degrees with min < max, got [{lo}, {hi}]"),
                    );
                }
            }
        }
        for (k, lim) in [
            ("x", self.linear_limits_mm.x),
            ("y", self.linear_limits_mm.y),
            ("z", self.linear_limits_mm.z),
        ] {
            if let Some((lo, hi)) = lim {
                if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                    return bad(
                        format!("linear_limits_mm.{k}"),
                        format!("must be [min, max] in mm with min < max, got [{lo}, {hi}]"),
                    );
                }
            }
        }
        if self.rotaries.len() == 2 {
            let (a, b) = (&self.rotaries[0], &self.rotaries[1]);
            if a.name == b.name {
                return bad(
                    "rotaries[1].name".into(),
                    format!("both rotaries are called {}", a.name),
                );
            }
            if a.mount == Mount::Head && b.mount == Mount::Head {
                return bad(
                    "rotaries".into(),
                    "two head rotaries (head-head) are not supported; use table-table or head-table"
                        .into(),
                );
            }
            let f = self.form();
            if f.b1.cross(&f.b2).norm() < MIN_AXIS_SINE {
                return bad(
                    "rotaries".into(),
                    "the two rotary axes are parallel: they cannot tilt the tool".into(),
                );
            }
            if f.b1.cross(&Vector3::z()).norm() < MIN_AXIS_SINE {
                return bad(
                    format!("rotaries[{}].axis", f.outer),
                    "the outer rotary is parallel to the spindle: it cannot tilt the tool".into(),
                );
            }
        }
        Ok(())
    }

    fn form(&self) -> OrientationForm {
        let (r0, r1) = (&self.rotaries[0], &self.rotaries[1]);
        match (r0.mount, r1.mount) {
            (Mount::Head, _) => OrientationForm {
                outer: 0,
                inner: 1,
                b1: r0.axis,
                b2: r1.axis,
                sign1: -1.0,
            },
            (_, Mount::Head) => OrientationForm {
                outer: 1,
                inner: 0,
                b1: r1.axis,
                b2: r0.axis,
                sign1: -1.0,
            },
            _ => OrientationForm {
                outer: 0,
                inner: 1,
                b1: r0.axis,
                b2: r1.axis,
                sign1: 1.0,
            },
        }
    }

    /// Index in [`Machine::rotaries`] of the inner axis, the one that is free at the singular
    /// pose (the rotary table of table-table and head-table machines).
    pub fn inner_rotary(&self) -> Option<usize> {
        (self.rotaries.len() == 2).then(|| self.form().inner)
    }

    /// The tool axis (workpiece frame) of the singular pose: along the inner rotary axis.
    /// Its opposite is singular too.
    pub fn singular_axis(&self) -> Option<Vector3> {
        (self.rotaries.len() == 2).then(|| self.form().b2)
    }

    /// True when the great-circle arc of tool axes from `p` to `q` passes within
    /// [`SINGULAR_CONE_RAD`] of the singular pose (or its opposite).
    pub fn arc_meets_singular(&self, p: &Vector3, q: &Vector3) -> bool {
        let Some(s) = self.singular_axis() else {
            return false;
        };
        let (p, q) = (p.normalize(), q.normalize());
        [s, -s]
            .iter()
            .any(|s| angle_to_arc(&p, &q, s) < SINGULAR_CONE_RAD)
    }

    /// The rotary angles clamped into the travel when they are within it up to output
    /// rounding; `None` when an angle is outside.
    pub fn within_limits(&self, rotary_deg: [f64; 2]) -> Option<[f64; 2]> {
        let mut out = rotary_deg;
        for (i, r) in self.rotaries.iter().enumerate() {
            if !r.within(out[i]) {
                return None;
            }
            if let Some((lo, hi)) = r.limits_deg {
                out[i] = out[i].clamp(lo, hi);
            }
        }
        Some(out)
    }

    /// True when linear joint values are within the travel (see [`Machine::check_linear`]
    /// for the error).
    pub fn linear_within_limits(&self, xyz: &[f64; 3]) -> bool {
        let l = &self.linear_limits_mm;
        [l.x, l.y, l.z]
            .iter()
            .zip(xyz)
            .all(|(lim, v)| lim.is_none_or(|(lo, hi)| *v >= lo && *v <= hi))
    }

    /// Tool axis in the workpiece frame for rotary angles (degrees).
    pub fn tool_axis(&self, rotary_deg: [f64; 2]) -> Vector3 {
        if self.rotaries.len() != 2 {
            return Vector3::z();
        }
        let f = self.form();
        let phi1 = f.sign1 * self.rotaries[f.outer].phi(rotary_deg[f.outer]);
        let phi2 = self.rotaries[f.inner].phi(rotary_deg[f.inner]);
        // v = R(b2, φ2)ᵀ R(b1, φ1)ᵀ z
        (rot(&f.b1, phi1) * rot(&f.b2, phi2)).inverse() * Vector3::z()
    }

    /// Forward kinematics: joint values to the tool pose in the workpiece frame.
    pub fn forward(&self, j: &Joints) -> ToolPose {
        let p = Point3::from(j.xyz_mm);
        match self.kinematics() {
            Kinematics::ThreeAxis => ToolPose {
                tip: p,
                axis: Vector3::z(),
            },
            Kinematics::TableTable => {
                // p_machine = T0(θ0) T1(θ1) p_work; undo outer first.
                let mut q = p;
                for (i, r) in self.rotaries.iter().enumerate() {
                    q = table_apply(r, -r.phi(j.rotary_deg[i]), &q);
                }
                ToolPose {
                    tip: q,
                    axis: self.tool_axis(j.rotary_deg),
                }
            }
            Kinematics::HeadTable => {
                let (h, t) = self.head_table();
                let rh = &self.rotaries[h];
                let rt = &self.rotaries[t];
                let d = rh.pivot_mm;
                let tip_m = p + d - rot(&rh.axis, rh.phi(j.rotary_deg[h])) * d;
                ToolPose {
                    tip: table_apply(rt, -rt.phi(j.rotary_deg[t]), &tip_m),
                    axis: self.tool_axis(j.rotary_deg),
                }
            }
        }
    }

    /// Indices of the head and the table rotary of a head-table machine.
    fn head_table(&self) -> (usize, usize) {
        if self.rotaries[0].mount == Mount::Head {
            (0, 1)
        } else {
            (1, 0)
        }
    }

    /// Linear joint values that put the tip at `tip` (workpiece frame) with the rotaries at
    /// `rotary_deg`.
    pub fn linear_joints(&self, tip: &Point3, rotary_deg: [f64; 2]) -> [f64; 3] {
        let p = match self.kinematics() {
            Kinematics::ThreeAxis => *tip,
            Kinematics::TableTable => {
                let mut q = *tip;
                for i in (0..2).rev() {
                    let r = &self.rotaries[i];
                    q = table_apply(r, r.phi(rotary_deg[i]), &q);
                }
                q
            }
            Kinematics::HeadTable => {
                let (h, t) = self.head_table();
                let (rh, rt) = (&self.rotaries[h], &self.rotaries[t]);
                let tip_m = table_apply(rt, rt.phi(rotary_deg[t]), tip);
                let d = rh.pivot_mm;
                tip_m - d + rot(&rh.axis, rh.phi(rotary_deg[h])) * d
            }
        };
        [p.x, p.y, p.z]
    }

    /// Every rotary solution for tool axis `axis` (unit, workpiece frame): both branches,
    /// each angle within its limits at every turn `k·360°` for limited axes and at the turn
    /// nearest `previous` for endless ones. With `respect_limits` false, every axis is taken
    /// at the turn nearest `previous`, limits ignored (the solution continuity would pick).
    /// At the singular pose the inner angle is `previous`'s. Empty when the axis cannot be
    /// reached within the limits; `Err` when no rotation of this machine reaches it at all.
    pub fn rotary_solutions(
        &self,
        axis: &Vector3,
        previous: [f64; 2],
        respect_limits: bool,
    ) -> std::result::Result<Vec<RotarySolution>, Unreachable> {
        let mut out = Vec::new();
        self.rotary_solutions_into(axis, previous, respect_limits, &mut out)?;
        Ok(out)
    }

    /// [`Self::rotary_solutions`] into `out` (cleared first): the joint solve asks for them
    /// at every state of every move, and a vector each was most of its allocations.
    pub fn rotary_solutions_into(
        &self,
        axis: &Vector3,
        previous: [f64; 2],
        respect_limits: bool,
        out: &mut Vec<RotarySolution>,
    ) -> std::result::Result<(), Unreachable> {
        out.clear();
        if self.rotaries.len() != 2 {
            return if (axis - Vector3::z()).norm() <= SINGULAR_CONE_RAD {
                out.push(RotarySolution {
                    rotary_deg: [0.0; 2],
                    branch: 0,
                    singular: false,
                });
                Ok(())
            } else {
                Err(Unreachable)
            };
        }
        let f = self.form();
        let v = axis.normalize();
        let z = Vector3::z();
        let c12 = f.b1.dot(&f.b2);
        let s2 = 1.0 - c12 * c12;
        let (k1, k2) = (f.b1.dot(&z), f.b2.dot(&v));
        let alpha = (k1 - k2 * c12) / s2;
        let beta = (k2 - k1 * c12) / s2;
        let n = f.b1.cross(&f.b2);
        let g2 = (1.0 - (alpha * alpha + beta * beta + 2.0 * alpha * beta * c12)) / s2;
        if g2 < -ORIENTATION_RESIDUAL_RAD {
            return Err(Unreachable);
        }
        let gamma = g2.max(0.0).sqrt();
        let singular = (v - f.b2 * k2).norm() < SINGULAR_CONE_RAD;
        for (branch, sgn) in [(0u8, 1.0), (1u8, -1.0)] {
            if branch == 1 && (singular || gamma == 0.0) {
                break;
            }
            let w = f.b1 * alpha + f.b2 * beta + n * (sgn * gamma);
            let inner = &self.rotaries[f.inner];
            let outer = &self.rotaries[f.outer];
            let phi2 = if singular {
                inner.phi(previous[f.inner])
            } else {
                match angle_about(&f.b2, &v, &w) {
                    Some(a) => a,
                    None => inner.phi(previous[f.inner]),
                }
            };
            let w = rot(&f.b2, phi2) * v;
            let Some(phi1) = angle_about(&f.b1, &w, &z) else {
                return Err(Unreachable);
            };
            let mut deg = [0.0; 2];
            deg[f.inner] = inner.direction * phi2.to_degrees();
            deg[f.outer] = outer.direction * f.sign1 * phi1.to_degrees();
            if singular {
                deg[f.inner] = previous[f.inner];
            }
            // Residual check: the solution must reproduce the axis.
            let back = self.tool_axis(deg);
            if (back - v).norm() > 2.0 * SINGULAR_CONE_RAD + ORIENTATION_RESIDUAL_RAD {
                return Err(Unreachable);
            }
            // Every turn of each axis that the limits allow (endless, or limits ignored:
            // the turn nearest previous).
            let turns = |i: usize| {
                let r = &self.rotaries[i];
                let limits = r.limits_deg.filter(|_| respect_limits);
                let nearest = limits.is_none().then(|| nearest_turn(deg[i], previous[i]));
                let (lo, hi) = limits.unwrap_or((0.0, 0.0));
                // An empty range without limits.
                let (kmin, kmax) = match limits {
                    Some(_) => (
                        ((lo - deg[i]) / 360.0).floor() as i64,
                        ((hi - deg[i]) / 360.0).ceil() as i64,
                    ),
                    None => (1, 0),
                };
                nearest
                    .into_iter()
                    .chain((kmin..=kmax).filter_map(move |k| {
                        let a = deg[i] + 360.0 * k as f64;
                        r.within(a).then(|| a.clamp(lo, hi))
                    }))
            };
            for a0 in turns(0) {
                for a1 in turns(1) {
                    out.push(RotarySolution {
                        rotary_deg: [a0, a1],
                        branch,
                        singular,
                    });
                }
            }
        }
        Ok(())
    }

    /// Checks linear joint values against the travel; the error names the axis and value.
    pub fn check_linear(&self, xyz: &[f64; 3], location: &str) -> Result<()> {
        let l = &self.linear_limits_mm;
        for (k, (name, lim)) in [("X", l.x), ("Y", l.y), ("Z", l.z)].iter().enumerate() {
            if let Some((lo, hi)) = lim {
                if xyz[k] < *lo || xyz[k] > *hi {
                    return Err(Error::Machine {
                        location: location.to_string(),
                        message: format!(
                            "{name} would be {:.4} mm, outside the travel [{lo}, {hi}] mm of machine `{}`",
                            xyz[k], self.name
                        ),
                    });
                }
            }
        }
        Ok(())
    }
}

/// No rotation of the machine gives that tool axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unreachable;

/// Turns point `p` about table rotary `r`'s axis line by `phi` (rad, right-handed).
fn table_apply(r: &Rotary, phi: f64, p: &Point3) -> Point3 {
    let c = Point3::from(r.pivot_mm);
    c + rot(&r.axis, phi) * (p - c)
}
