//! Execution on demand (SPEC §12): the observer as an articulated humanoid carries a
//! plan out in physics, and the rigid-body solver decides what happens.
//!
//! The interface is plain data and two calls:
//!
//! * [`replay`]`(&spec)` rebuilds the scene with [`crate::simulate::build_world`] (the one
//!   physics setup) and steps it to the decision moment Δ, hashing the state exactly as
//!   `simulate` does; [`Replay::check`] compares that hash with the dataset's
//!   `decision_state_hash` (or, for datasets without the column, [`Replay::check_full`]
//!   replays the whole scene against `state_hash`) and refuses on a mismatch.
//! * [`Replay::execute`]`(&plan, &config)` forks the world at Δ, adds the humanoid
//!   ([`humanoid`]) as kinematic bodies moved to their next pose every step ([`motion`]),
//!   steps on, and classifies what happened ([`outcome`]) into an [`Outcome`].
//!
//! A replay is made once per scene and forked for each decision, so every decision starts
//! from the same bits, whatever the order, thread or process. Nothing here reads a clock
//! or iterates a hash map.

pub mod escape;
pub mod grasp;
pub mod humanoid;
pub mod motion;
pub mod outcome;

use crate::simulate::{build_world, hash_hex, simulate, BodyState, SceneWorld, SimOptions};
use crate::spec::{SceneSpec, Vec3};
use humanoid::{BodyPose, LinkPose};
use rapier3d::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

pub use outcome::{Outcome, OutcomeKind, StrikeRecord};

/// Version of the executor's code (humanoid, controller, outcome rule); part of the
/// execution cache key together with the config's own `version`.
pub const EXECUTOR_VERSION: &str = "exec-4";

/// One hand keyframe (body frame; `t` in seconds after the decision moment).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExecKeyframe {
    pub t: f64,
    pub left: [f64; 3],
    pub right: [f64; 3],
    /// 0 straight … 1 deep crouch (clamped).
    pub knee_bend: f64,
}

/// A motor plan in plain numbers (SPEC §9, already parsed and sanity-checked): walking
/// command `[vx, vy, yaw_rate]` (body frame) for `walking_duration` s, and keyframes
/// sorted by time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExecPlan {
    pub walking_cmd: [f64; 3],
    pub walking_duration: f64,
    pub keyframes: Vec<ExecKeyframe>,
}

impl ExecPlan {
    /// Hex SHA-256 (16 bytes) of the plan's numbers (the cache key's plan part).
    pub fn hash(&self) -> String {
        let mut h = Sha256::new();
        let mut put = |x: f64| h.update(x.to_bits().to_le_bytes());
        self.walking_cmd.iter().for_each(|&x| put(x));
        put(self.walking_duration);
        for k in &self.keyframes {
            put(k.t);
            k.left.iter().chain(&k.right).for_each(|&x| put(x));
            put(k.knee_bend);
        }
        hash_hex(h)
    }

    /// Largest forward hand extension beyond rest over the keyframes (m).
    pub fn reach(&self) -> f64 {
        self.keyframes
            .iter()
            .map(|k| (k.left[0] - motion::REST_LEFT[0]).max(k.right[0] - motion::REST_RIGHT[0]))
            .fold(0.0, f64::max)
    }
}

/// One executed physics step as recorded by [`Replay::execute_recorded`] (for videos):
/// frame `k` is the state after `k` steps from Δ (frame 0: the world at Δ, the humanoid
/// in its starting pose).
#[derive(Debug, Clone, PartialEq)]
pub struct ExecFrame {
    /// Every dynamic body's state, in the scene's dynamic-body order (the `Simulation`
    /// slots of the same spec).
    pub bodies: Vec<BodyState>,
    /// The humanoid's links, in [`humanoid::Part::ALL`] order.
    pub links: [LinkPose; 13],
    /// The base's `(x, y, yaw)` and the pelvis drop (m).
    pub base: Vec3,
    pub drop: f64,
}

impl ExecFrame {
    fn of(sw: &SceneWorld, pose: &BodyPose, links: &[LinkPose; 13]) -> ExecFrame {
        ExecFrame {
            bodies: sw
                .dynamic_bodies
                .iter()
                .map(|&i| sw.body_state(i))
                .collect(),
            links: *links,
            base: pose.base,
            drop: pose.drop,
        }
    }
}

