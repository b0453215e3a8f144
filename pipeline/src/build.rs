//! `rh-pipeline build`: plans every scene group, runs the groups in parallel (rayon),
//! and writes specs and the Parquet table atomically.
//!
//! Determinism: a group's output depends only on (build seed, group index, config,
//! catalog); results are gathered and written in scene-index order, so `--jobs` and
//! sharding never change a byte.
//!
//! Crash safety and resume (SPEC §13). The output directory holds, in this order:
//! 1. `build.json` (the manifest: what is being built), written before anything else;
//! 2. per finished group, its specs and then its rows as a small Parquet record
//!    `.rh-build/groups/<g>.parquet`;
//! 3. when every group is done: `data/…parquet`, `eval/…parquet` (whole builds) and
//!    `README.md`, built from the records alone; then `.rh-build/` is removed.
//!
//! Every file is written to a temporary name and renamed, so a reader never sees half a
//! file. A build killed at any moment and started again with the same arguments finds
//! the same manifest, loads the finished groups' records instead of simulating them, and
//! writes the same bytes: finished and fresh groups reach the final table by the same
//! path (their records). The directory is locked (`flock`) while a build runs in it.

use crate::card;
use crate::config::Config;
use crate::dataset;
use crate::families;
use crate::integrity::{self, FileSums};
use crate::manifest::{Manifest, MANIFEST_FILE};
use crate::plan::plan_group;
use crate::render::{with_thread_renderer, RenderOptions, Renderer};
use crate::scene::{produce_group, SceneMedia, SceneResult};
use crate::simulate::{simulate, SimOptions};
use arrow::array::RecordBatch;
use rayon::prelude::*;
use rh_catalog::Catalog;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Work-in-progress folder of an unfinished build (removed when the build completes).
pub const WORK_DIR: &str = ".rh-build";

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
    /// Groups whose finished records a previous, interrupted run left (not recomputed).
    pub resumed_groups: usize,
    /// Groups simulated by this run.
    pub computed_groups: usize,
    /// Scenes in the `eval` config (whole builds only).
    pub eval_scenes: Option<usize>,
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
                "{}: [speed_bands] has no entry for family '{f}' (add `{f} = [slow, normal, fast, very_fast]`)",
                config.source
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

fn internal(path: &Path, e: impl std::fmt::Display) -> BuildError {
    BuildError::Internal(format!("{}: {e}", path.display()))
}

/// Path of group `g`'s record.
pub fn record_path(out: &Path, g: u64) -> PathBuf {
    out.join(WORK_DIR)
        .join("groups")
        .join(format!("{g:08}.parquet"))
}

