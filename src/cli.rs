//! Command-line front end: argument parsing and the commands, over the same library calls
//! the page uses. Returns the text to print so that tests can run it in-process.

use crate::error::{Error, Result};
use crate::machine::{self, JobInfo};
use crate::model::{samples, Model};
use crate::plan::{isoparametric, PlanOptions};
use crate::verify::{self, CutterPath, VerifyOptions};
use std::time::Instant;

const USAGE: &str = "usage:
  tspath info MODEL
  tspath sample --list
  tspath sample NAME -o FILE.json
  tspath plan MODEL [--tool-radius MM] [--scallop MM] [--chordal MM] [--feed MM_PER_MIN]
              [-o OUT.nc] [--report REPORT.json] [--verify [--verify-samples N]]
  tspath verify MODEL GCODE_OR_TOOLPATH --tool-radius MM [--samples N] [--bound MM]
              [--scallop MM] [--gouge-tolerance MM]
MODEL is a model file (.json, .tsm, .obj) or the name of a built-in sample.
verify simulates the ball-end cut of a G-code program (as `plan` writes it) or of a
tspath-cl JSON tool path and prints the scallops and gouges it leaves as JSON; --bound
raises the sample count until the stated error bound is within MM.
";

/// Runs one command; returns what it prints on success.
pub fn run(args: &[String]) -> Result<String> {
    let Some(cmd) = args.first() else {
        return Err(Error::Io(USAGE.into()));
    };
    let rest = &args[1..];
    match cmd.as_str() {
        "info" => info(rest),
        "sample" => sample(rest),
        "plan" => plan(rest),
        "verify" => verify_cmd(rest),
        "-h" | "--help" | "help" => Ok(USAGE.into()),
        other => Err(Error::Io(format!("unknown command `{other}`\n{USAGE}"))),
    }
}

/// Loads a model file, or a built-in sample when no file of that name exists.
pub fn load_model(arg: &str) -> Result<Model> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let bytes =
            std::fs::read(path).map_err(|e| Error::Io(format!("cannot read {arg}: {e}")))?;
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("model");
        crate::io::load(&bytes, stem)
    } else if samples::SAMPLES.iter().any(|s| s.name == arg) {
        samples::load_sample(arg)
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
    let a = parse(args, &[], &[])?;
    let [model] = a.positional[..] else {
        return Err(Error::Io(format!("info takes one MODEL\n{USAGE}")));
    };
    let m = load_model(model)?;
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

fn plan(args: &[String]) -> Result<String> {
    let a = parse(
        args,
        &[
            "--tool-radius",
            "--scallop",
            "--chordal",
            "--feed",
            "-o",
            "--report",
            "--verify-samples",
        ],
        &["--verify"],
    )?;
    let [model] = a.positional[..] else {
        return Err(Error::Io(format!("plan takes one MODEL\n{USAGE}")));
    };
    let m = load_model(model)?;
    let mut opts = PlanOptions::default();
    if let Some(v) = a.number("--tool-radius")? {
        opts.tool_radius_mm = v;
    }
    if let Some(v) = a.number("--scallop")? {
        opts.scallop_mm = v;
    }
    if let Some(v) = a.number("--chordal")? {
        opts.chordal_mm = v;
    }
    if let Some(v) = a.number("--feed")? {
        opts.feed_mm_min = v;
    }
    let t0 = Instant::now();
    let path = isoparametric::plan_zigzag(&m, &opts, &mut |_| true)?;
    let mut report = path.report("isoparametric", opts.feed_mm_min, opts.plunge_feed_mm_min);
    report.plan_ms = t0.elapsed().as_secs_f64() * 1e3;
    let gcode = machine::gcode_3axis(
        &path,
        &opts,
        &JobInfo {
            model: m.name.clone(),
            strategy: "isoparametric".into(),
        },
    );
    let mut report_value = serde_json::to_value(&report).expect("report serialises");
    if a.has("--verify") {
        let mut vopts = VerifyOptions::default()
            .with_scallop(opts.scallop_mm)
            .with_gouge_tolerance(opts.chordal_mm);
        if let Some(n) = a.count("--verify-samples")? {
            vopts = vopts.with_samples(n);
        }
        let v = verify::verify(&m.surface, &CutterPath::from_toolpath(&path)?, &vopts)?;
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
    Ok(out)
}

fn verify_cmd(args: &[String]) -> Result<String> {
    let a = parse(
        args,
        &[
            "--tool-radius",
            "--samples",
            "--bound",
            "--scallop",
            "--gouge-tolerance",
        ],
        &[],
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
    let m = load_model(model)?;
    let text = std::fs::read_to_string(path_file)
        .map_err(|e| Error::Io(format!("cannot read {path_file}: {e}")))?;
    let mut opts = VerifyOptions::default();
    let path = if text.trim_start().starts_with('{') {
        CutterPath::from_cl_json(&text, r)?
    } else {
        let prog = verify::gcode::read_3axis(&text)?;
        if let Some(hr) = prog.header_tool_radius_mm {
            if hr != r {
                return Err(Error::param(
                    "tool_radius_mm",
                    format!("{path_file} says it was made for a ball-end radius {hr} mm, but --tool-radius is {r} mm"),
                ));
            }
        }
        // The tolerances the program was made for, unless given.
        if let Some(h) = prog.header_scallop_mm {
            opts.scallop_mm = h;
        }
        if let Some(c) = prog.header_chordal_mm {
            opts.gouge_tolerance_mm = c;
        }
        CutterPath::from_tool_tips(r, prog.tips)?
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
