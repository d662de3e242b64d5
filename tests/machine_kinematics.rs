//! Kinematics against closed forms, forward ∘ inverse on every machine, continuity of the
//! rotaries across the singular pose, unwinding, and limit errors.

use crate::machine_support;

use machine_support::*;
use tspath::geom::{Point3, Vector3};
use tspath::machine::{self, post, Dialect, Machine, Units};

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// Unusual machines: a nutating (45°) B head axis, pivots off every axis, reversed directions.
fn odd_machines() -> Vec<Machine> {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    [
        format!(
            r#"{{"format": "tspath-machine", "version": 1, "name": "odd-table-table",
            "rotaries": [
              {{"name": "B", "mount": "table", "axis": [0, {s}, {s}], "pivot_mm": [12, -7, -95], "direction": -1, "limits_deg": [-180, 180]}},
              {{"name": "C", "mount": "table", "axis": [0, 0, 1], "pivot_mm": [3, 4, 0], "direction": -1, "limits_deg": null}}
            ]}}"#
        ),
        r#"{"format": "tspath-machine", "version": 1, "name": "odd-head-table",
            "rotaries": [
              {"name": "C", "mount": "table", "axis": [0, 0, 1], "pivot_mm": [-5, 2, 0], "direction": -1},
              {"name": "A", "mount": "head", "axis": [1, 0, 0], "pivot_mm": [0, 20, 180], "limits_deg": [-95, 95]}
            ]}"#
        .to_string(),
    ]
    .iter()
    .map(|j| machine::from_json(j).unwrap())
    .collect()
}

fn five_axis_machines() -> Vec<Machine> {
    let mut v: Vec<Machine> = machine::MACHINES
        .iter()
        .map(|m| machine::builtin(m.name).unwrap())
        .filter(|m| !m.rotaries.is_empty())
        .collect();
    v.extend(odd_machines());
    v
}

#[test]
fn table_table_ac_matches_its_closed_form() {
    // A about X through q = (0, 0, -80), carrying C about Z through the origin:
    // tool axis v = (sin A sin C, sin A cos C, cos A); joints X = Rx(A)(Rz(C) p − q) + q.
    let m = machine::builtin("table-table-ac").unwrap();
    let q = Vector3::new(0.0, 0.0, -80.0);
    let p = Point3::new(12.0, -7.5, 3.25);
    let mut worst: f64 = 0.0;
    for ia in -8..=8 {
        for ic in -12..=12 {
            let (a, c) = (ia as f64 * 15.0, ic as f64 * 30.0 + 7.0);
            let (sa, ca) = a.to_radians().sin_cos();
            let (sc, cc) = c.to_radians().sin_cos();
            let v = Vector3::new(sa * sc, sa * cc, ca);
            worst = worst.max((m.tool_axis([a, c]) - v).norm());
            let rz = Vector3::new(cc * p.x - sc * p.y, sc * p.x + cc * p.y, p.z) - q;
            let x = Vector3::new(rz.x, ca * rz.y - sa * rz.z, sa * rz.y + ca * rz.z) + q;
            let j = m.linear_joints(&p, [a, c]);
            worst = worst.max((Vector3::from(j) - x).norm());
            // The inverse finds (A, C) or its twin (−A, C + 180°).
            if a.abs() > 1.0 {
                let sols = m.rotary_solutions(&v, [0.0, 0.0], true).unwrap();
                let same =
                    |x: f64, y: f64| ((x - y) / 360.0 - ((x - y) / 360.0).round()).abs() < 1e-9;
                assert!(
                    sols.iter()
                        .any(|s| (s.rotary_deg[0] - a).abs() < 1e-9 && same(s.rotary_deg[1], c)),
                    "A {a} C {c}: {sols:?}"
                );
                assert!(sols.iter().any(
                    |s| (s.rotary_deg[0] + a).abs() < 1e-9 && same(s.rotary_deg[1], c + 180.0)
                ));
            }
        }
    }
    assert!(worst < 1e-12, "closed form differs by {worst}");
    println!("table-table-ac against its closed form: largest difference {worst:.1e}");
}

