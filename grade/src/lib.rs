//! ReactHuman's grading core (`rh-grade`, under the `rh-score` binary): reads model
//! predictions (`preds.jsonl`), derives each plan's action with the versioned action rule,
//! scores the five metrics of specification §11 against a dataset's ground truth, aggregates them,
//! and reproduces the paper's analyses; [`api::score`] is the one scoring sequence. No
//! simulator, renderer, LLM client or network: those are rh-execute's, rh-runner's and
//! rh-locate's, the figures and the site rh-report's.
//!
//! Pipeline of one run: [`dataset::Dataset::load`] reads `DIR/data/*.parquet` (columns
//! by name; a missing or mistyped column is an input error naming file and column) →
//! [`score::Scoring::score_path`] streams `preds.jsonl` line by line (capped length), parses
//! batches in parallel with rayon ([`preds::process_line`]: lenient plan extraction in
//! [`plan`], action rule and world-frame kinematics in [`action_rule`], metrics in [`metrics`],
//! AIA in [`aia`]) and folds results in file order into per-model accumulators
//! ([`aggregate`]) → [`report::Report::build`] computes breakdowns and the paper's analyses →
//! [`tables`] (terminal, Markdown, CSV), `serde_json` (JSON) and rh-score's figures (SVG + PNG).
//!
//! Decisions recorded here and printed by `rh-score --explain` ([`explain`]):
//! * Absurd numbers (NaN/inf, |speed| > 10 m/s, |yaw rate| > 20 rad/s, durations or
//!   keyframe times outside [0, 30] s, |hand coordinate| > 10 m) make the plan
//!   unparseable (R1), counted as `absurd_number`; nothing is clamped.
//! * Coverage: metrics over the expected scenes (eval subset, or all), an unanswered scene
//!   counting as failed ([`coverage`]); 95% intervals ([`stats`]); `--compare` ([`compare`]).
//! * Duplicate (scene, model) lines: the first wins; an `error` line followed by a scored
//!   line for the same pair is a retry and is replaced.
//! * Scenes with `valid = false` are not scored (`invalid_scene` warnings); baselines skip
//!   them.
//! * Memory is bounded by scenes × models (one 12-byte record per pair for the cross-model
//!   analyses), never by the size of the predictions file.
//! * Figures: plotters with the SVG and bitmap backends; text is drawn with `ab_glyph`
//!   from the Hack font embedded via the `epaint_default_fonts` crate, so PNGs need no
//!   system fonts or fontconfig.
//! * Thresholds live in `configs/scoring.toml`, embedded as the default; `--config`
//!   replaces it.

pub mod action_rule;
pub mod aggregate;
pub mod aia;
pub mod analyses;
pub mod api;
pub mod baseline;
pub mod compare;
pub mod config;
pub mod coverage;
pub mod dataset;
pub mod dataset_diagnosis;
pub mod error;
pub mod execution;
pub mod explain;
pub mod fast_map;
pub mod intervals;
pub mod metrics;
pub mod metrics_row;
pub mod oracle;
pub mod plan;
pub mod plan_json;
pub mod preds;
pub mod refusal;
pub mod report;
pub mod safety_rule;
pub mod score;
pub mod stats;
#[cfg(any(test, feature = "synthetic"))]
pub mod synthetic;
pub mod tables;
pub mod text_table;

pub use config::Config;
pub use dataset::Dataset;
pub use error::InputError;
pub use report::Report;
pub use rh_contract::Action;
pub use safety_rule::SafetyRule;
pub use score::Scoring;
