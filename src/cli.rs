//! Command-line front end: argument parsing and the commands, over the same library calls
//! the page uses. Returns the text to print so that tests can run it in-process.

use crate::error::{Error, Result};
use crate::machine::{self, Dialect, JobInfo, Units};
use crate::model::setup::{ImportSetup, LengthUnit, ProgramZero, Up};
use crate::model::{samples, Model};
use crate::plan::{self, PlanOptions, Strategy};
use crate::verify::{self, CutterPath, VerifyOptions};
use std::time::Instant;

const USAGE: &str = "usage:
  tspath info MODEL
  tspath sample --list
  tspath sample NAME -o FILE.json
  tspath export MODEL -o FILE.stl|FILE.obj [--chordal MM]
  tspath plan MODEL [--strategy isoparametric|isfc|watershed|multi-rectangle|isoplanar]
              [--isfc-plain] [--slice-angle DEG] [--no-deform] [--shear]
              [--tool-radius MM] [--scallop MM] [--chordal MM] [--feed MM_PER_MIN]
              [--plunge-feed MM_PER_MIN] [--clearance MM] [--full-retract]
              [--feed-height MM]
              [--max-cl-points N]
              [--start-patch N] [--finish-patch N] [--lead DEG] [--tilt DEG] [--max-tilt DEG]
              [--max-axis-step DEG]
              [--axis-preset vertical|gan2014|yuan2012]
              [--shank MM] [--shank-length MM] [--holder MM] [--holder-length MM]
              [--machine NAME|FILE.json] [--dialect NAME] [--units mm|inch]
              [--work-offset G54..G59] [-o OUT.nc] [--report REPORT.json]
              [--verify [--verify-samples N] [--verify-max-samples N]]
              --verify simulates the cut, from N samples (default 100 000; at least a
              spacing of a quarter of sqrt(8 r h)) up to at most --verify-max-samples
              (default 8 000 000) until its error bound is a quarter of the scallop
              exits with 3 after writing its outputs when the plan has problems (rest area,
              gouges, scallop over the request, an unproven simulation), listed on stderr;
              on a terminal it shows how far planning has got on stderr
  tspath compare MODEL [plan's options] [--strategies a,b,...] [--no-verify]
              [--verify-max-samples N] [--report C.json] [--csv C.csv]
              plans MODEL with every strategy (isoparametric, isfc, watershed,
              multi-rectangle, isoplanar, isoplanar-baseline), simulates each cut, and
              prints a Markdown table: lengths, retractions, reversals, CL points, simulated
              scallop, gouges, axis step, plan and machining time (on --machine), and the
              cutting length over L_min = integral of dA / g (curvature) and area/sqrt(8 r h)
  tspath machine --list
  tspath machine NAME [-o FILE.json]
  tspath verify MODEL GCODE_OR_TOOLPATH --tool-radius MM [--samples N] [--bound MM]
              [--scallop MM] [--gouge-tolerance MM] [--machine NAME|FILE.json] [--dialect NAME]
MODEL is a model file (.json, .tsm, .obj) or the name of a built-in sample. Every command
that reads a MODEL places it with [--model-units mm|cm|m|inch] (the unit of a file that
does not say its own, OBJ; default: the unit its header comment names, else mm)
[--scale F] [--up z|y] (y: the file's +Y becomes +Z, as modelling tools write)
[--rotate 0|90|180|270] (about +Z, counter-clockwise from above) [--on-table] (lowest
point at Z 0) [--stock-side MM] [--stock-top MM] (stock beyond the part's box in X/Y and
above it; its bottom is the part's lowest point) [--zero WHERE]
(the program's X0 Y0 Z0: model (default, the model's origin), stock-top-centre,
stock-top-corner, stock-bottom-centre, stock-bottom-corner (front-left: least X, Y), or a
point x,y,z in mm of the placed model); `info` shows the placement, the millimetre box
and the stock.
--clearance is the gap kept under the tool on rapids (default 5 mm): between cuts the tool
rapids that high over what its ball, shank and holder pass above, or with --full-retract at
the safe plane (the clearance and a ball diameter above the model and its stock, where the
program starts and ends); it rapids down to --feed-height above each cut (default 2 mm,
along its way down) and goes on at --plunge-feed (default 300 mm/min).
--max-cl-points (default 2 000 000) refuses, before planning, settings whose estimated CL
points exceed it, naming the estimate and the scallop that would fit.
--max-axis-step (default 5°) is the largest turn of the tool axis from one cut point to
the next (five-axis): larger turns are spread over the points around them, else split.
--axis-preset gan2014 leads the tool 10° from the surface normal along the feed, as the
space-filling-curve paper machined (five-axis machines); --lead/--tilt after it override.
--machine is a built-in machine (default 3-axis) or a machine JSON file (start from
`tspath machine NAME -o FILE.json`); --dialect is linuxcnc (default), linuxcnc-tcp, fanuc,
heidenhain, siemens or plain; --units mm (default) or inch.
verify simulates the ball-end cut of a program (read for --machine and --dialect) or of a
tspath-cl JSON tool path and prints the scallops and gouges it leaves as JSON; --bound
raises the sample count until the stated error bound is within MM.
";

/// What a command did, beyond its output.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Status {
    /// Done as asked.
    Done,
    /// `plan` wrote its outputs, but the plan leaves something undone: these problems
    /// (one line each). The command exits with [`EXIT_PROBLEMS`].
    Problems(Vec<String>),
}

/// Exit status of `tspath plan` when the plan has problems (rest area, gouges, scallop over
/// the request, turns within the safety margin, an unproven simulation), after writing its
/// outputs. Errors exit with 2.
pub const EXIT_PROBLEMS: u8 = 3;

/// Runs one command; returns what it prints on success.
pub fn run(args: &[String]) -> Result<String> {
    run_with_status(args).map(|(out, _)| out)
}

/// Runs one command; returns what it prints on success and whether a plan has problems.
pub fn run_with_status(args: &[String]) -> Result<(String, Status)> {
    let Some(cmd) = args.first() else {
        return Err(Error::Io(USAGE.into()));
    };
    let rest = &args[1..];
    if cmd == "plan" {
        return plan(rest);
    }
    let out = match cmd.as_str() {
        "info" => info(rest),
        "sample" => sample(rest),
        "verify" => verify_cmd(rest),
        "compare" => compare_cmd(rest),
        "export" => export(rest),
        "machine" => machine_cmd(rest),
        "-h" | "--help" | "help" => Ok(USAGE.into()),
        other => Err(Error::Io(format!("unknown command `{other}`\n{USAGE}"))),
    }?;
    Ok((out, Status::Done))
}

/// Loads a model file, or a built-in sample when no file of that name exists.
pub fn load_model(arg: &str) -> Result<Model> {
    load_model_with(arg, &ImportSetup::default())
}

/// As [`load_model`], placed by `setup`.
pub fn load_model_with(arg: &str, setup: &ImportSetup) -> Result<Model> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let bytes =
            std::fs::read(path).map_err(|e| Error::Io(format!("cannot read {arg}: {e}")))?;
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("model");
        crate::io::load_with(&bytes, stem, setup)
    } else if samples::SAMPLES.iter().any(|s| s.name == arg) {
        samples::load_sample_with(arg, setup)
    } else {
        Err(Error::Io(format!(
            "{arg}: no such file, and not a built-in sample (see `tspath sample --list`)"
        )))
    }
}

