//! Stage 4 — render (specification §7): an offscreen wgpu renderer (Vulkan; Mesa's lavapipe on
//! CPU-only machines) that draws a simulated scene from the spec's three cameras and
//! writes what the model under test sees:
//!
//! * `videos/<cam>/<scene_id>.mp4` for `ego`, `closeup`, `overhead`: H.264 yuv420p,
//!   `+faststart`, the observation window `[0, Δ]`, frame `k` showing physics step
//!   `spec.frame_step(k)`;
//! * `frames/<scene_id>/<cam>_t0.000.png` … `_t0.600.png` (the same pixels as the video
//!   frames at those times, before compression);
//! * `videos/full/<scene_id>.mp4`: the whole event from an outside camera, for people
//!   (never model input): the counterfactual run with the observer as a body
//!   (`scene::full_event_simulation`), so what it shows is what the labels mean.
//!
//! With `RenderOptions::masks` also `masks/<scene_id>/<cam>_t0.000.png` … (16-bit
//! instance ids) and `depth/<scene_id>/<cam>_t….png` (16-bit depth in mm) of the
//! observation frames; the id pass behind them always runs and measures the hazard's
//! visibility (`RenderedScene::observed`).
//!
//! Entry points: [`Renderer::new`] (one per worker thread, reused across scenes, or
//! [`with_thread_renderer`]), [`Renderer::render_scene`], and [`contact_sheet`].
//! Every file is written atomically (temporary sibling + rename).
//!
//! One module per job:
//!
//! | module | job |
//! |---|---|
//! | `renderer` | [`Renderer`]: one scene's videos and frames, single frames, hazard masks |
//! | `geometry` | the scene's meshes: static pieces, walls, moving bodies, ropes |
//! | `recipes/` | how each catalog object looks (one table row per recipe) |
//! | `models/` | real meshes of catalog objects: package archives, hash, OBJ/MTL, textures, triangle budget, fit onto the parts |
//! | `observer` | the observer's humanoid mesh |
//! | `lighting` | sun, ambient and the shadow map's projection |
//! | `camera` | view-projection matrices (basis from `view::View`), full-event camera |
//! | `regions` | shadow-tile rectangle maths: where a moving shadow can change pixels |
//! | `measure` | the instance-id pass at the observation frames: hazard visibility, masks, depth |
//! | `gpu` | the wgpu device and pipelines (one per worker thread on a CPU rasterizer, one for all workers on a GPU), static cache and overlay drawing |
//! | `memory` | the process memory policy of rendering many scenes (glibc: mmap and trim thresholds, one arena, no huge pages) |
//! | `fxaa` | post-process anti-aliasing of read-back frames (where MSAA is off) |
//! | `encode` | H.264 encoding through FFmpeg (feature `video`, default; `encode_off` without it) |
//! | `execution` | execution videos: outside and ego views of executed plans, tiled ([`Renderer::render_executions`]) |
//! | `ego` | [`EgoCamera`]: the ego view of a closed-loop episode, one step at a time (the Gym env's image) |
//! | `sheet` | the contact sheet (`rh-pipeline sheet`) |

mod camera;
mod cells;
mod decor;
mod ego;
pub mod encode;
#[cfg(not(feature = "video"))]
mod encode_off;
mod execution;
mod font;
mod fxaa;
mod geometry;
pub mod gpu;
mod lighting;
mod measure;
pub mod memory;
pub mod mesh;
pub mod models;
mod observer;
pub mod recipes;
mod regions;
mod renderer;
mod sheet;
mod tiles;

use encode::EncodeSettings;
use std::collections::BTreeMap;

