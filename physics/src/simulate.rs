//! Stage 3 — simulate: rapier3d (enhanced determinism) at the spec's fixed dt.
//!
//! `simulate(&spec, options)` builds the world from plain spec numbers, steps it until
//! the scene settles or the horizon, and returns the per-step state of every dynamic
//! body, the hazard's contacts and energy, and a SHA-256 hash of the whole per-step
//! state. The same spec gives the same hash in any process, thread count or shard: a
//! scene is simulated single-threaded, and nothing here reads a clock or a hash map.

use crate::body::{Geometry, LinkShape, Part, BODY_FRICTION, BODY_RESTITUTION};
use crate::shapes::{link_shape, posed_parts, rot, v3};
use crate::spec::{ObserverSpec, SceneSpec};
use crate::strike::{touch_at, HarmRule, Region, StrikeMonitor};
use rapier3d::prelude::*;
use sha2::{Digest, Sha256};

/// Contact flags of the hazard at one step.
pub const TOUCH_FLOOR: u8 = 1;
pub const TOUCH_SOURCE: u8 = 2;
pub const TOUCH_OTHER: u8 = 4;
pub const TOUCH_OBSERVER: u8 = 8;

#[derive(Debug, Clone, Copy, Default)]
pub struct SimOptions {
    /// Adds the observer's body — the humanoid's thirteen links standing at rest
    /// ([`observer_links`]) — as fixed colliders (the counterfactual of specification §6); the run
    /// then follows the strike test (`crate::strike`, thresholds from `spec.labels`) and
    /// stops at the end of a strike's window.
    pub observer_collider: bool,
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

/// The hazard touched the standing observer (counterfactual run): the harming window
/// (`crate::strike`) if the harm test passed, else the first touch's window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strike {
    /// First step of the window (the touch that opened it).
    pub step: u32,
    /// First step with an active hazard–body contact at all (≤ `step`).
    pub first_touch: u32,
    /// Largest speed, relative to the (static) body, of the hazard's point of contact
    /// just before a contact step, over the window (m/s): `v + ω × (p − c)` with the
    /// hazard's velocities of the previous step ([`touch_at`]).
    pub speed: f64,
    /// Total normal impulse the body's links received over the window (N·s).
    pub impulse: f64,
    /// The link that took the most of it.
    pub part: Part,
    /// The harm test's verdict on the window (rule v5): the worst body region, its
    /// largest transient energy (J) and sustained force (N), their larger ratio to the
    /// region's limits, and whether the window harms (ratio ≥ 1, or a sharp or hot
    /// hazard's touch).
    pub region: Region,
    pub energy: f64,
    pub force: f64,
    pub ratio: f64,
    pub harm: bool,
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
    /// A plain run's world every [`SNAPSHOT_STEPS`] steps, where [`counterfactual`] may
    /// start (empty for other runs; shared by clones).
    pub snapshots: Snapshots,
}

/// A plain run keeps its world every this many steps (0.2 s at 1/240 s): the latest one
/// before anything comes near the observer is where its counterfactual run starts.
pub const SNAPSHOT_STEPS: u32 = 48;

/// The worlds a plain run kept, by step ([`SNAPSHOT_STEPS`] apart, from that step on).
#[derive(Clone, Default)]
pub struct Snapshots(std::sync::Arc<Vec<SceneWorld>>);

impl Snapshots {
    /// The world kept at `step` (a positive multiple of [`SNAPSHOT_STEPS`]), forked.
    fn at(&self, step: u32) -> Option<SceneWorld> {
        let i = (step / SNAPSHOT_STEPS).checked_sub(1)? as usize;
        (step % SNAPSHOT_STEPS == 0)
            .then(|| self.0.get(i))
            .flatten()
            .map(fork_world)
    }
}

impl std::fmt::Debug for Snapshots {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Snapshots({} worlds)", self.0.len())
    }
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

pub use crate::world::{build_world, fork_world, SceneWorld};
pub use rh_contract::execution::hash_hex;

/// Runs the scene. Pure in `spec` and `options`.
pub fn simulate(spec: &SceneSpec, options: SimOptions) -> Simulation {
    run(spec, options, None)
}

