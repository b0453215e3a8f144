//! The oracle baseline's DODGE plans checked in physics with `--execute`'s executor
//! (`cfg.execution`): for every valid DODGE scene whose spec replays (checked against the
//! dataset's hash), the heuristic dodge is executed; when it is struck, the first escape
//! walk that is not (`rh_physics::execute::escape`, the walks of the label's validator
//! `valid_escapable`) replaces it. The core's oracle (`rh_grade::oracle`) takes this as
//! its [`rh_grade::oracle::DodgeCheck`].

use rh_contract::Action;
use rh_grade::config::Config;
use rh_grade::dataset::{ReplayKey, Scene};
use rh_grade::fast_map::FastMap;
use rh_grade::oracle::OracleHints;
use rh_grade::plan_json::{kf, plan};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// The oracle's physics check ([`rh_grade::oracle::DodgeCheck`]): of the valid DODGE
/// scenes among `scenes`, with their replay keys.
pub fn physics_dodges_of(
    dir: &Path,
    scenes: &[&Scene],
    keys: &FastMap<String, ReplayKey>,
    hints: &BTreeMap<String, OracleHints>,
    cfg: &Config,
) -> BTreeMap<String, Value> {
    use rayon::prelude::*;
    use rh_physics::execute::escape::{escape_plans, first_unstruck};
    let dodges: Vec<&Scene> = scenes
        .iter()
        .copied()
        .filter(|s| s.valid && s.gt_action == Action::Dodge)
        .collect();
    let found: Vec<Option<(String, Value)>> = dodges
        .par_iter()
        .map(|s| {
            let key = keys.get(&s.scene_id)?;
            let (replay, _) = crate::checked_replay(dir, key, &s.scene_id).ok()?;
            let heuristic = rh_grade::oracle::heuristic_dodge(s, hints.get(&s.scene_id), cfg);
            let parsed = rh_grade::plan::plan_from_value(&heuristic, cfg).ok()?;
            let mut plans = vec![crate::exec_plan(&parsed)];
            plans.extend(escape_plans(replay.spec()));
            match first_unstruck(&replay, &plans, &cfg.execution)? {
                0 => None,
                i => Some((s.scene_id.clone(), escape_json(&plans[i]))),
            }
        })
        .collect();
    found.into_iter().flatten().collect()
}

/// An escape walk as a plan line's `plan` (numbers unchanged through JSON).
fn escape_json(p: &rh_contract::execution::ExecPlan) -> Value {
    let keyframes = p
        .keyframes
        .iter()
        .map(|k| kf(k.t, k.left, k.right, k.knee_bend))
        .collect();
    plan(
        "Dodge: walk out of the hazard's path.",
        p.walking_cmd,
        p.walking_duration,
        keyframes,
    )
}
