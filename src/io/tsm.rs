//! Reader of Autodesk T-Splines `.tsm` files (`#TS0200`, written by T-Splines for Rhino and
//! Fusion exports) into the project's T-mesh.
//!
//! Owns: parsing the records, checking their cross references (every error names the line),
//! and rebuilding the T-mesh they describe, grip blocks included. Must not: evaluate the
//! surface (`surface`) or change how the T-mesh is walked (`tmesh`).
//!
//! # What the file says
//! Lines hold one record each; `#` starts a comment (in any byte encoding). Records of one
//! kind are numbered by order of appearance, and a record without operands is a deleted slot
//! that keeps its number.
//! - Header: `degree 3`, `units <metres per unit> <name>`, `force-bezier-end-conditions`
//!   (T-Splines for Rhino) or `end-conditions` (Fusion: `SUBD_CREASES`), `star-smoothness`,
//!   `cap-type`; trailer `tol`, `ver` (Fusion adds `geom-tol`, `behavior-version`, ...).
//! - `f link flag`: a face and one of its links. `e link interval`: an edge and its knot
//!   interval. `v link DIR`: a vertex, one of its links, and the compass direction (`NORTH`,
//!   `WEST`, `SOUTH`, `EAST`) that link has in the vertex's own frame.
//! - `l prev next opp vertex face edge flag`: a link (half-edge) starting at `vertex`, in
//!   `face` (-1: outside), with `flag + 1` the quarter turns its face occupies at `vertex`
//!   (0: a corner, 1: a T-junction on a side; outside links up to 2). Face loops follow `next`
//!   counter-clockwise; the next link counter-clockwise around a vertex is `opp(prev)`.
//! - `0g x y z w`: a control point ("grip") with weight `w` (not premultiplied).
//! - `0m gv V` / `0m gvp V`: the k-th of these says which vertex the k-th grip belongs to,
//!   `gvp` marking the vertex's main grip; -1: none.
//! - `0m cg V 4 dN dW dS dE g...`: vertex `V` carries a block of `(1+dN+dS) x (1+dW+dE)`
//!   grips at its own parameters: the main grip in the middle, and for each direction k of
//!   N, W, S, E (counter-clockwise) a wedge listing the grips `a` steps along k and `b` steps
//!   along the next direction, `a` in 1..=d_k then `b` in 0..=d_(k+1); -1 is a hole (the
//!   outside quadrant of a concave corner). Blocks encode Bézier end conditions and creases.
//!   A `cg` record of valence n other than 4 with all extents 0 (a star point without extra
//!   grips; no public file has one to confirm the form) is read as a plain vertex.
//! - `ec edge c`: an edge condition, `c` = 0 on boundary edges (kept in
//!   [`TsmMeta::edge_conditions`]; creases themselves come from grip blocks).
//! - `100001uv s t`: parameters of each vertex slot (kept for checking, see
//!   [`TsmMeta::uv_records`]). Everything else (`100001uvr`, `50000grip`, `105…`,
//!   `odd-grip-map`, unknown records) is application data and skipped.
//!
//! # The T-mesh built from it
//! Every grip becomes a T-mesh vertex. A vertex's block is a little grid joined by
//! zero-interval edges, with 0 × 0 faces for its cells inside the mesh. Each file face keeps
//! its loop, taking at each vertex the block's outer corner in the face's quadrant (at a
//! corner) or the block's outer row (at a T-junction). Each file edge becomes a strip of
//! zero width between the faces on its two sides, split by one knot line per row of the two
//! blocks at its ends; where the two ends have different numbers of rows, the extra lines fan
//! into the outermost common one (zero-area faces with an empty side); they are fan lines of
//! the T-mesh, which a crossing ray does not see, since the repeated knot they carry belongs to
//! the block only. Walking this mesh gives each grip the repeated knots its block stands for
//! (the same knot vectors as GrapeTec/T-SPLINE's reader, `tests/tsm.rs`).

use crate::error::{Error, Result};
use crate::geom::Point3;
use crate::tmesh::walk::rot;
use crate::tmesh::{ControlPoint, FaceLoop, Scheme, TMesh, KNOT_MATCH_REL};
use std::collections::{HashMap, VecDeque};

const FORMAT: &str = "tsm";

/// Largest block extent accepted in one direction of a `cg` record (files use 0 or 1).
const MAX_BLOCK_EXTENT: i64 = 64;

/// Largest valence of a star point's `cg` record accepted.
const MAX_STAR_VALENCE: i64 = 64;

/// Millimetres per metre (the `units` record gives metres per file unit).
const MM_PER_M: f64 = 1000.0;

/// Largest knot interval accepted (parameter units; modellers write intervals near 1).
/// Beyond it sums of intervals lose all precision.
const MAX_KNOT_INTERVAL: f64 = 1e9;

/// Largest coordinate accepted once in millimetres (1000 km): beyond it the rational sums of
/// evaluation overflow long before anything could be machined.
const MAX_COORDINATE_MM: f64 = 1e9;

/// Largest weight ratio accepted for a grip (weight and its inverse below this).
const MAX_WEIGHT: f64 = 1e9;

/// Accepted range of the `units` scale (metres per file unit): nanometres to kilometres.
const METRES_PER_UNIT_RANGE: (f64, f64) = (1e-9, 1e3);

/// Compass names in counter-clockwise order: index = quarter turns counter-clockwise from
/// north.
const COMPASS: [&str; 4] = ["NORTH", "WEST", "SOUTH", "EAST"];

/// What a `.tsm` file holds besides the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct TsmMeta {
    /// Format tag after `#`, e.g. `TS0200`.
    pub format_version: String,
    /// Unit name as written (`millimeters`), or `millimeters (not stated)` without a record.
    pub units: String,
    /// Metres per file unit as written (0.001 for millimetres).
    pub metres_per_unit: f64,
    /// `force-bezier-end-conditions` (boundaries interpolate their control polygon).
    pub force_bezier_end_conditions: bool,
    /// `end-conditions` as written (Fusion exports: `SUBD_CREASES`), if present.
    pub end_conditions: Option<String>,
    /// `star-smoothness` and `cap-type` as written (they matter only at extraordinary points;
    /// T-Splines for Rhino writes `cap-type 1`, Fusion `cap-type G1CAPS`).
    pub star_smoothness: i64,
    pub cap_type: String,
    /// For each `v` slot, the T-mesh vertex of its main grip (`None`: a deleted slot).
    pub vertex_of_slot: Vec<Option<u32>>,
    /// For each `v` slot, the file's `100001uv` parameters (`None`: absent or empty).
    pub uv_records: Vec<Option<[f64; 2]>>,
    /// For each T-mesh vertex, the `0g` record (grip number) it comes from.
    pub grip_of_vertex: Vec<u32>,
    /// The `ec` records: file edge and its condition (0: boundary).
    pub edge_conditions: Vec<(u32, i64)>,
    /// Records skipped as application data or unknown.
    pub skipped_records: usize,
}

