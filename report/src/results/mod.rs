//! Results files for leaderboards (`rh-score PREDS --results DIR`): one JSON file per
//! model run saying exactly what was measured — the dataset's identity, the prompt, the
//! action rule, the scoring configuration and the executor, coverage, every headline
//! metric with its 95% interval, the per family / speed band / ground-truth action /
//! adversarial rows and, with `--execute`, the outcomes. The schema is
//! `schemas/results.schema.json` (tested); `rh-score leaderboard` ([`crate::leaderboard`])
//! merges them. The numbers are the report's ([`crate::report::Report`]), copied, never
//! recomputed.

pub mod identity;

use crate::coverage::ModelCoverage;
use crate::error::InputError;
use crate::report::{ActionRuleSummary, ClassRecall, Interval, MetricsRow, ModelReport, Report};
use anyhow::Result;
pub use identity::{DatasetIdentity, PromptIdentity, ScoringIdentity};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The results format's name and version (`format`).
pub const FORMAT: &str = "rh-results/1";

/// A metric's value and its 95% interval (`null` when undefined).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    pub value: Option<f64>,
    pub ci: Interval,
}

/// The headline metrics of a run (the report's overall row and balanced accuracy).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Headline {
    /// Safe action accuracy over the expected scenes.
    pub saa: Estimate,
    /// Share of expected scenes whose plan broke no safety rule.
    pub safety: Estimate,
    /// Mean per-class recall (CATCH, DODGE, NO_ACTION).
    pub balanced_accuracy: Estimate,
    /// Action-intent agreement.
    pub aia: Estimate,
    /// Mean distance of the hands' end point from the impact point (m).
    pub d_end: Estimate,
    /// Mean closest approach of the hazard to the body (m, HDE).
    pub d_min: Estimate,
    /// Share of answered decisions that were NO_ACTION.
    pub freeze_rate: Estimate,
}

/// The executor a run's plans were executed with (`--execute`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExecutorIdentity {
    /// The executor's code version (`rh_contract::execution::EXECUTOR_VERSION`).
    pub version: String,
    /// `[execution] version` of the scoring configuration.
    pub config_version: String,
}

/// One model run's results file.
#[derive(Debug, Clone, Serialize)]
pub struct ResultsFile {
    pub format: String,
    pub tool: String,
    pub tool_version: String,
    pub model: String,
    /// The predictions file as given (informative).
    pub predictions: String,
    pub dataset: DatasetIdentity,
    pub prompt: PromptIdentity,
    pub action_rule: ActionRuleSummary,
    pub scoring: ScoringIdentity,
    /// `null` when the plans were not executed.
    pub executor: Option<ExecutorIdentity>,
    pub coverage: ModelCoverage,
    pub headline: Headline,
    pub recall: Vec<ClassRecall>,
    pub overall: MetricsRow,
    pub by_family: Vec<MetricsRow>,
    pub by_speed_band: Vec<MetricsRow>,
    pub by_gt_action: Vec<MetricsRow>,
    pub by_adversarial: Vec<MetricsRow>,
    /// Outcomes in physics (`--execute`), else `null`.
    pub execution: Option<crate::execution::report::ModelOutcomes>,
}

fn headline(m: &ModelReport) -> Headline {
    let o = &m.overall;
    let e = |value, ci| Estimate { value, ci };
    Headline {
        saa: e(o.saa, o.saa_ci),
        safety: e(o.safety, o.safety_ci),
        balanced_accuracy: e(m.balanced_accuracy, m.balanced_accuracy_ci),
        aia: e(o.aia, o.aia_ci),
        d_end: e(o.d_end, o.d_end_ci),
        d_min: e(o.d_min, o.d_min_ci),
        freeze_rate: e(o.freeze_rate, o.freeze_rate_ci),
    }
}

/// One results file per model of `report`.
pub fn results_files(
    report: &Report,
    dataset: &DatasetIdentity,
    scoring: &ScoringIdentity,
) -> Vec<ResultsFile> {
    let executor = report.execution.as_ref().map(|e| ExecutorIdentity {
        version: rh_contract::execution::EXECUTOR_VERSION.to_string(),
        config_version: e.config.version.clone(),
    });
    report
        .models
        .iter()
        .map(|m| ResultsFile {
            format: FORMAT.to_string(),
            tool: report.tool.clone(),
            tool_version: report.version.clone(),
            model: m.model.clone(),
            predictions: report.input.file.clone(),
            dataset: dataset.clone(),
            prompt: PromptIdentity::of(&m.prompt_version),
            action_rule: report.action_rule.clone(),
            scoring: scoring.clone(),
            executor: executor.clone(),
            coverage: m.coverage.clone(),
            headline: headline(m),
            recall: m.recall.clone(),
            overall: m.overall.clone(),
            by_family: m.by_family.clone(),
            by_speed_band: m.by_speed_band.clone(),
            by_gt_action: m.by_gt_action.clone(),
            by_adversarial: m.by_adversarial.clone(),
            execution: report
                .execution
                .as_ref()
                .and_then(|e| e.models.iter().find(|o| o.model == m.model).cloned()),
        })
        .collect()
}

/// A model name as a file name: characters other than letters, digits, `-`, `_` and `.`
/// become `_` (`Qwen/Qwen2.5-VL` → `Qwen_Qwen2.5-VL`); a leading `.` too.
pub fn file_stem(model: &str) -> String {
    let mut s: String = model
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.starts_with('.') || s.is_empty() {
        s.insert(0, '_');
    }
    s
}

/// Refuses (exit 2) models whose results files would clash: names that map to one file
/// name (`a/b` and `a_b`), compared without case too (one file on a case-insensitive
/// file system). Checked before any output is written.
pub fn check_file_names<'a>(models: impl IntoIterator<Item = &'a str>) -> Result<()> {
    let mut seen: std::collections::BTreeMap<String, &str> = Default::default();
    for m in models {
        let name = format!("{}.json", file_stem(m));
        if let Some(other) = seen.insert(name.to_lowercase(), m) {
            return Err(InputError(format!(
                "--results: models {other:?} and {m:?} would both be written to {name}; rename one (nothing was written)"
            ))
            .into());
        }
    }
    Ok(())
}

/// Writes each file as `DIR/<model>.json` (atomically); returns the paths. Two models
/// whose names map to the same file name are an input error, found before any file is
/// written ([`check_file_names`]).
pub fn write_results(dir: &Path, files: &[ResultsFile]) -> Result<Vec<PathBuf>> {
    check_file_names(files.iter().map(|f| f.model.as_str()))?;
    std::fs::create_dir_all(dir)
        .map_err(|e| rh_contract::fsio::CannotWrite::new("the results directory", dir, e))?;
    let mut paths: Vec<PathBuf> = Vec::new();
    for f in files {
        let path = dir.join(format!("{}.json", file_stem(&f.model)));
        let text = serde_json::to_string_pretty(f)? + "\n";
        rh_contract::fsio::write_file(&path, "the results file", text.as_bytes())?;
        paths.push(path);
    }
    Ok(paths)
}
