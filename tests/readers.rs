//! Malformed inputs to the JSON T-mesh and OBJ readers and to model building: every case
//! must give a typed error whose message names the record (JSON) or line (OBJ) at fault and
//! says what was expected, never a panic. Then a fuzz test that mutates valid files and
//! checks that whatever loads evaluates to finite numbers.
//!
//! The fuzz test runs `DEFAULT_FUZZ_CASES` cases per format; `TSPATH_FUZZ_CASES=N` (or
//! proptest's own `PROPTEST_CASES=N`) runs more.

use crate::support;

use proptest::prelude::*;
use serde_json::{json, Value};
use tspath::error::Error;
use tspath::io;
use tspath::model::samples::sample_json;
use tspath::Model;

// ---------------------------------------------------------------------------------------
// Helpers

fn load(bytes: &[u8]) -> Result<Model, Error> {
    io::load(bytes, "test")
}

fn load_str(text: &str) -> Result<Model, Error> {
    load(text.as_bytes())
}

/// The location and message of a parse error, or a panic saying what came instead.
#[track_caller]
fn parse_error(r: Result<Model, Error>, format: &str) -> (String, String) {
    match r {
        Err(Error::Parse {
            format: f,
            location,
            message,
        }) => {
            assert_eq!(f, format, "{location}: {message}");
            (location, message)
        }
        Err(e) => panic!("expected a {format} parse error, got {e:?}"),
        Ok(_) => panic!("expected a {format} parse error, the file loaded"),
    }
}

/// The message of an invalid-mesh error.
#[track_caller]
fn mesh_error(r: Result<Model, Error>) -> String {
    match r {
        Err(Error::InvalidMesh(m)) => m,
        Err(e) => panic!("expected an invalid-mesh error, got {e:?}"),
        Ok(_) => panic!("expected an invalid-mesh error, the file loaded"),
    }
}

#[track_caller]
fn assert_mentions(text: &str, parts: &[&str]) {
    for p in parts {
        assert!(text.contains(p), "`{text}` should mention `{p}`");
    }
}

/// Points, surface faces and patches evaluate to finite numbers at a few parameters.
fn assert_finite(m: &Model) -> Result<(), String> {
    const PARAMS: [(f64, f64); 5] = [(0.0, 0.0), (1.0, 1.0), (0.5, 0.5), (0.3, 0.7), (1.0, 0.0)];
    let finite = |d: &tspath::surface::SurfaceDerivs| {
        [d.su, d.sv, d.suu, d.suv, d.svv]
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()))
            && d.point.iter().all(|x| x.is_finite())
    };
    for f in 0..m.surface.faces().len() {
        for (u, v) in PARAMS {
            let d = m.surface.derivs(f, u, v);
            if !finite(&d) {
                return Err(format!("face {f} at ({u}, {v}): {d:?}"));
            }
        }
    }
    for (k, p) in m.layout.patches.iter().enumerate() {
        for (u, v) in PARAMS {
            let d = p.derivs(&m.surface, u, v);
            if !finite(&d) {
                return Err(format!("patch {k} at ({u}, {v}): {d:?}"));
            }
        }
    }
    let b = m.surface.bbox();
    if !(b.min.iter().chain(b.max.iter()).all(|x| x.is_finite())) {
        return Err(format!("bounding box {b:?}"));
    }
    Ok(())
}

/// A JSON T-mesh with the given points and faces (and extra top-level members).
fn json_mesh(points: Value, faces: Value, extra: &[(&str, Value)]) -> String {
    let mut root = json!({
        "format": "tspath-tmesh",
        "version": 1,
        "points": points,
        "faces": faces,
    });
    for (k, v) in extra {
        root[*k] = v.clone();
    }
    serde_json::to_string_pretty(&root).unwrap()
}

/// `n` points on a line, z = 0 (enough for topology cases, which fail before geometry).
fn points(n: usize) -> Value {
    Value::Array(
        (0..n)
            .map(|i| json!([i as f64, (i * i % 7) as f64, 0.0]))
            .collect(),
    )
}

/// The dome sample as a JSON value, to be edited.
fn dome() -> Value {
    serde_json::from_str(&sample_json("dome").unwrap()).unwrap()
}

