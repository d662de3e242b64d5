//! Air moves: how the tool leaves the surface after a cut and comes back for the next one.
//!
//! Owns: the geometry of retracts and approaches (the moves between the last cut point, the
//! safe plane and the next cut point). Must not: change cutting moves or tool axes.
//!
//! The planner retracts straight up and comes straight down onto the next cut; between
//! cuts the tool rises only as high as the clearance over what it passes above (or to the
//! safe plane, with `full_retract`). The ball's way is checked by exact distances to a tessellation of the surface
//! ([`super::distance`]). Where the ball's way up would pass through the model (under an overhang, on the
//! underside of a closed part reached with a tilted axis) the tool first backs out along
//! its own axis, through the space its shank and holder occupied (which the axis search kept
//! clear), until it is outside the model's box grown by the ball and the clearance; from
//! there it rises beside the model. Approaches mirror retracts.

use super::distance::{PlanRect, SurfaceDistance};
use super::toolpath::{Move, MoveKind, Toolpath};
use super::PlanOptions;
use crate::geom::{most, Point3, Vector3};
use crate::model::Model;

/// What routing the air moves found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AirStats {
    /// Retracts and approaches that lead off the surface along its normal, or back out
    /// along the tool axis or the normal, before rising.
    pub escaped: usize,
    /// Retracts and approaches whose ball would pass through the model either way.
    pub blocked: usize,
    /// The cut point of the first of those (ball centre, mm).
    pub first_blocked: Option<Point3>,
    /// Rapids between cuts run below the safe plane, at the clearance over what lies
    /// beneath them (see `Beneath::transit_height`).
    pub lowered: usize,
    /// Length those save against rising to the safe plane (mm).
    pub lowered_saving_mm: f64,
}

/// Tests whether the ball swept between two points stays out of the model.
struct Sweep<'a> {
    dist: &'a SurfaceDistance,
    /// Least distance from the tessellated surface the ball centre keeps: the ball radius
    /// less the overcut allowed, plus the tessellation's own deviation (mm).
    rad: f64,
    /// Length of the lead-off along the contact normal (mm): twice the tessellation's
    /// deviation and the overcut, so that after it the ball clears the triangles by the
    /// margin `rad` asks for.
    lead_mm: f64,
}

impl Sweep<'_> {
    fn clear(&self, from: &Point3, to: &Point3) -> bool {
        !self.dist.segment_within(from, to, self.rad)
    }

    /// Whether every leg of `way` (from the cut point on) is clear.
    fn clear_way(&self, way: &[Point3]) -> bool {
        way.windows(2).all(|w| self.clear(&w[0], &w[1]))
    }
}

/// How cut move `cut` gets up to the safe plane at `safe_z`: the points the ball centre
/// passes through after leaving it, the last one on the safe plane; `None` if no way tried
/// is clear. Straight up when that is clear; else first a short lead-off along the contact
/// normal (it takes the ball a little more than the triangles' tolerance off the surface,
/// so that what follows can be checked against them with a margin), then straight up, or
/// backing out along the tool axis, the contact normal or that normal made horizontal to
/// the edge of the grown box and up beside the model.
fn way_up(sweep: &Sweep, grown: &Bounds, cut: &Move, safe_z: f64) -> Option<Vec<Point3>> {
    let p = cut.cl_point;
    let up = |q: &Point3| Point3::new(q.x, q.y, safe_z);
    if sweep.clear(&p, &up(&p)) {
        return Some(vec![up(&p)]);
    }
    let normal = (cut.cl_point - cut.cc_point).try_normalize(DIRECTION_MIN)?;
    let lead = p + normal * sweep.lead_mm;
    if sweep.clear(&lead, &up(&lead)) {
        return Some(vec![lead, up(&lead)]);
    }
    escape_directions(cut)
        .iter()
        .filter_map(|d| d.try_normalize(DIRECTION_MIN))
        .map(|d| grown.exit(&lead, &d))
        .find(|e| sweep.clear_way(&[lead, *e, up(e)]))
        .map(|e| vec![lead, e, up(&e)])
}

/// Shortest direction vector (mm, before normalising) worth trying.
const DIRECTION_MIN: f64 = 1e-9;

/// The ways out tried from a cut: its tool axis, its contact normal, and that normal made
/// horizontal.
fn escape_directions(cut: &Move) -> [Vector3; 3] {
    let normal = cut.cl_point - cut.cc_point;
    [cut.tool_axis, normal, Vector3::new(normal.x, normal.y, 0.0)]
}

/// An air move's cut (index), whether it leaves or reaches it, and the way found (`None`:
/// blocked).
type AirLeg = (usize, Leg, Option<Vec<Point3>>);

