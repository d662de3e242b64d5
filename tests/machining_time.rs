//! The machining-time model (issue 17) against closed forms: a straight move that speeds up,
//! cruises and brakes (with and without a jerk limit), a short move that never reaches the
//! feed, a 90° corner at the junction-deviation speed, a zig-zag of N passes, rotaries
//! that bound a move's speed, and a plan's report equal to the sum over its moves.

use tspath::machine::motion::{segment_times, Dynamics, Segment};
use tspath::machine::{self, path_times};
use tspath::model::samples;
use tspath::plan::{self, PlanOptions};

const ROTARY_FEED: f64 = 5400.0;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1e-9)
}

/// Dynamics with the given linear acceleration and jerk, everything else out of the way.
fn dynamics(accel: f64, jerk: f64) -> Dynamics {
    Dynamics {
        rapid_mm_min: 1e6,
        linear_accel_mm_s2: accel,
        linear_jerk_mm_s3: jerk,
        junction_deviation_mm: 0.01,
        ..Dynamics::default()
    }
}

fn feed_move(dx: f64, dy: f64, feed: f64) -> Segment {
    Segment {
        linear_mm: [dx, dy, 0.0],
        rotary_deg: [0.0; 2],
        tip_length_mm: dx.hypot(dy),
        feed_mm_min: Some(feed),
    }
}

#[test]
fn a_long_straight_move_speeds_up_cruises_and_brakes() {
    let (l, feed, a) = (100.0, 3000.0, 500.0);
    let v = feed / 60.0;
    // No jerk limit: a trapezoid, V/a to speed up and to brake, the rest at V.
    let t = segment_times(
        &[feed_move(l, 0.0, feed)],
        ROTARY_FEED,
        &dynamics(a, f64::INFINITY),
    );
    let expect = 2.0 * v / a + (l - v * v / a) / v;
    println!(
        "trapezoid: {} s, closed form {expect} s, length/feed {} s",
        t[0],
        l / v
    );
    assert!(close(t[0], expect));
    // Jerk j: each speed change takes V/a + a/j at the mean speed V/2.
    let j = 5000.0;
    let t = segment_times(&[feed_move(l, 0.0, feed)], ROTARY_FEED, &dynamics(a, j));
    let ramp = v / a + a / j;
    let expect = 2.0 * ramp + (l - v * ramp) / v;
    println!("S-curve: {} s, closed form {expect} s", t[0]);
    assert!(close(t[0], expect));
}

#[test]
fn a_short_move_never_reaches_the_feed() {
    let (l, feed, a) = (1.0, 6000.0, 200.0);
    // Trapezoid: peak sqrt(a l), time 2 sqrt(l / a).
    let t = segment_times(
        &[feed_move(l, 0.0, feed)],
        ROTARY_FEED,
        &dynamics(a, f64::INFINITY),
    );
    assert!((a * l).sqrt() < feed / 60.0);
    let expect = 2.0 * (l / a).sqrt();
    println!("short trapezoid: {} s, closed form {expect} s", t[0]);
    assert!((t[0] - expect).abs() <= 1e-9 * expect);
    // Jerk-limited with the acceleration never reached: each half is 2 sqrt(vp / j) long at
    // mean speed vp / 2, so l = 2 vp^1.5 / sqrt(j) and the time is 4 sqrt(vp / j).
    let j: f64 = 1000.0;
    let vp = (l * j.sqrt() / 2.0).powf(2.0 / 3.0);
    assert!(vp < a * a / j && vp < feed / 60.0);
    let t = segment_times(&[feed_move(l, 0.0, feed)], ROTARY_FEED, &dynamics(1e9, j));
    let expect = 4.0 * (vp / j).sqrt();
    println!("short S-curve: {} s, closed form {expect} s", t[0]);
    assert!((t[0] - expect).abs() <= 1e-9 * expect);
}

#[test]
fn a_right_angle_corner_is_taken_at_the_junction_speed() {
    let (l, feed, a, delta) = (50.0, 3000.0, 400.0, 0.02);
    let v = feed / 60.0;
    let mut d = dynamics(a, f64::INFINITY);
    d.junction_deviation_mm = delta;
    // sin(45°) / (1 - sin(45°)) = 1 + sqrt(2).
    let vj = (a * delta * (1.0 + 2f64.sqrt())).sqrt();
    assert!(vj < v);
    let t = segment_times(
        &[feed_move(l, 0.0, feed), feed_move(0.0, l, feed)],
        ROTARY_FEED,
        &d,
    );
    // Each leg: from rest to V, brake to vj (or the mirror), the rest at V.
    let leg = v / a + (v - vj) / a + (l - v * v / (2.0 * a) - (v * v - vj * vj) / (2.0 * a)) / v;
    println!(
        "corner at {vj:.3} mm/s: legs {} + {} s, closed form {leg} s each",
        t[0], t[1]
    );
    assert!(close(t[0], leg) && close(t[1], leg));
    // Straight on, no slowing: one move's time split in two.
    let straight = segment_times(
        &[feed_move(l, 0.0, feed), feed_move(l, 0.0, feed)],
        ROTARY_FEED,
        &d,
    );
    let one = segment_times(&[feed_move(2.0 * l, 0.0, feed)], ROTARY_FEED, &d);
    assert!(close(straight[0] + straight[1], one[0]));
}