fn text(v: &Value) -> String {
    serde_json::to_string_pretty(v).unwrap()
}

/// 1-based line number of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

// ---------------------------------------------------------------------------------------
// Files that are not model files at all

#[test]
fn empty_and_whitespace_only_files() {
    for bytes in [&b""[..], b"   ", b"\n\n\t \r\n"] {
        let (loc, msg) = parse_error(load(bytes), "model");
        assert_eq!(loc, "byte 0");
        assert_mentions(&msg, &["empty"]);
    }
}

#[test]
fn binary_garbage_is_not_a_model_file() {
    // A deterministic byte soup (a linear congruential sequence), all 256 values present.
    let mut x: u32 = 12345;
    let bytes: Vec<u8> = (0..4096)
        .map(|i| {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            if i < 256 {
                (255 - i) as u8
            } else {
                (x >> 16) as u8
            }
        })
        .collect();
    let (_, msg) = parse_error(load(&bytes), "model");
    assert_mentions(&msg, &["JSON", ".obj"]);
}

#[test]
fn json_that_is_not_utf8_names_the_byte() {
    let good = sample_json("dome").unwrap();
    let at = good.find("\"dome\"").unwrap() + 2;
    let mut bytes = good.into_bytes();
    bytes[at] = 0xE9; // Latin-1 é
    let (loc, msg) = parse_error(load(&bytes), "json");
    assert_eq!(loc, format!("byte {at}"));
    assert_mentions(&msg, &["UTF-8"]);
}

// ---------------------------------------------------------------------------------------
// JSON: truncated files

/// Every prefix of a sample file fails with a parse error located on the prefix's last line
/// (where the text stops), except the whole file with or without its final newline.
#[test]
fn json_every_prefix_is_a_located_parse_error() {
    for name in ["dome", "tjunction", "keycap-convex"] {
        let full = sample_json(name).unwrap();
        let trimmed = full.trim_end().len();
        for len in 0..full.len() {
            let prefix = &full.as_bytes()[..len];
            let r = load(prefix);
            if len >= trimmed {
                assert!(r.is_ok(), "{name}: prefix of {len} bytes: {:?}", r.err());
                continue;
            }
            if prefix.iter().all(u8::is_ascii_whitespace) {
                parse_error(r, "model");
                continue;
            }
            let (loc, msg) = parse_error(r, "json");
            let line = prefix.iter().filter(|&&b| b == b'\n').count() + 1;
            let expect = format!("line {line} column ");
            assert!(
                loc.starts_with(&expect),
                "{name}: prefix of {len} bytes: `{loc}: {msg}`, expected {expect}"
            );
            assert!(!msg.is_empty());
        }
    }
}

// ---------------------------------------------------------------------------------------
// JSON: wrong counts

#[test]
fn json_face_with_two_vertices() {
    let mut d = dome();
    d["faces"][4] = json!([5, 6]);
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "faces[4]");
    assert_mentions(&msg, &["2 vertices", "4"]);
    // The object form: two vertices cannot bound a face either.
    d["faces"][4] = json!({"vertices": [5, 6], "corners": [0, 1, 1, 1]});
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "faces[4]");
    assert_mentions(&msg, &["2 vertices"]);
}

#[test]
fn json_three_corners() {
    let mut d = dome();
    d["faces"][2] = json!({"vertices": [2, 3, 7, 6], "corners": [0, 1, 2]});
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "faces[2]");
    assert_mentions(&msg, &["four", "corners", "found 3"]);
    // A corner that is not a loop position of the face.
    d["faces"][2] = json!({"vertices": [2, 3, 7, 6], "corners": [0, 1, 2, 9]});
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "faces[2]");
    assert_mentions(&msg, &["corner", "9", "4 vertices"]);
}

#[test]
fn json_points_with_two_or_five_numbers() {
    for p in [
        json!([1.0, 2.0]),
        json!([1.0, 2.0, 3.0, 1.0, 5.0]),
        json!(7.0),
    ] {
        let mut d = dome();
        d["points"][3] = p;
        let (loc, msg) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "points[3]");
        assert_mentions(&msg, &["[x, y, z]"]);
    }
}