/// Splits `--flag value` pairs and positionals.
struct Args<'a> {
    positional: Vec<&'a str>,
    flags: Vec<(&'a str, Option<&'a str>)>,
}

fn parse<'a>(args: &'a [String], with_value: &[&str], bare: &[&str]) -> Result<Args<'a>> {
    let mut out = Args {
        positional: Vec::new(),
        flags: Vec::new(),
    };
    let mut i = 0;
    while i < args.len() {
        let a = args[i].as_str();
        if with_value.contains(&a) {
            let v = args
                .get(i + 1)
                .ok_or_else(|| Error::Io(format!("{a} needs a value\n{USAGE}")))?;
            out.flags.push((a, Some(v.as_str())));
            i += 2;
        } else if bare.contains(&a) {
            out.flags.push((a, None));
            i += 1;
        } else if a.starts_with('-') && a.len() > 1 {
            return Err(Error::Io(format!("unknown option {a}\n{USAGE}")));
        } else {
            out.positional.push(a);
            i += 1;
        }
    }
    Ok(out)
}

impl Args<'_> {
    fn value(&self, flag: &str) -> Option<&str> {
        self.flags
            .iter()
            .rev()
            .find(|(f, _)| *f == flag)
            .and_then(|(_, v)| *v)
    }
    fn has(&self, flag: &str) -> bool {
        self.flags.iter().any(|(f, _)| *f == flag)
    }
    fn count(&self, flag: &'static str) -> Result<Option<usize>> {
        match self.value(flag) {
            None => Ok(None),
            Some(v) => v
                .parse::<usize>()
                .map(Some)
                .map_err(|_| Error::Io(format!("{flag}: `{v}` is not a whole number"))),
        }
    }
    fn number(&self, flag: &'static str) -> Result<Option<f64>> {
        match self.value(flag) {
            None => Ok(None),
            Some(v) => v
                .parse::<f64>()
                .map(Some)
                .map_err(|_| Error::Io(format!("{flag}: `{v}` is not a number"))),
        }
    }
}

