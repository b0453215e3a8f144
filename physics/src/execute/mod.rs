//! Execution on demand (specification §12): the observer as an articulated humanoid carries a
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
//!   ([`crate::body`]) as kinematic bodies moved to their next pose every step ([`motion`]),
//!   steps on, and classifies what happened ([`outcome`]) into an [`Outcome`].
//!
//! A replay is made once per scene and forked for each decision, so every decision starts
//! from the same bits, whatever the order, thread or process. Nothing here reads a clock
//! or iterates a hash map.

pub mod escape;
pub mod grasp;
pub mod motion;
pub mod outcome;

use crate::body::{BodyPose, LinkPose};
use crate::simulate::{build_world, hash_hex, simulate, BodyState, SceneWorld, SimOptions};
use crate::spec::{SceneSpec, Vec3};

use sha2::{Digest, Sha256};

pub use rh_contract::execution::{
    ExecConfig, ExecKeyframe, ExecPlan, Outcome, OutcomeKind, StrikeRecord, EXECUTOR_VERSION,
};

/// Largest forward hand extension beyond rest over a plan's keyframes (m).
pub fn plan_reach(plan: &ExecPlan) -> f64 {
    plan.keyframes
        .iter()
        .map(|k| {
            (k.left[0] - crate::body::REST_LEFT[0]).max(k.right[0] - crate::body::REST_RIGHT[0])
        })
        .fold(0.0, f64::max)
}

/// One executed physics step as recorded by [`Replay::execute_recorded`] (for videos):
/// frame `k` is the state after `k` steps from Δ (frame 0: the world at Δ, the humanoid
/// in its starting pose).
#[derive(Debug, Clone, PartialEq)]
pub struct ExecFrame {
    /// Every dynamic body's state, in the scene's dynamic-body order (the `Simulation`
    /// slots of the same spec).
    pub bodies: Vec<BodyState>,
    /// The humanoid's links, in [`crate::body::Part::ALL`] order.
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
    let decision_step = spec.decision_step();
    let mut hasher = Sha256::new();
    world.hash_step(&mut hasher);
    for _ in 0..decision_step {
        world.step();
        world.hash_step(&mut hasher);
    }
    Replay {
        spec: spec.clone(),
        world,
        decision_step,
        decision_hash: hash_hex(hasher),
    }
}

/// [`replay`], taken from the world at Δ that a plain run of `spec` on this thread kept
/// (`simulate::decision_world`) when there is one: the same world and hash without
/// stepping again.
pub fn replay_reusing(spec: &SceneSpec) -> Replay {
    match crate::simulate::decision_world(spec) {
        Some((world, decision_hash)) => Replay {
            spec: spec.clone(),
            world,
            decision_step: spec.decision_step(),
            decision_hash,
        },
        None => replay(spec),
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
        crate::simulate::fork_world(&self.world)
    }

    /// A fresh execution from Δ (the world forked, the humanoid standing at rest) to step
    /// by hand; the closed-loop controller (`crate::control`) drives one.
    pub fn start(&self, cfg: &ExecConfig) -> outcome::Execution {
        outcome::Execution::start(&self.spec, self.fork(), cfg)
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
        assert!(d.validate().unwrap_err().to_string().contains("max_speed"));
    }

    /// One body, one harm test: the executor judges `struck` with the scene's own label
    /// numbers (`crate::strike`); its window for the catching hands and its link surface
    /// are the counterfactual label's (`configs/labels.toml`, `humanoid::BODY_*`), so the
    /// `freeze` plan is struck exactly where the standing body would be harmed.
    #[test]
    fn execution_strikes_like_the_label() {
        let c = ExecConfig::embedded_default();
        let l = crate::spec::LabelConfig::embedded();
        assert_eq!(c.strike_window_s, l.strike_window_s);
        // Rule v4's catch timing walks with the executor's base limits.
        assert_eq!(
            (c.max_speed, c.max_accel),
            (l.catch_walk_speed, l.catch_walk_accel)
        );
        assert_eq!(c.link_friction, crate::body::BODY_FRICTION);
        assert_eq!(c.link_restitution, crate::body::BODY_RESTITUTION);
    }
}