/// The counterfactual run of `spec` (`options` with `observer_collider`) given its plain
/// run `plain` and the first step `near` at which some dynamic body comes near enough to
/// the observer's body to touch it: until then the observer's static colliders change
/// nothing, so the run is the plain run up to the last [`SNAPSHOT_STEPS`] multiple
/// before `near` and goes on from a fork of the world kept there, with the observer
/// added (from t0 when that multiple is 0). Pure in (`spec`, `options`, `near`): where
/// `plain` kept no world there, the plain run is replayed to that step.
pub fn counterfactual(
    spec: &SceneSpec,
    plain: &Simulation,
    near: u32,
    options: SimOptions,
) -> Simulation {
    let start = resume_step(near);
    if !options.observer_collider || start == 0 || start >= plain.steps() {
        return simulate(spec, options);
    }
    let world = plain
        .snapshots
        .at(start)
        .unwrap_or_else(|| fork_world(&replay_to(spec, start)));
    run(
        spec,
        options,
        Some(Resume {
            world,
            step: start,
            plain,
        }),
    )
}

/// The step a counterfactual run whose bodies first come near the observer at step `near`
/// resumes its plain run from: the last multiple of [`SNAPSHOT_STEPS`] before it (0: the
/// run starts at t0).
pub fn resume_step(near: u32) -> u32 {
    near.saturating_sub(1) / SNAPSHOT_STEPS * SNAPSHOT_STEPS
}

/// The plain world of `spec` stepped `steps` times.
fn replay_to(spec: &SceneSpec, steps: u32) -> SceneWorld {
    let mut sw = build_world(spec);
    for _ in 0..steps {
        sw.step();
    }
    sw
}

/// Where a counterfactual run starts when not at t0: the world at plain step `step`
/// (forked) and the plain run, whose steps `0..=step` it shares.
struct Resume<'a> {
    world: SceneWorld,
    step: u32,
    plain: &'a Simulation,
}

fn run(spec: &SceneSpec, options: SimOptions, resume: Option<Resume>) -> Simulation {
    let (mut sw, prefix) = match resume {
        Some(Resume { world, step, plain }) => (world, Some((plain, step))),
        None => (build_world(spec), None),
    };
    let first_step = prefix.map_or(0, |(_, step)| step + 1);
    let observer: Vec<ColliderHandle> = if options.observer_collider {
        insert_observer(&mut sw.world, &spec.observer)
    } else {
        Vec::new()
    };
    let mut strikes = StrikeMonitor::new(
        HarmRule::of_labels(&spec.labels, &spec.hazard_flags, spec.physics.dt),
        observer.len(),
    );
    let link_shapes = Geometry::of(&spec.observer).shapes();
    let hazard_collider = sw.collider_handles[spec.hazard];
    let source_collider = spec.source_support.map(|i| sw.collider_handles[i]);

    // Penetration at t0, by direct shape queries (a collision pass through the world
    // before the first step would disturb rapier's state); a resumed run's is its plain
    // run's (nothing was near the observer's body then).
    let initial_penetration = match prefix {
        Some((plain, _)) => plain.initial_penetration,
        None => initial_penetration(&sw.world),
    };
    let mut sim = Simulation::empty(spec, sw.dynamic_bodies.clone(), initial_penetration);
    let mut hasher = Sha256::new();
    let mut calm_steps = 0u32;
    if let Some((plain, step)) = prefix {
        calm_steps = sim.resume_from(spec, plain, step, &mut hasher);
    }
    // A plain run keeps its world at Δ for this thread's escape walks (`decision_world`),
    // and every SNAPSHOT_STEPS steps for its counterfactual (`counterfactual`).
    let keep_at = (!options.observer_collider).then(|| spec.decision_step());
    let mut snapshots = Vec::new();

    for step in first_step..=spec.physics.max_steps {
        if step > 0 {
            sw.step();
        }
        if keep_at.is_some() && step > 0 && step % SNAPSHOT_STEPS == 0 {
            snapshots.push(fork_world(&sw));
        }
        sim.record(spec, &sw, &mut hasher);
        let flags = hazard_contact_flags(
            &sw.world,
            hazard_collider,
            sw.floor,
            source_collider,
            &observer,
        );
        sim.hazard_contacts.push(flags);
        if keep_at == Some(step) {
            keep_decision_world(spec, fork_world(&sw), hash_hex(hasher.clone()));
        }

        if step == 0 {
            continue;
        }
        if !observer.is_empty() {
            follow_strike(
                &mut strikes,
                &sim,
                step,
                &sw.world,
                hazard_collider,
                &observer,
                &link_shapes,
            );
            if strikes.strike_over(step) && !options.run_past_strike {
                break;
            }
        }
        let calm = sw
            .dynamic_bodies
            .iter()
            .all(|&i| calm(spec, &sw.body_state(i)));
        calm_steps = if calm { calm_steps + 1 } else { 0 };
        if step >= spec.physics.min_steps && calm_steps >= spec.physics.settle_steps {
            break;
        }
    }
    sim.state_hash = hash_hex(hasher);
    sim.snapshots = Snapshots(std::sync::Arc::new(snapshots));
    sim.strike = strike_of(&strikes);
    sim
}

