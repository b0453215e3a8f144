//! Configuration of `rh-score predict`: the canonical prompt (`configs/prompt.toml`, part
//! of the benchmark's definition) and the runner's settings (`configs/predict.toml`:
//! client defaults, generation parameters, the price table). Both are embedded; `--prompt`
//! and `--config` replace them.

use crate::error::InputError;
use anyhow::Result;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

pub const PROMPT_TOML: &str = include_str!("../../../configs/prompt.toml");
pub const PREDICT_TOML: &str = include_str!("../../../configs/predict.toml");

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PromptConfig {
    pub version: String,
    pub images: ImageOptions,
    pub text: PromptText,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageOptions {
    pub cameras: Vec<String>,
    pub times: Vec<f64>,
    pub max_side: u32,
    pub jpeg_quality: u8,
    /// "4:2:0" or "4:4:4".
    pub chroma_subsampling: String,
    pub detail: String,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PromptText {
    pub system: String,
    pub user_intro: String,
    /// The scene's head camera calibration (prompt v5; `predict::camera::camera_text`).
    pub camera: String,
    pub frame_label: String,
    pub user_outro: String,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PredictConfig {
    pub client: rh_llm::ClientConfig,
    pub generation: Generation,
    /// `[run]` (the defaults when a config file has none).
    #[serde(default)]
    pub run: RunConfig,
    pub prices: BTreeMap<String, Price>,
}

/// `[run]`: when a run gives up, and how often it reports progress to a log.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Stop with exit 2 when the first this-many requests all fail (a dead endpoint).
    pub abort_after_failures: usize,
    /// Seconds between progress lines when stderr is not a terminal.
    pub progress_every_s: f64,
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig {
            abort_after_failures: 8,
            progress_every_s: 10.0,
        }
    }
}

#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Generation {
    pub temperature: f64,
    pub max_tokens: u32,
}

/// USD per million tokens.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Price {
    pub input: f64,
    pub output: f64,
}

fn parse<T: serde::de::DeserializeOwned>(text: &str, origin: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| InputError(format!("{origin}: {e}")).into())
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path)
        .map_err(|e| InputError(format!("cannot read {}: {e}", path.display())).into())
}

impl PromptConfig {
    pub fn load(path: Option<&Path>) -> Result<PromptConfig> {
        let cfg: PromptConfig = match path {
            Some(p) => parse(&read(p)?, &p.display().to_string())?,
            None => parse(PROMPT_TOML, "configs/prompt.toml (embedded)")?,
        };
        let origin = path.map_or("configs/prompt.toml".into(), |p| p.display().to_string());
        let bad = |m: String| -> anyhow::Error { InputError(format!("{origin}: {m}")).into() };
        if cfg.images.cameras.is_empty() || cfg.images.times.is_empty() {
            return Err(bad("[images] cameras and times must not be empty".into()));
        }
        if !(1..=100).contains(&cfg.images.jpeg_quality) {
            return Err(bad("[images] jpeg_quality must be 1-100".into()));
        }
        if subsampling(&cfg.images.chroma_subsampling).is_none() {
            return Err(bad(
                "[images] chroma_subsampling must be \"4:2:0\" or \"4:4:4\"".into(),
            ));
        }
        if !(16..=8192).contains(&cfg.images.max_side) {
            return Err(bad("[images] max_side must be 16-8192".into()));
        }
        if !["low", "high", "auto"].contains(&cfg.images.detail.as_str()) {
            return Err(bad(
                "[images] detail must be \"low\", \"high\" or \"auto\"".into()
            ));
        }
        if cfg.version.trim().is_empty() {
            return Err(bad("version must not be empty".into()));
        }
        Ok(cfg)
    }
}

/// The bounds of the client's numbers (docs/reliability.md, "Bounds"), from the file or
/// the flags that override it (`origin` says which): checked before any request.
pub fn check_client(c: &rh_llm::ClientConfig, origin: &str) -> Result<()> {
    let bad = |m: String| -> anyhow::Error { InputError(format!("{origin} {m}")).into() };
    if !(1..=MAX_CONCURRENCY).contains(&c.concurrency) {
        return Err(bad(format!(
            "concurrency {}: must be 1-{MAX_CONCURRENCY}",
            c.concurrency
        )));
    }
    for (name, v) in [
        ("timeout_s", c.timeout_s),
        ("backoff_base_s", c.backoff_base_s),
        ("backoff_max_s", c.backoff_max_s),
        ("max_retry_after_s", c.max_retry_after_s),
    ] {
        if !(v.is_finite() && v >= 0.0 && v <= 86_400.0) || (name == "timeout_s" && v <= 0.0) {
            return Err(bad(format!(
                "{name} {v}: must be a number of seconds in (0, 86400]"
            )));
        }
    }
    if c.max_retries > 100 || c.max_rate_limit_retries > 1000 {
        return Err(bad(format!(
            "max_retries {} / max_rate_limit_retries {}: at most 100 / 1000",
            c.max_retries, c.max_rate_limit_retries
        )));
    }
    Ok(())
}