#[test]
fn json_missing_or_wrong_top_level_members() {
    let cases: Vec<(Value, &str)> = vec![
        (json!([1, 2, 3]), "top level"),
        (json!({"format": "other", "version": 1}), "\"format\""),
        (
            json!({"format": "tspath-tmesh", "version": 2}),
            "\"version\"",
        ),
        (
            json!({"format": "tspath-tmesh", "version": 1, "faces": []}),
            "\"points\"",
        ),
        (
            json!({"format": "tspath-tmesh", "version": 1, "points": []}),
            "\"faces\"",
        ),
    ];
    for (v, loc) in cases {
        // A top-level array is not detected as JSON at all (detection looks for `{`).
        let r = load_str(&v.to_string());
        if v.is_array() {
            parse_error(r, "model");
            continue;
        }
        let (l, _) = parse_error(r, "json");
        assert_eq!(l, loc);
    }
    let mut d = dome();
    d["units"] = json!("furlong");
    let (l, m) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(l, "\"units\"");
    assert_mentions(&m, &["furlong", "mm"]);
    let mut d = dome();
    d["scheme"] = json!("loop");
    let (l, _) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(l, "\"scheme\"");
    let mut d = dome();
    d["faces"] = json!([]);
    d["knots"] = json!([]);
    assert_mentions(&mesh_error(load_str(&text(&d))), &["no faces"]);
}

// ---------------------------------------------------------------------------------------
// JSON: dangling references

#[test]
fn json_face_index_beyond_the_points() {
    let mut d = dome();
    d["faces"][5] = json!([5, 6, 10, 16]);
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "faces[5]");
    assert_mentions(&msg, &["16", "points"]);
}

#[test]
fn json_negative_or_fractional_index() {
    for bad in [json!(-1), json!(2.5), json!("3")] {
        let mut d = dome();
        d["faces"][1] = json!([1, 2, bad, 5]);
        let (loc, msg) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "faces[1]");
        assert_mentions(&msg, &["vertex index"]);
    }
}

#[test]
fn json_knot_records() {
    // An interval for an edge no face has.
    let mut d = dome();
    d["knots"].as_array_mut().unwrap().push(json!([0, 15, 1.0]));
    let k = d["knots"].as_array().unwrap().len() - 1;
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, format!("knots[{k}]"));
    assert_mentions(&msg, &["0", "15", "no face"]);
    // Negative, non-numeric, wrongly shaped.
    for bad in [json!([0, 1, -1.0]), json!([0, 1, "x"]), json!([0, 1])] {
        let mut d = dome();
        d["knots"][0] = bad;
        let (loc, _) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "knots[0]");
    }
    // The same edge twice with different intervals.
    let mut d = dome();
    let first = d["knots"][0].clone();
    let mut again = first.clone();
    again[2] = json!(first[2].as_f64().unwrap() + 1.0);
    d["knots"].as_array_mut().unwrap().push(again);
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, format!("knots[{k}]"));
    assert_mentions(&msg, &["knots[0]"]);
    // A default knot that is not a non-negative number.
    for bad in [json!(-1.0), json!("one")] {
        let mut d = dome();
        d["default_knot"] = bad;
        let (loc, _) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "\"default_knot\"");
    }
}

// ---------------------------------------------------------------------------------------
// JSON: bad numbers

#[test]
fn json_non_numbers_in_points() {
    let good = sample_json("dome").unwrap();
    let target = "[28.2842712474619, 20.0,";
    let line = line_of(&good, target);
    for bad in ["NaN", "Infinity", "-inf", "1e999", "0x10", "1.2.3", "--1"] {
        let t = good.replacen(target, &format!("[{bad}, 20.0,"), 1);
        let (loc, msg) = parse_error(load_str(&t), "json");
        assert!(
            loc.starts_with(&format!("line {line} column")),
            "{bad}: `{loc}: {msg}` should be on line {line}"
        );
    }
    // Strings and nulls are valid JSON but not numbers: the record is named.
    for bad in [json!("abc"), json!(null), json!(true)] {
        let mut d = dome();
        d["points"][7][1] = bad;
        let (loc, msg) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "points[7]");
        assert_mentions(&msg, &["number"]);
    }
}

