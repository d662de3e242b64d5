//! Ball-centre gouge check against the whole surface.
//!
//! A CL point is placed by its own face's normal (`cl_point = cc + r·n`). Where the surface is
//! creased inward (C0 knot lines, e.g. those a `.tsm` grip block puts in) or another part of
//! the surface comes within the ball, that ball cuts into the neighbouring face. This module
//! owns finding such CL points and lifting them clear: the ball centre moves away from the
//! nearest surface point until it is a radius from every face, and where that took it off
//! its own side (a shallow concave crease) it slides down the other side until it touches
//! its own again, so it touches both sides of the crease. It must not move a CL point that
//! gouges nothing (tolerance below), nor change moves off the surface. Only balls near a
//! spot where the surface is tighter than the ball, creased or singular ([`spots`]) are
//! checked, against every face within reach there; where other parts of a smooth surface
//! come within the ball (thin walls) is not looked for.

mod nearest;
mod spots;

use super::{Move, MoveKind, Toolpath};
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector3};
use crate::model::Model;
use crate::tmesh::{Scheme, TMesh};
use nearest::Nearest;
use spots::Spots;

/// What the check found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GougeStats {
    /// CL points lifted because the ball cut into the surface.
    pub lifted: usize,
    /// Deepest cut found before lifting (mm).
    pub worst_mm: f64,
    /// The CL point of that deepest cut, before lifting (mm).
    pub worst_at: Option<Point3>,
    /// CL points still closer than a radius after the lifting rounds (mm deep at most
    /// `residual_mm`).
    pub residual: usize,
    pub residual_mm: f64,
    /// Cut points added between two cut points where the ball, moving straight from one to
    /// the other, cut into the surface (a fold or crease between them); those that cut in
    /// themselves are lifted too.
    pub inserted: usize,
}

/// Least cosine between the way a first cut point after an approach would be lifted and its
/// own surface normal (dimensionless; 60°).
const PLUNGE_LIFT_COS: f64 = 0.5;
/// Lifting rounds per CL point (each moves it away from the then nearest point).
const LIFT_ROUNDS: usize = 8;
/// A lift stops when its depth is more than this share of its depth `STUCK_ROUNDS + 1`
/// measurements earlier (it is not getting clearer: the ball is in a slot narrower than it,
/// between three or more walls).
const STUCK_SHARE: f64 = 0.5;
const STUCK_ROUNDS: usize = 2;
/// Least angle between two walls a lifted ball touches, or between one and the other's
/// opposite, for a step to clear both at once (as the cosine between their normals; 2.6°):
/// nearer parallel, one wall's step serves.
const TWO_WALLS_COS: f64 = 0.999;
/// A ball centre nearer the surface than this share of the radius counts as on it: the way
/// from the nearest point to it gives no direction to lift along (dimensionless).
const ON_SURFACE_SHARE: f64 = 1e-9;
/// Moves between two checks for cancellation.
const CANCEL_EVERY: usize = 256;

/// True if the surface may have C0 lines (creases): only repeated knots, that is zero knot
/// intervals, put them in a T-spline; a Catmull–Clark limit surface is G1 except along
/// infinitely sharp tagged creases and at infinitely sharp tagged corners.
pub fn may_crease(mesh: &TMesh) -> bool {
    match mesh.scheme() {
        Scheme::TSpline => mesh.half_edges().iter().any(|h| h.knot == 0.0),
        Scheme::CatmullClark => mesh.tags().has_sharp_features(),
    }
}

/// True if a ball of radius `r` placed by its contact normal may cut into the surface
/// elsewhere: the surface may crease, or somewhere it is concave (towards the tool) with a
/// radius below the ball's (within [`TIGHT_MARGIN`]). The planner runs [`lift`] only then
/// (it costs about as much as the rest of a keycap plan).
pub fn needed(model: &Model, r: f64) -> bool {
    may_crease(&model.mesh)
        || model
            .smallest_concave_radius()
            .is_some_and(|c| c.radius_mm < r * (1.0 + TIGHT_MARGIN))
}

/// Relative margin on the tool radius below which a concave radius counts as tight: the
/// smallest radius is sampled, and may lie lower between samples.
const TIGHT_MARGIN: f64 = 0.25;

