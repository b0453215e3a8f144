//! Ground truth: reads a dataset directory built by `rh-pipeline` (specification §8).
//!
//! Every `data/*.parquet` file is read in name order; columns are looked up by name, and a
//! missing required column or one of the wrong type is an input error (exit 2) naming the
//! file and the column.

use crate::error::InputError;
use crate::fast_map::FastMap;
use anyhow::Result;
use arrow::array::{Array, RecordBatch, StringArray};
use rh_contract::columns::col;
use rh_contract::Action;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The speed bands of specification §4, slowest first (the data contract's).
pub use rh_contract::SPEED_BANDS;

/// One scene's ground truth, as the scorer needs it.
#[derive(Debug, Clone)]
pub struct Scene {
    pub scene_id: String,
    pub group_id: String,
    /// Index into `Dataset::families`.
    pub family: u16,
    /// Index into [`SPEED_BANDS`], or `None` for an unknown band name.
    pub speed_band: Option<u8>,
    pub speed_band_name: String,
    pub speed_sweep: bool,
    pub object_id: String,
    pub looks_like: Option<String>,
    pub adversarial: bool,
    /// The scene that is this one with only the object replaced by its look-alike
    /// (`twin_scene_id`, label rule v5); `None` outside adversarial twin pairs.
    pub twin_scene_id: Option<String>,
    pub gt_action: Action,
    pub dangerous: bool,
    pub danger_present: bool,
    pub impact_point: Option<[f64; 3]>,
    pub object_start: [f64; 3],
    /// `(x, y, yaw)` of the observer on the floor.
    pub observer_pose: [f64; 3],
    /// The dataset's `valid` verdict (true when the column is absent). Invalid scenes are
    /// not scored: predictions for them are counted under `invalid_scene`.
    pub valid: bool,
}

impl Scene {
    /// The hazard's target on the floor plane: the impact point, else the object's start.
    pub fn hazard_point(&self) -> [f64; 3] {
        self.impact_point.unwrap_or(self.object_start)
    }
}

/// All scenes of a dataset directory.
#[derive(Debug, Clone, Default)]
pub struct Dataset {
    pub dir: PathBuf,
    pub scenes: Vec<Scene>,
    pub families: Vec<String>,
    pub index: FastMap<String, u32>,
    /// Scene ids that appeared more than once in the Parquet files (first row kept).
    pub duplicate_rows: usize,
}

impl Dataset {
    /// Builds a dataset from scenes in memory (tests, benchmarks, fixtures).
    pub fn from_scenes(dir: PathBuf, scenes: Vec<SceneInput>) -> Dataset {
        let mut ds = Dataset {
            dir,
            ..Default::default()
        };
        for s in scenes {
            ds.push(s);
        }
        ds
    }

    fn family_index(&mut self, family: &str) -> u16 {
        if let Some(i) = self.families.iter().position(|f| f == family) {
            return i as u16;
        }
        self.families.push(family.to_string());
        (self.families.len() - 1) as u16
    }

    fn push(&mut self, s: SceneInput) {
        if self.index.contains_key(&s.scene_id) {
            self.duplicate_rows += 1;
            return;
        }
        let family = self.family_index(&s.family);
        let speed_band = SPEED_BANDS
            .iter()
            .position(|b| *b == s.speed_band)
            .map(|i| i as u8);
        self.index
            .insert(s.scene_id.clone(), self.scenes.len() as u32);
        self.scenes.push(Scene {
            scene_id: s.scene_id,
            group_id: s.group_id,
            family,
            speed_band,
            speed_band_name: s.speed_band,
            speed_sweep: s.speed_sweep,
            object_id: s.object_id,
            looks_like: s.looks_like,
            adversarial: s.adversarial,
            twin_scene_id: s.twin_scene_id,
            gt_action: s.gt_action,
            dangerous: s.dangerous,
            danger_present: s.danger_present,
            impact_point: s.impact_point,
            object_start: s.object_start,
            observer_pose: s.observer_pose,
            valid: s.valid,
        });
    }

    pub fn family_name(&self, scene: &Scene) -> &str {
        &self.families[scene.family as usize]
    }

    /// Number of valid (scored) scenes.
    pub fn valid_scenes(&self) -> usize {
        self.scenes.iter().filter(|s| s.valid).count()
    }

    pub fn get(&self, scene_id: &str) -> Option<(u32, &Scene)> {
        self.index
            .get(scene_id)
            .map(|&i| (i, &self.scenes[i as usize]))
    }

    /// Reads `DIR/data/*.parquet` in name order.
    pub fn load(dir: &Path) -> Result<Dataset> {
        let data = dir.join("data");
        if !dir.is_dir() {
            return Err(InputError(format!(
                "dataset directory {} does not exist",
                dir.display()
            ))
            .into());
        }
        if !data.is_dir() {
            return Err(InputError(crate::dataset_diagnosis::missing_parquet_message(dir)).into());
        }
        let files = parquet_files(&data)?;
        if files.is_empty() {
            return Err(InputError(crate::dataset_diagnosis::missing_parquet_message(dir)).into());
        }
        let mut ds = Dataset {
            dir: dir.to_path_buf(),
            ..Default::default()
        };
        for file in &files {
            for s in read_parquet(file)? {
                ds.push(s);
            }
        }
        if ds.scenes.is_empty() {
            return Err(InputError(format!("dataset {} has no scenes", dir.display())).into());
        }
        Ok(ds)
    }
}

/// The `.parquet` files of a folder, in name order (`rh_dataset::read`).
pub fn parquet_files(folder: &Path) -> Result<Vec<PathBuf>, InputError> {
    rh_dataset::read::parquet_files(folder).map_err(|e| InputError(e.into()))
}

/// A record-batch reader over one Parquet file (`rh_dataset::read`); a file that cannot
/// be opened or is not Parquet is an input error naming it.
pub fn open_parquet(
    file: &Path,
    batch_size: usize,
) -> Result<parquet::arrow::arrow_reader::ParquetRecordBatchReader, InputError> {
    rh_dataset::read::open_parquet(file, batch_size).map_err(|e| InputError(e.into()))
}

/// One scene as read from a row (or made by a fixture), before interning.
#[derive(Debug, Clone)]
pub struct SceneInput {
    pub scene_id: String,
    pub group_id: String,
    pub family: String,
    pub speed_band: String,
    pub speed_sweep: bool,
    pub object_id: String,
    pub looks_like: Option<String>,
    pub adversarial: bool,
    /// The scene that is this one with only the object replaced by its look-alike
    /// (`twin_scene_id`, label rule v5); `None` outside adversarial twin pairs.
    pub twin_scene_id: Option<String>,
    pub gt_action: Action,
    pub dangerous: bool,
    pub danger_present: bool,
    pub impact_point: Option<[f64; 3]>,
    pub object_start: [f64; 3],
    pub observer_pose: [f64; 3],
    pub valid: bool,
}

fn bad(file: &Path, column: &str, what: impl std::fmt::Display) -> anyhow::Error {
    InputError(rh_dataset::read::bad(file, column, what)).into()
}

fn strings(batch: &RecordBatch, file: &Path, name: &str) -> Result<Vec<Option<String>>> {
    Ok(rh_dataset::read::strings(batch, file, name).map_err(|e| InputError(e.into()))?)
}

fn required_strings(batch: &RecordBatch, file: &Path, name: &str) -> Result<Vec<String>> {
    Ok(rh_dataset::read::required_strings(batch, file, name).map_err(|e| InputError(e.into()))?)
}

fn bools(batch: &RecordBatch, file: &Path, name: &str) -> Result<Vec<bool>> {
    Ok(rh_dataset::read::bools(batch, file, name).map_err(|e| InputError(e.into()))?)
}

fn vec3s(batch: &RecordBatch, file: &Path, name: &str) -> Result<Vec<Option<[f64; 3]>>> {
    Ok(rh_dataset::read::vec3s(batch, file, name).map_err(|e| InputError(e.into()))?)
}

fn read_parquet(file: &Path) -> Result<Vec<SceneInput>> {
    let reader = open_parquet(file, 8192)?;
    let mut out = Vec::new();
    for batch in reader {
        let batch = batch.map_err(|e| InputError(format!("{}: {e}", file.display())))?;
        out.extend(scenes_of_batch(&batch, file)?);
    }
    Ok(out)
}

/// The scenes of one batch of scene-table rows read from `file` (named in errors), in
/// row order: the reader of [`Dataset::load`], and of readers that stream a table batch
/// by batch (`export`) so that memory does not grow with the table.
pub fn scenes_of_batch(batch: &RecordBatch, file: &Path) -> Result<Vec<SceneInput>> {
    let mut out = Vec::with_capacity(batch.num_rows());
    let scene_id = required_strings(batch, file, col::SCENE_ID)?;
    let group_id = required_strings(batch, file, col::GROUP_ID)?;
    let family = required_strings(batch, file, col::FAMILY)?;
    let speed_band = required_strings(batch, file, col::SPEED_BAND)?;
    let speed_sweep = bools(batch, file, col::SPEED_SWEEP)?;
    let object_id = required_strings(batch, file, col::OBJECT_ID)?;
    let looks_like = strings(batch, file, col::LOOKS_LIKE)?;
    let adversarial = bools(batch, file, col::ADVERSARIAL)?;
    // Builds before label rule v5's twins have no such column.
    let twin_scene_id = match batch.column_by_name(col::TWIN_SCENE_ID) {
        Some(_) => strings(batch, file, col::TWIN_SCENE_ID)?,
        None => vec![None; batch.num_rows()],
    };
    let gt_action = required_strings(batch, file, col::GT_ACTION)?;
    let dangerous = bools(batch, file, col::DANGEROUS)?;
    let danger_present = bools(batch, file, col::DANGER_PRESENT)?;
    let impact_point = vec3s(batch, file, col::IMPACT_POINT)?;
    let object_start = vec3s(batch, file, col::OBJECT_START)?;
    let observer_pose = vec3s(batch, file, col::OBSERVER_POSE)?;
    let valid = if batch.column_by_name(col::VALID).is_some() {
        bools(batch, file, col::VALID)?
    } else {
        vec![true; batch.num_rows()]
    };
    for i in 0..batch.num_rows() {
        let gt = Action::parse(&gt_action[i]).ok_or_else(|| {
            bad(
                file,
                col::GT_ACTION,
                format!(
                    "has value {:?} in row {i}, expected CATCH, DODGE or NO_ACTION",
                    gt_action[i]
                ),
            )
        })?;
        let object_start = object_start[i]
            .ok_or_else(|| bad(file, col::OBJECT_START, format!("is null in row {i}")))?;
        let observer_pose = observer_pose[i]
            .ok_or_else(|| bad(file, col::OBSERVER_POSE, format!("is null in row {i}")))?;
        let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        if !finite(&object_start) {
            return Err(bad(
                file,
                col::OBJECT_START,
                format!("is not finite in row {i}"),
            ));
        }
        if !finite(&observer_pose) {
            return Err(bad(
                file,
                col::OBSERVER_POSE,
                format!("is not finite in row {i}"),
            ));
        }
        if impact_point[i].is_some_and(|p| !finite(&p)) {
            return Err(bad(
                file,
                col::IMPACT_POINT,
                format!("is not finite in row {i}"),
            ));
        }
        out.push(SceneInput {
            scene_id: scene_id[i].clone(),
            group_id: group_id[i].clone(),
            family: family[i].clone(),
            speed_band: speed_band[i].clone(),
            speed_sweep: speed_sweep[i],
            object_id: object_id[i].clone(),
            looks_like: looks_like[i].clone(),
            adversarial: adversarial[i],
            twin_scene_id: twin_scene_id[i].clone(),
            gt_action: gt,
            dangerous: dangerous[i],
            danger_present: danger_present[i],
            impact_point: impact_point[i],
            object_start,
            observer_pose,
            valid: valid[i],
        });
    }
    Ok(out)
}

/// What `--execute` needs to replay one scene: its spec file and the stored state hashes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReplayKey {
    /// `spec_file`, relative to the dataset root (default `specs/<scene_id>.json`).
    pub spec_file: String,
    /// `state_hash` (whole run), when the column exists.
    pub state_hash: Option<String>,
    /// `decision_state_hash` (steps 0..=Δ), when the column exists.
    pub decision_state_hash: Option<String>,
}

