//! `rh-score export`: a dataset's scenes as fine-tuning data, a Hugging Face dataset in
//! the conversational format TRL reads. `--format sft`: one `messages` row per scene, the
//! canonical prompt (`configs/prompt.toml`) then the oracle's plan as the assistant turn;
//! `--format preference`: `prompt`, `chosen` (the oracle's plan) and `rejected` (a plan the
//! benchmark's rules score as wrong, [`example`]). Rendered builds carry the observation
//! frames (an `images` column, the JPEGs `rh-score predict` sends); label-only builds
//! give text-only examples.
//!
//! Entry point: [`run`]. The scene table is streamed batch by batch (a row group of
//! output at a time, [`table::Sink`]), so memory does not grow with the number of scenes;
//! the only per-dataset state is the eval subset's ids (at most a few hundred).

pub mod card;
pub mod example;
pub mod table;

use anyhow::Result;
use example::{Example, SceneInfo};
use rayon::prelude::*;
use rh_grade::aia::AiaMatcher;
use rh_grade::config::Config;
use rh_grade::dataset::{
    eval_scene_ids, open_parquet, parquet_files, replay_keys_of_batch, scenes_of_batch, Dataset,
};
use rh_grade::error::InputError;
use rh_grade::fast_map::FastMap;
use rh_prompt::PromptConfig;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use table::{Shape, Sink};

/// What the rows are for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Supervised fine-tuning: `messages` (system, user, assistant).
    Sft,
    /// Preference pairs (DPO): `prompt`, `chosen`, `rejected`.
    Preference,
}

/// Which scenes become rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Split {
    /// Every valid scene outside the balanced eval subset (all valid scenes when the
    /// dataset has none): training data that leaves the benchmark's scenes unseen.
    Train,
    /// The balanced eval subset only.
    Eval,
    /// Every valid scene.
    All,
}

impl Split {
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Eval => "eval",
            Split::All => "all",
        }
    }
}

/// Everything `rh-score export` was asked to do.
#[derive(Debug, Clone)]
pub struct ExportOptions {
    pub dataset: PathBuf,
    pub out: PathBuf,
    pub format: Format,
    pub split: Split,
    /// Leave the images out even when the dataset has frames.
    pub text_only: bool,
    pub prompt: PromptConfig,
    pub config: Config,
    /// The oracle's physics check of its dodges (`rh_execute::physics_dodges_of`); without
    /// one, a dataset with specs is refused.
    pub dodge_check: Option<rh_grade::oracle::DodgeCheck>,
}

/// What was written.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Summary {
    pub out: String,
    pub file: String,
    pub format: &'static str,
    pub split: &'static str,
    pub rows: usize,
    pub images: bool,
    /// Rows whose chosen plan is at full precision (millimetres would not score).
    pub full_precision_plans: usize,
    /// The dataset had no eval subset, so `train` took every valid scene.
    pub no_eval_subset: bool,
}

/// Scene rows read per batch: a few row groups of text rows, or one of rows with images
/// (each carries its frames, so memory stays bounded by the row group).
fn read_batch_rows(images: bool) -> usize {
    if images {
        table::IMAGE_ROW_GROUP
    } else {
        256
    }
}

/// Refuses an output directory that exists and is not empty (nothing is overwritten), or
/// a file.
fn check_out(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(InputError(format!(
            "--out {}: is a file; give a directory (new or empty) for the exported dataset",
            out.display()
        ))
        .into());
    }
    if out.exists() {
        let empty = out.is_dir()
            && std::fs::read_dir(out)
                .map(|mut d| d.next().is_none())
                .unwrap_or(false);
        if !empty {
            return Err(InputError(format!(
                "--out {}: exists and is not an empty directory (the export writes a new dataset; \
                 remove it or choose another)",
                out.display()
            ))
            .into());
        }
    }
    Ok(())
}