#[test]
fn forward_kinematics_inverts_every_inverse_solution() {
    let mut seed = 7u64;
    let mut worst_tip: f64 = 0.0;
    let mut worst_axis: f64 = 0.0;
    let mut solutions = 0;
    for m in five_axis_machines() {
        for _ in 0..400 {
            let tilt = 80.0 * lcg(&mut seed);
            let azimuth = 360.0 * lcg(&mut seed) - 180.0;
            let v = axis(tilt, azimuth);
            let tip = Point3::new(
                100.0 * lcg(&mut seed) - 50.0,
                100.0 * lcg(&mut seed) - 50.0,
                40.0 * lcg(&mut seed),
            );
            let previous = [40.0 * lcg(&mut seed) - 20.0, 720.0 * lcg(&mut seed) - 360.0];
            let Ok(sols) = m.rotary_solutions(&v, previous, true) else {
                continue; // a nutating head cannot reach every axis
            };
            for s in sols {
                let j = machine::Joints {
                    xyz_mm: m.linear_joints(&tip, s.rotary_deg),
                    rotary_deg: s.rotary_deg,
                };
                let pose = m.forward(&j);
                worst_tip = worst_tip.max((pose.tip - tip).norm());
                // Chord length = angle (rad) for small angles, without acos round-off.
                worst_axis = worst_axis.max((pose.axis - v).norm().to_degrees());
                for (i, r) in m.rotaries.iter().enumerate() {
                    if let Some((lo, hi)) = r.limits_deg {
                        assert!(s.rotary_deg[i] >= lo && s.rotary_deg[i] <= hi);
                    }
                }
                solutions += 1;
            }
        }
    }
    assert!(solutions > 2000);
    assert!(worst_tip < 1e-9 && worst_axis < 1e-9);
    println!(
        "forward ∘ inverse over {solutions} solutions on {} machines: tip {worst_tip:.1e} mm, axis {worst_axis:.1e}°",
        five_axis_machines().len()
    );
}

/// Joint values of a path on a machine (through the post, as every program gets them).
fn joints_of(path: &tspath::plan::Toolpath, m: &Machine) -> tspath::Result<Vec<machine::Joints>> {
    machine::post::post_program(
        path,
        &opts(),
        &job("sweep"),
        m,
        Dialect::LinuxCnc,
        Units::Mm,
    )
    .map(|p| p.joints)
}

/// Largest rotary change between consecutive moves, and the tool-axis angle of that step.
fn rotary_steps(path: &tspath::plan::Toolpath, j: &[machine::Joints]) -> Vec<(f64, f64, f64)> {
    (1..j.len())
        .map(|i| {
            let d0 = (j[i].rotary_deg[0] - j[i - 1].rotary_deg[0]).abs();
            let d1 = (j[i].rotary_deg[1] - j[i - 1].rotary_deg[1]).abs();
            let step = path.moves[i]
                .tool_axis
                .angle(&path.moves[i - 1].tool_axis)
                .to_degrees();
            (d0, d1, step)
        })
        .collect()
}