impl TsmMeta {
    /// The unit as shown to a person, e.g. `millimeters (0.001 m)`.
    pub fn units_label(&self) -> String {
        format!("{} ({} m)", self.units, self.metres_per_unit)
    }
}

// ---------------------------------------------------------------------------------------
// Parsing: records with their line numbers.

/// One record slot: the line it came from and its operands (`None`: a deleted slot).
#[derive(Debug, Clone)]
struct Slot<T> {
    line: usize,
    rec: Option<T>,
}

#[derive(Debug, Clone, Copy)]
struct RawLink {
    prev: usize,
    next: usize,
    opp: usize,
    vertex: usize,
    face: Option<usize>,
    edge: usize,
    flag: u32,
}

#[derive(Debug, Clone, Copy)]
struct RawGrip {
    xyz: [f64; 3],
    w: f64,
}

#[derive(Debug, Clone, Copy)]
struct GripOwner {
    line: usize,
    vertex: Option<usize>,
    main: bool,
}

#[derive(Debug, Clone)]
struct RawBlock {
    line: usize,
    vertex: usize,
    /// Extents N, W, S, E.
    dims: [i32; 4],
    grips: Vec<Option<usize>>,
}

#[derive(Debug, Default)]
struct Parsed {
    format_version: String,
    units: Option<(f64, String)>,
    force_bezier: bool,
    end_conditions: Option<String>,
    star_smoothness: i64,
    cap_type: String,
    faces: Vec<Slot<usize>>,
    edges: Vec<Slot<(usize, f64)>>,
    vertices: Vec<Slot<(usize, usize)>>,
    links: Vec<Slot<RawLink>>,
    grips: Vec<Slot<RawGrip>>,
    owners: Vec<GripOwner>,
    blocks: Vec<RawBlock>,
    uv: Vec<Option<[f64; 2]>>,
    edge_conditions: Vec<(u32, i64)>,
    skipped: usize,
    /// Index operands as read, checked once every record is known.
    pending: Vec<Pending>,
}

/// An index operand checked once the number of records of its kind is known.
#[derive(Debug, Clone, Copy)]
struct Pending {
    line: usize,
    what: &'static str,
    value: i64,
    kind: Kind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Face,
    Edge,
    Vertex,
    Link,
    Grip,
}

impl Kind {
    fn record(self) -> &'static str {
        match self {
            Kind::Face => "f",
            Kind::Edge => "e",
            Kind::Vertex => "v",
            Kind::Link => "l",
            Kind::Grip => "0g",
        }
    }
}

fn at(line: usize) -> String {
    format!("line {line}")
}

fn perr(line: usize, msg: impl Into<String>) -> Error {
    Error::parse(FORMAT, at(line), msg)
}

struct Fields<'a> {
    line: usize,
    key: &'a str,
    args: &'a [&'a str],
}

impl Fields<'_> {
    fn count(&self, n: usize, what: &str) -> Result<()> {
        if self.args.len() == n {
            Ok(())
        } else {
            Err(perr(
                self.line,
                format!(
                    "`{}` record needs {n} operands ({what}), found {}",
                    self.key,
                    self.args.len()
                ),
            ))
        }
    }

    fn int(&self, i: usize, what: &str) -> Result<i64> {
        let s = self.args[i];
        s.parse::<i64>().map_err(|_| {
            perr(
                self.line,
                format!(
                    "`{}` record: {what} must be an integer, found `{s}`",
                    self.key
                ),
            )
        })
    }

    fn num(&self, i: usize, what: &str) -> Result<f64> {
        let s = self.args[i];
        match s.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(perr(
                self.line,
                format!(
                    "`{}` record: {what} must be a finite number, found `{s}`",
                    self.key
                ),
            )),
        }
    }
}

/// Numbered (from 1) lines with comments and surrounding blanks removed, blank ones left out.
type Lines<'a> = Vec<(usize, &'a [u8])>;

/// Splits the bytes into numbered lines without comments; the first non-blank line must be
/// the `#TS…` tag, returned separately.
fn split_lines(bytes: &[u8]) -> Result<(String, Lines<'_>)> {
    let mut tag = None;
    let mut out = Vec::new();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        let body = match raw.iter().position(|&b| b == b'#') {
            Some(p) if tag.is_none() && raw[..p].iter().all(u8::is_ascii_whitespace) => {
                let rest = &raw[p + 1..];
                if !rest.starts_with(b"TS") {
                    return Err(perr(
                        line,
                        "a .tsm file starts with a `#TS0200` tag; this line is another comment",
                    ));
                }
                let v: String = rest
                    .iter()
                    .take_while(|b| b.is_ascii_alphanumeric())
                    .map(|&b| b as char)
                    .collect();
                tag = Some(v);
                continue;
            }
            Some(p) => &raw[..p],
            None => raw,
        };
        let body = body.trim_ascii();
        if body.is_empty() {
            continue;
        }
        if tag.is_none() {
            return Err(perr(line, "a .tsm file starts with a `#TS0200` tag"));
        }
        out.push((line, body));
    }
    match tag {
        Some(t) => Ok((t, out)),
        None => Err(Error::parse(
            FORMAT,
            "start of file",
            "the file is empty (no `#TS0200` tag)",
        )),
    }
}