/// The strike a counterfactual run records ([`StrikeMonitor::report`] with its verdict).
fn strike_of(strikes: &StrikeMonitor) -> Option<Strike> {
    strikes.report().map(|w| {
        let v = strikes.rule().judge(w);
        Strike {
            step: w.start,
            first_touch: strikes.first_touch().unwrap_or(w.start),
            speed: w.speed,
            impulse: w.impulse,
            part: Part::ALL[w.heaviest_part()],
            region: v.region,
            energy: v.energy,
            force: v.force,
            ratio: v.ratio,
            harm: v.harm,
        }
    })
}

/// Whether a body in state `b` is still for the settle rule.
fn calm(spec: &SceneSpec, b: &BodyState) -> bool {
    still(
        Vector::from(b.linvel),
        Vector::from(b.angvel),
        spec.physics.settle_speed,
    )
}

/// Whether a body moving at `linvel` and turning at `angvel` is still: slower than
/// `settle_speed` (m/s) and turning slower than ten times that (rad/s). The settle rule
/// of `simulate` and of the executor (`execute::outcome`, its own `settle_speed`).
pub(crate) fn still(linvel: Vector, angvel: Vector, settle_speed: f64) -> bool {
    (linvel.length() as f64) < settle_speed && (angvel.length() as f64) < settle_speed * 10.0
}

impl Simulation {
    /// A run of `spec` with nothing recorded yet (room for its horizon).
    fn empty(spec: &SceneSpec, dynamic_bodies: Vec<usize>, initial_penetration: f64) -> Self {
        let hazard_slot = dynamic_bodies
            .iter()
            .position(|&i| i == spec.hazard)
            .expect("the hazard is a dynamic body");
        let steps = spec.physics.max_steps as usize + 1;
        Simulation {
            dt: spec.physics.dt,
            states: Vec::with_capacity(steps * dynamic_bodies.len()),
            dynamic_bodies,
            hazard_slot,
            hazard_lowest_z: Vec::with_capacity(steps),
            hazard_com: Vec::with_capacity(steps),
            hazard_contacts: Vec::with_capacity(steps),
            energy: Vec::with_capacity(steps),
            initial_penetration,
            strike: None,
            state_hash: String::new(),
            snapshots: Snapshots::default(),
        }
    }

    /// Records this step of `sw` (not its contacts): every dynamic body's state, folded
    /// into `hasher`, their mechanical energy, the hazard's lowest point and centre of mass.
    fn record(&mut self, spec: &SceneSpec, sw: &SceneWorld, hasher: &mut Sha256) {
        let gravity = v3(spec.physics.gravity);
        let mut energy = 0.0f64;
        for &i in &sw.dynamic_bodies {
            let rb = &sw.world.bodies[sw.body_handles[i]];
            let state = state_of(rb);
            state.hash_into(hasher);
            self.states.push(state);
            let com = rb.center_of_mass();
            energy += rb.kinetic_energy() as f64 - rb.mass() as f64 * (gravity.dot(com) as f64);
        }
        self.energy.push(energy);
        self.hazard_lowest_z.push(lowest_z(
            &sw.world.colliders[sw.collider_handles[spec.hazard]],
        ));
        let com = sw.world.bodies[sw.body_handles[spec.hazard]].center_of_mass();
        self.hazard_com
            .push([com.x as f64, com.y as f64, com.z as f64]);
    }

