//! Configuration of `rh-score predict`: the runner's settings (`configs/predict.toml`:
//! client defaults, generation parameters, the price table; embedded, `--config` replaces
//! it) and, re-exported, the canonical prompt's (`rh_prompt::config`).

use anyhow::Result;
use rh_grade::error::InputError;
use rh_prompt::config::{parse, read};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

pub use rh_prompt::config::{
    check_generation, subsampling, Generation, ImageOptions, PromptConfig, PromptText,
    PREDICT_TOML, PROMPT_TOML,
};

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

/// USD per million tokens.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Price {
    pub input: f64,
    pub output: f64,
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
