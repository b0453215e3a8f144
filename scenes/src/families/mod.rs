//! Event families (specification §4): one file per family behind the `Family` trait.
//!
//! A family lays out its scene (`sample`) from a seeded stream and the band's speed
//! value, and says whether its intended event really happened (`event_happened`).
//! The contract that makes speed bands honest: a sampler draws the same random numbers
//! in the same order whatever the speed, so the four bands of a group differ only in
//! the speed parameter and what follows from it physically.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rh_catalog::{Object, Room, ShapeKind};
use rh_physics::simulate::Simulation;
use rh_physics::spec::{
    quat, BodyKind, BodyRole, BodySpec, JointKind, JointSpec, PartSpec, Quat, SceneSpec, ShapeSpec,
    Vec3, IDENTITY,
};
use std::collections::BTreeMap;

pub mod bouncing_object;
pub mod ceiling_drop;
pub mod chain_reaction;
pub mod door_swing;
pub mod edge_creep;
pub mod furniture_tip;
pub mod hanging_fall;
pub mod ladder_slip;
pub mod launch;
pub mod multi_object;
pub mod object_drop;
pub mod pendulum_swing;
pub mod rolling_ball;
pub mod shelf_slide;
pub mod sliding_object;
pub mod stack_collapse;
pub mod stair_tumble;
pub mod surface_cascade;
pub mod thrown_object;

pub use door_swing::hinge_inertia;
pub use ladder_slip::required_floor_friction;

pub const GRAVITY: f64 = 9.81;

/// What a sampler gets: the true physics of the object, the room, the band's speed.
pub struct FamilyInput<'a> {
    pub object: &'a Object,
    pub room: &'a Room,
    pub speed: f64,
    /// The family's speed in each band, slowest first: a sampler may size its layout so
    /// that even the slowest band's event happens (without the draws depending on `speed`).
    pub band_speeds: [f64; 4],
    /// Whether this group's observer stands far from the event (drawn by the randomizer).
    pub far_observer: bool,
    pub observer_height: f64,
    /// Where the group's event is aimed (label rule v5): families that aim their own
    /// event (`Family::self_aimed`) read it.
    pub intent: crate::intent::Intent,
}

/// Where the observer stands: on the floor at (x, y), facing `yaw`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObserverPose {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
}

/// A family's layout of one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub bodies: Vec<BodySpec>,
    pub joints: Vec<JointSpec>,
    pub hazard: usize,
    /// The body the hazard starts on, if any (table, shelf, ramp).
    pub source_support: Option<usize>,
    pub observer: ObserverPose,
    /// Family-specific numbers worth recording (drop height, ramp angle, …).
    pub params: BTreeMap<String, f64>,
}

/// What a family is called and what its speed bands vary (the spec records both).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FamilyInfo {
    pub name: &'static str,
    /// What the speed value means (e.g. `push_speed_mps`).
    pub speed_parameter: &'static str,
    /// False for families whose pace gravity sets; their bands exist but analyses skip them.
    pub speed_sweep: bool,
}

pub trait Family: Sync {
    /// The family's name and speed parameter.
    fn info(&self) -> FamilyInfo;
    fn name(&self) -> &'static str {
        self.info().name
    }
    fn speed_parameter(&self) -> &'static str {
        self.info().speed_parameter
    }
    fn speed_sweep(&self) -> bool {
        self.info().speed_sweep
    }
    /// Lays out the scene. Must draw from `rng` identically for every `input.speed`.
    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout;
    /// Whether the family aims its own event at the observer (`input.intent`); for the
    /// others `aim::aim_group` places the observer on the simulated path.
    fn self_aimed(&self) -> bool {
        false
    }
    /// Whether the start of the body set in motion follows from the speed (label rule v5:
    /// every band meets the same point, or leaves its edge at the same time, so a faster
    /// band starts farther back). Everything else of the layout stays speed-independent.
    fn timed(&self) -> bool {
        self.self_aimed()
    }
    /// Whether the family's intended event happened in the simulation.
    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool;
}

