//! What a strategy hands the shared pipeline: the cuts it chose, in order, as moves on the
//! surface (ball centres a radius along the surface normal, tool axes still +Z), the air
//! moves between cuts that leave the surface, and the part of its patch each cut point
//! stands for (its footprint: what is left uncut if the point cannot be cut).
//!
//! Owns: building moves from surface points ([`DraftBuilder`]), footprints. Must not:
//! choose tool axes, route air moves or decide what is reachable (that is
//! [`super::pipeline`]'s).

use super::toolpath::{Move, MoveKind, PatchRun, Toolpath};
use super::PlanOptions;
use crate::geom::{Point3, Vector3};
use crate::model::Model;

/// A rectangle `[u0, u1, v0, v1]` of a layout patch's `(u, v)` square that one cut point
/// stands for. Links along a patch side, which add no area of their own, have none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    pub patch: u32,
    pub rect: [f64; 4],
}

impl Footprint {
    /// No area.
    pub const NONE: Footprint = Footprint {
        patch: u32::MAX,
        rect: [0.0; 4],
    };

    /// True for a footprint without area.
    pub fn is_none(&self) -> bool {
        self.patch == u32::MAX || self.rect[1] <= self.rect[0] || self.rect[3] <= self.rect[2]
    }

    /// Its area on the surface (mm²), by 2 × 2 Gauss points.
    pub fn area_mm2(&self, model: &Model) -> f64 {
        if self.is_none() {
            return 0.0;
        }
        let p = &model.layout.patches[self.patch as usize];
        let [u0, u1, v0, v1] = self.rect;
        let g = 0.5 / 3f64.sqrt();
        let mut a = 0.0;
        for x in [0.5 - g, 0.5 + g] {
            for y in [0.5 - g, 0.5 + g] {
                let d = p.derivs(&model.surface, u0 + x * (u1 - u0), v0 + y * (v1 - v0));
                a += d.su.cross(&d.sv).norm();
            }
        }
        0.25 * a * (u1 - u0) * (v1 - v0)
    }

    /// Its area (mm²) by the midpoint rule on `n × n` cells (for large rectangles).
    pub fn area_mm2_fine(&self, model: &Model, n: usize) -> f64 {
        if self.is_none() {
            return 0.0;
        }
        let p = &model.layout.patches[self.patch as usize];
        let [u0, u1, v0, v1] = self.rect;
        let (du, dv) = ((u1 - u0) / n as f64, (v1 - v0) / n as f64);
        let mut a = 0.0;
        for i in 0..n {
            for j in 0..n {
                let d = p.derivs(
                    &model.surface,
                    u0 + (i as f64 + 0.5) * du,
                    v0 + (j as f64 + 0.5) * dv,
                );
                a += d.su.cross(&d.sv).norm();
            }
        }
        a * du * dv
    }

    /// Its middle on the surface (mm).
    pub fn centre(&self, model: &Model) -> Point3 {
        let p = &model.layout.patches[self.patch as usize];
        let [u0, u1, v0, v1] = self.rect;
        p.subs(&model.surface, 0.5 * (u0 + u1), 0.5 * (v0 + v1))
    }
}

/// A point of the surface a strategy wants cut: where on which patch, the contact point and
/// the unit normal on the tool's side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub patch: u32,
    pub uv: [f64; 2],
    pub cc: Point3,
    pub normal: Vector3,
}

/// The footprints of a draft's moves, their sides kept in single precision: 20 bytes each,
/// where 40 held the head five-axis draft's 7.8 MB through the whole pipeline. A footprint
/// is area counted for the rest, never a place the tool goes; rounding its sides to about
/// 6e-8 of the patch square keeps which footprints touch and overlap (rounding keeps
/// equal sides equal and does not reverse order) and moves areas by about 1e-7 of
/// themselves.
#[derive(Debug, Clone, Default)]
pub struct Footprints(Vec<PackedFootprint>);