/// The data files of the dataset at `dir`, or an input error saying what is missing.
fn data_files(dir: &Path) -> Result<Vec<PathBuf>> {
    if !dir.is_dir() {
        return Err(InputError(format!(
            "dataset directory {} does not exist",
            dir.display()
        ))
        .into());
    }
    let files = if dir.join("data").is_dir() {
        parquet_files(&dir.join("data"))?
    } else {
        Vec::new()
    };
    if files.is_empty() {
        return Err(InputError(rh_grade::dataset_diagnosis::missing_parquet_message(dir)).into());
    }
    Ok(files)
}

/// Writes the export of `opts.dataset` into `opts.out`: `data/train-00000-of-00001.parquet`,
/// `README.md` (the dataset card) and `export.json` (what was exported, from which build).
/// Whole or not at all: everything goes into a temporary sibling directory renamed onto
/// `opts.out` at the end, so a failed export (a full disk) leaves no `out/` behind.
pub fn run(opts: &ExportOptions) -> Result<Summary> {
    check_out(&opts.out)?;
    let staged = ExportOptions {
        out: rh_contract::fsio::temp_sibling(&opts.out),
        ..opts.clone()
    };
    let result = write_export(&staged, &opts.out).and_then(|summary| {
        let cannot = |e| rh_contract::fsio::CannotWrite::new("the export", &opts.out, e);
        if opts.out.is_dir() {
            std::fs::remove_dir(&opts.out).map_err(cannot)?;
        }
        std::fs::rename(&staged.out, &opts.out).map_err(cannot)?;
        Ok(summary)
    });
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&staged.out);
    }
    result
}

/// An output failure of the export (a message naming the file) as a `CannotWrite` of `out`.
fn cannot_write(out: &Path, message: String) -> anyhow::Error {
    rh_contract::fsio::CannotWrite::new("the export", out, std::io::Error::other(message)).into()
}

/// The export written into `opts.out` (the staging directory), `out` being where it goes.
fn write_export(opts: &ExportOptions, out: &Path) -> Result<Summary> {
    let files = data_files(&opts.dataset)?;
    let eval = eval_scene_ids(&opts.dataset)?;
    if opts.split == Split::Eval && eval.is_none() {
        return Err(InputError(format!(
            "--split eval: {} has no eval/ subset (a shard, or an old build); use --split all",
            opts.dataset.display()
        ))
        .into());
    }
    let Some(first) = first_scene(&files, opts.split, eval.as_ref())? else {
        let why = if opts.split == Split::Train && eval.is_some() {
            " (every valid scene is in the eval subset; --split all takes them)"
        } else {
            ""
        };
        return Err(InputError(format!(
            "{}: no valid scenes in --split {}{why}",
            opts.dataset.display(),
            opts.split.name()
        ))
        .into());
    };
    let shape = Shape {
        preference: opts.format == Format::Preference,
        images: !opts.text_only && has_frames(opts, &first),
    };
    let mut sink = Sink::create(&opts.out.join(FILE), shape).map_err(|e| cannot_write(out, e))?;
    let aia = AiaMatcher::new(&opts.config.aia);
    let mut full_precision = 0;
    for data in &files {
        for batch in open_parquet(data, read_batch_rows(shape.images))? {
            let batch = batch.map_err(|e| InputError(format!("{}: {e}", data.display())))?;
            let examples = examples_of_batch(opts, &batch, data, eval.as_ref(), shape, &aia)?;
            full_precision += examples.iter().filter(|e| e.full_precision).count();
            if !examples.is_empty() {
                sink.write(&examples).map_err(|e| cannot_write(out, e))?;
            }
        }
    }
    let shape = sink.shape;
    let rows = sink.rows;
    sink.finish().map_err(|e| cannot_write(out, e))?;
    let summary = Summary {
        out: out.display().to_string(),
        file: FILE.into(),
        format: match opts.format {
            Format::Sft => "sft",
            Format::Preference => "preference",
        },
        split: opts.split.name(),
        rows,
        images: shape.images,
        full_precision_plans: full_precision,
        no_eval_subset: eval.is_none(),
    };
    card::write(opts, &summary).map_err(|e| cannot_write(out, e))?;
    Ok(summary)
}

/// The export's one data file (split `train`, the split TRL's trainers read by default).
pub const FILE: &str = "data/train-00000-of-00001.parquet";

