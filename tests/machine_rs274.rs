//! LinuxCNC's stand-alone interpreter `rs274` (Debian package linuxcnc-uspace, installed by
//! scripts/setup) must accept every LinuxCNC-dialect program the project writes for the
//! sample models — 3-axis and 5-axis, mm and inch, G94 and G93 — and its canonical moves must
//! be the ones the project's own reader sees. A broken program must be rejected.
//!
//! rs274 facts found by experiment (LinuxCNC 2.9): `rs274 -g -t TOOLTABLE FILE` runs in batch
//! mode and prints canonical commands (`STRAIGHT_FEED(x, y, z, a, b, c)` in program units and
//! degrees, 4 decimals) on stdout; on an error it exits with status 1 and prints the message
//! and the offending line on stderr. The stand-alone build always has axes X Y Z A B C
//! (an .ini cannot change that; U V W are rejected), rotary words are plain degrees, and
//! tool-table lengths are read in inches. These tests need no .ini. It keeps its tool table in
//! `$HOME/.tool.mmap`: concurrent runs need separate HOMEs (see `machine_support::rs274`).

// Index loops over X Y Z A B C read like the axes they compare.
#![allow(clippy::needless_range_loop)]

use crate::machine_support;

use machine_support::*;
use tspath::machine::{self, post, reader, Dialect, Units, MACHINES};

/// rs274 prints 4 decimals.
const PRINT_ROUNDING: f64 = 0.5e-4;