#[derive(Debug, Clone, Copy)]
struct PackedFootprint {
    patch: u32,
    rect: [f32; 4],
}

impl Footprints {
    /// None, with room for `n`.
    pub fn with_capacity(n: usize) -> Self {
        Footprints(Vec::with_capacity(n))
    }

    /// Adds `f`, its sides rounded to single precision.
    pub fn push(&mut self, f: Footprint) {
        self.0.push(PackedFootprint {
            patch: f.patch,
            rect: f.rect.map(|x| x as f32),
        });
    }

    /// Footprint `i`.
    pub fn get(&self, i: usize) -> Footprint {
        let p = self.0[i];
        Footprint {
            patch: p.patch,
            rect: p.rect.map(f64::from),
        }
    }

    /// How many (one per move of the draft).
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True for a draft without moves.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    fn reserve_exact(&mut self, more: usize) {
        self.0.reserve_exact(more);
    }

    fn shrink_to_fit(&mut self) {
        self.0.shrink_to_fit();
    }
}

impl FromIterator<Footprint> for Footprints {
    fn from_iter<I: IntoIterator<Item = Footprint>>(iter: I) -> Self {
        let iter = iter.into_iter();
        let mut out = Footprints::with_capacity(iter.size_hint().0);
        for f in iter {
            out.push(f);
        }
        out
    }
}

/// A strategy's cuts, ready for the pipeline.
#[derive(Debug, Clone)]
pub struct Draft {
    /// The strategy's name, as the report and the program header give it.
    pub strategy: &'static str,
    /// The moves: cuts on the surface, and the air moves between them (a retract to the
    /// safe plane, a rapid above the next cut, a plunge onto it).
    pub toolpath: Toolpath,
    /// One per move: the patch area it stands for.
    pub footprints: Footprints,
    /// Height of the safe plane (mm).
    pub safe_z: f64,
    /// Retractions the strategy could not avoid.
    pub forced_retractions: usize,
    /// What the space-filling curve is made of (`isfc` only).
    pub isfc: Option<super::isfc::IsfcStats>,
    /// What the slices are made of (`isoplanar` only).
    pub isoplanar: Option<super::isoplanar::IsoplanarStats>,
}

/// Room made for a draft, as a multiple of the CL points the work estimate expects (it
/// was 0.72 to 1.24 times the draft's moves on the head, the keycap, dome and bumps-hole).
const DRAFT_ROOM: f64 = 1.3;

/// Room added each time a draft outgrows its room, as a share of its moves: a vector that
/// doubles holds its old and new arrays at once, three times its moves (the head five-axis
/// draft grew wasm memory to 48 MB that way; its moves, params and footprints take 28 MB).
const DRAFT_GROWTH: usize = 4;

/// Room a finished draft keeps for the moves the pipeline adds (lifting balls out of the
/// surface, splitting turns), as a share of its moves: 1/16 (the head five-axis plan adds
/// 1.8 %).
const PATH_HEADROOM: usize = 16;

/// Builds a [`Draft`] move by move.
pub struct DraftBuilder {
    r: f64,
    safe_z: f64,
    moves: Vec<Move>,
    params: Vec<[f64; 2]>,
    footprints: Footprints,
}

impl DraftBuilder {
    /// An empty draft for `model` planned with `opts`: the safe plane is two tool radii
    /// and the clearance above the model and its stock.
    pub fn new(model: &Model, opts: &PlanOptions) -> Self {
        let r = opts.tool_radius_mm;
        let top = model.surface.bbox().max[2].max(model.stock.max[2]);
        let room = (super::budget::estimate(model, opts).cl_points * DRAFT_ROOM)
            .min(opts.max_cl_points as f64);
        // NaN (no estimate) gives none.
        let room = room as usize;
        DraftBuilder {
            r,
            safe_z: top + 2.0 * r + opts.clearance_mm,
            moves: Vec::with_capacity(room),
            params: Vec::with_capacity(room),
            footprints: Footprints::with_capacity(room),
        }
    }

