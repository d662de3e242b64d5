//! Catmull–Clark rules with creases and corners: which rule a vertex follows and the new
//! positions of vertices and edges after one step, given the sharpness of the edges and
//! vertices (DeRose, Kass & Truong 1998, "Subdivision surfaces in character animation", with
//! OpenSubdiv's uniform crease decay and its fractional blending between rules).
//!
//! Sharpness: 0 is smooth; an edge of sharpness `s` is sharp for `s` steps (the last one in
//! part when `s` is fractional) and smooth after; [`INFINITELY_SHARP`] never decays (model
//! boundaries and infinitely sharp creases). A vertex's own sharpness (a tagged corner) keeps
//! it in place while it lasts.
//!
//! Owns: the rules. Must not: know how a mesh is stored (callers hand in the neighbours).

use crate::geom::Vector4;

/// Sharpness of an edge or vertex that never becomes smooth (model boundaries, infinitely
/// sharp creases, interpolated corners).
pub const INFINITELY_SHARP: f64 = f64::INFINITY;

/// Tagged sharpness at or above which a crease or corner counts as infinitely sharp, as in
/// OpenSubdiv (ten steps shrink any feature below 1e-3 of its face).
pub const SHARPNESS_INFINITE_FROM: f64 = 10.0;

/// A tagged sharpness as the rules use it: at or above [`SHARPNESS_INFINITE_FROM`] infinite.
pub fn from_tag(s: f64) -> f64 {
    if s >= SHARPNESS_INFINITE_FROM {
        INFINITELY_SHARP
    } else {
        s.max(0.0)
    }
}

/// Sharpness after one subdivision step: one less, down to 0; infinite stays infinite.
pub fn decayed(s: f64) -> f64 {
    if s.is_infinite() {
        s
    } else {
        (s - 1.0).max(0.0)
    }
}

/// The creases one step down: each sharp edge `(a, b)` still sharp after [`decayed`] gives
/// its two halves `(a, m)` and `(m, b)` (undirected, `(min, max)`), `m` its edge point from
/// `mid`; an edge `mid` does not know (no face of the mesh has it) is dropped. Vertices keep
/// their numbers.
pub fn child_creases<'a>(
    creases: impl IntoIterator<Item = (&'a (u32, u32), &'a f64)> + 'a,
    mid: impl Fn(u32, u32) -> Option<u32> + 'a,
) -> impl Iterator<Item = ((u32, u32), f64)> + 'a {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    creases
        .into_iter()
        .map(|(&(a, b), &s)| (a, b, decayed(s)))
        .filter(|&(_, _, s)| s > 0.0)
        .filter_map(move |(a, b, s)| Some((a, b, s, mid(a, b)?)))
        .flat_map(move |(a, b, s, m)| [(key(a, m), s), (key(m, b), s)])
}

/// The sharp vertices one step down ([`decayed`], the smooth ones dropped).
pub fn child_corners<'a>(
    corners: impl IntoIterator<Item = (&'a u32, &'a f64)> + 'a,
) -> impl Iterator<Item = (u32, f64)> + 'a {
    corners
        .into_iter()
        .map(|(&v, &s)| (v, decayed(s)))
        .filter(|&(_, s)| s > 0.0)
}

/// The rule a vertex follows, from its own sharpness and its edges'.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexRule {
    /// No sharp edge: the smooth rule.
    Smooth,
    /// One sharp edge: the smooth rule (the crease fades out at the vertex).
    Dart,
    /// Two sharp edges: the vertex moves along the crease curve only.
    Crease,
    /// Three or more sharp edges, or a sharp vertex: the vertex stays.
    Corner,
}

impl VertexRule {
    /// The rule for a vertex of sharpness `vertex` whose edges have the sharpness `edges`.
    pub fn of(vertex: f64, edges: impl Iterator<Item = f64>) -> VertexRule {
        if vertex > 0.0 {
            return VertexRule::Corner;
        }
        match edges.filter(|&s| s > 0.0).count() {
            0 => VertexRule::Smooth,
            1 => VertexRule::Dart,
            2 => VertexRule::Crease,
            _ => VertexRule::Corner,
        }
    }
}

/// One edge at a vertex: the point at its other end and its sharpness.
#[derive(Debug, Clone, Copy)]
pub struct EdgeEnd {
    pub point: Vector4,
    pub sharpness: f64,
}

/// New position of a vertex at `p` of sharpness `vertex`, with its edges `edges` (each once);
/// `smooth` gives the smooth rule's position (asked only when a smooth or dart rule takes
/// part). Where the rule changes in this step (a semi-sharp crease ends), the positions of the
/// rule before and after are blended by the mean sharpness of what ends (OpenSubdiv).
pub fn vertex_point(
    p: Vector4,
    vertex: f64,
    edges: &[EdgeEnd],
    smooth: impl FnOnce() -> Vector4,
) -> Vector4 {
    let before = VertexRule::of(vertex, edges.iter().map(|e| e.sharpness));
    let after = VertexRule::of(decayed(vertex), edges.iter().map(|e| decayed(e.sharpness)));
    let crease = |sharp: &dyn Fn(f64) -> bool| {
        let ends: Vector4 = edges
            .iter()
            .filter(|e| sharp(e.sharpness))
            .map(|e| e.point)
            .sum();
        (ends + p * 6.0) / 8.0
    };
    let mut smooth = Some(smooth);
    let mut at = |rule: VertexRule, now: bool| match rule {
        VertexRule::Smooth | VertexRule::Dart => (smooth.take().expect("asked once"))(),
        VertexRule::Crease if now => crease(&|s| s > 0.0),
        VertexRule::Crease => crease(&|s| decayed(s) > 0.0),
        VertexRule::Corner => p,
    };
    if before == after || matches!(before, VertexRule::Smooth | VertexRule::Dart) {
        return at(before, true);
    }
    let w = transition_weight(vertex, edges);
    at(before, true) * w + at(after, false) * (1.0 - w)
}

