//! The canonical prompt's configuration (`configs/prompt.toml`, part of the benchmark's
//! definition: cameras, times, image encoding, texts; `--prompt` replaces it) and the
//! canonical request's generation parameters (`[generation]` of `configs/predict.toml`).

use anyhow::Result;
use rh_grade::error::InputError;
use serde::Deserialize;
use std::path::Path;

pub const PROMPT_TOML: &str = include_str!("../../configs/prompt.toml");
/// `rh-score predict`'s settings (the runner's `PredictConfig`); its `[generation]` is the
/// canonical request's ([`canonical_generation`]).
pub const PREDICT_TOML: &str = include_str!("../../configs/predict.toml");

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

#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Generation {
    pub temperature: f64,
    pub max_tokens: u32,
}

pub fn parse<T: serde::de::DeserializeOwned>(text: &str, origin: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| InputError(format!("{origin}: {e}")).into())
}

pub fn read(path: &Path) -> Result<String> {
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

/// The generation parameters of the canonical request: `[generation]` of the embedded
/// `configs/predict.toml` (the runner reads the whole file, `PredictConfig`).
pub fn canonical_generation() -> Result<Generation> {
    #[derive(Deserialize)]
    struct Only {
        generation: Generation,
    }
    let only: Only = parse(PREDICT_TOML, "configs/predict.toml (embedded)")?;
    check_generation(&only.generation, "configs/predict.toml: [generation]")?;
    Ok(only.generation)
}

/// Chroma subsampling of the prompt's JPEGs (`[images] chroma_subsampling`).
pub fn subsampling(name: &str) -> Option<turbojpeg::Subsamp> {
    match name {
        "4:2:0" => Some(turbojpeg::Subsamp::Sub2x2),
        "4:4:4" => Some(turbojpeg::Subsamp::None),
        _ => None,
    }
}
