//! Stage 3 — simulate: rapier3d (enhanced determinism) at the spec's fixed dt.
//!
//! `simulate(&spec, options)` builds the world from plain spec numbers, steps it until
//! the scene settles or the horizon, and returns the per-step state of every dynamic
//! body, the hazard's contacts and energy, and a SHA-256 hash of the whole per-step
//! state. The same spec gives the same hash in any process, thread count or shard: a
//! scene is simulated single-threaded, and nothing here reads a clock or a hash map.

use crate::spec::{BodyKind, JointKind, ObserverSpec, PartSpec, SceneSpec, ShapeSpec};
use rapier3d::prelude::*;
use sha2::{Digest, Sha256};

/// Contact flags of the hazard at one step.
pub const TOUCH_FLOOR: u8 = 1;
pub const TOUCH_SOURCE: u8 = 2;
pub const TOUCH_OTHER: u8 = 4;
pub const TOUCH_OBSERVER: u8 = 8;

#[derive(Debug, Clone, Copy, Default)]
pub struct SimOptions {
    /// Adds the observer's body as a static collider (the counterfactual of SPEC §6);
    /// the run then stops `strike_window_steps` after the hazard first touches it.
    pub observer_collider: bool,
    /// How long a strike is followed to add up the impulse it delivers (steps).
    pub strike_window_steps: u32,
    /// Keeps simulating after the strike window (until the scene settles or the
    /// horizon) instead of stopping there: the full-event video's run. The strike's
    /// numbers still cover only the window, so they equal the stopping run's.
    pub run_past_strike: bool,
}

/// State of one dynamic body at one step (f32, exactly as the solver holds it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    pub position: [f32; 3],
    pub rotation: [f32; 4],
    pub linvel: [f32; 3],
    pub angvel: [f32; 3],
}

/// The hazard struck the standing observer (counterfactual run).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strike {
    /// First step with an active hazard–observer contact.
    pub step: u32,
    /// Largest speed, relative to the (static) observer, of the hazard's point of contact
    /// just before a contact step, over the strike window (m/s): `v + ω × (p − c)` with
    /// the body's velocities of the previous step and `p` the hazard's point nearest the
    /// observer's body.
    pub speed: f64,
    /// Total normal impulse the observer's body received over the strike window (N·s).
    pub impulse: f64,
}

#[derive(Debug, Clone)]
pub struct Simulation {
    pub dt: f64,
    /// Spec indices of the dynamic bodies, in spec order.
    pub dynamic_bodies: Vec<usize>,
    /// `states[step * dynamic_bodies.len() + j]`; step 0 is the initial state at t0.
    pub states: Vec<BodyState>,
    /// Index of the hazard among `dynamic_bodies`.
    pub hazard_slot: usize,
    /// The hazard's lowest point (m above the floor) per step.
    pub hazard_lowest_z: Vec<f64>,
    /// The hazard's centre of mass (world) per step; labels use it, the hash does not.
    pub hazard_com: Vec<[f64; 3]>,
    /// The hazard's contact flags per step.
    pub hazard_contacts: Vec<u8>,
    /// Total mechanical energy of the dynamic bodies per step (J).
    pub energy: Vec<f64>,
    /// Deepest penetration between any two colliders at t0 (m, ≥ 0).
    pub initial_penetration: f64,
    pub strike: Option<Strike>,
    /// Hex SHA-256 (first 16 bytes) of every dynamic body's state at every step.
    pub state_hash: String,
}

impl Simulation {
    /// Number of steps simulated (states hold `steps() + 1` entries per body).
    pub fn steps(&self) -> u32 {
        (self.hazard_lowest_z.len() - 1) as u32
    }

    pub fn state(&self, step: u32, slot: usize) -> &BodyState {
        &self.states[step as usize * self.dynamic_bodies.len() + slot]
    }

    pub fn hazard_state(&self, step: u32) -> &BodyState {
        self.state(step, self.hazard_slot)
    }