/// Whether an air move leaves a cut or comes down to one.
#[derive(Clone, Copy, PartialEq)]
enum Leg {
    Leaving,
    Arriving,
}

#[derive(Clone, Copy, PartialEq)]

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

/// What [`route`] did.
pub enum Routed {
    /// Every retract and approach found a clear way; the path holds them.
    Done(AirStats),
    /// Some found none: these cut points (indices into the path as given) must be left out,
    /// so that the cut ends (or starts) where the ball can get away; the path is unchanged.
    LeaveOut(Vec<usize>),
}

/// Cut points walked along a cut looking for one the tool can leave from.
const MAX_WALK: usize = 100_000;

/// Routes every retract and approach of `path` around the model (see the module doc). Runs
/// after the tool axes are set; keeps `runs` and `params` in step with the moves. Where no
/// way is clear, the cut points to leave out are returned instead: from the end of a cut
/// back (or from its start on) to the first point with a clear way.
pub fn route(
    model: &Model,
    path: &mut Toolpath,
    opts: &PlanOptions,
    dist: &SurfaceDistance,
) -> Routed {
    // The model and its stock: escapes end outside both.
    let (bbox, stock) = (model.surface.bbox(), model.stock);
    let grow = path.tool_radius_mm + opts.clearance_mm;
    let grown = Bounds {
        lo: [0, 1, 2].map(|k| bbox.min[k].min(stock.min[k]) - grow),
        hi: [0, 1, 2].map(|k| bbox.max[k].max(stock.max[k]) + grow),
    };
    // Stock declared above the part may still be there: coming down, the tool feeds from
    // the feed height above the stock's top (ball centre at this height), not only above
    // the cut.
    let feed_floor = (stock.max[2] > bbox.max[2])
        .then(|| stock.max[2] + opts.feed_height_mm + path.tool_radius_mm);
    let sweep = Sweep {
        dist,
        rad: path.tool_radius_mm - opts.overcut_mm() + dist.tolerance_mm,
        lead_mm: 2.0 * dist.tolerance_mm + opts.overcut_mm(),
    };
    let mut stats = AirStats::default();
    if sweep.rad <= 0.0 {
        return Routed::Done(stats);
    }
    let moves = &path.moves;
    // The cut each air move leaves (the first retract after a cut) or comes down to (the
    // rapid above the next cut, before its plunge), and the way found.
    // Kept for the air moves only, by move index (a vector over every move would be
    // as large as a fifth of the path).
    let mut legs: Vec<(usize, AirLeg)> = (0..moves.len())
        .filter_map(|i| {
            let m = moves[i];
            let (cut, leg) = match m.kind {
                MoveKind::Retract if i > 0 && moves[i - 1].kind.on_surface() => {
                    (i - 1, Leg::Leaving)
                }
                MoveKind::Rapid if moves.get(i + 1).is_some_and(|x| x.kind == MoveKind::Plunge) => {
                    (i + 1, Leg::Arriving)
                }
                _ => return None,
            };
            let way = way_up(&sweep, &grown, &moves[cut], m.cl_point.z);
            Some((i, (cut, leg, way)))
        })
        .collect();
    let mut leave_out: Vec<usize> = Vec::new();
    for (i, leg) in &legs {
        let (i, (cut, leg, None)) = (*i, leg) else {
            continue;
        };
        let (cut, leg) = (*cut, *leg);
        stats.blocked += 1;
        stats.first_blocked.get_or_insert(moves[cut].cl_point);
        let safe_z = moves[i].cl_point.z;
        let clear_from = |j: usize| way_up(&sweep, &grown, &moves[j], safe_z).is_some();
        // Walk along the cut, away from the blocked end, to the first point that has a way.
        let mut j = cut;
        let mut walked = 0;
        loop {
            leave_out.push(j);
            let next = match leg {
                Leg::Leaving => j.checked_sub(1),
                Leg::Arriving => Some(j + 1),
            };
            let Some(next) = next.filter(|&k| k < moves.len() && moves[k].kind.on_surface()) else {
                break;
            };
            walked += 1;
            if walked > MAX_WALK || clear_from(next) {
                break;
            }
            j = next;
        }
    }
    if !leave_out.is_empty() {
        leave_out.sort_unstable();
        leave_out.dedup();
        return Routed::LeaveOut(leave_out);
    }
    if !opts.full_retract {
        let beneath = Beneath::new(model, opts, dist, path.tool_radius_mm);
        lower_transits(&mut legs, moves, &beneath, &mut stats);
    }
    path.rebuild(|old, i, add| {
        let m = old.moves[i];
        let param = old.param(i);
        let mut push = |mv: Move| add(mv, param);
        let Some((cut, leg, Some(way))) = legs
            .binary_search_by_key(&i, |x| x.0)
            .ok()
            .map(|k| &legs[k].1)
        else {
            push(m);
            return;
        };
        if way.len() > 1 {
            stats.escaped += 1;
        }
        match leg {
            Leg::Leaving => {
                for p in way {
                    push(Move { cl_point: *p, ..m });
                }
            }
            Leg::Arriving => {
                let down: Vec<Point3> = way.iter().rev().copied().collect();
                let at = old.moves[*cut].cl_point;
                let below = feed_floor.map_or(0.0, |z| way_below(&down, &at, z));
                let (rapid, fed) = split_at_feed_height(&down, &at, opts.feed_height_mm.max(below));
                for p in rapid {
                    push(Move { cl_point: p, ..m });
                }
                for p in fed {
                    push(Move {
                        kind: MoveKind::Approach,
                        cl_point: p,
                        ..m
                    });
                }
            }
        }
    });
    Routed::Done(stats)
}

