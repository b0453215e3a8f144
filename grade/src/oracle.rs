//! The `oracle` baseline's plans (`rh-score baseline oracle`): from the scene's ground
//! truth, a plan that the action rule classifies as the ground-truth action and that the
//! humanoid can carry out in physics (`--execute`, specification §12) in time.
//!
//! * **CATCH** — the base turns to face the impact point and walks straight towards it
//!   (≤ [`CATCH_SPEED`], within the executor's 1.5 m/s and 3.5 rad/s) until the point is
//!   [`CATCH_STANDOFF`] m ahead of the pelvis (less when that is out of the arm's reach),
//!   as fast as the limits allow, so the hands are there before the object arrives; the
//!   final keyframe, at the end of the walk (≥ 0.2 s, the hands' travel), puts the mean
//!   hand exactly on the impact point. Impact points too low for the standing arm (below
//!   ≈ 0.66 m) are met with a knee bend (the least that brings the point within reach,
//!   ≤ 1); the hands are on the point in the crouched body frame (action rule v2 lowers
//!   them with the pelvis, as the executor does), so d_end is < 1e-6 m everywhere and the
//!   executed hands are where the metric reads them. When the
//!   point is closer than the stance (walking there would be a retreat) the base stays
//!   and only the hands go. A first keyframe at 0.15 s reaches ≥ 0.30 m forward whenever
//!   the final one does not, so the rule's reach test (≥ 0.20 m) holds.
//! * **DODGE** — hands at rest, walk [`DODGE_DISTANCE`] m at [`DODGE_SPEED`] m/s away
//!   from the impact point, turned towards the side of the hazard's path the observer is
//!   already on (the path from the hazard's horizontal motion between Δ and the impact,
//!   from the dataset's `trajectory` column, when the dataset has it: [`OracleHints`]).
//!   With the dataset's specs that walk is executed first ([`physics_dodges`]); if it
//!   would be struck, the first of the label's escape walks that is not replaces it.
//! * **NO_ACTION** — stand still, hands at rest.

use crate::config::Config;
use crate::dataset::{open_parquet, parquet_files, read_replay_keys, Dataset, ReplayKey, Scene};
use crate::fast_map::FastMap;
use crate::plan_json::{kf, plan, solve_walk, wrap_angle};
use anyhow::Result;
use arrow::array::{Array, FixedSizeListArray, Float32Array, Float64Array, ListArray, RecordBatch};
use rh_contract::Action;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// CATCH stance: the impact point this far ahead of the pelvis when the arm allows (m).
pub const CATCH_STANDOFF: f64 = 0.40;
/// CATCH walking speed (m/s), under the robot's 1.5 m/s.
pub const CATCH_SPEED: f64 = 1.3;
/// DODGE: distance (m) and speed (m/s) of the walk away.
pub const DODGE_DISTANCE: f64 = 1.6;
pub const DODGE_SPEED: f64 = 1.45;
/// specification §2 arm (the executor's body): shoulder height above the pelvis, shoulder offset
/// sideways, reach used for planning (a little short of the 0.55 m arm), the palms'
/// offset either side of the mean hand.
const SHOULDER_Z: f64 = 0.30;
const SHOULDER_Y: f64 = 0.17;
const PLAN_REACH: f64 = 0.53;
const HAND_HALF_GAP: f64 = 0.05;
/// Forward hand distance that passes rule v1's reach test with margin (rest x 0.10).
const REACH_X: f64 = 0.32;
/// specification §1's default decision moment Δ (s), for datasets without specs.
const DEFAULT_DELTA: f64 = 0.6;

/// Ground truth beyond the scene row that the oracle uses when the dataset has it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OracleHints {
    /// The hazard's horizontal displacement (world) from Δ to the impact (else to the end
    /// of the stored trajectory).
    pub hazard_motion: Option<[f64; 2]>,
    /// The DODGE plan checked in physics ([`physics_dodges`]) when the heuristic dodge
    /// would be struck and an escape walk is not.
    pub dodge: Option<Value>,
}

/// Largest forward distance of the mean hand at body height `zb` above the pelvis that
/// the arms reach (negative when no forward distance does).
fn forward_reach(zb: f64) -> f64 {
    let dz = zb - SHOULDER_Z;
    let lateral = SHOULDER_Y - HAND_HALF_GAP;
    let v = PLAN_REACH * PLAN_REACH - dz * dz - lateral * lateral;
    if v > 0.0 {
        v.sqrt()
    } else {
        -1.0
    }
}