#[test]
fn rotaries_cross_the_singular_pose_without_jumping() {
    let mut report = Vec::new();
    for m in five_axis_machines() {
        let inner = m.inner_rotary().unwrap();
        let outer = 1 - inner;
        for azimuth in [0.0, 30.0, 90.0, 135.0, -60.0] {
            // Straight through the pole: tilt −20° … 20° in 1° steps along one azimuth.
            let axes: Vec<Vector3> = (-20..=20).map(|t| axis(t as f64, azimuth)).collect();
            let path = sweep(&axes, 3.0, 0.5, 10.0);
            let j = match joints_of(&path, &m) {
                Ok(j) => j,
                Err(e) if m.name == "odd-table-table" => {
                    // The nutating table cannot reach every pose; it must say so clearly.
                    assert!(e.to_string().contains("move"), "{e}");
                    continue;
                }
                Err(e) => panic!("{} azimuth {azimuth}: {e}", m.name),
            };
            let pole = 20; // move index of tilt 0 (move i has tilt i − 20)
            assert_eq!(
                j[pole].rotary_deg[inner],
                j[pole - 1].rotary_deg[inner],
                "{}: the inner axis keeps its value at the singular pose",
                m.name
            );
            let mut worst_outer: f64 = 0.0;
            let mut worst_inner: f64 = 0.0;
            for (i, (d0, d1, step)) in rotary_steps(&path, &j).into_iter().enumerate().take(40) {
                let (d_out, d_in) = if outer == 0 { (d0, d1) } else { (d1, d0) };
                if m.name.starts_with("odd") {
                    // Non-orthogonal axes: bound by twice the step.
                    assert!(
                        d_out.max(d_in) <= 2.0 * step + 1e-9,
                        "{} move {}",
                        m.name,
                        i + 1
                    );
                } else {
                    assert!(
                        d_out <= step + 1e-9,
                        "{} az {azimuth} move {}: outer {d_out}° > step {step}°",
                        m.name,
                        i + 1
                    );
                    assert!(
                        d_in <= 1e-9,
                        "{} az {azimuth} move {}: inner turned {d_in}°",
                        m.name,
                        i + 1
                    );
                }
                worst_outer = worst_outer.max(d_out);
                worst_inner = worst_inner.max(d_in);
            }
            report.push(format!(
                "{} azimuth {azimuth}°: largest step outer {worst_outer:.4}°, inner {worst_inner:.4}° (axis step 1°)",
                m.name
            ));
        }
        // A near miss (0.5° from the pole): the inner axis turns as the azimuth of the tool
        // axis does, never more, and the outer no more than the axis step.
        let axes: Vec<Vector3> = (-20..=20)
            .map(|t| {
                let x = (t as f64).to_radians().sin();
                Vector3::new(x, 0.5f64.to_radians().sin(), 1.0).normalize()
            })
            .collect();
        let path = sweep(&axes, 3.0, 0.5, 10.0);
        if let Ok(j) = joints_of(&path, &m) {
            if !m.name.starts_with("odd") {
                let mut worst_in: f64 = 0.0;
                for (i, (d0, d1, step)) in rotary_steps(&path, &j).into_iter().enumerate().take(40)
                {
                    let (d_out, d_in) = if outer == 0 { (d0, d1) } else { (d1, d0) };
                    let (a, b) = (path.moves[i].tool_axis, path.moves[i + 1].tool_axis);
                    let mut daz = (b.y.atan2(b.x) - a.y.atan2(a.x)).to_degrees().abs();
                    if daz > 180.0 {
                        daz = 360.0 - daz;
                    }
                    assert!(d_out <= step + 1e-9, "{} near miss move {}", m.name, i + 1);
                    assert!(
                        d_in <= daz + 1e-6,
                        "{} near miss move {}: inner {d_in}° > azimuth {daz}°",
                        m.name,
                        i + 1
                    );
                    worst_in = worst_in.max(d_in);
                }
                report.push(format!(
                    "{} near miss 0.5°: inner axis turns at most {worst_in:.2}° per move (= the azimuth change of the tool axis)",
                    m.name
                ));
            }
        }
    }
    for r in report {
        println!("{r}");
    }
}

#[test]
fn rotaries_pass_near_the_singular_pose_with_the_smallest_motion() {
    // The tool axis sweeps past the pole (+Z, along C) in 1° steps, missing it by `miss`, the
    // closest approach halfway between two moves. On a machine whose outer rotary is the tilt
    // (|A| or |B| = tilt) and whose inner one turns with the azimuth, going from one move to
    // the next either keeps the tilt's sign (outer turns by the tilt change, inner by the
    // azimuth change Δ) or flips it through the pole (outer by the sum of the tilts, inner by
    // 180° − Δ). Near the pole Δ approaches 180°: the flip is the small motion; farther off,
    // keeping is. The rotaries must take the smaller (Euclidean, degrees) of the two at every
    // move, and the LinuxCNC program must keep the ball centre on the chords.
    let mut report = Vec::new();
    for m in five_axis_machines()
        .into_iter()
        .filter(|m| !m.name.starts_with("odd"))
    {
        let inner = m.inner_rotary().unwrap();
        for miss in [0.0f64, 1e-5, 1e-3, 0.05, 0.3, 0.5, 2.0] {
            for azimuth in [0.0f64, 30.0, 135.0, -60.0] {
                let (s, c) = azimuth.to_radians().sin_cos();
                let axes: Vec<Vector3> = (-20..20)
                    .map(|k| {
                        let t = (k as f64 + 0.5).to_radians();
                        let v = Vector3::new(t.sin(), miss.to_radians().sin(), t.cos());
                        Vector3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z).normalize()
                    })
                    .collect();
                let path = sweep(&axes, 3.0, 0.5, 10.0);
                let label = format!("{} miss {miss}° azimuth {azimuth}°", m.name);
                let j = joints_of(&path, &m).unwrap_or_else(|e| panic!("{label}: {e}"));
                let tilt = |v: &Vector3| v.z.clamp(-1.0, 1.0).acos().to_degrees();
                let mut worst_inner: f64 = 0.0;
                for i in 1..axes.len() {
                    let (a, b) = (&axes[i - 1], &axes[i]);
                    let mut daz = (b.y.atan2(b.x) - a.y.atan2(a.x)).to_degrees().abs();
                    if daz > 180.0 {
                        daz = 360.0 - daz;
                    }
                    let keep = (tilt(b) - tilt(a)).hypot(daz);
                    let flip = (tilt(a) + tilt(b)).hypot(180.0 - daz);
                    let step = (j[i].rotary_deg[0] - j[i - 1].rotary_deg[0])
                        .hypot(j[i].rotary_deg[1] - j[i - 1].rotary_deg[1]);
                    assert!(
                        (step - keep.min(flip)).abs() <= 1e-6,
                        "{label} move {i}: rotaries moved {step}°, keeping the tilt's sign \
                         takes {keep}°, flipping it {flip}°"
                    );
                    worst_inner = worst_inner
                        .max((j[i].rotary_deg[inner] - j[i - 1].rotary_deg[inner]).abs());
                }
                let rt = machine::round_trip(
                    &path,
                    &opts(),
                    &job("sweep"),
                    &m,
                    Dialect::LinuxCnc,
                    Units::Mm,
                )
                .unwrap_or_else(|e| panic!("{label}: {e}"));
                assert!(
                    rt.max_position_error_mm <= 1e-3 && rt.max_axis_error_deg <= 0.01,
                    "{label}: {rt:?}"
                );
                if azimuth == 30.0 {
                    report.push(format!(
                        "{label}: inner axis turns at most {worst_inner:.4}° per move, {} blocks inserted",
                        rt.inserted_blocks
                    ));
                }
            }
        }
    }
    for r in report {
        println!("{r}");
    }
}