/// What a level rapid with the tool axis vertical must clear: the model's triangles beneath
/// each part of the tool, and the stock where it was declared beyond the part.
struct Beneath<'a> {
    dist: &'a SurfaceDistance,
    /// Per part of the tool: its radius, and how far its lowest point lies above the ball
    /// centre (mm): the ball (radius r, r below), the flutes and shank (from the centre
    /// up) and the holder (from the shank's length up).
    parts: [(f64, f64); 3],
    /// The gap kept (mm): the clearance, and no less than the feed height, as the tool
    /// comes down at the rapid rate no nearer a cut than that.
    gap: f64,
    /// The stock's box where it reaches beyond the part's (it may still be there).
    stock: Option<crate::geom::Aabb>,
}

/// Stock reaching beyond the part's box by less than this share of the model's size is the
/// part's box (the placement rounds it).
const STOCK_SAME_SHARE: f64 = 1e-9;

/// A tool axis this close to +Z (length of the difference of unit vectors) is vertical.
const AXIS_VERTICAL: f64 = 1e-12;

impl<'a> Beneath<'a> {
    fn new(model: &Model, opts: &PlanOptions, dist: &'a SurfaceDistance, r: f64) -> Self {
        let (bbox, stock) = (model.surface.bbox(), model.stock);
        let size = bbox.size().into_iter().fold(0.0, f64::max);
        let beyond = (0..3).any(|k| {
            stock.min[k] < bbox.min[k] - STOCK_SAME_SHARE * size
                || stock.max[k] > bbox.max[k] + STOCK_SAME_SHARE * size
        });
        Beneath {
            dist,
            parts: [
                (r, -r),
                (r.max(opts.shank_radius()), 0.0),
                (opts.holder_radius_mm, opts.shank_length_mm),
            ],
            gap: most(opts.clearance_mm, opts.feed_height_mm),
            stock: beyond.then_some(stock),
        }
    }

    /// The lowest ball-centre height (mm) at which a vertical tool moves level from above
    /// `a` to above `b` (plan view) keeping every part the gap above all it may pass over:
    /// the model's surface within the part's radius and the gap of the rectangle the two
    /// points span (a rapid need not run straight; found from the triangles, grown by
    /// their tolerance), and the stock's top where the stock lies there. `None` where
    /// nothing lies beneath.
    fn transit_height(&self, a: [f64; 2], b: [f64; 2]) -> Option<f64> {
        let (c, tol) = (self.gap, self.dist.tolerance_mm);
        self.parts
            .iter()
            .filter_map(|&(rho, lowest)| {
                let rect = PlanRect::spanned(a, b, rho + c + tol);
                let surface = self.dist.highest_under(&rect).map(|z| z + tol);
                let stock = self
                    .stock
                    .filter(|s| rect.meets([s.min[0], s.min[1]], [s.max[0], s.max[1]]))
                    .map(|s| s.max[2]);
                let top = [surface, stock].into_iter().flatten().reduce(most)?;
                Some(top + c - lowest)
            })
            .reduce(most)
    }
}

