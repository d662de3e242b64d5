//! Round trip of every dialect: plan → program → reader → forward kinematics → compare with
//! the planned ball centres and tool axes; inch and mm programs describe the same motion;
//! the same input gives the same bytes.

// Index loops over X Y Z A B C read like the axes they compare.
#![allow(clippy::needless_range_loop)]

use crate::machine_support;

use machine_support::*;
use tspath::machine::{self, post, reader, Dialect, Units, DIALECTS, MACHINES};

/// Done-when limits of the round trip.
const MAX_POSITION_ERROR_MM: f64 = 1e-3;
const MAX_AXIS_ERROR_DEG: f64 = 0.01;

/// Rotary words are written with 4 decimals: an inserted block and the two planned moves
/// around it are each off by at most half the last digit per word (two words), so its
/// rotaries are this close to the segment between theirs when inserting adds no rotary motion.
const INSERTED_ROTARY_ROUNDING_DEG: f64 = 2.0 * std::f64::consts::SQRT_2 * 0.5e-4;

/// Round trip of every sample, machine and dialect in `units`; prints the worst cases.
fn round_trips(units: Units) {
    let mut worst_pos = (0.0, String::new());
    let mut worst_ax = (0.0, String::new());
    let mut worst_feed = (0.0, String::new());
    let mut worst_off_segment: f64 = 0.0;
    let mut worst_off_arc = (0.0, String::new());
    let mut inserted = 0;
    let mut inverse_time_checked = 0;
    let mut programs = 0;
    // Worst position (mm) and axis (degrees) error of each dialect.
    let mut by_dialect = vec![(0.0f64, 0.0f64); DIALECTS.len()];
    for (name, planned) in sample_plans() {
        let tilted = along_normals(&planned);
        let o = opts_for(&name);
        for m in MACHINES {
            let mach = machine::builtin(m.name).unwrap();
            let five = !mach.rotaries.is_empty();
            for (d, &(dialect, dname, _)) in DIALECTS.iter().enumerate() {
                let mut paths = vec![("axis +Z", &planned)];
                if five && dialect != Dialect::Plain {
                    paths.push(("axis along normals", &tilted));
                }
                for (what, path) in paths {
                    let label =
                        format!("{name} / {what} / {} / {dname} / {}", m.name, units.name());
                    let rt = machine::round_trip(path, &o, &job(&name), &mach, dialect, units)
                        .unwrap_or_else(|e| panic!("{label}: {e}"));
                    assert_eq!(rt.moves_compared, path.moves.len(), "{label}");
                    assert!(
                        rt.max_position_error_mm <= MAX_POSITION_ERROR_MM,
                        "{label}: position error {} mm at move {}",
                        rt.max_position_error_mm,
                        rt.worst_position_move
                    );
                    assert!(
                        rt.max_axis_error_deg <= MAX_AXIS_ERROR_DEG,
                        "{label}: axis error {}° at move {}",
                        rt.max_axis_error_deg,
                        rt.worst_axis_move
                    );
                    assert!(
                        rt.max_feed_error_rel <= 1e-3,
                        "{label}: feed error {}",
                        rt.max_feed_error_rel
                    );
                    assert!(
                        rt.max_inserted_rotary_off_segment_deg <= INSERTED_ROTARY_ROUNDING_DEG,
                        "{label}: an inserted block's rotaries are {}° off the joint-space segment",
                        rt.max_inserted_rotary_off_segment_deg
                    );
                    let keep = |w: &mut (f64, String), v: f64, at: String| {
                        if v > w.0 {
                            *w = (v, at);
                        }
                    };
                    keep(
                        &mut worst_pos,
                        rt.max_position_error_mm,
                        format!("{label}, move {}", rt.worst_position_move),
                    );
                    keep(
                        &mut worst_ax,
                        rt.max_axis_error_deg,
                        format!("{label}, move {}", rt.worst_axis_move),
                    );
                    keep(&mut worst_feed, rt.max_feed_error_rel, label.clone());
                    keep(&mut worst_off_arc, rt.max_inserted_axis_off_arc_deg, label);
                    worst_off_segment =
                        worst_off_segment.max(rt.max_inserted_rotary_off_segment_deg);
                    by_dialect[d].0 = by_dialect[d].0.max(rt.max_position_error_mm);
                    by_dialect[d].1 = by_dialect[d].1.max(rt.max_axis_error_deg);
                    inserted += rt.inserted_blocks;
                    inverse_time_checked += rt.inverse_time_blocks_checked;
                    programs += 1;
                }
            }
        }
    }
    println!("round trip over {programs} {} programs:", units.name());
    println!(
        "  worst position error {:.3e} mm ({})",
        worst_pos.0, worst_pos.1
    );
    println!(
        "  worst tool-axis error {:.3e} deg ({})",
        worst_ax.0, worst_ax.1
    );
    for (&(_, dname, _), (pos, ax)) in DIALECTS.iter().zip(&by_dialect) {
        println!("    {dname:<13} position {pos:.3e} mm, tool axis {ax:.3e} deg");
    }
    assert!(inverse_time_checked > 0, "some G93 feeds are checked");
    println!(
        "  worst relative feed error {:.3e} ({}; {inverse_time_checked} G93 blocks checked)",
        worst_feed.0, worst_feed.1
    );
    println!(
        "  {inserted} inserted blocks: rotaries at most {worst_off_segment:.1e}° off the joint-space \
         segment; tool axis at most {:.3e}° off the planned arc ({})",
        worst_off_arc.0, worst_off_arc.1
    );
}