#[test]
fn a_limit_met_later_decides_the_way_past_the_pole() {
    // The tool axis tilts from 40° on one side of the pole to 40° on the other, missing the
    // pole by 0.001° halfway between two moves. Flipping the tilt's sign there is the smaller
    // step (a free trunnion does it), but on a trunnion that tilts one way only to 30° it
    // would end at a tilt of 40° on the wrong side: the rotaries must keep the tilt's sign and
    // turn C round the pole instead, decided before the limit is met.
    let axes: Vec<Vector3> = (-40..40)
        .map(|k| {
            let t = (k as f64 + 0.5).to_radians();
            Vector3::new(t.sin(), 1e-3f64.to_radians().sin(), t.cos()).normalize()
        })
        .collect();
    let path = sweep(&axes, 3.0, 0.5, 10.0);
    let trunnion = |limits: &str| {
        machine::from_json(&format!(
            r#"{{"format": "tspath-machine", "version": 1, "name": "one-way",
            "rotaries": [
              {{"name": "A", "mount": "table", "axis": [1, 0, 0], "pivot_mm": [0, 0, -80], "limits_deg": {limits}}},
              {{"name": "C", "mount": "table", "axis": [0, 0, 1]}}
            ]}}"#
        ))
        .unwrap()
    };
    let pass = 40; // move index of the first axis past the pole
    let free = joints_of(&path, &trunnion("[-120, 120]")).unwrap();
    assert!(
        free[pass - 1].rotary_deg[0] * free[pass].rotary_deg[0] < 0.0,
        "a free trunnion flips the tilt's sign: {:?} {:?}",
        free[pass - 1],
        free[pass]
    );
    let c_free = (free[pass].rotary_deg[1] - free[pass - 1].rotary_deg[1]).abs();
    assert!(c_free < 1.0, "and turns C a little: {c_free}°");
    for limits in ["[-120, 30]", "[-30, 120]"] {
        let j = joints_of(&path, &trunnion(limits)).unwrap_or_else(|e| panic!("{limits}: {e}"));
        let a: Vec<f64> = j.iter().map(|j| j.rotary_deg[0]).collect();
        let sign = a[1].signum();
        assert!(
            a.iter()
                .skip(1)
                .all(|x| x * sign >= 0.0 && x.abs() <= 40.0 + 1e-9),
            "{limits}: A keeps its sign: {a:?}"
        );
        let steps = rotary_steps(&path, &j);
        let (_, c_pass, _) = steps[pass - 1];
        assert!(
            (c_pass - (180.0 - c_free)).abs() < 1e-6,
            "{limits}: C turns round the pole by the azimuth change, {c_pass}°"
        );
        for (i, (da, _, step)) in steps.iter().enumerate() {
            assert!(
                *da <= step + 1e-9,
                "{limits} move {}: A {da}° > step {step}°",
                i + 1
            );
        }
        // The half turn of the table within one 0.5 mm move stays on the chord in LinuxCNC's
        // joint interpolation.
        let rt = machine::round_trip(
            &path,
            &opts(),
            &job("sweep"),
            &trunnion(limits),
            Dialect::LinuxCnc,
            Units::Mm,
        )
        .unwrap();
        assert!(rt.max_position_error_mm <= 1e-3 && rt.max_axis_error_deg <= 0.01);
        println!(
            "A in {limits} past the pole at 0.001°: A keeps its sign, C turns {c_pass:.3}° at the pass \
             (a free trunnion flips A and turns C {c_free:.3}°); {} blocks inserted",
            rt.inserted_blocks
        );
    }
}

