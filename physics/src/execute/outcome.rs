//! The execution loop and the outcome rule (versioned with `[execution]` in
//! `configs/scoring.toml`; times are seconds after the decision moment Δ):
//!
//! * `struck` — the harm test of the counterfactual label (`crate::strike`, the same
//!   [`StrikeMonitor`] with the same numbers: the scene's own `labels` — the per-region
//!   limits of ISO/TS 15066 Annex A, the window, a sharp or hot hazard harming at a touch)
//!   on the moving body: within `strike_window_s` of a touch some body region takes a
//!   transient energy or a sustained force over its limit. The part that took the most
//!   impulse, the impulse and the time of the touch are recorded.
//!   While the plan is *reaching* (a palm more than `reaching_offset` from rest,
//!   [`Motion::reaching`]) the hands and forearms are catching, not part of that test:
//!   they count as struck only under a blow of `hand_strike_impulse` or more within the
//!   window (a slamming door, not a caught ball). With the palms at rest they are body
//!   parts like the label's. Once a hand has closed on the hazard ([`super::grasp`]) its
//!   contacts with the hands stop counting.
//! * `caught` — not struck, and the hazard was held: touching the hands/forearms (or
//!   grasped by a closed hand, see [`super::grasp`]), not the floor, moving with the
//!   touching link (relative speed ≤ `hold_speed_max`) for `hold_time_s` without a break,
//!   before it ever touched the floor after Δ. A hazard heavier than `grasp_mass_max` is
//!   never caught (the arms cannot hold it, even balanced on flat palms).
//! * `missed` — neither, but a catch was attempted: the hands/forearms touched the hazard,
//!   or the plan reached out (forward extension ≥ `attempt_reach`) and a hand came within
//!   `attempt_radius` of it.
//! * `clear` — none of these (contacts below the strike threshold may have happened;
//!   `first_contact_t` says).
//!
//! The run stops at the first strike, at a catch, once the hazard lies still on the floor
//! after the plan's last motion (one that started on the floor — a ladder, a wardrobe, a
//! door — once it has stayed still for `settle_time_s`), or at `horizon_s` (at most the
//! scene's own horizon, `physics.max_steps`, where the label's counterfactual stops too).

use super::grasp::{self, GraspState};
use super::motion::{Motion, PlanReference, Reference};
use super::{ExecConfig, ExecFrame, ExecPlan, Outcome, OutcomeKind, StrikeRecord};
use crate::body::{Geometry, LinkShape, Part};
use crate::simulate::{hash_hex, lowest_z, still, SceneWorld};
use crate::spec::{SceneSpec, Vec3};
use crate::strike::{touch_at, HarmRule, StrikeMonitor, StrikeWindow, Touch};
use rapier3d::prelude::*;

use sha2::{Digest, Sha256};

fn v3(a: Vec3) -> Vector {
    Vector::new(a[0] as Real, a[1] as Real, a[2] as Real)
}

fn pose_of(p: &crate::body::LinkPose) -> Pose {
    let q = p.rotation;
    Pose::from_parts(
        v3(p.position),
        Rotation::from_xyzw(q[0] as Real, q[1] as Real, q[2] as Real, q[3] as Real).normalize(),
    )
}

fn collider(shape: LinkShape, cfg: &ExecConfig) -> ColliderBuilder {
    ColliderBuilder::new(crate::shapes::link_shape(shape))
        .friction(cfg.link_friction as Real)
        .restitution(cfg.link_restitution as Real)
        .friction_combine_rule(CoefficientCombineRule::Average)
        .restitution_combine_rule(CoefficientCombineRule::Average)
}

fn norm(v: Vector) -> f64 {
    v.length() as f64
}

/// What the loop has seen so far.
struct Monitor {
    first_contact: Option<(u32, Part)>,
    /// The strike test on the body (the hands/forearms too while not reaching).
    strikes: StrikeMonitor,
    /// Impulse on the hands/forearms since their first touch while reaching (a slamming door).
    hand_window: Option<StrikeWindow>,
    /// The plan is reaching this step (see [`Motion::reaching`]).
    reaching: bool,
    strike: Option<StrikeRecord>,
    floor_step: Option<u32>,
    held_steps: u32,
    caught: bool,
    hand_touched: bool,
    min_hand_distance: f64,
    grasp: GraspState,
    /// The links' shapes (for the body region of a touch).
    shapes: [LinkShape; 13],
}

impl Monitor {
    /// Nothing seen yet; the harm test with the scene's label numbers at step `dt`.
    fn new(spec: &SceneSpec, shapes: [LinkShape; 13], dt: f64) -> Monitor {
        let rule = HarmRule::of_labels(&spec.labels, &spec.hazard_flags, dt);
        Monitor {
            first_contact: None,
            strikes: StrikeMonitor::new(rule, Part::ALL.len()),
            hand_window: None,
            reaching: false,
            strike: None,
            floor_step: None,
            held_steps: 0,
            caught: false,
            hand_touched: false,
            min_hand_distance: f64::INFINITY,
            grasp: GraspState::Open,
            shapes,
        }
    }
}

