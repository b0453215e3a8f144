//! `rh-score predict`: runs a model over a dataset through the OpenAI-compatible chat API
//! with the canonical prompt and writes `preds.jsonl` (SPEC §9).
//!
//! Entry point: [`run`] over [`PredictOptions`]. Pieces: [`config`] (prompt and runner
//! configuration), [`prompt`] (one scene's messages: frames → JPEG data URLs), [`output`]
//! (resume, torn-line repair, append), [`runner`] (the async loop: bounded in-flight
//! scenes, the shared [`rh_llm::Client`] with its cache, retries and adaptive limit, cost
//! budget, progress).

pub mod config;
pub mod output;
pub mod prompt;
pub mod runner;

use crate::dataset::Dataset;
use crate::types::InputError;
use anyhow::Result;
use arrow::array::{Array, StringArray};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

pub use runner::Summary;

/// Which scenes to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Subset {
    /// The balanced evaluation subset (the dataset's `eval` config).
    Eval,
    /// Every valid scene.
    All,
}

/// Everything `rh-score predict` was asked to do.
#[derive(Debug, Clone)]
pub struct PredictOptions {
    pub dataset: PathBuf,
    pub model: String,
    pub out: PathBuf,
    pub subset: Subset,
    pub limit: Option<usize>,
    /// Client settings, already merged from config, flags and environment.
    pub client: rh_llm::ClientConfig,
    pub generation: config::Generation,
    pub price: Option<config::Price>,
    pub max_cost: Option<f64>,
    pub retry_errors: bool,
    /// `None`: `--no-cache`.
    pub cache_dir: Option<PathBuf>,
    pub sample: u32,
    pub prompt: config::PromptConfig,
    pub progress: bool,
}

/// Scene ids of the dataset's `eval/*.parquet`, or `None` when it has no eval config.
fn eval_scene_ids(dir: &Path) -> Result<Option<BTreeSet<String>>> {
    let eval = dir.join("eval");
    if !eval.is_dir() {
        return Ok(None);
    }
    let files = crate::dataset::parquet_files(&eval)?;
    if files.is_empty() {
        return Ok(None);
    }
    let mut ids = BTreeSet::new();
    for f in files {
        let bad = |e: &dyn std::fmt::Display| InputError(format!("{}: {e}", f.display()));
        let reader = crate::dataset::open_parquet(&f, 1024)?;
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

/// The scene ids to run, in dataset order: valid scenes of the subset, first `limit`.
pub fn select_scenes(ds: &Dataset, subset: Subset, limit: Option<usize>) -> Result<Vec<String>> {
    let eval = match subset {
        Subset::All => None,
        Subset::Eval => Some(eval_scene_ids(&ds.dir)?.ok_or_else(|| {
            InputError(format!(
                "{} has no eval/ subset (a shard, or an old build); use --subset all",
                ds.dir.display()
            ))
        })?),
    };
    let ids: Vec<String> = ds
        .scenes
        .iter()
        .filter(|s| s.valid)
        .filter(|s| eval.as_ref().is_none_or(|e| e.contains(&s.scene_id)))
        .map(|s| s.scene_id.clone())
        .take(limit.unwrap_or(usize::MAX))
        .collect();
    if ids.is_empty() {
        return Err(InputError(format!(
            "{}: no valid scenes to run in the selected subset",
            ds.dir.display()
        ))
        .into());
    }
    Ok(ids)
}

/// The request for one scene, as `--dry-run` prints it (images elided, no key).
pub fn dry_run(opts: &PredictOptions, scene_id: &str) -> Result<serde_json::Value> {
    let built = prompt::build(&opts.prompt, &opts.dataset, scene_id).map_err(|e| InputError(e))?;
    let req = runner::request(opts, built.messages);
    Ok(serde_json::json!({
        "url": format!("{}/chat/completions", opts.client.base_url.trim_end_matches('/')),
        "scene_id": scene_id,
        "prompt_version": opts.prompt.version,
        "prompt_hash": req.prompt_hash(),
        "body": prompt::elide_images(&req.body()),
    }))
}

/// Runs the model over the selected scenes of the dataset into `opts.out`.
pub fn run(opts: &PredictOptions, scenes: &[String]) -> Result<Summary> {
    runner::run(opts, scenes)
}