#[test]
fn rotaries_unwind_at_rapids_within_their_travel() {
    // C limited to ±360°: two chains, each turning the tool axis azimuth by 540°.
    let m = machine::from_json(
        r#"{"format": "tspath-machine", "version": 1, "name": "ac-cable-limited",
        "rotaries": [
          {"name": "A", "mount": "table", "axis": [1, 0, 0], "pivot_mm": [0, 0, -80], "limits_deg": [-120, 120]},
          {"name": "C", "mount": "table", "axis": [0, 0, 1], "limits_deg": [-360, 360]}
        ]}"#,
    )
    .unwrap();
    let chain = |from: f64| -> Vec<Vector3> {
        (0..=108)
            .map(|k| axis(30.0, from + 5.0 * k as f64))
            .collect()
    };
    let first = sweep(&chain(0.0), 3.0, 0.2, 10.0);
    let second = sweep(&chain(540.0), 3.0, 0.2, 10.0);
    let mut moves = first.moves.clone();
    moves.extend(second.moves.iter().copied());
    let path = tspath::plan::Toolpath {
        moves,
        ..first.clone()
    };
    let j = joints_of(&path, &m).unwrap();
    let c: Vec<f64> = j.iter().map(|j| j.rotary_deg[1]).collect();
    assert!(
        c.iter().all(|c| (-360.0..=360.0).contains(c)),
        "C stays within its travel"
    );
    let steps = rotary_steps(&path, &j);
    let rapid = first.moves.len(); // index of the second chain's rapid
    for (i, (_, dc, _)) in steps.iter().enumerate() {
        if i + 1 != rapid {
            assert!(
                *dc <= 5.0 + 1e-9,
                "move {}: C jumps {dc}° while cutting",
                i + 1
            );
        }
    }
    let unwind = c[rapid] - c[rapid - 1];
    println!(
        "C over two 540° chains: range [{:.1}, {:.1}]°, unwound by {unwind:.1}° at the rapid between them",
        c.iter().cloned().fold(f64::INFINITY, f64::min),
        c.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
    );
    // Without the rapid there is nowhere to unwind: a clear error naming C and its limits.
    let mut one = path.clone();
    for mv in one.moves.iter_mut().skip(1) {
        if mv.kind == tspath::plan::MoveKind::Rapid || mv.kind == tspath::plan::MoveKind::Retract {
            mv.kind = tspath::plan::MoveKind::Feed;
        }
    }
    let e = joints_of(&one, &m)
        .map(|_| panic!("cannot unwind"))
        .unwrap_or_else(|e| e)
        .to_string();
    assert!(
        e.contains("move ") && e.contains("C = ") && e.contains("[-360, 360]"),
        "{e}"
    );
    println!("one 1080° chain: {e}");
}

