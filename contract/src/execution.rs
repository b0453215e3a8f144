//! The executor's interface (specification §12), plain data shared by the physics that runs it
//! (`rh-physics`) and the scorer that reports it: a motor plan in ([`ExecPlan`]), the
//! robot's limits and the outcome thresholds ([`ExecConfig`], `[execution]` of
//! `configs/scoring.toml`), and what happened out ([`Outcome`]).

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// `[x, y, z]` in metres (or `(x, y, yaw)` for a base pose).
pub type Vec3 = [f64; 3];

/// Hex of the first 16 bytes of a SHA-256 (the executor's hashes).
pub fn hash_hex(hasher: Sha256) -> String {
    crate::digest::hex(&hasher.finalize()[..16])
}

/// Version of the executor's code (humanoid, controller, outcome rule); part of the
/// execution cache key together with the config's own `version`.
pub const EXECUTOR_VERSION: &str = "exec-6";

/// One hand keyframe (body frame; `t` in seconds after the decision moment).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExecKeyframe {
    pub t: f64,
    pub left: [f64; 3],
    pub right: [f64; 3],
    /// 0 straight … 1 deep crouch (clamped).
    pub knee_bend: f64,
}

/// A motor plan in plain numbers (specification §9, already parsed and sanity-checked): walking
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
    /// A hazard that started on the floor (a ladder, a wardrobe, a door) ends the run
    /// once it has stayed still this long (s) after the plan's last motion; 0: never
    /// (configs of `version` e4 and before).
    #[serde(default)]
    pub settle_time_s: f64,
}

impl ExecConfig {
    /// The `[execution]` table of the embedded `configs/scoring.toml`.
    pub fn embedded_default() -> ExecConfig {
        #[derive(Deserialize)]
        struct File {
            execution: ExecConfig,
        }
        let text = include_str!("../../configs/scoring.toml");
        let file: File = toml::from_str(text).expect("the embedded scoring.toml parses");
        file.execution
    }

    /// Checks every number is finite and in range; names the field otherwise.
    pub fn validate(&self) -> Result<(), ExecConfigError> {
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
                return Err(ExecConfigError::NotPositive {
                    field: name,
                    value: v,
                });
            }
        }
        let non_negative = [
            ("max_pelvis_drop", self.max_pelvis_drop),
            ("link_friction", self.link_friction),
            ("link_restitution", self.link_restitution),
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
            ("settle_time_s", self.settle_time_s),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ExecConfigError::Negative {
                    field: name,
                    value: v,
                });
            }
        }
        if self.horizon_s > 60.0 {
            return Err(ExecConfigError::LongHorizon {
                horizon_s: self.horizon_s,
            });
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

/// Why an `[execution]` section is unusable; the message names the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExecConfigError {
    #[error("execution.{field} = {value} must be a positive number")]
    NotPositive { field: &'static str, value: f64 },
    #[error("execution.{field} = {value} must be a non-negative number")]
    Negative { field: &'static str, value: f64 },
    #[error("execution.horizon_s = {horizon_s} is more than 60 s")]
    LongHorizon { horizon_s: f64 },
}

/// The message, for callers that pass errors on as text.
impl From<ExecConfigError> for String {
    fn from(e: ExecConfigError) -> String {
        e.to_string()
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutcomeKind {
    Caught,
    Struck,
    Missed,
    Clear,
}

impl OutcomeKind {
    pub const ALL: [OutcomeKind; 4] = [
        OutcomeKind::Caught,
        OutcomeKind::Struck,
        OutcomeKind::Missed,
        OutcomeKind::Clear,
    ];

    pub fn name(self) -> &'static str {
        match self {
            OutcomeKind::Caught => "caught",
            OutcomeKind::Struck => "struck",
            OutcomeKind::Missed => "missed",
            OutcomeKind::Clear => "clear",
        }
    }

    pub fn index(self) -> usize {
        self as usize
    }
}

/// What struck the body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrikeRecord {
    pub part: String,
    /// Total impulse on the non-catching parts over the strike window (N·s).
    pub impulse: f64,
    /// Largest relative speed at a touch within the window (m/s).
    pub speed: f64,
    /// First touch (s after Δ).
    pub t: f64,
}

/// One executed decision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    pub outcome: OutcomeKind,
    pub strike: Option<StrikeRecord>,
    /// First contact of the hazard with any body part (s after Δ).
    pub first_contact_t: Option<f64>,
    pub first_contact_part: Option<String>,
    /// Smallest distance between a hand (palm) and the hazard's surface (m).
    pub min_hand_distance: f64,
    /// The executed base's final `(x, y, yaw)` (world).
    pub base_end: Vec3,
    /// The hazard's first floor contact after Δ (s after Δ), if it started above it.
    pub floor_t: Option<f64>,
    pub catch_attempted: bool,
    /// Which base limits bound: speed, acceleration, yaw rate, yaw acceleration.
    pub limits_hit: [bool; 4],
    /// Physics steps executed after Δ.
    pub steps: u32,
    /// SHA-256 (16 bytes, hex) of every dynamic body's state and every link's position
    /// at every executed step.
    pub state_hash: String,
}