fn parse(bytes: &[u8]) -> Result<Parsed> {
    let (tag, lines) = split_lines(bytes)?;
    let mut p = Parsed {
        format_version: tag,
        star_smoothness: 0,
        ..Parsed::default()
    };
    let mut degree = None;
    for (line, body) in lines {
        let text = std::str::from_utf8(body).map_err(|e| {
            perr(
                line,
                format!(
                    "byte {} is not text; only `#` comments may hold other encodings",
                    e.valid_up_to() + 1
                ),
            )
        })?;
        let tokens: Vec<&str> = text.split_ascii_whitespace().collect();
        let f = Fields {
            line,
            key: tokens[0],
            args: &tokens[1..],
        };
        let empty = f.args.is_empty();
        match f.key {
            "degree" => {
                f.count(1, "the degree")?;
                degree = Some((line, f.int(0, "the degree")?));
            }
            "units" => {
                if f.args.is_empty() {
                    return Err(perr(
                        line,
                        "`units` record needs metres per unit and a unit name",
                    ));
                }
                let m = f.num(0, "metres per unit")?;
                let (lo, hi) = METRES_PER_UNIT_RANGE;
                if !(lo..=hi).contains(&m) {
                    return Err(perr(
                        line,
                        format!("`units`: metres per unit must be positive, between {lo} and {hi}; found {m}"),
                    ));
                }
                p.units = Some((m, f.args[1..].join(" ")));
            }
            "force-bezier-end-conditions" => {
                f.count(1, "0 or 1")?;
                p.force_bezier = f.int(0, "the flag")? != 0;
            }
            "star-smoothness" => {
                f.count(1, "an integer")?;
                p.star_smoothness = f.int(0, "the smoothness")?;
            }
            "cap-type" => {
                f.count(1, "a cap type")?;
                p.cap_type = f.args[0].to_string();
            }
            "end-conditions" => {
                f.count(1, "an end-condition name")?;
                p.end_conditions = Some(f.args[0].to_string());
            }
            "f" => {
                let rec = if empty {
                    None
                } else {
                    f.count(2, "link and flag")?;
                    let link = f.int(0, "the link")?;
                    f.int(1, "the flag")?;
                    p.pend(line, "its link", link, Kind::Link);
                    Some(link as usize)
                };
                p.faces.push(Slot { line, rec });
            }
            "e" => {
                let rec = if empty {
                    None
                } else {
                    f.count(2, "link and knot interval")?;
                    let link = f.int(0, "the link")?;
                    let k = f.num(1, "the knot interval")?;
                    if k < 0.0 {
                        return Err(perr(
                            line,
                            format!("`e` record: knot interval {k} is negative"),
                        ));
                    }
                    if k > MAX_KNOT_INTERVAL {
                        return Err(perr(
                            line,
                            format!("`e` record: knot interval {k} is above {MAX_KNOT_INTERVAL}"),
                        ));
                    }
                    p.pend(line, "its link", link, Kind::Link);
                    Some((link as usize, k))
                };
                p.edges.push(Slot { line, rec });
            }
            "v" => {
                let rec = if empty {
                    None
                } else {
                    f.count(2, "link and direction")?;
                    let link = f.int(0, "the link")?;
                    let dir = COMPASS.iter().position(|&c| c == f.args[1]).ok_or_else(|| {
                        perr(
                            line,
                            format!(
                                "`v` record: direction must be NORTH, WEST, SOUTH or EAST, found `{}`",
                                f.args[1]
                            ),
                        )
                    })?;
                    p.pend(line, "its link", link, Kind::Link);
                    Some((link as usize, dir))
                };
                p.vertices.push(Slot { line, rec });
            }
            "l" => {
                let rec = if empty {
                    None
                } else {
                    f.count(7, "prev next opp vertex face edge flag")?;
                    let mut v = [0i64; 7];
                    let names = ["prev", "next", "opp", "vertex", "face", "edge", "flag"];
                    for (i, name) in names.iter().enumerate() {
                        v[i] = f.int(i, name)?;
                    }
                    p.pend(line, "prev", v[0], Kind::Link);
                    p.pend(line, "next", v[1], Kind::Link);
                    p.pend(line, "opp", v[2], Kind::Link);
                    p.pend(line, "vertex", v[3], Kind::Vertex);
                    if v[4] != -1 {
                        p.pend(line, "face", v[4], Kind::Face);
                    }
                    p.pend(line, "edge", v[5], Kind::Edge);
                    if !(0..=2).contains(&v[6]) {
                        return Err(perr(
                            line,
                            format!("`l` record: flag must be 0, 1 or 2, found {}", v[6]),
                        ));
                    }
                    Some(RawLink {
                        prev: v[0] as usize,
                        next: v[1] as usize,
                        opp: v[2] as usize,
                        vertex: v[3] as usize,
                        face: (v[4] != -1).then_some(v[4] as usize),
                        edge: v[5] as usize,
                        flag: v[6] as u32,
                    })
                };
                p.links.push(Slot { line, rec });
            }
            "0g" => {
                let rec = if empty {
                    None
                } else {
                    f.count(4, "x y z w")?;
                    let xyz = [f.num(0, "x")?, f.num(1, "y")?, f.num(2, "z")?];
                    let w = f.num(3, "the weight")?;
                    if !(w > 0.0) {
                        return Err(perr(
                            line,
                            format!("`0g` record: weight must be positive, found {w}"),
                        ));
                    }
                    if !(1.0 / MAX_WEIGHT..=MAX_WEIGHT).contains(&w) {
                        return Err(perr(
                            line,
                            format!(
                                "`0g` record: weight {w} is outside {} to {MAX_WEIGHT}",
                                1.0 / MAX_WEIGHT
                            ),
                        ));
                    }
                    Some(RawGrip { xyz, w })
                };
                p.grips.push(Slot { line, rec });
            }
            "ec" => {
                if !empty {
                    f.count(2, "edge and condition")?;
                    let e = f.int(0, "the edge")?;
                    let c = f.int(1, "the condition")?;
                    p.pend(line, "its edge", e, Kind::Edge);
                    p.edge_conditions.push((e.max(0) as u32, c));
                }
            }
            "100001uv" => {
                let rec = if empty {
                    None
                } else {
                    f.count(2, "s t")?;
                    Some([f.num(0, "s")?, f.num(1, "t")?])
                };
                p.uv.push(rec);
            }
            "0m" => p.meta_record(&f)?,
            "tol" | "ver" => {
                f.count(1, "a number")?;
                f.num(0, "the value")?;
            }
            _ => p.skipped += 1,
        }
    }
    match degree {
        Some((_, 3)) => {}
        Some((line, d)) => {
            return Err(Error::Unsupported(format!(
                "tsm line {line}: degree {d}; only cubic (degree 3) T-splines are read"
            )))
        }
        None => {
            return Err(Error::parse(
                FORMAT,
                "header",
                "no `degree` record (expected `degree 3`)",
            ))
        }
    }
    Ok(p)
}

impl Parsed {
    fn pend(&mut self, line: usize, what: &'static str, value: i64, kind: Kind) {
        self.pending.push(Pending {
            line,
            what,
            value,
            kind,
        });
    }

