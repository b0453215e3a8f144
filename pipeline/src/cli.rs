//! The `rh-pipeline` command line (SPEC §14). Exit status: 0 success, 2 bad input or
//! usage (with a message naming what is wrong), 1 internal failure.

use crate::build::{build, BuildError, BuildOptions};
use clap::{Parser, Subcommand};
use rh_catalog::Catalog;
use rh_dataset::verify::{verify, verify_fast};
use rh_scenes::config::Config;
use rh_scenes::selection::{LexiconPlanner, Planner};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "rh-pipeline",
    version,
    about = "Builds the ReactHuman dataset: bit-for-bit reproducible physics scenes with exact ground truth",
    after_help = "Exit status: 0 success, 2 bad input or usage, 1 internal failure."
)]
pub struct Cli {
    /// Build configuration (TOML); defaults to the embedded configs/default.toml.
    #[arg(long, global = true, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Catalog directory holding objects.toml and rooms.toml; defaults to the embedded catalog.
    #[arg(long, global = true, value_name = "DIR")]
    pub catalog: Option<PathBuf>,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Build N scenes into a Hugging Face-style dataset directory.
    Build {
        /// Number of scenes (four speed bands per scene group). With --descriptions it
        /// defaults to four per description (group g takes description g mod D).
        #[arg(long, required_unless_present = "descriptions")]
        n: Option<u64>,
        /// Plan the scene groups from these descriptions (a text file, one a line; blank
        /// lines and lines starting with # are skipped) instead of round-robin families.
        #[arg(long, value_name = "FILE")]
        descriptions: Option<PathBuf>,
        /// Which planner reads the descriptions.
        #[arg(long, value_enum, default_value = "lexicon", requires = "descriptions")]
        planner: PlannerKind,
        #[command(flatten)]
        llm: LlmArgs,
        /// Output directory (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Build seed; defaults to the configuration's build.seed.
        #[arg(long)]
        seed: Option<u64>,
        /// Comma-separated families; defaults to the configuration's build.families.
        #[arg(long, value_delimiter = ',')]
        families: Option<Vec<String>>,
        /// Skip rendering (videos and frames); labels, specs and Parquet only.
        #[arg(long)]
        no_render: bool,
        /// Also write each observation frame's segmentation and depth: 16-bit PNGs of
        /// instance ids (`masks/<scene_id>/<cam>_t….png`) and of the distance from the
        /// camera in mm (`depth/…`), named by the `<cam>_mask_paths` / `<cam>_depth_paths`
        /// columns.
        #[arg(long, conflicts_with = "no_render")]
        masks: bool,
        /// Build only shard i of N (scene groups g with g mod N = i), e.g. 0/4.
        #[arg(long, value_name = "i/N")]
        shard: Option<String>,
        /// Worker threads (default: all cores). Never changes the output.
        #[arg(long)]
        jobs: Option<usize>,
        /// Print the build summary as JSON on stdout.
        #[arg(long)]
        json: bool,
        /// No progress output.
        #[arg(long)]
        quiet: bool,
        /// When stderr is not a terminal (a log file, CI): seconds between progress lines
        /// (scenes done of total, rate, ETA). A terminal gets a progress bar instead.
        #[arg(long, value_name = "SECONDS", default_value_t = rh_contract::progress::LOG_EVERY_S)]
        progress_every: f64,
    },
    /// Map a free-text description to a validated selection (family, object, room); prints JSON.
    Plan {
        /// e.g. "a cast-iron pan slides off the counter"
        description: String,
        /// Seed for choices the description leaves open.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Ask a language model (OpenAI-compatible API; --model) instead of the lexicon.
        #[arg(long, requires = "model")]
        llm: bool,
        #[command(flatten)]
        llm_args: LlmArgs,
    },
    /// Combine the outputs of `build --shard i/N` (all N of them) into one dataset equal to
    /// the unsharded build.
    Merge {
        /// Output directory (must not exist, or be empty).
        out: PathBuf,
        /// The shard directories, in any order.
        #[arg(required = true, value_name = "SHARD_DIR")]
        shards: Vec<PathBuf>,
        /// Print the merge summary as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Download a dataset from the Hugging Face Hub into the HF cache (offline: use the
    /// cache) and print its local path. Honours HF_ENDPOINT, HF_HOME, HF_TOKEN, HF_HUB_OFFLINE.
    Download {
        /// Dataset repository id, owner/name.
        repo: String,
        /// Branch, tag or commit (default: main).
        #[arg(long)]
        revision: Option<String>,
        /// Also copy the files into this directory as a plain dataset directory.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Check a dataset end to end (exit 2 on any problem): every file against the SHA-256
    /// its build.json records, every spec against the one derived again from (selection,
    /// seed, configuration), every Parquet column against the value derived from the
    /// replay. `--fast` only replays the specs and compares per-step state hashes.
    Verify {
        /// Dataset directory built by `rh-pipeline build`.
        dir: PathBuf,
        /// Only replay each stored spec and compare its state hash (no file checksums, no
        /// re-derivation of specs and labels).
        #[arg(long)]
        fast: bool,
        /// Print the report as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Tile one observation frame per family of a rendered dataset (the close-up at
    /// t = 0.30 s of each family's first scene) into one labelled PNG, to eyeball all
    /// families at once.
    Sheet {
        /// Dataset directory built by `rh-pipeline build` (with rendering).
        dir: PathBuf,
        /// The PNG to write.
        #[arg(long, value_name = "PNG")]
        out: PathBuf,
        /// Print the tiles (family, scene id) as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Label balance: build K scenes per family in memory and count CATCH / DODGE /
    /// NO_ACTION per family (the paper's 17 × 18 subset by default).
    Balance {
        /// Build seed; defaults to the configuration's build.seed.
        #[arg(long)]
        seed: Option<u64>,
        /// Scenes per family.
        #[arg(long, default_value_t = 18)]
        per_family: usize,
        /// Comma-separated families (default: all implemented).
        #[arg(long, value_delimiter = ',')]
        families: Option<Vec<String>>,
        /// Print the counts as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
}

/// Which planner turns descriptions into selections.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PlannerKind {
    Lexicon,
    Llm,
}

/// The language model of the LLM planner (same client as `rh-score predict`).
#[derive(clap::Args, Debug, Clone)]
pub struct LlmArgs {
    /// Model id for the LLM planner.
    #[arg(long)]
    pub model: Option<String>,
    /// OpenAI-compatible endpoint (default: $OPENAI_BASE_URL, else configs/planner.toml).
    #[arg(long, value_name = "URL")]
    pub base_url: Option<String>,
    /// Environment variable holding the API key (unset is fine for local servers).
    #[arg(long, value_name = "VAR", default_value = "OPENAI_API_KEY")]
    pub api_key_env: String,
    /// Do not read or write the response cache.
    #[arg(long)]
    pub no_cache: bool,
}

fn llm_planner<'a>(
    catalog: &'a Catalog,
    args: &LlmArgs,
) -> Result<crate::llm_plan::LlmPlanner<'a>, Failure> {
    let model = args
        .model
        .as_deref()
        .ok_or_else(|| input("the LLM planner needs --model ID"))?;
    let cfg = crate::llm_plan::PlannerConfig::embedded();
    let mut client = cfg.client.clone();
    if let Some(u) = args.base_url.clone().or_else(|| {
        std::env::var("OPENAI_BASE_URL")
            .ok()
            .filter(|s| !s.is_empty())
    }) {
        client.base_url = u;
    }
    client.api_key = std::env::var(&args.api_key_env)
        .ok()
        .filter(|k| !k.is_empty());
    let cache = (!args.no_cache).then(|| rh_llm::cache::Cache::new(rh_llm::cache::default_dir()));
    crate::llm_plan::LlmPlanner::new(catalog, client, cache, model, cfg).map_err(|m| Failure {
        code: 1,
        message: m,
    })
}

/// Reads a descriptions file: one a line; blank lines and `#` comments skipped.
fn read_descriptions(path: &std::path::Path) -> Result<Vec<String>, Failure> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        input(format!(
            "cannot read --descriptions {}: {e}",
            path.display()
        ))
    })?;
    let lines: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_string)
        .collect();
    if lines.is_empty() {
        return Err(input(format!("{}: no descriptions", path.display())));
    }
    Ok(lines)
}