    pub fn hazard_position(&self, step: u32) -> [f64; 3] {
        self.hazard_state(step).position.map(f64::from)
    }

    /// Velocity of the hazard's centre of mass (rapier's linear velocity is the CoM's).
    pub fn hazard_velocity(&self, step: u32) -> [f64; 3] {
        self.hazard_state(step).linvel.map(f64::from)
    }

    /// The hazard's centre of mass (not its body origin, which may sit elsewhere).
    pub fn hazard_com(&self, step: u32) -> [f64; 3] {
        self.hazard_com[step as usize]
    }

    /// The state hash of steps `0..=step` only (`step` ≤ `steps()`): the same SHA-256
    /// over the same numbers, stopped early. At the decision step Δ it is the
    /// `decision_state_hash` column, which `execute` checks its replay against.
    pub fn state_hash_through(&self, step: u32) -> String {
        let mut hasher = Sha256::new();
        let n = (step.min(self.steps()) as usize + 1) * self.dynamic_bodies.len();
        for state in &self.states[..n] {
            state.hash_into(&mut hasher);
        }
        hash_hex(hasher)
    }

    /// First step (≥ 1) whose hazard touches anything.
    pub fn first_contact_step(&self) -> Option<u32> {
        (1..=self.steps()).find(|&k| self.hazard_contacts[k as usize] != 0)
    }

    /// First step (≥ 1) at which the hazard touches the floor, having started above it.
    /// The solver's contacts engage a few millimetres before touching (a fast body can
    /// be held at ~5 mm by continuous collision detection), so a floor contact with the
    /// lowest point within 1 cm counts.
    /// `floor_eps` is `labels.floor_contact_eps`.
    pub fn time_to_floor_step(&self, floor_eps: f64) -> Option<u32> {
        if self.hazard_lowest_z[0] <= floor_eps {
            return None;
        }
        (1..=self.steps()).find(|&k| {
            self.hazard_lowest_z[k as usize] <= floor_eps
                && self.hazard_contacts[k as usize] & TOUCH_FLOOR != 0
        })
    }
}

fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0] as Real, a[1] as Real, a[2] as Real)
}

fn rot(q: [f64; 4]) -> Rotation {
    Rotation::from_xyzw(q[0] as Real, q[1] as Real, q[2] as Real, q[3] as Real).normalize()
}

fn shared_shape(shape: &ShapeSpec) -> SharedShape {
    match *shape {
        ShapeSpec::Box { half_extents: h } => {
            SharedShape::cuboid(h[0] as Real, h[1] as Real, h[2] as Real)
        }
        ShapeSpec::Sphere { radius } => SharedShape::ball(radius as Real),
        // rapier's cylinders and capsules are along local y; the spec's are along z.
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => SharedShape::cylinder(half_height as Real, radius as Real),
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => SharedShape::capsule_y(half_height as Real, radius as Real),
    }
}

/// Extra rotation taking a y-axis primitive to the spec's z axis.
fn axis_fix(shape: &ShapeSpec) -> Rotation {
    match shape {
        ShapeSpec::Cylinder { .. } | ShapeSpec::Capsule { .. } => {
            Rotation::from_axis_angle(Vector::X, std::f32::consts::FRAC_PI_2 as Real)
        }
        _ => Rotation::IDENTITY,
    }
}

/// A body's parts as (pose in the body frame, shape) pairs.
fn posed_parts(parts: &[PartSpec]) -> Vec<(Pose, SharedShape)> {
    parts
        .iter()
        .map(|p| {
            let pose = Pose::from_parts(v3(p.offset), rot(p.rotation) * axis_fix(&p.shape));
            (pose, shared_shape(&p.shape))
        })
        .collect()
}

fn collider_for(parts: &[PartSpec]) -> ColliderBuilder {
    let posed = posed_parts(parts);
    if posed.len() == 1 {
        let (pose, shape) = posed.into_iter().next().expect("one part");
        ColliderBuilder::new(shape).position(pose)
    } else {
        ColliderBuilder::compound(posed)
    }
}

