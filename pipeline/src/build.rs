//! `rh-pipeline build`: plans every scene group, runs the groups in parallel (rayon),
//! and writes specs and the Parquet table atomically.
//!
//! Determinism: a group's output depends only on (build seed, group index, config,
//! catalog); results are gathered and written in scene-index order, so `--jobs` and
//! sharding never change a byte.
//!
//! Crash safety and resume (specification §13). The output directory holds, in this order:
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

use arrow::array::RecordBatch;
use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_dataset::card;
pub use rh_dataset::finalize::BuildError;
use rh_dataset::finalize::{finalize, RowSink};
use rh_dataset::integrity;
use rh_dataset::manifest::{Manifest, MANIFEST_FILE};
pub use rh_dataset::records::FamilyRejections;
use rh_dataset::records::{gather_rejections, group_files, load_record, reopen_if_damaged};
pub use rh_dataset::records::{record_path, WORK_DIR};
use rh_dataset::{stream, table};
use rh_scenes::config::Config;
use rh_scenes::driver::{run_group, GroupError, RenderStage};
use rh_scenes::families;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone)]
pub struct BuildOptions {
    pub n: u64,
    pub out: PathBuf,
    pub seed: u64,
    pub families: Vec<String>,
    /// Planned selections (from descriptions): group `g` takes `selections[g mod len]`
    /// instead of the embedded round-robin planner.
    pub selections: Option<Vec<rh_physics::spec::Selection>>,
    pub jobs: usize,
    /// `(i, N)`: build only the groups `g` with `g mod N == i`.
    pub shard: (u64, u64),
    pub render: bool,
    /// Also write the observation frames' instance-id and depth PNGs (needs `render`).
    pub masks: bool,
    pub progress: bool,
    /// Seconds between progress lines when stderr is not a terminal.
    pub progress_every_s: f64,
    /// The release this build is (`build --release`), recorded in `build.json`.
    pub release: Option<String>,
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
    /// Per family: scene-group attempts made and, per validator column, how many of them
    /// it rejected (`valid_visible`: the visibility rule). `None` when some group's counts
    /// are not known: the build was already complete (the per-group records holding the
    /// counts are gone by then), or a damaged finished build was repaired.
    pub rejections: Option<BTreeMap<String, FamilyRejections>>,
}

/// The most scenes one build makes (`--n`; docs/reliability.md, "Bounds").
pub const MAX_SCENES: u64 = 1_000_000;
/// The most worker threads (`--jobs`) and shards (`--shard i/N`).
pub const MAX_JOBS: usize = 1024;
pub const MAX_SHARDS: u64 = 10_000;