/// All implemented families, in canonical order.
pub fn all() -> Vec<&'static dyn Family> {
    vec![
        &object_drop::OBJECT_DROP,
        &shelf_slide::SHELF_SLIDE,
        &hanging_fall::HangingFall,
        &ceiling_drop::CeilingDrop,
        &sliding_object::SlidingObject,
        &rolling_ball::RollingBall,
        &surface_cascade::SurfaceCascade,
        &furniture_tip::FurnitureTip,
        &stack_collapse::StackCollapse,
        &ladder_slip::LadderSlip,
        &door_swing::DoorSwing,
        &pendulum_swing::PendulumSwing,
        &thrown_object::ThrownObject,
        &bouncing_object::BouncingObject,
        &stair_tumble::StairTumble,
        &chain_reaction::ChainReaction,
        &multi_object::MultiObject,
    ]
}

pub fn get(name: &str) -> Option<&'static dyn Family> {
    all().into_iter().find(|f| f.name() == name)
}

// ---------------------------------------------------------------------------
// Shared building blocks for samplers.

/// A catalog part's shape (full extents, as `objects.toml` and `decor.toml` give them)
/// as a spec shape (half extents, radii); a capsule's length is end to end.
pub fn spec_shape(shape: ShapeKind, size: &[f64]) -> ShapeSpec {
    match shape {
        ShapeKind::Box => ShapeSpec::Box {
            half_extents: [size[0] / 2.0, size[1] / 2.0, size[2] / 2.0],
        },
        ShapeKind::Sphere => ShapeSpec::Sphere {
            radius: size[0] / 2.0,
        },
        ShapeKind::Cylinder => ShapeSpec::Cylinder {
            half_height: size[1] / 2.0,
            radius: size[0] / 2.0,
        },
        ShapeKind::Capsule => ShapeSpec::Capsule {
            half_height: (size[1] - size[0]).max(0.0) / 2.0,
            radius: size[0] / 2.0,
        },
    }
}

/// Converts catalog parts into spec parts.
pub fn object_parts(object: &Object) -> Vec<PartSpec> {
    object
        .parts
        .iter()
        .map(|p| PartSpec {
            shape: spec_shape(p.shape, &p.size),
            offset: p.offset,
            rotation: IDENTITY,
        })
        .collect()
}

/// The catalog object as the scene's hazard body.
pub fn hazard_body(
    object: &Object,
    position: Vec3,
    rotation: Quat,
    linvel: Vec3,
    angvel: Vec3,
) -> BodySpec {
    BodySpec {
        name: object.id.clone(),
        role: BodyRole::Hazard,
        kind: BodyKind::Dynamic,
        catalog_id: Some(object.id.clone()),
        parts: object_parts(object),
        position,
        rotation,
        mass: object.mass,
        friction: object.friction,
        restitution: object.restitution,
        linvel,
        angvel,
        ccd: true,
        push_mass: None,
    }
}

/// A fixed furniture box (table, shelf board, ramp).
pub fn fixed_box(
    name: &str,
    half_extents: Vec3,
    position: Vec3,
    rotation: Quat,
    friction: f64,
    restitution: f64,
) -> BodySpec {
    BodySpec {
        name: name.to_string(),
        role: BodyRole::Support,
        kind: BodyKind::Fixed,
        catalog_id: None,
        parts: vec![PartSpec {
            shape: ShapeSpec::Box { half_extents },
            offset: [0.0; 3],
            rotation: IDENTITY,
        }],
        position,
        rotation,
        mass: 0.0,
        friction,
        restitution,
        linvel: [0.0; 3],
        angvel: [0.0; 3],
        ccd: false,
        push_mass: None,
    }
}

/// Distance from the object's origin down to its lowest point, unrotated.
pub fn bottom_offset(object: &Object) -> f64 {
    object
        .parts
        .iter()
        .map(|p| p.half_extents()[2] - p.offset[2])
        .fold(0.0, f64::max)
}

/// Half length of the object's footprint along a horizontal direction at angle `rel`
/// to its own x axis.
pub fn footprint_half_length(object: &Object, rel: f64) -> f64 {
    let h = object.half_extents();
    h[0] * rel.cos().abs() + h[1] * rel.sin().abs()
}

