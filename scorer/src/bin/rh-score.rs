//! `rh-score`: the ReactHuman offline scorer (SPEC §9–§11, §14).

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use rh_score::baseline::{write_baseline, BaselineKind};
use rh_score::types::is_input_error;
use rh_score::{Config, Dataset, InputError, Report, Scoring};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "rh-score",
    version,
    about = "Score ReactHuman predictions (preds.jsonl) against a dataset's ground truth",
    long_about = "Score ReactHuman predictions (preds.jsonl) against a dataset's ground truth.\n\n\
        Derives each plan's action with the versioned action rule, computes SAA, safety \
        (R1-R4), d_end, AIA and HDE, aggregates them per model, family, speed band, \
        ground-truth action and adversarial flag, and reproduces the paper's analyses. \
        `rh-score --explain` prints every definition.\n\n\
        Exit status: 0 success, 2 bad input or usage, 1 internal error.",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,

    /// Predictions file (JSON Lines: scene_id, model, plan | response [, error]); "-" reads
    /// standard input.
    preds: Option<PathBuf>,

    /// Dataset directory (data/*.parquet + specs/), or a Hugging Face Hub dataset id
    /// owner/name[@revision], downloaded once into the HF cache and then used offline.
    /// Default: $RH_DATASET, else the released dataset (Alan123/reacthuman-benchmark-scaled).
    #[arg(long, value_name = "DIR|owner/name")]
    dataset: Option<String>,

    /// Write the full report as JSON ("-" for stdout, which replaces the table).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,

    /// Write per-(model, breakdown, group) metrics as CSV.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,

    /// Write the report as Markdown.
    #[arg(long, value_name = "FILE")]
    markdown: Option<PathBuf>,

    /// Write the figures (SVG and PNG) into this directory.
    #[arg(long, value_name = "DIR")]
    figures: Option<PathBuf>,

    /// Write a self-contained static site into this directory (leaderboard, figures,
    /// scene browser with videos and every model's decision; opens from file://).
    #[arg(long, value_name = "DIR")]
    html: Option<PathBuf>,

    /// Write one JSON line per decision (its action, rules and metrics).
    #[arg(long, value_name = "FILE")]
    decisions: Option<PathBuf>,

    /// Print every definition (action rule, metrics, safety rules, vocabularies,
    /// aggregation, warnings) and exit unless a predictions file is given too.
    #[arg(long)]
    explain: bool,

    /// Scoring configuration (default: the embedded configs/scoring.toml).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,

    /// Execute every scored plan in physics (SPEC §12): replay the scene from its spec to
    /// the decision moment (checked against the stored state hash), add the humanoid, and
    /// report caught / struck / missed / clear per model, with agreement with the labels.
    #[arg(long)]
    execute: bool,

    /// Execution cache directory (default: $RH_EXEC_CACHE, else ~/.cache/reacthuman/execute).
    #[arg(long, value_name = "DIR", requires = "execute")]
    exec_cache: Option<PathBuf>,

    /// Neither read nor write the execution cache.
    #[arg(long, requires = "execute")]
    no_exec_cache: bool,

    /// Draw every executed decision into this directory: DIR/<scene_id>/<model>__outside.mp4
    /// and __ego.mp4 (H.264), one scene's executions tiled side by side
    /// (DIR/<scene_id>/tiled.mp4) and DIR/index.json. Needs a build with the `videos`
    /// feature (the default) and a GPU or lavapipe.
    #[arg(long, value_name = "DIR", requires = "execute")]
    execute_videos: Option<PathBuf>,

    /// Only these scenes get execution videos (comma-separated scene ids; default: all).
    #[arg(
        long,
        value_name = "ID,...",
        value_delimiter = ',',
        requires = "execute_videos"
    )]
    video_scenes: Option<Vec<String>>,

    /// The scene whose executions are tiled (default: the one with the most executed
    /// decisions, the first on a tie).
    #[arg(long, value_name = "ID", requires = "execute_videos")]
    tiled_scene: Option<String>,

    /// Which scenes every model is expected to answer: the dataset's balanced eval subset
    /// or every valid scene (default: eval when the dataset has an eval/ subset, else all).
    /// Decisions on other scenes are dropped (`outside_subset`).
    #[arg(long, value_enum)]
    subset: Option<rh_score::dataset::Subset>,

    /// Metrics over each model's answered scenes only (unanswered scenes left out instead
    /// of counted as failed); the report says so.
    #[arg(long)]
    answered_only: bool,

    /// Paired comparison of two models on the scenes both answered: the difference in SAA
    /// and safety with a 95% interval, and McNemar's exact p-value.
    #[arg(long, num_args = 2, value_names = ["A", "B"])]
    compare: Option<Vec<String>>,

    /// Do not print the terminal report.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Write reference predictions for every scene of a dataset to stdout (preds.jsonl).
    Baseline {
        /// Which baseline.
        #[arg(value_enum)]
        kind: BaselineKind,
        /// Dataset directory or Hub dataset id owner/name[@revision]. Default: $RH_DATASET,
        /// else the released dataset.
        #[arg(long, value_name = "DIR|owner/name")]
        dataset: Option<String>,
        /// Seed of the random baseline.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Model name written on every line (default: baseline-KIND).
        #[arg(long)]
        model: Option<String>,
        /// Scoring configuration (body constants, thresholds).
        #[arg(long, value_name = "FILE")]
        config: Option<PathBuf>,
    },
    /// Run a model over a dataset through the OpenAI-compatible chat API with the
    /// canonical prompt (configs/prompt.toml) and write preds.jsonl. Resumes: run it again
    /// with the same arguments after a crash, a kill or --max-cost and it does only what is
    /// missing.
    #[cfg(feature = "predict")]
    Predict(Box<PredictArgs>),
    /// Write a synthetic dataset with the rh-pipeline column contract (tests).
    #[command(hide = true)]
    MakeFixture {
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = 40)]
        n: usize,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Leave this column out (repeatable).
        #[arg(long = "drop-column")]
        drop: Vec<String>,
    },
}

