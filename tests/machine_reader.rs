//! The program reader on hand-written files: modal words, incremental moves, units, comments,
//! and errors that name the line.

use tspath::machine::reader::{read, FeedMode};
use tspath::machine::Units;

#[test]
fn reads_a_hand_written_iso_program() {
    let text = "%
O0100 (hand written)
N10 g21 g90 g17 (metric)
N20 G0 X 10 Y10 Z5 ; rapid above
N30 G1 Z-1 F200
N40 X20
N50 G91 Y5
N60 G90 G0 Z5
N70 G20 G1 X1 F10
M30
%
";
    let p = read(text).unwrap();
    assert_eq!(p.units, Units::Inch, "the last unit word wins");
    let got: Vec<([f64; 3], FeedMode, f64, usize)> = p
        .moves
        .iter()
        .map(|m| (m.xyz_mm, m.feed_mode, m.feed, m.line))
        .collect();
    let want = [
        ([10.0, 10.0, 5.0], FeedMode::Rapid, f64::NAN, 4),
        ([10.0, 10.0, -1.0], FeedMode::PerMinute, 200.0, 5),
        ([20.0, 10.0, -1.0], FeedMode::PerMinute, 200.0, 6),
        ([20.0, 15.0, -1.0], FeedMode::PerMinute, 200.0, 7),
        ([20.0, 15.0, 5.0], FeedMode::Rapid, f64::NAN, 8),
        ([25.4, 15.0, 5.0], FeedMode::PerMinute, 254.0, 9),
    ];
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g.0, w.0, "line {}", w.3);
        assert_eq!(g.1, w.1);
        assert!(
            g.2 == w.2 || (g.2.is_nan() && w.2.is_nan()),
            "line {}: feed {}",
            w.3,
            g.2
        );
        assert_eq!(g.3, w.3);
    }
}

#[test]
fn reads_a_hand_written_heidenhain_program() {
    let text = "0 BEGIN PGM T1 INCH
1 ; a comment
2 TOOL CALL 1 Z S8000
3 L Z+1 R0 FMAX M3
4 L X+1 Y+2 R0 F100
5 L IX+0.5 R0
6 END PGM T1 INCH
";
    let p = read(text).unwrap();
    assert_eq!(p.units, Units::Inch);
    assert_eq!(p.moves.len(), 3);
    assert_eq!(p.moves[0].feed_mode, FeedMode::Rapid);
    assert_eq!(p.moves[1].xyz_mm, [25.4, 50.8, 25.4]);
    // Inch programs give F in 0.1 inch/min: F100 = 10 inch/min = 254 mm/min.
    assert!((p.moves[1].feed - 254.0).abs() < 1e-9);
    assert!((p.moves[2].xyz_mm[0] - 38.1).abs() < 1e-12);
    let e = read(&text.replace("5 L IX+0.5 R0", "5 CC X+0 Y+0"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 6") && e.contains("CC"), "{e}");
}

#[test]
fn errors_name_the_line_and_the_problem() {
    let cases = [
        ("G21\nG0 X0 Y0\nG2 X1 Y1 I1 J0\n", "line 3", "arcs"),
        ("G21\nG1 X1 Y1\n", "line 2", "feed"),
        ("G21 (unclosed\n", "line 1", "not closed"),
        ("G21\nG93 G1 X1 A10\n", "line 2", "G93"),
        ("G21\nG1 X1 Q3 F100\n", "line 2", "Q"),
        ("G21\nX1\n", "line 2", "motion mode"),
        ("G21\nG1 X1 X2 F100\n", "line 2", "twice"),
        ("G21\nG1 X F100\n", "line 2", "number"),
        ("G71\nG1 X1 F100\n", "line 1", "G710"),
    ];
    for (text, line, what) in cases {
        let e = read(text).unwrap_err().to_string();
        assert!(e.contains(line) && e.contains(what), "{text:?}: {e}");
    }
}
