//! `rh-score`, the ReactHuman offline scorer: the command line ([`cli`]) over the grading
//! core [`rh_grade`] (predictions, plans, the action rule, metrics, intervals, the report
//! model and its text tables, baselines, the one scoring sequence `rh_grade::api::score`),
//! and what links more than the core: `--execute` in physics and its videos
//! ([`execution`], features `execute` and `videos`), the model runner and the training
//! export ([`predict`], [`export`], feature `predict`), figures, the site, leaderboards
//! and results files, and Hub datasets ([`hub_dataset`]). The core's modules are
//! re-exported under their own names, so `rh_score::score`, `rh_score::report` … are the
//! core's.

#[cfg(any(test, feature = "synthetic"))]
pub use rh_grade::synthetic;
pub use rh_grade::{
    action_rule, aggregate, aia, analyses, api, baseline, compare, config, coverage,
    dataset_diagnosis, error, explain, fast_map, intervals, metrics, metrics_row, oracle, plan,
    plan_json, preds, refusal, report, safety_rule, score, stats, tables, text_table,
};

/// The core's dataset reader ([`rh_grade::dataset`]) and [`resolve_dir`], which also
/// fetches Hub datasets.
pub mod dataset {
    pub use crate::hub_dataset::resolve_dir;
    pub use rh_grade::dataset::*;
}

pub mod cli;
pub mod execute_scored;
pub mod execution;
#[cfg(feature = "predict")]
pub mod export;
pub mod figures;
pub mod html;
pub mod hub_dataset;
pub mod leaderboard;
#[cfg(feature = "predict")]
pub mod predict;
pub mod progress;
pub mod results;

pub use rh_contract::Action;
pub use rh_grade::{Config, Dataset, InputError, Report, SafetyRule, Scoring};