/// Lowers each rapid between two cuts (a retract's way up, then the way down to the next
/// cut) from the safe plane to its [`Beneath::transit_height`], where the tool axis is
/// vertical at both ends and the ways have a top to lower: the way up and down keep their
/// points (they were found clear up to the safe plane, and now stop lower on the same
/// lines), and the level move between them clears what lies beneath.
fn lower_transits(
    legs: &mut [(usize, AirLeg)],
    moves: &[Move],
    beneath: &Beneath,
    stats: &mut AirStats,
) {
    let vertical = |m: &Move| (m.tool_axis - Vector3::z()).norm() <= AXIS_VERTICAL;
    for k in 1..legs.len() {
        let (head, tail) = legs.split_at_mut(k);
        let (i, (cut_a, Leg::Leaving, Some(up))) = &mut head[k - 1] else {
            continue;
        };
        let (j, (cut_b, Leg::Arriving, Some(down))) = &mut tail[0] else {
            continue;
        };
        if *j != *i + 1
            || ![*cut_a, *i, *j, *cut_b]
                .iter()
                .all(|&x| vertical(&moves[x]))
        {
            continue;
        }
        let (Some(&top_a), Some(&top_b)) = (up.last(), down.last()) else {
            continue;
        };
        let Some(over) = beneath.transit_height([top_a.x, top_a.y], [top_b.x, top_b.y]) else {
            continue;
        };
        // Never below a point of the ways (they keep rising to the top), nor below either
        // cut.
        let floor = up[..up.len() - 1]
            .iter()
            .chain(&down[..down.len() - 1])
            .map(|p| p.z)
            .chain([moves[*cut_a].cl_point.z, moves[*cut_b].cl_point.z])
            .fold(over, most);
        let safe = most(top_a.z, top_b.z);
        if floor < safe {
            if let (Some(p), Some(q)) = (up.last_mut(), down.last_mut()) {
                stats.lowered += 1;
                stats.lowered_saving_mm += (p.z - floor) + (q.z - floor);
                p.z = floor;
                q.z = floor;
            }
        }
    }
}

/// The length of the way down (`down`, then the cut at `cut`) below height `z` (mm): from
/// where it first goes below `z` to the cut. 0 when the cut is above it; the whole way
/// when it starts below it.
fn way_below(down: &[Point3], cut: &Point3, z: f64) -> f64 {
    let mut pts: Vec<Point3> = down.to_vec();
    pts.push(*cut);
    let mut below = 0.0;
    // From the cut back up: the part of each leg below `z`.
    for w in pts.windows(2).rev() {
        let (hi, lo) = (w[0], w[1]);
        let len = (hi - lo).norm();
        if hi.z <= z {
            below += len;
            continue;
        }
        if lo.z < z {
            below += len * (z - lo.z) / (hi.z - lo.z);
        }
        break;
    }
    below
}

/// Points closer than this are one point when the feed height falls on a corner of the
/// way down (mm).
const SAME_POINT_MM: f64 = 1e-6;