/// Execution thresholds and limits (`[execution]` of `configs/scoring.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExecConfig {
    pub version: String,
    pub horizon_s: f64,
    pub max_speed: f64,
    pub max_accel: f64,
    pub max_yaw_rate: f64,
    pub max_yaw_accel: f64,
    pub track_time_constant: f64,
    pub max_pelvis_drop: f64,
    pub max_drop_speed: f64,
    pub max_hand_speed: f64,
    pub link_friction: f64,
    pub link_restitution: f64,
    pub strike_speed_min: f64,
    pub strike_impulse_min: f64,
    pub strike_impulse_heavy: f64,
    pub strike_window_s: f64,
    pub hand_strike_impulse: f64,
    pub reaching_offset: f64,
    pub hold_time_s: f64,
    pub hold_speed_max: f64,
    pub grasp_speed_max: f64,
    pub grasp_mass_max: f64,
    pub grasp_momentum_max: f64,
    pub attempt_reach: f64,
    pub attempt_radius: f64,
    pub floor_contact_eps: f64,
    pub settle_speed: f64,
}

impl ExecConfig {
    /// The `[execution]` table of the embedded `configs/scoring.toml`.
    pub fn embedded_default() -> ExecConfig {
        #[derive(Deserialize)]
        struct File {
            execution: ExecConfig,
        }
        let text = include_str!("../../../configs/scoring.toml");
        let file: File = toml::from_str(text).expect("the embedded scoring.toml parses");
        file.execution
    }

    /// Checks every number is finite and in range; names the field otherwise.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("horizon_s", self.horizon_s),
            ("max_speed", self.max_speed),
            ("max_accel", self.max_accel),
            ("max_yaw_rate", self.max_yaw_rate),
            ("max_yaw_accel", self.max_yaw_accel),
            ("track_time_constant", self.track_time_constant),
            ("max_drop_speed", self.max_drop_speed),
            ("max_hand_speed", self.max_hand_speed),
            ("strike_window_s", self.strike_window_s),
            ("hold_time_s", self.hold_time_s),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("execution.{name} = {v} must be a positive number"));
            }
        }
        let non_negative = [
            ("max_pelvis_drop", self.max_pelvis_drop),
            ("link_friction", self.link_friction),
            ("link_restitution", self.link_restitution),
            ("strike_speed_min", self.strike_speed_min),
            ("strike_impulse_min", self.strike_impulse_min),
            ("strike_impulse_heavy", self.strike_impulse_heavy),
            ("hand_strike_impulse", self.hand_strike_impulse),
            ("reaching_offset", self.reaching_offset),
            ("hold_speed_max", self.hold_speed_max),
            ("grasp_speed_max", self.grasp_speed_max),
            ("grasp_mass_max", self.grasp_mass_max),
            ("grasp_momentum_max", self.grasp_momentum_max),
            ("attempt_reach", self.attempt_reach),
            ("attempt_radius", self.attempt_radius),
            ("floor_contact_eps", self.floor_contact_eps),
            ("settle_speed", self.settle_speed),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "execution.{name} = {v} must be a non-negative number"
                ));
            }
        }
        if self.horizon_s > 60.0 {
            return Err(format!(
                "execution.horizon_s = {} is more than 60 s",
                self.horizon_s
            ));
        }
        Ok(())
    }

    /// Hex SHA-256 (16 bytes) of the config and [`EXECUTOR_VERSION`] (cache key part).
    pub fn hash(&self) -> String {
        let mut h = Sha256::new();
        h.update(EXECUTOR_VERSION.as_bytes());
        h.update(
            serde_json::to_string(self)
                .expect("config serializes")
                .as_bytes(),
        );
        hash_hex(h)
    }
}

/// Why a scene cannot be executed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExecError {
    #[error("scene {scene}: the replay's state hash at the decision moment is {replayed}, the dataset says {stored} (the spec does not reproduce the stored simulation; refusing to execute)")]
    DecisionHashMismatch {
        scene: String,
        stored: String,
        replayed: String,
    },
    #[error("scene {scene}: the replay's full state hash is {replayed}, the dataset says {stored} (the spec does not reproduce the stored simulation; refusing to execute)")]
    FullHashMismatch {
        scene: String,
        stored: String,
        replayed: String,
    },
}

/// A scene replayed to the decision moment, ready to execute plans from.
pub struct Replay {
    spec: SceneSpec,
    world: SceneWorld,
    /// Physics step of Δ.
    pub decision_step: u32,
    /// The state hash of steps `0..=Δ`, computed while replaying.
    pub decision_hash: String,
}