    /// Takes steps `0..=step` of `plain` (a counterfactual run resumed there): the
    /// records, their states folded into `hasher`; returns the settle rule's count of
    /// calm steps at `step`.
    fn resume_from(
        &mut self,
        spec: &SceneSpec,
        plain: &Simulation,
        step: u32,
        hasher: &mut Sha256,
    ) -> u32 {
        let k = step as usize + 1;
        let n = self.dynamic_bodies.len();
        self.states.extend_from_slice(&plain.states[..k * n]);
        for state in &self.states {
            state.hash_into(hasher);
        }
        self.energy.extend_from_slice(&plain.energy[..k]);
        self.hazard_lowest_z
            .extend_from_slice(&plain.hazard_lowest_z[..k]);
        self.hazard_com.extend_from_slice(&plain.hazard_com[..k]);
        self.hazard_contacts
            .extend_from_slice(&plain.hazard_contacts[..k]);
        // Step 0 is never counted (the loop judges steps from 1 on).
        (1..k)
            .rev()
            .take_while(|&j| {
                self.states[j * n..(j + 1) * n]
                    .iter()
                    .all(|b| calm(spec, b))
            })
            .count() as u32
    }
}

/// How many worlds at Δ a thread keeps (a group's four bands, with room to spare).
const DECISION_WORLDS_KEPT: usize = 16;

