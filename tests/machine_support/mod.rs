//! Shared by the machine tests: sample plans, five-axis variants of them, synthetic paths
//! through the singular pose, and running LinuxCNC's `rs274`.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;
use tspath::geom::{Point3, Vector3};
use tspath::machine::JobInfo;
use tspath::model::samples;
use tspath::plan::{isoparametric, Move, MoveKind, PlanOptions, Toolpath};

/// Coarse options so that every sample plans in a moment.
pub fn opts() -> PlanOptions {
    let mut o = PlanOptions::default()
        .with_tool_radius(3.0)
        .with_scallop(0.05);
    // Planned three-axis (tool axis +Z); the five-axis variants are made from these paths.
    o.max_tilt_deg = 0.0;
    o
}

/// Coarse options a sample is planned (and posted) with, so that the machine tests stay quick
/// on every sample: the scallop sets how many passes a path has, and the machine tests need
/// the shapes (steep walls, poles, saddles, extraordinary points), not fine finishing. A
/// smaller ball where the model's concave radii are small: the keycaps' fillets are about
/// 1.4 mm, the bumps-hole dimple's rim about 2.4 mm.
pub fn opts_for(sample: &str) -> PlanOptions {
    match sample {
        "dome" => opts(),
        s if s.starts_with("keycap") => opts().with_tool_radius(0.5).with_scallop(0.05),
        "bumps-hole" => opts().with_tool_radius(2.0).with_scallop(0.2),
        "head" => opts().with_scallop(0.3),
        _ => opts().with_scallop(0.2),
    }
}

pub fn job(model: &str) -> JobInfo {
    JobInfo {
        model: model.into(),
        strategy: "isoparametric".into(),
        program_zero: "the model's origin".into(),
    }
}

/// The planner's path on one sample (tool axis +Z).
pub fn sample_plan(name: &str) -> Toolpath {
    let m = samples::load_sample(name).unwrap();
    isoparametric::plan_zigzag(&m, &opts_for(name), &mut |_| true)
        .unwrap_or_else(|e| panic!("planning {name}: {e}"))
}

/// The planners' paths on every sample (tool axis +Z), and the space-filling curve's on two
/// (a part with a hole and one with extraordinary points).
pub fn sample_plans() -> Vec<(String, Toolpath)> {
    let mut plans: Vec<(String, Toolpath)> = samples::SAMPLES
        .iter()
        .map(|s| (s.name.to_string(), sample_plan(s.name)))
        .collect();
    for name in ["plate-hole", "keycap-convex"] {
        let m = samples::load_sample(name).unwrap();
        let o = opts_for(name).with_strategy(tspath::plan::Strategy::Isfc);
        let p = tspath::plan::plan(&m, &o, &mut |_| true)
            .unwrap_or_else(|e| panic!("planning {name} with isfc: {e}"));
        plans.push((format!("{name}-isfc"), p.toolpath));
    }
    plans
}

/// Largest tilt of the test axes from +Z (degrees): a five-axis finishing path on a part
/// clamped on the table works from above.
pub const MAX_TILT_DEG: f64 = 60.0;

/// The same path with the tool axis along the surface normal at each contact point (the ball
/// centre is `cc + r·n`, so `n = (cl − cc)/r`), tilted at most [`MAX_TILT_DEG`] from +Z;
/// moves off the surface take the axis of the nearest move on it. The ball centres do not
/// change: a ball-end cuts the same with any axis.
pub fn along_normals(path: &Toolpath) -> Toolpath {
    let on_surface =
        |m: &Move| matches!(m.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge);
    let limit = |n: Vector3| -> Vector3 {
        let tilt = n.z.clamp(-1.0, 1.0).acos();
        let max = MAX_TILT_DEG.to_radians();
        let h = Vector3::new(n.x, n.y, 0.0);
        if tilt <= max || h.norm() == 0.0 {
            n
        } else {
            (h.normalize() * max.sin() + Vector3::z() * max.cos()).normalize()
        }
    };
    let normals: Vec<Option<Vector3>> = path
        .moves
        .iter()
        .map(|m| on_surface(m).then(|| limit((m.cl_point - m.cc_point).normalize())))
        .collect();
    let n = path.moves.len();
    let mut moves = path.moves.clone();
    for i in 0..n {
        let axis = normals[i].or_else(|| {
            (1..n).find_map(|d| {
                let after = (i + d < n).then(|| normals[i + d]).flatten();
                let before = (i >= d).then(|| normals[i - d]).flatten();
                match moves[i].kind {
                    MoveKind::Rapid => after.or(before),
                    _ => before.or(after),
                }
            })
        });
        moves[i].tool_axis = axis.unwrap_or(Vector3::z());
    }
    Toolpath {
        tool_radius_mm: path.tool_radius_mm,
        moves,
        max_predicted_scallop_mm: path.max_predicted_scallop_mm,
        runs: path.runs.clone(),
        params: path.params.clone(),
    }
}