#[test]
fn limits_are_respected_or_the_error_says_which_move_and_axis() {
    let name = "dome";
    let planned = sample_plan(name);
    let tilted = along_normals(&planned);
    // Built-in machines: every rotary within its travel on the dome with normal tool axes.
    for m in five_axis_machines()
        .into_iter()
        .filter(|m| !m.name.starts_with("odd"))
    {
        let j = joints_of(&tilted, &m).unwrap();
        for (i, r) in m.rotaries.iter().enumerate() {
            if let Some((lo, hi)) = r.limits_deg {
                let (a, b) = j
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), j| {
                        (a.min(j.rotary_deg[i]), b.max(j.rotary_deg[i]))
                    });
                assert!(a >= lo && b <= hi);
                println!(
                    "{} on {name} along normals: {} in [{a:.3}, {b:.3}]° within [{lo}, {hi}]°",
                    m.name, r.name
                );
            }
        }
    }
    let with = |limits: &str, linear: &str| {
        machine::from_json(&format!(
            r#"{{"format": "tspath-machine", "version": 1, "name": "limited",
            "rotaries": [
              {{"name": "A", "mount": "table", "axis": [1, 0, 0], "pivot_mm": [0, 0, -80], "limits_deg": {limits}}},
              {{"name": "C", "mount": "table", "axis": [0, 0, 1]}}
            ], "linear_limits_mm": {linear}}}"#
        ))
        .unwrap()
    };
    // The dome's normals tilt up to 60°: A within ±30° cannot reach them.
    let e = joints_of(&tilted, &with("[-30, 30]", "null"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("move ") && e.contains("A = ") && e.contains("[-30, 30]"),
        "{e}"
    );
    println!("A in [-30, 30]: {e}");
    // A one-sided trunnion follows the dome on its negative branch: the zig-zag passes the pole
    // at 0.3°, and C turns round instead of A changing sign.
    let one_sided = with("[-120, 30]", "null");
    let j = joints_of(&tilted, &one_sided).unwrap();
    let a_max = j
        .iter()
        .map(|j| j.rotary_deg[0])
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(a_max <= 30.0);
    println!("A in [-120, 30] on {name} along normals: A at most {a_max:.3}°");
    // Straight through the pole, continuity wants A to change sign; a trunnion that only tilts
    // one way would need a 180° C swing while cutting: a clear error.
    let through: Vec<Vector3> = (-20..=20).map(|t| axis(t as f64, 0.0)).collect();
    let e = joints_of(&sweep(&through, 3.0, 0.5, 10.0), &with("[0, 120]", "null"))
        .map(|_| panic!("a forced swing is an error"))
        .unwrap_or_else(|e| e)
        .to_string();
    assert!(
        e.contains("move 21") && e.contains("swing") && e.contains("A = "),
        "{e}"
    );
    println!("A in [0, 120] through the pole: {e}");
    // Linear travel.
    let e = joints_of(&tilted, &with("[-120, 120]", r#"{"z": [-50, 10]}"#))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("move ") && e.contains("Z would be") && e.contains("[-50, 10]"),
        "{e}"
    );
    println!("Z in [-50, 10]: {e}");
    // A 3-axis machine refuses a tilted axis, naming the move.
    let e = post(
        &tilted,
        &opts(),
        &job(name),
        &machine::builtin("3-axis").unwrap(),
        Dialect::Fanuc,
        Units::Mm,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("move ") && e.contains("not +Z"), "{e}");
    let e = post(
        &tilted,
        &opts(),
        &job(name),
        &machine::builtin("table-table-ac").unwrap(),
        Dialect::Plain,
        Units::Mm,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("plain dialect"), "{e}");
}

#[test]
fn machine_files_round_trip_and_errors_name_the_field() {
    for m in machine::MACHINES {
        let a = machine::builtin(m.name).unwrap();
        let text = machine::to_json(&a);
        assert_eq!(machine::from_json(&text).unwrap(), a);
        assert_eq!(machine::to_json(&machine::from_json(&text).unwrap()), text);
    }
    let base = machine::to_json(&machine::builtin("table-table-bc").unwrap());
    let cases = [
        (
            base.replace("\"pivot_mm\"", "\"pivot\""),
            "unknown field `pivot`",
        ),
        (
            base.replacen("\"direction\": 1.0", "\"direction\": 2.0", 1),
            "rotaries[0].direction",
        ),
        (base.replace("tspath-machine", "something"), "format"),
        (
            base.replacen("\"name\": \"B\"", "\"name\": \"Q\"", 1),
            "rotaries[0].name",
        ),
        (
            base.replacen("-110.0", "200.0", 1),
            "rotaries[0].limits_deg",
        ),
        (
            base.replacen(
                "\"axis\": [\n        0.0,\n        1.0,\n        0.0\n      ]",
                "\"axis\": [0.0, 0.0, 1.0]",
                1,
            ),
            "parallel",
        ),
    ];
    for (text, want) in cases {
        assert_ne!(text, base, "the case `{want}` edits the file");
        let e = machine::from_json(&text).unwrap_err().to_string();
        assert!(e.contains(want), "expected `{want}` in: {e}");
    }
}