#[test]
fn json_weights_must_be_positive() {
    for w in [0.0, -1.0, -0.0] {
        let mut d = dome();
        d["points"][9][3] = json!(w);
        let (loc, msg) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "points[9]");
        assert_mentions(&msg, &["weight", "positive"]);
    }
}

#[test]
fn json_numbers_too_large_for_the_surface() {
    // Finite in the file but beyond any machinable size: overflows once scaled or evaluated.
    let mut d = dome();
    d["points"][5][0] = json!(1e300);
    let (loc, msg) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "points[5]");
    assert_mentions(&msg, &["mm"]);
    let mut d = dome();
    d["units"] = json!("m");
    d["points"][5][2] = json!(1e306);
    let (loc, _) = parse_error(load_str(&text(&d)), "json");
    assert_eq!(loc, "points[5]");
    // Weights so far apart that rational evaluation over- or underflows.
    for w in [1e-300, 1e300] {
        let mut d = dome();
        d["points"][5][3] = json!(w);
        let (loc, msg) = parse_error(load_str(&text(&d)), "json");
        assert_eq!(loc, "points[5]");
        assert_mentions(&msg, &["weight"]);
    }
    // Knot intervals whose sums overflow.
    let mut d = dome();
    for k in d["knots"].as_array_mut().unwrap() {
        k[2] = json!(1e308);
    }
    let r = load_str(&text(&d));
    match r {
        Err(Error::Parse { location, .. }) => assert!(location.starts_with("knots[")),
        Err(Error::InvalidMesh(m)) => assert_mentions(&m, &["face"]),
        Err(e) => panic!("{e:?}"),
        Ok(m) => assert_finite(&m).unwrap(),
    }
}

// ---------------------------------------------------------------------------------------
// JSON: topology

#[test]
fn json_edge_used_by_three_faces() {
    // Three quads hinged on edge 0–1, like pages of a book.
    let t = json_mesh(
        points(8),
        json!([[0, 1, 2, 3], [1, 0, 4, 5], [0, 1, 6, 7]]),
        &[],
    );
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["0->1", "faces 0 and 2"]);
}

#[test]
fn json_edge_used_twice_in_the_same_direction() {
    let t = json_mesh(points(6), json!([[0, 1, 2, 3], [0, 1, 4, 5]]), &[]);
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["0->1", "faces 0 and 1", "orient"]);
}

#[test]
fn json_inconsistent_orientation() {
    // A 2 × 1 strip whose second face runs clockwise.
    let t = json_mesh(points(6), json!([[0, 1, 4, 3], [4, 5, 2, 1]]), &[]);
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["1->4", "faces 0 and 1"]);
}

#[test]
fn json_bow_tie_vertex() {
    let t = json_mesh(points(7), json!([[0, 1, 2, 3], [0, 4, 5, 6]]), &[]);
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["vertex 0", "non-manifold"]);
    // A face that passes through the same vertex twice.
    let t = json_mesh(
        points(5),
        json!([{"vertices": [0, 1, 2, 0, 3, 4], "corners": [0, 1, 3, 4]}]),
        &[],
    );
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["vertex 0", "non-manifold"]);
}

#[test]
fn json_opposite_sides_disagree() {
    // One quad whose bottom side is 2 long and top side 1.
    let t = json_mesh(
        points(4),
        json!([[0, 1, 2, 3]]),
        &[("knots", json!([[0, 1, 2.0]]))],
    );
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["face 0", "opposite sides", "2.0", "1.0"]);
    // With a T-junction: side 0 is split 1 + 1, side 2 is 1.5.
    let t = json_mesh(
        points(5),
        json!([{"vertices": [0, 4, 1, 2, 3], "corners": [0, 2, 3, 4]}]),
        &[("knots", json!([[2, 3, 1.5]]))],
    );
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["face 0", "opposite sides"]);
}

#[test]
fn json_unused_point_between_used_ones() {
    // Points 2 and 3 are gaps no face refers to.
    let t = json_mesh(points(6), json!([[0, 1, 4, 5]]), &[]);
    let msg = mesh_error(load_str(&t));
    assert_mentions(&msg, &["vertex 2", "not used"]);
}

