//! What a results file says was measured: the dataset (its build manifest `build.json`,
//! read by `rh_dataset::manifest`, and hashes of the expected scenes and their ground
//! truth), the prompt, and the scoring configuration.

use crate::config::Config;
use crate::coverage::Expected;
use crate::dataset::Dataset;
use crate::error::InputError;
use anyhow::Result;
use rh_contract::digest::sha256_hex;
use rh_dataset::manifest::Manifest;
use serde::{Deserialize, Serialize};

/// The dataset a run was scored on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetIdentity {
    /// The dataset directory as scored (informative; not part of the identity).
    pub dir: String,
    /// SHA-256 of the build's `build.json` without its file sums, as a whole (unsharded)
    /// build: seed, scene count, families, render flag, configuration and catalog hashes
    /// and pipeline version (`null`: the dataset has no `build.json`).
    pub build_fingerprint: Option<String>,
    pub seed: Option<u64>,
    /// Scenes of the whole build (`build.json`'s `n`).
    pub n: Option<u64>,
    pub rh_pipeline_version: Option<String>,
    pub config_sha256: Option<String>,
    pub catalog_sha256: Option<String>,
    /// The label rule's version (`labels.rule_version` of the build configuration).
    pub label_rule: Option<String>,
    /// Valid scenes of the dataset.
    pub scenes: u64,
    /// "eval" (the dataset's balanced subset) or "all" (every valid scene).
    pub subset: String,
    pub expected_scenes: u64,
    /// SHA-256 of the expected scene ids, sorted, one a line.
    pub subset_sha256: String,
    /// SHA-256 of the expected scenes' ground truth, sorted by id, one `id<TAB>action` a
    /// line.
    pub ground_truth_sha256: String,
}

/// The prompt the predictions were made with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PromptIdentity {
    /// The lines' `prompt_version` (`rh-score predict` records it); `null` when no line
    /// carries one (baselines use no prompt); versions joined by `+` when lines mix them.
    pub version: Option<String>,
    /// SHA-256 of the canonical prompt template (`configs/prompt.toml` as embedded in
    /// this rh-score) when `version` is its version; `null` otherwise.
    pub template_sha256: Option<String>,
}

/// How the run was scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScoringIdentity {
    /// SHA-256 of the scoring configuration (`configs/scoring.toml` or `--config`) as JSON.
    pub config_sha256: String,
    /// Metrics over the answered scenes only (`--answered-only`).
    pub answered_only: bool,
}

impl DatasetIdentity {
    /// The identity of `ds` with the expected scenes `expected`; `build.json` is read
    /// when the dataset has one (a damaged one is an input error naming it).
    pub fn of(ds: &Dataset, expected: &Expected) -> Result<DatasetIdentity> {
        let manifest = Manifest::read(&ds.dir).map_err(|e| InputError(e.into()))?;
        let mut rows: Vec<(&str, &str)> = ds
            .scenes
            .iter()
            .zip(&expected.mask)
            .filter(|(_, &e)| e)
            .map(|(s, _)| (s.scene_id.as_str(), s.gt_action.as_str()))
            .collect();
        rows.sort_unstable();
        let ids: String = rows.iter().map(|(id, _)| format!("{id}\n")).collect();
        let truth: String = rows.iter().map(|(id, a)| format!("{id}\t{a}\n")).collect();
        let m = manifest.as_ref();
        Ok(DatasetIdentity {
            dir: ds.dir.display().to_string(),
            build_fingerprint: m.map(|m| sha256_hex(m.whole().to_json().as_bytes())),
            seed: m.map(|m| m.seed),
            n: m.map(|m| m.n),
            rh_pipeline_version: m.map(|m| m.rh_pipeline_version.clone()),
            config_sha256: m.map(|m| m.config_sha256.clone()),
            catalog_sha256: m.map(|m| m.catalog_sha256.clone()),
            label_rule: m.and_then(|m| m.label_rule().map(str::to_string)),
            scenes: ds.valid_scenes() as u64,
            subset: expected.subset.to_string(),
            expected_scenes: expected.count(),
            subset_sha256: sha256_hex(ids.as_bytes()),
            ground_truth_sha256: sha256_hex(truth.as_bytes()),
        })
    }
}

impl PromptIdentity {
    /// From a model's prompt versions as the report gives them (`-`: none).
    pub fn of(report_version: &str) -> PromptIdentity {
        let version = (report_version != "-").then(|| report_version.to_string());
        PromptIdentity {
            template_sha256: version.as_deref().and_then(template_sha256),
            version,
        }
    }
}

/// SHA-256 of the embedded canonical prompt when `version` is its version.
fn template_sha256(version: &str) -> Option<String> {
    let cfg = rh_prompt::config::PromptConfig::load(None).ok()?;
    (cfg.version == version).then(|| sha256_hex(rh_prompt::config::PROMPT_TOML.as_bytes()))
}

impl ScoringIdentity {
    pub fn of(cfg: &Config, answered_only: bool) -> ScoringIdentity {
        let json = serde_json::to_string(cfg).expect("the scoring configuration serializes");
        ScoringIdentity {
            config_sha256: sha256_hex(json.as_bytes()),
            answered_only,
        }
    }
}