#[test]
fn a_zig_zag_of_n_passes() {
    let (n, l, s, feed, a, delta) = (7, 40.0, 0.5, 2400.0, 800.0, 0.01);
    let v = feed / 60.0;
    let mut d = dynamics(a, f64::INFINITY);
    d.junction_deviation_mm = delta;
    let mut segs = Vec::new();
    for k in 0..n {
        let dir = if k % 2 == 0 { 1.0 } else { -1.0 };
        segs.push(feed_move(dir * l, 0.0, feed));
        if k + 1 < n {
            segs.push(feed_move(0.0, s, feed));
        }
    }
    let t = segment_times(&segs, ROTARY_FEED, &d);
    // Every corner is 90°: vj; a step of s peaks at sqrt(vj² + a s) (below V here).
    let vj = (a * delta * (1.0 + 2f64.sqrt())).sqrt();
    let vp = (vj * vj + a * s).sqrt();
    assert!(vp < v);
    let step = 2.0 * (vp - vj) / a;
    let cruise = |v0: f64, v1: f64| {
        (v - v0) / a
            + (v - v1) / a
            + (l - (v * v - v0 * v0) / (2.0 * a) - (v * v - v1 * v1) / (2.0 * a)) / v
    };
    let expect =
        cruise(0.0, vj) + cruise(vj, 0.0) + (n - 2) as f64 * cruise(vj, vj) + (n - 1) as f64 * step;
    let total: f64 = t.iter().sum();
    println!(
        "zig-zag of {n} passes: {total:.4} s, closed form {expect:.4} s, length/feed {:.4} s",
        (n as f64 * l + (n - 1) as f64 * s) / v
    );
    assert!(close(total, expect));
}

/// A move that turns the rotaries faster than they can go takes the rotaries' time, as the
/// post's inverse-time feed says; a move that only turns starts and ends stopped.
#[test]
fn rotaries_bound_a_moves_speed() {
    let d = Dynamics {
        rotary_accel_deg_s2: 1e12,
        rotary_jerk_deg_s3: f64::INFINITY,
        ..dynamics(1e12, f64::INFINITY)
    };
    let seg = Segment {
        linear_mm: [1.0, 0.0, 0.0],
        rotary_deg: [90.0, 0.0],
        tip_length_mm: 1.0,
        feed_mm_min: Some(1000.0),
    };
    let t = segment_times(&[seg], ROTARY_FEED, &d);
    let expect = 90.0 / ROTARY_FEED * 60.0;
    println!(
        "1 mm with a 90° turn: {} s (rotary bound {expect} s, feed alone 0.06 s)",
        t[0]
    );
    assert!((t[0] - expect).abs() <= 1e-6 * expect);
    // Turning only, with a finite angular acceleration: a trapezoid in degrees.
    let alpha = 300.0;
    let d = Dynamics {
        rotary_accel_deg_s2: alpha,
        ..d
    };
    let turn = Segment {
        linear_mm: [0.0; 3],
        rotary_deg: [0.0, 180.0],
        tip_length_mm: 0.0,
        feed_mm_min: Some(1000.0),
    };
    let w = ROTARY_FEED / 60.0;
    let t = segment_times(&[feed_move(10.0, 0.0, 1000.0), turn], ROTARY_FEED, &d);
    let expect = w / alpha + 180.0 / w;
    println!("a 180° turn alone: {} s, closed form {expect} s", t[1]);
    assert!(close(t[1], expect));
}

/// A plan's report: the machining time is the sum over its moves, at least the feed time,
/// and named for the machine; the built-in machines' dynamics round-trip through JSON.
#[test]
fn the_reports_time_is_the_sum_over_its_moves() {
    let m = samples::load_sample("dome").unwrap();
    let o = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.02);
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let r = planned.report(&o);
    let mach = machine::builtin("3-axis").unwrap();
    let t = path_times(&planned.toolpath, &o, &mach);
    assert_eq!(t.seconds.len(), planned.toolpath.moves.len());
    let sum: f64 = t.seconds.iter().sum::<f64>() / 60.0;
    println!(
        "dome: machining time {:.3} min on {}, feed time {:.3} min, {} moves",
        r.machining_time_min,
        r.time_machine,
        r.feed_time_min,
        t.seconds.len()
    );
    assert_eq!(r.time_machine, "3-axis");
    assert!(close(r.machining_time_min, sum));
    assert!(r.machining_time_min > r.feed_time_min);
    assert!(t.from_joints);
    for name in [
        "3-axis",
        "table-table-ac",
        "table-table-bc",
        "head-table-bc",
    ] {
        let m = machine::builtin(name).unwrap();
        let back = machine::from_json(&machine::to_json(&m)).unwrap();
        assert_eq!(back.dynamics, m.dynamics, "{name}");
    }
    // A machine file may leave the dynamics out (defaults) and names a bad field.
    let mut json: serde_json::Value = serde_json::from_str(&machine::to_json(&mach)).unwrap();
    json["dynamics"]["linear_accel_mm_s2"] = serde_json::json!(-1.0);
    let err = machine::from_json(&json.to_string())
        .unwrap_err()
        .to_string();
    assert!(err.contains("dynamics.linear_accel_mm_s2"), "{err}");
    json.as_object_mut().unwrap().remove("dynamics");
    assert_eq!(
        machine::from_json(&json.to_string()).unwrap().dynamics,
        Dynamics::default()
    );
}