#[test]
fn every_dialect_round_trips_within_a_micron_and_a_hundredth_of_a_degree_in_mm() {
    round_trips(Units::Mm);
}

#[test]
fn every_dialect_round_trips_within_a_micron_and_a_hundredth_of_a_degree_in_inch() {
    round_trips(Units::Inch);
}

/// Largest rounding of one written length: half the last decimal (mm programs 1e-4 mm,
/// inch programs 1e-5 inch).
const MM_ROUNDING_MM: f64 = 0.5e-4;
const INCH_ROUNDING_MM: f64 = 0.5e-5 * 25.4;

#[test]
fn inch_program_describes_the_same_motion_as_the_mm_program() {
    let mut worst_len: f64 = 0.0;
    let mut worst_deg: f64 = 0.0;
    let mut worst_feed: f64 = 0.0;
    let mut pairs = 0;
    for (name, planned) in sample_plans() {
        let tilted = along_normals(&planned);
        for m in MACHINES {
            let mach = machine::builtin(m.name).unwrap();
            for &(dialect, dname, _) in DIALECTS {
                let five = !mach.rotaries.is_empty() && dialect != Dialect::Plain;
                let path = if five { &tilted } else { &planned };
                let text =
                    |u| post(path, &opts_for(&name), &job(&name), &mach, dialect, u).unwrap();
                let (mm_text, inch_text) = (text(Units::Mm), text(Units::Inch));
                assert_ne!(mm_text, inch_text);
                let mm = reader::read(&mm_text).unwrap();
                let inch = reader::read(&inch_text).unwrap();
                assert_eq!(mm.units, Units::Mm);
                assert_eq!(inch.units, Units::Inch, "{dname}: the inch program says so");
                assert_eq!(mm.moves.len(), inch.moves.len(), "{} / {dname}", m.name);
                for (a, b) in mm.moves.iter().zip(&inch.moves) {
                    assert_eq!(a.feed_mode, b.feed_mode, "line {}", a.line);
                    assert_eq!(a.machine_frame, b.machine_frame);
                    assert_eq!(a.tcp, b.tcp);
                    for k in 0..3 {
                        if a.xyz_mm[k].is_nan() {
                            assert!(b.xyz_mm[k].is_nan());
                            continue;
                        }
                        let d = (a.xyz_mm[k] - b.xyz_mm[k]).abs();
                        assert!(
                            d <= MM_ROUNDING_MM + INCH_ROUNDING_MM + 1e-12,
                            "{} / {dname} line {}: {} mm vs {} mm",
                            m.name,
                            a.line,
                            a.xyz_mm[k],
                            b.xyz_mm[k]
                        );
                        worst_len = worst_len.max(d);
                        let e = (a.abc_deg[k] - b.abc_deg[k]).abs();
                        if e.is_finite() {
                            worst_deg = worst_deg.max(e);
                        }
                    }
                    if a.feed.is_finite() {
                        let e = (a.feed - b.feed).abs() / a.feed;
                        assert!(e <= 1e-4, "line {}: feed {} vs {}", a.line, a.feed, b.feed);
                        worst_feed = worst_feed.max(e);
                    }
                }
                pairs += 1;
            }
        }
    }
    assert_eq!(worst_deg, 0.0, "rotary angles are written the same in both");
    println!(
        "inch vs mm over {pairs} program pairs: largest coordinate difference {worst_len:.3e} mm \
         (bound {:.3e} mm from rounding), rotaries identical, largest feed difference {worst_feed:.3e} (relative)",
        MM_ROUNDING_MM + INCH_ROUNDING_MM
    );
}

#[test]
fn same_input_same_bytes_in_every_dialect() {
    // Two independent plans of a sample with no pole on it and of one whose tool axes pass
    // the pole over and over (the branch choice there must be deterministic too).
    for name in ["dome", "bumps"] {
        let (a, b) = (sample_plan(name), sample_plan(name));
        let (ta, tb) = (along_normals(&a), along_normals(&b));
        let o = opts_for(name);
        for m in MACHINES {
            let mach = machine::builtin(m.name).unwrap();
            let json_again = machine::from_json(&machine::to_json(&mach)).unwrap();
            for &(dialect, dname, _) in DIALECTS {
                let five = !mach.rotaries.is_empty() && dialect != Dialect::Plain;
                let (pa, pb) = if five { (&ta, &tb) } else { (&a, &b) };
                for units in [Units::Mm, Units::Inch] {
                    let x = post(pa, &o, &job(name), &mach, dialect, units).unwrap();
                    let y = post(pb, &o, &job(name), &json_again, dialect, units).unwrap();
                    assert!(x == y, "{name} / {} / {dname}: two runs differ", m.name);
                }
            }
        }
    }
}

