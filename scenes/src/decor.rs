//! Decor (specification §3, "Decor"): the room furnished — furniture against its walls,
//! fixtures hung on them, windows and doors in them — from the catalog's `decor.toml`,
//! placed from the group's own "decor" stream after the event is laid out, simulated and
//! aimed, so that every piece stands clear of it:
//!
//! * the space every body of the event takes at t0 and sweeps in the plain run (each
//!   dynamic body's bounding sphere at every step), widened by `[decor] clearance_m`;
//! * the observer's free disc: `labels.escape_distance` (every escape walk the labels
//!   consider) plus `[decor] observer_clearance_m` (the body's width and the arms'
//!   reach to the side) around where the observer stands — also more than the reach
//!   envelope's `labels.reach_radius` (a piece hung above the standing body's head, no
//!   walk meets: there the reach radius plus `clearance_m` is kept clear);
//! * every camera's line of sight to the hazard at every video frame (the segment from
//!   the camera to the hazard's centre, widened by the hazard's bounding radius and
//!   `clearance_m`), so decor never hides the hazard from the model or a validator.
//!
//! The pieces are fixed bodies of role `decor` appended after the event's bodies (their
//! indices, the joints and the hazard's are unchanged). Furniture collides (physics stays
//! honest: a plan that walks into the sofa meets it); windows and doors are drawn only.
//! One placement serves a group's bands (their union is kept clear), so the bands show
//! the same room. `[decor] enabled = false` builds the same scenes bare.

use rand::RngExt;
use rh_catalog::decor::DecorPiece;
use rh_catalog::Catalog;
use rh_physics::seeds;
use rh_physics::simulate::Simulation;
use rh_physics::spec::{
    quat, BodyKind, BodyRole, BodySpec, PartSpec, SceneSpec, ShapeSpec, Vec3, IDENTITY,
};

pub use crate::config::DecorConfig;

/// How far a piece may reach into its wall (m): a window's or door's frame is set in it.
const WALL_SLACK: f64 = 0.03;

/// How far above the observer's head a piece hangs clear of every escape walk (m).
const OVERHEAD_GAP: f64 = 0.1;

/// An axis-aligned box, `[min, max]`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Aabb {
    min: Vec3,
    max: Vec3,
}

impl Aabb {
    fn grown(self, by: f64) -> Aabb {
        Aabb {
            min: self.min.map(|v| v - by),
            max: self.max.map(|v| v + by),
        }
    }
    fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.min[k] < o.max[k] && o.min[k] < self.max[k])
    }
    fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: [0, 1, 2].map(|k| self.min[k].min(o.min[k])),
            max: [0, 1, 2].map(|k| self.max[k].max(o.max[k])),
        }
    }
    /// Horizontal distance from `(x, y)` to the box.
    fn distance_xy(&self, x: f64, y: f64) -> f64 {
        let dx = (self.min[0] - x).max(x - self.max[0]).max(0.0);
        let dy = (self.min[1] - y).max(y - self.max[1]).max(0.0);
        dx.hypot(dy)
    }
    /// Whether the segment `a`–`b` passes through the box (slab test).
    fn cut_by(&self, a: Vec3, b: Vec3) -> bool {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let d = b[k] - a[k];
            if d.abs() < 1e-12 {
                if a[k] < self.min[k] || a[k] > self.max[k] {
                    return false;
                }
                continue;
            }
            let (mut u, mut v) = ((self.min[k] - a[k]) / d, (self.max[k] - a[k]) / d);
            if u > v {
                std::mem::swap(&mut u, &mut v);
            }
            t0 = t0.max(u);
            t1 = t1.min(v);
            if t0 > t1 {
                return false;
            }
        }
        true
    }
}

/// A part's world box at a body pose.
fn part_box(p: &PartSpec, position: Vec3, rotation: [f64; 4]) -> Aabb {
    let q = quat::mul(rotation, p.rotation);
    let c = add(position, quat::rotate(rotation, p.offset));
    let half = match p.shape {
        ShapeSpec::Box { half_extents: h } => {
            let mut e = [0.0; 3];
            for (axis, &hk) in h.iter().enumerate() {
                let mut u = [0.0; 3];
                u[axis] = hk;
                let w = quat::rotate(q, u);
                for k in 0..3 {
                    e[k] += w[k].abs();
                }
            }
            e
        }
        other => [other.bounding_radius(); 3],
    };
    Aabb {
        min: [0, 1, 2].map(|k| c[k] - half[k]),
        max: [0, 1, 2].map(|k| c[k] + half[k]),
    }
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Steps per box of a moving body's swept space (its bounding spheres' box over them).
const SWEEP_CHUNK: usize = 8;

/// What a group's event needs kept clear, over all its bands, as boxes and segments.
struct Keepout {
    /// Every event body's parts at t0 and each moving body's swept space, widened by
    /// the clearance.
    taken: Vec<Aabb>,
    /// Per band: the observer's position and height, and the reach radius.
    observers: Vec<([f64; 2], f64, f64)>,
    /// Every camera's sight line to the hazard at every video frame, and how far around
    /// it to keep clear.
    sight: Vec<(Vec3, Vec3, f64)>,
    clearance: f64,
    observer_radius: f64,
}