/// Lifts every cutting CL point of `path` near a spot (see [`spots`]) whose ball of radius `r`
/// cuts into the surface by more than `tol` mm, until it is a radius from the nearest surface point (within `tol`).
/// The contact point becomes that nearest point; `left[i]` becomes the material the lifted
/// ball leaves at move `i`'s old contact point (mm; untouched for moves not lifted).
/// Then the straight moves next to lifted points, those over which the ball turns round a
/// convex crease, and those that cut into a surface point they know of (their ends' contacts,
/// crease points where they pass from one face to another; [`WITNESS_DEPTH`]) are checked
/// between their ends: where the ball cuts in on the way, a lifted cut point is added
/// half-way, or where it cuts such a point deepest (and the pieces checked again,
/// [`SEGMENT_HALVINGS`] deep). Returns what it did and, when points were added, for
/// every move of the new path the old move it is (`u32::MAX` for added ones; empty when
/// nothing was added). `keep_going` is told every few hundred moves the share of the work
/// done (0 to 1: the lifting pass to one half, the straight moves to the whole); false
/// cancels.
pub fn lift(
    model: &Model,
    path: &mut Toolpath,
    r: f64,
    tol: f64,
    left: &mut [f64],
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<(GougeStats, Vec<u32>)> {
    let near = Nearest::new(&model.surface);
    let spots = Spots::new(model, &near, r, tol);
    let creased = may_crease(&model.mesh);
    // Where a move's contact point is on the surface: the face and its parameters there.
    let hint = |m: &Move, q: [f64; 2]| {
        let patch = model.layout.patches.get(m.patch as usize)?;
        m.kind
            .on_surface()
            .then(|| patch.face_param(&model.surface, q[0], q[1]))
    };
    let mut stats = GougeStats::default();
    let mut lifted = vec![false; path.moves.len()];
    let share = 0.5 / path.moves.len().max(1) as f64;
    for (i, m) in path.moves.iter_mut().enumerate() {
        if i % CANCEL_EVERY == 0 && !keep_going(share * i as f64) {
            return Err(Error::Cancelled);
        }
        // Every move ending on the surface, the first cut point after an approach too.
        if !m.kind.on_surface() || !spots.near(&m.cl_point) {
            continue;
        }
        // The first cut point after an approach is lifted only off a surface facing it
        // (within 60° of its own normal): at a fold, moving it away from the nearest point
        // would take it to the far side, and the move to the next lifted point through.
        let away = m.cl_point - m.cc_point;
        let own_side = (m.kind == MoveKind::Plunge).then_some(away);
        let Some(mut l) = near.nearest_from(&m.cl_point, r, &[]).and_then(|first| {
            lift_one(
                &near,
                m.cl_point,
                first,
                r,
                tol,
                &[],
                own_side,
                away,
                &mut stats,
            )
        }) else {
            continue;
        };
        // Lifted off a wall it cut into, the ball may have left its own contact: in a
        // shallow concave crease the way off the other wall is mostly up. It slides down
        // that wall until it touches its own side again, into the crease.
        if let Some(n_own) = away.try_normalize(ON_SURFACE_SHARE * r).filter(|_| l.clear) {
            if let Some((centre, contact)) =
                settle(&near, (l.centre, l.contact), (m.cc_point, n_own), r, tol)
            {
                (l.centre, l.contact) = (centre, contact);
            }
        }
        lifted[i] = true;
        if let Some(x) = left.get_mut(i) {
            *x = ((l.centre - m.cc_point).norm() - r).max(0.0);
        }
        m.cl_point = l.centre;
        m.cc_point = l.contact;
    }
    // Straight moves next to lifted points.
    let n = path.moves.len();
    let near_lifted = |i: usize| {
        (i.saturating_sub(SEGMENT_REACH)..(i + SEGMENT_REACH + 1).min(n)).any(|k| lifted[k])
    };
    let mut added: Vec<Vec<(Move, [f64; 2])>> = vec![Vec::new(); n];
    let mut witnesses = Vec::new();
    for i in 1..n {
        if i % CANCEL_EVERY == 0 && !keep_going(0.5 + share * i as f64) {
            return Err(Error::Cancelled);
        }
        let (a, b) = (&path.moves[i - 1], &path.moves[i]);
        if !(a.kind.on_surface() && matches!(b.kind, MoveKind::Feed | MoveKind::Link)) {
            continue;
        }
        let (pa, pb) = (
            path.params.get(i - 1).copied().unwrap_or_default(),
            path.params.get(i).copied().unwrap_or_default(),
        );
        // Points of the surface the move must stay a radius from: its ends' contacts (a
        // ball leaving a convex crease, its contact on the crease line and its centre set by
        // one side's normal, cuts the crease on its way to a point well along the other
        // side), and the crease points where it passes from one face to another (a crease
        // between its ends, or just past one, which its ends' normals do not tell: the
        // cuts into face.tsm were found there).
        witnesses.clear();
        witnesses.extend([a.cc_point, b.cc_point]);
        // The ends' faces: read for every move where the surface may crease (the face
        // changes start from them), else only for a move that is split.
        let ends = creased.then(|| (hint(a, pa), hint(b, pb)));
        if let Some((Some((fa, _)), Some((fb, _)))) = ends.filter(|_| a.patch == b.patch) {
            if let Some(patch) = model.layout.patches.get(a.patch as usize) {
                let surface = &model.surface;
                let face = |q: [f64; 2]| patch.face_param(surface, q[0], q[1]).0;
                face_changes(&face, (pa, fa), (pb, fb), &mut |x, y| {
                    let normal = |q: [f64; 2]| patch.normal(surface, q[0], q[1]);
                    if let (Some(nx), Some(ny)) = (normal(x), normal(y)) {
                        if nx.angle(&ny) > CREASE_TURN_RAD {
                            let q = [0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1])];
                            witnesses.push(patch.subs(surface, q[0], q[1]));
                        }
                    }
                });
            }
        }
        // The ball turning round a convex crease between the two points: its centre moves
        // on an arc round the crease, the straight move cuts the chord of that arc.
        let turn = (a.cl_point - a.cc_point).angle(&(b.cl_point - b.cc_point));
        let pivots = r * (1.0 - (0.5 * turn).cos()) > tol;
        let cuts_in = witness_cut(a, b, &witnesses, r, WITNESS_DEPTH * tol).is_some();
        if !(pivots || near_lifted(i) || cuts_in) {
            continue;
        }
        let mut out = Vec::new();
        let (ha, hb) = ends.unwrap_or_else(|| (hint(a, pa), hint(b, pb)));
        let hints: Vec<(u32, [f64; 2])> = [ha, hb].into_iter().flatten().collect();
        split_segment(
            &near,
            (a, pa),
            (b, pb),
            (r, tol),
            (&hints, &witnesses),
            SEGMENT_HALVINGS,
            &mut stats,
            &mut out,
        );
        stats.inserted += out.len();
        added[i] = out;
    }
    if stats.inserted == 0 {
        return Ok((stats, Vec::new()));
    }
    let mut origin = Vec::with_capacity(n + stats.inserted);
    path.rebuild(|old, i, add| {
        for (m, q) in &added[i] {
            add(*m, *q);
            origin.push(u32::MAX);
        }
        add(old.moves[i], old.param(i));
        origin.push(i as u32);
    });
    Ok((stats, origin))
}

