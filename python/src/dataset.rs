//! `reacthuman._native.NativeDataset`: a loaded dataset and the calls that need one
//! (score, classify, prompt, execute). Every call goes to the scorer's crates (`rh_grade`, `rh_execute`, `rh_prompt`) or the
//! physics (`rh_physics`) library; nothing here decides a number.

use crate::errors::{run, Error, Result};
use pyo3::prelude::*;
use rh_grade::dataset::{ReplayKey, Scene, Subset};
use rh_grade::fast_map::FastMap;
use rh_grade::plan::{plan_from_text, plan_from_value, Plan, PlanError};
use rh_grade::{Config, Dataset};
use rh_physics::execute::Replay;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// A dataset directory loaded by the scorer, with the replays made so far.
#[pyclass(module = "reacthuman._native", frozen)]
pub struct NativeDataset {
    pub ds: Dataset,
    pub cfg: Config,
    keys: OnceLock<FastMap<String, ReplayKey>>,
    replays: Mutex<HashMap<String, Arc<Replay>>>,
}

/// Resolves a directory or Hub id (`rh_locate::resolve_dir`), a missing one being
/// `FileNotFoundError`.
fn resolve(path: &str) -> Result<PathBuf> {
    let p = Path::new(path);
    if !p.exists() {
        let repo = path.split_once('@').map_or(path, |(r, _)| r);
        let hub_like = !path.starts_with('.') && !path.starts_with('/') && rh_hub_like(repo);
        if !hub_like {
            return Err(Error::NotFound(format!(
                "dataset directory {path} does not exist (nor is it a Hub dataset id owner/name)"
            )));
        }
    } else if !p.join("data").is_dir() {
        return Err(Error::NotFound(format!(
            "{}: no data/ folder; {}",
            p.display(),
            rh_grade::dataset_diagnosis::missing_parquet_message(p)
        )));
    }
    Ok(rh_locate::resolve_dir(Some(path.to_string()))?)
}

/// `owner/name` with one slash (the Hub's dataset id shape).
fn rh_hub_like(repo: &str) -> bool {
    let mut parts = repo.split('/');
    matches!((parts.next(), parts.next(), parts.next()), (Some(a), Some(b), None) if !a.is_empty() && !b.is_empty())
}

fn plan_error_text(e: &PlanError) -> String {
    match e {
        PlanError::NoJson => "plan: no JSON object in the text (r1_no_json_in_response)".into(),
        PlanError::NotAPlan => {
            "plan: no field walking_cmd or keyframes (r1_not_a_plan: not a plan)".into()
        }
        PlanError::Malformed(m) | PlanError::Absurd(m) | PlanError::TooLarge(m) => {
            format!("plan: {m} ({})", e.kind())
        }
    }
}

/// Parses a plan given as JSON text: an object (the scorer's plan forms) or a string (a
/// model's raw response, read leniently as the scorer reads `response`).
pub fn parse_plan(text: &str, cfg: &Config) -> Result<Plan> {
    // NaN / Infinity (Python's json writes them bare) are quoted as the scorer does for
    // model text, so they reach the plan's sanity check (`absurd_number`).
    let v: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => rh_grade::plan::quote_nonfinite(text)
            .and_then(|t| serde_json::from_str(&t).ok())
            .ok_or_else(|| Error::Value(format!("plan is not valid JSON: {e}")))?,
    };
    let r = match &v {
        Value::String(s) => plan_from_text(s, cfg),
        other => plan_from_value(other, cfg),
    };
    r.map_err(|e| Error::Value(plan_error_text(&e)))
}

/// A scene with no hazard direction (observer at the origin): the action rule without its
/// retreat test, for `classify(plan)` without a scene.
fn neutral_scene() -> Scene {
    Scene {
        scene_id: String::new(),
        group_id: String::new(),
        family: 0,
        speed_band: None,
        speed_band_name: String::new(),
        speed_sweep: false,
        object_id: String::new(),
        looks_like: None,
        adversarial: false,
        twin_scene_id: None,
        gt_action: rh_grade::Action::NoAction,
        dangerous: false,
        danger_present: false,
        impact_point: None,
        object_start: [0.0; 3],
        observer_pose: [0.0; 3],
        valid: true,
    }
}

fn subset(name: Option<&str>) -> Result<Option<Subset>> {
    match name {
        None => Ok(None),
        Some("eval") => Ok(Some(Subset::Eval)),
        Some("all") => Ok(Some(Subset::All)),
        Some(other) => Err(Error::Value(format!(
            "subset must be \"eval\" or \"all\", got {other:?}"
        ))),
    }
}