pub fn yaw_quat(yaw: f64) -> Quat {
    quat::from_axis_angle([0.0, 0.0, 1.0], yaw)
}

pub fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi <= lo {
        // Still draw, so the stream's position does not depend on the range.
        let _: f64 = rng.random();
        lo
    } else {
        rng.random_range(lo..hi)
    }
}

/// Unit vector in the floor plane at heading `angle`.
pub fn heading(angle: f64) -> [f64; 2] {
    [angle.cos(), angle.sin()]
}

/// Friction coefficient rapier uses for a pair (the `Average` combine rule).
pub fn combined_friction(a: f64, b: f64) -> f64 {
    (a + b) / 2.0
}

/// The standard observer placement: beyond `landing` along the hazard's floor heading
/// `dir`, at `near` distance (or `far` distance for far-observer groups), with a
/// lateral offset, facing back toward `face_point`. Always makes the same draws.
pub fn observer_beyond(
    rng: &mut ChaCha8Rng,
    landing: [f64; 2],
    dir: [f64; 2],
    near: (f64, f64),
    far: (f64, f64),
    lateral: f64,
    far_observer: bool,
    face_point: [f64; 2],
) -> ObserverPose {
    let d_near = uniform(rng, near.0, near.1);
    let d_far = uniform(rng, far.0, far.1);
    let side = uniform(rng, -lateral, lateral);
    let d = if far_observer { d_far } else { d_near };
    let perp = [-dir[1], dir[0]];
    let x = landing[0] + dir[0] * d + perp[0] * side;
    let y = landing[1] + dir[1] * d + perp[1] * side;
    let yaw = (face_point[1] - y).atan2(face_point[0] - x);
    ObserverPose { x, y, yaw }
}

/// A sampler's event origin: near the room centre, shifted against the heading so the
/// event and the observer both fit in the room.
pub fn event_origin(rng: &mut ChaCha8Rng, room: &Room, dir: [f64; 2], back: f64) -> [f64; 2] {
    let jitter_x = uniform(rng, -0.3, 0.3);
    let jitter_y = uniform(rng, -0.3, 0.3);
    let limit_x = (room.size[0] / 2.0 - 0.8).max(0.0);
    let limit_y = (room.size[1] / 2.0 - 0.8).max(0.0);
    [
        (-dir[0] * back + jitter_x).clamp(-limit_x, limit_x),
        (-dir[1] * back + jitter_y).clamp(-limit_y, limit_y),
    ]
}

/// Distance from the object's origin up to its highest point, unrotated.
pub fn top_offset(object: &Object) -> f64 {
    object
        .parts
        .iter()
        .map(|p| p.half_extents()[2] + p.offset[2])
        .fold(0.0, f64::max)
}

/// Centre of mass in the object frame: the simulator spreads a body's mass over its
/// parts by volume, so this is the volume-weighted mean of the part centres.
pub fn com_offset(object: &Object) -> Vec3 {
    let total: f64 = object.parts.iter().map(|p| p.volume()).sum();
    let mut c = [0.0; 3];
    for p in &object.parts {
        let w = p.volume() / total;
        for (k, ck) in c.iter_mut().enumerate() {
            *ck += w * p.offset[k];
        }
    }
    c
}

/// Floor-plane point `p + dir * d`.
pub fn ahead(p: [f64; 2], dir: [f64; 2], d: f64) -> [f64; 2] {
    [p[0] + dir[0] * d, p[1] + dir[1] * d]
}

/// The horizontal unit vector 90° counter-clockwise of `dir` (`ẑ × dir`).
pub fn left_of(dir: [f64; 2]) -> [f64; 2] {
    [-dir[1], dir[0]]
}

pub fn cross3(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Velocity of the point `p` of a body spinning with `omega` about the fixed point `pivot`.
pub fn velocity_about(omega: Vec3, pivot: Vec3, p: Vec3) -> Vec3 {
    cross3(omega, [p[0] - pivot[0], p[1] - pivot[1], p[2] - pivot[2]])
}

/// A spot on one of the room's four walls: `base` is a point of the wall plane at floor
/// level and `normal_angle` the heading of the wall's normal into the room.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallSite {
    pub normal_angle: f64,
    pub base: [f64; 2],
}