/// Replays `spec` to its decision moment Δ (bit for bit the build's simulation).
pub fn replay(spec: &SceneSpec) -> Replay {
    let mut world = build_world(spec);
    let decision_step = crate::label::decision_step(spec);
    let mut hasher = Sha256::new();
    world.hash_step(&mut hasher);
    for _ in 0..decision_step {
        world.world.step();
        world.hash_step(&mut hasher);
    }
    Replay {
        spec: spec.clone(),
        world,
        decision_step,
        decision_hash: hash_hex(hasher),
    }
}

impl Replay {
    pub fn spec(&self) -> &SceneSpec {
        &self.spec
    }

    /// Refuses unless the replay's hash at Δ is the dataset's `decision_state_hash`.
    pub fn check(&self, stored: &str) -> Result<(), ExecError> {
        if self.decision_hash == stored {
            return Ok(());
        }
        Err(ExecError::DecisionHashMismatch {
            scene: self.spec.scene_id.clone(),
            stored: stored.to_string(),
            replayed: self.decision_hash.clone(),
        })
    }

    /// For datasets without `decision_state_hash`: replays the whole scene and refuses
    /// unless it gives the stored `state_hash` (the prefix to Δ is then the build's too).
    pub fn check_full(&self, stored: &str) -> Result<(), ExecError> {
        let replayed = simulate(&self.spec, SimOptions::default()).state_hash;
        if replayed == stored {
            return Ok(());
        }
        Err(ExecError::FullHashMismatch {
            scene: self.spec.scene_id.clone(),
            stored: stored.to_string(),
            replayed,
        })
    }

    /// A copy of the world at Δ to step on (fresh solver workspace; the state is cloned).
    fn fork(&self) -> SceneWorld {
        let w = &self.world.world;
        let mut world = PhysicsWorld::new();
        world.gravity = w.gravity;
        world.integration_parameters = w.integration_parameters;
        world.islands = w.islands.clone();
        world.broad_phase = w.broad_phase.clone();
        world.narrow_phase = w.narrow_phase.clone();
        world.bodies = w.bodies.clone();
        world.colliders = w.colliders.clone();
        world.impulse_joints = w.impulse_joints.clone();
        world.multibody_joints = w.multibody_joints.clone();
        world.soft_bodies = w.soft_bodies.clone();
        world.ccd_solver = w.ccd_solver.clone();
        SceneWorld {
            world,
            floor: self.world.floor,
            body_handles: self.world.body_handles.clone(),
            collider_handles: self.world.collider_handles.clone(),
            dynamic_bodies: self.world.dynamic_bodies.clone(),
        }
    }

    /// Executes `plan` from Δ and says what happened. Pure in (replay, plan, config).
    pub fn execute(&self, plan: &ExecPlan, cfg: &ExecConfig) -> Outcome {
        outcome::run(&self.spec, self.fork(), plan, cfg, None)
    }

    /// [`Replay::execute`] that also records every step ([`ExecFrame`]) for the videos;
    /// the outcome (and its `state_hash`) is the same bits as without recording.
    pub fn execute_recorded(&self, plan: &ExecPlan, cfg: &ExecConfig) -> (Outcome, Vec<ExecFrame>) {
        let mut frames = Vec::new();
        let outcome = outcome::run(&self.spec, self.fork(), plan, cfg, Some(&mut frames));
        (outcome, frames)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_config_is_valid() {
        let c = ExecConfig::embedded_default();
        c.validate().unwrap();
        assert_eq!(c.hash(), ExecConfig::embedded_default().hash());
        let mut d = c.clone();
        d.max_speed = f64::NAN;
        assert!(d.validate().unwrap_err().contains("max_speed"));
    }

    /// One body, one strike test: the executor's strike thresholds and link surface are
    /// the counterfactual label's (`configs/labels.toml`, `humanoid::BODY_*`), so the
    /// `freeze` plan is struck exactly where the standing body would be.
    #[test]
    fn execution_strikes_like_the_label() {
        let c = ExecConfig::embedded_default();
        let l = crate::config::Config::embedded().unwrap().labels;
        assert_eq!(
            (c.strike_speed_min, c.strike_impulse_min),
            (l.strike_speed_min, l.strike_impulse_min)
        );
        assert_eq!(
            (c.strike_impulse_heavy, c.strike_window_s),
            (l.strike_impulse_heavy, l.strike_window_s)
        );
        // Rule v4's catch timing walks with the executor's base limits.
        assert_eq!(
            (c.max_speed, c.max_accel),
            (l.catch_walk_speed, l.catch_walk_accel)
        );
        assert_eq!(c.link_friction, humanoid::BODY_FRICTION);
        assert_eq!(c.link_restitution, humanoid::BODY_RESTITUTION);
    }
}