/// One selection per description; description `i` plans with group `i`'s seed.
fn plan_descriptions(
    planner: &dyn Planner,
    descriptions: &[String],
    path: &std::path::Path,
    build_seed: u64,
) -> Result<Vec<rh_physics::spec::Selection>, Failure> {
    descriptions
        .iter()
        .enumerate()
        .map(|(i, d)| {
            planner
                .plan(d, rh_physics::seeds::group_seed(build_seed, i as u64))
                .map_err(|e| input(format!("{}: description {}: {e}", path.display(), i + 1)))
        })
        .collect()
}

/// A failure with its exit code.
pub struct Failure {
    pub code: u8,
    pub message: String,
}

fn input(message: impl Into<String>) -> Failure {
    Failure {
        code: 2,
        message: message.into(),
    }
}

fn parse_shard(text: &str) -> Result<(u64, u64), Failure> {
    let bad = || {
        input(format!(
            "--shard '{text}': expected i/N with 0 <= i < N, e.g. 0/4"
        ))
    };
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (u64, u64) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

fn load(cli: &Cli) -> Result<(Catalog, Config), Failure> {
    let catalog = match &cli.catalog {
        Some(dir) => Catalog::load_dir(dir),
        None => Catalog::embedded(),
    }
    .map_err(|e| input(format!("catalog: {e}")))?;
    let config = match &cli.config {
        Some(path) => Config::load(path),
        None => Config::embedded(),
    }
    .map_err(|e| input(format!("config: {e}")))?;
    Ok((catalog, config))
}

fn build_failure(e: BuildError) -> Failure {
    match e {
        BuildError::Input(m) => input(m),
        BuildError::Internal(m) => Failure {
            code: 1,
            message: m,
        },
    }
}

fn print_json<T: serde::Serialize>(value: &T) {
    println!(
        "{}",
        serde_json::to_string_pretty(value).expect("summary serializes")
    );
}

/// `rh-pipeline sheet`: the contact sheet of a rendered dataset.
#[cfg(feature = "render")]
fn sheet(dir: &Path, out: &Path, json: bool) -> Result<(), Failure> {
    if !dir.join("specs").is_dir() {
        return Err(input(format!(
            "{}: not a dataset directory (no specs/)",
            dir.display()
        )));
    }
    let sheet = rh_render::contact_sheet(dir, out).map_err(|e| match e {
        rh_render::RenderError::Io(m) => input(m),
        other => Failure {
            code: 1,
            message: other.to_string(),
        },
    })?;
    if json {
        let tiles: Vec<serde_json::Value> = sheet
            .tiles
            .iter()
            .map(|(family, id)| serde_json::json!({ "family": family, "scene_id": id }))
            .collect();
        print_json(&serde_json::json!({
            "out": out.display().to_string(),
            "width": sheet.width,
            "height": sheet.height,
            "tiles": tiles,
        }));
    } else {
        println!(
            "contact sheet of {} families ({}x{}) written to {}",
            sheet.tiles.len(),
            sheet.width,
            sheet.height,
            out.display()
        );
    }
    Ok(())
}

/// `rh-pipeline sheet` in a program built without the `render` feature.
#[cfg(not(feature = "render"))]
fn sheet(_dir: &Path, _out: &Path, _json: bool) -> Result<(), Failure> {
    Err(input(
        "`sheet` needs the `render` feature; this rh-pipeline was built without it \
         (cargo build --no-default-features)",
    ))
}

/// `rh-pipeline build`: builds, then prints the summary.
fn run_build(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
    json: bool,
) -> Result<(), Failure> {
    let summary = build(opts, catalog, config).map_err(build_failure)?;
    if json {
        print_json(&summary);
    } else {
        println!(
            "built {} scenes ({} valid) into {} — {}{}",
            summary.scenes,
            summary.valid,
            summary.out,
            summary.data_file,
            if summary.resumed_groups > 0 {
                format!(" (resumed {} groups)", summary.resumed_groups)
            } else {
                String::new()
            }
        );
        let actions: Vec<String> = summary
            .per_action
            .iter()
            .map(|(a, c)| format!("{a} {c}"))
            .collect();
        println!("labels: {}", actions.join(", "));
        if let Some(rejections) = &summary.rejections {
            let attempts: u32 = rejections.values().map(|f| f.attempts).sum();
            let by_family: Vec<String> = rejections
                .iter()
                .filter_map(|(family, f)| {
                    let n = f.rejected_by.get("valid_visible").copied().unwrap_or(0);
                    (n > 0).then(|| format!("{family} {n}/{}", f.attempts))
                })
                .collect();
            println!(
                "visibility rejected {} of {attempts} group attempts{}",
                rejections
                    .values()
                    .map(|f| f.rejected_by.get("valid_visible").copied().unwrap_or(0))
                    .sum::<u32>(),
                if by_family.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", by_family.join(", "))
                }
            );
        }
        if !summary.invalid_scene_ids.is_empty() {
            println!(
                "warning: {} scene(s) failed validation after every attempt: {}",
                summary.invalid_scene_ids.len(),
                summary.invalid_scene_ids.join(", ")
            );
        }
    }
    Ok(())
}