/// Runs `plan` in `sw` (the world at Δ) and classifies the outcome. With `record`, every
/// step's state is pushed onto it as well (a side output: it only reads the world).
pub(super) fn run(
    spec: &SceneSpec,
    sw: SceneWorld,
    plan: &ExecPlan,
    cfg: &ExecConfig,
    mut record: Option<&mut Vec<ExecFrame>>,
) -> Outcome {
    let o = &spec.observer;
    let reference = PlanReference {
        plan,
        start: [o.x, o.y, o.yaw],
    };
    let plan_end = plan
        .keyframes
        .iter()
        .map(|k| k.t)
        .fold(plan.walking_duration, f64::max);
    let reach = super::plan_reach(plan);
    let mut ex = Execution::start(spec, sw, cfg);
    if let Some(r) = record.as_deref_mut() {
        r.push(ex.frame());
    }
    while !ex.at_horizon() {
        let settled = ex.step(&reference, reach);
        if let Some(r) = record.as_deref_mut() {
            r.push(ex.frame());
        }
        if settled || ex.quiet(plan_end) {
            break;
        }
    }
    ex.finish(reach)
}

/// One execution in progress: the world at Δ with the humanoid added, stepped one physics
/// step at a time by [`Execution::step`] with the body tracking a [`Reference`]. The plan
/// executor ([`run`]) and the closed-loop controller (`crate::control`) both drive it, so
/// they share the body, its limits, the grasp and the outcome rule.
pub struct Execution {
    sw: SceneWorld,
    cfg: ExecConfig,
    geometry: Geometry,
    motion: Motion,
    poses: [crate::body::LinkPose; 13],
    links: Vec<(RigidBodyHandle, ColliderHandle)>,
    hazard_c: ColliderHandle,
    hazard_b: RigidBodyHandle,
    dt: f64,
    horizon: u32,
    window_steps: u32,
    hold_steps: u32,
    started_on_floor: bool,
    /// Steps in a row the hazard has been still (`settle_speed`), and how many end the
    /// run of a hazard that started on the floor (`settle_time_s`; 0: never).
    still_steps: u32,
    settle_steps: u32,
    m: Monitor,
    hasher: Sha256,
    executed: u32,
}

impl Execution {
    /// Adds the humanoid, standing at rest at the observer's pose, to `sw` (the world at Δ).
    pub fn start(spec: &SceneSpec, mut sw: SceneWorld, cfg: &ExecConfig) -> Execution {
        let dt = spec.physics.dt;
        let geometry = Geometry::of(&spec.observer);
        let o = &spec.observer;
        let motion = Motion::new(cfg, geometry, [o.x, o.y, o.yaw], dt);
        let shapes = geometry.shapes();
        let poses = geometry.link_poses(&motion.pose);
        let links: Vec<(RigidBodyHandle, ColliderHandle)> = (0..Part::ALL.len())
            .map(|i| {
                sw.world.insert(
                    RigidBodyBuilder::kinematic_position_based().pose(pose_of(&poses[i])),
                    collider(shapes[i], cfg),
                )
            })
            .collect();
        let hazard_c = sw.collider_handles[spec.hazard];
        let hazard_b = sw.body_handles[spec.hazard];
        let steps = |s: f64| (s / dt).round().max(1.0) as u32;
        // Never past the scene's own horizon (where the build, and the label's
        // counterfactual, stop too).
        let scene_left = spec
            .physics
            .max_steps
            .saturating_sub(spec.decision_step())
            .max(1);
        let started_on_floor = lowest_z(&sw.world.colliders[hazard_c]) <= cfg.floor_contact_eps;
        Execution {
            sw,
            cfg: cfg.clone(),
            geometry,
            motion,
            poses,
            links,
            hazard_c,
            hazard_b,
            dt,
            horizon: steps(cfg.horizon_s).min(scene_left),
            window_steps: steps(cfg.strike_window_s),
            hold_steps: steps(cfg.hold_time_s),
            started_on_floor,
            still_steps: 0,
            settle_steps: (cfg.settle_time_s / dt).round() as u32,
            m: Monitor::new(spec, shapes, dt),
            hasher: Sha256::new(),
            executed: 0,
        }
    }

    /// Physics steps executed so far, and the horizon in steps.
    pub fn executed(&self) -> u32 {
        self.executed
    }

    pub fn horizon(&self) -> u32 {
        self.horizon
    }