impl Keepout {
    fn of(runs: &[(SceneSpec, Simulation)], clearance: f64, observer_radius: f64) -> Keepout {
        let mut k = Keepout {
            taken: Vec::new(),
            observers: Vec::new(),
            sight: Vec::new(),
            clearance,
            observer_radius,
        };
        for (spec, sim) in runs {
            let o = &spec.observer;
            k.observers
                .push(([o.x, o.y], o.height, spec.labels.reach_radius));
            for body in spec.bodies.iter().filter(|b| b.role != BodyRole::Decor) {
                k.taken.extend(
                    body.parts
                        .iter()
                        .map(|p| part_box(p, body.position, body.rotation).grown(clearance)),
                );
            }
            k.sweep(spec, sim);
            let r = spec.bodies[spec.hazard].bounding_radius() + clearance;
            let frames = (0..)
                .map(|f| spec.frame_step(f))
                .take_while(|&step| step <= sim.steps());
            for step in frames {
                let h = sim.hazard_com(step);
                k.sight
                    .extend(spec.cameras.iter().map(|c| (c.position, h, r)));
            }
        }
        k
    }

    /// Each moving body's bounding spheres over the run, a box per `SWEEP_CHUNK` steps.
    fn sweep(&mut self, spec: &SceneSpec, sim: &Simulation) {
        let n = sim.dynamic_bodies.len();
        let steps: Vec<usize> = (0..=sim.steps() as usize).collect();
        for (slot, &bi) in sim.dynamic_bodies.iter().enumerate() {
            let r = spec.bodies[bi].bounding_radius() + self.clearance;
            for chunk in steps.chunks(SWEEP_CHUNK) {
                let boxes = chunk.iter().map(|&step| {
                    let c = sim.states[step * n + slot].position.map(f64::from);
                    Aabb { min: c, max: c }.grown(r)
                });
                self.taken.extend(boxes.reduce(Aabb::union));
            }
        }
    }

    /// Whether a piece occupying `b` (colliding or not) leaves the event alone.
    fn clear(&self, b: &Aabb, collides: bool) -> bool {
        let observers_clear = || {
            self.observers.iter().all(|&([x, y], height, reach)| {
                // Above the standing body (a wall cabinet, a shelf) no escape walk meets a
                // piece, only the hands could: there the reach envelope is kept clear.
                let radius = if b.min[2] >= height + OVERHEAD_GAP {
                    reach + self.clearance
                } else {
                    self.observer_radius
                };
                b.distance_xy(x, y) >= radius
            })
        };
        (!collides || observers_clear())
            && self.taken.iter().all(|t| !t.overlaps(b))
            && self
                .sight
                .iter()
                .all(|&(eye, at, r)| !b.grown(r).cut_by(eye, at))
    }
}

/// The yaw turning a piece's +y (out of its wall) into the room, and the wall's point
/// and direction (the piece's +x) for wall `w` (0: +x, 1: −x, 2: +y, 3: −y).
fn wall_frame(w: usize, half: [f64; 2]) -> (f64, Vec3, Vec3, f64) {
    use std::f64::consts::{FRAC_PI_2, PI};
    match w {
        0 => (FRAC_PI_2, [half[0], 0.0, 0.0], [0.0, 1.0, 0.0], half[1]),
        1 => (-FRAC_PI_2, [-half[0], 0.0, 0.0], [0.0, -1.0, 0.0], half[1]),
        2 => (PI, [0.0, half[1], 0.0], [-1.0, 0.0, 0.0], half[0]),
        _ => (0.0, [0.0, -half[1], 0.0], [1.0, 0.0, 0.0], half[0]),
    }
}

/// A piece as a body at `position`, turned by `yaw`: its colliding parts (none for a
/// window or door), every part's world box.
fn piece_body(piece: &DecorPiece, index: usize, position: Vec3, yaw: f64) -> (BodySpec, Aabb) {
    let rotation = quat::from_axis_angle([0.0, 0.0, 1.0], yaw);
    let parts: Vec<PartSpec> = piece
        .parts
        .iter()
        .map(|p| PartSpec {
            shape: crate::families::spec_shape(p.shape, &p.size),
            offset: p.offset,
            rotation: IDENTITY,
        })
        .collect();
    let bounds = parts
        .iter()
        .map(|p| part_box(p, position, rotation))
        .reduce(Aabb::union)
        .expect("a decor piece has parts");
    let colliding = piece
        .parts
        .iter()
        .zip(parts)
        .filter(|(d, _)| d.collide && piece.collides())
        .map(|(_, p)| p)
        .collect();
    let body = BodySpec {
        name: format!("decor_{index}_{}", piece.id),
        role: BodyRole::Decor,
        kind: BodyKind::Fixed,
        catalog_id: Some(piece.id.clone()),
        parts: colliding,
        position,
        rotation,
        mass: 0.0,
        friction: 0.6,
        restitution: 0.1,
        linvel: [0.0; 3],
        angvel: [0.0; 3],
        ccd: false,
        push_mass: None,
    };
    (body, bounds)
}