// ---------------------------------------------------------------------------------------
// OBJ

/// An `n × m` grid of quads, vertices numbered row by row from 1, gently curved.
fn obj_grid(n: usize, m: usize) -> String {
    let grid = support::quad_grid_obj(n, m, |i, j| {
        let (x, y) = (i as f64 * 10.0, j as f64 * 10.0);
        [x, y, 0.01 * (x - 15.0) * (y - 10.0)]
    });
    format!("# grid\n{grid}")
}

/// A cube cage (eight extraordinary points of valence 3), with texture/normal indices.
const OBJ_CUBE: &str = "\
o cube
v -10 -10 -10
v 10 -10 -10
v 10 10 -10
v -10 10 -10
v -10 -10 10
v 10 -10 10
v 10 10 10
v -10 10 10
vt 0 0
vn 0 0 1
f 1/1/1 4/1/1 3/1/1 2/1/1
f 5//1 6//1 7//1 8//1
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
";

/// A plate of a triangle, a quad and a pentagon (subdivided once on reading).
const OBJ_MIXED: &str = "\
v 0 0 0
v 10 0 1
v 20 0 0
v 0 10 1
v 10 10 2
v 20 10 1
v 30 5 0
f 1 2 5 4
f 2 3 5
f 3 7 6 5
";

#[test]
fn obj_bases_load_and_evaluate() {
    for t in [obj_grid(3, 2), OBJ_CUBE.to_string(), OBJ_MIXED.to_string()] {
        let m = load_str(&t).unwrap();
        assert_eq!(m.format, "obj");
        assert_finite(&m).unwrap();
    }
}

#[test]
fn obj_every_prefix_loads_or_names_its_last_line() {
    for full in [obj_grid(3, 2), OBJ_CUBE.to_string(), OBJ_MIXED.to_string()] {
        for len in 0..=full.len() {
            let prefix = &full[..len];
            let last = prefix.lines().count().max(1);
            match load_str(prefix) {
                Ok(m) => assert_finite(&m).unwrap(),
                Err(Error::Parse {
                    format: "obj",
                    location,
                    message,
                }) => {
                    if location != "end of file" {
                        assert_eq!(location, format!("line {last}"), "{len}: {message}");
                    }
                }
                // Before any `v` or `f` record the file is not recognised as OBJ.
                Err(Error::Parse {
                    format: "model", ..
                }) => assert!(!prefix.contains("\nv ") && !prefix.starts_with("v ")),
                // A subset of the faces may meet at a vertex only (a bow-tie).
                Err(Error::InvalidMesh(m)) => assert_mentions(&m, &["line"]),
                Err(e) => panic!("prefix of {len} bytes: {e:?}"),
            }
        }
    }
}

/// Replaces line `n` (1-based) of `text`.
fn with_line(text: &str, n: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[n - 1] = new;
    lines.join("\n") + "\n"
}

#[test]
fn obj_wrong_counts() {
    let g = obj_grid(2, 2); // line 1 comment, 9 vertices on lines 2..10, faces 11..14
    for (line, bad, expect) in [
        (12, "f 2 3", "found 2"),
        (12, "f", "found 0"),
        (4, "v 1 2", "found 2"),
        (4, "v 1 2 3 1 5", "found 5"),
    ] {
        let (loc, msg) = parse_error(load_str(&with_line(&g, line, bad)), "obj");
        assert_eq!(loc, format!("line {line}"), "{bad}: {msg}");
        assert_mentions(&msg, &[expect]);
    }
}

#[test]
fn obj_dangling_references() {
    let g = obj_grid(2, 2);
    for (bad, expect) in [
        ("f 2 3 6 10", "10"),
        ("f 2 3 6 0", "start at 1"),
        ("f 2 3 6 -10", "-10"),
        ("f 2 3 6 x", "`x`"),
        ("f 2 3 6 /5", "`/5`"),
        ("f 2 3 6 99999999999999999999999", "vertex index"),
    ] {
        let (loc, msg) = parse_error(load_str(&with_line(&g, 13, bad)), "obj");
        assert_eq!(loc, "line 13", "{bad}: {msg}");
        assert_mentions(&msg, &[expect]);
    }
    // Negative indices count back from the last vertex so far: -1 is vertex 9 here.
    let rel = with_line(&g, 14, "f -5 -4 -1 -2");
    let a = load_str(&rel).unwrap();
    let b = load_str(&g).unwrap();
    assert_eq!(a.surface.subs(3, 0.3, 0.6), b.surface.subs(3, 0.3, 0.6));
}