    fn meta_record(&mut self, f: &Fields) -> Result<()> {
        let Some(&sub) = f.args.first() else {
            self.skipped += 1;
            return Ok(());
        };
        let line = f.line;
        match sub {
            "gv" | "gvp" => {
                f.count(2, "`gv` and a vertex")?;
                let v = f.int(1, "the vertex")?;
                if v < -1 {
                    return Err(perr(
                        line,
                        format!("`0m {sub}`: vertex must be -1 or an index, found {v}"),
                    ));
                }
                if v >= 0 {
                    self.pend(line, "its vertex", v, Kind::Vertex);
                }
                self.owners.push(GripOwner {
                    line,
                    vertex: (v >= 0).then_some(v as usize),
                    main: sub == "gvp",
                });
            }
            "cg" => {
                if f.args.len() < 3 {
                    return Err(perr(
                        line,
                        "`0m cg` record needs a vertex, a valence, extents and grips",
                    ));
                }
                let vertex = f.int(1, "the vertex")?;
                let valence = f.int(2, "the valence")?;
                if valence != 4 {
                    // A star point without extra grips is a plain vertex.
                    let extents = &f.args[3..];
                    if (3..=MAX_STAR_VALENCE).contains(&valence)
                        && extents.len() == valence as usize
                        && extents.iter().all(|x| *x == "0")
                    {
                        self.pend(line, "its vertex", vertex, Kind::Vertex);
                        return Ok(());
                    }
                    return Err(Error::Unsupported(format!(
                        "tsm line {line}: a grip block of valence {valence} with extra grips (Bézier end conditions or creases at a star point); only star points without extra grips are read"
                    )));
                }
                if f.args.len() < 7 {
                    return Err(perr(line, "`0m cg` record needs four extents N W S E"));
                }
                let mut dims = [0i32; 4];
                for (k, d) in dims.iter_mut().enumerate() {
                    let x = f.int(3 + k, "a block extent")?;
                    if !(0..=MAX_BLOCK_EXTENT).contains(&x) {
                        return Err(perr(
                            line,
                            format!(
                                "`0m cg`: block extent {x} is out of range 0..={MAX_BLOCK_EXTENT}"
                            ),
                        ));
                    }
                    *d = x as i32;
                }
                let size = ((1 + dims[0] + dims[2]) * (1 + dims[1] + dims[3]) - 1) as usize;
                if f.args.len() != 7 + size {
                    return Err(perr(
                        line,
                        format!(
                            "`0m cg`: a block of extents {dims:?} lists {size} grips, found {}",
                            f.args.len() - 7
                        ),
                    ));
                }
                let mut grips = Vec::with_capacity(size);
                for i in 0..size {
                    let g = f.int(7 + i, "a grip")?;
                    if g < -1 {
                        return Err(perr(
                            line,
                            format!("`0m cg`: grip must be -1 or an index, found {g}"),
                        ));
                    }
                    if g >= 0 {
                        self.pend(line, "a grip", g, Kind::Grip);
                    }
                    grips.push((g >= 0).then_some(g as usize));
                }
                self.pend(line, "its vertex", vertex, Kind::Vertex);
                self.blocks.push(RawBlock {
                    line,
                    vertex: vertex.max(0) as usize,
                    dims,
                    grips,
                });
            }
            _ => self.skipped += 1,
        }
        Ok(())
    }

    /// Checks every index operand against the records present.
    fn check_indices(&self) -> Result<()> {
        for q in &self.pending {
            let (live, n) = match q.kind {
                Kind::Face => (q.value >= 0 && self.live_face(q.value), self.faces.len()),
                Kind::Edge => (q.value >= 0 && self.live_edge(q.value), self.edges.len()),
                Kind::Vertex => (
                    q.value >= 0 && self.live_vertex(q.value),
                    self.vertices.len(),
                ),
                Kind::Link => (q.value >= 0 && self.live_link(q.value), self.links.len()),
                Kind::Grip => (q.value >= 0 && self.live_grip(q.value), self.grips.len()),
            };
            if !live {
                let why = if q.value < 0 || q.value as usize >= n {
                    format!("there are {n} `{}` records", q.kind.record())
                } else {
                    format!("`{}` record {} is deleted", q.kind.record(), q.value)
                };
                return Err(perr(
                    q.line,
                    format!("{} {} refers to nothing: {why}", q.what, q.value),
                ));
            }
        }
        Ok(())
    }

    fn live_face(&self, i: i64) -> bool {
        self.faces.get(i as usize).is_some_and(|s| s.rec.is_some())
    }
    fn live_edge(&self, i: i64) -> bool {
        self.edges.get(i as usize).is_some_and(|s| s.rec.is_some())
    }
    fn live_vertex(&self, i: i64) -> bool {
        self.vertices
            .get(i as usize)
            .is_some_and(|s| s.rec.is_some())
    }
    fn live_link(&self, i: i64) -> bool {
        self.links.get(i as usize).is_some_and(|s| s.rec.is_some())
    }
    fn live_grip(&self, i: i64) -> bool {
        self.grips.get(i as usize).is_some_and(|s| s.rec.is_some())
    }

    /// A live link (indices were checked).
    fn link(&self, l: usize) -> RawLink {
        self.links[l]
            .rec
            .expect("link indices are checked before use")
    }
}

// ---------------------------------------------------------------------------------------
// Topology: links, loops and the compass frame of every vertex.

struct Topology {
    /// Compass direction of each link in its start vertex's frame (0 for irregular vertices).
    dir: Vec<usize>,
    /// Per vertex slot: the four quadrants (N→W, W→S, S→E, E→N) inside the mesh, or `None`
    /// where the faces around it do not add up to a full turn.
    quadrants: Vec<Option<[bool; 4]>>,
    /// Per face slot: its links, starting at a corner.
    loops: Vec<Vec<usize>>,
}