/// Splits the way down to a cut (`down`: from the safe plane to the last point before the
/// cut at `cut`) where it is `feed_height` from the cut, measured along the way: the points
/// the tool reaches at the rapid rate (the last one at the feed height), and those after it
/// that it reaches at the plunge feed (the cut itself, reached by the plunge, not included).
/// A way shorter than the feed height is fed from its first point on.
fn split_at_feed_height(
    down: &[Point3],
    cut: &Point3,
    feed_height: f64,
) -> (Vec<Point3>, Vec<Point3>) {
    if feed_height <= SAME_POINT_MM || down.is_empty() {
        return (down.to_vec(), Vec::new());
    }
    let mut left = feed_height;
    let mut to = *cut;
    for j in (0..down.len()).rev() {
        if left <= SAME_POINT_MM {
            // The feed height is on the corner `down[j + 1]`.
            return (down[..j + 2].to_vec(), down[j + 2..].to_vec());
        }
        let from = down[j];
        let len = (to - from).norm();
        if len > left {
            // The feed height lies on the leg from `down[j]` to `to`.
            let at = to + (from - to) * (left / len);
            let mut rapid = down[..=j].to_vec();
            if (at - from).norm() > SAME_POINT_MM {
                rapid.push(at);
            }
            return (rapid, down[j + 1..].to_vec());
        }
        left -= len;
        to = from;
    }
    (down[..1].to_vec(), down[1..].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_rapid_clears_the_highest_point_beneath_each_part_of_the_tool() {
        let mut m = crate::model::samples::load_sample("bumps").unwrap();
        let bb = m.surface.bbox();
        let dist = SurfaceDistance::new(&m, 0.01);
        let tol = dist.tolerance_mm;
        let mut opts = PlanOptions::default().with_tool_radius(1.0);
        // A short move beside the model: nothing beneath.
        let out = [bb.max[0] + 30.0, bb.min[1]];
        let beneath = Beneath::new(&m, &opts, &dist, 1.0);
        assert_eq!(beneath.transit_height(out, [out[0] + 5.0, out[1]]), None);
        // Across the whole model: the ball passes over its highest point (the highest
        // triangle corner lies within the tolerance of the surface's box).
        let (a, b) = (
            [bb.min[0], 0.5 * (bb.min[1] + bb.max[1])],
            [bb.max[0], 0.5 * (bb.min[1] + bb.max[1])],
        );
        let over = beneath.transit_height(a, b).unwrap();
        let want = bb.max[2] + 5.0 + 1.0;
        assert!((over - want).abs() <= 2.0 * tol, "{over} against {want}");
        // Along the front edge the ball passes over the plate; a holder 100 mm wide 1 mm
        // above the ball centre passes over the top and decides.
        let (a, b) = ([bb.min[0], bb.min[1]], [bb.max[0], bb.min[1]]);
        let low = beneath.transit_height(a, b).unwrap();
        assert!(low < want - 1.0, "{low}");
        opts.holder_radius_mm = 100.0;
        opts.shank_length_mm = 1.0;
        let wide = Beneath::new(&m, &opts, &dist, 1.0)
            .transit_height(a, b)
            .unwrap();
        let want_wide = bb.max[2] + 5.0 - 1.0;
        assert!(
            (wide - want_wide).abs() <= 2.0 * tol,
            "{wide} against {want_wide}"
        );
        // Stock declared 4 mm above the part: its top is beneath every part.
        m.stock.max[2] = bb.max[2] + 4.0;
        let stocked = Beneath::new(&m, &opts, &dist, 1.0)
            .transit_height(a, b)
            .unwrap();
        assert!(
            (stocked - (bb.max[2] + 4.0 + 5.0 + 1.0)).abs() < 1e-9,
            "{stocked}"
        );
        // ... and nothing beside it.
        assert_eq!(
            Beneath::new(&m, &opts, &dist, 1.0)
                .transit_height([out[0] + 200.0, out[1]], [out[0] + 205.0, out[1]]),
            None
        );
    }

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

    #[test]
    fn the_way_below_a_height_is_measured_from_where_it_goes_below() {
        let cut = Point3::new(0.0, 0.0, 0.0);
        let safe = Point3::new(0.0, 0.0, 10.0);
        assert!((way_below(&[safe], &cut, 4.0) - 4.0).abs() < 1e-12);
        assert_eq!(way_below(&[safe], &cut, -1.0), 0.0);
        assert!((way_below(&[safe], &cut, 12.0) - 10.0).abs() < 1e-12);
        // Down to a lead-off point 0.1 mm aside, then across onto the cut.
        let lead = Point3::new(0.1, 0.0, 0.0);
        let up = Point3::new(0.1, 0.0, 10.0);
        assert!((way_below(&[up, lead], &cut, 3.0) - 3.1).abs() < 1e-12);
    }

    #[test]
    fn the_rapid_stops_at_the_feed_height_measured_along_the_way_down() {
        let cut = Point3::new(0.0, 0.0, 0.0);
        let lead = Point3::new(0.1, 0.0, 0.0);
        let safe = Point3::new(0.1, 0.0, 10.0);
        // Down from the safe plane to the lead-off point, then across onto the cut: the
        // 2 mm are 0.1 mm across and 1.9 mm of the vertical leg.
        let (rapid, fed) = split_at_feed_height(&[safe, lead], &cut, 2.0);
        assert_eq!(rapid.len(), 2);
        assert!((rapid[1] - Point3::new(0.1, 0.0, 1.9)).norm() < 1e-12);
        assert_eq!(fed, vec![lead]);
        // Straight down: the rapid ends 2 mm above the cut, nothing else is fed.
        let above = Point3::new(0.0, 0.0, 10.0);
        let (rapid, fed) = split_at_feed_height(&[above], &cut, 2.0);
        assert_eq!(rapid, vec![above, Point3::new(0.0, 0.0, 2.0)]);
        assert!(fed.is_empty());
        // A way shorter than the feed height is fed from the safe plane on.
        let (rapid, fed) = split_at_feed_height(&[safe, lead], &cut, 20.0);
        assert_eq!((rapid, fed), (vec![safe], vec![lead]));
        // Feed height 0: the rapid goes all the way down, as the way was.
        let (rapid, fed) = split_at_feed_height(&[safe, lead], &cut, 0.0);
        assert_eq!((rapid, fed), (vec![safe, lead], vec![]));
        // The feed height on a corner of the way: no point repeated.
        let (rapid, fed) = split_at_feed_height(&[safe, lead], &cut, 0.1);
        assert_eq!((rapid, fed), (vec![safe, lead], vec![]));
    }
}