/// The first scene the export takes (`None`: none).
fn first_scene(
    files: &[PathBuf],
    split: Split,
    eval: Option<&BTreeSet<String>>,
) -> Result<Option<String>> {
    for data in files {
        for batch in open_parquet(data, 1024)? {
            let batch = batch.map_err(|e| InputError(format!("{}: {e}", data.display())))?;
            let found = scenes_of_batch(&batch, data)?
                .into_iter()
                .find(|s| s.valid && selected(split, eval, &s.scene_id));
            if let Some(s) = found {
                return Ok(Some(s.scene_id));
            }
        }
    }
    Ok(None)
}

/// Whether the split takes a valid scene.
fn selected(split: Split, eval: Option<&BTreeSet<String>>, id: &str) -> bool {
    match (split, eval) {
        (Split::All, _) | (Split::Train, None) => true,
        (Split::Train, Some(e)) => !e.contains(id),
        (Split::Eval, Some(e)) => e.contains(id),
        (Split::Eval, None) => false,
    }
}

/// The examples of one batch of scene rows: its selected valid scenes, in row order.
fn examples_of_batch(
    opts: &ExportOptions,
    batch: &arrow::array::RecordBatch,
    file: &Path,
    eval: Option<&BTreeSet<String>>,
    shape: Shape,
    aia: &AiaMatcher,
) -> Result<Vec<Example>> {
    let inputs = scenes_of_batch(batch, file)?;
    let keep: Vec<u32> = (0..inputs.len() as u32)
        .filter(|&i| {
            let s = &inputs[i as usize];
            s.valid && selected(opts.split, eval, &s.scene_id)
        })
        .collect();
    if keep.is_empty() {
        return Ok(Vec::new());
    }
    let batch = rh_dataset::table::take_rows(batch, &keep);
    let names = object_names(&batch);
    let inputs: Vec<_> = keep.iter().map(|&i| inputs[i as usize].clone()).collect();
    let keys: FastMap<_, _> = replay_keys_of_batch(&batch, file)?.into_iter().collect();
    let ds = Dataset::from_scenes(opts.dataset.clone(), inputs);
    let hints = rh_grade::oracle::batch_hints(
        &opts.dataset,
        &batch,
        &keys,
        &ds.scenes,
        &opts.config,
        opts.dodge_check,
    )?;
    ds.scenes
        .par_iter()
        .map(|scene| {
            let fallback = scene.object_id.replace('_', " ");
            let info = SceneInfo {
                dir: &opts.dataset,
                scene,
                family: ds.family_name(scene),
                object_name: names
                    .get(&scene.scene_id)
                    .map(String::as_str)
                    .unwrap_or(&fallback),
                hints: hints.get(&scene.scene_id),
            };
            example::build(
                &info,
                &opts.prompt,
                &opts.config,
                aia,
                shape.images,
                shape.preference,
            )
            .map_err(|e| anyhow::anyhow!("{e}"))
        })
        .collect()
}

/// The `object_name` of each scene of the batch (none when the table lacks the column).
fn object_names(batch: &arrow::array::RecordBatch) -> FastMap<String, String> {
    let table = Path::new("scene table");
    let (Ok(ids), Some(_)) = (
        rh_dataset::read::required_strings(batch, table, "scene_id"),
        batch.column_by_name(rh_contract::columns::col::OBJECT_NAME),
    ) else {
        return FastMap::default();
    };
    let names = rh_dataset::read::strings(batch, table, "object_name").unwrap_or_default();
    ids.into_iter()
        .zip(names)
        .filter_map(|(id, n)| Some((id, n?)))
        .collect()
}

/// Whether the scene's first observation frame is on disk (a rendered build).
fn has_frames(opts: &ExportOptions, scene_id: &str) -> bool {
    let cam = opts.prompt.images.cameras.first();
    let t = opts.prompt.images.times.first();
    match (cam, t) {
        (Some(c), Some(&t)) => {
            rh_prompt::messages::frame_file(&opts.dataset, scene_id, c, t).is_ok()
        }
        _ => false,
    }
}
