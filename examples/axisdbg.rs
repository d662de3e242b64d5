use tspath::model::samples;
use tspath::plan::{isoparametric, PlanOptions};
fn main() {
    let m = samples::load_sample("keycap-concave").unwrap();
    let mut opts = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.05)
        .with_chordal(0.005)
        .with_holder(1.0, 15.0, 6.0, 30.0);
    opts.flute_length_mm = Some(1.0);
    let p = isoparametric::plan_zigzag(&m, &opts, &mut |_| true).unwrap();
    let mut worst = (0.0, 0);
    for i in 1..p.moves.len() {
        let a = p.moves[i - 1]
            .tool_axis
            .dot(&p.moves[i].tool_axis)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        if a > worst.0 {
            worst = (a, i);
        }
    }
    let i = worst.1;
    for j in i - 3..i + 3 {
        let m = &p.moves[j];
        println!(
            "{j} {:?} {:?} cl {:?} line {} patch {}",
            m.kind,
            m.tool_axis.as_slice(),
            m.cl_point.coords.as_slice(),
            m.line,
            m.patch
        );
    }
}
