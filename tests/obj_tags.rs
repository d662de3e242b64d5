//! OBJ subdivision tags (issue 20): not applied yet, but never dropped silently. A cage
//! with `t crease` tags loads with a warning naming the tag and its line, every plan of it
//! lists that among its problems (the CLI exits 3), and an unknown tag is refused naming it.

mod support;

use support::extruded_obj;
use tspath::io;
use tspath::model::samples;
use tspath::plan::{self, PlanOptions, PlanStatus};

/// A wavy sheet cage (quads) with two crease tags and a corner tag, as subdivision tools
/// write them.
fn tagged_sheet() -> String {
    let profile: Vec<(f64, f64)> = (0..6)
        .map(|i| (5.0 * i as f64, 2.0 * (0.8 * i as f64).sin()))
        .collect();
    extruded_obj(&profile, 3, 6.0, false)
        + "t crease 2/1/0 7 8 2.0\nt crease 2/1/0 8 9 2.0\nt corner 1/1/0 0 10.0\n"
}

#[test]
fn subdivision_tags_are_named_not_dropped() {
    let text = tagged_sheet();
    let m = io::load(text.as_bytes(), "sheet").unwrap();
    assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
    let first_tag_line = text.lines().position(|l| l.starts_with("t ")).unwrap() + 1;
    assert!(
        m.warnings[0].contains("2 `t crease`")
            && m.warnings[0].contains(&format!("line {first_tag_line}")),
        "{}",
        m.warnings[0]
    );
    assert!(m.warnings[1].contains("`t corner`"), "{}", m.warnings[1]);
    assert_eq!(m.summary().warnings, m.warnings);
    // Every plan says so.
    let o = PlanOptions::default()
        .with_tool_radius(1.0)
        .with_scallop(0.1);
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let r = planned.report(&o);
    assert_eq!(r.status, PlanStatus::PlannedWithProblems);
    assert_eq!(
        r.problems
            .iter()
            .filter(|p| p.kind == "model_not_as_modelled")
            .count(),
        2
    );
    // The same cage without its tags: no warning.
    let plain: String = text
        .lines()
        .filter(|l| !l.starts_with("t "))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(io::load(plain.as_bytes(), "sheet")
        .unwrap()
        .warnings
        .is_empty());
    // Nor on a sample.
    assert!(samples::load_sample("dome").unwrap().warnings.is_empty());
    // An unknown tag is refused, named with its line.
    let bad = format!("{plain}t smooth 0/0/0\n");
    let e = io::load(bad.as_bytes(), "sheet").unwrap_err().to_string();
    let line = bad.lines().count();
    assert!(
        e.contains("`t smooth`") && e.contains(&format!("line {line}")),
        "{e}"
    );
}