/// `rh-pipeline verify`: replays every spec against its stored state hash.
fn run_verify(dir: &Path, catalog: &Catalog, fast: bool, json: bool) -> Result<(), Failure> {
    let report = if fast {
        verify_fast(dir)
    } else {
        verify(dir, catalog)
    }
    .map_err(input)?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("report serializes")
        );
    } else {
        for p in &report.file_problems {
            println!("FILE {}: {}", p.file, p.problem);
        }
        for m in &report.mismatches {
            println!("MISMATCH {}: {}", m.scene_id, m.problem);
        }
        if report.mode == "full" {
            println!(
                "verified {} files against build.json: {} problem(s); {} scenes derived again: {} match, {} differ",
                report.files_checked,
                report.file_problems.len(),
                report.scenes,
                report.matched,
                report.scenes - report.matched
            );
        } else {
            println!(
                "verified {} scenes: {} match, {} mismatch",
                report.scenes,
                report.matched,
                report.mismatches.len()
            );
        }
    }
    if report.ok() {
        Ok(())
    } else if report.mode == "full" {
        Err(input(format!(
            "{}: {} file problem(s), {} scene(s) differ from what their build derives",
            dir.display(),
            report.file_problems.len(),
            report.scenes - report.matched
        )))
    } else {
        Err(input(format!(
            "{} scene(s) did not replay to their stored state hash",
            report.mismatches.len()
        )))
    }
}

