use tspath::model::samples;
use tspath::plan::{isoparametric, PlanOptions};
use tspath::verify::{self, cutter::CutterPath, VerifyOptions};
fn main() {
    let name = std::env::args().nth(1).unwrap_or("keycap-convex".into());
    let r: f64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.5);
    let h: f64 = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.005);
    let m = samples::load_sample(&name).unwrap();
    let opts = PlanOptions::default().with_tool_radius(r).with_scallop(h);
    let p = isoparametric::plan_zigzag(&m, &opts, &mut |_| true).unwrap();
    let cp = CutterPath::from_toolpath(&p).unwrap();
    let v = verify::verify_to_bound(
        &m.surface,
        &cp,
        &VerifyOptions::default()
            .with_scallop(h)
            .with_gouge_tolerance(opts.chordal_mm)
            .with_samples(2_000_000),
        0.15 * h,
    )
    .unwrap();
    println!(
        "max {:.5} bound {:.5} uncut {:.4}",
        v.max_scallop_mm, v.error_bound_mm, v.uncut_fraction
    );
    let mut pv = v.patches.clone();
    pv.sort_by(|a, b| b.max_scallop_mm.total_cmp(&a.max_scallop_mm));
    for f in pv.iter().take(8) {
        let fs = &m.surface.faces()[f.patch as usize];
        let c = fs.subs(0.5, 0.5);
        let lp = m
            .layout
            .patches
            .iter()
            .position(|p| p.pieces.iter().any(|q| q.face == f.patch))
            .unwrap();
        println!(
            "face {} (layout patch {lp}) max {:.5} uncut {:.4} centre {:.2?}",
            f.patch,
            f.max_scallop_mm,
            f.uncut_fraction,
            c.coords.as_slice()
        );
    }
    for f in v.patches.iter().filter(|f| f.gouge_count > 0) {
        let fs = &m.surface.faces()[f.patch as usize];
        println!(
            "gouge face {} count {} max {:.5} centre {:.2?}",
            f.patch,
            f.gouge_count,
            f.max_gouge_mm,
            fs.subs(0.5, 0.5).coords.as_slice()
        );
    }
}