/// The spec's fixed bodies (furniture, walls, stairs) as world-posed shapes, for line-of-
/// sight queries: `Obstacles::blocks` says whether a segment passes through any of them.
pub struct Obstacles {
    parts: Vec<(Pose, SharedShape)>,
}

impl Obstacles {
    pub fn of(spec: &SceneSpec) -> Obstacles {
        let parts = spec
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Fixed)
            .flat_map(|b| {
                let body_pose = Pose::from_parts(v3(b.position), rot(b.rotation));
                posed_parts(&b.parts)
                    .into_iter()
                    .map(move |(pose, shape)| (body_pose * pose, shape))
            })
            .collect();
        Obstacles { parts }
    }

    /// Adds the observer's collision capsule (see `observer_capsule`), its radius widened
    /// by `inflate` (m), as one more obstacle.
    pub fn with_observer(mut self, observer: &ObserverSpec, inflate: f64) -> Obstacles {
        let (centre, half, radius) = observer_capsule(observer, inflate);
        self.parts.push((
            Pose::from_parts(centre, Rotation::IDENTITY),
            SharedShape::capsule_z(half, radius),
        ));
        self
    }

    /// Whether `p` lies inside one of the obstacles.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.parts
            .iter()
            .any(|(pose, shape)| shape.contains_point(pose, v3(p)))
    }

    /// Whether the straight segment from `a` to `b` passes through a fixed body.
    pub fn blocks(&self, a: [f64; 3], b: [f64; 3]) -> bool {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if length < 1e-9 {
            return false;
        }
        let ray = rapier3d::parry::query::Ray::new(v3(a), v3(d.map(|c| c / length)));
        self.parts
            .iter()
            .any(|(pose, shape)| shape.cast_ray(pose, &ray, length as Real, true).is_some())
    }
}

/// The observer's body as a collider (the counterfactual of SPEC §6; the one definition
/// of its geometry): a vertical capsule of the torso radius from the floor to the top of
/// the head, as (centre, half height of the segment, radius); `inflate` widens the radius
/// (line-of-sight queries use it to cover the drawn limbs).
fn observer_capsule(o: &ObserverSpec, inflate: f64) -> (Vector, Real, Real) {
    let radius = o.torso_radius as Real;
    let half = ((o.height as Real) / 2.0 - radius).max(0.0);
    let centre = Vector::new(o.x as Real, o.y as Real, (o.height / 2.0) as Real);
    (centre, half, radius + inflate as Real)
}

/// Height of a collider's lowest point: the tightest of its parts' bounding boxes (a
/// compound's own box is its local box rotated, which can reach far below its parts).
pub(crate) fn lowest_z(collider: &Collider) -> f64 {
    let pose = collider.position();
    match collider.shape().as_compound() {
        Some(compound) => compound
            .shapes()
            .iter()
            .map(|(part_pose, shape)| shape.compute_aabb(&(*pose * *part_pose)).mins.z)
            .fold(Real::MAX, Real::min) as f64,
        None => collider.compute_aabb().mins.z as f64,
    }
}