/// Holds an exclusive `flock` on a directory while alive (released by the kernel when
/// the process dies, even by SIGKILL).
pub struct DirLock(#[allow(dead_code)] std::fs::File);

/// Locks `dir` against a second `rh-pipeline` writing into it at the same time.
pub fn lock_dir(dir: &Path) -> Result<DirLock, BuildError> {
    let file = std::fs::File::open(dir)
        .map_err(|e| BuildError::Input(format!("cannot open {}: {e}", dir.display())))?;
    match file.try_lock() {
        Ok(()) => Ok(DirLock(file)),
        Err(std::fs::TryLockError::WouldBlock) => Err(BuildError::Input(format!(
            "{} is being written by another rh-pipeline process",
            dir.display()
        ))),
        // A file system without locks: go on unlocked.
        Err(std::fs::TryLockError::Error(_)) => Ok(DirLock(file)),
    }
}

/// Removes temporary files (`.NAME.PID.tmp`) a killed writer left in the dataset's
/// folders, and retired work folders (`.rh-build.done.PID`) a killed build did not finish
/// deleting.
fn remove_stale_temporaries(out: &Path) {
    if let Ok(entries) = std::fs::read_dir(out) {
        for e in entries.flatten() {
            if e.file_name()
                .to_string_lossy()
                .starts_with(&format!("{WORK_DIR}.done."))
            {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
    }
    // Folders that hold files written atomically (videos and frames one level down).
    let mut dirs: Vec<PathBuf> = ["", "data", "eval", "specs", ".rh-build/groups"]
        .iter()
        .map(|sub| out.join(sub))
        .collect();
    for media in ["videos", "frames"] {
        if let Ok(entries) = std::fs::read_dir(out.join(media)) {
            dirs.extend(entries.flatten().map(|e| e.path()).filter(|p| p.is_dir()));
        }
    }
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name();
            let name = name.to_string_lossy();
            // `write_atomic`'s `.<name>.<pid>.tmp`, the encoder's `.<name>.<pid>.<n>.tmp.mp4`.
            if name.starts_with('.') && (name.ends_with(".tmp") || name.ends_with(".tmp.mp4")) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Checks that `out` is new, empty, or holds this very build, and records the manifest.
/// Returns whether the directory already holds the finished build.
pub fn claim_out_dir(out: &Path, manifest: &Manifest) -> Result<bool, BuildError> {
    let fail = |e: std::io::Error| {
        BuildError::Input(format!("cannot write to --out {}: {e}", out.display()))
    };
    std::fs::create_dir_all(out).map_err(fail)?;
    match Manifest::read(out).map_err(BuildError::Input)? {
        Some(existing) => {
            let diff = existing.differences(manifest);
            if !diff.is_empty() {
                return Err(BuildError::Input(format!(
                    "{} holds a different build ({}); use a new --out or delete it",
                    out.display(),
                    diff.join("; ")
                )));
            }
        }
        None => {
            // A build owns its directory: anything already there (a dataset of another
            // version, or unrelated files) is refused rather than mixed with the dataset.
            let mut present: Vec<String> = std::fs::read_dir(out)
                .map_err(fail)?
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect();
            present.sort();
            if !present.is_empty() {
                let shown: Vec<&str> = present.iter().take(5).map(|s| s.as_str()).collect();
                return Err(BuildError::Input(format!(
                    "--out {} is not empty and holds no {MANIFEST_FILE} ({} entr{}: {}{}); a build writes into a new or empty directory, or resumes its own — use a new --out",
                    out.display(),
                    present.len(),
                    if present.len() == 1 { "y" } else { "ies" },
                    shown.join(", "),
                    if present.len() > 5 { ", …" } else { "" }
                )));
            }
            dataset::write_atomic(&out.join(MANIFEST_FILE), manifest.to_json().as_bytes())
                .map_err(fail)?;
        }
    }
    let data = out.join(dataset::data_file_name(
        manifest.shard[0] as usize,
        manifest.shard[1] as usize,
    ));
    Ok(!out.join(WORK_DIR).exists() && data.exists() && out.join("README.md").exists())
}

/// Renders a valid scene's videos and frames into `out` (stage 4). Invalid scenes are
/// not rendered: their video columns stay null. The simulation is run again from the
/// spec (milliseconds, and identical by construction) rather than kept per group.
fn render_scene(
    r: &SceneResult,
    catalog: &Catalog,
    opts: &RenderOptions,
    out: &Path,
) -> Result<Option<SceneMedia>, BuildError> {
    if !r.verdicts.all() || r.spec.cameras.is_empty() {
        return Ok(None);
    }
    let sim = simulate(&r.spec, SimOptions::default());
    let rendered = with_thread_renderer(opts, |renderer| {
        renderer.render_scene(&r.spec, &sim, catalog, out)
    })
    .and_then(|x| x)
    .map_err(|e| BuildError::Internal(format!("render {}: {e}", r.spec.scene_id)))?;
    Ok(Some(SceneMedia {
        videos: rendered.videos,
        full_event: rendered.full_event,
    }))
}

/// Reads group `g`'s record if it is there and whole (right rows, every file it names
/// present: specs, videos, frames).
fn load_record(out: &Path, manifest: &Manifest, g: u64) -> Option<RecordBatch> {
    let path = record_path(out, g);
    if !path.exists() {
        return None;
    }
    let batch = dataset::read_batch(&path).ok()?;
    let indices = dataset::u64_column(&batch, "scene_index");
    let expected: Vec<u64> = (g * 4..g * 4 + manifest.group_size(g)).collect();
    if indices != expected {
        return None;
    }
    // Every file the rows name, with the checksum recorded when the group finished.
    let sums = integrity::read_group_sums(&path)?;
    let named: Vec<String> = dataset::referenced_files(&batch);
    if named.len() != sums.len() || !named.iter().all(|f| sums.contains_key(f)) {
        return None;
    }
    let problems = integrity::check(out, &sums);
    if !problems.is_empty() {
        eprintln!(
            "group {g}: {}; computing it again",
            integrity::describe(&problems, 3)
        );
        return None;
    }
    Some(batch)
}

/// A finished build whose files are not all what its manifest records: turns it back
/// into an unfinished one, keeping (as records) the groups whose files are intact, so
/// the run recomputes only the damaged groups. Returns the problems found (empty: the
/// build is intact and nothing was changed).
fn reopen_if_damaged(out: &Path, manifest: &Manifest) -> Result<Vec<integrity::FileProblem>, BuildError> {
    let Some(sums) = &manifest.files else {
        // A finished build of a version that recorded no checksums: nothing to compare.
        return Ok(vec![]);
    };
    let problems = integrity::check(out, sums);
    if problems.is_empty() {
        return Ok(problems);
    }
    let groups_dir = out.join(WORK_DIR).join("groups");
    std::fs::create_dir_all(&groups_dir).map_err(|e| internal(&groups_dir, e))?;
    let data_file = dataset::data_file_name(manifest.shard[0] as usize, manifest.shard[1] as usize);
    let data_ok = !problems.iter().any(|p| p.file == data_file);
    let rows = if data_ok {
        dataset::read_batch(&out.join(&data_file)).ok()
    } else {
        None
    };
    if let Some(rows) = rows {
        let bad: std::collections::BTreeSet<&str> = problems.iter().map(|p| p.file.as_str()).collect();
        let index = dataset::u64_column(&rows, "scene_index");
        for g in manifest.groups() {
            let picks: Vec<u32> = (0..rows.num_rows() as u32)
                .filter(|&i| index[i as usize] / 4 == g)
                .collect();
            let batch = dataset::take_rows(&rows, &picks);
            let files = dataset::referenced_files(&batch);
            if picks.is_empty() || files.iter().any(|f| bad.contains(f.as_str()) || !sums.contains_key(f)) {
                continue;
            }
            let group_sums: FileSums = files.iter().map(|f| (f.clone(), sums[f].clone())).collect();
            let record = record_path(out, g);
            integrity::write_group_sums(&record, &group_sums).map_err(|e| internal(&record, e))?;
            dataset::write_atomic(&record, &dataset::parquet_bytes(&batch)).map_err(|e| internal(&record, e))?;
        }
    }
    Ok(problems)
}

/// Builds the dataset described by `opts`.
pub fn build(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
) -> Result<BuildSummary, BuildError> {
    check_options(opts, catalog, config)?;
    let render_opts = RenderOptions::from_config(&config.render);
    if opts.render {
        // Fail before any work when there is nothing to render with.
        let renderer = Renderer::new(render_opts.clone()).map_err(|e| {
            BuildError::Input(format!("render stage: {e} (or build with --no-render)"))
        })?;
        if opts.progress {
            eprintln!(
                "rendering on {} ({} MSAA samples)",
                renderer.adapter_name(),
                renderer.samples()
            );
        }
    }
    let manifest = Manifest::new(
        opts.seed,
        opts.n,
        &opts.families,
        opts.shard,
        opts.render,
        catalog,
        config,
    );
    let out = &opts.out;
    std::fs::create_dir_all(out)
        .map_err(|e| BuildError::Input(format!("cannot write to --out {}: {e}", out.display())))?;
    let _lock = lock_dir(out)?;
    let complete = claim_out_dir(out, &manifest)?;
    remove_stale_temporaries(out);
    interrupt::say_resume_on_interrupt(out);
    let data_file = dataset::data_file_name(opts.shard.0 as usize, opts.shard.1 as usize);
    let groups = manifest.groups();

    let complete = complete && {
        let on_disk = Manifest::read(out).map_err(BuildError::Input)?.unwrap_or_else(|| manifest.clone());
        let problems = reopen_if_damaged(out, &on_disk)?;
        if !problems.is_empty() {
            eprintln!(
                "{} holds this build, but {} file(s) are not what its {MANIFEST_FILE} records ({}); rebuilding the groups they belong to",
                out.display(),
                problems.len(),
                integrity::describe(&problems, 5)
            );
        }
        problems.is_empty()
    };
    if complete {
        if opts.progress {
            eprintln!(
                "{} already holds this build, complete; nothing to do",
                out.display()
            );
        }
        let rows = dataset::read_batch(&out.join(&data_file)).map_err(BuildError::Internal)?;
        let eval = out
            .join(card::EVAL_FILE)
            .exists()
            .then(|| card::eval_selection(&rows).0.len());
        return Ok(summarize(out, &rows, data_file, groups.len(), 0, eval));
    }

    for sub in ["specs", "data", ".rh-build/groups"] {
        std::fs::create_dir_all(out.join(sub)).map_err(|e| internal(&out.join(sub), e))?;
    }
    let (done, todo): (Vec<u64>, Vec<u64>) = groups
        .iter()
        .copied()
        .partition(|&g| load_record(out, &manifest, g).is_some());
    if !done.is_empty() && opts.progress {
        eprintln!(
            "resumed {} groups from {} (finished before the last run stopped)",
            done.len(),
            out.join(WORK_DIR).display()
        );
    }

    let scenes_todo: u64 = todo.iter().map(|&g| manifest.group_size(g)).sum();
    let progress = Progress::new(scenes_todo, opts.progress);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| BuildError::Internal(format!("thread pool: {e}")))?;
    pool.install(|| {
        todo.par_iter()
            .try_for_each(|&g| -> Result<(), BuildError> {
                let selection = plan_group(catalog, &opts.families, opts.seed, g)
                    .map_err(|e| BuildError::Input(e.to_string()))?;
                let count = manifest.group_size(g);
                let mut results =
                    produce_group(&selection, opts.seed, g * 4, count, catalog, config)
                        .map_err(|e| BuildError::Input(e.to_string()))?;
                if opts.render {
                    for r in results.iter_mut() {
                        r.media = render_scene(r, catalog, &render_opts, out)?;
                    }
                }
                for r in &results {
                    let path = out.join(dataset::spec_path(&r.spec.scene_id));
                    dataset::write_atomic(&path, r.spec.to_json().as_bytes())
                        .map_err(|e| internal(&path, e))?;
                }
                // Then the checksums of every file the rows name, and the record last: its
                // presence says the group (specs, media, sums) is done.
                let path = record_path(out, g);
                let batch = dataset::record_batch(&results, catalog);
                let sums = integrity::group_sums(out, &batch).map_err(|e| internal(out, e))?;
                integrity::write_group_sums(&path, &sums).map_err(|e| internal(&path, e))?;
                let bytes = dataset::parquet_bytes(&batch);
                dataset::write_atomic(&path, &bytes).map_err(|e| internal(&path, e))?;
                progress.advance(count, opts.progress);
                Ok(())
            })
    })?;
    progress.finish();

    // Every group's rows, from the records, in scene-index order.
    let batches: Vec<RecordBatch> = groups
        .iter()
        .map(|&g| {
            let path = record_path(out, g);
            dataset::read_batch(&path).map_err(BuildError::Internal)
        })
        .collect::<Result<_, _>>()?;
    let rows = dataset::concat(&batches).map_err(BuildError::Internal)?;
    let mut sums = FileSums::new();
    for &g in &groups {
        let path = record_path(out, g);
        let group = integrity::read_group_sums(&path).ok_or_else(|| {
            BuildError::Internal(format!("{}: checksums missing", integrity::group_sums_path(&path).display()))
        })?;
        sums.extend(group);
    }
    let eval = finalize(out, &manifest, &rows, sums)?;
    // Retire the records in one atomic step (a rename), then delete them: a crash in
    // between leaves a finished build whose next run only removes the leftover.
    let work = out.join(WORK_DIR);
    let retired = out.join(format!("{WORK_DIR}.done.{}", std::process::id()));
    std::fs::rename(&work, &retired).map_err(|e| internal(&work, e))?;
    std::fs::remove_dir_all(&retired).map_err(|e| internal(&retired, e))?;
    Ok(summarize(
        out,
        &rows,
        data_file,
        done.len(),
        todo.len(),
        eval,
    ))
}

/// Writes the dataset's final files from its rows (in scene-index order): the data
/// Parquet, the eval subset (whole builds), and the card; then `build.json` again, now
/// with the SHA-256 of every file (`sums`: the groups' specs and media, plus the files
/// written here). Returns the eval subset's size.
pub fn finalize(
    out: &Path,
    manifest: &Manifest,
    rows: &RecordBatch,
    mut sums: FileSums,
) -> Result<Option<usize>, BuildError> {
    let data_file = dataset::data_file_name(manifest.shard[0] as usize, manifest.shard[1] as usize);
    let path = out.join(&data_file);
    let bytes = dataset::parquet_bytes(rows);
    dataset::write_atomic(&path, &bytes).map_err(|e| internal(&path, e))?;
    sums.insert(data_file.clone(), integrity::sha256_bytes(&bytes));
    let eval = if manifest.is_whole() {
        let (indices, counts) = card::eval_selection(rows);
        let subset = dataset::take_rows(rows, &indices);
        let path = out.join(card::EVAL_FILE);
        let bytes = dataset::parquet_bytes(&subset);
        dataset::write_atomic(&path, &bytes).map_err(|e| internal(&path, e))?;
        sums.insert(card::EVAL_FILE.to_string(), integrity::sha256_bytes(&bytes));
        Some(counts)
    } else {
        None
    };
    let readme = card::render(&card::CardInput {
        manifest,
        rows,
        data_files: std::slice::from_ref(&data_file),
        eval: eval.as_ref(),
    });
    let path = out.join("README.md");
    dataset::write_atomic(&path, readme.as_bytes()).map_err(|e| internal(&path, e))?;
    sums.insert("README.md".to_string(), integrity::sha256_bytes(readme.as_bytes()));
    let finished = Manifest {
        files: Some(sums),
        ..manifest.clone()
    };
    let path = out.join(MANIFEST_FILE);
    dataset::write_atomic(&path, finished.to_json().as_bytes()).map_err(|e| internal(&path, e))?;
    Ok(eval.map(|c| c.values().sum()))
}

fn summarize(
    out: &Path,
    rows: &RecordBatch,
    data_file: String,
    resumed_groups: usize,
    computed_groups: usize,
    eval_scenes: Option<usize>,
) -> BuildSummary {
    let ids = dataset::string_column(rows, "scene_id");
    let valid = dataset::bool_column(rows, "valid");
    let family = dataset::string_column(rows, "family");
    let action = dataset::string_column(rows, "gt_action");
    let mut summary = BuildSummary {
        out: out.display().to_string(),
        scenes: rows.num_rows(),
        valid: 0,
        invalid_scene_ids: vec![],
        per_family: BTreeMap::new(),
        per_action: BTreeMap::new(),
        data_file,
        resumed_groups,
        computed_groups,
        eval_scenes,
    };
    for i in 0..rows.num_rows() {
        if valid[i] {
            summary.valid += 1;
        } else {
            summary.invalid_scene_ids.push(ids[i].clone());
        }
        *summary.per_family.entry(family[i].clone()).or_default() += 1;
        *summary.per_action.entry(action[i].clone()).or_default() += 1;
    }
    summary
}

/// Ctrl-C (SIGINT) or SIGTERM during a build: say that the finished groups are kept and
/// that running the same command again resumes, then exit 130. The message is prepared
/// before the handler is installed; the handler only writes it (async-signal-safe).
mod interrupt {
    use std::path::Path;
    use std::sync::OnceLock;

    static MESSAGE: OnceLock<Vec<u8>> = OnceLock::new();

    extern "C" fn on_signal(_: libc::c_int) {
        if let Some(m) = MESSAGE.get() {
            // SAFETY: write(2) and _exit(2) are async-signal-safe; the buffer is immutable.
            unsafe {
                libc::write(2, m.as_ptr().cast(), m.len());
            }
        }
        unsafe { libc::_exit(130) }
    }

    pub fn say_resume_on_interrupt(out: &Path) {
        let text = format!(
            "\nrh-pipeline: interrupted. Finished scene groups are kept in {}; run the same command again to resume (they are not recomputed, and the result is byte-identical to an uninterrupted build).\n",
            out.display()
        );
        if MESSAGE.set(text.into_bytes()).is_ok() {
            // SAFETY: installs a handler that only calls async-signal-safe functions.
            unsafe {
                libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
                libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
            }
        }
    }
}