/// The bounds of the generation settings: temperature in [0, 2] (the OpenAI API's range),
/// max_tokens 1-1,000,000.
pub fn check_generation(g: &Generation, origin: &str) -> Result<()> {
    if !(g.temperature.is_finite() && (0.0..=2.0).contains(&g.temperature)) {
        return Err(InputError(format!(
            "{origin} temperature {}: must be within [0, 2]",
            g.temperature
        ))
        .into());
    }
    if !(1..=1_000_000).contains(&g.max_tokens) {
        return Err(InputError(format!(
            "{origin} max_tokens {}: must be 1-1000000",
            g.max_tokens
        ))
        .into());
    }
    Ok(())
}

/// The most requests in flight (`--concurrency`, `[client] concurrency`).
pub const MAX_CONCURRENCY: usize = 1024;

impl PredictConfig {
    pub fn load(path: Option<&Path>) -> Result<PredictConfig> {
        let cfg: PredictConfig = match path {
            Some(p) => parse(&read(p)?, &p.display().to_string())?,
            None => parse(PREDICT_TOML, "configs/predict.toml (embedded)")?,
        };
        if cfg.run.abort_after_failures == 0 || !(cfg.run.progress_every_s > 0.0) {
            return Err(InputError(
                "predict config: [run] abort_after_failures and progress_every_s must be positive"
                    .into(),
            )
            .into());
        }
        if cfg.run.abort_after_failures > 100_000 || cfg.run.progress_every_s > 86_400.0 {
            return Err(InputError(
                "predict config: [run] abort_after_failures must be at most 100000 and progress_every_s at most 86400".into(),
            )
            .into());
        }
        let origin = path.map_or("configs/predict.toml".into(), |p| p.display().to_string());
        check_client(&cfg.client, &format!("{origin}: [client]"))?;
        check_generation(&cfg.generation, &format!("{origin}: [generation]"))?;
        Ok(cfg)
    }

    /// The price of `model`: an exact entry, else the longest entry that prefixes it
    /// (so `gpt-4o-2024-08-06` costs as `gpt-4o`), else free.
    pub fn price(&self, model: &str) -> Option<Price> {
        if let Some(p) = self.prices.get(model) {
            return Some(*p);
        }
        self.prices
            .iter()
            .filter(|(k, _)| model.starts_with(k.as_str()))
            .max_by_key(|(k, _)| k.len())
            .map(|(_, p)| *p)
    }
}

impl Price {
    pub fn cost(&self, usage: rh_llm::Usage) -> f64 {
        (usage.prompt_tokens as f64 * self.input + usage.completion_tokens as f64 * self.output)
            / 1e6
    }
}

/// Chroma subsampling of the prompt's JPEGs (`[images] chroma_subsampling`).
pub fn subsampling(name: &str) -> Option<turbojpeg::Subsamp> {
    match name {
        "4:2:0" => Some(turbojpeg::Subsamp::Sub2x2),
        "4:4:4" => Some(turbojpeg::Subsamp::None),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_configs_load_and_prices_match_by_prefix() {
        let p = PromptConfig::load(None).unwrap();
        assert_eq!(p.images.times, vec![0.0, 0.15, 0.30, 0.45, 0.60]);
        assert_eq!(p.images.cameras, vec!["ego".to_string()]);
        let c = PredictConfig::load(None).unwrap();
        assert_eq!(c.price("gpt-4o-mini").unwrap().input, 0.15);
        assert_eq!(c.price("gpt-4o-2024-08-06").unwrap().input, 2.50);
        assert!(c.price("llama3.2-vision").is_none());
        let cost = c.price("gpt-4o").unwrap().cost(rh_llm::Usage {
            prompt_tokens: 1_000_000,
            completion_tokens: 100_000,
        });
        assert!((cost - 3.5).abs() < 1e-12);
    }
}