/// Speed of the hazard's point nearest the observer's body, relative to that (static)
/// body, with the hazard's velocities of the step before `step` (before the contact
/// impulse) and its pose at `step`.
fn contact_point_speed(
    sim: &Simulation,
    step: u32,
    world: &PhysicsWorld,
    hazard: ColliderHandle,
    observer: ColliderHandle,
) -> f64 {
    let (h, o) = (&world.colliders[hazard], &world.colliders[observer]);
    let com = sim.hazard_com(step);
    // The contact query gives the hazard's deepest (or nearest) point even when the
    // shapes overlap; should it find none, the centre of mass stands in.
    let point = match rapier3d::parry::query::contact(
        h.position(),
        h.shape(),
        o.position(),
        o.shape(),
        0.1,
    ) {
        Ok(Some(c)) => [c.point1.x as f64, c.point1.y as f64, c.point1.z as f64],
        _ => com,
    };
    let state = sim.hazard_state(step - 1);
    let v = state.linvel.map(f64::from);
    let w = state.angvel.map(f64::from);
    let r = [point[0] - com[0], point[1] - com[1], point[2] - com[2]];
    let u = [
        v[0] + w[1] * r[2] - w[2] * r[1],
        v[1] + w[2] * r[0] - w[0] * r[2],
        v[2] + w[0] * r[1] - w[1] * r[0],
    ];
    (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
}

const FLOOR_HALF_EXTENT: Real = 50.0;
const FLOOR_HALF_THICKNESS: Real = 0.5;

/// A spec's world as built for stepping: the floor, every body and joint, in spec
/// order — the one place the physics setup lives (`simulate` and `execute` both start
/// from it, so a replay cannot drift from the build).
pub struct SceneWorld {
    pub world: PhysicsWorld,
    pub floor: ColliderHandle,
    /// Per spec body.
    pub body_handles: Vec<RigidBodyHandle>,
    /// Per spec body.
    pub collider_handles: Vec<ColliderHandle>,
    /// Spec indices of the dynamic bodies, in spec order (the hashed state's order).
    pub dynamic_bodies: Vec<usize>,
}

impl SceneWorld {
    /// State of spec body `i` as the solver holds it.
    pub fn body_state(&self, i: usize) -> BodyState {
        state_of(&self.world.bodies[self.body_handles[i]])
    }

    /// Folds every dynamic body's current state into `hasher`, in the state hash's order.
    pub fn hash_step(&self, hasher: &mut Sha256) {
        for &i in &self.dynamic_bodies {
            self.body_state(i).hash_into(hasher);
        }
    }
}

impl BodyState {
    /// The state's 13 numbers, little-endian, in the state hash's order.
    pub fn hash_into(&self, hasher: &mut Sha256) {
        for value in self
            .position
            .iter()
            .chain(&self.rotation)
            .chain(&self.linvel)
            .chain(&self.angvel)
        {
            hasher.update(value.to_le_bytes());
        }
    }
}

/// Hex of the first 16 bytes of a SHA-256 digest (the state hash's format).
pub fn hash_hex(hasher: Sha256) -> String {
    hasher.finalize()[..16]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Builds the spec's world at t0 (no observer). Pure in `spec`.
pub fn build_world(spec: &SceneSpec) -> SceneWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = v3(spec.physics.gravity);
    world.integration_parameters.dt = spec.physics.dt as Real;
    world.integration_parameters.num_solver_iterations = spec.physics.solver_iterations.max(1);

    let floor = world
        .insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, 0.0, -FLOOR_HALF_THICKNESS)),
            ColliderBuilder::cuboid(FLOOR_HALF_EXTENT, FLOOR_HALF_EXTENT, FLOOR_HALF_THICKNESS)
                .friction(spec.room.floor_friction as Real)
                .restitution(spec.room.floor_restitution as Real)
                .friction_combine_rule(CoefficientCombineRule::Average)
                .restitution_combine_rule(CoefficientCombineRule::Average),
        )
        .1;

    let (body_handles, collider_handles) = insert_bodies(&mut world, spec);

    insert_joints(&mut world, spec, &body_handles);
    let dynamic_bodies: Vec<usize> = (0..spec.bodies.len())
        .filter(|&i| spec.bodies[i].kind == BodyKind::Dynamic)
        .collect();
    SceneWorld {
        world,
        floor,
        body_handles,
        collider_handles,
        dynamic_bodies,
    }
}

