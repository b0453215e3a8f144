//! `--execute` (specification §12): every scored decision with a parseable plan is carried out in
//! physics by `rh_physics::execute` — the scorer's only door into the simulator — and
//! its outcome (`caught` / `struck` / `missed` / `clear`) joins the report.
//!
//! * Plans without a parseable plan (R1: no JSON, NaN, 1e30, empty keyframes …) and lost
//!   decisions are not executed (counted as `not_executed`).
//! * Each scene is replayed once from `specs/<id>.json` to Δ and checked against the
//!   dataset's `decision_state_hash` (older datasets: a full replay against
//!   `state_hash`); a mismatch refuses the run (exit 2) naming the scene. The world at Δ
//!   is forked for each of the scene's decisions, in parallel (rayon).
//! * Outcomes are cached on disk by (scene hash at Δ, plan hash, execution config hash),
//!   so rescoring the same predictions executes nothing again.
//!
//! This module is the executor's plain data (what is waiting, how a run went, the
//! report); running plans and the replay check are rh-execute's, which links the
//! simulator, and the videos rh-execute-videos'.

pub mod report;

use crate::plan::Plan;
use rh_contract::execution::{ExecKeyframe, ExecPlan};
use rh_contract::Action;
use std::path::{Path, PathBuf};

pub use report::ExecutionReport;

/// One scored decision waiting for execution.
#[derive(Debug, Clone)]
pub struct Pending {
    pub line: u64,
    pub scene: u32,
    pub model: usize,
    /// `None`: R1, not executed.
    pub plan: Option<ExecPlan>,
    pub action: Option<Action>,
    pub saa: bool,
}

/// The plan as the executor takes it (plain numbers).
pub fn exec_plan(p: &Plan) -> ExecPlan {
    ExecPlan {
        walking_cmd: p.walking_cmd,
        walking_duration: p.walking_duration,
        keyframes: p
            .keyframes
            .iter()
            .map(|k| ExecKeyframe {
                t: k.t,
                left: k.left,
                right: k.right,
                knee_bend: k.knee_bend,
            })
            .collect(),
    }
}

/// Where outcomes are cached: `$RH_EXEC_CACHE`, else `~/.cache/reacthuman/execute`.
pub fn default_cache_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("RH_EXEC_CACHE").filter(|d| !d.is_empty()) {
        return PathBuf::from(d);
    }
    let home = std::env::var_os("HOME").map_or_else(|| PathBuf::from("."), PathBuf::from);
    home.join(".cache/reacthuman/execute")
}

/// How an execution run went.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RunStats {
    pub executed: usize,
    pub from_cache: usize,
    pub not_executed: usize,
    pub scenes_replayed: usize,
    /// Replays checked against `decision_state_hash` / (older datasets) `state_hash`.
    pub checked_at_decision: usize,
    pub checked_full: usize,
}

/// What `--execute-videos` draws (`videos::write_videos`).
pub struct VideoRequest<'a> {
    pub dir: &'a Path,
    /// Only these scenes (scene ids); `None`: every scene with an executed decision.
    pub scenes: Option<&'a [String]>,
    /// The tiled scene; `None`: the scene with the most executed decisions (the first
    /// in dataset order on a tie).
    pub tiled_scene: Option<&'a str>,
    pub progress: bool,
}
