//! The execution loop and the outcome rule (versioned with `[execution]` in
//! `configs/scoring.toml`; times are seconds after the decision moment Δ):
//!
//! * `struck` — the strike test of the counterfactual label (`crate::strike`, the same
//!   [`StrikeMonitor`]; thresholds `strike_*` equal to the label's) on the moving body:
//!   within `strike_window_s` of a touch, the hazard's contact point moves at ≥
//!   `strike_speed_min` relative to the touched link with a total impulse ≥
//!   `strike_impulse_min`, or the impulse alone is ≥ `strike_impulse_heavy`. The part that
//!   took the most impulse, the impulse and the time of the touch are recorded.
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
//! away from the body after the plan's last motion, or at `horizon_s` (at most the scene's
//! own horizon, `physics.max_steps`, where the label's counterfactual stops too).

use super::grasp::{self, GraspState};
use super::motion::Motion;
use super::{ExecConfig, ExecFrame, ExecPlan, Outcome, OutcomeKind, StrikeRecord};
use crate::body::{Geometry, LinkShape, Part};
use crate::simulate::{hash_hex, lowest_z, SceneWorld};
use crate::spec::{SceneSpec, Vec3};
use crate::strike::{contact_point_speed, StrikeMonitor, StrikeRule, StrikeWindow};
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
}

impl Monitor {
    /// Nothing seen yet; the strike test with `[execution]`'s numbers at step `dt`.
    fn new(cfg: &ExecConfig, dt: f64) -> Monitor {
        let rule = StrikeRule::new(
            cfg.strike_speed_min,
            cfg.strike_impulse_min,
            cfg.strike_impulse_heavy,
            cfg.strike_window_s,
            dt,
        );
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
        }
    }
}

/// Runs `plan` in `sw` (the world at Δ) and classifies the outcome. With `record`, every
/// step's state is pushed onto it as well (a side output: it only reads the world).
pub(super) fn run(
    spec: &SceneSpec,
    mut sw: SceneWorld,
    plan: &ExecPlan,
    cfg: &ExecConfig,
    mut record: Option<&mut Vec<ExecFrame>>,
) -> Outcome {
    let dt = spec.physics.dt;
    let geometry = Geometry::of(&spec.observer);
    let o = &spec.observer;
    let mut motion = Motion::new(plan, cfg, geometry, [o.x, o.y, o.yaw], dt);
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
    // Never past the scene's own horizon (where the build, and the label's counterfactual,
    // stop too).
    let scene_left = spec
        .physics
        .max_steps
        .saturating_sub(spec.decision_step())
        .max(1);
    let (horizon, window_steps, hold_steps) = (
        steps(cfg.horizon_s).min(scene_left),
        steps(cfg.strike_window_s),
        steps(cfg.hold_time_s),
    );
    let plan_end = plan
        .keyframes
        .iter()
        .map(|k| k.t)
        .fold(plan.walking_duration, f64::max);
    let started_on_floor = lowest_z(&sw.world.colliders[hazard_c]) <= cfg.floor_contact_eps;
    let mut m = Monitor::new(cfg, dt);
    let attempting = super::plan_reach(plan) >= cfg.attempt_reach;
    let mut hasher = Sha256::new();
    let mut executed = 0;
    if let Some(r) = record.as_deref_mut() {
        r.push(ExecFrame::of(&sw, &motion.pose, &poses));
    }
    for k in 0..horizon {
        motion.advance(k);
        m.reaching = motion.reaching();
        let poses = geometry.link_poses(&motion.pose);
        for (i, (b, _)) in links.iter().enumerate() {
            sw.world.bodies[*b].set_next_kinematic_position(pose_of(&poses[i]));
        }
        let v_before = sw.world.bodies[hazard_b].linvel();
        let w_before = sw.world.bodies[hazard_b].angvel();
        sw.world.step();
        executed = k + 1;
        sw.hash_step(&mut hasher);
        if let Some(r) = record.as_deref_mut() {
            r.push(ExecFrame::of(&sw, &motion.pose, &poses));
        }
        for (b, _) in &links {
            let t = sw.world.bodies[*b].translation();
            for x in [t.x, t.y, t.z] {
                hasher.update(x.to_le_bytes());
            }
        }
        observe(
            &mut m,
            &sw,
            &links,
            hazard_c,
            hazard_b,
            (v_before, w_before),
            executed,
            cfg,
            window_steps,
            hold_steps,
            started_on_floor,
        );
        grasp::update(
            &mut m.grasp,
            &mut sw,
            &links,
            hazard_c,
            hazard_b,
            v_before,
            attempting,
            m.floor_step.is_some(),
            executed,
            cfg,
        );
        if m.strike.is_some() || m.caught {
            break;
        }
        let quiet = m.floor_step.is_some()
            && norm(sw.world.bodies[hazard_b].linvel()) < cfg.settle_speed
            && !m.strikes.window_open()
            && executed as f64 * dt > plan_end;
        if quiet {
            break;
        }
    }
    let attempted = m.hand_touched
        || (super::plan_reach(plan) >= cfg.attempt_reach
            && m.min_hand_distance <= cfg.attempt_radius);
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
    if let Some(s) = m.strike.as_mut() {
        s.t *= dt;
    }
    Outcome {
        outcome: kind,
        strike: m.strike,
        first_contact_t: m.first_contact.map(|(s, _)| t(s)),
        first_contact_part: m.first_contact.map(|(_, p)| p.name().to_string()),
        min_hand_distance: m.min_hand_distance,
        base_end: motion.pose.base,
        floor_t: m.floor_step.map(t),
        catch_attempted: attempted,
        limits_hit: motion.limits_hit,
        steps: executed,
        state_hash: hash_hex(hasher),
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
    let (mut on_floor, mut touching_hands, mut body_touch) = (false, false, None::<f64>);
    let mut hold_speed = f64::INFINITY;
    let mut impulses = [0.0f64; 13];
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
            impulses[i] += pair.total_impulse_magnitude() as f64;
            let speed = contact_point_speed(world, hazard_c, v_before, w_before, other);
            body_touch = Some(body_touch.map_or(speed, |s| s.max(speed)));
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
    m.strikes.step(step, body_touch, &impulses);
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
    w.add(None, impulses);
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
