//! `rh-score`'s command line: the argument definitions (clap), parsed by the binary and
//! read by the command modules ([`super::score_command`], [`super::baseline_command`],
//! [`super::predict_command`]).

use clap::{Parser, Subcommand};
use rh_grade::baseline::BaselineKind;
use std::path::PathBuf;

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
        Exit status: 0 success, 2 bad input or usage, 3 an output that cannot be written \
        (full disk, read-only directory, /dev/full; the file is named and any previous \
        one left unchanged), 1 internal error.",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub cmd: Option<Cmd>,

    /// Predictions file (JSON Lines: scene_id, model, plan | response [, error]); "-" reads
    /// standard input.
    pub preds: Option<PathBuf>,

    /// Dataset directory (data/*.parquet + specs/), or a Hugging Face Hub dataset id
    /// owner/name[@revision], downloaded once into the HF cache and then used offline.
    /// Default: $RH_DATASET, else the project's release (`released_dataset` in configs/hub.toml).
    #[arg(long, value_name = "DIR|owner/name")]
    pub dataset: Option<String>,

    /// Use a dataset whose build did not finish (its build.json records no file
    /// checksums, or files it records are missing); refused otherwise (exit 2).
    #[arg(long)]
    pub allow_incomplete: bool,

    /// Write the full report as JSON ("-" for stdout, which replaces the table).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Write per-(model, breakdown, group) metrics as CSV.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,

    /// Write the report as Markdown.
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,

    /// Write the figures (SVG and PNG) into this directory.
    #[arg(long, value_name = "DIR")]
    pub figures: Option<PathBuf>,

    /// Write a self-contained static site into this directory (leaderboard, figures,
    /// scene browser with videos and every model's decision; opens from file://).
    #[arg(long, value_name = "DIR")]
    pub html: Option<PathBuf>,

    /// Write one results file per model into this directory (DIR/<model>.json: what was
    /// measured — dataset, prompt, rules — coverage and every headline metric with its
    /// interval; schemas/results.schema.json), for `rh-score leaderboard`.
    #[arg(long, value_name = "DIR")]
    pub results: Option<PathBuf>,

    /// Write one JSON line per decision (its action, rules and metrics).
    #[arg(long, value_name = "FILE")]
    pub decisions: Option<PathBuf>,

    /// Print every definition (action rule, metrics, safety rules, vocabularies,
    /// aggregation, warnings) and exit unless a predictions file is given too.
    #[arg(long)]
    pub explain: bool,

    /// Scoring configuration (default: the embedded configs/scoring.toml).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,

    /// Execute every scored plan in physics (specification §12): replay the scene from its spec to
    /// the decision moment (checked against the stored state hash), add the humanoid, and
    /// report caught / struck / missed / clear per model, with agreement with the labels.
    #[arg(long)]
    pub execute: bool,

    /// Execution cache directory (default: $RH_EXEC_CACHE, else ~/.cache/reacthuman/execute).
    #[arg(long, value_name = "DIR", requires = "execute")]
    pub exec_cache: Option<PathBuf>,

    /// Neither read nor write the execution cache.
    #[arg(long, requires = "execute")]
    pub no_exec_cache: bool,

    /// Draw every executed decision into this directory: DIR/<scene_id>/<model>__outside.mp4
    /// and __ego.mp4 (H.264), one scene's executions tiled side by side
    /// (DIR/<scene_id>/tiled.mp4) and DIR/index.json. Needs a build with the `videos`
    /// feature (the default) and a GPU or lavapipe.
    #[arg(long, value_name = "DIR", requires = "execute")]
    pub execute_videos: Option<PathBuf>,

    /// Only these scenes get execution videos (comma-separated scene ids; default: all).
    #[arg(
        long,
        value_name = "ID,...",
        value_delimiter = ',',
        requires = "execute_videos"
    )]
    pub video_scenes: Option<Vec<String>>,

    /// The scene whose executions are tiled (default: the one with the most executed
    /// decisions, the first on a tie).
    #[arg(long, value_name = "ID", requires = "execute_videos")]
    pub tiled_scene: Option<String>,

    /// Which scenes every model is expected to answer: the dataset's balanced eval subset
    /// or every valid scene (default: eval when the dataset has an eval/ subset, else all).
    /// Decisions on other scenes are dropped (`outside_subset`).
    #[arg(long, value_enum)]
    pub subset: Option<rh_grade::dataset::Subset>,

    /// Metrics over each model's answered scenes only (unanswered scenes left out instead
    /// of counted as failed); the report says so.
    #[arg(long)]
    pub answered_only: bool,

    /// Paired comparison of two models on the scenes both answered: the difference in SAA
    /// and safety with a 95% interval, and McNemar's exact p-value.
    #[arg(long, num_args = 2, value_names = ["A", "B"])]
    pub compare: Option<Vec<String>>,

    /// Do not print the terminal report.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Subcommand, Debug)]
