//! `rh-pipeline build`: plans every scene group, runs the groups in parallel (rayon),
//! and writes specs and the Parquet table atomically.
//!
//! Determinism: a group's output depends only on (build seed, group index, config,
//! catalog); results are gathered and written in scene-index order, so `--jobs` and
//! sharding never change a byte.

use crate::config::Config;
use crate::dataset;
use crate::families;
use crate::plan::plan_group;
use crate::scene::{produce_group, SceneResult};
use rayon::prelude::*;
use rh_catalog::Catalog;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Debug, Clone)]
pub struct BuildOptions {
    pub n: u64,
    pub out: PathBuf,
    pub seed: u64,
    pub families: Vec<String>,
    pub jobs: usize,
    /// `(i, N)`: build only the groups `g` with `g mod N == i`.
    pub shard: (u64, u64),
    pub render: bool,
    pub progress: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// Bad arguments or unusable output directory (exit 2).
    #[error("{0}")]
    Input(String),
    /// A failure of this program (exit 1).
    #[error("internal error: {0}")]
    Internal(String),
}

#[derive(Debug, Clone, Serialize)]
pub struct BuildSummary {
    pub out: String,
    pub scenes: usize,
    pub valid: usize,
    pub invalid_scene_ids: Vec<String>,
    pub per_family: BTreeMap<String, usize>,
    pub per_action: BTreeMap<String, usize>,
    pub data_file: String,
}

/// Checks the options against the catalog and configuration before any work.
pub fn check_options(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
) -> Result<(), BuildError> {
    if opts.n == 0 {
        return Err(BuildError::Input("--n must be at least 1".into()));
    }
    if opts.jobs == 0 {
        return Err(BuildError::Input("--jobs must be at least 1".into()));
    }
    if opts.shard.1 == 0 || opts.shard.0 >= opts.shard.1 {
        return Err(BuildError::Input(format!(
            "--shard {}/{}: need 0 <= i < N",
            opts.shard.0, opts.shard.1
        )));
    }
    if opts.families.is_empty() {
        return Err(BuildError::Input(
            "--families must name at least one family".into(),
        ));
    }
    for f in &opts.families {
        if !rh_catalog::FAMILIES.contains(&f.as_str()) {
            return Err(BuildError::Input(format!(
                "unknown family '{f}' (known: {})",
                rh_catalog::FAMILIES.join(", ")
            )));
        }
        if families::get(f).is_none() {
            return Err(BuildError::Input(format!(
                "family '{f}' is not implemented in this build (implemented: {})",
                crate::randomize::implemented_families()
            )));
        }
        if config.speed_bands(f).is_none() {
            return Err(BuildError::Input(format!(
                "the configuration has no [speed_bands] entry for '{f}'"
            )));
        }
        if catalog.objects_for_family(f).next().is_none() {
            return Err(BuildError::Input(format!(
                "the catalog has no object for family '{f}'"
            )));
        }
    }
    Ok(())
}

fn prepare_out(out: &Path) -> Result<(), BuildError> {
    let fail = |e: std::io::Error| {
        BuildError::Input(format!("cannot write to --out {}: {e}", out.display()))
    };
    std::fs::create_dir_all(out.join("specs")).map_err(fail)?;
    std::fs::create_dir_all(out.join("data")).map_err(fail)?;
    let probe = out.join(".rh-write-probe");
    dataset::write_atomic(&probe, b"probe").map_err(fail)?;
    std::fs::remove_file(&probe).map_err(fail)
}

struct Progress {
    bar: Option<indicatif::ProgressBar>,
    done: AtomicU64,
    total: u64,
}

impl Progress {
    fn new(total: u64, enabled: bool) -> Progress {
        let bar = (enabled && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new(total);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} building [{bar:40}] {pos}/{len} scenes  {per_sec}  eta {eta}",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar
        });
        Progress {
            bar,
            done: AtomicU64::new(0),
            total,
        }
    }

    fn advance(&self, scenes: u64, enabled: bool) {
        let before = self.done.fetch_add(scenes, Ordering::Relaxed);
        let after = before + scenes;
        match &self.bar {
            Some(bar) => bar.inc(scenes),
            // Not a terminal (CI logs): a line at every tenth.
            None if enabled => {
                if (before * 10 / self.total.max(1)) != (after * 10 / self.total.max(1))
                    || after == self.total
                {
                    eprintln!("built {after}/{} scenes", self.total);
                }
            }
            None => {}
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Builds the dataset described by `opts`.
pub fn build(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
) -> Result<BuildSummary, BuildError> {
    check_options(opts, catalog, config)?;
    if opts.render && opts.progress {
        // The render stage is not part of this build yet: scenes get specs, labels and
        // Parquet rows, and their video columns stay null (as with --no-render).
        eprintln!(
            "note: this build has no render stage yet; building without videos (as --no-render)"
        );
    }
    prepare_out(&opts.out)?;

    let n_groups = opts.n.div_ceil(4);
    let groups: Vec<u64> = (0..n_groups)
        .filter(|g| g % opts.shard.1 == opts.shard.0)
        .collect();
    let scenes_here: u64 = groups.iter().map(|g| (opts.n - g * 4).min(4)).sum();
    let progress = Progress::new(scenes_here, opts.progress);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| BuildError::Internal(format!("thread pool: {e}")))?;

    let per_group: Result<Vec<Vec<SceneResult>>, BuildError> = pool.install(|| {
        groups
            .par_iter()
            .map(|&g| {
                let selection = plan_group(catalog, &opts.families, opts.seed, g)
                    .map_err(|e| BuildError::Input(e.to_string()))?;
                let count = (opts.n - g * 4).min(4);
                let results = produce_group(&selection, opts.seed, g * 4, count, catalog, config)
                    .map_err(|e| BuildError::Input(e.to_string()))?;
                for r in &results {
                    let path = opts.out.join(dataset::spec_path(&r.spec.scene_id));
                    dataset::write_atomic(&path, r.spec.to_json().as_bytes())
                        .map_err(|e| BuildError::Internal(format!("{}: {e}", path.display())))?;
                }
                progress.advance(count, opts.progress);
                Ok(results)
            })
            .collect()
    });
    progress.finish();
    let mut results: Vec<SceneResult> = per_group?.into_iter().flatten().collect();
    results.sort_by_key(|r| r.spec.scene_index);

    let data_file = dataset::data_file_name(opts.shard.0 as usize, opts.shard.1 as usize);
    let batch = dataset::record_batch(&results, catalog);
    let path = opts.out.join(&data_file);
    dataset::write_atomic(&path, &dataset::parquet_bytes(&batch))
        .map_err(|e| BuildError::Internal(format!("{}: {e}", path.display())))?;

    let mut summary = BuildSummary {
        out: opts.out.display().to_string(),
        scenes: results.len(),
        valid: 0,
        invalid_scene_ids: vec![],
        per_family: BTreeMap::new(),
        per_action: BTreeMap::new(),
        data_file,
    };
    for r in &results {
        if r.verdicts.all() {
            summary.valid += 1;
        } else {
            summary.invalid_scene_ids.push(r.spec.scene_id.clone());
        }
        *summary.per_family.entry(r.spec.family.clone()).or_default() += 1;
        *summary
            .per_action
            .entry(r.labels.gt_action.name().to_string())
            .or_default() += 1;
    }
    Ok(summary)
}