/// Draws a wall (uniformly among the four) and a point along it, at least `margin` from
/// the corners. Always makes two draws.
pub fn wall_site(rng: &mut ChaCha8Rng, room: &Room, margin: f64) -> WallSite {
    let side = uniform(rng, 0.0, 4.0).floor().min(3.0) as usize;
    let t = uniform(rng, -1.0, 1.0);
    let [hx, hy] = [room.size[0] / 2.0, room.size[1] / 2.0];
    let (normal_angle, base) = match side {
        0 => (std::f64::consts::PI, [hx, t * (hy - margin).max(0.0)]),
        1 => (0.0, [-hx, t * (hy - margin).max(0.0)]),
        2 => (
            -std::f64::consts::FRAC_PI_2,
            [t * (hx - margin).max(0.0), hy],
        ),
        _ => (
            std::f64::consts::FRAC_PI_2,
            [t * (hx - margin).max(0.0), -hy],
        ),
    };
    WallSite { normal_angle, base }
}

/// The wall behind a `WallSite` as a fixed slab (0.2 m thick, its face on the wall
/// plane), `half_width` along the wall, from the floor to `height`.
pub fn wall_body(site: &WallSite, half_width: f64, height: f64, friction: f64) -> BodySpec {
    let n = heading(site.normal_angle);
    fixed_box(
        "wall",
        [0.1, half_width, height / 2.0],
        [
            site.base[0] - n[0] * 0.1,
            site.base[1] - n[1] * 0.1,
            height / 2.0,
        ],
        yaw_quat(site.normal_angle),
        friction,
        0.1,
    )
}