fn check_topology(p: &Parsed) -> Result<Topology> {
    let nl = p.links.len();
    for (l, slot) in p.links.iter().enumerate() {
        let Some(k) = slot.rec else { continue };
        let line = slot.line;
        let bad = |msg: String| Err(perr(line, msg));
        if k.opp == l {
            return bad(format!("link {l} is its own opposite"));
        }
        if p.link(k.opp).opp != l {
            return bad(format!(
                "link {l} names {} as opposite, but {} names {}",
                k.opp,
                k.opp,
                p.link(k.opp).opp
            ));
        }
        if p.link(k.next).prev != l || p.link(k.prev).next != l {
            return bad(format!(
                "link {l}: its next ({}) and previous ({}) links do not point back to it",
                k.next, k.prev
            ));
        }
        if p.link(k.opp).edge != k.edge {
            return bad(format!(
                "link {l} is on edge {} but its opposite {} is on edge {}",
                k.edge,
                k.opp,
                p.link(k.opp).edge
            ));
        }
        if p.link(k.next).face != k.face {
            return bad(format!(
                "link {l} and its next link {} are in different faces",
                k.next
            ));
        }
        let end = p.link(k.opp).vertex;
        if p.link(k.next).vertex != end {
            return bad(format!(
                "link {l} ends at vertex {end} (where its opposite starts) but its next link starts at vertex {}",
                p.link(k.next).vertex
            ));
        }
        if end == k.vertex {
            return bad(format!("link {l} starts and ends at vertex {end}"));
        }
        if k.face.is_some() && k.flag > 1 {
            return bad(format!(
                "link {l}: a face link's flag must be 0 (corner) or 1 (T-junction), found {}",
                k.flag
            ));
        }
        if k.face.is_none() && p.link(k.opp).face.is_none() {
            return bad(format!(
                "link {l}: edge {} has no face on either side",
                k.edge
            ));
        }
    }
    for (e, slot) in p.edges.iter().enumerate() {
        let Some((l, _)) = slot.rec else { continue };
        if p.link(l).edge != e {
            return Err(perr(
                slot.line,
                format!(
                    "edge {e} names link {l}, which lies on edge {}",
                    p.link(l).edge
                ),
            ));
        }
    }
    // Every link's edge must be the edge of it or its opposite, once.
    let mut edge_links = vec![0usize; p.edges.len()];
    for slot in &p.links {
        if let Some(k) = slot.rec {
            edge_links[k.edge] += 1;
            if edge_links[k.edge] > 2 {
                return Err(perr(
                    slot.line,
                    format!("edge {} is used by more than two links", k.edge),
                ));
            }
        }
    }
    // Vertex rings: directions counter-clockwise from the `v` record's link.
    let mut dir = vec![0usize; nl];
    let mut seen = vec![false; nl];
    let mut quadrants = vec![None; p.vertices.len()];
    let mut ring_len = vec![0usize; p.vertices.len()];
    for slot in &p.links {
        if let Some(k) = slot.rec {
            ring_len[k.vertex] += 1;
        }
    }
    for (v, slot) in p.vertices.iter().enumerate() {
        let Some((start, compass)) = slot.rec else {
            continue;
        };
        if p.link(start).vertex != v {
            return Err(perr(
                slot.line,
                format!(
                    "vertex {v} names link {start}, which starts at vertex {}",
                    p.link(start).vertex
                ),
            ));
        }
        let mut ring = Vec::new();
        let mut l = start;
        loop {
            ring.push(l);
            l = p.link(p.link(l).prev).opp;
            if l == start {
                break;
            }
            if ring.len() > ring_len[v] {
                return Err(perr(
                    slot.line,
                    format!("the links around vertex {v} do not close into one ring"),
                ));
            }
        }
        if ring.len() != ring_len[v] {
            return Err(perr(
                slot.line,
                format!(
                    "vertex {v} has {} links but only {} are in the ring around it (non-manifold vertex)",
                    ring_len[v],
                    ring.len()
                ),
            ));
        }
        let total: u32 = ring.iter().map(|&l| p.link(l).flag + 1).sum();
        let mut q = compass;
        let mut inside = [false; 4];
        for &l in &ring {
            seen[l] = true;
            let k = p.link(l);
            dir[l] = q % 4;
            for i in 0..=k.flag as usize {
                inside[(q + i) % 4] = k.face.is_some();
            }
            q += k.flag as usize + 1;
        }
        quadrants[v] = (total == 4).then_some(inside);
    }
    if let Some(l) = (0..nl).find(|&l| p.links[l].rec.is_some() && !seen[l]) {
        return Err(perr(
            p.links[l].line,
            format!(
                "link {l} starts at vertex {}, whose record is missing",
                p.link(l).vertex
            ),
        ));
    }
    // Face loops, each starting at a corner.
    let mut in_face = vec![0usize; p.faces.len()];
    for slot in &p.links {
        if let Some(f) = slot.rec.and_then(|k| k.face) {
            in_face[f] += 1;
        }
    }
    let mut loops = vec![Vec::new(); p.faces.len()];
    for (f, slot) in p.faces.iter().enumerate() {
        let Some(start) = slot.rec else { continue };
        if p.link(start).face != Some(f) {
            return Err(perr(
                slot.line,
                format!("face {f} names link {start}, which is not in face {f}"),
            ));
        }
        let mut lp = vec![start];
        let mut l = p.link(start).next;
        while l != start {
            if lp.len() >= in_face[f] {
                return Err(perr(
                    slot.line,
                    format!("the loop of face {f} does not close"),
                ));
            }
            lp.push(l);
            l = p.link(l).next;
        }
        if lp.len() != in_face[f] {
            return Err(perr(
                slot.line,
                format!(
                    "face {f} has {} links but its loop holds {}",
                    in_face[f],
                    lp.len()
                ),
            ));
        }
        let corners = lp.iter().filter(|&&l| p.link(l).flag == 0).count();
        if corners != 4 {
            return Err(perr(
                slot.line,
                format!("face {f} has {corners} corners (links with flag 0); a face has 4"),
            ));
        }
        let first = lp
            .iter()
            .position(|&l| p.link(l).flag == 0)
            .expect("four corners");
        lp.rotate_left(first);
        // Opposite sides must span the same parameter length.
        let mut sums = [0.0f64; 4];
        let mut side = 0;
        for (i, &l) in lp.iter().enumerate() {
            if i > 0 && p.link(l).flag == 0 {
                side += 1;
            }
            let e = p.link(l).edge;
            sums[side] += p.edges[e].rec.map_or(0.0, |r| r.1);
        }
        let tol = KNOT_MATCH_REL * sums.iter().cloned().fold(1.0, f64::max);
        if (sums[0] - sums[2]).abs() > tol || (sums[1] - sums[3]).abs() > tol {
            return Err(perr(
                slot.line,
                format!(
                    "face {f}: opposite sides have different knot interval sums ({} {} {} {})",
                    sums[0], sums[1], sums[2], sums[3]
                ),
            ));
        }
        loops[f] = lp;
    }
    Ok(Topology {
        dir,
        quadrants,
        loops,
    })
}

// ---------------------------------------------------------------------------------------
// Grip blocks.

/// Unit step of compass direction `k` in a vertex's frame (x east, y north).
fn unit(k: usize) -> (i32, i32) {
    match k % 4 {
        0 => (0, 1),
        1 => (-1, 0),
        2 => (0, -1),
        _ => (1, 0),
    }
}

/// `a` steps along direction `ka` and `b` along `kb`.
fn pos(a: i32, ka: usize, b: i32, kb: usize) -> (i32, i32) {
    let (ua, ub) = (unit(ka), unit(kb));
    (a * ua.0 + b * ub.0, a * ua.1 + b * ub.1)
}

/// The T-mesh vertices of one file vertex at block positions `(x, y)`.
#[derive(Debug, Clone)]
struct Block {
    /// Extents N, W, S, E.
    d: [i32; 4],
    ids: Vec<Option<u32>>,
}

impl Block {
    fn single(id: u32) -> Self {
        Block {
            d: [0; 4],
            ids: vec![Some(id)],
        }
    }

    fn width(&self) -> i32 {
        1 + self.d[1] + self.d[3]
    }

    fn at(&self, (x, y): (i32, i32)) -> Option<u32> {
        let [dn, dw, ds, de] = self.d;
        if x < -dw || x > de || y < -ds || y > dn {
            return None;
        }
        self.ids[((y + ds) * self.width() + (x + dw)) as usize]
    }

    /// Extent along direction `k`.
    fn ext(&self, k: usize) -> i32 {
        self.d[k % 4]
    }
}

/// Places every used grip: T-mesh vertex ids (in grip order), their points, and the block of
/// each vertex slot.
struct Placed {
    points: Vec<ControlPoint>,
    grip_of_vertex: Vec<u32>,
    blocks: Vec<Option<Block>>,
}