#[cfg(feature = "predict")]
#[derive(clap::Args, Debug)]
struct PredictArgs {
    /// Dataset directory (data/*.parquet + frames/) or Hub dataset id owner/name[@revision].
    /// Default: $RH_DATASET, else the released dataset.
    #[arg(long, value_name = "DIR|owner/name")]
    dataset: Option<String>,
    /// Model id as the server knows it (e.g. gpt-4o, Qwen/Qwen2.5-VL-7B-Instruct).
    #[arg(long)]
    model: String,
    /// Predictions file (JSON Lines), appended to and resumed.
    #[arg(long, value_name = "FILE", required_unless_present = "dry_run")]
    out: Option<PathBuf>,
    /// OpenAI-compatible endpoint, e.g. http://127.0.0.1:8000/v1 (default: $OPENAI_BASE_URL,
    /// else configs/predict.toml).
    #[arg(long, value_name = "URL")]
    base_url: Option<String>,
    /// Environment variable holding the API key (unset is fine for local servers).
    #[arg(long, value_name = "VAR", default_value = "OPENAI_API_KEY")]
    api_key_env: String,
    /// Which scenes: the balanced eval subset or every valid scene.
    #[arg(long, value_enum, default_value = "eval")]
    subset: rh_score::dataset::Subset,
    /// Only the first N scenes of the subset (dataset order).
    #[arg(long, value_name = "N")]
    limit: Option<usize>,
    /// Most requests in flight (adaptive: halves on HTTP 429, grows back).
    #[arg(long, value_name = "N")]
    concurrency: Option<usize>,
    /// Sampling temperature (default: configs/predict.toml).
    #[arg(long)]
    temperature: Option<f64>,
    /// Most completion tokens per answer (default: configs/predict.toml).
    #[arg(long)]
    max_tokens: Option<u32>,
    /// Stop cleanly before the requests recorded in --out cost more than this (USD); run
    /// again with a higher value to resume.
    #[arg(long, value_name = "USD")]
    max_cost: Option<f64>,
    /// Price of input tokens, USD per million (overrides the price table).
    #[arg(long, value_name = "USD")]
    price_in: Option<f64>,
    /// Price of output tokens, USD per million (overrides the price table).
    #[arg(long, value_name = "USD")]
    price_out: Option<f64>,
    /// Ask again for the scenes whose line in --out is an `error` line (lost decisions);
    /// their old lines are removed.
    #[arg(long)]
    retry_errors: bool,
    /// Do not read or write the response cache.
    #[arg(long)]
    no_cache: bool,
    /// Response cache directory (default: $RH_LLM_CACHE, else ~/.cache/reacthuman/llm).
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Index of this independent sample (for several samples at temperature > 0; part of
    /// the cache key).
    #[arg(long, default_value_t = 0)]
    sample_index: u32,
    /// Per-request timeout in seconds (default: configs/predict.toml).
    #[arg(long, value_name = "S")]
    timeout: Option<f64>,
    /// Retries of a transient failure (default: configs/predict.toml).
    #[arg(long, value_name = "N")]
    max_retries: Option<u32>,
    /// Runner configuration (client defaults, generation, prices); default: the embedded
    /// configs/predict.toml.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Prompt template; default: the embedded canonical configs/prompt.toml. A changed
    /// prompt must carry its own version.
    #[arg(long, value_name = "FILE")]
    prompt: Option<PathBuf>,
    /// Print the first scene's full request (images elided) and exit without sending it.
    #[arg(long)]
    dry_run: bool,
    /// Print the run summary as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[cfg(feature = "predict")]
fn predict(a: PredictArgs) -> Result<()> {
    use rh_score::predict::config::{Generation, PredictConfig, Price, PromptConfig};
    let cfg = PredictConfig::load(a.config.as_deref())?;
    let prompt = PromptConfig::load(a.prompt.as_deref())?;
    let mut client = cfg.client.clone();
    if let Some(u) = a.base_url.clone().or_else(|| {
        std::env::var("OPENAI_BASE_URL")
            .ok()
            .filter(|s| !s.is_empty())
    }) {
        client.base_url = u;
    }
    client.api_key = std::env::var(&a.api_key_env).ok().filter(|k| !k.is_empty());
    if let Some(c) = a.concurrency {
        if c == 0 {
            return Err(InputError("--concurrency must be at least 1".into()).into());
        }
        client.concurrency = c;
    }
    if let Some(t) = a.timeout {
        if !(t > 0.0) {
            return Err(InputError("--timeout must be positive".into()).into());
        }
        client.timeout_s = t;
    }
    if let Some(r) = a.max_retries {
        client.max_retries = r;
    }
    if a.max_cost.is_some_and(|c| !(c >= 0.0)) {
        return Err(InputError("--max-cost must be a non-negative number of USD".into()).into());
    }
    let table = cfg.price(&a.model);
    let price = match (a.price_in, a.price_out, table) {
        (None, None, t) => t,
        (i, o, t) => Some(Price {
            input: i.or(t.map(|p| p.input)).unwrap_or(0.0),
            output: o.or(t.map(|p| p.output)).unwrap_or(0.0),
        }),
    };
    rh_score::predict::check_price(&a.model, a.max_cost, price)?;
    if price.is_none() && !a.dry_run {
        eprintln!(
            "rh-score predict: no price for model {:?} in the price table: its cost counts as $0 (give --price-in/--price-out for a real figure)",
            a.model
        );
    }
    let dataset = dataset_dir(a.dataset.clone())?;
    let ds = Dataset::load(&dataset)?;
    let scenes = rh_score::predict::select_scenes(&ds, a.subset, a.limit)?;
    let opts = rh_score::predict::PredictOptions {
        dataset,
        model: a.model.clone(),
        out: a.out.clone().unwrap_or_default(),
        subset: a.subset,
        limit: a.limit,
        client,
        generation: Generation {
            temperature: a.temperature.unwrap_or(cfg.generation.temperature),
            max_tokens: a.max_tokens.unwrap_or(cfg.generation.max_tokens),
        },
        price,
        max_cost: a.max_cost,
        retry_errors: a.retry_errors,
        cache_dir: (!a.no_cache).then(|| {
            a.cache_dir
                .clone()
                .unwrap_or_else(rh_llm::cache::default_dir)
        }),
        sample: a.sample_index,
        prompt,
        progress: !a.quiet && !a.json,
        abort_after_failures: cfg.run.abort_after_failures,
        progress_every_s: cfg.run.progress_every_s,
    };
    if a.dry_run {
        let req = rh_score::predict::dry_run(&opts, &scenes)?;
        let e = &req["estimate"];
        eprintln!(
            "rh-score predict --dry-run: {} scenes ≈ {} input tokens ({} a scene) + at most {} output tokens; cost {}",
            e["scenes"],
            e["input_tokens"],
            e["input_tokens_per_scene"],
            e["output_tokens_at_most"],
            match (e["cost_usd_at_least"].as_f64(), e["cost_usd_at_most"].as_f64()) {
                (Some(lo), Some(hi)) => format!("≈ ${lo:.4} to ${hi:.4} (estimate)"),
                _ => "unknown: no price for this model (give --price-in/--price-out)".into(),
            }
        );
        return print_out(&(serde_json::to_string_pretty(&req)? + "\n"));
    }
    let s = rh_score::predict::run(&opts, &scenes)?;
    if a.json {
        print_out(&(serde_json::to_string_pretty(&s)? + "\n"))?;
    } else {
        eprintln!(
            "rh-score predict: {} of {} scenes in {} ({} already there, {} new: {} answered, \
             {} lost as error lines, {} refusals, {} without a parseable plan); {} requests, \
             {} retries, {} rate-limited, {} from the cache; cost ${:.4} (file total ${:.4}); \
             {:.1} decisions/s; prompt {}",
            s.scenes - s.remaining,
            s.scenes,
            s.out,
            s.already_done,
            s.written,
            s.answered,
            s.lost,
            s.refusals,
            s.unparseable,
            s.requests,
            s.retries,
            s.rate_limited,
            s.cache_hits,
            s.cost_usd,
            s.total_cost_usd,
            s.decisions_per_s,
            s.prompt_version
        );
    }
    if s.stopped == "max_cost" {
        eprintln!(
            "rh-score predict: stopped by --max-cost {:.4} USD with {} scene(s) left; run again \
             with a higher --max-cost to resume",
            a.max_cost.unwrap_or(0.0),
            s.remaining
        );
    }
    if s.lost > 0 {
        eprintln!(
            "rh-score predict: {} decision(s) lost; `--retry-errors` asks for them again",
            s.lost
        );
    }
    Ok(())
}

/// Resolves `--dataset` / `$RH_DATASET` / the released dataset to a local directory: an
/// existing path is used as is; `owner/name[@revision]` is downloaded from the Hub into the
/// Hugging Face cache (or found there when the Hub is unreachable).
fn dataset_dir(arg: Option<String>) -> Result<PathBuf> {
    rh_score::dataset::resolve_dir(arg)
}

fn load_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => Config::load(p).map_err(|e| InputError(format!("{e:#}")).into()),
        None => Ok(Config::default()),
    }
}