impl NativeDataset {
    pub fn scene(&self, scene_id: &str) -> Result<&Scene> {
        self.ds
            .get(scene_id)
            .map(|(_, s)| s)
            .ok_or_else(|| Error::Key(format!("scene_id {scene_id:?} is not in the dataset")))
    }

    /// The scene replayed to Δ and checked against the stored state hash (cached).
    pub fn replay(&self, scene_id: &str) -> Result<Arc<Replay>> {
        self.scene(scene_id)?;
        if let Some(r) = self.replays.lock().expect("not poisoned").get(scene_id) {
            return Ok(r.clone());
        }
        let keys = match self.keys.get() {
            Some(k) => k,
            None => {
                let k = rh_grade::dataset::read_replay_keys(&self.ds.dir)?;
                self.keys.get_or_init(|| k)
            }
        };
        let key = rh_execute::replay_key(keys, scene_id)?;
        let (r, _) = rh_execute::checked_replay(&self.ds.dir, key, scene_id)?;
        let r = Arc::new(r);
        self.replays
            .lock()
            .expect("not poisoned")
            .insert(scene_id.to_string(), r.clone());
        Ok(r)
    }
}

#[pymethods]
impl NativeDataset {
    /// `allow_incomplete`: use a build that did not finish (refused otherwise with
    /// `ValueError`, naming what is missing and the command that finishes it).
    #[new]
    #[pyo3(signature = (path, allow_incomplete = false))]
    fn new(py: Python<'_>, path: &str, allow_incomplete: bool) -> PyResult<Self> {
        run(py, || {
            let dir = resolve(path)?;
            rh_grade::dataset::check_finished(&dir, allow_incomplete)?;
            Ok(NativeDataset {
                ds: Dataset::load(&dir)?,
                cfg: Config::default(),
                keys: OnceLock::new(),
                replays: Mutex::new(HashMap::new()),
            })
        })
    }

    /// The dataset directory (a Hub id resolves to its local snapshot).
    #[getter]
    fn dir(&self) -> String {
        self.ds.dir.display().to_string()
    }

    /// Scene ids in dataset order.
    fn scene_ids(&self) -> Vec<String> {
        self.ds.scenes.iter().map(|s| s.scene_id.clone()).collect()
    }

    /// Scene ids of the eval subset (sorted), or None when the dataset has none.
    fn eval_ids(&self, py: Python<'_>) -> PyResult<Option<Vec<String>>> {
        run(py, || {
            let ids = rh_grade::dataset::eval_scene_ids(&self.ds.dir)?;
            Ok(ids.map(|s| s.into_iter().collect()))
        })
    }

    /// The scenes `rh-score predict --subset S [--limit N]` runs, in its order: the valid
    /// scenes of the subset in dataset order (`rh_prompt::select_scenes`).
    #[pyo3(signature = (subset, limit=None))]
    fn predict_scenes(
        &self,
        py: Python<'_>,
        subset: String,
        limit: Option<usize>,
    ) -> PyResult<Vec<String>> {
        run(py, || {
            let s = self::subset(Some(&subset))?.expect("a named subset");
            Ok(rh_prompt::select_scenes(&self.ds, s, limit)?)
        })
    }

    /// `specs/<scene_id>.json` (absolute) of a known scene.
    fn spec_path(&self, scene_id: &str) -> PyResult<String> {
        crate::errors::guard(|| {
            self.scene(scene_id)?;
            let rel = rh_contract::layout::spec_path(scene_id);
            Ok(self.ds.dir.join(rel).display().to_string())
        })
    }

    /// The observation frames of a known scene: (camera, t, absolute path), whether or
    /// not they exist (a `--no-render` build has none).
    fn frame_paths(&self, scene_id: &str) -> PyResult<Vec<(String, f64, String)>> {
        crate::errors::guard(|| {
            self.scene(scene_id)?;
            let mut out = Vec::new();
            for cam in rh_contract::layout::CAMERAS {
                for t in rh_contract::layout::FRAME_TIMES {
                    let rel = rh_contract::layout::frame_path(scene_id, cam, t);
                    out.push((
                        cam.to_string(),
                        t,
                        self.ds.dir.join(rel).display().to_string(),
                    ));
                }
            }
            Ok(out)
        })
    }