fn place_grips(p: &Parsed, topo: &Topology, mm_per_unit: f64) -> Result<Placed> {
    let ng = p.grips.len();
    // Without any `0m` grip records (Fusion exports), grip k is the main grip of vertex k.
    let implicit: Vec<GripOwner>;
    let owners = if p.owners.is_empty() && p.blocks.is_empty() && ng > 0 {
        if ng != p.vertices.len() {
            return Err(perr(
                p.grips[ng - 1].line,
                format!(
                    "the file has no `0m gv`/`0m gvp` records, so its grips are taken one per vertex in order, but there are {ng} `0g` grips and {} `v` records",
                    p.vertices.len()
                ),
            ));
        }
        implicit = p
            .grips
            .iter()
            .enumerate()
            .map(|(k, g)| GripOwner {
                line: g.line,
                vertex: g.rec.and(p.vertices[k].rec.map(|_| k)),
                main: true,
            })
            .collect();
        &implicit
    } else {
        &p.owners
    };
    if owners.len() != ng {
        let line = p
            .owners
            .last()
            .map(|o| o.line)
            .or(p.grips.last().map(|g| g.line))
            .unwrap_or(1);
        return Err(perr(
            line,
            format!(
                "there are {ng} `0g` grips but {} `0m gv`/`0m gvp` records; each grip needs one",
                owners.len()
            ),
        ));
    }
    // Main grip of each vertex.
    let mut main: Vec<Option<usize>> = vec![None; p.vertices.len()];
    for (g, o) in owners.iter().enumerate() {
        let Some(v) = o.vertex else { continue };
        if p.grips[g].rec.is_none() {
            return Err(perr(
                o.line,
                format!("grip {g} is deleted but assigned to vertex {v}"),
            ));
        }
        if o.main {
            if main[v].is_some() {
                return Err(perr(o.line, format!("vertex {v} has a second main grip")));
            }
            main[v] = Some(g);
        }
    }
    // Block position of each grip, per vertex.
    let mut placed_at: Vec<Option<(usize, (i32, i32))>> = vec![None; ng];
    for (v, slot) in p.vertices.iter().enumerate() {
        if slot.rec.is_none() {
            continue;
        }
        let g = main[v].ok_or_else(|| {
            perr(
                slot.line,
                format!("vertex {v} has no main grip (no `0m gvp {v}` record)"),
            )
        })?;
        placed_at[g] = Some((v, (0, 0)));
    }
    let mut block_of: Vec<Option<&RawBlock>> = vec![None; p.vertices.len()];
    for b in &p.blocks {
        let v = b.vertex;
        if block_of[v].is_some() {
            return Err(perr(b.line, format!("vertex {v} has a second grip block")));
        }
        if topo.quadrants[v].is_none() && b.dims != [0; 4] {
            return Err(Error::Unsupported(format!(
                "tsm line {}: vertex {v} is an extraordinary point (its faces do not make a full turn); grip blocks there are not read",
                b.line
            )));
        }
        block_of[v] = Some(b);
        let mut it = b.grips.iter();
        for k in 0..4 {
            for a in 1..=b.dims[k] {
                for c in 0..=b.dims[(k + 1) % 4] {
                    let Some(&Some(g)) = it.next() else { continue };
                    let o = &owners[g];
                    if o.vertex != Some(v) || o.main {
                        return Err(perr(
                            b.line,
                            format!(
                                "grip {g} is in the block of vertex {v}, but its `0m gv` record (line {}) gives it to {}",
                                o.line,
                                match (o.vertex, o.main) {
                                    (Some(w), true) => format!("vertex {w} as main grip"),
                                    (Some(w), false) => format!("vertex {w}"),
                                    (None, _) => "no vertex".to_string(),
                                }
                            ),
                        ));
                    }
                    if placed_at[g].is_some() {
                        return Err(perr(b.line, format!("grip {g} is placed twice")));
                    }
                    placed_at[g] = Some((v, pos(a, k, c, k + 1)));
                }
            }
        }
    }
    for (g, o) in owners.iter().enumerate() {
        if let (Some(v), None) = (o.vertex, placed_at[g]) {
            return Err(perr(
                o.line,
                format!(
                    "grip {g} belongs to vertex {v}, but no `0m cg` block of vertex {v} places it"
                ),
            ));
        }
    }
    // T-mesh vertices in grip order.
    let mut points = Vec::new();
    let mut grip_of_vertex = Vec::new();
    let mut blocks: Vec<Option<Block>> = vec![None; p.vertices.len()];
    for (v, b) in block_of.iter().enumerate() {
        if p.vertices[v].rec.is_none() {
            continue;
        }
        blocks[v] = Some(match b {
            Some(b) => Block {
                d: b.dims,
                ids: vec![
                    None;
                    ((1 + b.dims[0] + b.dims[2]) * (1 + b.dims[1] + b.dims[3])) as usize
                ],
            },
            None => Block::single(0),
        });
    }
    for (g, at) in placed_at.iter().enumerate() {
        let Some((v, xy)) = *at else { continue };
        let grip = p.grips[g].rec.expect("placed grips are live");
        if grip
            .xyz
            .iter()
            .any(|c| (c * mm_per_unit).abs() > MAX_COORDINATE_MM)
        {
            return Err(perr(
                p.grips[g].line,
                format!("grip {g}: a coordinate is beyond {MAX_COORDINATE_MM} mm"),
            ));
        }
        let id = points.len() as u32;
        points.push(ControlPoint {
            point: Point3::new(
                grip.xyz[0] * mm_per_unit,
                grip.xyz[1] * mm_per_unit,
                grip.xyz[2] * mm_per_unit,
            ),
            weight: grip.w,
        });
        grip_of_vertex.push(g as u32);
        let blk = blocks[v].as_mut().expect("live vertex");
        let (dw, ds, w) = (blk.d[1], blk.d[2], blk.width());
        blk.ids[((xy.1 + ds) * w + (xy.0 + dw)) as usize] = Some(id);
    }
    Ok(Placed {
        points,
        grip_of_vertex,
        blocks,
    })
}

// ---------------------------------------------------------------------------------------
// The T-mesh.

struct Builder<'a> {
    p: &'a Parsed,
    topo: &'a Topology,
    blocks: &'a [Option<Block>],
    faces: Vec<FaceLoop>,
    knots: HashMap<(u32, u32), f64>,
    /// Strip lines that fan into the far end (see [`crate::tmesh`]).
    fan_lines: Vec<(u32, u32)>,
}

