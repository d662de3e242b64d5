use std::time::Instant;
use tspath::model::samples;
use tspath::plan::{isoparametric, PlanOptions};
fn main() {
    let m = samples::load_sample("keycap-convex").unwrap();
    let opts = PlanOptions::default()
        .with_tool_radius(0.5)
        .with_scallop(0.005)
        .with_chordal(0.001);
    let t = Instant::now();
    let o = tspath::plan::axis::Obstacles::new(&m, 0.07);
    println!("obstacles {:?} points gap {}", t.elapsed(), o.gap_mm);
    let t = Instant::now();
    let o2 = opts.clone();
    let mut t08 = None;
    let p = isoparametric::plan(&m, &o2, &mut |f| {
        if f >= 0.8 && t08.is_none() {
            t08 = Some(t.elapsed());
        }
        true
    });
    println!("path part {:?}", t08);
    println!(
        "plan {:?} {:?}",
        t.elapsed(),
        p.as_ref()
            .map(|p| (p.toolpath.moves.len(), p.axes))
            .map_err(|e| e.to_string())
    );
}