/// Moves on either side of a lifted point whose straight moves are checked between their ends.
const SEGMENT_REACH: usize = 2;
/// Most halvings of a straight move while adding lifted points on it.
pub const SEGMENT_HALVINGS: usize = 6;
/// Where between its ends a straight move is checked (fractions of it).
const SEGMENT_PROBES: [f64; 3] = [0.5, 0.25, 0.75];

/// Where the ball moving straight from `a` to `b` cuts deepest, by more than `depth`, into
/// one of `witnesses`, points of the surface (a cut found for certain, wherever the rest of
/// the surface lies): the share of the way along, if it does. A witness either end's ball
/// already cuts is left to the lifting of that end (the move cannot clear it). face.tsm's
/// watershed plan at r 0.5 mm cut 0.0029 mm into a crease 0.06 of the way along a 0.95 mm
/// move starting just before it, and 0.0021 mm 0.64 of the way along a 0.45 mm move across
/// one; the end normals turned too little for the pivot estimate.
fn witness_cut(a: &Move, b: &Move, witnesses: &[Point3], r: f64, depth: f64) -> Option<f64> {
    let d = b.cl_point - a.cl_point;
    let len2 = d.norm_squared();
    let near = r - depth;
    let mut deepest: Option<(f64, f64)> = None;
    for q in witnesses {
        if (a.cl_point - q).norm() < near || (b.cl_point - q).norm() < near {
            continue;
        }
        let s = if len2 > 0.0 {
            ((q - a.cl_point).dot(&d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let gap = (a.cl_point + d * s - q).norm();
        if gap < near && deepest.is_none_or(|(g, _)| gap < g) {
            deepest = Some((gap, s));
        }
    }
    deepest.map(|(_, s)| s)
}

/// Least turn of the normal across a face change for it to count as a crease (rad): a kink
/// turning less cuts a move of length L at most about L times a quarter of the turn deep
/// (0.0001 mm for a 4 mm move).
const CREASE_TURN_RAD: f64 = 1e-4;

/// How deep a move must cut into one of its witnesses (its ends' contacts, crease points
/// where it passes from one face to another) to be split, as a multiple of the lifting
/// tolerance; once split, the pieces are split further (up to [`SEGMENT_HALVINGS`] deep)
/// where they cut one deeper than the tolerance. The pipeline's lifting tolerance is a fifth
/// of the overcut limit (`GOUGE_LIFT_SHARE`), the rest left to the straight moves: four
/// fifths. Splitting every move that cut a witness deeper than the tolerance took face.tsm's
/// plan (r 0.5 mm, h 0.01 mm) from 572 to 735 ms and added 2 900 cut points, for cuts the
/// simulation had passed.
const WITNESS_DEPTH: f64 = 4.0;

/// Halvings of a move's parameter segment while looking for where it passes from one face to
/// another (the place is found to 2^-20 of the segment).
const FACE_CHANGE_HALVINGS: usize = 20;

/// Calls `found` with the parameters either side of each place where the segment from `a`
/// to `b` (each with its face) passes from one face to another, 2^-20 of the segment apart:
/// every change between faces the halving meets (the faces are rectangles in the patch's
/// parameters, so the segment passes through each once).
fn face_changes(
    face: &dyn Fn([f64; 2]) -> u32,
    a: ([f64; 2], u32),
    b: ([f64; 2], u32),
    found: &mut dyn FnMut([f64; 2], [f64; 2]),
) {
    fn halve(
        face: &dyn Fn([f64; 2]) -> u32,
        (a, fa): ([f64; 2], u32),
        (b, fb): ([f64; 2], u32),
        depth: usize,
        found: &mut dyn FnMut([f64; 2], [f64; 2]),
    ) {
        if fa == fb {
            return;
        }
        if depth == 0 {
            found(a, b);
            return;
        }
        let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let fm = face(m);
        halve(face, (a, fa), (m, fm), depth - 1, found);
        halve(face, (m, fm), (b, fb), depth - 1, found);
    }
    halve(face, a, b, FACE_CHANGE_HALVINGS, found);
}

/// A ball centre lifted clear of the surface, and the point it touches.
struct Lifted {
    centre: Point3,
    contact: Point3,
    /// Whether it ended within the tolerance of touching (else it is counted as residual).
    clear: bool,
}

/// Lifts the ball centred at `c`, whose nearest surface point is `first` (distance, point),
/// until it is a radius from the nearest surface point (within `tol`), if it cuts in by more
/// than `tol`; `None` if it does not. Where its centre lies on the surface (no way away from
/// the nearest point), it is lifted along `away`, its own tool side (from its contact
/// point to its centre), or left where it is (residual) if that has no direction either.
#[allow(clippy::too_many_arguments)]
fn lift_one(
    near: &Nearest,
    c: Point3,
    first: (f64, Point3),
    r: f64,
    tol: f64,
    hints: &[(u32, [f64; 2])],
    own_side: Option<Vector3>,
    away: Vector3,
    stats: &mut GougeStats,
) -> Option<Lifted> {
    let (d, q) = first;
    let off_side = |n: Vector3| (c - q).dot(&n) < PLUNGE_LIFT_COS * d * n.norm();
    if d >= r - tol || own_side.is_some_and(off_side) {
        return None;
    }
    if r - d > stats.worst_mm {
        stats.worst_mm = r - d;
        stats.worst_at = Some(c);
    }
    stats.lifted += 1;
    let (mut c, mut nearest) = (c, (d, q));
    let mut depth = r - d;
    // The wall the ball last touched (point, unit normal): in a spot tighter than the ball a
    // step away from one wall takes it into the other, so the step clears both.
    let mut last: Option<(Point3, Vector3)> = None;
    // The depths of the last rounds, to see whether the ball gets any clearer.
    let mut before = [f64::INFINITY; STUCK_ROUNDS];
    for round in 0..LIFT_ROUNDS {
        let (d, q) = nearest;
        let least = ON_SURFACE_SHARE * r;
        let n = if d > least {
            (c - q) / d
        } else {
            match away.try_normalize(least) {
                Some(n) => n,
                None => break,
            }
        };
        c += match last {
            Some(wall) => step_clear_of_both(n, depth, wall, c, r),
            None => n * depth,
        };
        last = Some((q, n));
        let Some(next) = near.nearest_from(&c, r, hints) else {
            break;
        };
        nearest = next;
        // In a slot narrower than the ball no place clears every wall: the ball goes round
        // them and along the slot. It stops once it has not got clearer for a few rounds.
        let stuck = r - next.0 > STUCK_SHARE * before[0];
        before.rotate_left(1);
        before[STUCK_ROUNDS - 1] = depth;
        depth = r - next.0;
        if depth <= 0.1 * tol || round + 1 == LIFT_ROUNDS || stuck {
            break;
        }
    }
    let clear = depth <= tol;
    if !clear {
        stats.residual += 1;
        stats.residual_mm = stats.residual_mm.max(depth);
    }
    Some(Lifted {
        centre: c,
        contact: nearest.1,
        clear,
    })
}

/// The ball centred at `c`, touching the wall at `q` and clear of its own side's plane `own`
/// (its contact point, unit normal) by more than `tol`, slid along the wall's plane until it
/// is a radius from its own side's too (both planes' normals kept): the new centre and
/// nearest surface point, if the ball there cuts in nowhere by more than `tol`. None where it
/// already touches its own side, the two planes are near parallel, or the slide is longer
/// than the ball's diameter (the walls are no planes at that scale).
fn settle(
    near: &Nearest,
    (c, q): (Point3, Point3),
    (cc, n_own): (Point3, Vector3),
    r: f64,
    tol: f64,
) -> Option<(Point3, Point3)> {
    let gap = (c - cc).dot(&n_own) - r;
    let n_wall = (c - q).try_normalize(ON_SURFACE_SHARE * r)?;
    let k = n_own.dot(&n_wall);
    if gap <= tol || k.abs() > TWO_WALLS_COS {
        return None;
    }
    // Along the wall's plane, straight towards the own side's plane: each multiple of `t`
    // (length² 1 − k²) brings the ball 1 − k² nearer that plane.
    let t = n_wall * k - n_own;
    let slide = t * (gap / (1.0 - k * k));
    if slide.norm() > 2.0 * r {
        return None;
    }
    let settled = c + slide;
    match near.nearest_from(&settled, r, &[]) {
        Some((d, _)) if r - d > tol => None,
        Some((_, contact)) => Some((settled, contact)),
        None => Some((settled, q + slide)),
    }
}

/// The step of a ball centred at `c` that takes it `depth` further along the unit normal `n`
/// of the wall it touches, without going closer than `r` to the plane `wall` (point, unit
/// normal) it touched before: along `n` alone where that keeps it clear of `wall`, else the
/// shortest step that puts it `depth` further from the one and a radius from the other.
fn step_clear_of_both(
    n: Vector3,
    depth: f64,
    wall: (Point3, Vector3),
    c: Point3,
    r: f64,
) -> Vector3 {
    let plain = n * depth;
    let (q0, n0) = wall;
    let k = n.dot(&n0);
    // How far inside the old wall's plane the ball is now, and would be after the plain step.
    let e0 = r - (c - q0).dot(&n0);
    if e0 - depth * k <= 0.0 || k.abs() > TWO_WALLS_COS {
        return plain;
    }
    let det = 1.0 - k * k;
    let both = n * ((depth - k * e0) / det) + n0 * ((e0 - k * depth) / det);
    // Longer than the ball's diameter, the walls are no planes at that scale.
    if both.norm() > 2.0 * r {
        plain
    } else {
        both
    }
}

/// Adds to `out`, in order from `a` to `b`, cut points where the ball moving straight from
/// `a` to `b` cuts in by more than `tol` (half-way where a probe finds it, else where it cuts
/// one of `witnesses` deepest), lifted clear where they cut in themselves, checking the
/// pieces again up to `depth` deep.
#[allow(clippy::too_many_arguments)]
fn split_segment(
    near: &Nearest,
    a: (&Move, [f64; 2]),
    b: (&Move, [f64; 2]),
    (r, tol): (f64, f64),
    (hints, witnesses): (&[(u32, [f64; 2])], &[Point3]),
    depth: usize,
    stats: &mut GougeStats,
    out: &mut Vec<(Move, [f64; 2])>,
) {
    if depth == 0 {
        return;
    }
    let (ma, mb) = (a.0, b.0);
    let at = |s: f64| ma.cl_point + (mb.cl_point - ma.cl_point) * s;
    let probe = |s: f64| near.nearest_from(&at(s), r, hints);
    // The first probe is the middle, whose nearest point the lifting starts from.
    let middle = probe(SEGMENT_PROBES[0]);
    let cuts_in = |x: Option<(f64, Point3)>| x.is_some_and(|(d, _)| d < r - tol);
    // Split half-way where a probe cuts in, else where the move cuts a witness deepest.
    let (s, first) = if cuts_in(middle) || SEGMENT_PROBES[1..].iter().any(|&s| cuts_in(probe(s))) {
        (SEGMENT_PROBES[0], middle)
    } else if let Some(s) = witness_cut(ma, mb, witnesses, r, tol) {
        (s, probe(s))
    } else {
        return;
    };
    let c = at(s);
    let away = (ma.cl_point - ma.cc_point) + (mb.cl_point - mb.cc_point);
    let (centre, contact, clear) =
        match first.and_then(|first| lift_one(near, c, first, r, tol, hints, None, away, stats)) {
            Some(l) => (l.centre, l.contact, l.clear),
            None => (c, first.map_or(ma.cc_point, |(_, q)| q), true),
        };
    let q = [
        a.1[0] + s * (b.1[0] - a.1[0]),
        a.1[1] + s * (b.1[1] - a.1[1]),
    ];
    let m = Move {
        cl_point: centre,
        cc_point: contact,
        ..*mb
    };
    // Where the ball cannot be put clear at the split, points nearer either end would not
    // clear the move through it either (the residual is reported).
    let depth = if clear { depth - 1 } else { 0 };
    let known = (hints, witnesses);
    split_segment(near, a, (&m, q), (r, tol), known, depth, stats, out);
    out.push((m, q));
    split_segment(near, (&m, q), b, (r, tol), known, depth, stats, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance from `c` to the plane through `q` with unit normal `n`.
    fn above(c: &Point3, (q, n): (Point3, Vector3)) -> f64 {
        (c - q).dot(&n)
    }

    /// A ball on a convex crease between two planes (side A falling away at `a` rad, side
    /// B flat), its contact on the crease and its centre set by side A's normal, moving
    /// straight to a point `s` mm along side B: its centre comes
    /// `r (r sin a + s cos a) / sqrt((s + r sin a)^2 + r^2 (1 - cos a)^2)` from the crease
    /// (closed form), and the crease point, its own contact, tells the cut.
    #[test]
    fn a_move_leaving_a_convex_crease_is_measured_against_its_own_contact() {
        let r = 0.5;
        let feed = |cc: Point3, n: Vector3| Move {
            kind: MoveKind::Feed,
            cc_point: cc,
            cl_point: cc + n * r,
            tool_axis: Vector3::z(),
            patch: 0,
            line: 0,
        };
        for (angle, s) in [(0.075_f64, 0.95), (0.2, 0.3), (0.02, 2.0), (0.3, 0.05)] {
            let crease = Point3::origin();
            let a = feed(crease, Vector3::new(-angle.sin(), 0.0, angle.cos()));
            let b = feed(Point3::new(s, 0.0, 0.0), Vector3::z());
            let (sa, ca) = angle.sin_cos();
            let closest =
                r * (r * sa + s * ca) / ((s + r * sa).powi(2) + (r * (1.0 - ca)).powi(2)).sqrt();
            let depth = r - closest;
            assert!(depth > 0.0);
            for tol in [0.5 * depth, 0.9 * depth] {
                assert!(
                    witness_cut(&a, &b, &[crease], r, tol).is_some(),
                    "{angle} {s} {depth}"
                );
            }
            // A witness an end's ball cuts is left to that end.
            let inside = Point3::new(0.0, 0.0, 0.5 * r);
            assert!(witness_cut(&a, &b, &[inside], r, 0.5 * depth).is_none());
            // One on the move's line past its end is as far as from that end.
            let past = b.cl_point + (b.cl_point - a.cl_point).normalize() * (1.5 * r);
            assert!(witness_cut(&a, &b, &[past], r, 0.5 * depth).is_none());
            for tol in [1.1 * depth, 2.0 * depth] {
                assert!(
                    witness_cut(&a, &b, &[crease], r, tol).is_none(),
                    "{angle} {s} {depth}"
                );
            }
        }
    }

    /// The halving finds every place a segment passes from one face to another, to 2^-20 of
    /// it, and none where its ends share a face.
    #[test]
    fn face_changes_are_found_along_a_segment() {
        // Faces in strips u < 0.25, 0.25..0.6, u ≥ 0.6.
        let face = |q: [f64; 2]| {
            if q[0] < 0.25 {
                0
            } else if q[0] < 0.6 {
                1
            } else {
                2
            }
        };
        let (a, b) = ([0.1, 0.3], [0.9, 0.7]);
        let mut found = Vec::new();
        face_changes(&face, (a, face(a)), (b, face(b)), &mut |x, y| {
            found.push((x, y))
        });
        assert_eq!(found.len(), 2, "{found:?}");
        let t = |q: [f64; 2]| (q[0] - a[0]) / (b[0] - a[0]);
        for ((x, y), u) in found.iter().zip([0.25, 0.6]) {
            // Either side of the change, 2^-20 of the segment apart, on the segment.
            assert!(x[0] < u && u <= y[0], "{x:?} {y:?}");
            assert!((t(*y) - t(*x) - 2f64.powi(-20)).abs() < 1e-15);
            for q in [x, y] {
                assert!((q[1] - (a[1] + t(*q) * (b[1] - a[1]))).abs() < 1e-12);
            }
        }
    }

    /// Against a second method: on a patch of rectangular faces (knots at uneven spacing),
    /// every change of face that sampling 20 000 points along a segment sees lies between a
    /// pair the halving gives, and every pair brackets a change; 200 segments.
    #[test]
    fn face_changes_agree_with_dense_sampling() {
        let (ku, kv) = ([0.0, 0.13, 0.3, 0.31, 0.7, 1.0], [0.0, 0.5, 0.52, 0.9, 1.0]);
        let cell = |k: &[f64], x: f64| {
            k[1..]
                .iter()
                .take_while(|&&e| e <= x)
                .count()
                .min(k.len() - 2)
        };
        let face = |q: [f64; 2]| (cell(&ku, q[0]) * 10 + cell(&kv, q[1])) as u32;
        let mut next = crate::testing::uniform(12345);
        const SAMPLES: usize = 20_000;
        let mut changes = 0;
        for _ in 0..200 {
            let (a, b) = ([next(), next()], [next(), next()]);
            let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            let t_of = |q: [f64; 2]| {
                let d = [b[0] - a[0], b[1] - a[1]];
                ((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1])
            };
            let mut pairs = Vec::new();
            face_changes(&face, (a, face(a)), (b, face(b)), &mut |x, y| {
                pairs.push((t_of(x), t_of(y)))
            });
            for &(x, y) in &pairs {
                assert_ne!(face(at(x)), face(at(y)));
            }
            for i in 1..=SAMPLES {
                let (t0, t1) = ((i - 1) as f64 / SAMPLES as f64, i as f64 / SAMPLES as f64);
                if face(at(t0)) != face(at(t1)) {
                    changes += 1;
                    assert!(
                        pairs.iter().any(|&(x, y)| x < t1 + 1e-12 && y > t0 - 1e-12),
                        "a change in [{t0}, {t1}] of {a:?} -> {b:?} not found: {pairs:?}"
                    );
                }
            }
        }
        assert!(changes > 200, "{changes}");
    }

    /// A ball centred on the surface itself (catmark_rook.obj read in centimetres, r 0.5
    /// mm: a centre landed exactly on a wall across a slot, and the lift's direction, from
    /// the nearest point to the centre, was 0 / 0) is lifted along its own tool side to a
    /// radius from the surface, not to NaN.
    #[test]
    fn a_ball_centred_on_the_surface_is_lifted_along_its_own_side() {
        let model = crate::model::samples::load_sample("dome").unwrap();
        let near = Nearest::new(&model.surface);
        let (r, tol) = (0.5, 1e-4);
        let patch = &model.layout.patches[0];
        let q = patch.subs(&model.surface, 0.4, 0.6);
        let n = patch.normal(&model.surface, 0.4, 0.6).unwrap() * model.tool_side();
        let mut stats = GougeStats::default();
        let l = lift_one(&near, q, (0.0, q), r, tol, &[], None, n * r, &mut stats).unwrap();
        let (d, _) = near.nearest_from(&l.centre, r, &[]).unwrap();
        assert!(l.clear && (d - r).abs() <= tol, "{:?} at {d} mm", l.centre);
        assert!((l.centre - q).dot(&n) > r - tol, "{:?}", l.centre);
        // With no side of its own either, it stays where it is, counted as residual.
        let mut stats = GougeStats::default();
        let l = lift_one(
            &near,
            q,
            (0.0, q),
            r,
            tol,
            &[],
            None,
            Vector3::zeros(),
            &mut stats,
        );
        assert_eq!(l.map(|l| (l.centre, l.clear)), Some((q, false)));
        assert_eq!(stats.residual, 1);
    }

    /// Between two walls (planes) whose normals are 90°, 60° and 150° apart, a ball cutting into both
    /// is stepped onto both at once: a radius from each (closed form); where the plain step
    /// clears the wall touched before, it is the plain step; across a slot narrower than the
    /// ball (walls facing each other) it is the plain step, never a leap.
    #[test]
    fn a_ball_between_two_walls_is_stepped_onto_both() {
        let r = 1.0;
        let floor = (Point3::origin(), Vector3::z());
        for deg in [90.0f64, 60.0, 150.0] {
            let a = deg.to_radians();
            // A wall through the origin whose normal is turned `deg` from the floor's.
            let wall = (Point3::origin(), Vector3::new(-a.sin(), 0.0, a.cos()));
            // The centre a radius from both (in the plane y = 0.2), pushed 0.2 mm into both.
            let (n0, n1) = (floor.1, wall.1);
            let k = n0.dot(&n1);
            let x = Point3::new(0.0, 0.2, 0.0) + (n0 + n1) * (r / (1.0 + k));
            let c = x - (n0 + n1).normalize() * 0.2;
            let depth = r - above(&c, wall);
            assert!(
                depth > 0.0 && r - above(&c, floor) > 0.0,
                "{deg}°: not inside both"
            );
            let step = step_clear_of_both(wall.1, depth, floor, c, r);
            let moved = c + step;
            for (name, plane) in [("wall", wall), ("floor", floor)] {
                let h = above(&moved, plane);
                assert!((h - r).abs() < 1e-12, "{deg}°: {h} mm from the {name}");
            }
        }
        // The floor already clear after the plain step: the plain step.
        let wall = (Point3::origin(), Vector3::new(-1.0, 0.0, 0.0));
        let c = Point3::new(-0.5, 0.0, 1.5);
        let step = step_clear_of_both(wall.1, 0.5, floor, c, r);
        assert_eq!(step, wall.1 * 0.5);
        // Walls 1.6 mm apart facing each other: no place a radius from both.
        let roof = (Point3::new(0.0, 0.0, 1.6), -Vector3::z());
        let c = Point3::new(0.0, 0.0, 0.7);
        let step = step_clear_of_both(roof.1, r - above(&c, roof), floor, c, r);
        assert_eq!(step, roof.1 * (r - above(&c, roof)));
    }
}