impl Builder<'_> {
    fn block(&self, v: usize) -> &Block {
        self.blocks[v].as_ref().expect("live vertex")
    }

    fn knot(&mut self, a: u32, b: u32, k: f64, line: usize) -> Result<()> {
        let key = (a.min(b), a.max(b));
        match self.knots.insert(key, k) {
            Some(old) if old != k => Err(perr(
                line,
                format!(
                    "the grips of T-mesh vertices {a} and {b} get two knot intervals ({old} and {k})"
                ),
            )),
            _ => Ok(()),
        }
    }

    fn grip(&self, v: usize, xy: (i32, i32), line: usize, why: &str) -> Result<u32> {
        self.block(v).at(xy).ok_or_else(|| {
            perr(
                line,
                format!(
                    "{why} needs a control point at block position {xy:?} of vertex {v}, where its grip block has none"
                ),
            )
        })
    }

    fn push_loop(&mut self, vertices: Vec<u32>, corners: [u32; 4]) {
        self.faces.push(FaceLoop { vertices, corners });
    }

    /// A file face: at a corner the block's outer corner in the face's quadrant, at a
    /// T-junction the block's outer row along the face's side.
    fn face(&mut self, f: usize) -> Result<()> {
        let line = self.p.faces[f].line;
        let why = format!("face {f}");
        let lp = self.topo.loops[f].clone();
        let mut verts: Vec<u32> = Vec::new();
        let mut corners = Vec::new();
        let mut ends = Vec::new(); // per link: last vertex index in `verts`
        for &l in &lp {
            let k = self.p.link(l);
            let v = k.vertex;
            let d = self.topo.dir[l];
            let b = self.block(v).clone();
            let first = verts.len();
            if k.flag == 0 {
                corners.push(verts.len() as u32);
                verts.push(self.grip(v, pos(b.ext(d), d, b.ext(d + 1), d + 1), line, &why)?);
            } else {
                for j in -b.ext(d + 2)..=b.ext(d) {
                    verts.push(self.grip(v, pos(j, d, b.ext(d + 1), d + 1), line, &why)?);
                }
            }
            for i in first + 1..verts.len() {
                self.knot(verts[i - 1], verts[i], 0.0, line)?;
            }
            ends.push((first, verts.len() - 1));
        }
        for (i, &l) in lp.iter().enumerate() {
            let interval = self.interval(l);
            let a = verts[ends[i].1];
            let b = verts[ends[(i + 1) % lp.len()].0];
            self.knot(a, b, interval, self.p.links[l].line)?;
        }
        let c = [corners[0], corners[1], corners[2], corners[3]];
        self.push_loop(verts, c);
        Ok(())
    }

    fn interval(&self, l: usize) -> f64 {
        let e = self.p.link(l).edge;
        self.p.edges[e].rec.expect("edge indices are checked").1
    }

    /// The 0 × 0 cells of a vertex's block that lie in quadrants inside the mesh.
    fn cells(&mut self, v: usize) -> Result<()> {
        let b = self.block(v).clone();
        let Some(inside) = self.topo.quadrants[v] else {
            return Ok(());
        };
        let line = self.p.vertices[v].line;
        let [dn, dw, ds, de] = b.d;
        for y in -ds..dn {
            for x in -dw..de {
                // Quadrants: 0 N→W (x<0, y≥0), 1 W→S, 2 S→E, 3 E→N.
                let q = match (x >= 0, y >= 0) {
                    (false, true) => 0,
                    (false, false) => 1,
                    (true, false) => 2,
                    (true, true) => 3,
                };
                if !inside[q] {
                    continue;
                }
                let why = format!("the grip block of vertex {v}");
                let c = [(x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1)];
                let mut ids = [0u32; 4];
                for (i, &xy) in c.iter().enumerate() {
                    ids[i] = self.grip(v, xy, line, &why)?;
                }
                for i in 0..4 {
                    self.knot(ids[i], ids[(i + 1) % 4], 0.0, line)?;
                }
                self.push_loop(ids.to_vec(), [0, 1, 2, 3]);
            }
        }
        Ok(())
    }

    /// How far a block row reaches to the side of direction `side` (at `along` steps in
    /// direction `k`): the block's extent where a face lies on that side, else as far as
    /// grips go before a hole.
    fn reach(&self, v: usize, k: usize, side: usize, has_face: bool) -> i32 {
        let b = self.block(v);
        let along = b.ext(k);
        let max = b.ext(side);
        if has_face {
            return max;
        }
        (1..=max)
            .take_while(|&j| b.at(pos(along, k, j, side)).is_some())
            .last()
            .unwrap_or(0)
    }

    /// The zero-width strip along file edge `e`, one knot line per block row, fanned where
    /// the two ends have different rows.
    fn strip(&mut self, e: usize) -> Result<()> {
        let (l, interval) = self.p.edges[e].rec.expect("live edge");
        let line = self.p.edges[e].line;
        let why = format!("edge {e}");
        let kl = self.p.link(l);
        let o = kl.opp;
        let ko = self.p.link(o);
        let (v, u) = (kl.vertex, ko.vertex);
        let (dv, du) = (self.topo.dir[l], self.topo.dir[o]);
        let (left, right) = (kl.face.is_some(), ko.face.is_some());
        // Rows across the edge, j growing towards the face left of `l`. At `u` the left of
        // `o` is the right of `l`, so u's own offsets are negated.
        let v_lo = -self.reach(v, dv, dv + 3, right);
        let v_hi = self.reach(v, dv, dv + 1, left);
        let u_lo = -self.reach(u, du, du + 1, right);
        let u_hi = self.reach(u, du, du + 3, left);
        let (bv, bu) = (self.block(v).ext(dv), self.block(u).ext(du));
        let mut lines = Vec::new();
        for j in v_lo..=v_hi {
            lines.push((j, j.clamp(u_lo, u_hi)));
        }
        for j in u_lo..=u_hi {
            lines.push((j.clamp(v_lo, v_hi), j));
        }
        lines.sort_unstable();
        lines.dedup();
        let mut ids = Vec::with_capacity(lines.len());
        for (i, &(jv, ju)) in lines.iter().enumerate() {
            let a = self.grip(v, pos(bv, dv, jv, dv + 1), line, &why)?;
            let b = self.grip(u, pos(bu, du, -ju, du + 1), line, &why)?;
            self.knot(a, b, interval, line)?;
            ids.push((a, b));
            // A row of one end's block only: it fans into the other end. The mesh boundary
            // stays a knot line whatever the rows.
            let on_boundary = (i == 0 && !right) || (i + 1 == lines.len() && !left);
            if jv != ju && !on_boundary {
                self.fan_lines.push((a, b));
            }
        }
        for w in 0..lines.len() - 1 {
            let ((a1, b1), (a2, b2)) = (lines[w], lines[w + 1]);
            let ((va, ua), (vb, ub)) = (ids[w], ids[w + 1]);
            match (a2 - a1, b2 - b1) {
                (1, 1) => {
                    self.knot(ua, ub, 0.0, line)?;
                    self.knot(vb, va, 0.0, line)?;
                    self.push_loop(vec![va, ua, ub, vb], [0, 1, 2, 3]);
                }
                // Only u's row steps: empty side at v, rotated so that side 3 is not empty.
                (0, 1) => {
                    self.knot(ua, ub, 0.0, line)?;
                    self.push_loop(vec![ub, va, ua], [0, 1, 1, 2]);
                }
                // Only v's row steps: empty side at u.
                (1, 0) => {
                    self.knot(vb, va, 0.0, line)?;
                    self.push_loop(vec![va, ua, vb], [0, 1, 1, 2]);
                }
                _ => {
                    return Err(perr(
                        line,
                        format!("edge {e}: the grip rows at its ends cannot be joined"),
                    ))
                }
            }
        }
        Ok(())
    }
}

