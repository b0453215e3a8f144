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

    /// Execute plans in physics (SPEC §12; not available in this build).
    #[arg(long)]
    execute: bool,

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

/// Resolves `--dataset` / `$RH_DATASET` / the released dataset to a local directory: an
/// existing path is used as is; `owner/name[@revision]` is downloaded from the Hub into the
/// Hugging Face cache (or found there when the Hub is unreachable).
fn dataset_dir(arg: Option<String>) -> Result<PathBuf> {
    let given = arg.or_else(|| std::env::var("RH_DATASET").ok().filter(|s| !s.is_empty()));
    let id = match given {
        Some(d) => {
            let path = PathBuf::from(&d);
            if path.exists() {
                return Ok(path);
            }
            let (repo, _) = d.split_once('@').unwrap_or((&d, ""));
            if !rh_hub::is_repo_id(repo) {
                return Err(InputError(format!(
                    "dataset directory {d} does not exist (nor is it a Hub dataset id owner/name)"
                ))
                .into());
            }
            d
        }
        None => rh_hub::RELEASED_DATASET.to_string(),
    };
    let (repo, revision) = match id.split_once('@') {
        Some((r, rev)) => (r, Some(rev)),
        None => (id.as_str(), None),
    };
    match rh_hub::fetch(repo, revision) {
        Ok(snapshot) => {
            if snapshot.from_cache_only {
                eprintln!(
                    "rh-score: the Hub at {} was not used ({}); {repo} comes from the Hugging Face cache, all {} files checked",
                    rh_hub::endpoint(),
                    snapshot.cache_reason.as_deref().unwrap_or("offline"),
                    snapshot.files
                );
            }
            Ok(snapshot.path)
        }
        Err(e) if e.exit_code() == 2 => Err(InputError(e.to_string()).into()),
        Err(e) => Err(anyhow::anyhow!("{e}")),
    }
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
    if cli.execute {
        return Err(InputError(
            "--execute (physics execution of plans, SPEC §12) is not available in this build"
                .into(),
        )
        .into());
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
    let ds = Dataset::load(&dataset_dir(cli.dataset)?)?;
    let mut scoring = Scoring::new(&ds, &cfg);
    if let Some(p) = &cli.decisions {
        let f = std::fs::File::create(p)
            .map_err(|e| InputError(format!("cannot write decisions to {}: {e}", p.display())))?;
        scoring = scoring.with_decisions_output(Box::new(std::io::BufWriter::new(f)));
    }
    if preds.as_os_str() == "-" {
        scoring.score_reader(std::io::BufReader::with_capacity(1 << 20, std::io::stdin()))?;
    } else {
        scoring.score_path(&preds)?;
    }
    let report = Report::build(&scoring, &preds.display().to_string());
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
    let warned: u64 = report.input.warnings.iter().map(|w| w.count).sum();
    if warned > 0 {
        eprintln!(
            "rh-score: {warned} input warning(s) in {}; see the report's warnings section",
            preds.display()
        );
        // One line per kind, naming its first line, so a user can go and look.
        for w in &report.input.warnings {
            match w.first_lines.first() {
                Some(first) => eprintln!(
                    "rh-score:   {} ×{} (first at line {first})",
                    w.kind, w.count
                ),
                None => eprintln!("rh-score:   {} ×{}", w.kind, w.count),
            }
        }
    }
    Ok(())
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
