//! `--execute` (SPEC §12): every scored decision with a parseable plan is carried out in
//! physics by `rh_pipeline::execute` — the scorer's only door into the simulator — and
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

pub mod report;
#[cfg(feature = "videos")]
pub mod videos;

use crate::dataset::{read_replay_keys, Dataset, ReplayKey};
use crate::plan::Plan;
use crate::types::{Action, InputError};
use anyhow::Result;
use rayon::prelude::*;
use rh_pipeline::execute::{replay, ExecConfig, ExecKeyframe, ExecPlan, Outcome, Replay};
use rh_pipeline::spec::SceneSpec;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
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

/// The cache key of one execution.
pub fn cache_key(scene_hash: &str, plan: &ExecPlan, cfg: &ExecConfig) -> String {
    let mut h = Sha256::new();
    for part in [scene_hash, &plan.hash(), &cfg.hash()] {
        h.update(part.as_bytes());
        h.update(b"/");
    }
    h.finalize()[..16]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn cache_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(&key[..2]).join(format!("{key}.json"))
}

fn cache_get(dir: &Path, key: &str) -> Option<Outcome> {
    let text = std::fs::read_to_string(cache_path(dir, key)).ok()?;
    serde_json::from_str(&text).ok()
}

/// Writes a cache entry atomically (temp file, then rename); failures only cost a rerun.
fn cache_put(dir: &Path, key: &str, outcome: &Outcome) {
    let path = cache_path(dir, key);
    let Some(parent) = path.parent() else { return };
    if std::fs::create_dir_all(parent).is_err() {
        return;
    }
    let tmp = parent.join(format!(".{key}.{}.tmp", std::process::id()));
    let text = serde_json::to_string(outcome).expect("an outcome serializes");
    if std::fs::write(&tmp, text).is_ok() && std::fs::rename(&tmp, &path).is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
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

/// Executes every pending decision (outcomes aligned with `pending`; `None` for R1).
pub fn execute_all(
    ds: &Dataset,
    pending: &[Pending],
    cfg: &ExecConfig,
    cache: Option<&Path>,
) -> Result<(Vec<Option<Outcome>>, RunStats)> {
    let keys = read_replay_keys(&ds.dir)?;
    let mut stats = RunStats::default();
    let mut outcomes: Vec<Option<Outcome>> = vec![None; pending.len()];
    // Cache look-ups; what is left, grouped by scene (BTreeMap: a fixed order).
    let mut todo: BTreeMap<u32, Vec<(usize, String)>> = BTreeMap::new();
    for (i, p) in pending.iter().enumerate() {
        let Some(plan) = &p.plan else {
            stats.not_executed += 1;
            continue;
        };
        let sc = &ds.scenes[p.scene as usize];
        let key = replay_key(&keys, &sc.scene_id)?;
        let scene_hash = key
            .decision_state_hash
            .clone()
            .or(key.state_hash.clone())
            .unwrap_or_default();
        let ck = cache_key(&scene_hash, plan, cfg);
        match cache.and_then(|d| cache_get(d, &ck)) {
            Some(o) => {
                outcomes[i] = Some(o);
                stats.from_cache += 1;
            }
            None => todo.entry(p.scene).or_default().push((i, ck)),
        }
    }
    let scenes: Vec<(u32, Vec<(usize, String)>)> = todo.into_iter().collect();
    let done: Vec<Result<(Vec<(usize, String, Outcome)>, bool)>> = scenes
        .par_iter()
        .map(|(scene, decisions)| {
            let sc = &ds.scenes[*scene as usize];
            let key = replay_key(&keys, &sc.scene_id)?;
            let (r, full) = checked_replay(&ds.dir, key, &sc.scene_id)?;
            let out = decisions
                .par_iter()
                .map(|(i, ck)| {
                    let plan = pending[*i].plan.as_ref().expect("only plans are queued");
                    (*i, ck.clone(), r.execute(plan, cfg))
                })
                .collect();
            Ok((out, full))
        })
        .collect();
    for d in done {
        let (list, full) = d?;
        stats.scenes_replayed += 1;
        if full {
            stats.checked_full += 1;
        } else {
            stats.checked_at_decision += 1;
        }
        for (i, ck, o) in list {
            if let Some(dir) = cache {
                cache_put(dir, &ck, &o);
            }
            outcomes[i] = Some(o);
            stats.executed += 1;
        }
    }
    Ok((outcomes, stats))
}

/// Replays a scene from its spec to Δ and checks it against the dataset's
/// `decision_state_hash` (older datasets: a full replay against `state_hash`); true when
/// the full replay was the check.
pub(crate) fn checked_replay(
    dir: &Path,
    key: &ReplayKey,
    scene_id: &str,
) -> Result<(Replay, bool)> {
    let spec = load_spec(dir, &key.spec_file)?;
    let r = replay(&spec);
    let full = match (&key.decision_state_hash, &key.state_hash) {
        (Some(h), _) => {
            r.check(h).map_err(|e| InputError(e.to_string()))?;
            false
        }
        (None, Some(h)) => {
            r.check_full(h).map_err(|e| InputError(e.to_string()))?;
            true
        }
        (None, None) => {
            return Err(InputError(format!(
                "scene {scene_id}: the dataset has neither decision_state_hash nor state_hash, so its replay cannot be checked; refusing to execute"
            ))
            .into())
        }
    };
    Ok((r, full))
}

pub(crate) fn replay_key<'a>(
    keys: &'a crate::types::FastMap<String, ReplayKey>,
    id: &str,
) -> Result<&'a ReplayKey> {
    keys.get(id).ok_or_else(|| {
        InputError(format!("scene {id} is not in the dataset's replay columns")).into()
    })
}

fn load_spec(dir: &Path, rel: &str) -> Result<SceneSpec> {
    let path = dir.join(rel);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        InputError(format!(
            "--execute needs the scene specs: cannot read {}: {e}",
            path.display()
        ))
    })?;
    SceneSpec::from_json(&text).map_err(|e| {
        InputError(format!("{} is not a valid scene spec: {e}", path.display())).into()
    })
}