/// `download`: the dataset from the Hub (or a complete cached copy), checked; prints
/// its path.
fn download(repo: &str, revision: Option<&str>, out: Option<&Path>) -> Result<(), Failure> {
    let snapshot = rh_hub::fetch(repo, revision).map_err(|e| Failure {
        code: e.exit_code(),
        message: e.to_string(),
    })?;
    if snapshot.from_cache_only {
        eprintln!(
            "the Hub at {} was not used ({}); {repo} comes from the Hugging Face cache, all {} files checked",
            rh_hub::endpoint(),
            snapshot.cache_reason.as_deref().unwrap_or("offline"),
            snapshot.files
        );
    }
    let path = match out {
        Some(dir) => {
            let files = rh_hub::copy_snapshot(&snapshot.path, dir).map_err(|e| Failure {
                code: 1,
                message: format!("cannot copy {repo} into {}: {e}", dir.display()),
            })?;
            eprintln!("copied {files} files into {}", dir.display());
            dir.to_path_buf()
        }
        None => snapshot.path,
    };
    println!("{}", path.display());
    Ok(())
}

/// `balance`: label counts per family over `per_family` scenes each, built in memory.
fn balance(
    catalog: &Catalog,
    config: &Config,
    seed: Option<u64>,
    per_family: usize,
    families: Option<Vec<String>>,
    json: bool,
) -> Result<(), Failure> {
    if per_family == 0 {
        return Err(input("--per-family must be at least 1"));
    }
    let families = families.unwrap_or_default();
    for f in &families {
        if rh_scenes::families::get(f).is_none() {
            return Err(input(format!(
                "unknown or unimplemented family '{f}' (implemented: {})",
                rh_scenes::randomize::implemented_families()
            )));
        }
    }
    let rows = rh_scenes::balance::label_balance(
        catalog,
        config,
        seed.unwrap_or(config.build.seed),
        &families,
        per_family,
    )
    .map_err(|e| Failure {
        code: 1,
        message: format!("{e:#}"),
    })?;
    if json {
        print_json(&rows);
    } else {
        print!("{}", rh_scenes::balance::format_table(&rows));
    }
    Ok(())
}

