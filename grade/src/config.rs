//! Scoring configuration: thresholds of the action rule, body constants, sanity limits,
//! analysis parameters and the AIA vocabularies. The default is `configs/scoring.toml`,
//! embedded at compile time; `--config FILE` replaces it.

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The embedded default configuration (`configs/scoring.toml`).
pub const DEFAULT_CONFIG_TOML: &str = include_str!("../../configs/scoring.toml");

/// The longest prediction line any configuration may allow (`sanity.max_line_bytes`).
pub const MAX_LINE_BYTES: usize = 256 << 20;

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    pub action_rule: ActionRuleConfig,
    pub body: BodyConfig,
    pub sanity: SanityConfig,
    pub analyses: AnalysesConfig,
    pub aia: AiaConfig,
    /// `[execution]`: the physics executor's limits and outcome thresholds (`--execute`);
    /// the embedded default's when a config file has none.
    #[serde(default = "rh_contract::execution::ExecConfig::embedded_default")]
    pub execution: rh_contract::execution::ExecConfig,
    /// `[execution_video]`: how `--execute-videos` draws the executions (the embedded
    /// default's when a config file has none).
    #[serde(default = "ExecVideoConfig::embedded_default")]
    pub execution_video: ExecVideoConfig,
    /// `[statistics]`: bootstrap resamples and seed of the report's intervals (the
    /// defaults when a config file has none).
    #[serde(default)]
    pub statistics: crate::stats::StatsConfig,
}

/// `[execution_video]` of `configs/scoring.toml` (`--execute-videos`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExecVideoConfig {
    pub width: u32,
    pub height: u32,
    /// 0: the dataset's fps.
    pub fps: u32,
    pub include_observation: bool,
    pub tile_columns: u32,
    pub preset: String,
    pub crf: u32,
    /// libx264 B-frames (0: none), as the dataset's `[render]`.
    #[serde(default)]
    pub bframes: u32,
}

impl ExecVideoConfig {
    /// The `[execution_video]` table of the embedded `configs/scoring.toml`.
    pub fn embedded_default() -> ExecVideoConfig {
        #[derive(Deserialize)]
        struct File {
            execution_video: ExecVideoConfig,
        }
        let file: File =
            toml::from_str(DEFAULT_CONFIG_TOML).expect("the embedded scoring.toml parses");
        file.execution_video
    }

    fn validate(&self) -> Result<()> {
        let v = self;
        if v.width < 16 || v.height < 16 || v.width % 2 == 1 || v.height % 2 == 1 {
            bail!(
                "config fields execution_video.width and .height must be even numbers >= 16, got {} x {}",
                v.width,
                v.height
            );
        }
        if v.width > 3840 || v.height > 2160 || v.fps > 240 {
            bail!("config fields execution_video.width/height/fps are at most 3840/2160/240");
        }
        if v.tile_columns == 0 || v.crf > 51 || v.preset.is_empty() || v.bframes > 16 {
            bail!("config fields execution_video.tile_columns must be >= 1, crf <= 51, bframes <= 16, preset not empty");
        }
        Ok(())
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActionRuleConfig {
    pub version: String,
    pub reach_threshold: f64,
    pub retreat_threshold: f64,
    pub move_threshold: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    pub pelvis_height: f64,
    pub rest_left: [f64; 3],
    pub rest_right: [f64; 3],
    pub default_keyframe_dt: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SanityConfig {
    pub max_abs_coordinate: f64,
    pub max_speed: f64,
    pub max_yaw_rate: f64,
    pub max_duration: f64,
    pub max_line_bytes: usize,
    pub max_keyframes: usize,
    pub max_nesting: usize,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysesConfig {
    pub miss_radius: f64,
    pub far_standing: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AiaConfig {
    pub negation_window: usize,
    pub negation: Vec<String>,
    pub coordinators: Vec<String>,
    pub coordination_fillers: Vec<String>,
    pub clause_breaks: Vec<String>,
    pub catch: Vec<String>,
    pub dodge: Vec<String>,
    pub no_action: Vec<String>,
    pub material_doubt: Vec<String>,
}

impl Default for Config {
    fn default() -> Self {
        Config::from_toml_str(DEFAULT_CONFIG_TOML).expect("embedded configs/scoring.toml is valid")
    }
}

impl Config {
    /// Parses and validates a configuration document.
    pub fn from_toml_str(text: &str) -> Result<Config> {
        let cfg: Config = toml::from_str(text).context("invalid scoring config")?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads a configuration file (`--config`).
    pub fn load(path: &Path) -> Result<Config> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read config {}", path.display()))?;
        Config::from_toml_str(&text).with_context(|| format!("in config {}", path.display()))
    }

    fn validate(&self) -> Result<()> {
        let a = &self.action_rule;
        for (name, v) in [
            ("action_rule.reach_threshold", a.reach_threshold),
            ("action_rule.retreat_threshold", a.retreat_threshold),
            ("action_rule.move_threshold", a.move_threshold),
            ("body.pelvis_height", self.body.pelvis_height),
            ("body.default_keyframe_dt", self.body.default_keyframe_dt),
            ("sanity.max_abs_coordinate", self.sanity.max_abs_coordinate),
            ("sanity.max_speed", self.sanity.max_speed),
            ("sanity.max_yaw_rate", self.sanity.max_yaw_rate),
            ("sanity.max_duration", self.sanity.max_duration),
            ("analyses.miss_radius", self.analyses.miss_radius),
            ("analyses.far_standing", self.analyses.far_standing),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("config field {name} must be a positive finite number, got {v}");
            }
        }
        if let Err(e) = self.execution.validate() {
            bail!("config field {e}");
        }
        self.execution_video.validate()?;
        if self.statistics.bootstrap_resamples < 100 || self.statistics.max_bootstrap_draws < 1000 {
            bail!("config fields statistics.bootstrap_resamples must be >= 100 and statistics.max_bootstrap_draws >= 1000");
        }
        if self.statistics.bootstrap_resamples > 1_000_000
            || self.statistics.max_bootstrap_draws > 100_000_000_000
        {
            bail!("config fields statistics.bootstrap_resamples must be <= 1000000 and statistics.max_bootstrap_draws <= 100000000000");
        }
        if !(1024..=MAX_LINE_BYTES).contains(&self.sanity.max_line_bytes) {
            bail!(
                "config field sanity.max_line_bytes must be within [1024, {MAX_LINE_BYTES}] (got {})",
                self.sanity.max_line_bytes
            );
        }
        if !(1..=1_000_000).contains(&self.sanity.max_keyframes)
            || !(4..=128).contains(&self.sanity.max_nesting)
        {
            bail!("config fields sanity.max_keyframes must be within [1, 1000000] and sanity.max_nesting within [4, 128]");
        }
        for (name, list) in [
            ("aia.catch", &self.aia.catch),
            ("aia.dodge", &self.aia.dodge),
            ("aia.no_action", &self.aia.no_action),
        ] {
            if list.is_empty() {
                bail!("config field {name} must not be empty");
            }
        }
        Ok(())
    }
}