#[test]
fn obj_bad_numbers() {
    let g = obj_grid(2, 2);
    for bad in [
        "v nan 0 0",
        "v 0 inf 0",
        "v 0 0 -infinity",
        "v 1e999 0 0",
        "v abc 0 0",
        "v 1,5 0 0",
    ] {
        let (loc, msg) = parse_error(load_str(&with_line(&g, 5, bad)), "obj");
        assert_eq!(loc, "line 5", "{bad}: {msg}");
        assert_mentions(&msg, &["number"]);
    }
    for bad in ["v 1 2 3 0", "v 1 2 3 -2", "v 1 2 3 1e-300", "v 1 2 3 1e300"] {
        let (loc, msg) = parse_error(load_str(&with_line(&g, 5, bad)), "obj");
        assert_eq!(loc, "line 5", "{bad}: {msg}");
        assert_mentions(&msg, &["weight"]);
    }
    let (loc, msg) = parse_error(load_str(&with_line(&g, 5, "v 1e300 0 0")), "obj");
    assert_eq!(loc, "line 5");
    assert_mentions(&msg, &["mm"]);
}

#[test]
fn obj_empty_and_faceless() {
    let (loc, msg) = parse_error(load_str("v 1 2 3\nv 4 5 6\n"), "obj");
    assert_eq!(loc, "end of file");
    assert_mentions(&msg, &["no faces"]);
    // Comments only: not recognised as any format.
    parse_error(load_str("# nothing here\n"), "model");
}

#[test]
fn obj_non_utf8_bytes() {
    // In a comment or a group name the bytes do not matter.
    let g = obj_grid(2, 2);
    let mut bytes = b"# caf\xe9 \xff\xfe\ng \xe9t\xe9\n".to_vec();
    bytes.extend_from_slice(g.as_bytes());
    let m = load(&bytes).unwrap();
    assert_eq!(
        m.surface.subs(0, 0.5, 0.5),
        load_str(&g).unwrap().surface.subs(0, 0.5, 0.5)
    );
    // In a number they do, and the line is named.
    let mut bytes = g.clone().into_bytes();
    let at = g.find("v 10 0").unwrap() + 3;
    bytes[at] = 0xB9; // Latin-1 superscript one
    let (loc, _) = parse_error(load(&bytes), "obj");
    assert_eq!(loc, format!("line {}", line_of(&g, "v 10 0")));
}

#[test]
fn obj_edge_used_by_three_faces() {
    let t = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 -1 0\nv 0 -1 0\nv 1 0 1\nv 0 0 1\n\
             f 1 2 3 4\nf 2 1 6 5\nf 1 2 7 8\n";
    let msg = mesh_error(load_str(t));
    assert_mentions(&msg, &["edge 1–2", "lines 9, 10 and 11"]);
}

#[test]
fn obj_edge_used_twice_in_the_same_direction() {
    let t = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 -1 0\nv 0 -1 0\n\
             f 1 2 3 4\n# the second face runs the wrong way round\nf 1 2 5 6\n";
    let msg = mesh_error(load_str(t));
    assert_mentions(&msg, &["vertex 1 to vertex 2", "lines 7 and 9", "orient"]);
}

#[test]
fn obj_inconsistent_orientation_in_a_grid() {
    // Flip one face of a 3 × 2 grid (line 18 is its fifth face).
    let g = obj_grid(3, 2);
    let flipped = with_line(&g, 18, "f 6 10 11 7");
    let msg = mesh_error(load_str(&flipped));
    // Its first neighbour in file order is the face on line 15.
    assert_mentions(&msg, &["lines 15 and 18", "orient"]);
}