/// Runs the scene. Pure in `spec` and `options`.
pub fn simulate(spec: &SceneSpec, options: SimOptions) -> Simulation {
    let SceneWorld {
        mut world,
        floor,
        body_handles,
        collider_handles,
        dynamic_bodies,
    } = build_world(spec);

    let observer_collider = options.observer_collider.then(|| {
        let (centre, half, radius) = observer_capsule(&spec.observer, 0.0);
        world
            .insert(
                RigidBodyBuilder::fixed().translation(centre),
                ColliderBuilder::capsule_z(half, radius),
            )
            .1
    });

    let hazard_slot = dynamic_bodies
        .iter()
        .position(|&i| i == spec.hazard)
        .expect("the hazard is a dynamic body");
    let hazard_collider = collider_handles[spec.hazard];
    let source_collider = spec.source_support.map(|i| collider_handles[i]);

    // Penetration at t0, by direct shape queries (a collision pass through the world
    // before the first step would disturb rapier's state).
    let initial_penetration = initial_penetration(&world);

    let gravity = v3(spec.physics.gravity);
    let n_dyn = dynamic_bodies.len();
    let max_steps = spec.physics.max_steps as usize;
    let mut sim = Simulation {
        dt: spec.physics.dt,
        dynamic_bodies: dynamic_bodies.clone(),
        states: Vec::with_capacity((max_steps + 1) * n_dyn),
        hazard_slot,
        hazard_lowest_z: Vec::with_capacity(max_steps + 1),
        hazard_com: Vec::with_capacity(max_steps + 1),
        hazard_contacts: Vec::with_capacity(max_steps + 1),
        energy: Vec::with_capacity(max_steps + 1),
        initial_penetration,
        strike: None,
        state_hash: String::new(),
    };
    let mut hasher = Sha256::new();
    let mut calm_steps = 0u32;

    for step in 0..=spec.physics.max_steps {
        if step > 0 {
            world.step();
        }
        // Record every dynamic body's state and fold it into the hash.
        let mut energy = 0.0f64;
        for &i in &dynamic_bodies {
            let rb = &world.bodies[body_handles[i]];
            let state = state_of(rb);
            state.hash_into(&mut hasher);
            sim.states.push(state);
            let com = rb.center_of_mass();
            energy += rb.kinetic_energy() as f64 - rb.mass() as f64 * (gravity.dot(com) as f64);
        }
        sim.energy.push(energy);
        sim.hazard_lowest_z
            .push(lowest_z(&world.colliders[hazard_collider]));
        let com = world.bodies[body_handles[spec.hazard]].center_of_mass();
        sim.hazard_com
            .push([com.x as f64, com.y as f64, com.z as f64]);

        let flags = hazard_contact_flags(
            &world,
            hazard_collider,
            floor,
            source_collider,
            observer_collider,
        );
        sim.hazard_contacts.push(flags);

        if step == 0 {
            continue;
        }
        if let Some(observer) = observer_collider {
            let window = options.strike_window_steps;
            let window_over =
                track_strike(&mut sim, step, &world, hazard_collider, observer, window);
            if window_over && !options.run_past_strike {
                break;
            }
        }
        let calm = dynamic_bodies.iter().all(|&i| {
            let rb = &world.bodies[body_handles[i]];
            (rb.linvel().length() as f64) < spec.physics.settle_speed
                && (rb.angvel().length() as f64) < spec.physics.settle_speed * 10.0
        });
        calm_steps = if calm { calm_steps + 1 } else { 0 };
        if step >= spec.physics.min_steps && calm_steps >= spec.physics.settle_steps {
            break;
        }
    }
    sim.state_hash = hash_hex(hasher);
    sim
}

fn state_of(rb: &RigidBody) -> BodyState {
    let t = rb.translation();
    let q = rb.rotation();
    let v = rb.linvel();
    let w = rb.angvel();
    BodyState {
        position: [t.x, t.y, t.z],
        rotation: [q.x, q.y, q.z, q.w],
        linvel: [v.x, v.y, v.z],
        angvel: [w.x, w.y, w.z],
    }
}

