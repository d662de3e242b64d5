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

mod machine_support;

use machine_support::*;
use tspath::machine::{self, post, reader, Dialect, Units, MACHINES};

/// rs274 prints 4 decimals.
const PRINT_ROUNDING: f64 = 0.5e-4;

#[test]
fn rs274_accepts_every_linuxcnc_program_and_sees_the_same_moves() {
    let dir = scratch("rs274-accept");
    let mut files = 0;
    let mut blocks = 0;
    let mut inverse_time_blocks = 0;
    let mut worst: f64 = 0.0;
    // The sample plans (tool axis +Z, and along the surface normals), and a sweep of the tool
    // axis straight through the singular pose and past it at 0.5°.
    let crossing: Vec<tspath::geom::Vector3> = (-20..=20)
        .map(|t| axis(t as f64, 30.0))
        .chain((-20..=20).map(|t| {
            tspath::geom::Vector3::new(
                (t as f64).to_radians().sin(),
                0.5f64.to_radians().sin(),
                1.0,
            )
            .normalize()
        }))
        .collect();
    let sweep_path = sweep(&crossing, 3.0, 0.5, 10.0);
    let mut cases = sample_plans();
    cases.push(("singular-sweep".into(), sweep_path));
    for (name, planned) in cases {
        let tilted = along_normals(&planned);
        for m in MACHINES {
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
                        let text = post(path, &opts(), &job(&name), &mach, dialect, units).unwrap();
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
        "rs274 accepted {files} LinuxCNC programs ({blocks} motion blocks, {inverse_time_blocks} in \
         G93 inverse time); largest difference between its canonical moves and the reader's: \
         {worst:.1e} (program units or degrees; it prints 4 decimals)"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A five-axis LinuxCNC program of the dome with the tool along the normals.
fn five_axis_program() -> (String, f64) {
    let (name, planned) = sample_plans().remove(0);
    let path = along_normals(&planned);
    let mach = machine::builtin("table-table-ac").unwrap();
    let text = post(
        &path,
        &opts(),
        &job(&name),
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
    let (_, planned) = sample_plans().remove(0);
    let three = post(
        &planned,
        &opts(),
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