fn write_file(path: &Path, what: &str, text: &str) -> Result<()> {
    std::fs::write(path, text)
        .map_err(|e| InputError(format!("cannot write {what} to {}: {e}", path.display())).into())
}

fn score(cli: Cli) -> Result<()> {
    let cfg = load_config(cli.config.as_deref())?;
    if cli.explain {
        print!("{}", rh_score::explain::explain(&cfg));
        if cli.preds.is_none() {
            return Ok(());
        }
    }
    let Some(preds) = cli.preds else {
        return Err(InputError(
            "missing the predictions file: rh-score PREDS.jsonl --dataset DIR (see --help)".into(),
        )
        .into());
    };
    if cli.html.is_some() && preds.as_os_str() == "-" {
        return Err(InputError(
            "--html reads the predictions twice (per-decision details for the scene pages): give a file, not stdin".into(),
        )
        .into());
    }
    if cli.execute && !cfg!(feature = "execute") {
        return Err(InputError(
            "--execute: this rh-score was built without the `execute` feature (no simulator); build it with default features (cargo build --release -p rh-score)".into(),
        )
        .into());
    }
    if cli.execute_videos.is_some() && !cfg!(feature = "videos") {
        return Err(InputError(
            "--execute-videos: this rh-score was built without the `videos` feature (no renderer); build it with default features (cargo build --release -p rh-score)".into(),
        )
        .into());
    }
    let ds = Dataset::load(&dataset_dir(cli.dataset)?)?;
    let expected = rh_score::coverage::Expected::resolve(&ds, cli.subset)?;
    let mut scoring = Scoring::new(&ds, &cfg).with_expected(expected);
    if let Some(p) = &cli.decisions {
        let f = std::fs::File::create(p)
            .map_err(|e| InputError(format!("cannot write decisions to {}: {e}", p.display())))?;
        scoring = scoring.with_decisions_output(Box::new(std::io::BufWriter::new(f)));
    }
    if cli.execute {
        scoring = scoring.with_execution();
    }
    if preds.as_os_str() == "-" {
        scoring.score_reader(std::io::BufReader::with_capacity(1 << 20, std::io::stdin()))?;
    } else {
        scoring.score_path(&preds)?;
    }
    rh_score::refusal::check_scored(&scoring, &preds.display().to_string())?;
    let mut report = Report::build_with(&scoring, &preds.display().to_string(), cli.answered_only);
    if let Some(pair) = &cli.compare {
        let c = rh_score::compare::compare(&scoring, &pair[0], &pair[1])?;
        report.comparisons.push(c);
    }
    if cli.execute {
        let cache = (!cli.no_exec_cache).then(|| {
            cli.exec_cache
                .clone()
                .unwrap_or_else(rh_score::execution::default_cache_dir)
        });
        let videos = cli.execute_videos.as_deref().map(|dir| Videos {
            dir,
            scenes: cli.video_scenes.as_deref(),
            tiled_scene: cli.tiled_scene.as_deref(),
            progress: !cli.quiet,
        });
        report.execution = Some(execute(&mut scoring, &ds, &cfg, cache.as_deref(), videos)?);
    }
    drop(scoring);

    let json_stdout = cli.json.as_deref() == Some(Path::new("-"));
    if let Some(p) = &cli.json {
        let text = serde_json::to_string_pretty(&report).context("serializing the report")? + "\n";
        if json_stdout {
            print_out(&text)?;
        } else {
            write_file(p, "the JSON report", &text)?;
        }
    }
    if let Some(p) = &cli.csv {
        write_file(p, "the CSV report", &rh_score::tables::csv(&report))?;
        if let Some(e) = &report.execution {
            // Outcome rates have other columns: their own file beside it, FILE.execution.csv.
            let q = p.with_extension("execution.csv");
            write_file(
                &q,
                "the execution CSV",
                &rh_score::execution::report::csv(e),
            )?;
        }
    }
    if let Some(p) = &cli.markdown {
        write_file(
            p,
            "the Markdown report",
            &rh_score::tables::markdown(&report),
        )?;
    }
    if let Some(d) = &cli.figures {
        rh_score::figures::write_figures(&report, d)?;
    }
    let site = match &cli.html {
        Some(dir) => Some(rh_score::html::write_site(&report, &ds, &cfg, &preds, dir)?),
        None => None,
    };
    if !cli.quiet && !json_stdout {
        print_out(&rh_score::tables::terminal(&report))?;
        if let Some(e) = &report.execution {
            print_out(&rh_score::execution::report::terminal(e, 50))?;
        }
    } else if let Some(e) = &report.execution {
        // The disagreements are always listed (on stderr when stdout is taken).
        if !e.disagreements.is_empty() {
            eprint!("{}", rh_score::execution::report::terminal(e, 50));
        }
    }
    if let Some(site) = site {
        let index = site
            .dir
            .canonicalize()
            .unwrap_or(site.dir.clone())
            .join("index.html");
        eprintln!(
            "rh-score: site with {} models and {} scenes ({} video files) in {}; open file://{}",
            site.models,
            site.scenes,
            site.media_files,
            site.dir.display(),
            index.display()
        );
    }
    eprint!("{}", rh_score::refusal::stderr_notes(&report));
    Ok(())
}