#[test]
fn obj_bow_tie_vertex() {
    let t = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0 0\nv -1 -1 0\nv 0 -1 0\n\
             f 1 2 3 4\nf 1 5 6 7\n";
    let msg = mesh_error(load_str(t));
    assert_mentions(
        &msg,
        &["vertex 1", "line 1", "lines 8 and 9", "non-manifold"],
    );
    // The same with triangles (the subdivided path).
    let t = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n";
    let msg = mesh_error(load_str(t));
    assert_mentions(&msg, &["vertex 1", "lines 6 and 7"]);
}

#[test]
fn obj_face_repeating_a_vertex() {
    let g = obj_grid(2, 2);
    for bad in ["f 2 3 3 6", "f 2 3 6 2", "f 2 3 6 5 2 1"] {
        let msg = mesh_error(load_str(&with_line(&g, 12, bad)));
        assert_mentions(&msg, &["line 12", "twice"]);
    }
}

#[test]
fn obj_unused_vertices_are_dropped() {
    // Two vertices no face uses, in the middle of the list: the surface is the same.
    let g = obj_grid(2, 2);
    let mut lines: Vec<String> = g.lines().map(str::to_string).collect();
    lines.insert(5, "v 500 500 500".into());
    lines.insert(6, "v -500 0 0".into());
    // Faces refer to the old numbers: renumber indices ≥ 5 (the gap sits after vertex 4).
    for l in lines.iter_mut().filter(|l| l.starts_with("f ")) {
        let ids: Vec<String> = l[2..]
            .split_whitespace()
            .map(|w| {
                let i: usize = w.parse().unwrap();
                (if i >= 5 { i + 2 } else { i }).to_string()
            })
            .collect();
        *l = format!("f {}", ids.join(" "));
    }
    let gapped = lines.join("\n");
    let a = load_str(&gapped).unwrap();
    let b = load_str(&g).unwrap();
    assert_eq!(a.mesh.vertex_count(), b.mesh.vertex_count());
    for f in 0..b.surface.faces().len() {
        assert_eq!(a.surface.subs(f, 0.2, 0.9), b.surface.subs(f, 0.2, 0.9));
    }
}

// ---------------------------------------------------------------------------------------
// Fuzz: mutated valid files load or fail with a typed error, never panic; what loads
// evaluates to finite numbers.

const DEFAULT_FUZZ_CASES: u32 = 400;

fn fuzz_cases() -> u32 {
    ["TSPATH_FUZZ_CASES", "PROPTEST_CASES"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse().ok())
        .unwrap_or(DEFAULT_FUZZ_CASES)
}

#[derive(Debug, Clone)]
enum Mutation {
    /// XOR a byte with a mask.
    Flip(usize, u8),
    /// Delete up to `n` bytes.
    Delete(usize, usize),
    /// Insert digits or punctuation.
    Insert(usize, String),
    /// Copy line `a` to before line `b`.
    DuplicateLine(usize, usize),
    /// Keep only a prefix.
    Truncate(usize),
}