/// Inserts every body of the spec with its collider, in spec order.
fn insert_bodies(
    world: &mut PhysicsWorld,
    spec: &SceneSpec,
) -> (Vec<RigidBodyHandle>, Vec<ColliderHandle>) {
    let mut body_handles = Vec::with_capacity(spec.bodies.len());
    let mut collider_handles = Vec::with_capacity(spec.bodies.len());
    for b in &spec.bodies {
        let builder = match b.kind {
            BodyKind::Fixed => RigidBodyBuilder::fixed(),
            BodyKind::Dynamic => RigidBodyBuilder::dynamic()
                .linvel(v3(b.linvel))
                .angvel(v3(b.angvel))
                .ccd_enabled(b.ccd)
                // Never frozen by the sleep heuristic (an object balanced on an edge must
                // tip); `simulate` stops by its own settle rule instead.
                .can_sleep(false),
        }
        .pose(Pose::from_parts(v3(b.position), rot(b.rotation)));
        let mut collider = collider_for(&b.parts)
            .friction(b.friction as Real)
            .restitution(b.restitution as Real)
            .friction_combine_rule(CoefficientCombineRule::Average)
            .restitution_combine_rule(CoefficientCombineRule::Average);
        if b.kind == BodyKind::Dynamic {
            collider = collider.mass(b.mass as Real);
        }
        let (bh, ch) = world.insert(builder, collider);
        body_handles.push(bh);
        collider_handles.push(ch);
    }
    (body_handles, collider_handles)
}

/// Inserts the spec's joints, in spec order; a world anchor is a fixed body at the origin.
fn insert_joints(world: &mut PhysicsWorld, spec: &SceneSpec, body_handles: &[RigidBodyHandle]) {
    let mut world_anchor = None;
    for j in &spec.joints {
        let a = match j.body_a {
            Some(i) => body_handles[i],
            None => {
                *world_anchor.get_or_insert_with(|| world.bodies.insert(RigidBodyBuilder::fixed()))
            }
        };
        let b = body_handles[j.body_b];
        let joint: GenericJoint = match &j.kind {
            JointKind::Revolute { axis } => RevoluteJointBuilder::new(v3(*axis).normalize())
                .local_anchor1(v3(j.anchor_a))
                .local_anchor2(v3(j.anchor_b))
                .into(),
            JointKind::Spherical => SphericalJointBuilder::new()
                .local_anchor1(v3(j.anchor_a))
                .local_anchor2(v3(j.anchor_b))
                .into(),
            JointKind::Rope { max_length } => RopeJointBuilder::new(*max_length as Real)
                .local_anchor1(v3(j.anchor_a))
                .local_anchor2(v3(j.anchor_b))
                .into(),
        };
        world.impulse_joints.insert(a, b, joint, true);
    }
}

/// The deepest penetration between two colliders (not both fixed) before the first step.
fn initial_penetration(world: &PhysicsWorld) -> f64 {
    let mut initial_penetration: f64 = 0.0;
    let colliders: Vec<&Collider> = world.colliders.iter().map(|(_, c)| c).collect();
    for (i, a) in colliders.iter().enumerate() {
        for b in &colliders[i + 1..] {
            let both_fixed = [a, b].iter().all(|c| {
                c.parent()
                    .is_none_or(|p| world.bodies[p].body_type() == RigidBodyType::Fixed)
            });
            if both_fixed {
                continue;
            }
            if let Ok(Some(contact)) = rapier3d::parry::query::contact(
                a.position(),
                a.shape(),
                b.position(),
                b.shape(),
                0.0,
            ) {
                initial_penetration = initial_penetration.max(-(contact.dist as f64));
            }
        }
    }
    initial_penetration
}