/// Runs rs274 on every LinuxCNC program (both LinuxCNC dialects, mm and inch) of the sample
/// plans and a sweep through and past the singular pose on the built-in machines `machines`,
/// and compares its canonical moves with the reader's.
fn accepts_every_program_on(machines: &[&str], tag: &str) {
    let dir = scratch(&format!("rs274-accept-{tag}"));
    let mut files = 0;
    let mut blocks = 0;
    let mut inverse_time_blocks = 0;
    let mut worst: f64 = 0.0;
    // The sample plans (tool axis +Z, and along the surface normals), and a sweep of the tool
    // axis straight through the singular pose and past it at 0.5° and at 0.001° (where the
    // rotaries flip the tilt's sign through the pole).
    let past = |miss_deg: f64, offset: f64| {
        (-20..=20).map(move |t| {
            tspath::geom::Vector3::new(
                (t as f64 + offset).to_radians().sin(),
                miss_deg.to_radians().sin(),
                1.0,
            )
            .normalize()
        })
    };
    let crossing: Vec<tspath::geom::Vector3> = (-20..=20)
        .map(|t| axis(t as f64, 30.0))
        .chain(past(0.5, 0.0))
        .chain(past(1e-3, 0.5))
        .collect();
    let sweep_path = sweep(&crossing, 3.0, 0.5, 10.0);
    let mut cases = sample_plans();
    cases.push(("singular-sweep".into(), sweep_path));
    for (name, planned) in cases {
        let tilted = along_normals(&planned);
        for m in MACHINES.iter().filter(|m| machines.contains(&m.name)) {
            let mach = machine::builtin(m.name).unwrap();
            let five = !mach.rotaries.is_empty();
            for dialect in [Dialect::LinuxCnc, Dialect::LinuxCncTcp] {
                for units in [Units::Mm, Units::Inch] {
                    let sweeping = name == "singular-sweep";
                    let mut paths = if sweeping {
                        vec![]
                    } else {
                        vec![("z", &planned)]
                    };
                    if five {
                        paths.push(("normals", if sweeping { &planned } else { &tilted }));
                    }
                    for (what, path) in paths {
                        let o = if sweeping { opts() } else { opts_for(&name) };
                        let text = post(path, &o, &job(&name), &mach, dialect, units).unwrap();
                        let file = dir.join(format!(
                            "{name}-{what}-{}-{}-{}.ngc",
                            m.name,
                            dialect.name(),
                            units.name()
                        ));
                        std::fs::write(&file, &text).unwrap();
                        let run = rs274(&file, path.tool_radius_mm);
                        assert!(
                            run.accepted,
                            "rs274 rejected {}: {} (exit {:?}; stdout ends {:?})",
                            file.display(),
                            run.message,
                            run.status,
                            &run.stdout[run.stdout.len().saturating_sub(300)..]
                        );
                        let canon = canonical_moves(&run.stdout);
                        let ours = reader::read(&text).unwrap();
                        assert_eq!(canon.len(), ours.moves.len(), "{}", file.display());
                        for ((feed, c), o) in canon.iter().zip(&ours.moves) {
                            assert_eq!(
                                *feed,
                                o.feed_mode != reader::FeedMode::Rapid,
                                "{} line {}",
                                file.display(),
                                o.line
                            );
                            if o.feed_mode == reader::FeedMode::InverseTime {
                                inverse_time_blocks += 1;
                            }
                            for k in 0..6 {
                                let v = if k < 3 {
                                    o.xyz_mm[k] / units.mm()
                                } else {
                                    o.abc_deg[k - 3]
                                };
                                if v.is_nan() || (o.machine_frame && k < 2) {
                                    continue; // never programmed, or machine X/Y unknown
                                }
                                let d = (c[k] - v).abs();
                                assert!(
                                    d <= PRINT_ROUNDING + 1e-9,
                                    "{} line {}: rs274 has {} for {}, the reader {v}",
                                    file.display(),
                                    o.line,
                                    c[k],
                                    "XYZABC".as_bytes()[k] as char
                                );
                                worst = worst.max(d);
                            }
                        }
                        assert_eq!(
                            text.lines().any(|l| l.starts_with("G93 ")),
                            run.stdout.contains("feed mode set to inverse time"),
                            "rs274 switches to inverse time exactly when the program does"
                        );
                        files += 1;
                        blocks += canon.len();
                    }
                }
            }
        }
    }
    assert!(inverse_time_blocks > 0, "some programs use G93");
    println!(
        "rs274 accepted {files} LinuxCNC programs for {} ({blocks} motion blocks, \
         {inverse_time_blocks} in G93 inverse time); largest difference between its canonical \
         moves and the reader's: {worst:.1e} (program units or degrees; it prints 4 decimals)",
        machines.join(", ")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

// Split by machine so that the test harness runs them side by side.

#[test]
fn rs274_accepts_every_linuxcnc_program_and_sees_the_same_moves_3_axis_and_ac() {
    accepts_every_program_on(&["3-axis", "table-table-ac"], "ac");
}

#[test]
fn rs274_accepts_every_linuxcnc_program_and_sees_the_same_moves_bc() {
    accepts_every_program_on(&["table-table-bc", "head-table-bc"], "bc");
}

#[test]
fn every_built_in_machine_is_run_through_rs274() {
    let tested = [
        "3-axis",
        "table-table-ac",
        "table-table-bc",
        "head-table-bc",
    ];
    for m in MACHINES {
        assert!(tested.contains(&m.name), "add {} to an rs274 test", m.name);
    }
}

/// A five-axis LinuxCNC program of the dome with the tool along the normals.
fn five_axis_program() -> (String, f64) {
    let name = "dome";
    let path = along_normals(&sample_plan(name));
    let mach = machine::builtin("table-table-ac").unwrap();
    let text = post(
        &path,
        &opts_for(name),
        &job(name),
        &mach,
        Dialect::LinuxCnc,
        Units::Mm,
    )
    .unwrap();
    (text, path.tool_radius_mm)
}

#[test]
fn rs274_rejects_broken_programs() {
    let dir = scratch("rs274-reject");
    let (good, r) = five_axis_program();
    let file = dir.join("good.ngc");
    std::fs::write(&file, &good).unwrap();
    assert!(rs274(&file, r).accepted, "the unbroken program runs");

    // 1. An inverse-time move without its F word.
    let lines: Vec<&str> = good.lines().collect();
    let g93 = lines
        .iter()
        .position(|l| l.starts_with("G93 "))
        .expect("a G93 block");
    let next = g93
        + 1
        + lines[g93 + 1..]
            .iter()
            .position(|l| l.starts_with("G1 ") && l.contains(" F"))
            .expect("a second inverse-time block");
    let broken_line = lines[next].split(" F").next().unwrap().to_string();
    let mut broken: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    broken[next] = broken_line.clone();
    let text = broken.join("\n") + "\n";
    let file = dir.join("no-inverse-time-feed.ngc");
    std::fs::write(&file, &text).unwrap();
    let run = rs274(&file, r);
    assert!(!run.accepted, "rs274 must reject a G93 move without F");
    assert!(
        run.message.contains("F word missing") && run.message.contains(&broken_line),
        "rs274 says: {}",
        run.message
    );
    let ours = reader::read(&text).unwrap_err().to_string();
    assert!(
        ours.contains(&format!("line {}", next + 1)) && ours.contains("G93"),
        "{ours}"
    );
    println!(
        "rs274 on a G93 move without F: {}",
        run.message.replace('\n', " | ")
    );

    // 2. A word LinuxCNC does not have on this machine (a U axis).
    let mut broken: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    broken[next] = format!("{} U1.0", lines[next]);
    let file = dir.join("bad-word.ngc");
    std::fs::write(&file, broken.join("\n") + "\n").unwrap();
    let run = rs274(&file, r);
    assert!(!run.accepted, "rs274 must reject a U word");
    assert!(run.message.to_lowercase().contains("u"), "{}", run.message);
    println!("rs274 on a U word: {}", run.message.replace('\n', " | "));

    // 3. A feed move before any feed rate (first F removed from a 3-axis program).
    let planned = sample_plan("dome");
    let three = post(
        &planned,
        &opts_for("dome"),
        &job("dome"),
        &machine::builtin("3-axis").unwrap(),
        Dialect::LinuxCnc,
        Units::Inch,
    )
    .unwrap();
    let first_f = three
        .lines()
        .position(|l| l.starts_with("G1 ") && l.contains(" F"))
        .unwrap();
    let text: String = three
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == first_f {
                l.split(" F").next().unwrap().to_string() + "\n"
            } else {
                l.to_string() + "\n"
            }
        })
        .collect();
    let file = dir.join("no-feed.ngc");
    std::fs::write(&file, &text).unwrap();
    let run = rs274(&file, r);
    assert!(!run.accepted, "rs274 must reject G1 without a feed rate");
    assert!(run.message.contains("zero feed rate"), "{}", run.message);
    assert!(reader::read(&text).is_err());
    println!(
        "rs274 on G1 before any F: {}",
        run.message.replace('\n', " | ")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 18: the plunge comes down fast to a feed height, then at the plunge feed. Read by
/// LinuxCNC's interpreter: after every run of rapids, the moves at the plunge feed cover
/// exactly the feed height (along the way down), as many as the path's approach and plunge
/// moves, and the cut after them runs at the cutting feed.
#[test]
fn rs274_sees_every_approach_slow_down_at_the_feed_height() {
    let dir = scratch("rs274-feed-height");
    let mach = machine::builtin("3-axis").unwrap();
    let mut approaches = 0;
    let isoplanar = tspath::plan::Strategy::Isoplanar;
    let isoparametric = tspath::plan::Strategy::Isoparametric;
    for (name, strategy, feed_height) in [
        ("keycap-convex", isoparametric, 2.0),
        ("dome", isoparametric, 3.5),
        ("bumps-hole", isoplanar, 0.7),
    ] {
        let m = tspath::model::samples::load_sample(name).unwrap();
        let o = opts_for(name)
            .with_feed_height(feed_height)
            .with_strategy(strategy);
        let path = tspath::plan::plan(&m, &o, &mut |_| true).unwrap().toolpath;
        // Moves at the plunge feed per approach, in the planned path.
        let mut planned: Vec<usize> = Vec::new();
        for (i, mv) in path.moves.iter().enumerate() {
            if mv.kind.at_plunge_feed() && (i == 0 || !path.moves[i - 1].kind.at_plunge_feed()) {
                planned.push(0);
            }
            if mv.kind.at_plunge_feed() {
                *planned.last_mut().unwrap() += 1;
            }
        }
        let text = post(&path, &o, &job(name), &mach, Dialect::LinuxCnc, Units::Mm).unwrap();
        let file = dir.join(format!("{name}.ngc"));
        std::fs::write(&file, &text).unwrap();
        let run = rs274(&file, path.tool_radius_mm);
        assert!(run.accepted, "{name}: {}", run.message);
        // Walk the canonical commands: feed rate, rapids, feeds.
        let mut rate = 0.0;
        let mut at = [0.0; 3];
        let mut seen: Vec<(usize, f64)> = Vec::new(); // (moves, length) at the plunge feed
        let mut after_rapid = false;
        for l in run.stdout.lines() {
            if let Some(i) = l.find("SET_FEED_RATE(") {
                let v = &l[i + "SET_FEED_RATE(".len()..];
                rate = v.trim_end().trim_end_matches(')').parse().unwrap();
                continue;
            }
            let Some((feed, xyz)) = canonical_moves(l)
                .first()
                .map(|(f, v)| (*f, [v[0], v[1], v[2]]))
            else {
                continue;
            };
            let len = (0..3).map(|k| (xyz[k] - at[k]).powi(2)).sum::<f64>().sqrt();
            at = xyz;
            if !feed {
                after_rapid = true;
                continue;
            }
            if after_rapid {
                assert_eq!(
                    rate, o.plunge_feed_mm_min,
                    "{name}: the first feed after rapids"
                );
                seen.push((0, 0.0));
                after_rapid = false;
            }
            if rate == o.plunge_feed_mm_min {
                let s = seen.last_mut().expect("a plunge-feed move after rapids");
                s.0 += 1;
                s.1 += len;
            } else {
                assert_eq!(rate, o.feed_mm_min, "{name}");
            }
        }
        assert_eq!(seen.len(), planned.len(), "{name}: approaches");
        for (k, ((moves, len), want)) in seen.iter().zip(&planned).enumerate() {
            assert_eq!(moves, want, "{name} approach {k}: moves at the plunge feed");
            // rs274 prints 4 decimals: each of the few moves may be off by √3·0.5e-4.
            assert!(
                (len - feed_height).abs() < 1e-3,
                "{name} approach {k}: {len} mm at the plunge feed, feed height {feed_height} mm"
            );
        }
        approaches += seen.len();
    }
    println!("rs274: {approaches} approaches, each fed over exactly its feed height");
    std::fs::remove_dir_all(&dir).unwrap();
}