fn write_file(path: &str, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| Error::Io(format!("cannot write {path}: {e}")))
}

fn info(args: &[String]) -> Result<String> {
    let a = parse(args, SETUP_FLAGS, SETUP_SWITCHES)?;
    let [model] = a.positional[..] else {
        return Err(Error::Io(format!("info takes one MODEL\n{USAGE}")));
    };
    let m = load_model_with(model, &import_setup(&a)?)?;
    let mut s = serde_json::to_string_pretty(&m.summary()).expect("summary serialises");
    s.push('\n');
    Ok(s)
}

fn sample(args: &[String]) -> Result<String> {
    let a = parse(args, &["-o"], &["--list"])?;
    if a.has("--list") {
        return Ok(samples::SAMPLES
            .iter()
            .map(|s| format!("{}\n", s.name))
            .collect());
    }
    let [name] = a.positional[..] else {
        return Err(Error::Io(format!("sample takes one NAME\n{USAGE}")));
    };
    let json = samples::sample_json(name)?;
    match a.value("-o") {
        Some(path) => {
            write_file(path, &json)?;
            Ok(String::new())
        }
        None => Ok(json),
    }
}

fn export(args: &[String]) -> Result<String> {
    let a = parse(
        args,
        &[SETUP_FLAGS, &["-o", "--chordal"]].concat(),
        SETUP_SWITCHES,
    )?;
    let [model] = a.positional[..] else {
        return Err(Error::Io(format!("export takes one MODEL\n{USAGE}")));
    };
    let out = a
        .value("-o")
        .ok_or_else(|| Error::Io(format!("export needs -o FILE.stl or FILE.obj\n{USAGE}")))?;
    let chordal = a.number("--chordal")?.unwrap_or(0.01);
    if !(chordal.is_finite() && chordal > 0.0) {
        return Err(Error::param(
            "chordal_mm",
            format!("must be a positive number of mm, got {chordal}"),
        ));
    }
    let m = load_model_with(model, &import_setup(&a)?)?;
    let t = m.tessellate(chordal);
    let lower = out.to_ascii_lowercase();
    if lower.ends_with(".stl") {
        std::fs::write(out, crate::io::export::stl(&t, &m.name))
            .map_err(|e| Error::Io(format!("cannot write {out}: {e}")))?;
    } else if lower.ends_with(".obj") {
        write_file(out, &crate::io::export::obj(&t, &m.name))?;
    } else {
        return Err(Error::Io(format!(
            "{out}: the output must end in .stl or .obj"
        )));
    }
    Ok(format!(
        "{}: {} triangles, {} vertices, chordal tolerance {chordal} mm\n",
        out,
        t.indices.len() / 3,
        t.positions.len() / 3
    ))
}

/// The model set-up flags every command that reads a model takes.
const SETUP_FLAGS: &[&str] = &[
    "--model-units",
    "--scale",
    "--up",
    "--rotate",
    "--stock-side",
    "--stock-top",
    "--zero",
];
const SETUP_SWITCHES: &[&str] = &["--on-table"];