/// The oracle's CATCH plan (see the module doc).
pub fn catch(scene: &Scene, cfg: &Config) -> Value {
    let [x0, y0, th0] = scene.observer_pose;
    let p = scene.hazard_point();
    let pelvis = cfg.body.pelvis_height;
    let max_drop = cfg.execution.max_pelvis_drop;
    let (dx, dy) = (p[0] - x0, p[1] - y0);
    let d = dx.hypot(dy);
    // The least knee bend (in 0.01 m steps of pelvis drop) that brings the point within
    // a forward reach of REACH_X - 0.02; only for points below the shoulder.
    let mut drop = 0.0;
    while forward_reach(p[2] - (pelvis - drop)) < REACH_X - 0.02
        && drop < max_drop
        && p[2] < pelvis + SHOULDER_Z
    {
        drop = (drop + 0.01).min(max_drop);
    }
    let zb = p[2] - (pelvis - drop);
    let a = CATCH_STANDOFF.min(forward_reach(zb).max(0.12));
    let (s0, c0) = th0.sin_cos();
    let (mut goal, mut yaw1, mut hand) = ([x0, y0], th0, [c0 * dx + s0 * dy, -s0 * dx + c0 * dy]);
    let walk = d - a;
    if d > 1e-9 && walk >= -0.10 {
        goal = [x0 + dx / d * walk, y0 + dy / d * walk];
        yaw1 = dy.atan2(dx);
        hand = [a, 0.0];
    }
    let dth = wrap_angle(yaw1 - th0);
    let dist = (goal[0] - x0).hypot(goal[1] - y0);
    let mut dur = (dist / CATCH_SPEED).max(dth.abs() / 3.0).max(0.1);
    let mut cmd = solve_walk(scene.observer_pose, goal, th0 + dth, dur);
    // A turning walk is an arc, longer than the chord: stretch it to the speed.
    let speed = cmd[0].hypot(cmd[1]);
    if speed > CATCH_SPEED {
        dur *= speed / CATCH_SPEED;
        cmd = solve_walk(scene.observer_pose, goal, th0 + dth, dur);
    }
    let knee = drop / max_drop;
    // The hands on the point in the crouched body frame, where action rule v2 (and the
    // executor) put them: the oracle's d_end is exactly 0.
    let z_rule = p[2] - crate::action_rule::pelvis_height(knee, cfg);
    let at = |x: f64| {
        (
            [x, hand[1] + HAND_HALF_GAP, z_rule],
            [x, hand[1] - HAND_HALF_GAP, z_rule],
        )
    };
    let mut keyframes = Vec::new();
    if hand[0] < REACH_X {
        let (l, r) = at(REACH_X);
        keyframes.push(kf(0.15, l, r, knee));
    }
    let (l, r) = at(hand[0]);
    keyframes.push(kf(dur.max(0.2), l, r, knee));
    plan(
        "Step toward the object, reach out and catch it with both hands.",
        cmd,
        dur,
        keyframes,
    )
}

/// The oracle's DODGE plan (see the module doc): the physics-checked one when the hints
/// have it, else the heuristic walk.
pub fn dodge(scene: &Scene, hints: Option<&OracleHints>, cfg: &Config) -> Value {
    match hints.and_then(|h| h.dodge.clone()) {
        Some(plan) => plan,
        None => heuristic_dodge(scene, hints, cfg),
    }
}

/// The heuristic walk away from the impact point (see the module doc).
pub fn heuristic_dodge(scene: &Scene, hints: Option<&OracleHints>, cfg: &Config) -> Value {
    let [x0, y0, th0] = scene.observer_pose;
    let p = scene.hazard_point();
    let (ux, uy) = (p[0] - x0, p[1] - y0);
    let n = ux.hypot(uy);
    let u = if n > 1e-9 {
        [ux / n, uy / n]
    } else {
        [th0.cos(), th0.sin()]
    };
    let mut away = [-u[0], -u[1]];
    if let Some([vx, vy]) = hints.and_then(|h| h.hazard_motion) {
        let vn = vx.hypot(vy);
        if vn > 0.05 {
            // Perpendicular to the hazard's path, on the observer's side of it.
            let mut side = [-vy / vn, vx / vn];
            if (x0 - p[0]) * side[0] + (y0 - p[1]) * side[1] < 0.0 {
                side = [-side[0], -side[1]];
            }
            away = [away[0] + side[0], away[1] + side[1]];
        }
    }
    let an = away[0].hypot(away[1]).max(1e-12);
    let dir = [away[0] / an, away[1] / an];
    let dur = DODGE_DISTANCE / DODGE_SPEED;
    let (s, c) = th0.sin_cos();
    let cmd = [
        (c * dir[0] + s * dir[1]) * DODGE_SPEED,
        (-s * dir[0] + c * dir[1]) * DODGE_SPEED,
        0.0,
    ];
    plan(
        "Dodge: step back and move away from the hazard's path.",
        cmd,
        dur,
        vec![kf(dur, cfg.body.rest_left, cfg.body.rest_right, 0.0)],
    )
}

