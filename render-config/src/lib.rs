//! The renderer's settings: the `[render]` section of the build configuration
//! (`configs/default.toml`) — the model-input image size and frame rate, the full-event
//! video, the H.264 encoder, anti-aliasing and the object models (`[render.models]`).
//!
//! The renderer owns this type (`rh_render::RenderOptions::from_config` reads it); it sits
//! in a crate of its own below rh-scenes and rh-render because the build configuration
//! that rh-scenes loads, validates and stores in every manifest (`build.json`'s
//! `config.render`) holds it as one section, and because scene generation reads its image
//! size and frame rate (a spec's `video`, the ego pixel estimates). Nothing else of it
//! reaches a scene.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderConfig {
    pub width: u32,
    pub height: u32,
    pub fps: u32,
    /// Size and frame rate of the full-event video (for people, not model input).
    #[serde(default = "default_full_width")]
    pub full_width: u32,
    #[serde(default = "default_full_height")]
    pub full_height: u32,
    #[serde(default = "default_full_fps")]
    pub full_fps: u32,
    /// libx264 preset and constant rate factor.
    #[serde(default = "default_preset")]
    pub preset: String,
    #[serde(default = "default_crf")]
    pub crf: u32,
    /// libx264 threads per video (0 = automatic).
    #[serde(default = "default_encoder_threads")]
    pub encoder_threads: u32,
    /// libx264 B-frames between reference frames (0: none; the preset's own is 3).
    #[serde(default)]
    pub bframes: u32,
    /// MSAA samples (4 or 1) on a hardware GPU.
    #[serde(default = "default_msaa")]
    pub msaa: u32,
    /// MSAA samples (4 or 1) on a CPU rasterizer (Mesa's lavapipe), where 4 samples
    /// cost about 3× the time.
    #[serde(default = "default_msaa_cpu")]
    pub msaa_cpu: u32,
    /// FXAA-style post-process anti-aliasing where MSAA is off (a CPU rasterizer).
    #[serde(default = "default_fxaa")]
    pub fxaa: bool,
    /// Real meshes of catalog objects: triangle budget, bounds tolerance, textures,
    /// package directory (`[render.models]`).
    #[serde(default)]
    pub models: rh_catalog::models::ModelConfig,
}

fn default_fxaa() -> bool {
    true
}

fn default_msaa_cpu() -> u32 {
    1
}

fn default_full_width() -> u32 {
    640
}
fn default_full_height() -> u32 {
    360
}
fn default_full_fps() -> u32 {
    30
}
fn default_preset() -> String {
    "superfast".into()
}
fn default_crf() -> u32 {
    20
}
fn default_encoder_threads() -> u32 {
    1
}
fn default_msaa() -> u32 {
    4
}

impl RenderConfig {
    /// The section's ranges, as (field, value, least, most), in the order the build
    /// configuration checks them (docs/reliability.md, "Bounds").
    pub fn bounds(&self) -> [(&'static str, f64, f64, f64); 10] {
        let r = self;
        [
            ("render.width", r.width as f64, 1.0, 7680.0),
            ("render.height", r.height as f64, 1.0, 4320.0),
            ("render.fps", r.fps as f64, 1.0, 240.0),
            ("render.full_width", r.full_width as f64, 1.0, 7680.0),
            ("render.full_height", r.full_height as f64, 1.0, 4320.0),
            ("render.full_fps", r.full_fps as f64, 1.0, 240.0),
            (
                "render.encoder_threads",
                r.encoder_threads as f64,
                0.0,
                64.0,
            ),
            ("render.crf", r.crf as f64, 0.0, 51.0),
            ("render.msaa", r.msaa as f64, 1.0, 16.0),
            ("render.msaa_cpu", r.msaa_cpu as f64, 1.0, 16.0),
        ]
    }

    /// The section's other rules: the first one broken, as (field, message).
    pub fn problem(&self) -> Option<(&'static str, &'static str)> {
        if self.width == 0 || self.height == 0 || self.fps == 0 {
            return Some(("render", "width, height and fps must be positive"));
        }
        if self.bframes > 16 {
            return Some(("render.bframes", "must be at most 16"));
        }
        None
    }
}
