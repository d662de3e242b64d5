//! The space-filling curve's cells and tree as the page draws them (`plan::isfc::layer`):
//! four segments per cell along its loop between the corners' contact points, one segment
//! per tree link between the centres of the cells it joins, and the layer a plan keeps is the
//! layer of the curve it was planned from.

use crate::support;

use std::collections::HashMap;
use support::{holed_samples, isfc_opts as opts};
use tspath::model::samples;
use tspath::plan::isfc::layer::{Layer, SEGMENT_FLOATS};
use tspath::plan::isfc::{curve, Curve};
use tspath::plan::{self, Strategy};
use tspath::Model;

fn point(a: &[f32]) -> [f32; 3] {
    [a[0], a[1], a[2]]
}

fn as_f32(p: &tspath::geom::Point3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// Checks `layer` against `c`, computing what it should hold independently; returns the
/// number of tree links that cross a patch side.
fn check_layer(name: &str, c: &Curve, layer: &Layer) -> usize {
    assert_eq!(
        layer.cells.len(),
        4 * SEGMENT_FLOATS * c.cells.len(),
        "{name}"
    );
    assert_eq!(layer.cell_count(), c.cells.len(), "{name}");
    assert_eq!(layer.tree.len(), SEGMENT_FLOATS * c.tree.len(), "{name}");
    assert_eq!(layer.link_count(), c.tree.len(), "{name}");
    assert_eq!(layer.across.len(), c.tree.len(), "{name}");

    // Cell outlines: segment k of a cell runs from corner k to corner k + 1, so the four
    // chain round the cell and close.
    for (i, cell) in c.cells.iter().enumerate() {
        let segs = &layer.cells[i * 24..(i + 1) * 24];
        for k in 0..4 {
            let s = &segs[6 * k..6 * k + 6];
            let a = as_f32(&c.vertices[cell.corners[k] as usize].cc);
            let b = as_f32(&c.vertices[cell.corners[(k + 1) % 4] as usize].cc);
            assert_eq!(point(&s[..3]), a, "{name}: cell {i} segment {k} start");
            assert_eq!(point(&s[3..]), b, "{name}: cell {i} segment {k} end");
            let next = &segs[(6 * (k + 1)) % 24..];
            assert_eq!(
                point(&s[3..]),
                point(next),
                "{name}: cell {i} is not a loop"
            );
        }
    }

    // Tree links: between the centres of the cells each link joins.
    let centre = |cell: u32| {
        let mut sum = [0.0f64; 3];
        for &v in &c.cells[cell as usize].corners {
            let p = c.vertices[v as usize].cc;
            for (k, x) in [p.x, p.y, p.z].into_iter().enumerate() {
                sum[k] += x / 4.0;
            }
        }
        sum
    };
    let mut across = 0;
    for (k, &l) in c.tree.iter().enumerate() {
        let link = &c.links[l];
        let s = &layer.tree[6 * k..6 * k + 6];
        for (end, cell) in [(&s[..3], link.a), (&s[3..], link.b)] {
            let want = centre(cell);
            for d in 0..3 {
                assert!(
                    (f64::from(end[d]) - want[d]).abs() <= 1e-6 * want[d].abs().max(1.0),
                    "{name}: tree link {k} ends at {end:?}, the centre of cell {cell} is {want:?}"
                );
            }
        }
        let crosses = c.cells[link.a as usize].patch != c.cells[link.b as usize].patch;
        assert_eq!(layer.across[k], u8::from(crosses), "{name}: link {k}");
        assert_eq!(crosses, l >= c.within, "{name}: link {k} across patches");
        across += usize::from(crosses);
    }

    // The drawn tree alone joins every cell: its segments' ends, matched to the cells'
    // centres, connect them all.
    let mut by_centre: HashMap<[u32; 3], usize> = HashMap::new();
    let key = |p: &[f32]| [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
    let mut next = 0usize;
    let mut id = |p: &[f32], map: &mut HashMap<[u32; 3], usize>| {
        *map.entry(key(p)).or_insert_with(|| {
            next += 1;
            next - 1
        })
    };
    let mut edges = Vec::new();
    for s in layer.tree.chunks(6) {
        let a = id(&s[..3], &mut by_centre);
        let b = id(&s[3..], &mut by_centre);
        edges.push((a, b));
    }
    if c.loops.len() == 1 && c.cells.len() > 1 {
        assert_eq!(
            by_centre.len(),
            c.cells.len(),
            "{name}: the tree's ends are the centres of all {} cells",
            c.cells.len()
        );
        let mut parent: Vec<usize> = (0..by_centre.len()).collect();
        fn find(p: &mut [usize], mut a: usize) -> usize {
            while p[a] != a {
                p[a] = p[p[a]];
                a = p[a];
            }
            a
        }
        for &(a, b) in &edges {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            assert_ne!(ra, rb, "{name}: the drawn tree has a cycle");
            parent[ra] = rb;
        }
        let root = find(&mut parent, 0);
        assert!(
            (0..by_centre.len()).all(|i| find(&mut parent, i) == root),
            "{name}: the drawn tree leaves cells apart"
        );
    }

    // The start is the first loop's first vertex.
    let first = c.loops[0][0] as usize;
    let p = c.vertices[first].cc;
    assert_eq!(layer.start_mm, Some([p.x, p.y, p.z]), "{name}: start");
    across
}

#[test]
fn cells_and_tree_segments_are_the_curves() {
    for (name, m, o) in holed_samples() {
        let c = curve(&m, &o, &mut |_| true).unwrap();
        let layer = Layer::of(&c);
        let across = check_layer(name, &c, &layer);
        // One loop over a connected layout: the tree joins every cell, some across sides.
        assert_eq!(c.loops.len(), 1, "{name}");
        assert_eq!(layer.link_count(), layer.cell_count() - 1, "{name}");
        assert!(
            across >= m.layout.len() - 1,
            "{name}: {across} links cross patch sides"
        );
    }
}

#[test]
fn a_plan_keeps_the_layer_of_the_curve_it_was_planned_from() {
    let m: Model = samples::load_sample("plate-hole").unwrap();
    let o = opts(1.0, 0.05);
    let planned = plan::plan(&m, &o, &mut |_| true).unwrap();
    let kept = planned
        .isfc_layer
        .as_ref()
        .expect("an isfc plan keeps its layer");
    let c = curve(&m, &o, &mut |_| true).unwrap();
    assert_eq!(kept, &Layer::of(&c), "the plan's layer is its curve's");
    check_layer("plate-hole (planned)", &c, kept);
    let report = planned.report(&o);
    assert_eq!(report.cells, Some(kept.cell_count()));
    assert_eq!(report.tree_links, Some(kept.link_count()));
    // The report's note gives the same start (to the micrometre).
    let s = kept.start_mm.unwrap();
    let say = format!("starting at ({:.3}, {:.3}, {:.3}) mm", s[0], s[1], s[2]);
    assert!(
        report.notes.iter().any(|n| n.contains(&say)),
        "notes {:?} should say {say}",
        report.notes
    );

    // Zig-zags have no cells.
    let zig = plan::plan(
        &m,
        &o.clone().with_strategy(Strategy::Isoparametric),
        &mut |_| true,
    )
    .unwrap();
    assert!(zig.isfc_layer.is_none());
}