/// The oracle's plan for one scene.
pub fn oracle_plan(scene: &Scene, hints: Option<&OracleHints>, cfg: &Config) -> Value {
    match scene.gt_action {
        Action::Catch => catch(scene, cfg),
        Action::Dodge => dodge(scene, hints, cfg),
        Action::NoAction => crate::plan_json::freeze_template(cfg),
    }
}

/// The physics check of the oracle's dodges, which needs the simulator
/// (`rh_execute::physics_dodges_of`): for the valid DODGE scenes among `scenes`
/// whose spec replays (`keys`), the escape walks that replace a heuristic dodge (from
/// `hints`) the executor finds struck, by scene id.
pub type DodgeCheck = fn(
    &Path,
    &[&Scene],
    &FastMap<String, ReplayKey>,
    &BTreeMap<String, OracleHints>,
    &Config,
) -> BTreeMap<String, Value>;

/// The hints of every scene: [`read_hints`], then the physics-checked dodges
/// ([`physics_dodges`]) with `check`; without one, a dataset with specs is refused.
pub fn load_hints(
    ds: &Dataset,
    cfg: &Config,
    check: Option<DodgeCheck>,
) -> Result<BTreeMap<String, OracleHints>> {
    let mut hints = read_hints(ds)?;
    match check {
        Some(check) => {
            for (id, plan) in physics_dodges(ds, &hints, cfg, check) {
                hints.entry(id).or_default().dodge = Some(plan);
            }
        }
        None => refuse_without_physics(&ds.dir, cfg)?,
    }
    Ok(hints)
}

/// [`load_hints`] for one batch of scene rows of the dataset at `dir` (a reader that
/// streams the table, `export`): the hazard's motion from the batch's columns, Δ from the
/// scenes' specs, then the physics-checked dodges of `scenes` (the batch's) — the hints
/// [`load_hints`] gives these scenes.
pub fn batch_hints(
    dir: &Path,
    batch: &RecordBatch,
    keys: &FastMap<String, ReplayKey>,
    scenes: &[Scene],
    cfg: &Config,
    check: Option<DodgeCheck>,
) -> Result<BTreeMap<String, OracleHints>> {
    let delta = |id: &str| {
        keys.get(id)
            .and_then(|k| decision_time(dir, k))
            .unwrap_or(DEFAULT_DELTA)
    };
    let mut hints: BTreeMap<String, OracleHints> = motions_of_batch(batch, &delta)?
        .unwrap_or_default()
        .into_iter()
        .collect();
    match check {
        Some(check) => {
            let scenes: Vec<&Scene> = scenes.iter().collect();
            for (id, plan) in check(dir, &scenes, keys, &hints, cfg) {
                hints.entry(id).or_default().dodge = Some(plan);
            }
        }
        None => refuse_without_physics(dir, cfg)?,
    }
    Ok(hints)
}

/// Without the physics check the oracle cannot check its dodges: a dataset with specs is
/// refused.
fn refuse_without_physics(dir: &Path, _cfg: &Config) -> Result<()> {
    if dir.join("specs").is_dir() {
        return Err(crate::error::InputError(
            "the oracle checks its dodges in physics, but this rh-score was built without the `execute` feature; rebuild with default features".into(),
        )
        .into());
    }
    Ok(())
}

/// DODGE plans checked in physics with `--execute`'s executor (`cfg.execution`): for every
/// valid DODGE scene whose spec replays (checked against the dataset's hash), the
/// heuristic dodge is executed; when it is struck, the first escape walk that is not
/// (`rh_physics::execute::escape`, the walks of the label's validator
/// `valid_escapable`, so one exists in every valid scene of rule v4 that would strike)
/// replaces it. Scenes without specs, or where nothing escapes, keep the heuristic.
pub fn physics_dodges(
    ds: &Dataset,
    hints: &BTreeMap<String, OracleHints>,
    cfg: &Config,
    check: DodgeCheck,
) -> BTreeMap<String, Value> {
    let Ok(keys) = read_replay_keys(&ds.dir) else {
        return BTreeMap::new();
    };
    let scenes: Vec<&Scene> = ds.scenes.iter().collect();
    check(&ds.dir, &scenes, &keys, hints, cfg)
}