/// How an object rests on a flat surface: its natural pose, except that capsules (which
/// would balance on a round cap) lie on their side. Returns the rotation in the object
/// frame, the distance from its origin down to the surface, and its height.
pub fn resting_pose(object: &Object) -> (Quat, f64, f64) {
    if object.parts.iter().any(|p| p.shape == ShapeKind::Capsule) {
        // About x by 90°: a part's y extent becomes vertical (z' = y).
        let q = quat::from_axis_angle([1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2);
        let bottom = object
            .parts
            .iter()
            .map(|p| p.half_extents()[1] - p.offset[1])
            .fold(0.0, f64::max);
        let top = object
            .parts
            .iter()
            .map(|p| p.half_extents()[1] + p.offset[1])
            .fold(0.0, f64::max);
        (q, bottom, bottom + top)
    } else {
        let b = bottom_offset(object);
        (IDENTITY, b, b + top_offset(object))
    }
}

/// A fixed table block from the floor, its local x along `heading_angle`.
pub fn table_block(
    name: &str,
    centre: [f64; 2],
    half: [f64; 2],
    height: f64,
    heading_angle: f64,
    friction: f64,
) -> BodySpec {
    fixed_box(
        name,
        [half[0], half[1], height / 2.0],
        [centre[0], centre[1], height / 2.0],
        yaw_quat(heading_angle),
        friction,
        0.2,
    )
}

/// A moving copy of a catalog object that is not the hazard (a neighbour in a stack or a
/// row): same parts and physics, role `Prop`.
pub fn prop_copy(
    object: &Object,
    name: &str,
    position: Vec3,
    rotation: Quat,
    linvel: Vec3,
) -> BodySpec {
    BodySpec {
        name: name.to_string(),
        role: BodyRole::Prop,
        ..hazard_body(object, position, rotation, linvel, [0.0; 3])
    }
}

/// A dynamic plain box that is not the hazard (a trigger block).
#[allow(clippy::too_many_arguments)]
pub fn prop_box(
    name: &str,
    half_extents: Vec3,
    position: Vec3,
    rotation: Quat,
    mass: f64,
    friction: f64,
    restitution: f64,
    linvel: Vec3,
) -> BodySpec {
    BodySpec {
        name: name.to_string(),
        role: BodyRole::Prop,
        kind: BodyKind::Dynamic,
        catalog_id: None,
        parts: vec![PartSpec {
            shape: ShapeSpec::Box { half_extents },
            offset: [0.0; 3],
            rotation: IDENTITY,
        }],
        position,
        rotation,
        mass,
        friction,
        restitution,
        linvel,
        angvel: [0.0; 3],
        ccd: true,
        push_mass: None,
    }
}

/// World z component of a body's local z axis (1 upright, 0 lying on its side).
pub fn up_z(rotation: [f32; 4]) -> f64 {
    let [x, y, _, _] = rotation.map(f64::from);
    1.0 - 2.0 * (x * x + y * y)
}

/// Index among `sim.dynamic_bodies` of spec body `body`.
pub fn slot_of(sim: &Simulation, body: usize) -> Option<usize> {
    sim.dynamic_bodies.iter().position(|&i| i == body)
}

/// Whether the object rests in its natural pose on a flat face (not on a round cap or
/// a single sphere, which roll or balance).
pub fn is_single_sphere(object: &Object) -> bool {
    object.parts.len() == 1 && object.parts[0].shape == ShapeKind::Sphere
}

/// The hazard's largest distance from its start position over the run (m).
pub fn max_displacement(sim: &Simulation) -> f64 {
    let a = sim.hazard_position(0);
    (0..=sim.steps())
        .map(|k| {
            let b = sim.hazard_position(k);
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

/// Extra distance to shift an event away from its observer's side of the room when the
/// observer stands far (so that the far observer still stands inside the room). Depends
/// on the group's `far_observer`, never on the band.
pub fn far_shift(input: &FamilyInput) -> f64 {
    if input.far_observer {
        1.0
    } else {
        0.0
    }
}

/// The hazard's speed at the end of the run is small and it touched the floor.
pub fn reached_floor(spec: &SceneSpec, sim: &Simulation) -> bool {
    sim.time_to_floor_step(spec.labels.floor_contact_eps)
        .is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rh_catalog::Catalog;
    use rh_physics::seeds;

    /// The band contract: layouts of the four bands differ only in velocities.
    #[test]
    fn samplers_draw_the_same_layout_at_every_speed() {
        let catalog = Catalog::embedded().unwrap();
        for family in all() {
            let object = catalog.objects_for_family(family.name()).next().unwrap();
            let room = &catalog.rooms[0];
            let layouts: Vec<Layout> = [0.3, 2.0]
                .iter()
                .map(|&speed| {
                    let input = FamilyInput {
                        object,
                        room,
                        speed,
                        band_speeds: [0.3, 0.6, 1.0, 2.0],
                        far_observer: false,
                        observer_height: 1.32,
                        intent: crate::intent::Intent::Hands,
                    };
                    family.sample(&input, &mut seeds::stream(11, 0, "placement"))
                })
                .collect();
            // A timed family (a thrown object, a ball rolled to leave the edge at a drawn
            // time…) starts the body it sets in motion where the speed says; a throw's
            // elevation, release point and range follow from the speed.
            let strip = |l: &Layout| {
                let mut l = l.clone();
                for b in &mut l.bodies {
                    let moving = b.linvel != [0.0; 3];
                    b.linvel = [0.0; 3];
                    b.angvel = [0.0; 3];
                    if family.timed() && moving {
                        b.position = [0.0; 3];
                    }
                }
                let timing = [
                    "com_behind_edge_m",
                    "com_to_ledge_end_m",
                    "trigger_gap_m",
                    "run_up_m",
                    "slide_distance_m",
                ];
                if family.timed() {
                    l.params.retain(|k, _| !timing.contains(&k.as_str()));
                }
                l.params.retain(|k, _| !k.contains("elevation"));
                l.params
                    .retain(|k, _| k != "throw_distance_m" && k != "flight_s");
                // door_swing records the push impulse that gives its door the band's edge
                // speed (`J = I_hinge·v/w²`): a momentum, like the velocities above.
                l.params.retain(|k, _| k != "push_impulse_ns");
                l
            };
            assert_eq!(
                strip(&layouts[0]),
                strip(&layouts[1]),
                "{} layout depends on speed",
                family.name()
            );
        }
    }
}