    /// Room for one more move, grown by a quarter where it is full.
    fn make_room(&mut self) {
        if self.moves.len() == self.moves.capacity() {
            let more = self.moves.len() / DRAFT_GROWTH + 1;
            self.moves.reserve_exact(more);
            self.params.reserve_exact(more);
            self.footprints.reserve_exact(more);
        }
    }

    /// Moves so far (the index the next move gets).
    pub fn len(&self) -> usize {
        self.moves.len()
    }

    /// True before the first move.
    pub fn is_empty(&self) -> bool {
        self.moves.is_empty()
    }

    fn push(&mut self, kind: MoveKind, p: &SurfacePoint, line: u32, fp: Footprint) {
        self.make_room();
        self.moves.push(Move {
            kind,
            cc_point: p.cc,
            cl_point: p.cc + p.normal * self.r,
            tool_axis: Vector3::z(),
            patch: p.patch,
            line,
        });
        self.params.push(p.uv);
        self.footprints.push(fp);
    }

    /// A move off the surface, standing at the last move's contact point.
    fn air(&mut self, kind: MoveKind, cl: Point3) {
        let Some(last) = self.moves.last().copied() else {
            return;
        };
        self.make_room();
        self.moves.push(Move {
            kind,
            cl_point: cl,
            ..last
        });
        self.params.push(*self.params.last().unwrap_or(&[0.0, 0.0]));
        self.footprints.push(Footprint::NONE);
    }

    /// Comes down onto `p` from the safe plane (retracting from the last cut first).
    pub fn approach(&mut self, p: &SurfacePoint, line: u32, fp: Footprint) {
        self.retract();
        let cl = p.cc + p.normal * self.r;
        self.push(MoveKind::Rapid, p, line, Footprint::NONE);
        if let Some(m) = self.moves.last_mut() {
            m.cl_point = Point3::new(cl.x, cl.y, self.safe_z);
        }
        self.push(MoveKind::Plunge, p, line, fp);
    }

    /// Cuts to `p` at the cutting feed.
    pub fn feed(&mut self, p: &SurfacePoint, line: u32, fp: Footprint) {
        self.push(MoveKind::Feed, p, line, fp);
    }

    /// Moves along the surface to `p` between two cuts (a step-over, a patch transit).
    pub fn link(&mut self, p: &SurfacePoint, line: u32, fp: Footprint) {
        self.push(MoveKind::Link, p, line, fp);
    }

    /// Leaves the surface straight up to the safe plane, if on it.
    pub fn retract(&mut self) {
        if let Some(last) = self.moves.last().copied() {
            if last.kind.on_surface() {
                let up = Point3::new(last.cl_point.x, last.cl_point.y, self.safe_z);
                self.air(MoveKind::Retract, up);
            }
        }
    }

    /// The draft: a last retract, and the path with its patch runs and predicted scallop.
    pub fn finish(
        mut self,
        strategy: &'static str,
        runs: Vec<PatchRun>,
        max_predicted_scallop_mm: f64,
        forced_retractions: usize,
    ) -> Draft {
        self.retract();
        // Give back the room not used, but for what the pipeline adds to the path: a vector
        // that outgrows its room is copied whole where its block cannot grow in place (in
        // wasm, where other arrays follow it), and the copy and the old array are held at
        // once (the head five-axis plan's bridging grew wasm memory by 19 MB that way).
        let room = self.moves.len() + self.moves.len() / PATH_HEADROOM;
        self.moves.shrink_to(room);
        self.params.shrink_to(room);
        self.footprints.shrink_to_fit();
        Draft {
            strategy,
            toolpath: Toolpath {
                tool_radius_mm: self.r,
                moves: self.moves,
                max_predicted_scallop_mm,
                runs,
                params: self.params,
            },
            footprints: self.footprints,
            safe_z: self.safe_z,
            forced_retractions,
            isfc: None,
            isoplanar: None,
        }
    }
}