thread_local! {
    /// The worlds at Δ of this thread's latest plain runs, newest last, each under
    /// [`decision_key`] with the state hash of steps `0..=Δ`.
    static DECISION_WORLDS: std::cell::RefCell<Vec<(String, SceneWorld, String)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// What the world at Δ is a function of: the spec without what a plain run never reads
/// (the observer's place, the cameras, `family_params`), which is all an aimed or framed
/// copy of a simulated spec changes. Any other difference misses the cache.
fn decision_key(spec: &SceneSpec) -> String {
    let mut s = spec.clone();
    (s.observer.x, s.observer.y, s.observer.yaw) = (0.0, 0.0, 0.0);
    s.cameras.clear();
    s.family_params.clear();
    serde_json::to_string(&s).expect("a spec serializes")
}

/// Keeps the world of a plain run at Δ (see [`decision_world`]) with the state hash of
/// steps `0..=Δ`.
fn keep_decision_world(spec: &SceneSpec, world: SceneWorld, hash: String) {
    let entry = (decision_key(spec), world, hash);
    DECISION_WORLDS.with_borrow_mut(|kept| {
        kept.retain(|(k, _, _)| *k != entry.0);
        if kept.len() >= DECISION_WORLDS_KEPT {
            kept.remove(0);
        }
        kept.push(entry);
    });
}

/// The world at `spec`'s decision moment Δ and the state hash of steps `0..=Δ`, if a plain
/// run of this thread simulated it lately: bit for bit what stepping `build_world(spec)`
/// Δ times gives (the same world, stepped the same way), so an escape walk started from
/// it is the walk started from a fresh replay. `None`: replay it.
pub fn decision_world(spec: &SceneSpec) -> Option<(SceneWorld, String)> {
    let key = decision_key(spec);
    DECISION_WORLDS.with_borrow(|kept| {
        kept.iter()
            .rev()
            .find(|(k, _, _)| *k == key)
            .map(|(_, w, h)| (fork_world(w), h.clone()))
    })
}

/// The observer's body as the counterfactual of specification §6 strikes it: the humanoid
/// (`execute::humanoid`, specification §2 proportions) standing at its pose with no knee bend and
/// the palms at rest — exactly the executor's body under the `freeze` plan — as world
/// poses and shapes of its thirteen links, in [`Part::ALL`] order. The one definition of
/// the body that can be struck: the label's counterfactual run, the executor and
/// [`observer_penetration`] all use it.
pub fn observer_links(o: &ObserverSpec) -> Vec<(Pose, SharedShape)> {
    let geometry = Geometry::of(o);
    let poses = geometry.link_poses(&geometry.rest_pose([o.x, o.y, o.yaw]));
    poses
        .iter()
        .zip(geometry.shapes())
        .map(|(p, shape)| {
            let q = p.rotation;
            let pose = Pose::from_parts(v3(p.position), rot(q));
            (pose, link_shape(shape))
        })
        .collect()
}

/// Inserts [`observer_links`] as fixed bodies (one per link, the body's surface
/// `BODY_FRICTION` / `BODY_RESTITUTION`); returns their colliders in [`Part::ALL`] order.
fn insert_observer(world: &mut PhysicsWorld, o: &ObserverSpec) -> Vec<ColliderHandle> {
    observer_links(o)
        .into_iter()
        .map(|(pose, shape)| {
            world
                .insert(
                    RigidBodyBuilder::fixed().pose(pose),
                    ColliderBuilder::new(shape)
                        .friction(BODY_FRICTION as Real)
                        .restitution(BODY_RESTITUTION as Real)
                        .friction_combine_rule(CoefficientCombineRule::Average)
                        .restitution_combine_rule(CoefficientCombineRule::Average),
                )
                .1
        })
        .collect()
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

/// Feeds the harm test (counterfactual run) with this step's touches of the standing
/// body: per touched link its region, contact-point speeds, the hazard's effective mass
/// there and the impulse the link received.
fn follow_strike(
    strikes: &mut StrikeMonitor,
    sim: &Simulation,
    step: u32,
    world: &PhysicsWorld,
    hazard: ColliderHandle,
    observer: &[ColliderHandle],
    shapes: &[LinkShape; 13],
) {
    let before = sim.hazard_state(step - 1);
    let velocities = (
        Vector::from(before.linvel.map(|x| x as Real)),
        Vector::from(before.angvel.map(|x| x as Real)),
    );
    let touches: Vec<_> = observer
        .iter()
        .enumerate()
        .filter(|&(_, &link)| {
            world
                .narrow_phase
                .contact_pair(hazard, link)
                .is_some_and(|pair| pair.has_any_active_contact())
        })
        .map(|(i, &link)| {
            let mut t = touch_at(world, hazard, velocities, link, Part::ALL[i], shapes[i]);
            t.impulse = contact_impulse(world, hazard, link);
            t
        })
        .collect();
    strikes.step(step, &touches);
}

/// Total normal impulse between two colliders in the last step (N·s).
pub(crate) fn contact_impulse(world: &PhysicsWorld, a: ColliderHandle, b: ColliderHandle) -> f64 {
    world
        .narrow_phase
        .contact_pair(a, b)
        .filter(|pair| pair.has_any_active_contact())
        .map_or(0.0, |pair| pair.total_impulse_magnitude() as f64)
}

/// The contact pairs of collider `c` with an active contact this step, each with the
/// other collider.
pub fn active_contacts(
    world: &PhysicsWorld,
    c: ColliderHandle,
) -> impl Iterator<Item = (&ContactPair, ColliderHandle)> {
    world
        .narrow_phase
        .contact_pairs_with(c)
        .filter(|pair| pair.has_any_active_contact())
        .map(move |pair| {
            let other = if pair.collider1 == c {
                pair.collider2
            } else {
                pair.collider1
            };
            (pair, other)
        })
}

/// The hazard's active contacts this step, as `TOUCH_*` flags.
fn hazard_contact_flags(
    world: &PhysicsWorld,
    hazard_collider: ColliderHandle,
    floor: ColliderHandle,
    source_collider: Option<ColliderHandle>,
    observer: &[ColliderHandle],
) -> u8 {
    let mut flags = 0u8;
    for (_, other) in active_contacts(world, hazard_collider) {
        flags |= if other == floor {
            TOUCH_FLOOR
        } else if Some(other) == source_collider {
            TOUCH_SOURCE
        } else if observer.contains(&other) {
            TOUCH_OBSERVER
        } else {
            TOUCH_OTHER
        };
    }
    flags
}

/// The deepest any dynamic body of `sim` sinks into the standing observer's body — the
/// fixed links of the counterfactual run ([`observer_links`]) — over the whole run (m; 0
/// when nothing touches it). In the plain run the observer is no body and a hazard may
/// pass through it; in the counterfactual run it stays out up to the solver's contact
/// tolerance (millimetres).
pub fn observer_penetration(spec: &SceneSpec, sim: &Simulation) -> f64 {
    // The same links, at the same places, as the counterfactual's fixed colliders.
    let links = observer_links(&spec.observer);
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
                for (link_pose, link) in &links {
                    let contact = rapier3d::parry::query::contact(
                        link_pose,
                        link.as_ref(),
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
    }
    deepest
}