/// The model set-up the flags ask for.
fn import_setup(a: &Args) -> Result<ImportSetup> {
    let mut s = ImportSetup {
        strict_units: true,
        ..ImportSetup::default()
    };
    if let Some(u) = a.value("--model-units") {
        s.model_units = Some(LengthUnit::parse(u)?);
    }
    if let Some(v) = a.number("--scale")? {
        s.scale = v;
    }
    if let Some(u) = a.value("--up") {
        s.up = Up::parse(u)?;
    }
    if let Some(v) = a.number("--rotate")? {
        let turn = v.rem_euclid(360.0);
        if turn.fract() != 0.0 || turn as u32 % 90 != 0 {
            return Err(Error::Io(format!(
                "--rotate: `{v}` is not a quarter turn; use 0, 90, 180 or 270 (degrees, counter-clockwise seen from above)"
            )));
        }
        s.rotate_deg = turn as u32;
    }
    s.on_table = a.has("--on-table");
    if let Some(v) = a.number("--stock-side")? {
        s.stock_side_mm = v;
    }
    if let Some(v) = a.number("--stock-top")? {
        s.stock_top_mm = v;
    }
    if let Some(z) = a.value("--zero") {
        s.zero = ProgramZero::parse(z)?;
    }
    s.validate()?;
    Ok(s)
}

/// Options `plan` and `compare` take.
/// The plan's switches (flags without a value).
const PLAN_SWITCHES: &[&str] = &[
    "--verify",
    "--isfc-plain",
    "--no-deform",
    "--shear",
    "--on-table",
    "--full-retract",
];

/// The plan's own flags (with a value); `plan` and `compare` take these and the set-up's.
const PLAN_OWN_FLAGS: &[&str] = &[
    "--work-offset",
    "--slice-angle",
    "--tool-radius",
    "--scallop",
    "--chordal",
    "--feed",
    "--plunge-feed",
    "--clearance",
    "--feed-height",
    "--max-cl-points",
    "-o",
    "--report",
    "--verify-samples",
    "--verify-max-samples",
    "--machine",
    "--dialect",
    "--units",
    "--start-patch",
    "--finish-patch",
    "--lead",
    "--tilt",
    "--shank",
    "--shank-length",
    "--holder",
    "--holder-length",
    "--max-tilt",
    "--max-axis-step",
    "--strategy",
    "--axis-preset",
];

