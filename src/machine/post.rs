//! Post-processing: a [`Toolpath`] and a [`Machine`] into the text of one controller
//! dialect.
//!
//! Owns: dialects, units, number formatting, modal words (G93/G94, F), safe start and end.
//! Must not: plan or change the path (the joint values come from [`super::joints`]).
//!
//! Output modes. On a 3-axis machine, or in the `plain` dialect, positions are the tool tip
//! and the tool axis must be +Z. In the `linuxcnc` dialect on a 5-axis machine, X Y Z and the
//! rotaries are *machine joint values* from the inverse kinematics (a LinuxCNC with trivial
//! kinematics, or trt kinematics in identity mode), and moves that turn a rotary use
//! inverse-time feed (G93, F = 1/minutes) so the tool tip keeps the programmed feed; moves
//! whose joint interpolation would leave the planned chord by more than `chordal_mm` are split
//! (see [`super::joints::linearize`]). The
//! tool-centre-point dialects (`linuxcnc-tcp`, `fanuc` G43.4, `heidenhain` FUNCTION TCPM,
//! `siemens` TRAORI) write the *tool tip* in the workpiece frame plus the rotary angles;
//! the controller moves the linear axes and keeps the programmed feed at the tip (G94).
//!
//! Safe start: the spindle goes to the machine's safe Z (`safe_z_machine_mm`, in machine
//! coordinates: G53, SUPA or M91; usually the top of travel) before the tool change,
//! the rotaries turn to the first orientation up there, then the path starts. Safe end: a
//! retract along the tool axis to the clearance height (the highest cutting point along that
//! axis plus `clearance_mm`) unless the path already ends there, then the safe Z again.
//! Between cuts, a rapid that turns the rotaries goes up first (joint output: to the safe Z;
//! tool-tip output, with the control's tool-centre-point mode on: to the path's highest
//! tip), turns them there, moves level to above its target and comes down.

use super::joints;
use super::kinematics::{Joints, Kinematics, Machine};
use super::JobInfo;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::plan::{PlanOptions, Toolpath};
use std::fmt::Write;

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// A tool axis within this angle (rad) of +Z counts as +Z for 3-axis output.
const THREE_AXIS_TOL_RAD: f64 = 1e-9;

/// Planned tool axes must be unit vectors to this tolerance (planners normalise them).
const TOOL_AXIS_UNIT_TOL: f64 = 1e-6;

/// Decimals of lengths: 0.1 µm in mm programs, 0.254 µm in inch programs.
const MM_DECIMALS: usize = 4;
const INCH_DECIMALS: usize = 5;
/// Decimals of rotary angles (degrees).
const DEG_DECIMALS: usize = 4;
/// Decimals of feed words (then trailing zeros are dropped).
const FEED_DECIMALS: usize = 3;

/// Length unit of a program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    Mm,
    Inch,
}

impl Units {
    /// `mm` or `inch` (also `in`, `G21`, `G20`).
    pub fn parse(s: &str) -> Result<Units> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mm" | "g21" | "metric" => Ok(Units::Mm),
            "inch" | "in" | "g20" => Ok(Units::Inch),
            other => Err(Error::param(
                "units",
                format!("must be `mm` or `inch`, got `{other}`"),
            )),
        }
    }
    /// The name used in options and headers.
    pub fn name(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::Inch => "inch",
        }
    }
    /// Millimetres in one program unit.
    pub fn mm(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => MM_PER_INCH,
        }
    }
    fn decimals(self) -> usize {
        match self {
            Units::Mm => MM_DECIMALS,
            Units::Inch => INCH_DECIMALS,
        }
    }
}

/// A controller dialect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// LinuxCNC, machine joint values (G93 where rotaries move).
    LinuxCnc,
    /// LinuxCNC whose kinematics does the tool-centre-point (xyzac/xyzbc-trt-kins in TCP
    /// mode): tool tip + rotary angles.
    LinuxCncTcp,
    /// Fanuc-style, G43.4 tool-centre-point control.
    Fanuc,
    /// Heidenhain plain language (Klartext) with FUNCTION TCPM.
    Heidenhain,
    /// Siemens Sinumerik with TRAORI.
    Siemens,
    /// Plain 3-axis ISO G-code (tool axis must be +Z).
    Plain,
}

