//! Running decisions in physics (feature `execute`): one checked replay per scene,
//! forked per decision in parallel, with an on-disk outcome cache.

use crate::{Pending, RunStats};
use anyhow::Result;
use rayon::prelude::*;
use rh_grade::dataset::{read_replay_keys, Dataset, ReplayKey};
use rh_grade::error::InputError;
use rh_physics::execute::{replay, ExecConfig, ExecPlan, Outcome, Replay};
use rh_physics::spec::SceneSpec;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The cache key of one execution.
pub fn cache_key(scene_hash: &str, plan: &ExecPlan, cfg: &ExecConfig) -> String {
    let mut h = Sha256::new();
    for part in [scene_hash, &plan.hash(), &cfg.hash()] {
        h.update(part.as_bytes());
        h.update(b"/");
    }
    rh_contract::execution::hash_hex(h)
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
    let text = serde_json::to_string(outcome).expect("an outcome serializes");
    let _ = rh_contract::fsio::write_atomic(&cache_path(dir, key), text.as_bytes());
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
pub fn checked_replay(dir: &Path, key: &ReplayKey, scene_id: &str) -> Result<(Replay, bool)> {
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

pub fn replay_key<'a>(
    keys: &'a rh_grade::fast_map::FastMap<String, ReplayKey>,
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