/// The room a group is furnished in: its floor's half extents, its ceiling, and what
/// the event keeps clear.
struct Room<'a> {
    half: [f64; 2],
    ceiling: f64,
    keepout: &'a Keepout,
}

impl Room<'_> {
    /// Draws up to `tries` positions for a piece against a wall (flush in one of the
    /// wall's corners half the time) and returns the first inside the room, clear of the
    /// pieces placed and of the event.
    fn place(
        &self,
        piece: &DecorPiece,
        index: usize,
        placed: &[(usize, BodySpec, Aabb)],
        tries: u32,
        rng: &mut impl RngExt,
    ) -> Option<(BodySpec, Aabb)> {
        let half = self.half;
        let [x0, x1, _] = piece.footprint();
        for _ in 0..tries {
            let w = rng.random_range(0..4usize);
            let u: f64 = rng.random_range(0.0..1.0);
            let (yaw, wall, along, half_len) = wall_frame(w, half);
            let (lo, hi) = (-half_len - x0, half_len - x1);
            if lo > hi {
                continue;
            }
            // A quarter of the draws at either end of the wall, half along it.
            let s = match u {
                u if u < 0.25 => lo,
                u if u >= 0.75 => hi,
                u => lo + (u - 0.25) * 2.0 * (hi - lo),
            };
            let position = [wall[0] + along[0] * s, wall[1] + along[1] * s, piece.height];
            let (body, bounds) = piece_body(piece, index, position, yaw);
            let inside = bounds.max[2] <= self.ceiling
                && (0..2).all(|k| {
                    bounds.min[k] >= -half[k] - WALL_SLACK && bounds.max[k] <= half[k] + WALL_SLACK
                });
            let free = placed
                .iter()
                .all(|(_, _, b)| !b.grown(0.02).overlaps(&bounds));
            if inside && free && self.keepout.clear(&bounds, piece.collides()) {
                return Some((body, bounds));
            }
        }
        None
    }
}

/// Furnishes a group's simulated, aimed bands (with their cameras): the same pieces
/// appended to every band's bodies. Nothing changes when `[decor]` is off, the room has
/// no decor, or no piece fits.
pub fn furnish(runs: &mut [(SceneSpec, Simulation)], catalog: &Catalog, cfg: &DecorConfig) {
    let Some((first, _)) = runs.first() else {
        return;
    };
    if !cfg.enabled {
        return;
    }
    let mut pieces: Vec<&DecorPiece> = catalog.decor.for_room(&first.room.id).collect();
    if pieces.is_empty() {
        return;
    }
    let half = [first.room.size[0] / 2.0, first.room.size[1] / 2.0];
    let ceiling = first.room.ceiling_height;
    let mut rng = seeds::stream(first.seed, 0, "decor");
    // A drawn order: a room's first pieces are not always the ones that fit.
    for i in (1..pieces.len()).rev() {
        pieces.swap(i, rng.random_range(0..=i));
    }
    let observer_radius = first.labels.escape_distance + cfg.observer_clearance_m;
    let keepout = Keepout::of(runs, cfg.clearance_m, observer_radius);
    let room = Room {
        half,
        ceiling,
        keepout: &keepout,
    };
    let mut placed: Vec<(usize, BodySpec, Aabb)> = Vec::new();
    let mut left_out = Vec::new();
    for (index, piece) in pieces.iter().enumerate() {
        match room.place(piece, index, &placed, cfg.tries, &mut rng) {
            Some((body, bounds)) => placed.push((index, body, bounds)),
            None => left_out.push(index),
        }
    }
    // The fill pass: a room the event leaves little space in gets more tries for the
    // furniture left out (the small pieces fit where the large ones did not).
    let furniture = |placed: &[(usize, BodySpec, Aabb)]| {
        placed
            .iter()
            .filter(|(i, _, _)| pieces[*i].is_furniture())
            .count()
    };
    for index in left_out {
        if furniture(&placed) >= cfg.min_furniture {
            break;
        }
        let piece = pieces[index];
        if !piece.is_furniture() {
            continue;
        }
        if let Some((body, bounds)) = room.place(piece, index, &placed, cfg.fill_tries, &mut rng) {
            placed.push((index, body, bounds));
        }
    }
    // Bodies in the drawn order of their pieces, whichever pass placed them.
    placed.sort_by_key(|(i, _, _)| *i);
    let placed: Vec<(BodySpec, Aabb)> = placed.into_iter().map(|(_, b, a)| (b, a)).collect();
    for (spec, _) in runs.iter_mut() {
        spec.bodies.extend(placed.iter().map(|(b, _)| b.clone()));
    }
}

/// The decor bodies of a spec.
pub fn decor_bodies(spec: &SceneSpec) -> impl Iterator<Item = &BodySpec> {
    spec.bodies.iter().filter(|b| b.role == BodyRole::Decor)
}

/// A spec without its decor (what `[decor] enabled = false` builds).
pub fn bare(spec: &SceneSpec) -> SceneSpec {
    let mut s = spec.clone();
    s.bodies.retain(|b| b.role != BodyRole::Decor);
    s
}