/// Checks the options against the catalog and configuration before any work.
pub fn check_options(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
) -> Result<(), BuildError> {
    if opts.n == 0 {
        return Err(BuildError::Input("--n must be at least 1".into()));
    }
    if opts.n > MAX_SCENES {
        return Err(BuildError::Input(format!(
            "--n {}: at most {MAX_SCENES} scenes in one build (shard a larger one with --shard i/N, then merge)",
            opts.n
        )));
    }
    if opts.jobs == 0 {
        return Err(BuildError::Input("--jobs must be at least 1".into()));
    }
    if opts.jobs > MAX_JOBS {
        return Err(BuildError::Input(format!(
            "--jobs {}: at most {MAX_JOBS}",
            opts.jobs
        )));
    }
    if opts.shard.1 > MAX_SHARDS {
        return Err(BuildError::Input(format!(
            "--shard {}/{}: at most {MAX_SHARDS} shards",
            opts.shard.0, opts.shard.1
        )));
    }
    if opts.shard.1 == 0 || opts.shard.0 >= opts.shard.1 {
        return Err(BuildError::Input(format!(
            "--shard {}/{}: need 0 <= i < N",
            opts.shard.0, opts.shard.1
        )));
    }
    if opts.masks && !opts.render {
        return Err(BuildError::Input(
            "--masks writes the rendered frames' segmentation and depth; it cannot be combined with --no-render".into(),
        ));
    }
    if opts.families.is_empty() {
        return Err(BuildError::Input(
            "--families must name at least one family".into(),
        ));
    }
    for f in &opts.families {
        if !rh_contract::FAMILIES.contains(&f.as_str()) {
            return Err(BuildError::Input(format!(
                "unknown family '{f}' (known: {})",
                rh_contract::FAMILIES.join(", ")
            )));
        }
        if families::get(f).is_none() {
            return Err(BuildError::Input(format!(
                "family '{f}' is not implemented in this build (implemented: {})",
                rh_scenes::randomize::implemented_families()
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

/// Build progress: a bar on a terminal; in a log (CI, a file) a line every
/// `progress_every_s` — scenes done of total, rate, ETA (`rh_contract::progress`).
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    log: rh_contract::progress::ProgressLog,
}

impl Progress {
    fn new(total: u64, enabled: bool, every_s: f64) -> Progress {
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
        let log = rh_contract::progress::ProgressLog::start(
            enabled,
            "building",
            "scenes",
            total,
            std::time::Duration::from_secs_f64(every_s),
        );
        Progress { bar, log }
    }

    fn advance(&self, scenes: u64) {
        if let Some(bar) = &self.bar {
            bar.inc(scenes);
        }
        self.log.add(scenes);
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

/// Makes finished groups durable off the workers' path: fsyncs each file of a group and
/// renames it into place, in the order given (specs, then the record last, so a record
/// never names a spec that is not there). Workers hand over a group and go on simulating
/// while a few threads wait on the disk (fsync is I/O wait, not CPU: done inline it took
/// 10-30% of a label-only build on a busy disk). At most `SYNC_BACKLOG` groups wait.
struct Syncer {
    tx: Option<std::sync::mpsc::SyncSender<Vec<rh_contract::fsio::Unsynced>>>,
    threads: Vec<std::thread::JoinHandle<Result<(), BuildError>>>,
}

const SYNC_THREADS: usize = 4;
const SYNC_BACKLOG: usize = 32;

impl Syncer {
    fn start() -> Syncer {
        let (tx, rx) =
            std::sync::mpsc::sync_channel::<Vec<rh_contract::fsio::Unsynced>>(SYNC_BACKLOG);
        let rx = std::sync::Arc::new(std::sync::Mutex::new(rx));
        let threads = (0..SYNC_THREADS)
            .map(|_| {
                let rx = rx.clone();
                std::thread::spawn(move || loop {
                    let next = rx.lock().expect("syncer queue").recv();
                    let Ok(files) = next else { return Ok(()) };
                    for f in files {
                        let path = f.path().to_path_buf();
                        f.commit().map_err(|e| internal(&path, e))?;
                    }
                })
            })
            .collect();
        Syncer {
            tx: Some(tx),
            threads,
        }
    }

    fn submit(&self, files: Vec<rh_contract::fsio::Unsynced>) -> Result<(), BuildError> {
        let tx = self.tx.as_ref().expect("open until finish");
        tx.send(files)
            .map_err(|_| BuildError::Internal("the file syncer stopped".into()))
    }

    /// Waits until every submitted file is in place; the first error, if any.
    fn finish(mut self) -> Result<(), BuildError> {
        drop(self.tx.take());
        let mut result = Ok(());
        for t in self.threads.drain(..) {
            let r = t
                .join()
                .unwrap_or_else(|_| Err(BuildError::Internal("file syncer panicked".into())));
            if result.is_ok() {
                result = r;
            }
        }
        result
    }
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
    for media in ["videos", "frames", "masks", "depth"] {
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
    // A build.json without file checksums is a build that stopped before it finished.
    let mut sums_recorded = false;
    match Manifest::read(out).map_err(|e| BuildError::Input(e.into()))? {
        Some(existing) => {
            sums_recorded = existing.files.is_some();
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
            table::write_atomic(&out.join(MANIFEST_FILE), manifest.to_json().as_bytes())
                .map_err(fail)?;
        }
    }
    let data = out.join(table::data_file_name(
        manifest.shard[0] as usize,
        manifest.shard[1] as usize,
    ));
    Ok(sums_recorded
        && !out.join(WORK_DIR).exists()
        && data.exists()
        && out.join("README.md").exists())
}

/// Fails before any work when rendering is requested but impossible: no GPU, no
/// encoder, or a program built without the `render` feature.
/// Returns the banner to print and the adapter's record for `build.json`.
type RenderCheck = Option<(String, rh_contract::adapter::RenderAdapter)>;

fn check_render_stage(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
) -> Result<RenderCheck, BuildError> {
    if !opts.render {
        return Ok(None);
    }
    #[cfg(not(feature = "render"))]
    {
        let _ = (config, catalog);
        Err(BuildError::Input(
            "rendering was requested, but this rh-pipeline was built without the `render` \
             feature (cargo build --no-default-features): build with --no-render, or use a \
             build with default features"
                .into(),
        ))
    }
    #[cfg(feature = "render")]
    {
        rh_render::memory::set_render_policy();
        // Every model the catalog names: package installed, bytes as hashed, fits its parts.
        rh_render::models::check_catalog(catalog, &config.render.models, |o| {
            rh_scenes::families::object_parts(o)
        })
        .map_err(|e| BuildError::Input(format!("render stage: {e}")))?;
        let renderer =
            rh_render::Renderer::new(rh_render::RenderOptions::from_config(&config.render))
                .map_err(|e| {
                    BuildError::Input(format!("render stage: {e} (or build with --no-render)"))
                })?;
        Ok(Some((
            format!(
                "rendering on {} ({} MSAA samples)",
                renderer.adapter().describe(),
                renderer.samples()
            ),
            renderer.adapter().clone(),
        )))
    }
}

/// A build that `claim_out_dir` found complete (`complete`): its summary when every file
/// is what its manifest records, else None after reopening it (the damaged groups'
/// records removed, the intact ones kept) so that the build goes on and repairs it.
fn finished_build(
    out: &Path,
    manifest: &Manifest,
    complete: bool,
    progress: bool,
) -> Result<Option<BuildSummary>, BuildError> {
    if !complete {
        return Ok(None);
    }
    let on_disk = Manifest::read(out)
        .map_err(|e| BuildError::Input(e.into()))?
        .unwrap_or_else(|| manifest.clone());
    let problems = reopen_if_damaged(out, &on_disk).map_err(|e| BuildError::Internal(e.into()))?;
    if !problems.is_empty() {
        rh_contract::note!(
            "{} holds this build, but {} file(s) are not what its {MANIFEST_FILE} records ({}); rebuilding the groups they belong to",
            out.display(),
            problems.len(),
            integrity::describe(&problems, 5)
        );
        return Ok(None);
    }
    if progress {
        rh_contract::note!(
            "{} already holds this build, complete; nothing to do",
            out.display()
        );
    }
    let data_file = table::data_file_name(manifest.shard[0] as usize, manifest.shard[1] as usize);
    let rows = stream::read_columns(&out.join(&data_file), &stream::SUMMARY_COLUMNS)
        .map_err(|e| BuildError::Internal(e.into()))?;
    let eval = out
        .join(card::EVAL_FILE)
        .exists()
        .then(|| card::manifest_eval_selection(&rows, &on_disk).0.len());
    // Nothing was resumed: the build was already complete ("nothing to do").
    Ok(Some(summarize(out, &rows, data_file, 0, 0, eval)))
}

/// Builds the dataset described by `opts`.
pub fn build(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
) -> Result<BuildSummary, BuildError> {
    check_options(opts, catalog, config)?;
    // Fail before any work when there is nothing to render with; say what renders only
    // once there is something to render (not before "nothing to do").
    let (render_banner, render_adapter) = check_render_stage(opts, catalog, config)?.unzip();
    let mut manifest = Manifest::new(
        opts.seed,
        opts.n,
        &opts.families,
        opts.shard,
        opts.render,
        catalog,
        config,
    );
    manifest.selections = opts.selections.clone();
    manifest.masks = opts.masks;
    manifest.render_adapter = render_adapter;
    manifest.release = opts.release.clone();
    let out = &opts.out;
    std::fs::create_dir_all(out)
        .map_err(|e| BuildError::Input(format!("cannot write to --out {}: {e}", out.display())))?;
    let _lock = lock_dir(out)?;
    let complete = claim_out_dir(out, &manifest)?;
    remove_stale_temporaries(out);
    interrupt::say_resume_on_interrupt(out);
    let data_file = table::data_file_name(opts.shard.0 as usize, opts.shard.1 as usize);
    let groups = manifest.groups();

    if let Some(summary) = finished_build(out, &manifest, complete, opts.progress)? {
        return Ok(summary);
    }
    for sub in ["specs", "data", ".rh-build/groups"] {
        std::fs::create_dir_all(out.join(sub)).map_err(|e| internal(&out.join(sub), e))?;
    }
    let (done, todo): (Vec<u64>, Vec<u64>) = groups
        .iter()
        .copied()
        .partition(|&g| load_record(out, &manifest, g).is_some());
    if !done.is_empty() && opts.progress {
        rh_contract::note!(
            "resumed {} groups from {} (finished before the last run stopped)",
            done.len(),
            out.join(WORK_DIR).display()
        );
    }

    // Stage 4 for the DAG driver (`scene::run_group`): a valid scene's videos and frames.
    #[cfg(feature = "render")]
    let render_opts = rh_render::RenderOptions {
        masks: opts.masks,
        ..rh_render::RenderOptions::from_config(&config.render)
    };
    #[cfg(feature = "render")]
    let render_stage = |r: &rh_scenes::driver::SceneResult| {
        let media = rh_render::render_stage(r, catalog, &render_opts, out)
            .map_err(|e| format!("render {}: {e}", r.spec.scene_id));
        rh_render::memory::release_free_pages();
        media
    };
    #[cfg(feature = "render")]
    let render: Option<&RenderStage> = opts.render.then_some(&render_stage as &RenderStage);
    #[cfg(not(feature = "render"))]
    let render: Option<&RenderStage> = None;

    let scenes_todo: u64 = todo.iter().map(|&g| manifest.group_size(g)).sum();
    if let (Some(banner), true) = (&render_banner, opts.progress && scenes_todo > 0) {
        rh_contract::note!("{banner}");
    }
    let progress = Progress::new(scenes_todo, opts.progress, opts.progress_every_s);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| BuildError::Internal(format!("thread pool: {e}")))?;
    let syncer = Syncer::start();
    let produced = pool.install(|| {
        todo.par_iter()
            .try_for_each(|&g| -> Result<(), BuildError> {
                let count = manifest.group_size(g);
                let (results, rejections) = run_group(
                    catalog,
                    &opts.families,
                    opts.selections.as_deref(),
                    opts.seed,
                    g,
                    count,
                    config,
                    render,
                )
                .map_err(|e| match e {
                    GroupError::Input(m) => BuildError::Input(m),
                    GroupError::Render(m) => BuildError::Internal(m),
                })?;
                // Specs, then the checksums of every file the rows name, and the record
                // last: its presence says the group (specs, media, sums) is done.
                let files = group_files(out, g, &results, &rejections, catalog)
                    .map_err(|e| BuildError::Internal(e.into()))?;
                syncer.submit(files)?;
                progress.advance(count);
                Ok(())
            })
    });
    // Each worker's renderer goes while the pool is alive (`release_thread_renderer`).
    #[cfg(feature = "render")]
    pool.broadcast(|_| rh_render::release_thread_renderer());
    drop(pool);
    // Every submitted group is made durable, also when a worker failed.
    let synced = syncer.finish();
    synced?;
    produced?;
    progress.finish();

    // Every group's rows, from the records, in scene-index order: streamed, one group
    // at a time, so memory does not grow with --n.
    let records = |f: &mut RowSink| -> Result<(), BuildError> {
        for &g in &groups {
            f(table::read_batch(&record_path(out, g))
                .map_err(|e| BuildError::Internal(e.into()))?)?;
        }
        Ok(())
    };
    let sums = rh_dataset::records::gather_sums(out, &groups)
        .map_err(|e| BuildError::Internal(e.into()))?;
    let rejections = gather_rejections(out, &groups);
    let (rows, eval) = finalize(out, &manifest, &records, sums)?;
    // Retire the records in one atomic step (a rename), then delete them: a crash in
    // between leaves a finished build whose next run only removes the leftover.
    let work = out.join(WORK_DIR);
    let retired = out.join(format!("{WORK_DIR}.done.{}", std::process::id()));
    std::fs::rename(&work, &retired).map_err(|e| internal(&work, e))?;
    std::fs::remove_dir_all(&retired).map_err(|e| internal(&retired, e))?;
    let mut summary = summarize(out, &rows, data_file, done.len(), todo.len(), eval);
    summary.rejections = rejections;
    Ok(summary)
}

fn summarize(
    out: &Path,
    rows: &RecordBatch,
    data_file: String,
    resumed_groups: usize,
    computed_groups: usize,
    eval_scenes: Option<usize>,
) -> BuildSummary {
    let ids = table::string_column(rows, "scene_id");
    let valid = table::bool_column(rows, "valid");
    let family = table::string_column(rows, "family");
    let action = table::string_column(rows, "gt_action");
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
        rejections: None,
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
