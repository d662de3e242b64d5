//! Round trip of every dialect: plan → program → reader → forward kinematics → compare with
//! the planned ball centres and tool axes; inch and mm programs describe the same motion;
//! the same input gives the same bytes.

// Index loops over X Y Z A B C read like the axes they compare.
#![allow(clippy::needless_range_loop)]

mod machine_support;

use machine_support::*;
use tspath::machine::{self, post, reader, Dialect, Units, DIALECTS, MACHINES};

/// Done-when limits of the round trip.
const MAX_POSITION_ERROR_MM: f64 = 1e-3;
const MAX_AXIS_ERROR_DEG: f64 = 0.01;

#[test]
fn every_dialect_round_trips_within_a_micron_and_a_hundredth_of_a_degree() {
    let mut worst_pos = (0.0, String::new());
    let mut worst_ax = (0.0, String::new());
    let mut worst_feed: f64 = 0.0;
    let mut programs = 0;
    for (name, planned) in sample_plans() {
        let tilted = along_normals(&planned);
        for m in MACHINES {
            let mach = machine::builtin(m.name).unwrap();
            let five = !mach.rotaries.is_empty();
            for &(dialect, dname, _) in DIALECTS {
                for units in [Units::Mm, Units::Inch] {
                    let mut paths = vec![("axis +Z", &planned)];
                    if five && dialect != Dialect::Plain {
                        paths.push(("axis along normals", &tilted));
                    }
                    for (what, path) in paths {
                        let label =
                            format!("{name} / {what} / {} / {dname} / {}", m.name, units.name());
                        let rt =
                            machine::round_trip(path, &opts(), &job(&name), &mach, dialect, units)
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
                        if rt.max_position_error_mm > worst_pos.0 {
                            worst_pos = (
                                rt.max_position_error_mm,
                                format!("{label}, move {}", rt.worst_position_move),
                            );
                        }
                        if rt.max_axis_error_deg > worst_ax.0 {
                            worst_ax = (
                                rt.max_axis_error_deg,
                                format!("{label}, move {}", rt.worst_axis_move),
                            );
                        }
                        worst_feed = worst_feed.max(rt.max_feed_error_rel);
                        programs += 1;
                    }
                }
            }
        }
    }
    println!("round trip over {programs} programs:");
    println!(
        "  worst position error {:.3e} mm ({})",
        worst_pos.0, worst_pos.1
    );
    println!(
        "  worst tool-axis error {:.3e} deg ({})",
        worst_ax.0, worst_ax.1
    );
    println!("  worst relative feed error {worst_feed:.3e}");
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
                let text = |u| post(path, &opts(), &job(&name), &mach, dialect, u).unwrap();
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
    let (name, a) = sample_plans().remove(0);
    let (_, b) = sample_plans().remove(0);
    let (a, b) = (along_normals(&a), along_normals(&b));
    for m in MACHINES {
        let mach = machine::builtin(m.name).unwrap();
        let json_again = machine::from_json(&machine::to_json(&mach)).unwrap();
        for &(dialect, dname, _) in DIALECTS {
            let five = !mach.rotaries.is_empty() && dialect != Dialect::Plain;
            let (pa, pb) = if five {
                (a.clone(), b.clone())
            } else {
                (sample_plans().remove(0).1, sample_plans().remove(0).1)
            };
            for units in [Units::Mm, Units::Inch] {
                let x = post(&pa, &opts(), &job(&name), &mach, dialect, units).unwrap();
                let y = post(&pb, &opts(), &job(&name), &json_again, dialect, units).unwrap();
                assert!(x == y, "{} / {dname}: two runs differ", m.name);
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
    let o = opts();
    for (name, planned) in sample_plans() {
        let path = along_normals(&planned);
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