    pub fn at_horizon(&self) -> bool {
        self.executed >= self.horizon
    }

    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The body's state (base, pelvis drop, hands) and its base velocity.
    pub fn motion(&self) -> &Motion {
        &self.motion
    }

    /// The hazard's position, linear and angular velocity (world frame).
    pub fn hazard_state(&self) -> (Vec3, Vec3, Vec3) {
        let b = &self.sw.world.bodies[self.hazard_b];
        let (p, v, w) = (b.translation(), b.linvel(), b.angvel());
        let f = |x: Vector| [x.x as f64, x.y as f64, x.z as f64];
        (f(p), f(v), f(w))
    }

    /// This step's state (for videos).
    pub fn frame(&self) -> ExecFrame {
        ExecFrame::of(&self.sw, &self.motion.pose, &self.poses)
    }

    /// One physics step with the body tracking `r`; `reach` is the forward hand extension
    /// of what is being executed (the grasp gate's catch-attempt test). True once the
    /// outcome is settled (struck or caught).
    pub fn step(&mut self, r: &dyn Reference, reach: f64) -> bool {
        let k = self.executed;
        self.motion.advance(k, r);
        self.m.reaching = self.motion.reaching();
        self.poses = self.geometry.link_poses(&self.motion.pose);
        let sw = &mut self.sw;
        for (i, (b, _)) in self.links.iter().enumerate() {
            sw.world.bodies[*b].set_next_kinematic_position(pose_of(&self.poses[i]));
        }
        let v_before = sw.world.bodies[self.hazard_b].linvel();
        let w_before = sw.world.bodies[self.hazard_b].angvel();
        sw.step();
        self.executed = k + 1;
        sw.hash_step(&mut self.hasher);
        for (b, _) in &self.links {
            let t = sw.world.bodies[*b].translation();
            for x in [t.x, t.y, t.z] {
                self.hasher.update(x.to_le_bytes());
            }
        }
        let hazard = &sw.world.bodies[self.hazard_b];
        self.still_steps = if still(hazard.linvel(), hazard.angvel(), self.cfg.settle_speed) {
            self.still_steps + 1
        } else {
            0
        };
        let cfg = &self.cfg;
        observe(
            &mut self.m,
            sw,
            &self.links,
            self.hazard_c,
            self.hazard_b,
            (v_before, w_before),
            self.executed,
            cfg,
            self.window_steps,
            self.hold_steps,
            self.started_on_floor,
        );
        grasp::update(
            &mut self.m.grasp,
            sw,
            &self.links,
            self.hazard_c,
            self.hazard_b,
            v_before,
            reach >= cfg.attempt_reach,
            self.m.floor_step.is_some(),
            self.executed,
            cfg,
        );
        self.m.strike.is_some() || self.m.caught
    }

    /// Whether the run may stop: the hazard lies still on the floor (or, having started
    /// on it, has stayed still for `settle_time_s`), no strike window is open, and the
    /// motion ended (`motion_end` s after Δ) before now.
    pub fn quiet(&self, motion_end: f64) -> bool {
        let landed = self.m.floor_step.is_some()
            && norm(self.sw.world.bodies[self.hazard_b].linvel()) < self.cfg.settle_speed;
        let settled =
            self.started_on_floor && self.settle_steps > 0 && self.still_steps >= self.settle_steps;
        (landed || settled)
            && !self.m.strikes.window_open()
            && self.executed as f64 * self.dt > motion_end
    }

    /// The outcome so far (the run's verdict when it stops here); `reach` as in [`step`].
    ///
    /// [`step`]: Execution::step
    pub fn outcome(&self, reach: f64) -> Outcome {
        let (m, cfg, dt) = (&self.m, &self.cfg, self.dt);
        let attempted = m.hand_touched
            || (reach >= cfg.attempt_reach && m.min_hand_distance <= cfg.attempt_radius);
        let kind = if m.strike.is_some() {
            OutcomeKind::Struck
        } else if m.caught {
            OutcomeKind::Caught
        } else if attempted {
            OutcomeKind::Missed
        } else {
            OutcomeKind::Clear
        };
        let t = |step: u32| step as f64 * dt;
        let strike = m.strike.clone().map(|mut s| {
            s.t *= dt;
            s
        });
        Outcome {
            outcome: kind,
            strike,
            first_contact_t: m.first_contact.map(|(s, _)| t(s)),
            first_contact_part: m.first_contact.map(|(_, p)| p.name().to_string()),
            min_hand_distance: m.min_hand_distance,
            base_end: self.motion.pose.base,
            floor_t: m.floor_step.map(t),
            catch_attempted: attempted,
            limits_hit: self.motion.limits_hit,
            steps: self.executed,
            state_hash: hash_hex(self.hasher.clone()),
        }
    }