/// The model, machine and plan options of a `plan` or `compare` command line.
fn plan_setup(a: &Args) -> Result<(Model, machine::Machine, PlanOptions)> {
    let [model] = a.positional[..] else {
        return Err(Error::Io(format!(
            "plan and compare take one MODEL\n{USAGE}"
        )));
    };
    let m = load_model_with(model, &import_setup(a)?)?;
    let mach = load_machine(a.value("--machine").unwrap_or("3-axis"))?;
    let mut opts = PlanOptions::default();
    // The options a number sets as it is (checked with the others by `validate`).
    for (flag, slot) in [
        ("--tool-radius", &mut opts.tool_radius_mm),
        ("--scallop", &mut opts.scallop_mm),
        ("--chordal", &mut opts.chordal_mm),
        ("--feed", &mut opts.feed_mm_min),
        ("--plunge-feed", &mut opts.plunge_feed_mm_min),
        ("--clearance", &mut opts.clearance_mm),
        ("--feed-height", &mut opts.feed_height_mm),
        ("--max-axis-step", &mut opts.max_axis_step_deg),
    ] {
        if let Some(v) = a.number(flag)? {
            *slot = v;
        }
    }
    if let Some(v) = a.number("--max-cl-points")? {
        if !(v >= 1.0 && v.fract() == 0.0) {
            return Err(Error::Io(format!(
                "--max-cl-points: `{v}` is not a count of points (a whole number, 1 or more)"
            )));
        }
        opts.max_cl_points = v as u64;
    }
    if let Some(w) = a.value("--work-offset") {
        let n = w.trim_start_matches(['G', 'g']);
        opts.work_offset = match n.parse::<u8>() {
            Ok(g) if (54..=59).contains(&g) => g,
            _ => {
                return Err(Error::Io(format!(
                    "--work-offset: `{w}` is not a work offset; use G54 to G59"
                )))
            }
        };
    }
    let patch = |flag: &'static str| -> Result<Option<u32>> {
        match a.number(flag)? {
            None => Ok(None),
            Some(v) if v >= 0.0 && v.fract() == 0.0 => Ok(Some(v as u32)),
            Some(v) => Err(Error::Io(format!("{flag}: `{v}` is not a patch number"))),
        }
    };
    opts.start_patch = patch("--start-patch")?;
    opts.finish_patch = patch("--finish-patch")?;
    match a.value("--axis-preset") {
        None | Some("vertical") => {}
        Some("gan2014") => opts = opts.with_paper_axis(),
        Some("yuan2012") => opts.facet_normal_axis = true,
        Some(other) => {
            return Err(Error::Io(format!(
                "--axis-preset: `{other}` is not a preset: vertical (the collision-free axis closest to +Z, the default), gan2014 (10° lead from the surface normal, as in Gan et al. 2014) or yuan2012 (iso-planar: the area-weighted normal of the CL facets near the ball, Yuan & Shao 2012 eq. 12)"
            )))
        }
    }
    if let Some(v) = a.number("--lead")? {
        opts.lead_deg = v;
    }
    if let Some(v) = a.number("--tilt")? {
        opts.tilt_deg = v;
    }
    if let Some(v) = a.number("--shank")? {
        opts.shank_radius_mm = Some(v);
    }
    if let Some(v) = a.number("--shank-length")? {
        opts.shank_length_mm = v;
    }
    if let Some(v) = a.number("--holder")? {
        opts.holder_radius_mm = v;
    }
    if let Some(v) = a.number("--holder-length")? {
        opts.holder_length_mm = v;
    }
    // A three-axis machine keeps the tool axis at +Z; collisions go into the report.
    opts.max_tilt_deg = match a.number("--max-tilt")? {
        Some(v) => v,
        None if mach.rotaries.is_empty() => 0.0,
        None => opts.max_tilt_deg,
    };
    if mach.rotaries.is_empty()
        && (opts.max_tilt_deg != 0.0
            || opts.lead_deg != 0.0
            || opts.tilt_deg != 0.0
            || opts.facet_normal_axis)
    {
        return Err(Error::Io(
            "a three-axis machine cannot tilt the tool: drop --max-tilt/--lead/--tilt/--axis-preset or choose a five-axis --machine".into(),
        ));
    }
    // Every axis the planner chooses must be one the machine can post.
    let reach = mach.reachable_tilt_deg();
    if !mach.rotaries.is_empty() && opts.max_tilt_deg > reach {
        return Err(Error::Io(format!(
            "--max-tilt {}° is past what {} can tilt the tool ({reach}°, the travel of its tilting axis): use --max-tilt {reach} or less",
            opts.max_tilt_deg, mach.name
        )));
    }
    if let Some(name) = a.value("--strategy") {
        opts.strategy = Strategy::parse(name)?;
    }
    if a.has("--isfc-plain") {
        opts.isfc_plain = true;
    }
    if let Some(v) = a.number("--slice-angle")? {
        opts.slice_angle_deg = v;
    }
    if a.has("--no-deform") {
        opts.isoplanar_deform = false;
    }
    if a.has("--shear") {
        opts.isoplanar_shear = true;
    }
    if a.has("--full-retract") {
        opts.full_retract = true;
    }
    Ok((m, mach, opts))
}

/// How far a long job has got, shown on stderr as `what` and a percentage on one line
/// rewritten in place when stderr is a terminal (nothing otherwise: logs and pipes stay
/// clean); the line is cleared when the job is dropped, however it ended.
struct TerminalProgress {
    what: &'static str,
    shown: bool,
    last: Option<u32>,
}

impl TerminalProgress {
    fn new(what: &'static str) -> Self {
        use std::io::IsTerminal;
        TerminalProgress {
            what,
            shown: std::io::stderr().is_terminal(),
            last: None,
        }
    }