/// Every dialect with its name and a line saying what it writes.
pub const DIALECTS: &[(Dialect, &str, &str)] = &[
    (
        Dialect::LinuxCnc,
        "linuxcnc",
        "LinuxCNC; 5-axis: machine joint values from the inverse kinematics, G93 where rotaries move",
    ),
    (
        Dialect::LinuxCncTcp,
        "linuxcnc-tcp",
        "LinuxCNC whose trt kinematics does the TCP: tool tip and rotary angles",
    ),
    (
        Dialect::Fanuc,
        "fanuc",
        "Fanuc-style; 5-axis: G43.4 tool-centre-point control, tool tip and rotary angles",
    ),
    (
        Dialect::Heidenhain,
        "heidenhain",
        "Heidenhain plain language; 5-axis: FUNCTION TCPM, tool tip and rotary angles",
    ),
    (
        Dialect::Siemens,
        "siemens",
        "Siemens Sinumerik; 5-axis: TRAORI, tool tip and rotary angles",
    ),
    (
        Dialect::Plain,
        "plain",
        "plain 3-axis ISO G-code, tool tip, tool axis +Z",
    ),
];

impl Dialect {
    /// A dialect by name (see [`DIALECTS`]).
    pub fn parse(s: &str) -> Result<Dialect> {
        let key = s.trim().to_ascii_lowercase();
        DIALECTS
            .iter()
            .find(|(_, n, _)| *n == key)
            .map(|(d, _, _)| *d)
            .ok_or_else(|| {
                Error::param(
                    "dialect",
                    format!(
                        "unknown dialect `{s}`; known: {}",
                        DIALECTS
                            .iter()
                            .map(|(_, n, _)| *n)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
    }
    /// The dialect's name.
    pub fn name(self) -> &'static str {
        DIALECTS
            .iter()
            .find(|(d, _, _)| *d == self)
            .map(|(_, n, _)| *n)
            .expect("every dialect is listed")
    }
    /// True for the dialects whose controller does the tool-centre-point (5-axis output is
    /// tool tip + rotary angles).
    pub fn tool_tip_output(self) -> bool {
        !matches!(self, Dialect::LinuxCnc | Dialect::Plain)
    }
    fn syntax(self) -> Syntax {
        match self {
            Dialect::Heidenhain => Syntax::Heidenhain,
            Dialect::Siemens => Syntax::Siemens,
            _ => Syntax::Iso,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Syntax {
    Iso,
    Siemens,
    Heidenhain,
}

/// What the X Y Z (and rotary) words of a program mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputMode {
    /// Tool tip, no rotaries (tool axis +Z).
    ThreeAxis,
    /// Machine joint values (linear axes and rotary angles).
    Joints,
    /// Tool tip in the workpiece frame plus rotary angles (controller does the TCP).
    ToolTip,
}

/// Where a motion block of a posted program comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Path move `i`.
    Move(usize),
    /// A point on the chord from path move `i − 1` to move `i`, inserted so the machine's
    /// joint interpolation stays within the chordal tolerance of it.
    Inserted(usize),
    /// The safe start or end, or the way up, round and down of a rapid that turns the
    /// rotaries between cuts.
    Safe,
}

/// A posted program and how its motion blocks map back to the path.
#[derive(Debug, Clone, PartialEq)]
pub struct Posted {
    pub text: String,
    /// What each motion block in program order is.
    pub sources: Vec<Source>,
    /// The 1-based line of each motion block in `text` (beside `sources`).
    pub lines: Vec<usize>,
    /// Blocks inserted to keep joint-space motion on the planned chords.
    pub inserted: usize,
    /// Joint values of every path move.
    pub joints: Vec<Joints>,
    pub mode: OutputMode,
}

/// Formats `v` with `decimals` decimals, never as negative zero.
fn fixed(v: f64, decimals: usize) -> String {
    if let Some(s) = fixed_fast(v, decimals) {
        return s;
    }
    let s = format!("{v:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// Most decimals, and the largest magnitude of `v · 10^decimals`, [`fixed_fast`] formats.
const FAST_DECIMALS: usize = 9;
const FAST_LIMIT: f64 = 1e15;

/// [`fixed`] by integer arithmetic where that is sure to give the same text: `v · 10^d`
/// is rounded once in floating point (within half an ulp of the exact product, `10^d`
/// being exact), so its nearest integer is the exact product's unless its fraction lies
/// within a few ulps of one half; there, and for large or odd values, `None` (the exact
/// formatter decides). The standard formatter's exact decimal expansion costs a big-number
/// division per coordinate, most of a program's writing time.
fn fixed_fast(v: f64, decimals: usize) -> Option<String> {
    if decimals > FAST_DECIMALS {
        return None;
    }
    let scale = 10f64.powi(decimals as i32);
    let y = v.abs() * scale;
    if !(y < FAST_LIMIT) {
        return None;
    }
    let floor = y.floor();
    let frac = y - floor;
    let ulp = f64::EPSILON * y.max(1.0);
    if (frac - 0.5).abs() <= 4.0 * ulp {
        return None;
    }
    let mut n = if frac > 0.5 { floor + 1.0 } else { floor } as u64;
    // Digits from the last: the decimals (zeros kept), the point, the whole part.
    let mut buf = [0u8; 32];
    let mut at = buf.len();
    let mut push = |b: u8| {
        at -= 1;
        buf[at] = b;
    };
    let negative = v < 0.0 && n != 0;
    for _ in 0..decimals {
        push(b'0' + (n % 10) as u8);
        n /= 10;
    }
    if decimals > 0 {
        push(b'.');
    }
    loop {
        push(b'0' + (n % 10) as u8);
        n /= 10;
        if n == 0 {
            break;
        }
    }
    if negative {
        push(b'-');
    }
    Some(String::from_utf8_lossy(&buf[at..]).into_owned())
}

/// A feed value with at most [`FEED_DECIMALS`] decimals, trailing zeros dropped.
fn feed_text(v: f64) -> String {
    let s = fixed(v, FEED_DECIMALS);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// Parentheses end a G-code comment: keep them (and control characters) out of text.
fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c == '(' || c == ')' || c == ';' || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect()
}

/// A Heidenhain program name: letters, digits, `_` and `-`.
fn program_name(s: &str) -> String {
    let n: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    if n.is_empty() {
        "TSPATH".into()
    } else {
        n
    }
}

/// One motion block before formatting. Lengths in mm, angles in degrees.
struct Motion {
    rapid: bool,
    /// Machine coordinates (spindle to the top of Z), not the program's.
    machine_frame: bool,
    xyz: [Option<f64>; 3],
    rotary: Vec<(char, f64)>,
    /// `Some("G93")`/`Some("G94")` when the feed mode changes with this block.
    feed_mode: Option<&'static str>,
    /// Feed word value in program units (already converted), when written.
    feed: Option<f64>,
    extra: &'static str,
    source: Source,
}

struct Out {
    syntax: Syntax,
    units: Units,
    text: String,
    block: usize,
    sources: Vec<Source>,
    /// Lines written so far.
    written: usize,
    /// The line of each motion block (beside `sources`).
    lines: Vec<usize>,
}

impl Out {
    fn line(&mut self, s: &str) {
        debug_assert!(!s.contains('\n'), "one line at a time: {s:?}");
        self.written += 1;
        if self.syntax == Syntax::Heidenhain {
            let _ = writeln!(self.text, "{} {s}", self.block);
            self.block += 1;
        } else {
            let _ = writeln!(self.text, "{s}");
        }
    }
    fn comment(&mut self, s: &str) {
        let s = sanitize(s);
        match self.syntax {
            Syntax::Iso => self.line(&format!("({s})")),
            _ => self.line(&format!("; {s}")),
        }
    }
    fn len(&self, mm: f64) -> String {
        let s = fixed(mm / self.units.mm(), self.units.decimals());
        self.signed(s)
    }
    fn deg(&self, d: f64) -> String {
        self.signed(fixed(d, DEG_DECIMALS))
    }
    /// Heidenhain writes an explicit `+`.
    fn signed(&self, s: String) -> String {
        if self.syntax == Syntax::Heidenhain && !s.starts_with('-') {
            format!("+{s}")
        } else {
            s
        }
    }
    fn motion(&mut self, m: &Motion) {
        let mut words: Vec<String> = Vec::new();
        match self.syntax {
            Syntax::Heidenhain => words.push("L".into()),
            _ => {
                if let Some(fm) = m.feed_mode {
                    words.push(fm.into());
                }
                if m.machine_frame && self.syntax == Syntax::Iso {
                    words.push("G53".into());
                }
                words.push(if m.rapid { "G0" } else { "G1" }.into());
                if m.machine_frame && self.syntax == Syntax::Siemens {
                    words.push("SUPA".into());
                }
            }
        }
        for (k, name) in ["X", "Y", "Z"].iter().enumerate() {
            if let Some(v) = m.xyz[k] {
                words.push(format!("{name}{}", self.len(v)));
            }
        }
        for (name, v) in &m.rotary {
            words.push(format!("{name}{}", self.deg(*v)));
        }
        match self.syntax {
            Syntax::Heidenhain => {
                words.push("R0".into());
                if m.rapid {
                    words.push("FMAX".into());
                } else if let Some(f) = m.feed {
                    words.push(format!("F{}", feed_text(f)));
                }
                if m.machine_frame {
                    words.push("M91".into());
                }
            }
            _ => {
                if let Some(f) = m.feed {
                    words.push(format!("F{}", feed_text(f)));
                }
                if m.machine_frame && self.syntax == Syntax::Siemens {
                    words.push("D0".into());
                }
            }
        }
        if !m.extra.is_empty() {
            words.push(m.extra.into());
        }
        self.line(&words.join(" "));
        self.sources.push(m.source);
        self.lines.push(self.written);
    }
}

/// Posts `path` for `machine` in `dialect` and `units`; see [`super::post()`].
pub fn post_program(
    path: &Toolpath,
    opts: &PlanOptions,
    job: &JobInfo,
    machine: &Machine,
    dialect: Dialect,
    units: Units,
) -> Result<Posted> {
    machine.validate()?;
    for (name, v) in [
        ("feed_mm_min", opts.feed_mm_min),
        ("plunge_feed_mm_min", opts.plunge_feed_mm_min),
        ("spindle_rpm", opts.spindle_rpm),
        ("clearance_mm", opts.clearance_mm),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::param(name, format!("must be positive, got {v}")));
        }
    }
    opts.check_work_offset()?;
    let r = path.tool_radius_mm;
    let five = machine.kinematics() != Kinematics::ThreeAxis;
    let mode = match (five, dialect) {
        (false, _) | (_, Dialect::Plain) => OutputMode::ThreeAxis,
        (true, Dialect::LinuxCnc) => OutputMode::Joints,
        (true, _) => OutputMode::ToolTip,
    };
    let tips = joints::tips(path);
    // The safe plane in tool-tip output: the highest tip of the path (mm).
    let highest_tip = tips.iter().map(|t| t.z).fold(f64::NEG_INFINITY, f64::max);
    for (i, m) in path.moves.iter().enumerate() {
        let ok = m.cl_point.iter().all(|x| x.is_finite())
            && m.tool_axis.iter().all(|x| x.is_finite())
            && (m.tool_axis.norm() - 1.0).abs() < TOOL_AXIS_UNIT_TOL;
        if !ok {
            return Err(Error::Machine {
                location: format!("move {i}"),
                message: "the ball centre must be finite and the tool axis a unit vector".into(),
            });
        }
    }
    let joints: Vec<Joints> = if mode == OutputMode::ThreeAxis {
        let mut out = Vec::with_capacity(tips.len());
        for (i, (m, t)) in path.moves.iter().zip(&tips).enumerate() {
            if m.tool_axis.angle(&Vector3::z()) > THREE_AXIS_TOL_RAD {
                let a = m.tool_axis;
                return Err(Error::Machine {
                    location: format!("move {i}"),
                    message: format!(
                        "tool axis ({:.6}, {:.6}, {:.6}) is not +Z; {} writes 3-axis programs \
                         only for paths with the tool axis at +Z (choose a 5-axis machine and a \
                         5-axis dialect)",
                        a.x,
                        a.y,
                        a.z,
                        if five {
                            "the plain dialect".to_string()
                        } else {
                            format!("machine `{}`", machine.name)
                        }
                    ),
                });
            }
            let xyz_mm = [t.x, t.y, t.z];
            machine.check_linear(&xyz_mm, &format!("move {i}"))?;
            out.push(Joints {
                xyz_mm,
                rotary_deg: [0.0; 2],
            });
        }
        out
    } else {
        joints::solve_by(machine, path.moves.len(), |i| joints::path_request(path, i))?
    };

    // Rotary words in address order (A, B, C).
    let mut rot_order: Vec<(char, usize)> = if mode == OutputMode::ThreeAxis {
        Vec::new()
    } else {
        machine
            .rotaries
            .iter()
            .enumerate()
            .map(|(i, r)| (r.name, i))
            .collect()
    };
    rot_order.sort();
    let rot_words = |j: &Joints| -> Vec<(char, f64)> {
        rot_order
            .iter()
            .map(|&(n, i)| (n, j.rotary_deg[i]))
            .collect()
    };

    let syntax = dialect.syntax();
    let mut o = Out {
        syntax,
        units,
        text: String::new(),
        block: 0,
        sources: Vec::new(),
        written: 0,
        lines: Vec::new(),
    };
    let pname = program_name(&job.model);
    let unit_word = match units {
        Units::Mm => "MM",
        Units::Inch => "INCH",
    };

    // Program start and header.
    match syntax {
        Syntax::Iso => {
            o.line("%");
            if dialect == Dialect::Fanuc {
                o.line("O1000 (TSPATH)");
            }
        }
        Syntax::Heidenhain => o.line(&format!("BEGIN PGM {pname} {unit_word}")),
        Syntax::Siemens => {}
    }
    o.comment(&format!(
        "tspath {} - {} finishing",
        env!("CARGO_PKG_VERSION"),
        if mode == OutputMode::ThreeAxis {
            "three-axis"
        } else {
            "five-axis"
        }
    ));
    o.comment(&format!("model: {}", job.model));
    o.comment(&format!("strategy: {}", job.strategy));
    o.comment(&format!(
        "tool: T1 ball-end radius {} mm, scallop {} mm, chordal {} mm",
        opts.tool_radius_mm, opts.scallop_mm, opts.chordal_mm
    ));
    o.comment(&format!(
        "machine: {}, dialect: {}",
        machine.name,
        dialect.name()
    ));
    let names: String = rot_order.iter().map(|(n, _)| format!(" {n}")).collect();
    o.comment(&match mode {
        OutputMode::ThreeAxis => "positions: tool tip X Y Z".to_string(),
        OutputMode::Joints => {
            format!("positions: machine joints X Y Z{names}, rotaries in degrees")
        }
        OutputMode::ToolTip => format!("positions: tool tip X Y Z, rotaries{names} in degrees"),
    });
    o.comment(&format!(
        "units: {}, feed {}/min{}",
        units.name(),
        units.name(),
        if mode == OutputMode::Joints {
            ", inverse time G93 where rotaries move"
        } else {
            ""
        }
    ));
    if dialect == Dialect::LinuxCncTcp && mode == OutputMode::ToolTip {
        o.comment("the kinematics must be in TCP mode, e.g. xyzac-trt-kins");
    }
    if dialect == Dialect::Heidenhain && units == Units::Inch {
        o.comment("feeds F in 0.1 inch/min");
    }

    let safe_top = || Motion {
        rapid: true,
        machine_frame: true,
        xyz: [None, None, Some(machine.safe_z_machine_mm)],
        rotary: Vec::new(),
        feed_mode: None,
        feed: None,
        extra: "",
        source: Source::Safe,
    };
    // The work offset: the program's zero is where the operator set it.
    let offset = opts.work_offset;
    o.comment(&format!(
        "program zero: work offset G{offset}, set at {}",
        job.program_zero
    ));
    match syntax {
        Syntax::Iso => {
            let g = if units == Units::Mm { "G21" } else { "G20" };
            o.line(&format!("{g} G90 G17 G94 G40 G49 G80"));
            o.line(&format!("G{offset}"));
            o.motion(&safe_top());
            o.line("T1 M6");
            if !(dialect == Dialect::Fanuc && mode == OutputMode::ToolTip) {
                o.line("G43 H1");
            }
            o.line(&format!("S{} M3", feed_text(opts.spindle_rpm)));
        }
        Syntax::Siemens => {
            let g = if units == Units::Mm { "G710" } else { "G700" };
            o.line(&format!("{g} G90 G17 G94 G40"));
            // G58 and G59 are programmable frames on Siemens: the fifth and sixth settable
            // offsets are G505 and G506.
            let frame = match offset {
                58 => 505,
                59 => 506,
                g => g as u32,
            };
            o.line(&format!("G{frame}"));
            o.motion(&safe_top());
            o.line("T1 M6");
            o.line("D1");
            o.line(&format!("S{} M3", feed_text(opts.spindle_rpm)));
        }
        Syntax::Heidenhain => {
            // The preset table's line 1–6 stands for G54–G59.
            o.line(&format!("PRESET SELECT #{}", offset - 53));
            o.motion(&safe_top());
            o.line(&format!("TOOL CALL 1 Z S{}", feed_text(opts.spindle_rpm)));
        }
    }
    let first_rotary = joints.first().map(&rot_words).unwrap_or_default();
    if !first_rotary.is_empty() {
        o.motion(&Motion {
            rapid: true,
            machine_frame: false,
            xyz: [None; 3],
            rotary: first_rotary.clone(),
            feed_mode: None,
            feed: None,
            extra: "",
            source: Source::Safe,
        });
    }
    if mode == OutputMode::ToolTip {
        match dialect {
            Dialect::Fanuc => o.line("G43.4 H1"),
            Dialect::Heidenhain => o.line("FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS"),
            Dialect::Siemens => o.line("TRAORI"),
            _ => {}
        }
    }

    // The path, with the points joint-space motion needs to stay on the planned chords.
    struct Emit {
        i: usize,
        inserted: bool,
        tip: Point3,
        joints: Joints,
    }
    let mut emits: Vec<Emit> = Vec::with_capacity(path.moves.len());
    for (i, m) in path.moves.iter().enumerate() {
        let cutting = !m.kind.rapid();
        if mode == OutputMode::Joints && cutting && i > 0 {
            let prev = &path.moves[i - 1];
            let way = |m: &crate::plan::Move, k: usize| joints::Waypoint {
                cl_point: m.cl_point,
                joints: joints[k],
            };
            let extra = joints::linearize(
                machine,
                r,
                &way(prev, i - 1),
                &way(m, i),
                opts.chordal_mm,
                i,
            )?;
            for w in extra {
                emits.push(Emit {
                    i,
                    inserted: true,
                    tip: machine.forward(&w.joints).tip,
                    joints: w.joints,
                });
            }
        }
        emits.push(Emit {
            i,
            inserted: false,
            tip: tips[i],
            joints: joints[i],
        });
    }
    let inserted = emits.iter().filter(|e| e.inserted).count();
    let inverse_time_ok = mode == OutputMode::Joints;
    let mut inverse_time = false;
    let mut feed_written: Option<String> = None;
    let mut last_rot_text: Vec<String> = first_rotary.iter().map(|(_, v)| o.deg(*v)).collect();
    let mut last_tip: Option<Point3> = None;
    let mut last_rot: Option<[f64; 2]> = joints.first().map(|j| j.rotary_deg);
    let mut spindle_extra = syntax == Syntax::Heidenhain;
    for e in &emits {
        let m = &path.moves[e.i];
        let rapid = m.kind.rapid();
        let rotary = rot_words(&e.joints);
        let rot_text: Vec<String> = rotary.iter().map(|(_, v)| o.deg(*v)).collect();
        let rot_moves = rot_text != last_rot_text;
        let xyz = match mode {
            OutputMode::Joints => e.joints.xyz_mm,
            _ => [e.tip.x, e.tip.y, e.tip.z],
        };
        let mut motion = Motion {
            rapid,
            machine_frame: false,
            xyz: xyz.map(Some),
            rotary,
            feed_mode: None,
            feed: None,
            extra: if std::mem::take(&mut spindle_extra) {
                "M3"
            } else {
                ""
            },
            source: if e.inserted {
                Source::Inserted(e.i)
            } else {
                Source::Move(e.i)
            },
        };
        if let Some(feed_mm_min) = opts.feed_for(m.kind) {
            let len = last_tip.map(|p| (e.tip - p).norm()).unwrap_or(0.0);
            let turn = last_rot
                .map(|p| {
                    (0..2)
                        .map(|k| (e.joints.rotary_deg[k] - p[k]).abs())
                        .fold(0.0, f64::max)
                })
                .unwrap_or(0.0);
            // Minutes the move takes at the programmed tip feed, or longer when the rotaries
            // cannot turn that fast.
            let minutes = (len / feed_mm_min).max(turn / machine.max_rotary_feed_deg_min);
            if inverse_time_ok && rot_moves && minutes > 0.0 {
                if !inverse_time {
                    motion.feed_mode = Some("G93");
                    inverse_time = true;
                }
                motion.feed = Some(1.0 / minutes);
                feed_written = None;
            } else {
                if inverse_time {
                    motion.feed_mode = Some("G94");
                    inverse_time = false;
                }
                let mut f = feed_mm_min / units.mm();
                if syntax == Syntax::Heidenhain && units == Units::Inch {
                    f *= 10.0;
                }
                let text = feed_text(f);
                if feed_written.as_deref() != Some(text.as_str()) {
                    motion.feed = Some(f);
                    feed_written = Some(text);
                }
            }
        }
        // A rapid that turns the rotaries would sweep the tip along a curve (in joint
        // output, and in tool-tip output on a control that does not keep the tip on the
        // line at the rapid rate), and on a table machine swing the part up towards the
        // tool, which between cuts stands only the clearance over what lies beneath it:
        // go up first (joint output: to the top of Z, as at the start of the program;
        // tool-tip output, where the control's tool-centre-point mode stays on: to the
        // path's highest tip, the safe plane), turn the rotaries there, move level to above
        // the target and come down onto it.
        if rapid && rot_moves && last_tip.is_some() {
            let safe = |xyz: [Option<f64>; 3], rotary: Vec<(char, f64)>| Motion {
                rapid: true,
                machine_frame: false,
                xyz,
                rotary,
                feed_mode: None,
                feed: None,
                extra: "",
                source: Source::Safe,
            };
            let top = match mode {
                OutputMode::Joints => {
                    o.motion(&safe_top());
                    None
                }
                _ => {
                    o.motion(&safe([None, None, Some(highest_tip)], Vec::new()));
                    Some(highest_tip)
                }
            };
            o.motion(&safe([None; 3], motion.rotary.clone()));
            o.motion(&safe([Some(xyz[0]), Some(xyz[1]), top], Vec::new()));
        }
        o.motion(&motion);
        last_rot_text = rot_text;
        last_tip = Some(e.tip);
        last_rot = Some(e.joints.rotary_deg);
    }

    // Safe end: retract along the tool axis to the clearance height.
    if let (Some(last), Some(lj)) = (path.moves.last(), joints.last()) {
        let tip = tips[tips.len() - 1];
        let v = last.tool_axis;
        let highest = path
            .moves
            .iter()
            .zip(&tips)
            .filter(|(m, _)| m.kind.on_surface())
            .map(|(_, t)| (t - tip).dot(&v))
            .fold(f64::NEG_INFINITY, f64::max);
        let d = highest + opts.clearance_mm;
        if highest.is_finite() && d > 0.0 {
            let up = tip + v * d;
            let xyz = match mode {
                OutputMode::Joints => machine.linear_joints(&up, lj.rotary_deg),
                _ => [up.x, up.y, up.z],
            };
            machine.check_linear(&xyz, "the final retract")?;
            o.motion(&Motion {
                rapid: true,
                machine_frame: false,
                xyz: xyz.map(Some),
                rotary: rot_words(lj),
                feed_mode: None,
                feed: None,
                extra: "",
                source: Source::Safe,
            });
        }
    }
    if mode == OutputMode::ToolTip {
        match dialect {
            Dialect::Fanuc => o.line("G49"),
            Dialect::Heidenhain => o.line("FUNCTION RESET TCPM"),
            Dialect::Siemens => o.line("TRAFOOF"),
            _ => {}
        }
    }
    if inverse_time {
        o.line("G94");
    }
    match syntax {
        Syntax::Iso => {
            if dialect != Dialect::Fanuc || mode != OutputMode::ToolTip {
                o.line("G49");
            }
            o.motion(&safe_top());
            o.line("M5");
            o.line(if dialect == Dialect::Fanuc {
                "M30"
            } else {
                "M2"
            });
            o.line("%");
        }
        Syntax::Siemens => {
            o.motion(&safe_top());
            o.line("M5");
            o.line("M30");
        }
        Syntax::Heidenhain => {
            let mut m = safe_top();
            m.extra = "M30";
            o.motion(&m);
            o.line(&format!("END PGM {pname} {unit_word}"));
        }
    }
    Ok(Posted {
        text: o.text,
        sources: o.sources,
        lines: o.lines,
        inserted,
        joints,
        mode,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard library's exact formatter, negative zero dropped: what `fixed` wrote
    /// before it had a fast path.
    fn exact(v: f64, d: usize) -> String {
        let s = format!("{v:.d$}");
        match s.strip_prefix('-') {
            Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
            _ => s,
        }
    }

    #[test]
    fn the_fast_fixed_text_is_the_exact_formatters() {
        // Coordinates of every size and sign, from a fixed sequence; values a hair either
        // side of a rounding tie; dyadic values that are ties exactly (0.03125 at four
        // decimals); zeros of both signs.
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut values: Vec<f64> = (0..200_000)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let unit = (x >> 11) as f64 / (1u64 << 53) as f64;
                let scale = 10f64.powi((x % 9) as i32 - 3);
                (unit - 0.5) * 2.0 * scale
            })
            .collect();
        for k in 0..2000 {
            let tie = (k as f64 + 0.5) / 1e4;
            values.extend([tie, -tie, tie.next_up(), tie.next_down()]);
        }
        values.extend([
            0.03125,
            -0.03125,
            0.5,
            1.5,
            2.5,
            0.0,
            -0.0,
            1e-12,
            -1e-12,
            99999.99995,
        ]);
        let mut fast = 0;
        for &v in &values {
            for d in [0, 1, 3, 4, 6] {
                assert_eq!(fixed(v, d), exact(v, d), "{v:e} at {d} decimals");
                fast += usize::from(fixed_fast(v, d).is_some());
            }
        }
        // The fast path takes nearly all of them (the ties go to the exact formatter).
        assert!(fast as f64 > 0.95 * (5 * values.len()) as f64, "{fast}");
    }
}