    /// The JSON report of `rh-score PREDS --dataset DIR --json -` (`rh_grade::api`): from
    /// a file (`path`) or JSON Lines text (`text`, reported as `name`).
    #[pyo3(signature = (path=None, text=None, name="<list>", subset=None, answered_only=false))]
    fn score(
        &self,
        py: Python<'_>,
        path: Option<String>,
        text: Option<String>,
        name: &str,
        subset: Option<String>,
        answered_only: bool,
    ) -> PyResult<String> {
        run(py, || {
            let subset = self::subset(subset.as_deref())?;
            let preds = match (&path, &text) {
                (Some(p), None) => {
                    let p = Path::new(p);
                    if !p.exists() {
                        return Err(Error::NotFound(format!(
                            "predictions file {} does not exist",
                            p.display()
                        )));
                    }
                    rh_grade::api::Preds::Path(p)
                }
                (None, Some(t)) => rh_grade::api::Preds::Text { name, text: t },
                _ => return Err(Error::Value("give the predictions as path or text".into())),
            };
            let report =
                rh_grade::api::score_report(&self.ds, &self.cfg, subset, answered_only, preds)?;
            serde_json::to_string(&report).map_err(|e| Error::Internal(e.to_string()))
        })
    }

    /// The decision lines (JSON Lines text) of `rh-score PREDS --dataset DIR [--subset S]
    /// --decisions FILE` for predictions given as JSON Lines text: one line per input
    /// decision (status scored / lost / duplicate, action, rules fired, metrics). Lines the
    /// scorer drops (outside the subset, no scene id, ...) have none.
    #[pyo3(signature = (text, subset=None))]
    fn decisions(&self, py: Python<'_>, text: String, subset: Option<String>) -> PyResult<String> {
        run(py, || {
            let subset = self::subset(subset.as_deref())?;
            let expected = rh_grade::coverage::Expected::resolve(&self.ds, subset)?;
            let mut out = Vec::new();
            rh_grade::Scoring::new(&self.ds, &self.cfg)
                .with_expected(expected)
                .with_decisions_output(Box::new(&mut out))
                .score_reader(std::io::Cursor::new(text.as_bytes()))?;
            String::from_utf8(out).map_err(|e| Error::Internal(e.to_string()))
        })
    }

    /// The action rule on a plan (JSON text) in a scene (or none): action and kinematics.
    #[pyo3(signature = (plan, scene_id=None))]
    fn classify(&self, py: Python<'_>, plan: String, scene_id: Option<String>) -> PyResult<String> {
        run(py, || {
            classify_json(
                &self.cfg,
                &plan,
                scene_id.as_deref().map(|id| self.scene(id)).transpose()?,
            )
        })
    }

    /// The canonical messages (JSON text) of a scene and their `prompt_hash`.
    fn prompt(&self, py: Python<'_>, scene_id: String) -> PyResult<(String, String)> {
        run(py, || {
            self.scene(&scene_id)?;
            let cfg = rh_prompt::PromptConfig::load(None)?;
            let (messages, hash) =
                rh_prompt::canonical(&cfg, &self.ds.dir, &scene_id).map_err(|e| match e {
                    rh_prompt::PromptError::MissingFrame(_) => Error::NotFound(e.to_string()),
                    rh_prompt::PromptError::Invalid(m) => Error::Value(m),
                })?;
            Ok((messages.to_string(), hash))
        })
    }

    /// The executor's outcome (JSON text) of a plan (JSON text) in a scene.
    fn execute(&self, py: Python<'_>, scene_id: String, plan: String) -> PyResult<String> {
        run(py, || {
            let plan = parse_plan(&plan, &self.cfg)?;
            let replay = self.replay(&scene_id)?;
            let outcome = replay.execute(&rh_execute::exec_plan(&plan), &self.cfg.execution);
            serde_json::to_string(&outcome).map_err(|e| Error::Internal(e.to_string()))
        })
    }
}

/// `classify` without a dataset (the neutral scene) or with one's scene.
pub fn classify_json(cfg: &Config, plan: &str, scene: Option<&Scene>) -> Result<String> {
    let plan = parse_plan(plan, cfg)?;
    let neutral = neutral_scene();
    let scene = scene.unwrap_or(&neutral);
    let (action, k) = rh_grade::action_rule::classify(&plan, scene, cfg);
    let v = json!({
        "action": action.as_str(),
        "rule_version": cfg.action_rule.version,
        "displacement": k.displacement,
        "hazard_dir": k.hazard_dir,
        "d_dot_u": k.d_dot_u,
        "reach": k.reach,
        "final_base": [k.final_base.x, k.final_base.y, k.final_base.yaw],
        "hands_world": k.hands_world,
        "plan": {
            "walking_cmd": plan.walking_cmd,
            "walking_duration": plan.walking_duration,
            "keyframes": plan.keyframes.iter().map(|f| json!({
                "t": f.t, "left_hand": f.left, "right_hand": f.right, "knee_bend": f.knee_bend,
            })).collect::<Vec<_>>(),
            "notes": plan.notes,
        },
    });
    Ok(v.to_string())
}