/// Reads the replay columns of `DIR/data/*.parquet` (absent optional columns are `None`).
pub fn read_replay_keys(dir: &Path) -> Result<FastMap<String, ReplayKey>> {
    let files = parquet_files(&dir.join("data"))?;
    let mut out = FastMap::default();
    for file in &files {
        let reader = open_parquet(file, 8192)?;
        for batch in reader {
            let batch = batch.map_err(|e| InputError(format!("{}: {e}", file.display())))?;
            for (id, key) in replay_keys_of_batch(&batch, file)? {
                out.entry(id).or_insert(key);
            }
        }
    }
    Ok(out)
}

/// The replay columns of one batch of scene-table rows (see [`read_replay_keys`]), in row
/// order.
pub fn replay_keys_of_batch(batch: &RecordBatch, file: &Path) -> Result<Vec<(String, ReplayKey)>> {
    let optional = |name: &str| -> Result<Vec<Option<String>>> {
        if batch.column_by_name(name).is_some() {
            strings(batch, file, name)
        } else {
            Ok(vec![None; batch.num_rows()])
        }
    };
    let ids = required_strings(batch, file, col::SCENE_ID)?;
    let specs = optional(col::SPEC_FILE)?;
    let full = optional(col::STATE_HASH)?;
    let decision = optional(col::DECISION_STATE_HASH)?;
    Ok(ids
        .into_iter()
        .enumerate()
        .map(|(i, id)| {
            let key = ReplayKey {
                spec_file: specs[i]
                    .clone()
                    .unwrap_or_else(|| rh_contract::layout::spec_path(&id)),
                state_hash: full[i].clone(),
                decision_state_hash: decision[i].clone(),
            };
            (id, key)
        })
        .collect())
}