/// Samples of each move where the machine's joint interpolation is checked.
const INTERPOLATION_SAMPLES: usize = 16;

#[test]
fn joint_space_moves_stay_within_the_chordal_tolerance_of_the_planned_chords() {
    // A controller interpolating joint values linearly moves the ball centre off the straight
    // chord where the rotaries turn fast (near the singular pose). Read every joint-value
    // program back, interpolate its joints as LinuxCNC would, and measure that deviation.
    for (name, planned) in sample_plans() {
        let path = along_normals(&planned);
        let o = opts_for(&name);
        for m in MACHINES {
            let mach = machine::builtin(m.name).unwrap();
            if mach.rotaries.is_empty() {
                continue;
            }
            let posted = machine::post::post_program(
                &path,
                &o,
                &job(&name),
                &mach,
                Dialect::LinuxCnc,
                Units::Mm,
            )
            .unwrap();
            let prog = reader::read(&posted.text).unwrap();
            let mut worst: f64 = 0.0;
            for w in prog.moves.windows(2) {
                let (a, b) = (&w[0], &w[1]);
                if b.feed_mode == reader::FeedMode::Rapid || a.machine_frame || a.xyz_mm[0].is_nan()
                {
                    continue;
                }
                let joints = |t: f64| {
                    let mut rot = [0.0; 2];
                    for (i, r) in mach.rotaries.iter().enumerate() {
                        let k = (r.name as u8 - b'A') as usize;
                        rot[i] = a.abc_deg[k] + (b.abc_deg[k] - a.abc_deg[k]) * t;
                    }
                    machine::Joints {
                        xyz_mm: [0, 1, 2].map(|k| a.xyz_mm[k] + (b.xyz_mm[k] - a.xyz_mm[k]) * t),
                        rotary_deg: rot,
                    }
                };
                let centre = |t: f64| {
                    let p = mach.forward(&joints(t));
                    p.tip + p.axis * path.tool_radius_mm
                };
                let (c0, c1) = (centre(0.0), centre(1.0));
                for s in 1..INTERPOLATION_SAMPLES {
                    let t = s as f64 / INTERPOLATION_SAMPLES as f64;
                    let d = (centre(t) - (c0 + (c1 - c0) * t)).norm();
                    worst = worst.max(d);
                }
            }
            assert!(
                worst <= o.chordal_mm + 1e-3,
                "{}: joint interpolation leaves the chord by {worst} mm",
                m.name
            );
            println!(
                "{} on {name} along normals: {} blocks inserted; joint interpolation stays within {worst:.4} mm of the chords (chordal tolerance {} mm)",
                m.name, posted.inserted, o.chordal_mm
            );
        }
    }
}

/// Every dialect writes the chosen work offset before the first move (issue 18: programs
/// carried none), in its own words, and still reads back; a bad offset is refused.
#[test]
fn every_dialect_writes_the_work_offset() {
    let planned = sample_plan("dome");
    let tilted = along_normals(&planned);
    for offset in [54u8, 55, 58, 59] {
        let mut o = opts_for("dome");
        o.work_offset = offset;
        for m in ["3-axis", "table-table-ac"] {
            let mach = machine::builtin(m).unwrap();
            for &(dialect, dname, _) in DIALECTS {
                let five = !mach.rotaries.is_empty() && dialect != Dialect::Plain;
                let path = if five { &tilted } else { &planned };
                let text = post(path, &o, &job("dome"), &mach, dialect, Units::Mm).unwrap();
                let want = match (dialect, offset) {
                    (Dialect::Heidenhain, g) => format!("PRESET SELECT #{}", g - 53),
                    (Dialect::Siemens, 58) => "G505".to_string(),
                    (Dialect::Siemens, 59) => "G506".to_string(),
                    (_, g) => format!("G{g}"),
                };
                // The offset's block comes before the first block that moves.
                let at = text
                    .lines()
                    .position(|l| {
                        l.split_whitespace().any(|w| w == want.as_str()) || l.ends_with(&want)
                    })
                    .unwrap_or_else(|| panic!("{m} {dname} G{offset}: no `{want}` in\n{text}"));
                let first_move = text
                    .lines()
                    .position(|l| {
                        l.split_whitespace()
                            .any(|w| w == "G0" || w == "G1" || w.starts_with("L"))
                    })
                    .unwrap();
                assert!(
                    at < first_move,
                    "{m} {dname}: `{want}` at line {at}, first move {first_move}"
                );
                let back = reader::read(&text).unwrap();
                assert!(!back.moves.is_empty());
            }
        }
    }
    let mut o = opts_for("dome");
    o.work_offset = 60;
    let e = post(
        &planned,
        &o,
        &job("dome"),
        &machine::builtin("3-axis").unwrap(),
        Dialect::LinuxCnc,
        Units::Mm,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("work_offset") && e.contains("G54"), "{e}");
}