pub enum Cmd {
    /// Write reference predictions for every scene of a dataset to stdout (preds.jsonl).
    Baseline {
        /// Which baseline.
        #[arg(value_enum)]
        kind: BaselineKind,
        /// Dataset directory or Hub dataset id owner/name[@revision]. Default: $RH_DATASET,
        /// else the released dataset.
        #[arg(long, value_name = "DIR|owner/name")]
        dataset: Option<String>,
        /// Use a dataset whose build did not finish (its build.json records no file
        /// checksums, or files it records are missing); refused otherwise (exit 2).
        #[arg(long)]
        allow_incomplete: bool,
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
    /// Merge results files (`rh-score PREDS --results DIR`) into one leaderboard: one row
    /// per model run with coverage and headline metrics with their 95% intervals. Runs
    /// measured on different datasets, label rules, prompts or scoring configurations are
    /// refused (exit 2, naming the field, the two values and the two files).
    Leaderboard {
        /// Results files (DIR/<model>.json).
        #[arg(required = true, value_name = "FILE")]
        files: Vec<PathBuf>,
        /// Write the board as a one-page site into this directory (DIR/index.html).
        #[arg(long, value_name = "DIR")]
        html: Option<PathBuf>,
        /// Write the board as Markdown.
        #[arg(long, value_name = "FILE")]
        markdown: Option<PathBuf>,
        /// Print the merged board as JSON on stdout (instead of the table).
        #[arg(long)]
        json: bool,
    },
    /// Run a model over a dataset through the OpenAI-compatible chat API with the
    /// canonical prompt (configs/prompt.toml) and write preds.jsonl. Resumes: run it again
    /// with the same arguments after a crash, a kill or --max-cost and it does only what is
    /// missing.
    Predict(Box<PredictArgs>),
    /// Write a dataset's scenes as fine-tuning data: a Hugging Face dataset in TRL's
    /// conversational format (`datasets.load_dataset(OUT)`), the canonical prompt with the
    /// oracle's plan as the answer (sft) or paired with a plan the benchmark scores as
    /// wrong (preference). Rendered builds carry the observation frames; label-only builds
    /// give text-only examples. Streams the table: memory does not grow with its size.
    Export(Box<ExportArgs>),
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

#[derive(clap::Args, Debug)]
pub struct PredictArgs {
    /// Dataset directory (data/*.parquet + frames/) or Hub dataset id owner/name[@revision].
    /// Default: $RH_DATASET, else the released dataset.
    #[arg(long, value_name = "DIR|owner/name")]
    pub dataset: Option<String>,
    /// Use a dataset whose build did not finish (its build.json records no file
    /// checksums, or files it records are missing); refused otherwise (exit 2).
    #[arg(long)]
    pub allow_incomplete: bool,
    /// Model id as the server knows it (e.g. gpt-4o, Qwen/Qwen2.5-VL-7B-Instruct).
    #[arg(long)]
    pub model: String,
    /// Predictions file (JSON Lines), appended to and resumed.
    #[arg(long, value_name = "FILE", required_unless_present = "dry_run")]
    pub out: Option<PathBuf>,
    /// OpenAI-compatible endpoint, e.g. http://127.0.0.1:8000/v1 (default: $OPENAI_BASE_URL,
    /// else configs/predict.toml).
    #[arg(long, value_name = "URL")]
    pub base_url: Option<String>,
    /// Environment variable holding the API key (unset is fine for local servers).
    #[arg(long, value_name = "VAR", default_value = "OPENAI_API_KEY")]
    pub api_key_env: String,
    /// Which scenes: the balanced eval subset or every valid scene.
    #[arg(long, value_enum, default_value = "eval")]
    pub subset: rh_grade::dataset::Subset,
    /// Only the first N scenes of the subset (dataset order).
    #[arg(long, value_name = "N")]
    pub limit: Option<usize>,
    /// Most requests in flight (adaptive: halves on HTTP 429, grows back).
    #[arg(long, value_name = "N")]
    pub concurrency: Option<usize>,
    /// Sampling temperature (default: configs/predict.toml).
    #[arg(long)]
    pub temperature: Option<f64>,
    /// Most completion tokens per answer (default: configs/predict.toml).
    #[arg(long)]
    pub max_tokens: Option<u32>,
    /// Stop cleanly before the requests recorded in --out cost more than this (USD); run
    /// again with a higher value to resume.
    #[arg(long, value_name = "USD")]
    pub max_cost: Option<f64>,
    /// Price of input tokens, USD per million (overrides the price table).
    #[arg(long, value_name = "USD")]
    pub price_in: Option<f64>,
    /// Price of output tokens, USD per million (overrides the price table).
    #[arg(long, value_name = "USD")]
    pub price_out: Option<f64>,
    /// Ask again for the scenes whose line in --out is an `error` line (lost decisions);
    /// their old lines are removed.
    #[arg(long)]
    pub retry_errors: bool,
    /// Do not read or write the response cache.
    #[arg(long)]
    pub no_cache: bool,
    /// Response cache directory (default: $RH_LLM_CACHE, else ~/.cache/reacthuman/llm).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Index of this independent sample (for several samples at temperature > 0; part of
    /// the cache key).
    #[arg(long, default_value_t = 0)]
    pub sample_index: u32,
    /// Per-request timeout in seconds (default: configs/predict.toml).
    #[arg(long, value_name = "S")]
    pub timeout: Option<f64>,
    /// Retries of a transient failure (default: configs/predict.toml).
    #[arg(long, value_name = "N")]
    pub max_retries: Option<u32>,
    /// Runner configuration (client defaults, generation, prices); default: the embedded
    /// configs/predict.toml.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Prompt template; default: the embedded canonical configs/prompt.toml. A changed
    /// prompt must carry its own version.
    #[arg(long, value_name = "FILE")]
    pub prompt: Option<PathBuf>,
    /// Print the first scene's full request (images elided) and exit without sending it.
    #[arg(long)]
    pub dry_run: bool,
    /// Print the run summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// Dataset directory (data/*.parquet, and frames/ for images) or Hub dataset id
    /// owner/name[@revision]. Default: $RH_DATASET, else the released dataset.
    #[arg(long, value_name = "DIR|owner/name")]
    pub dataset: Option<String>,
    /// Use a dataset whose build did not finish (its build.json records no file
    /// checksums, or files it records are missing); refused otherwise (exit 2).
    #[arg(long)]
    pub allow_incomplete: bool,
    /// Output directory (new or empty): data/train-00000-of-00001.parquet, README.md,
    /// export.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// sft: `messages` (system, user, assistant); preference: `prompt`, `chosen`,
    /// `rejected` (DPO).
    #[arg(long, value_enum, default_value = "sft")]
    pub format: rh_runner::export::Format,
    /// Which valid scenes: train (outside the eval subset, so the benchmark's scenes stay
    /// unseen), eval (the subset) or all.
    #[arg(long, value_enum, default_value = "train")]
    pub split: rh_runner::export::Split,
    /// Text-only examples even when the dataset has frames.
    #[arg(long)]
    pub text_only: bool,
    /// Scoring configuration (body constants, thresholds) the oracle plans with.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}
