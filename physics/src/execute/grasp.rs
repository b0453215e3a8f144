//! The grasp model: a real humanoid closes its hands on what it catches.
//!
//! The palms are flat kinematic boxes, and a flat box does not hold what lands on it at
//! speed (the object bounces or rolls off). So, once per execution, at the first step a
//! palm touches the hazard, the executor decides whether that hand closes:
//!
//! * the plan is a catch attempt (it reaches forward ≥ `attempt_reach`, the action rule's
//!   reach test: a dodge or a freeze never grasps), and the hazard has not touched the
//!   floor since Δ;
//! * the speed of the hazard relative to the palm just before the touch is ≤
//!   `grasp_speed_max`, its mass ≤ `grasp_mass_max`, and mass × relative speed ≤
//!   `grasp_momentum_max` (what a hand can stop without being knocked away: the labels'
//!   CATCH limits, `catch_speed_max` and `heavy_mass_kg` / `heavy_momentum`).
//!
//! If so, the hazard is attached to that palm by a rapier fixed joint at their relative
//! pose of that moment (no snap), and the solver stops pushing between the hazard and
//! the hands and forearms (both are moved rigidly with the body; their contacts would
//! only fight the joint); from then on the hazard moves with the hand, and everything
//! else (the other links, the floor, other objects, the scene's own joints) still acts
//! on it. If not, the hand stays
//! open for the rest of the run: an object that arrives too fast or too heavy is never
//! grasped, whatever it does later (it may still rest on the flat palms, see `outcome`).
//!
//! Limits: the grip is rigid once closed (no finger geometry, no grip-force limit, no
//! slip), the decision is made at one instant from the pre-contact relative speed, and
//! only a palm (not a forearm) closes.

use super::ExecConfig;
use crate::body::Part;
use crate::simulate::SceneWorld;
use rapier3d::prelude::*;

/// A closed hand: the palm holding the hazard and the joint that holds it.
#[derive(Debug, Clone, Copy)]
pub struct Grasp {
    /// Index of the palm in [`Part::ALL`].
    pub link: usize,
    pub joint: ImpulseJointHandle,
    /// Step (after Δ) at which the hand closed.
    pub step: u32,
}

/// The grasp decision of one run: undecided until a palm first touches the hazard.
#[derive(Debug, Clone, Copy, Default)]
pub enum GraspState {
    #[default]
    Open,
    Held(Grasp),
    /// A palm touched the hazard but the gate refused (too fast, too heavy, no catch
    /// attempt, or after a floor contact): the hands stay open.
    Refused,
}

impl GraspState {
    pub fn held(&self) -> Option<&Grasp> {
        match self {
            GraspState::Held(g) => Some(g),
            _ => None,
        }
    }
}

/// What the gate looks at when a palm first touches the hazard.
#[derive(Debug, Clone, Copy)]
pub struct Touch {
    pub link: usize,
    /// Speed of the hazard relative to the palm just before the touch (m/s).
    pub speed: f64,
    pub mass: f64,
}

/// Whether the hand closes on `touch` (see the module doc).
pub fn gate(touch: &Touch, attempting: bool, touched_floor: bool, cfg: &ExecConfig) -> bool {
    attempting
        && !touched_floor
        && touch.speed <= cfg.grasp_speed_max
        && touch.mass <= cfg.grasp_mass_max
        && touch.mass * touch.speed <= cfg.grasp_momentum_max
}

/// The palm touching the hazard this step with the fastest relative speed (pre-step
/// hazard velocity `v_before` against the palm's velocity at the hazard's centre).
fn palm_touch(
    sw: &SceneWorld,
    links: &[(RigidBodyHandle, ColliderHandle)],
    hazard_c: ColliderHandle,
    hazard_b: RigidBodyHandle,
    v_before: Vector,
) -> Option<Touch> {
    let world = &sw.world;
    let hazard = &world.bodies[hazard_b];
    let mut best: Option<Touch> = None;
    for (_, other) in crate::simulate::active_contacts(world, hazard_c) {
        let Some(i) = links.iter().position(|(_, c)| *c == other) else {
            continue;
        };
        if !matches!(Part::ALL[i], Part::LeftHand | Part::RightHand) {
            continue;
        }
        let palm = &world.bodies[links[i].0];
        let speed = (v_before - palm.velocity_at_point(hazard.center_of_mass())).length() as f64;
        if best.is_none_or(|b| speed > b.speed) {
            best = Some(Touch {
                link: i,
                speed,
                mass: hazard.mass() as f64,
            });
        }
    }
    best
}

/// Called after every step while the state is [`GraspState::Open`]: at the first palm
/// touch, closes the hand (inserting the joint) or refuses for the rest of the run.
#[allow(clippy::too_many_arguments)]
pub fn update(
    state: &mut GraspState,
    sw: &mut SceneWorld,
    links: &[(RigidBodyHandle, ColliderHandle)],
    hazard_c: ColliderHandle,
    hazard_b: RigidBodyHandle,
    v_before: Vector,
    attempting: bool,
    touched_floor: bool,
    step: u32,
    cfg: &ExecConfig,
) {
    if !matches!(state, GraspState::Open) {
        return;
    }
    let Some(touch) = palm_touch(sw, links, hazard_c, hazard_b, v_before) else {
        return;
    };
    if !gate(&touch, attempting, touched_floor, cfg) {
        *state = GraspState::Refused;
        return;
    }
    let palm_b = links[touch.link].0;
    let palm_pose = *sw.world.bodies[palm_b].position();
    let hazard_pose = *sw.world.bodies[hazard_b].position();
    let joint = FixedJointBuilder::new()
        .local_frame1(Pose::IDENTITY)
        .local_frame2(hazard_pose.inverse() * palm_pose)
        .contacts_enabled(false);
    let handle = sw
        .world
        .impulse_joints
        .insert(palm_b, hazard_b, joint, true);
    // The hazard leaves the group the catching links solve contacts with.
    let held = Group::GROUP_32;
    if let Some(c) = sw.world.colliders.get_mut(hazard_c) {
        c.set_solver_groups(InteractionGroups::new(
            held,
            Group::ALL,
            InteractionTestMode::And,
        ));
    }
    for (i, (_, c)) in links.iter().enumerate() {
        if Part::ALL[i].is_catching() {
            if let Some(c) = sw.world.colliders.get_mut(*c) {
                c.set_solver_groups(InteractionGroups::new(
                    Group::ALL,
                    Group::ALL.difference(held),
                    InteractionTestMode::And,
                ));
            }
        }
    }
    *state = GraspState::Held(Grasp {
        link: touch.link,
        joint: handle,
        step,
    });
}

/// Speed of the hazard relative to the palm holding it (at the hazard's centre), m/s.
pub fn held_speed(
    sw: &SceneWorld,
    links: &[(RigidBodyHandle, ColliderHandle)],
    g: &Grasp,
    hazard_b: RigidBodyHandle,
) -> f64 {
    let world = &sw.world;
    let hazard = &world.bodies[hazard_b];
    let palm = &world.bodies[links[g.link].0];
    (hazard.linvel() - palm.velocity_at_point(hazard.center_of_mass())).length() as f64
}
