//! `rh-score leaderboard results/*.json`: merges results files ([`crate::results`]) into
//! one board — one row per model run with its coverage and headline metrics with their
//! intervals — after checking that every run measured the same thing: the same dataset
//! (build fingerprint, seed, label rule, expected scenes and their ground truth), the same
//! prompt (runs without one, such as baselines, fit any), the same action rule and scoring
//! configuration, and the same executor where both executed. A difference is an input
//! error (exit 2) naming the field, the two values and the two files. Rendering is
//! [`render`].

pub mod render;

use crate::coverage::ModelCoverage;
use crate::error::InputError;
use crate::results::{
    DatasetIdentity, ExecutorIdentity, Headline, PromptIdentity, ScoringIdentity,
};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The action rule's part of a results file the board compares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RuleVersion {
    pub version: String,
}

/// What the board reads of one results file (other fields are left alone).
#[derive(Debug, Clone, Deserialize)]
pub struct Entry {
    pub format: String,
    pub tool_version: String,
    pub model: String,
    pub dataset: DatasetIdentity,
    pub prompt: PromptIdentity,
    pub action_rule: RuleVersion,
    pub scoring: ScoringIdentity,
    pub executor: Option<ExecutorIdentity>,
    pub coverage: ModelCoverage,
    pub headline: Headline,
}

/// One row of the board.
#[derive(Debug, Clone, Serialize)]
pub struct BoardRow {
    pub model: String,
    pub file: String,
    pub prompt_version: Option<String>,
    pub executed: bool,
    pub coverage: ModelCoverage,
    pub headline: Headline,
}

/// The merged board: what every run measured, and the rows (best SAA first).
#[derive(Debug, Clone, Serialize)]
pub struct Board {
    pub dataset: DatasetIdentity,
    pub action_rule: RuleVersion,
    pub scoring: ScoringIdentity,
    /// The prompt of the runs that used one (`null`: none did).
    pub prompt: Option<PromptIdentity>,
    pub rows: Vec<BoardRow>,
}

/// Reads one results file (an unreadable or malformed one is an input error naming it).
pub fn read_entry(path: &Path) -> Result<Entry> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError(format!("cannot read {}: {e}", path.display())))?;
    let entry: Entry = serde_json::from_str(&text).map_err(|e| {
        InputError(format!(
            "{} is not an rh-score results file (rh-score PREDS --results DIR writes them): {e}",
            path.display()
        ))
    })?;
    if entry.format != crate::results::FORMAT {
        return Err(InputError(format!(
            "{}: format {:?}, this rh-score reads {:?}",
            path.display(),
            entry.format,
            crate::results::FORMAT
        ))
        .into());
    }
    Ok(entry)
}

fn text<T: Serialize>(v: &T) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(v) => v.to_string(),
        Err(_) => "?".into(),
    }
}

/// The fields in which `b` was measured differently from `a`: `(field, a's value, b's)`.
/// Dataset fields compare exactly (a missing `build.json` included); a prompt or executor
/// field only when both runs have one.
pub fn differences(a: &Entry, b: &Entry) -> Vec<(String, String, String)> {
    let mut d = Vec::new();
    let mut cmp = |field: &str, x: String, y: String| {
        if x != y {
            d.push((field.to_string(), x, y));
        }
    };
    let (p, q) = (&a.dataset, &b.dataset);
    cmp("dataset.seed", text(&p.seed), text(&q.seed));
    cmp("dataset.n", text(&p.n), text(&q.n));
    cmp(
        "dataset.label_rule",
        text(&p.label_rule),
        text(&q.label_rule),
    );
    cmp(
        "dataset.build_fingerprint",
        text(&p.build_fingerprint),
        text(&q.build_fingerprint),
    );
    cmp("dataset.subset", p.subset.clone(), q.subset.clone());
    cmp(
        "dataset.subset_sha256",
        p.subset_sha256.clone(),
        q.subset_sha256.clone(),
    );
    cmp(
        "dataset.ground_truth_sha256",
        p.ground_truth_sha256.clone(),
        q.ground_truth_sha256.clone(),
    );
    let mut both = |field: &str, x: &Option<String>, y: &Option<String>| {
        if let (Some(x), Some(y)) = (x, y) {
            cmp(field, x.clone(), y.clone());
        }
    };
    both("prompt.version", &a.prompt.version, &b.prompt.version);
    both(
        "prompt.template_sha256",
        &a.prompt.template_sha256,
        &b.prompt.template_sha256,
    );
    if let (Some(x), Some(y)) = (&a.executor, &b.executor) {
        cmp("executor.version", x.version.clone(), y.version.clone());
        cmp(
            "executor.config_version",
            x.config_version.clone(),
            y.config_version.clone(),
        );
    }
    cmp(
        "action_rule.version",
        a.action_rule.version.clone(),
        b.action_rule.version.clone(),
    );
    cmp(
        "scoring.config_sha256",
        a.scoring.config_sha256.clone(),
        b.scoring.config_sha256.clone(),
    );
    cmp(
        "scoring.answered_only",
        a.scoring.answered_only.to_string(),
        b.scoring.answered_only.to_string(),
    );
    d
}

/// Reads the files and merges them into one board; runs measured differently, or two
/// runs of one model name, are an input error naming the files.
pub fn merge(paths: &[PathBuf]) -> Result<Board> {
    if paths.is_empty() {
        return Err(InputError("leaderboard: give at least one results file".into()).into());
    }
    let entries: Vec<Entry> = paths.iter().map(|p| read_entry(p)).collect::<Result<_>>()?;
    let (first, first_path) = (&entries[0], &paths[0]);
    for (e, p) in entries.iter().zip(paths).skip(1) {
        let diff = differences(first, e);
        if !diff.is_empty() {
            let list: Vec<String> = diff
                .iter()
                .map(|(f, x, y)| {
                    format!(
                        "{f}: {x} ({}) vs {y} ({})",
                        first_path.display(),
                        p.display()
                    )
                })
                .collect();
            return Err(InputError(format!(
                "leaderboard: {} and {} were not measured on the same thing, so their numbers are not comparable:\n  {}",
                first_path.display(),
                p.display(),
                list.join("\n  ")
            ))
            .into());
        }
    }
    for (i, e) in entries.iter().enumerate() {
        if let Some(j) = entries[..i].iter().position(|o| o.model == e.model) {
            return Err(InputError(format!(
                "leaderboard: model {:?} is in both {} and {}; give one run per model",
                e.model,
                paths[j].display(),
                paths[i].display()
            ))
            .into());
        }
    }
    let mut rows: Vec<BoardRow> = entries
        .iter()
        .zip(paths)
        .map(|(e, p)| BoardRow {
            model: e.model.clone(),
            file: p.display().to_string(),
            prompt_version: e.prompt.version.clone(),
            executed: e.executor.is_some(),
            coverage: e.coverage.clone(),
            headline: e.headline.clone(),
        })
        .collect();
    let key = |r: &BoardRow| r.headline.saa.value.unwrap_or(-1.0);
    rows.sort_by(|a, b| {
        key(b)
            .total_cmp(&key(a))
            .then_with(|| a.model.cmp(&b.model))
    });
    Ok(Board {
        dataset: first.dataset.clone(),
        action_rule: first.action_rule.clone(),
        scoring: first.scoring.clone(),
        prompt: entries
            .iter()
            .find(|e| e.prompt.version.is_some())
            .map(|e| e.prompt.clone()),
        rows,
    })
}