/// The hazard's active contacts this step, as `TOUCH_*` flags.
/// Follows a strike of the standing observer (counterfactual run) at `step`: opens it at
/// the first contact, keeps the largest contact-point speed and adds up the impulse.
/// Returns true once the strike window is over (the run can stop).
fn track_strike(
    sim: &mut Simulation,
    step: u32,
    world: &PhysicsWorld,
    hazard: ColliderHandle,
    observer: ColliderHandle,
    window_steps: u32,
) -> bool {
    if sim.strike.is_some_and(|s| step > s.step + window_steps) {
        return true;
    }
    if sim.hazard_contacts[step as usize] & TOUCH_OBSERVER != 0 {
        let speed = contact_point_speed(sim, step, world, hazard, observer);
        let strike = sim.strike.get_or_insert(Strike {
            step,
            speed: 0.0,
            impulse: 0.0,
        });
        strike.speed = strike.speed.max(speed);
    }
    match sim.strike.as_mut() {
        Some(strike) => {
            strike.impulse += contact_impulse(world, hazard, observer);
            step >= strike.step + window_steps
        }
        None => false,
    }
}

/// Total normal impulse between two colliders in the last step (N·s).
pub(crate) fn contact_impulse(world: &PhysicsWorld, a: ColliderHandle, b: ColliderHandle) -> f64 {
    world
        .narrow_phase
        .contact_pair(a, b)
        .filter(|pair| pair.has_any_active_contact())
        .map_or(0.0, |pair| pair.total_impulse_magnitude() as f64)
}

fn hazard_contact_flags(
    world: &PhysicsWorld,
    hazard_collider: ColliderHandle,
    floor: ColliderHandle,
    source_collider: Option<ColliderHandle>,
    observer_collider: Option<ColliderHandle>,
) -> u8 {
    let mut flags = 0u8;
    for pair in world.narrow_phase.contact_pairs_with(hazard_collider) {
        if !pair.has_any_active_contact() {
            continue;
        }
        let other = if pair.collider1 == hazard_collider {
            pair.collider2
        } else {
            pair.collider1
        };
        flags |= if other == floor {
            TOUCH_FLOOR
        } else if Some(other) == source_collider {
            TOUCH_SOURCE
        } else if Some(other) == observer_collider {
            TOUCH_OBSERVER
        } else {
            TOUCH_OTHER
        };
    }
    flags
}

/// The deepest any dynamic body of `sim` sinks into the standing observer's body — the
/// static capsule of the counterfactual run (`simulate` with `observer_collider`) —
/// over the whole run (m; 0 when nothing touches it). In the plain run the observer is
/// no body and a hazard may pass through it; in the counterfactual run it stays out up
/// to the solver's contact tolerance (millimetres).
pub fn observer_penetration(spec: &SceneSpec, sim: &Simulation) -> f64 {
    // The same capsule, at the same place, as the counterfactual's static collider.
    let (centre, half, radius) = observer_capsule(&spec.observer, 0.0);
    let capsule = SharedShape::capsule_z(half, radius);
    let capsule_pose = Pose::from_translation(centre);
    let parts: Vec<Vec<(Pose, SharedShape)>> = sim
        .dynamic_bodies
        .iter()
        .map(|&b| posed_parts(&spec.bodies[b].parts))
        .collect();
    let mut deepest = 0.0f64;
    for step in 0..=sim.steps() {
        for (slot, body_parts) in parts.iter().enumerate() {
            let s = sim.state(step, slot);
            let body_pose = Pose::from_parts(
                Vector::new(s.position[0], s.position[1], s.position[2]),
                Rotation::from_xyzw(s.rotation[0], s.rotation[1], s.rotation[2], s.rotation[3]),
            );
            for (part_pose, shape) in body_parts {
                let pose = body_pose * *part_pose;
                let contact = rapier3d::parry::query::contact(
                    &capsule_pose,
                    capsule.as_ref(),
                    &pose,
                    shape.as_ref(),
                    0.0,
                );
                if let Ok(Some(c)) = contact {
                    deepest = deepest.max(-(c.dist as f64));
                }
            }
        }
    }
    deepest
}