/// True for a file whose surface is the Catmull–Clark limit of its control grid: no Bézier end
/// conditions and no grip blocks (Fusion exports, `end-conditions SUBD_CREASES`: boundaries
/// are subdivision creases), every face a quadrilateral without T-junctions, one knot
/// interval throughout. T-spline knot rules give the same surface inside such a grid but not
/// next to its boundary or its star points.
fn subdivision_cage(p: &Parsed, topo: &Topology) -> bool {
    if p.force_bezier || !p.blocks.is_empty() {
        return false;
    }
    let mut intervals = p.edges.iter().filter_map(|e| e.rec.map(|(_, k)| k));
    let Some(first) = intervals.next() else {
        return false;
    };
    first > 0.0
        && intervals.all(|k| k == first)
        && topo
            .loops
            .iter()
            .filter(|lp| !lp.is_empty())
            .all(|lp| lp.len() == 4 && lp.iter().all(|&l| p.link(l).flag == 0))
}

/// Reads a `.tsm` file into a T-mesh (millimetres) and what else it says.
pub fn read(bytes: &[u8]) -> Result<(TMesh, TsmMeta)> {
    let p = parse(bytes)?;
    p.check_indices()?;
    let topo = check_topology(&p)?;
    let (metres_per_unit, units) = match &p.units {
        Some((m, name)) => (*m, name.clone()),
        None => (0.001, "millimeters (not stated)".to_string()),
    };
    let placed = place_grips(&p, &topo, metres_per_unit * MM_PER_M)?;
    let mut b = Builder {
        p: &p,
        topo: &topo,
        blocks: &placed.blocks,
        faces: Vec::new(),
        knots: HashMap::new(),
        fan_lines: Vec::new(),
    };
    for f in 0..p.faces.len() {
        if p.faces[f].rec.is_some() {
            b.face(f)?;
        }
    }
    for v in 0..p.vertices.len() {
        if p.vertices[v].rec.is_some() {
            b.cells(v)?;
        }
    }
    for e in 0..p.edges.len() {
        if p.edges[e].rec.is_some() {
            b.strip(e)?;
        }
    }
    if b.faces.is_empty() {
        return Err(Error::parse(FORMAT, "end of file", "the file has no faces"));
    }
    // Every grip must be part of some face, else its block put it outside the mesh.
    let mut used = vec![false; placed.points.len()];
    for f in &b.faces {
        for &v in &f.vertices {
            used[v as usize] = true;
        }
    }
    if let Some(v) = used.iter().position(|u| !u) {
        let g = placed.grip_of_vertex[v] as usize;
        return Err(perr(
            p.grips[g].line,
            format!(
                "grip {g} is not part of any face: its vertex's grip block places it outside the mesh"
            ),
        ));
    }
    let Builder {
        faces,
        knots,
        fan_lines,
        ..
    } = b;
    let scheme = if subdivision_cage(&p, &topo) {
        Scheme::CatmullClark
    } else {
        Scheme::TSpline
    };
    let mesh =
        TMesh::try_new_with_fan_lines(placed.points, &faces, &knots, 1.0, scheme, &fan_lines)
            .map_err(|e| match e {
                Error::InvalidMesh(m) => {
                    Error::InvalidMesh(format!("built from the .tsm file: {m}"))
                }
                other => other,
            })?;
    let mut vertex_of_slot = vec![None; p.vertices.len()];
    for (v, blk) in placed.blocks.iter().enumerate() {
        if let Some(blk) = blk {
            vertex_of_slot[v] = blk.at((0, 0));
        }
    }
    let mut uv_records = p.uv.clone();
    uv_records.resize(p.vertices.len(), None);
    Ok((
        mesh,
        TsmMeta {
            format_version: p.format_version.clone(),
            units,
            metres_per_unit,
            force_bezier_end_conditions: p.force_bezier,
            end_conditions: p.end_conditions.clone(),
            star_smoothness: p.star_smoothness,
            cap_type: p.cap_type.clone(),
            vertex_of_slot,
            uv_records,
            grip_of_vertex: placed.grip_of_vertex,
            edge_conditions: p.edge_conditions.clone(),
            skipped_records: p.skipped,
        },
    ))
}

// ---------------------------------------------------------------------------------------
// Global parameters.

/// Position of half-edge `h`'s origin in its face's local frame `[0,W]×[0,H]`.
fn local_origin(mesh: &TMesh, h: u32) -> [f64; 2] {
    let e = mesh.he(h);
    let f = &mesh.faces()[e.face as usize];
    let o = e.offset;
    match e.side {
        0 => [o, 0.0],
        1 => [f.width, o],
        2 => [f.width - o, f.height],
        _ => [0.0, f.height - o],
    }
}

/// Global `(s, t)` parameters of every T-mesh vertex, found by laying the faces out side by
/// side from face 0 across shared edges (knot intervals as lengths). `None` when the mesh has
/// no single planar parameterisation (a vertex would get two places: a closed or twisted
/// surface, or an extraordinary point).
pub fn global_parameters(mesh: &TMesh) -> Option<Vec<[f64; 2]>> {
    let nf = mesh.faces().len();
    let mut placement: Vec<Option<(u8, [f64; 2])>> = vec![None; nf];
    let mut param: Vec<Option<[f64; 2]>> = vec![None; mesh.vertex_count()];
    let scale = mesh
        .half_edges()
        .iter()
        .map(|h| h.knot)
        .fold(0.0, f64::max)
        .max(1.0);
    let tol = KNOT_MATCH_REL * scale * nf as f64;
    placement[0] = Some((0, [0.0, 0.0]));
    let mut queue = VecDeque::from([0u32]);
    while let Some(f) = queue.pop_front() {
        let (k, t) = placement[f as usize].expect("queued faces are placed");
        for h in mesh.face_half_edges(f) {
            let lo = local_origin(mesh, h);
            let r = rot(k, lo);
            let g = [r[0] + t[0], r[1] + t[1]];
            let v = mesh.he(h).origin as usize;
            match param[v] {
                Some(q) if (q[0] - g[0]).abs() > tol || (q[1] - g[1]).abs() > tol => return None,
                Some(_) => {}
                None => param[v] = Some(g),
            }
            let Some(tw) = mesh.he(h).twin else { continue };
            let gf = mesh.he(tw).face as usize;
            if placement[gf].is_some() {
                continue;
            }
            // The twin runs the other way: its direction in g's frame, turned by g's
            // rotation, is h's direction turned by f's, reversed.
            let (sh, st) = (mesh.he(h).side, mesh.he(tw).side);
            let kg = (k + sh + 2 + 4 - st) % 4;
            // h's end (the twin's origin) lands where h's walk says.
            let end_local = {
                let e = mesh.he(h);
                let d = rot(e.side, [1.0, 0.0]);
                [lo[0] + e.knot * d[0], lo[1] + e.knot * d[1]]
            };
            let re = rot(k, end_local);
            let end_global = [re[0] + t[0], re[1] + t[1]];
            let lt = rot(kg, local_origin(mesh, tw));
            placement[gf] = Some((kg, [end_global[0] - lt[0], end_global[1] - lt[1]]));
            queue.push_back(gf as u32);
        }
    }
    param.into_iter().collect()
}
