//! `rh-pipeline`'s arguments (clap): the global options, one variant per command, and
//! the parsing of `--shard`.

use super::failure::{input, Failure};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "rh-pipeline",
    version,
    about = "Builds the ReactHuman dataset: bit-for-bit reproducible physics scenes with exact ground truth",
    after_help = "Exit status: 0 success, 2 bad input or usage, 3 an output that cannot be written (full disk, read-only directory, /dev/full; the file is named), 1 internal failure, 130 interrupted."
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
    Build(BuildArgs),
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
    /// Print a dataset's fingerprint: SHA-256 of its scene table, evaluation subset and
    /// specs, the rendered media left out (the same on every render adapter), as the
    /// `[fingerprint]` table of a release file. For a build of the release
    /// (configs/release.toml, or $RH_RELEASE_CONFIG) also checks it against the release's
    /// pins: exit 2 naming what differs.
    Fingerprint {
        /// Dataset directory built by `rh-pipeline build`.
        dir: PathBuf,
        /// Print the fingerprint and the check as JSON on stdout.
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
        /// The camera whose frames are shown: ego (what the model sees), closeup or overhead.
        #[arg(long, value_name = "CAM", default_value = "ego")]
        camera: String,
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
        /// Scenes per family in the evaluation subset.
        #[arg(long, default_value_t = 18)]
        per_family: usize,
        /// The full build whose scene groups the subsets are chosen from (scenes; a
        /// family gets one group in 17 of them).
        #[arg(long, default_value_t = 680)]
        pool: u64,
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

// The arguments of `build` (no doc comment: the command's help is the variant's).
#[derive(clap::Args, Debug)]
pub struct BuildArgs {
    /// Number of scenes (four speed bands per scene group). With --descriptions it
    /// defaults to four per description (group g takes description g mod D).
    #[arg(long, required_unless_present_any = ["descriptions", "release"])]
    pub n: Option<u64>,
    /// Build the benchmark's canonical release (configs/release.toml, or --release-config):
    /// its seed, scene count, families and render flags, after checking that the
    /// configuration, catalog, label rule and prompt are the ones it pins (exit 2 naming
    /// each that differs); the finished build's fingerprint is then checked against the
    /// release's (exit 1 if it differs). With --no-render: its label-only part (the same
    /// fingerprint; not the release to upload).
    #[arg(long, conflicts_with_all = ["n", "seed", "families", "descriptions", "masks"])]
    pub release: bool,
    /// The release file of --release (default: $RH_RELEASE_CONFIG, else the embedded
    /// configs/release.toml).
    #[arg(long, value_name = "FILE", requires = "release")]
    pub release_config: Option<PathBuf>,
    /// Plan the scene groups from these descriptions (a text file, one a line; blank
    /// lines and lines starting with # are skipped) instead of round-robin families.
    #[arg(long, value_name = "FILE")]
    pub descriptions: Option<PathBuf>,
    /// Which planner reads the descriptions.
    #[arg(long, value_enum, default_value = "lexicon", requires = "descriptions")]
    pub planner: PlannerKind,
    #[command(flatten)]
    pub llm: LlmArgs,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Build seed; defaults to the configuration's build.seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Comma-separated families; defaults to the configuration's build.families.
    #[arg(long, value_delimiter = ',')]
    pub families: Option<Vec<String>>,
    /// Skip rendering (videos and frames); labels, specs and Parquet only.
    #[arg(long)]
    pub no_render: bool,
    /// Also write each observation frame's segmentation and depth: 16-bit PNGs of
    /// instance ids (`masks/<scene_id>/<cam>_t….png`) and of the distance from the
    /// camera in mm (`depth/…`), named by the `<cam>_mask_paths` / `<cam>_depth_paths`
    /// columns.
    #[arg(long, conflicts_with = "no_render")]
    pub masks: bool,
    /// Build only shard i of N (scene groups g with g mod N = i), e.g. 0/4.
    #[arg(long, value_name = "i/N")]
    pub shard: Option<String>,
    /// Worker threads (default: all cores). Never changes the output.
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Print the build summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// When stderr is not a terminal (a log file, CI): seconds between progress lines
    /// (scenes done of total, rate, ETA). A terminal gets a progress bar instead.
    #[arg(long, value_name = "SECONDS", default_value_t = rh_contract::progress::LOG_EVERY_S)]
    pub progress_every: f64,
}

/// `--shard i/N` as (i, N), 0 ≤ i < N.
pub fn parse_shard(text: &str) -> Result<(u64, u64), Failure> {
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