/// Reads the hints of every scene from `DIR/data/*.parquet` (`time_to_impact`,
/// `trajectory`) and `DIR/specs/` (Δ); a dataset without those columns gives none.
fn read_hints(ds: &Dataset) -> Result<BTreeMap<String, OracleHints>> {
    let deltas = decision_times(ds);
    let delta = |id: &str| deltas.get(id).copied().unwrap_or(DEFAULT_DELTA);
    let mut out = BTreeMap::new();
    let Ok(files) = parquet_files(&ds.dir.join("data")) else {
        return Ok(out);
    };
    for file in files {
        let reader = open_parquet(&file, 8192)?;
        for batch in reader {
            match motions_of_batch(&batch?, &delta)? {
                Some(hints) => out.extend(hints),
                None => return Ok(out),
            }
        }
    }
    Ok(out)
}

/// The hazard motions of one batch of rows, Δ of a scene from `delta`; `None` when the
/// batch lacks `time_to_impact` or `trajectory` (or they have other types).
fn motions_of_batch(
    batch: &RecordBatch,
    delta: &dyn Fn(&str) -> f64,
) -> Result<Option<Vec<(String, OracleHints)>>> {
    let (Some(ids), Some(tti), Some(traj)) = (
        batch.column_by_name("scene_id"),
        batch.column_by_name("time_to_impact"),
        batch.column_by_name("trajectory"),
    ) else {
        return Ok(None);
    };
    let ids = arrow::compute::cast(ids, &arrow::datatypes::DataType::Utf8)?;
    let ids = ids
        .as_any()
        .downcast_ref::<arrow::array::StringArray>()
        .expect("cast to Utf8");
    let (Some(tti), Some(traj)) = (
        tti.as_any().downcast_ref::<Float64Array>(),
        traj.as_any().downcast_ref::<ListArray>(),
    ) else {
        return Ok(None);
    };
    let mut out = Vec::with_capacity(batch.num_rows());
    for i in 0..batch.num_rows() {
        let id = ids.value(i).to_string();
        let t_end = (!tti.is_null(i)).then(|| tti.value(i));
        let motion = hazard_motion(&traj.value(i), delta(&id), t_end);
        out.push((
            id,
            OracleHints {
                hazard_motion: motion,
                dodge: None,
            },
        ));
    }
    Ok(Some(out))
}

/// Displacement of the trajectory's (t, x, y, z) samples from the one nearest `from` to
/// the one nearest `to` (else the last).
fn hazard_motion(samples: &dyn Array, from: f64, to: Option<f64>) -> Option<[f64; 2]> {
    let list = samples.as_any().downcast_ref::<FixedSizeListArray>()?;
    let values = list.values().as_any().downcast_ref::<Float32Array>()?;
    if list.value_length() != 4 || list.is_empty() {
        return None;
    }
    let row = |k: usize| [0, 1, 2].map(|j| values.value(4 * k + j) as f64);
    let nearest = |t: f64| {
        (0..list.len())
            .min_by(|&a, &b| {
                let (ta, tb) = (row(a)[0], row(b)[0]);
                (ta - t).abs().total_cmp(&(tb - t).abs())
            })
            .unwrap_or(0)
    };
    let a = row(nearest(from));
    let b = match to {
        Some(t) => row(nearest(t.max(from + 0.1))),
        None => row(list.len() - 1),
    };
    Some([b[1] - a[1], b[2] - a[2]])
}

/// Δ per scene from `specs/<id>.json` (`observation_window_s`), where readable.
fn decision_times(ds: &Dataset) -> BTreeMap<String, f64> {
    let Ok(keys) = read_replay_keys(&ds.dir) else {
        return BTreeMap::new();
    };
    keys.iter()
        .filter_map(|(id, key)| Some((id.clone(), decision_time(&ds.dir, key)?)))
        .collect()
}

/// Δ of one scene from its spec file (`observation_window_s`), where readable.
fn decision_time(dir: &Path, key: &ReplayKey) -> Option<f64> {
    let text = std::fs::read_to_string(dir.join(&key.spec_file)).ok()?;
    serde_json::from_str::<Value>(&text).ok()?["observation_window_s"].as_f64()
}