/// Share of the sharper rule where a vertex's rule changes in this step: the mean sharpness
/// (below 1) of the vertex and edges that become smooth.
fn transition_weight(vertex: f64, edges: &[EdgeEnd]) -> f64 {
    let ending = std::iter::once(vertex)
        .chain(edges.iter().map(|e| e.sharpness))
        .filter(|&s| s > 0.0 && decayed(s) == 0.0);
    let (mut n, mut sum) = (0usize, 0.0);
    for s in ending {
        n += 1;
        sum += s;
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).min(1.0)
    }
}

/// New point on an edge from `a` to `b` of sharpness `s`: the midpoint when sharp, the
/// smooth rule (with the points of the two faces) when smooth, blended for `0 < s < 1`.
/// An edge with one face is sharp whatever `s` says.
pub fn edge_point(a: Vector4, b: Vector4, faces: Option<(Vector4, Vector4)>, s: f64) -> Vector4 {
    let mid = (a + b) * 0.5;
    match faces {
        Some((f0, f1)) if s < 1.0 => {
            let smooth = (a + b + f0 + f1) * 0.25;
            if s > 0.0 {
                mid * s + smooth * (1.0 - s)
            } else {
                smooth
            }
        }
        _ => mid,
    }
}

/// Limit position of a vertex following `rule` (its sharpness already infinite or zero):
/// `smooth` gives the smooth limit mask's position, `crease_ends` the two ends of its sharp
/// edges for a crease.
pub fn limit_point(
    p: Vector4,
    rule: VertexRule,
    crease_ends: impl Iterator<Item = Vector4>,
    smooth: impl FnOnce() -> Vector4,
) -> Vector4 {
    match rule {
        VertexRule::Smooth | VertexRule::Dart => smooth(),
        VertexRule::Crease => (crease_ends.sum::<Vector4>() + p * 4.0) / 6.0,
        VertexRule::Corner => p,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn end(x: f64, s: f64) -> EdgeEnd {
        EdgeEnd {
            point: Vector4::new(x, 0.0, 0.0, 1.0),
            sharpness: s,
        }
    }

    #[test]
    fn rules_follow_the_count_of_sharp_edges() {
        let r = |v: f64, e: &[f64]| VertexRule::of(v, e.iter().copied());
        assert_eq!(r(0.0, &[0.0, 0.0, 0.0, 0.0]), VertexRule::Smooth);
        assert_eq!(r(0.0, &[0.5, 0.0, 0.0, 0.0]), VertexRule::Dart);
        assert_eq!(r(0.0, &[2.0, 0.0, 3.0, 0.0]), VertexRule::Crease);
        assert_eq!(r(0.0, &[1.0, 1.0, 1.0, 0.0]), VertexRule::Corner);
        assert_eq!(r(0.2, &[0.0, 0.0, 0.0, 0.0]), VertexRule::Corner);
        assert_eq!(decayed(2.5), 1.5);
        assert_eq!(decayed(0.5), 0.0);
        assert_eq!(decayed(INFINITELY_SHARP), INFINITELY_SHARP);
        assert_eq!(from_tag(10.0), INFINITELY_SHARP);
    }

    #[test]
    fn a_crease_ending_this_step_blends_by_its_sharpness() {
        let p = Vector4::new(0.0, 1.0, 0.0, 1.0);
        let smooth = Vector4::new(0.0, 0.25, 0.0, 1.0);
        let edges = [
            end(-1.0, 0.25),
            end(1.0, 0.25),
            end(0.0, 0.0),
            end(0.5, 0.0),
        ];
        // Crease rule: (a + 6p + b)/8 = (0, 0.75).
        let crease = (edges[0].point + edges[1].point + p * 6.0) / 8.0;
        let got = vertex_point(p, 0.0, &edges, || smooth);
        let want = crease * 0.25 + smooth * 0.75;
        assert!((got - want).norm() < 1e-15, "{got:?} {want:?}");
        // Infinitely sharp: the crease rule alone; sharpness 1 also (it ends after this step).
        let sharp = [end(-1.0, INFINITELY_SHARP), end(1.0, 1.0), end(0.0, 0.0)];
        assert!((vertex_point(p, 0.0, &sharp, || smooth) - crease).norm() < 1e-15);
        let e = edge_point(p, smooth, Some((p, p)), 0.5);
        let want = (p + smooth) * 0.25 + (p * 3.0 + smooth) * 0.125;
        assert!((e - want).norm() < 1e-15);
    }
}