/// `--execute`: runs the collected decisions in physics, completes and writes the held
/// back decision lines, and returns the report's execution part.
/// `--execute-videos` and its options.
#[cfg_attr(not(feature = "videos"), allow(dead_code))]
struct Videos<'a> {
    dir: &'a Path,
    scenes: Option<&'a [String]>,
    tiled_scene: Option<&'a str>,
    progress: bool,
}

#[cfg(feature = "execute")]
fn execute(
    scoring: &mut Scoring,
    ds: &Dataset,
    cfg: &Config,
    cache: Option<&Path>,
    videos: Option<Videos>,
) -> Result<rh_score::execution::ExecutionReport> {
    use rh_score::execution::{execute_all, ExecutionReport};
    let (collected, names) = scoring
        .take_execution()
        .expect("execution was enabled before scoring");
    let (outcomes, stats) = execute_all(ds, &collected.pending, &cfg.execution, cache)?;
    if let Some(v) = videos {
        write_videos(ds, &collected.pending, &outcomes, &names, cfg, v)?;
    }
    if let Some(w) = scoring.decisions_output() {
        let by_key: std::collections::BTreeMap<(usize, u32), usize> = collected
            .pending
            .iter()
            .enumerate()
            .map(|(i, p)| ((p.model, p.scene), i))
            .collect();
        for (model, scene, mut line) in collected.deferred {
            let scored = line.get("status").and_then(|s| s.as_str()) == Some("scored");
            if let (true, Some(&i), Some(obj)) =
                (scored, by_key.get(&(model, scene)), line.as_object_mut())
            {
                let value = match &outcomes[i] {
                    Some(o) => serde_json::to_value(o)?,
                    None => serde_json::json!({"outcome": null, "reason": "not executed (R1)"}),
                };
                obj.insert("execution".into(), value);
            }
            serde_json::to_writer(&mut *w, &line)?;
            w.write_all(b"\n")?;
        }
        w.flush()?;
    }
    Ok(ExecutionReport::build(
        ds,
        &names,
        &collected.pending,
        &outcomes,
        &cfg.execution,
        stats,
    ))
}