    /// The run's verdict ([`Execution::outcome`]), consuming it.
    pub fn finish(self, reach: f64) -> Outcome {
        self.outcome(reach)
    }
}

/// Reads this step's contacts of the hazard and updates the monitor.
#[allow(clippy::too_many_arguments)]
fn observe(
    m: &mut Monitor,
    sw: &SceneWorld,
    links: &[(RigidBodyHandle, ColliderHandle)],
    hazard_c: ColliderHandle,
    hazard_b: RigidBodyHandle,
    (v_before, w_before): (Vector, Vector),
    step: u32,
    cfg: &ExecConfig,
    window_steps: u32,
    hold_steps: u32,
    started_on_floor: bool,
) {
    let world = &sw.world;
    let hazard = &world.colliders[hazard_c];
    let v_hazard = world.bodies[hazard_b].linvel();
    let (mut on_floor, mut touching_hands) = (false, false);
    let mut hold_speed = f64::INFINITY;
    let mut touches: Vec<Touch> = Vec::new();
    let mut hand_impulses = [0.0f64; 13];
    for (pair, other) in crate::simulate::active_contacts(world, hazard_c) {
        if other == sw.floor {
            on_floor = true;
            continue;
        }
        let Some(i) = links.iter().position(|(_, c)| *c == other) else {
            continue;
        };
        let part = Part::ALL[i];
        let link_v = world.bodies[links[i].0].linvel();
        if m.first_contact.is_none() {
            m.first_contact = Some((step, part));
        }
        if part.is_catching() && m.reaching {
            touching_hands = true;
            m.hand_touched = true;
            hand_impulses[i] += pair.total_impulse_magnitude() as f64;
            hold_speed = hold_speed.min(norm(v_hazard - link_v));
        } else {
            let mut t = touch_at(
                world,
                hazard_c,
                (v_before, w_before),
                other,
                part,
                m.shapes[i],
            );
            t.impulse = pair.total_impulse_magnitude() as f64;
            touches.push(t);
        }
    }
    for hand in [Part::LeftHand, Part::RightHand] {
        let c = &world.colliders[links[hand as usize].1];
        if let Ok(d) = rapier3d::parry::query::distance(
            c.position(),
            c.shape(),
            hazard.position(),
            hazard.shape(),
        ) {
            m.min_hand_distance = m.min_hand_distance.min(d.distance as f64);
        }
    }
    if on_floor
        && !started_on_floor
        && m.floor_step.is_none()
        && lowest_z(hazard) <= cfg.floor_contact_eps
    {
        m.floor_step = Some(step);
    }
    if let Some(g) = m.grasp.held() {
        touching_hands = true;
        hold_speed = hold_speed.min(grasp::held_speed(sw, links, g, hazard_b));
    }
    m.strikes.step(step, &touches);
    if let Some(w) = m.strikes.strike() {
        // The test passed: stop here (the verdict cannot change within the window).
        m.strike = Some(StrikeRecord {
            part: Part::ALL[w.heaviest_part()].name().to_string(),
            impulse: w.impulse,
            speed: w.speed,
            t: w.start as f64,
        });
    }
    // A closed hand holds the hazard: its weight and the grip are no blow (the blow of
    // the catch itself, at the touch before the hand closed, is counted).
    if m.strike.is_none() && m.grasp.held().is_none() {
        follow_hand_strike(m, touching_hands, &hand_impulses, step, window_steps, cfg);
    }
    let liftable = world.bodies[hazard_b].mass() as f64 <= cfg.grasp_mass_max;
    let holding = touching_hands
        && liftable
        && !on_floor
        && hold_speed <= cfg.hold_speed_max
        && m.floor_step.is_none();
    m.held_steps = if holding { m.held_steps + 1 } else { 0 };
    if m.held_steps >= hold_steps && m.strike.is_none() {
        m.caught = true;
    }
}

/// The hands and forearms are struck only by a blow no catch could take: an impulse of at
/// least `hand_strike_impulse` within `strike_window_s` of their first touch.
fn follow_hand_strike(
    m: &mut Monitor,
    touching: bool,
    impulses: &[f64; 13],
    step: u32,
    window_steps: u32,
    cfg: &ExecConfig,
) {
    if m.hand_window.is_none() && touching {
        m.hand_window = Some(StrikeWindow::new(step, Part::ALL.len()));
    }
    let Some(w) = m.hand_window.as_mut() else {
        return;
    };
    w.add_impulses(impulses);
    if w.impulse >= cfg.hand_strike_impulse {
        m.strike = Some(StrikeRecord {
            part: Part::ALL[w.heaviest_part()].name().to_string(),
            impulse: w.impulse,
            speed: 0.0,
            t: w.start as f64,
        });
        m.hand_window = None;
    } else if step >= w.start + window_steps {
        m.hand_window = None;
    }
}