/// Which scenes a run covers: the eval subset or every valid scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Subset {
    /// The balanced evaluation subset (the dataset's `eval` config).
    Eval,
    /// Every valid scene.
    All,
}

/// Scene ids of the dataset's `eval/*.parquet`, or `None` when it has no eval config.
pub fn eval_scene_ids(dir: &Path) -> Result<Option<BTreeSet<String>>> {
    let eval = dir.join("eval");
    if !eval.is_dir() {
        return Ok(None);
    }
    let files = parquet_files(&eval)?;
    if files.is_empty() {
        return Ok(None);
    }
    let mut ids = BTreeSet::new();
    for f in files {
        let bad = |e: &dyn std::fmt::Display| InputError(format!("{}: {e}", f.display()));
        let reader = open_parquet(&f, 1024)?;
        for batch in reader {
            let batch = batch.map_err(|e| bad(&e))?;
            let col = batch
                .column_by_name("scene_id")
                .and_then(|c| c.as_any().downcast_ref::<StringArray>().cloned())
                .ok_or_else(|| bad(&"no string column `scene_id`"))?;
            for i in 0..col.len() {
                if col.is_valid(i) {
                    ids.insert(col.value(i).to_string());
                }
            }
        }
    }
    Ok(Some(ids))
}

/// Refuses (exit 2) a directory whose `build.json` does not record a finished build
/// (`rh_dataset::manifest::unfinished`: no file checksums, or recorded files missing),
/// naming what is missing and the command that finishes it; with `allow_incomplete`
/// (`--allow-incomplete`) it is used as it is, with a warning on stderr.
pub fn check_finished(dir: &Path, allow_incomplete: bool) -> Result<()> {
    match rh_dataset::manifest::unfinished(dir).map_err(|e| InputError(e.into()))? {
        None => Ok(()),
        Some(why) if allow_incomplete => {
            rh_contract::note!("rh-score: warning: {why}. Used as it is (--allow-incomplete).");
            Ok(())
        }
        Some(why) => Err(InputError(format!(
            "{why}; or pass --allow-incomplete to use it as it is"
        ))
        .into()),
    }
}