#[cfg(not(feature = "execute"))]
fn execute(
    _: &mut Scoring,
    _: &Dataset,
    _: &Config,
    _: Option<&Path>,
    _: Option<Videos>,
) -> Result<rh_score::execution::ExecutionReport> {
    unreachable!("--execute is refused before scoring in a build without `execute`")
}

/// Draws the execution videos (`--execute-videos`) and says what was written.
#[cfg(feature = "videos")]
fn write_videos(
    ds: &Dataset,
    pending: &[rh_score::execution::Pending],
    outcomes: &[Option<rh_contract::execution::Outcome>],
    names: &[String],
    cfg: &Config,
    v: Videos,
) -> Result<()> {
    use rh_score::execution::videos::{write_videos, VideoRequest};
    let req = VideoRequest {
        dir: v.dir,
        scenes: v.scenes,
        tiled_scene: v.tiled_scene,
        progress: v.progress,
    };
    let started = std::time::Instant::now();
    let index = write_videos(
        ds,
        pending,
        outcomes,
        names,
        &cfg.execution,
        &cfg.execution_video,
        &req,
    )?;
    let decisions: usize = index.scenes.iter().map(|s| s.decisions.len()).sum();
    let secs = started.elapsed().as_secs_f64();
    eprintln!(
        "rh-score: execution videos of {decisions} decisions in {} scenes ({:.2} s per decision) in {}; see {}",
        index.scenes.len(),
        secs / decisions.max(1) as f64,
        v.dir.display(),
        v.dir.join("index.json").display()
    );
    Ok(())
}