/// A path whose tool axis sweeps through `axes` one move each, the tip moving along X by
/// `step_mm` per move at height `z_mm`; it starts with a rapid and ends with a retract.
pub fn sweep(axes: &[Vector3], r: f64, step_mm: f64, z_mm: f64) -> Toolpath {
    let mut moves = Vec::new();
    let n = axes.len();
    for (i, a) in axes.iter().enumerate() {
        let a = a.normalize();
        let tip = Point3::new((i as f64 - n as f64 / 2.0) * step_mm, 5.0, z_mm);
        let kind = if i == 0 {
            MoveKind::Rapid
        } else {
            MoveKind::Feed
        };
        moves.push(Move {
            kind,
            cc_point: tip,
            cl_point: tip + a * r,
            tool_axis: a,
            patch: 0,
            line: 0,
        });
    }
    let last = *moves.last().unwrap();
    moves.push(Move {
        kind: MoveKind::Retract,
        cl_point: last.cl_point + last.tool_axis * 20.0,
        ..last
    });
    Toolpath {
        tool_radius_mm: r,
        moves,
        max_predicted_scallop_mm: 0.0,
        runs: Vec::new(),
        params: Vec::new(),
    }
}

/// Unit vector at `tilt_deg` from +Z towards azimuth `azimuth_deg` (from +X towards +Y).
pub fn axis(tilt_deg: f64, azimuth_deg: f64) -> Vector3 {
    let (t, a) = (tilt_deg.to_radians(), azimuth_deg.to_radians());
    Vector3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos())
}

/// A scratch directory for this test binary.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tspath-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// What `rs274` made of a file.
pub struct Rs274 {
    pub accepted: bool,
    pub status: Option<i32>,
    pub stdout: String,
    /// The interpreter's message (stderr without its `executing` lines).
    pub message: String,
}

/// Runs LinuxCNC's stand-alone interpreter in batch mode on `file` with a tool table for a
/// ball-end of `tool_radius_mm`. Panics (does not skip) when `rs274` is missing: the test
/// command installs it (`scripts/setup`, Debian package linuxcnc-uspace).
pub fn rs274(file: &Path, tool_radius_mm: f64) -> Rs274 {
    let dir = file.parent().unwrap();
    let table = dir.join("tool.tbl");
    // The stand-alone interpreter reads tool-table lengths in inches.
    std::fs::write(
        &table,
        format!("T1 P1 Z0 D{:.6} ;ball-end\n", 2.0 * tool_radius_mm / 25.4),
    )
    .unwrap();
    // rs274 maps its tool table through `$HOME/.tool.mmap`, truncating it at start: two runs
    // sharing a HOME crash each other (bus error). Each scratch directory is its own HOME.
    let out = Command::new("rs274")
        .env("HOME", dir)
        .current_dir(dir)
        .arg("-g")
        .arg("-t")
        .arg(&table)
        .arg(file)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run rs274 ({e}): LinuxCNC's stand-alone interpreter is needed; \
                 run scripts/setup (it installs the Debian package linuxcnc-uspace)"
            )
        });
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let message = stderr
        .lines()
        .filter(|l| l.trim() != "executing")
        .collect::<Vec<_>>()
        .join("\n");
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    Rs274 {
        accepted: out.status.success()
            && message.trim().is_empty()
            && stdout.contains("PROGRAM_END"),
        status: out.status.code(),
        stdout,
        message,
    }
}

/// The end points of `STRAIGHT_TRAVERSE` / `STRAIGHT_FEED` canonical commands:
/// (feed?, [x, y, z, a, b, c]) in program units and degrees.
pub fn canonical_moves(stdout: &str) -> Vec<(bool, [f64; 6])> {
    stdout
        .lines()
        .filter_map(|l| {
            let (feed, rest) = if let Some(i) = l.find("STRAIGHT_FEED(") {
                (true, &l[i + "STRAIGHT_FEED(".len()..])
            } else if let Some(i) = l.find("STRAIGHT_TRAVERSE(") {
                (false, &l[i + "STRAIGHT_TRAVERSE(".len()..])
            } else {
                return None;
            };
            let inside = rest.trim_end().trim_end_matches(')');
            let v: Vec<f64> = inside
                .split(',')
                .map(|x| x.trim().parse::<f64>().unwrap())
                .collect();
            assert_eq!(v.len(), 6, "{l}");
            Some((feed, [v[0], v[1], v[2], v[3], v[4], v[5]]))
        })
        .collect()
}