    /// Shows share `f` (0 to 1) done; never cancels.
    fn update(&mut self, f: f64) -> bool {
        use std::io::Write;
        let percent = (100.0 * f.clamp(0.0, 1.0)).floor() as u32;
        if self.shown && self.last != Some(percent) {
            self.last = Some(percent);
            let mut e = std::io::stderr();
            let _ = write!(e, "\r{} {percent:3} %", self.what);
            let _ = e.flush();
        }
        true
    }
}

impl Drop for TerminalProgress {
    fn drop(&mut self) {
        use std::io::Write;
        if self.last.is_some() {
            let mut e = std::io::stderr();
            let _ = write!(e, "\r{:width$}\r", "", width = self.what.len() + 6);
            let _ = e.flush();
        }
    }
}

fn plan(args: &[String]) -> Result<(String, Status)> {
    let a = parse(args, &[SETUP_FLAGS, PLAN_OWN_FLAGS].concat(), PLAN_SWITCHES)?;
    let (m, mach, opts) = plan_setup(&a)?;
    let dialect = Dialect::parse(a.value("--dialect").unwrap_or("linuxcnc"))?;
    let units = Units::parse(a.value("--units").unwrap_or("mm"))?;
    let t0 = Instant::now();
    let mut shown = TerminalProgress::new("planning");
    let planned = plan::plan(&m, &opts, &mut |f| shown.update(f));
    drop(shown);
    let planned = planned?;
    let mut report = planned.report(&opts);
    report.plan_ms = t0.elapsed().as_secs_f64() * 1e3;
    report.set_machining_time(&planned.toolpath, &opts, &mach);
    let gcode = machine::post(
        &planned.toolpath,
        &opts,
        &JobInfo::for_model(&m, planned.strategy),
        &mach,
        dialect,
        units,
    )?;
    let verification = if a.has("--verify") {
        let cap = a
            .count("--verify-max-samples")?
            .unwrap_or(verify::PLAN_VERIFY_MAX_SAMPLES);
        let v = verify::verify_plan(&m, &planned, &opts, a.count("--verify-samples")?, cap)?;
        report.add_verification(&v);
        Some(v)
    } else {
        None
    };
    let mut report_value = serde_json::to_value(&report).expect("report serialises");
    if let Some(v) = verification {
        report_value["verify"] = serde_json::to_value(&v).expect("verification serialises");
    }
    let report_json =
        serde_json::to_string_pretty(&report_value).expect("report serialises") + "\n";
    let mut out = String::new();
    match a.value("-o") {
        Some(p) => write_file(p, &gcode)?,
        None => out.push_str(&gcode),
    }
    match a.value("--report") {
        Some(p) => write_file(p, &report_json)?,
        None if a.value("-o").is_some() => out.push_str(&report_json),
        None => {}
    }
    let status = if report.problems.is_empty() {
        Status::Done
    } else {
        Status::Problems(report.problems.iter().map(|p| p.message.clone()).collect())
    };
    Ok((out, status))
}

/// `compare`: every strategy (or those `--strategies` names) on one model, each cut
/// simulated unless `--no-verify`; a Markdown table on stdout, JSON with `--report`, CSV
/// with `--csv`.
fn compare_cmd(args: &[String]) -> Result<String> {
    let a = parse(
        args,
        &[SETUP_FLAGS, PLAN_OWN_FLAGS, &["--strategies", "--csv"]].concat(),
        &[PLAN_SWITCHES, &["--no-verify"]].concat(),
    )?;
    if a.value("--strategy").is_some() || a.value("-o").is_some() {
        return Err(Error::Io(
            "compare plans every strategy and writes no program: use --strategies a,b,... to choose some, and --report/--csv for its files".into(),
        ));
    }
    let (m, mach, opts) = plan_setup(&a)?;
    let entries = plan::compare::Entry::parse_list(a.value("--strategies"))?;
    let max = if a.has("--no-verify") {
        None
    } else {
        Some(
            a.count("--verify-max-samples")?
                .unwrap_or(verify::PLAN_VERIFY_MAX_SAMPLES),
        )
    };
    let t0 = Instant::now();
    let (c, _) = plan::compare::compare(
        &m,
        &opts,
        &entries,
        Some(&mach),
        max,
        &|| t0.elapsed().as_secs_f64() * 1e3,
        &mut |_| true,
    )?;
    if let Some(p) = a.value("--report") {
        write_file(
            p,
            &(serde_json::to_string_pretty(&c).expect("comparison serialises") + "\n"),
        )?;
    }
    if let Some(p) = a.value("--csv") {
        write_file(p, &c.csv())?;
    }
    Ok(c.markdown())
}