pub use camera::{full_event_camera, view_proj};
pub use ego::EgoCamera;
pub use execution::{ExecTrack, ExecVideoOptions, ExecVideos, TiledVideo};
pub use gpu::probe_adapter;
pub use measure::Observed;
pub use renderer::{release_thread_renderer, render_stage, with_thread_renderer, Renderer};
pub use rh_contract::layout::{frame_file_name, frame_path};
pub use rh_contract::{CAMERAS, FRAME_TIMES, FULL_EVENT};
/// The `[render]` section these options come from (the renderer's own settings type).
pub use rh_render_config::RenderConfig;
pub use sheet::{contact_sheet, ContactSheet, SheetTile};

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("no GPU adapter for rendering: {0}")]
    NoAdapter(String),
    #[error("GPU: {0}")]
    Gpu(String),
    #[error("video encoding: {0}")]
    Encode(String),
    #[error("{0}")]
    Io(String),
    #[error("scene {0}: {1}")]
    Scene(String, String),
    /// A renderer setting from the environment that makes no sense.
    #[error("{0}")]
    Setting(String),
}

/// Renderer settings (from the `[render]` config section).
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// Also write the observation frames' instance-id and depth PNGs (`build --masks`).
    pub masks: bool,

    pub full_width: u32,
    pub full_height: u32,
    pub full_fps: u32,
    pub encode: EncodeSettings,
    /// MSAA samples on a hardware GPU, and on a CPU rasterizer.
    pub msaa: u32,
    pub msaa_cpu: u32,
    /// FXAA-style post-process anti-aliasing wherever MSAA is off.
    pub fxaa: bool,
    /// Real meshes of catalog objects (`[render.models]`).
    pub models: rh_catalog::models::ModelConfig,
}

impl RenderOptions {
    pub fn from_config(c: &RenderConfig) -> RenderOptions {
        RenderOptions {
            masks: false,

            full_width: c.full_width,
            full_height: c.full_height,
            full_fps: c.full_fps,
            encode: EncodeSettings {
                preset: c.preset.clone(),
                crf: c.crf,
                threads: c.encoder_threads,
                bframes: c.bframes,
            },
            msaa: c.msaa,
            msaa_cpu: c.msaa_cpu,
            fxaa: c.fxaa,
            models: c.models.clone(),
        }
    }
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            masks: false,

            full_width: 640,
            full_height: 360,
            full_fps: 30,
            encode: EncodeSettings {
                preset: "superfast".into(),
                crf: 20,
                threads: 1,
                bframes: 0,
            },
            msaa: 4,
            msaa_cpu: 1,
            fxaa: true,
            models: rh_catalog::models::ModelConfig::default(),
        }
    }
}

/// What `render_scene` wrote (paths relative to the dataset root).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedScene {
    /// Camera name → `videos/<cam>/<scene_id>.mp4` (the `<cam>_file_name` columns).
    pub videos: BTreeMap<String, String>,
    /// `videos/full/<scene_id>.mp4` (the `full_event_file_name` column).
    pub full_event: String,
    /// `frames/<scene_id>/<cam>_t0.150.png`, camera-major, times in `FRAME_TIMES` order.
    pub frames: Vec<String>,
    /// Observation-video frame `k` shows physics step `frame_steps[k]`.
    pub frame_steps: Vec<u32>,
    pub fps: u32,
    /// Full-event frame `j` shows physics step `full_event_steps[j]` of the full-event
    /// run (`scene::full_event_simulation`, else the plain run).
    pub full_event_steps: Vec<u32>,
    pub full_event_fps: u32,
    /// The id pass at the observation frames: the hazard's measured visibility per
    /// camera, and the mask/depth files written (with `RenderOptions::masks`).
    pub observed: Observed,
}

impl RenderedScene {
    pub fn video(&self, camera: &str) -> Option<&str> {
        self.videos.get(camera).map(String::as_str)
    }
}

/// How a frame is shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shading {
    /// The dataset's look: sun with shadows, ambient, specular.
    Lit,
    /// Flat unlit colours with the hazard in pure magenta (`HAZARD_MASK_RGB`): a diagnostic
    /// whose hazard mask is exact.
    HazardMask,
}

pub const HAZARD_MASK_RGB: [u8; 3] = [255, 0, 255];