#[cfg(not(feature = "videos"))]
#[cfg_attr(not(feature = "execute"), allow(dead_code))]
fn write_videos(
    _: &Dataset,
    _: &[rh_score::execution::Pending],
    _: &[Option<rh_contract::execution::Outcome>],
    _: &[String],
    _: &Config,
    _: Videos,
) -> Result<()> {
    unreachable!("--execute-videos is refused before scoring in a build without `videos`")
}

fn print_out(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r?),
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.cmd {
        None => score(cli),
        Some(Cmd::Baseline {
            kind,
            dataset,
            seed,
            model,
            config,
        }) => {
            let cfg = load_config(config.as_deref())?;
            let ds = Dataset::load(&dataset_dir(dataset)?)?;
            let model = model.unwrap_or_else(|| format!("baseline-{}", kind.name()));
            let stdout = std::io::stdout();
            let mut out = std::io::BufWriter::new(stdout.lock());
            match write_baseline(kind, &ds, seed, &model, &cfg, &mut out) {
                Err(e)
                    if e.downcast_ref::<std::io::Error>()
                        .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
                        || e.downcast_ref::<serde_json::Error>()
                            .and_then(|j| j.io_error_kind())
                            == Some(std::io::ErrorKind::BrokenPipe) =>
                {
                    Ok(())
                }
                r => r,
            }
        }
        #[cfg(feature = "predict")]
        Some(Cmd::Predict(a)) => predict(*a),
        Some(Cmd::MakeFixture { out, n, seed, drop }) => {
            let rows = rh_score::fixture::synth_rows(n, seed);
            let drop: Vec<&str> = drop.iter().map(String::as_str).collect();
            rh_score::fixture::write_dataset(&out, &rows, &drop)?;
            println!("wrote {n} synthetic scenes to {}", out.display());
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rh-score: error: {e:#}");
            if is_input_error(&e) {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
