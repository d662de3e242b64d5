//! Air moves: how the tool leaves the surface after a cut and comes back for the next one.
//!
//! Owns: the geometry of retracts and approaches (the moves between the last cut point, the
//! safe plane and the next cut point). Must not: change cutting moves or tool axes.
//!
//! The planner retracts straight up to the safe plane and comes straight down onto the next
//! cut. Where the ball's way up would pass through the model (under an overhang, on the
//! underside of a closed part reached with a tilted axis) the tool first backs out along
//! its own axis, through the space its shank and holder occupied (which the axis search kept
//! clear), until it is outside the model's box grown by the ball and the clearance; from
//! there it rises beside the model. Approaches mirror retracts.

use super::axis::Clearance;
use super::toolpath::{Move, MoveKind, Toolpath};
use super::PlanOptions;
use crate::geom::{Point3, Vector3};
use crate::model::Model;

/// What routing the air moves found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AirStats {
    /// Retracts and approaches moved off the vertical to back out along the tool axis.
    pub escaped: usize,
    /// Retracts and approaches whose ball would pass through the model either way.
    pub blocked: usize,
    /// The cut point of the first of those (ball centre, mm).
    pub first_blocked: Option<Point3>,
}

/// Tests whether the ball swept between two points stays out of the model.
struct Sweep<'a> {
    obs: &'a Clearance,
    /// Test radius: the ball less what the samples may miss and the plan's chordal
    /// tolerance (the ball already touches the surface at the cut point) (mm).
    rad: f64,
}

impl Sweep<'_> {
    fn clear(&self, from: &Point3, to: &Point3) -> bool {
        self.obs.capsule_hit(from, to, self.rad).is_none()
    }

    /// Whether every leg of `way` (from the cut point on) is clear.
    fn clear_way(&self, way: &[Point3]) -> bool {
        way.windows(2).all(|w| self.clear(&w[0], &w[1]))
    }
}

/// How cut point `p` (ball centre; contact normal `normal`, tool along `axis`) gets up to
/// the safe plane at `safe_z`: straight up when the ball's way is clear, else backing out
/// along the first of the tool axis, the contact normal and the normal's horizontal part
/// whose way out of the grown box and up beside the model is clear.
fn way_up(sweep: &Sweep, grown: &Bounds, p: &Point3, dirs: &[Vector3], safe_z: f64) -> Way {
    let up = Point3::new(p.x, p.y, safe_z);
    if sweep.clear(p, &up) {
        return Way::Straight;
    }
    dirs.iter()
        .filter_map(|d| d.try_normalize(DIRECTION_MIN))
        .map(|d| grown.exit(p, &d))
        .find(|e| sweep.clear_way(&[*p, *e, Point3::new(e.x, e.y, safe_z)]))
        .map_or(Way::Blocked, Way::Escape)
}

/// Shortest direction vector (mm, before normalising) worth trying.
const DIRECTION_MIN: f64 = 1e-9;

/// The ways out tried from a cut: its tool axis, its contact normal, and that normal made
/// horizontal.
fn escape_directions(cut: &Move) -> [Vector3; 3] {
    let normal = cut.cl_point - cut.cc_point;
    [cut.tool_axis, normal, Vector3::new(normal.x, normal.y, 0.0)]
}

/// Whether an air move leaves a cut or comes down to one.
#[derive(Clone, Copy)]
enum Leg {
    Leaving,
    Arriving,
}

enum Way {
    Straight,
    Escape(Point3),
    Blocked,
}

/// An axis-aligned box (mm).
struct Bounds {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Bounds {
    /// Where the ray from `p` (inside) along unit `dir` leaves the box.
    fn exit(&self, p: &Point3, dir: &Vector3) -> Point3 {
        let t = (0..3)
            .filter(|&k| dir[k] != 0.0)
            .map(|k| {
                let wall = if dir[k] > 0.0 { self.hi[k] } else { self.lo[k] };
                ((wall - p[k]) / dir[k]).max(0.0)
            })
            .fold(f64::INFINITY, f64::min);
        p + dir * if t.is_finite() { t } else { 0.0 }
    }
}

/// Routes every retract and approach of `path` around the model (see the module doc). Runs
/// after the tool axes are set; keeps `runs` and `params` in step with the moves.
pub fn route(model: &Model, path: &mut Toolpath, opts: &PlanOptions, obs: &Clearance) -> AirStats {
    let bbox = model.surface.bbox();
    let grow = path.tool_radius_mm + opts.clearance_mm;
    let grown = Bounds {
        lo: [0, 1, 2].map(|k| bbox.min[k] - grow),
        hi: [0, 1, 2].map(|k| bbox.max[k] + grow),
    };
    let sweep = Sweep {
        obs,
        rad: path.tool_radius_mm - obs.gap_mm() - opts.chordal_mm,
    };
    let mut stats = AirStats::default();
    if sweep.rad <= 0.0 {
        return stats;
    }
    let blocked = |stats: &mut AirStats, p: Point3| {
        stats.blocked += 1;
        stats.first_blocked.get_or_insert(p);
    };
    path.rebuild(|old, i, add| {
        let m = old.moves[i];
        let param = old.param(i);
        let mut push = |mv: Move| add(mv, param);
        // The cut this air move leaves (the first retract after a cut) or comes down to (the
        // rapid above the next cut, before its plunge).
        let cut = match m.kind {
            MoveKind::Retract if i > 0 && old.moves[i - 1].kind.on_surface() => {
                Some((old.moves[i - 1], Leg::Leaving))
            }
            MoveKind::Rapid
                if old
                    .moves
                    .get(i + 1)
                    .is_some_and(|x| x.kind == MoveKind::Plunge) =>
            {
                Some((old.moves[i + 1], Leg::Arriving))
            }
            _ => None,
        };
        let safe_z = m.cl_point.z;
        match cut.map(|(cut, leg)| {
            let way = way_up(
                &sweep,
                &grown,
                &cut.cl_point,
                &escape_directions(&cut),
                safe_z,
            );
            (way, cut, leg)
        }) {
            Some((Way::Escape(e), _, leg)) => {
                stats.escaped += 1;
                let above = Point3::new(e.x, e.y, safe_z);
                let points = match leg {
                    Leg::Leaving => [e, above],
                    Leg::Arriving => [above, e],
                };
                for p in points {
                    push(Move { cl_point: p, ..m });
                }
            }
            Some((Way::Blocked, cut, _)) => {
                blocked(&mut stats, cut.cl_point);
                push(m);
            }
            _ => push(m),
        }
    });
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_leaves_the_box_through_the_nearest_wall() {
        let b = Bounds {
            lo: [-1.0, -2.0, 0.0],
            hi: [3.0, 2.0, 5.0],
        };
        let p = Point3::new(0.0, 0.0, 1.0);
        // Straight up: the top.
        assert_eq!(b.exit(&p, &Vector3::z()), Point3::new(0.0, 0.0, 5.0));
        // Sideways: the wall at x = 3.
        assert_eq!(b.exit(&p, &Vector3::x()), Point3::new(3.0, 0.0, 1.0));
        // At 45° in x–z: x reaches 3 after 3·√2, z reaches 5 after 4·√2; x first.
        let d = Vector3::new(1.0, 0.0, 1.0).normalize();
        let e = b.exit(&p, &d);
        assert!((e - Point3::new(3.0, 0.0, 4.0)).norm() < 1e-12, "{e}");
    }
}