fn verify_cmd(args: &[String]) -> Result<String> {
    let a = parse(
        args,
        &[
            SETUP_FLAGS,
            &[
                "--tool-radius",
                "--samples",
                "--bound",
                "--scallop",
                "--gouge-tolerance",
                "--machine",
                "--dialect",
            ],
        ]
        .concat(),
        SETUP_SWITCHES,
    )?;
    let [model, path_file] = a.positional[..] else {
        return Err(Error::Io(format!(
            "verify takes a MODEL and a G-code or tool path file\n{USAGE}"
        )));
    };
    let Some(r) = a.number("--tool-radius")? else {
        return Err(Error::Io(format!(
            "verify needs --tool-radius MM (the ball-end radius)\n{USAGE}"
        )));
    };
    let m = load_model_with(model, &import_setup(&a)?)?;
    let text = std::fs::read_to_string(path_file)
        .map_err(|e| Error::Io(format!("cannot read {path_file}: {e}")))?;
    let (path, mut opts) = if text.trim_start().starts_with('{') {
        (
            CutterPath::from_cl_json(&text, r)?,
            VerifyOptions::default(),
        )
    } else {
        let mach = load_machine(a.value("--machine").unwrap_or("3-axis"))?;
        let dialect = Dialect::parse(a.value("--dialect").unwrap_or("linuxcnc"))?;
        let (path, header) =
            verify::gcode::read_program(&text, r, &mach, dialect).map_err(|e| match e {
                Error::InvalidParameter { name, message } => Error::InvalidParameter {
                    name,
                    message: format!("{path_file}: {message}"),
                },
                other => other,
            })?;
        // The tolerances the program was made for, unless given.
        (path, header.options())
    };
    if let Some(h) = a.number("--scallop")? {
        opts.scallop_mm = h;
    }
    if let Some(t) = a.number("--gouge-tolerance")? {
        opts.gouge_tolerance_mm = t;
    }
    if let Some(n) = a.count("--samples")? {
        opts.samples = n;
    }
    let v = match a.number("--bound")? {
        Some(b) => verify::verify_to_bound(&m.surface, &path, &opts, b)?,
        None => verify::verify(&m.surface, &path, &opts)?,
    };
    Ok(serde_json::to_string_pretty(&v).expect("verification serialises") + "\n")
}

/// A built-in machine by name, or a machine JSON file.
pub fn load_machine(arg: &str) -> Result<machine::Machine> {
    let path = std::path::Path::new(arg);
    if machine::MACHINES.iter().any(|m| m.name == arg) {
        machine::builtin(arg)
    } else if path.exists() {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Io(format!("cannot read {arg}: {e}")))?;
        machine::from_json(&text).map_err(|e| Error::Io(format!("{arg}: {e}")))
    } else {
        machine::builtin(arg)
    }
}

fn machine_cmd(args: &[String]) -> Result<String> {
    let a = parse(args, &["-o"], &["--list"])?;
    if a.has("--list") {
        let mut s = String::from("machines:\n");
        for m in machine::MACHINES {
            s.push_str(&format!("  {:<16} {}\n", m.name, m.description));
        }
        s.push_str("dialects:\n");
        for (_, name, what) in machine::DIALECTS {
            s.push_str(&format!("  {name:<16} {what}\n"));
        }
        return Ok(s);
    }
    let [name] = a.positional[..] else {
        return Err(Error::Io(format!("machine takes one NAME\n{USAGE}")));
    };
    let json = machine::to_json(&machine::builtin(name)?);
    match a.value("-o") {
        Some(path) => {
            write_file(path, &json)?;
            Ok(String::new())
        }
        None => Ok(json),
    }
}