fn snippet() -> impl Strategy<Value = String> {
    prop_oneof![
        "[0-9]{1,3}",
        "[-+.,eE0-9]{1,3}",
        "[\\[\\]{}:,\" /#\n-]{1,2}",
        prop::sample::select(vec![
            "1e999", "nan", "-1", "0", "1e300", "1e-300", "inf", "null", "\"\"", "f 1 2", "v 0",
            "\u{e9}", "\u{0}",
        ])
        .prop_map(str::to_string),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(i, m)| Mutation::Flip(i, m)),
        (any::<usize>(), 1usize..12).prop_map(|(i, n)| Mutation::Delete(i, n)),
        (any::<usize>(), snippet()).prop_map(|(i, s)| Mutation::Insert(i, s)),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::DuplicateLine(a, b)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn mutate(base: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut b = base.to_vec();
    for m in muts {
        let n = b.len().max(1);
        match m {
            Mutation::Flip(i, mask) if !b.is_empty() => b[i % n] ^= mask,
            Mutation::Delete(i, k) if !b.is_empty() => {
                let at = i % n;
                let end = (at + k).min(b.len());
                b.drain(at..end);
            }
            Mutation::Insert(i, s) => {
                let at = i % (b.len() + 1);
                b.splice(at..at, s.bytes());
            }
            Mutation::DuplicateLine(i, j) => {
                let mut lines: Vec<Vec<u8>> =
                    b.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
                let l = lines[i % lines.len()].clone();
                let at = j % lines.len();
                lines.insert(at, l);
                b = lines.join(&b'\n');
            }
            Mutation::Truncate(i) => b.truncate(i % (b.len() + 1)),
            _ => {}
        }
    }
    b
}

/// Checks one mutated file: a typed error with something to say, or a finite model.
fn check_loaded(bytes: &[u8]) -> Result<(), TestCaseError> {
    match load(bytes) {
        Ok(m) => {
            assert_finite(&m).map_err(TestCaseError::fail)?;
            let s = m.summary();
            prop_assert!(s.faces > 0 && s.patches > 0);
        }
        Err(Error::Parse {
            location, message, ..
        }) => prop_assert!(!location.is_empty() && !message.is_empty()),
        Err(Error::InvalidMesh(m)) | Err(Error::Unsupported(m)) => prop_assert!(!m.is_empty()),
        Err(e) => prop_assert!(false, "unexpected error kind {:?}", e),
    }
    Ok(())
}

fn json_bases() -> Vec<Vec<u8>> {
    ["dome", "tjunction"]
        .iter()
        .map(|n| sample_json(n).unwrap().into_bytes())
        .collect()
}

fn obj_bases() -> Vec<Vec<u8>> {
    [obj_grid(3, 2), OBJ_CUBE.to_string(), OBJ_MIXED.to_string()]
        .into_iter()
        .map(String::into_bytes)
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: fuzz_cases(),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn fuzz_mutated_json_never_panics(
        which in 0usize..2,
        muts in prop::collection::vec(mutation(), 1..5),
    ) {
        let bases = json_bases();
        check_loaded(&mutate(&bases[which], &muts))?;
    }

    #[test]
    fn fuzz_mutated_obj_never_panics(
        which in 0usize..3,
        muts in prop::collection::vec(mutation(), 1..5),
    ) {
        let bases = obj_bases();
        check_loaded(&mutate(&bases[which], &muts))?;
    }
}

// ---------------------------------------------------------------------------------------
// Model building: meshes that are valid T-meshes but carry no evaluable surface

/// A 3 × 3 grid of quads (4 × 4 points), with the given extra members.
fn json_grid(extra: &[(&str, Value)]) -> String {
    let pts: Vec<Value> = (0..16)
        .map(|k| {
            json!([
                (k % 4) as f64 * 10.0,
                (k / 4) as f64 * 10.0,
                ((k * 5) % 3) as f64
            ])
        })
        .collect();
    let mut faces = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            let v = j * 4 + i;
            faces.push(json!([v, v + 1, v + 5, v + 4]));
        }
    }
    json_mesh(Value::Array(pts), Value::Array(faces), extra)
}

#[test]
fn building_a_grid_under_both_schemes() {
    for scheme in ["t-spline", "catmull-clark"] {
        let m = load_str(&json_grid(&[("scheme", json!(scheme))])).unwrap();
        assert_finite(&m).unwrap();
    }
}

#[test]
fn building_with_every_knot_interval_zero() {
    let msg = mesh_error(load_str(&json_grid(&[("default_knot", json!(0.0))])));
    assert_mentions(&msg, &["positive parametric area"]);
}

#[test]
fn building_a_catmull_clark_cage_with_non_uniform_knots() {
    // Knot intervals 2 on a whole column of edges keep every face consistent.
    let knots: Vec<Value> = (0..4).map(|j| json!([j * 4, j * 4 + 1, 2.0])).collect();
    let t = json_grid(&[("scheme", json!("catmull-clark")), ("knots", json!(knots))]);
    match load_str(&t) {
        Err(Error::Unsupported(m)) => assert_mentions(&m, &["face 0", "uniform"]),
        other => panic!("{other:?}"),
    }
    // The same as a T-spline evaluates.
    let t = json_grid(&[("knots", json!(knots))]);
    assert_finite(&load_str(&t).unwrap()).unwrap();
}