pub fn run(cli: Cli) -> Result<(), Failure> {
    // Commands that need neither the catalog nor the configuration.
    match &cli.command {
        Command::Merge { out, shards, json } => {
            let summary = rh_dataset::merge::merge(out, shards).map_err(build_failure)?;
            if *json {
                print_json(&summary);
            } else {
                println!(
                    "merged {} shards: {} scenes ({} valid) into {} — {}",
                    summary.shards, summary.scenes, summary.valid, summary.out, summary.data_file
                );
            }
            return Ok(());
        }
        Command::Sheet { dir, out, json } => return sheet(dir, out, *json),
        Command::Download {
            repo,
            revision,
            out,
        } => return download(repo, revision.as_deref(), out.as_deref()),
        _ => {}
    }
    let (catalog, config) = load(&cli)?;
    match cli.command {
        Command::Merge { .. } | Command::Download { .. } | Command::Sheet { .. } => {
            unreachable!("handled above")
        }
        Command::Build {
            n,
            descriptions,
            planner,
            llm,
            out,
            seed,
            families,
            no_render,
            masks,
            shard,
            jobs,
            json,
            quiet,
            progress_every,
        } => {
            if !(progress_every.is_finite() && progress_every > 0.0) {
                return Err(input(format!(
                    "--progress-every {progress_every}: must be a positive number of seconds"
                )));
            }
            let seed = seed.unwrap_or(config.build.seed);
            let selections = match &descriptions {
                None => None,
                Some(path) => {
                    let texts = read_descriptions(path)?;
                    let sel = match planner {
                        PlannerKind::Lexicon => {
                            plan_descriptions(&LexiconPlanner::new(&catalog), &texts, path, seed)?
                        }
                        PlannerKind::Llm => {
                            plan_descriptions(&llm_planner(&catalog, &llm)?, &texts, path, seed)?
                        }
                    };
                    Some(sel)
                }
            };
            let n = match (n, &selections) {
                (Some(n), _) => n,
                (None, Some(s)) => 4 * s.len() as u64,
                (None, None) => unreachable!("clap requires --n without --descriptions"),
            };
            let families = match &selections {
                Some(s) => {
                    let mut f: Vec<String> = Vec::new();
                    for x in s {
                        if !f.contains(&x.family) {
                            f.push(x.family.clone());
                        }
                    }
                    f
                }
                None => families.unwrap_or_else(|| config.build.families.clone()),
            };
            let opts = BuildOptions {
                n,
                out,
                seed,
                families,
                selections,
                jobs: jobs
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                shard: match shard {
                    Some(s) => parse_shard(&s)?,
                    None => (0, 1),
                },
                render: !no_render,
                masks,
                progress: !quiet,
                progress_every_s: progress_every,
            };
            run_build(&opts, &catalog, &config, json)
        }
        Command::Balance {
            seed,
            per_family,
            families,
            json,
        } => balance(&catalog, &config, seed, per_family, families, json),
        Command::Plan {
            description,
            seed,
            llm,
            llm_args,
        } => {
            let lexicon = LexiconPlanner::new(&catalog);
            let selection = if llm {
                llm_planner(&catalog, &llm_args)?.plan(&description, seed)
            } else {
                lexicon.plan(&description, seed)
            }
            .map_err(|e| input(e.to_string()))?;
            let matches = lexicon.matches(&description);
            let out = serde_json::json!({ "selection": selection, "matched": matches });
            println!(
                "{}",
                serde_json::to_string_pretty(&out).expect("selection serializes")
            );
            Ok(())
        }
        Command::Verify { dir, fast, json } => run_verify(&dir, &catalog, fast, json),
    }
}

/// Entry point of the binary.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("rh-pipeline: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}
