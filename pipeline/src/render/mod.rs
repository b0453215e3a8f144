//! Stage 4 — render (SPEC §7): an offscreen wgpu renderer (Vulkan; Mesa's lavapipe on
//! CPU-only machines) that draws a simulated scene from the spec's three cameras and
//! writes what the model under test sees:
//!
//! * `videos/<cam>/<scene_id>.mp4` for `ego`, `closeup`, `overhead`: H.264 yuv420p,
//!   `+faststart`, the observation window `[0, Δ]`, frame `k` showing physics step
//!   `spec.frame_step(k)`;
//! * `frames/<scene_id>/<cam>_t0.000.png` … `_t0.600.png` (the same pixels as the video
//!   frames at those times, before compression);
//! * `videos/full/<scene_id>.mp4`: the whole simulation from an outside camera, for
//!   people (never model input).
//!
//! Entry points: [`Renderer::new`] (one per worker thread, reused across scenes, or
//! [`with_thread_renderer`]), [`Renderer::render_scene`], and [`contact_sheet`].
//! Every file is written atomically (temporary sibling + rename).

pub mod encode;
mod font;
pub mod gpu;
pub mod mesh;
pub mod recipes;

use crate::cameras::View;
use crate::config::RenderConfig;
use crate::simulate::Simulation;
use crate::spec::vec3::{add, cross, dot, norm, scale, sub};
use crate::spec::{BodyKind, CameraSpec, JointKind, SceneSpec, Vec3};
use encode::{EncodeSettings, VideoJob};
use gpu::{Gpu, OverlayJob, Uniforms, ViewJob};
use mesh::*;
use rh_catalog::Catalog;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Observation frames written as PNG per camera (seconds after t0).
pub const FRAME_TIMES: [f64; 5] = [0.0, 0.15, 0.30, 0.45, 0.60];
/// The cameras whose videos are model input, in column order.
pub const CAMERAS: [&str; 3] = ["ego", "closeup", "overhead"];
/// Name of the full-event video's folder under `videos/`.
pub const FULL_EVENT: &str = "full";

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
}

/// Renderer settings (from the `[render]` config section).
#[derive(Debug, Clone)]
pub struct RenderOptions {
    pub full_width: u32,
    pub full_height: u32,
    pub full_fps: u32,
    pub encode: EncodeSettings,
    /// MSAA samples on a hardware GPU, and on a CPU rasterizer.
    pub msaa: u32,
    pub msaa_cpu: u32,
}

impl RenderOptions {
    pub fn from_config(c: &RenderConfig) -> RenderOptions {
        RenderOptions {
            full_width: c.full_width,
            full_height: c.full_height,
            full_fps: c.full_fps,
            encode: EncodeSettings {
                preset: c.preset.clone(),
                crf: c.crf,
                threads: c.encoder_threads,
            },
            msaa: c.msaa,
            msaa_cpu: c.msaa_cpu,
        }
    }
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            full_width: 640,
            full_height: 360,
            full_fps: 30,
            encode: EncodeSettings {
                preset: "veryfast".into(),
                crf: 20,
                threads: 1,
            },
            msaa: 4,
            msaa_cpu: 1,
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
    /// Full-event frame `j` shows physics step `full_event_steps[j]`.
    pub full_event_steps: Vec<u32>,
    pub full_event_fps: u32,
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

/// The wgpu device and pipelines; create one per worker thread and reuse it.
pub struct Renderer {
    gpu: Gpu,
    opts: RenderOptions,
}

thread_local! {
    static THREAD_RENDERER: RefCell<Option<Renderer>> = const { RefCell::new(None) };
}

/// Runs `f` with this thread's renderer, creating it on first use (so a rayon worker
/// keeps one device for all its scenes).
pub fn with_thread_renderer<R>(
    opts: &RenderOptions,
    f: impl FnOnce(&mut Renderer) -> R,
) -> Result<R, RenderError> {
    THREAD_RENDERER.with(|cell| {
        let mut slot = cell.borrow_mut();
        if slot.is_none() {
            *slot = Some(Renderer::new(opts.clone())?);
        }
        let r = slot.as_mut().unwrap();
        r.opts = opts.clone();
        Ok(f(r))
    })
}

impl Renderer {
    /// Opens the GPU (a clear `RenderError::NoAdapter` when there is none) and checks
    /// that FFmpeg has an H.264 encoder.
    pub fn new(opts: RenderOptions) -> Result<Renderer, RenderError> {
        encode::init().map_err(RenderError::Encode)?;
        let gpu = Gpu::new(opts.msaa, opts.msaa_cpu)?;
        Ok(Renderer { gpu, opts })
    }

    pub fn adapter_name(&self) -> &str {
        &self.gpu.adapter_name
    }

    /// MSAA samples per pixel in use.
    pub fn samples(&self) -> u32 {
        self.gpu.samples()
    }

    pub fn options(&self) -> &RenderOptions {
        &self.opts
    }

    /// Renders one scene's videos and observation frames under `out_dir` (the dataset
    /// root). See the module docs for the files.
    pub fn render_scene(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        catalog: &Catalog,
        out_dir: &Path,
    ) -> Result<RenderedScene, RenderError> {
        let id = &spec.scene_id;
        let cams: Vec<&CameraSpec> = CAMERAS
            .iter()
            .map(|name| {
                spec.cameras
                    .iter()
                    .find(|c| c.name == *name)
                    .ok_or_else(|| {
                        RenderError::Scene(id.clone(), format!("no '{name}' camera in the spec"))
                    })
            })
            .collect::<Result<_, _>>()?;
        let scene = SceneGeometry::build(spec, sim, catalog);
        self.gpu
            .reserve(scene.statics.len() + scene.max_dynamic + 1024);
        self.gpu.set_static(&scene.statics);
        // The cameras stand still within a scene: the room, furniture and observer are
        // drawn once per view and every frame starts from that image.
        let full_cam = full_event_camera(spec, sim, self.opts.full_width, self.opts.full_height);
        let mut all_cams = cams.clone();
        all_cams.push(&full_cam);
        let static_views: Vec<ViewJob> = all_cams
            .iter()
            .enumerate()
            .map(|(slot, cam)| scene.view_job(slot, cam, Shading::Lit, scene.ranges_for(cam), 0..0))
            .collect();
        self.gpu
            .cache_static(scene.light_vp, &scene.static_casters(), &static_views)?;
        // What each view needs per frame that does not change within the scene.
        let fixed_views: Vec<FixedView> = all_cams
            .iter()
            .enumerate()
            .map(|(slot, cam)| scene.fixed_view(slot, cam))
            .collect();
        let (window_views, full_view) = fixed_views.split_at(cams.len());

        let fps = spec.video.fps;
        let frame_steps = spec.observation_frame_steps(sim.steps());
        let frames = frame_steps.len() as u32 - 1;
        let png_frames: Vec<(u32, f64)> = FRAME_TIMES
            .iter()
            .map(|&t| (((t * fps as f64).round() as u32).min(frames), t))
            .collect();

        let mut videos = BTreeMap::new();
        let mut jobs = Vec::new();
        for cam in &cams {
            let rel = format!("videos/{}/{id}.mp4", cam.name);
            jobs.push(VideoJob::spawn(
                out_dir.join(&rel),
                cam.width,
                cam.height,
                fps,
                self.opts.encode.clone(),
                self.gpu.frames.clone(),
            ));
            videos.insert(cam.name.clone(), rel);
        }
        let mut frame_files = vec![String::new(); cams.len() * FRAME_TIMES.len()];
        let (png_tx, png_rx) = std::sync::mpsc::channel::<(PathBuf, u32, u32, Vec<u8>)>();
        let png_thread = std::thread::spawn(move || -> Result<(), String> {
            for (path, w, h, rgba) in png_rx {
                write_png(&path, w, h, &rgba)?;
            }
            Ok(())
        });

        let debug = std::env::var_os("RH_RENDER_DEBUG").is_some();
        let t_start = std::time::Instant::now();
        let mut t_draw = 0.0;
        let mut result = Ok(());
        for (k, &step) in frame_steps.iter().enumerate() {
            let t = std::time::Instant::now();
            let images = self.draw_overlay_step(&scene, sim, step, window_views)?;
            t_draw += t.elapsed().as_secs_f64();
            for (ci, (img, job)) in images.into_iter().zip(&jobs).enumerate() {
                for (ti, &(pk, t)) in png_frames.iter().enumerate() {
                    if pk as usize == k {
                        let rel = frame_path(id, &cams[ci].name, t);
                        let _ = png_tx.send((
                            out_dir.join(&rel),
                            cams[ci].width,
                            cams[ci].height,
                            img.clone(),
                        ));
                        frame_files[ci * FRAME_TIMES.len() + ti] = rel;
                    }
                }
                if !job.send(img) {
                    result = Err(());
                }
            }
            if result.is_err() {
                break;
            }
        }

        // Full-event video: the whole simulation from outside.
        let full_fps = self.opts.full_fps.max(1);
        let duration = sim.steps() as f64 * sim.dt;
        let full_frames = (duration * full_fps as f64 + 1e-9).floor() as u32;
        let full_event_steps: Vec<u32> = (0..=full_frames)
            .map(|j| ((j as f64 / full_fps as f64 / sim.dt).round() as u32).min(sim.steps()))
            .collect();
        let full_rel = format!("videos/{FULL_EVENT}/{id}.mp4");
        let full_job = VideoJob::spawn(
            out_dir.join(&full_rel),
            full_cam.width,
            full_cam.height,
            full_fps,
            self.opts.encode.clone(),
            self.gpu.frames.clone(),
        );
        if result.is_ok() {
            for &step in &full_event_steps {
                let mut images = self.draw_overlay_step(&scene, sim, step, full_view)?;
                if !full_job.send(images.pop().unwrap()) {
                    break;
                }
            }
        }
        drop(png_tx);
        if debug {
            eprintln!(
                "render {id}: {} static + {} dynamic vertices; window draw {:.2} s, all frames {:.2} s",
                scene.statics.len(),
                scene.max_dynamic,
                t_draw,
                t_start.elapsed().as_secs_f64()
            );
        }
        let mut errors = Vec::new();
        for (job, cam) in jobs.into_iter().zip(&cams) {
            match job.finish() {
                Ok(n) if n as usize == frame_steps.len() => {}
                Ok(n) => errors.push(format!("{}: {n} frames written", cam.name)),
                Err(e) => errors.push(format!("{}: {e}", cam.name)),
            }
        }
        match full_job.finish() {
            Ok(n) if n as usize == full_event_steps.len() => {}
            Ok(n) => errors.push(format!("full: {n} frames written")),
            Err(e) => errors.push(format!("full: {e}")),
        }
        match png_thread.join() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => errors.push(e),
            Err(_) => errors.push("PNG writer panicked".into()),
        }
        if !errors.is_empty() {
            return Err(RenderError::Encode(format!(
                "scene {id}: {}",
                errors.join("; ")
            )));
        }
        Ok(RenderedScene {
            videos,
            full_event: full_rel,
            frames: frame_files,
            frame_steps,
            fps,
            full_event_steps,
            full_event_fps: full_fps,
        })
    }

    /// Renders the given cameras at one physics step (RGBA8 sRGB images, no files).
    pub fn render_frame(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        catalog: &Catalog,
        cameras: &[CameraSpec],
        step: u32,
        shading: Shading,
    ) -> Result<Vec<image::RgbaImage>, RenderError> {
        let scene = SceneGeometry::build(spec, sim, catalog);
        self.gpu
            .reserve(scene.statics.len() + scene.max_dynamic + 1024);
        self.gpu.set_static(&scene.statics);
        let cams: Vec<&CameraSpec> = cameras.iter().collect();
        let images = self.draw_step(&scene, sim, step.min(sim.steps()), &cams, shading)?;
        Ok(images
            .into_iter()
            .zip(cameras)
            .map(|(img, c)| image::RgbaImage::from_raw(c.width, c.height, img).unwrap())
            .collect())
    }

    /// Visible hazard pixels per spec camera at `step` (from the exact `HazardMask`
    /// rendering): 0 means the hazard is hidden (behind furniture, say) even if its
    /// centre projects inside the frame. A basis for an occlusion-aware framing check.
    pub fn hazard_pixels(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        catalog: &Catalog,
        step: u32,
    ) -> Result<Vec<(String, usize)>, RenderError> {
        let images =
            self.render_frame(spec, sim, catalog, &spec.cameras, step, Shading::HazardMask)?;
        Ok(spec
            .cameras
            .iter()
            .zip(images)
            .map(|(cam, img)| {
                let n = img
                    .pixels()
                    .filter(|p| p[0] > 247 && p[1] < 8 && p[2] > 247)
                    .count();
                (cam.name.clone(), n)
            })
            .collect())
    }

    /// The whole scene at one step, drawn from scratch (diagnostics and single frames).
    fn draw_step(
        &mut self,
        scene: &SceneGeometry,
        sim: &Simulation,
        step: u32,
        cams: &[&CameraSpec],
        shading: Shading,
    ) -> Result<Vec<Vec<u8>>, RenderError> {
        let dynamic = scene.dynamic_at(sim, step, shading == Shading::HazardMask);
        let dyn_range = self.gpu.set_dynamic(&dynamic)?;
        let views: Vec<ViewJob> = cams
            .iter()
            .enumerate()
            .map(|(slot, cam)| {
                scene.view_job(slot, cam, shading, scene.ranges_for(cam), dyn_range.clone())
            })
            .collect();
        let mut casters = scene.static_casters();
        casters.push(dyn_range);
        self.gpu.draw(scene.light_vp, &casters, &views)
    }

    /// The same pixels as `draw_step` with `Shading::Lit`, drawn over the views cached
    /// in `render_scene`: only the moving bodies and the static surfaces their shadows
    /// can reach are drawn.
    fn draw_overlay_step(
        &mut self,
        scene: &SceneGeometry,
        sim: &Simulation,
        step: u32,
        views: &[FixedView],
    ) -> Result<Vec<Vec<u8>>, RenderError> {
        let dynamic = scene.dynamic_at(sim, step, false);
        let dyn_range = self.gpu.set_dynamic(&dynamic)?;
        let moving = bounds(&dynamic);
        let jobs: Vec<OverlayJob> = views
            .iter()
            .map(|v| OverlayJob {
                slot: v.slot,
                uniforms: v.uniforms,
                redraw: moving
                    .map(|m| scene.shadow_redraws(v, m))
                    .unwrap_or_default(),
                dynamic: dyn_range.clone(),
            })
            .collect();
        self.gpu
            .draw_overlay(scene.light_vp, std::slice::from_ref(&dyn_range), &jobs)
    }
}

/// Axis-aligned bounds of some vertices (`None` when there are none).
fn bounds(verts: &[Vertex]) -> Option<[Vec3; 2]> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in verts {
        for i in 0..3 {
            lo[i] = lo[i].min(v.pos[i] as f64);
            hi[i] = hi[i].max(v.pos[i] as f64);
        }
    }
    (!verts.is_empty()).then_some([lo, hi])
}

/// Screen bounds (x, y, width, height; clamped, padded by 2 pixels) of the box
/// `[lo, hi]` in `cam` seen through `view` (its camera model): `None` when off screen,
/// the whole frame when the box reaches behind the camera or there is no view (a
/// camera looking straight up or down).
fn screen_rect(cam: &CameraSpec, view: Option<&View>, [lo, hi]: [Vec3; 2]) -> Option<[u32; 4]> {
    let whole = Some([0, 0, cam.width, cam.height]);
    let Some(view) = view else {
        return whole;
    };
    let (mut x0, mut y0) = (f64::INFINITY, f64::INFINITY);
    let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for corner in 0..8 {
        let p = [0, 1, 2].map(|i| if corner >> i & 1 == 1 { hi[i] } else { lo[i] });
        let Some([nx, ny]) = view.project(p) else {
            return whole;
        };
        let px = (nx * 0.5 + 0.5) * cam.width as f64;
        let py = (0.5 - ny * 0.5) * cam.height as f64;
        x0 = x0.min(px);
        y0 = y0.min(py);
        x1 = x1.max(px);
        y1 = y1.max(py);
    }
    let clamp_x = |v: f64| v.clamp(0.0, cam.width as f64) as u32;
    let clamp_y = |v: f64| v.clamp(0.0, cam.height as f64) as u32;
    let (x0, y0) = (clamp_x(x0.floor() - 2.0), clamp_y(y0.floor() - 2.0));
    let (x1, y1) = (clamp_x(x1.ceil() + 2.0), clamp_y(y1.ceil() + 2.0));
    (x1 > x0 && y1 > y0).then_some([x0, y0, x1 - x0, y1 - y0])
}

/// Merges rectangles pairwise, cheapest first (least area added), while a merge adds
/// no area or more than `max` remain.
fn merge_rects(rects: &mut Vec<[u32; 4]>, max: usize) {
    loop {
        let mut best: Option<(i64, usize, usize)> = None;
        for i in 0..rects.len() {
            for j in i + 1..rects.len() {
                let added = rect_area(rect_union(rects[i], rects[j])) as i64
                    - rect_area(rects[i]) as i64
                    - rect_area(rects[j]) as i64;
                if best.is_none_or(|(b, _, _)| added < b) {
                    best = Some((added, i, j));
                }
            }
        }
        match best {
            Some((added, i, j)) if added <= 0 || rects.len() > max => {
                rects[i] = rect_union(rects[i], rects[j]);
                rects.swap_remove(j);
            }
            _ => return,
        }
    }
}

fn rect_area(r: [u32; 4]) -> u64 {
    r[2] as u64 * r[3] as u64
}

fn rect_union(a: [u32; 4], b: [u32; 4]) -> [u32; 4] {
    let (x0, y0) = (a[0].min(b[0]), a[1].min(b[1]));
    let (x1, y1) = (
        (a[0] + a[2]).max(b[0] + b[2]),
        (a[1] + a[3]).max(b[1] + b[3]),
    );
    [x0, y0, x1 - x0, y1 - y0]
}

fn rects_meet(a: [u32; 4], b: [u32; 4]) -> bool {
    a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
}

/// Pixel rectangles (x, y, width, height) where moving geometry with bounds `[lo, hi]`
/// may shade static surfaces, i.e. where its shadow can fall. The shadow of a box B
/// lies in the translates B + d·t (t ≥ 0, `d` the sun's direction); those that meet a
/// receiver box R have t in an interval [t0, t1], and their union lies in the box
/// spanned by B + d·t0 and B + d·t1. Each receiver gives the screen bounds of that box
/// intersected with R. Rectangles are then merged, cheapest first, while a merge adds
/// no area or more than `MAX_REDRAW_RECTS` remain.
fn shadow_regions(
    cam: &CameraSpec,
    view: Option<&View>,
    [lo, hi]: [Vec3; 2],
    reach: f64,
    sun_dir: [f32; 4],
    receivers: &[[Vec3; 2]],
) -> Vec<[u32; 4]> {
    // A shaded point is on its triangle (centroid interpolation), so inside its
    // receiver box; the box only needs rounding slack.
    const PAD: f64 = 0.001;
    let (lo, hi) = (lo.map(|v| v - reach), hi.map(|v| v + reach));
    let d = [sun_dir[0] as f64, sun_dir[1] as f64, sun_dir[2] as f64];
    let mut rects: Vec<[u32; 4]> = Vec::new();
    for [rlo, rhi] in receivers {
        // The translates B + d·t that overlap R: t in [t0, t1], per axis.
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for i in 0..3 {
            let (rlo, rhi) = (rlo[i] - PAD, rhi[i] + PAD);
            if d[i].abs() < 1e-9 {
                if hi[i] < rlo || lo[i] > rhi {
                    t1 = -1.0;
                }
                continue;
            }
            let (a, b) = ((rlo - hi[i]) / d[i], (rhi - lo[i]) / d[i]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        if t1 < t0 {
            continue;
        }
        let mut box_lo = [0.0; 3];
        let mut box_hi = [0.0; 3];
        for i in 0..3 {
            box_lo[i] = (lo[i] + d[i] * t0).min(lo[i] + d[i] * t1).max(rlo[i] - PAD);
            box_hi[i] = (hi[i] + d[i] * t0).max(hi[i] + d[i] * t1).min(rhi[i] + PAD);
        }
        if (0..3).any(|i| box_lo[i] > box_hi[i]) {
            continue;
        }
        if let Some(r) = screen_rect(cam, view, [box_lo, box_hi]) {
            rects.push(r);
        }
    }
    let mut rects = cover_with_tiles(&rects, cam.width, cam.height);
    merge_rects(&mut rects, gpu::MAX_REDRAW_RECTS);
    rects
}

/// Side of the screen tiles `cover_with_tiles` snaps to (pixels).
const REDRAW_TILE: u32 = 16;

/// Few rectangles covering the union of many: mark the `REDRAW_TILE` tiles any
/// rectangle touches, take each tile row's runs, and stack runs with the same span in
/// consecutive rows into one rectangle.
fn cover_with_tiles(rects: &[[u32; 4]], width: u32, height: u32) -> Vec<[u32; 4]> {
    let (cols, rows) = (width.div_ceil(REDRAW_TILE), height.div_ceil(REDRAW_TILE));
    let mut marked = vec![false; (cols * rows) as usize];
    for &[x, y, w, h] in rects {
        for ty in y / REDRAW_TILE..(y + h).div_ceil(REDRAW_TILE).min(rows) {
            for tx in x / REDRAW_TILE..(x + w).div_ceil(REDRAW_TILE).min(cols) {
                marked[(ty * cols + tx) as usize] = true;
            }
        }
    }
    // Open rectangles in tile units: (first column, end column, first row, end row).
    let mut done: Vec<[u32; 4]> = Vec::new();
    let mut open: Vec<[u32; 4]> = Vec::new();
    for ty in 0..rows {
        let mut runs = Vec::new();
        let mut tx = 0;
        while tx < cols {
            if marked[(ty * cols + tx) as usize] {
                let start = tx;
                while tx < cols && marked[(ty * cols + tx) as usize] {
                    tx += 1;
                }
                runs.push((start, tx));
            } else {
                tx += 1;
            }
        }
        let mut next = Vec::new();
        for (c0, c1) in runs {
            match open.iter().position(|o| o[0] == c0 && o[1] == c1) {
                Some(i) => {
                    let mut o = open.swap_remove(i);
                    o[3] = ty + 1;
                    next.push(o);
                }
                None => next.push([c0, c1, ty, ty + 1]),
            }
        }
        done.append(&mut open);
        open = next;
    }
    done.append(&mut open);
    done.into_iter()
        .map(|[c0, c1, r0, r1]| {
            let (x0, y0) = (c0 * REDRAW_TILE, r0 * REDRAW_TILE);
            let (x1, y1) = (
                (c1 * REDRAW_TILE).min(width),
                (r1 * REDRAW_TILE).min(height),
            );
            [x0, y0, x1 - x0, y1 - y0]
        })
        .collect()
}

/// `<cam>_t0.150.png`
pub fn frame_file_name(camera: &str, t: f64) -> String {
    format!("{camera}_t{t:.3}.png")
}

/// `frames/<scene_id>/<cam>_t0.150.png`, relative to the dataset root.
pub fn frame_path(scene_id: &str, camera: &str, t: f64) -> String {
    format!("frames/{scene_id}/{}", frame_file_name(camera, t))
}

fn write_png(path: &Path, w: u32, h: u32, rgba: &[u8]) -> Result<(), String> {
    use image::ImageEncoder;
    let rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut bytes,
        image::codecs::png::CompressionType::Fast,
        image::codecs::png::FilterType::Sub,
    )
    .write_image(&rgb, w, h, image::ExtendedColorType::Rgb8)
    .map_err(|e| format!("{}: {e}", path.display()))?;
    crate::dataset::write_atomic(path, &bytes).map_err(|e| format!("{}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------
// Cameras and matrices

/// The camera basis exactly as `cameras::View` builds it (+z up).
fn basis(cam: &CameraSpec) -> (Vec3, Vec3, Vec3) {
    let f = sub(cam.look_at, cam.position);
    let f = scale(f, 1.0 / norm(f).max(1e-12));
    let mut r = cross(f, [0.0, 0.0, 1.0]);
    if norm(r) < 1e-3 {
        // Straight down/up (the validator rejects these; render something sensible).
        r = cross(f, [0.0, 1.0, 0.0]);
    }
    let r = scale(r, 1.0 / norm(r));
    let u = cross(r, f);
    (r, u, f)
}

/// Column-major view-projection matrix agreeing with `cameras::View::project`:
/// clip x/w and y/w are exactly its normalised coordinates; depth maps [near, far] to [0, 1].
pub fn view_proj(cam: &CameraSpec) -> [[f32; 4]; 4] {
    let (r, u, f) = basis(cam);
    let e = cam.position;
    let ty = (cam.fov_y / 2.0).tan();
    let tx = ty * cam.width as f64 / cam.height as f64;
    let (near, far) = (0.05, 60.0);
    let a = far / (far - near);
    let b = -near * far / (far - near);
    let rows = [
        [r[0] / tx, r[1] / tx, r[2] / tx, -dot(r, e) / tx],
        [u[0] / ty, u[1] / ty, u[2] / ty, -dot(u, e) / ty],
        [a * f[0], a * f[1], a * f[2], -a * dot(f, e) + b],
        [f[0], f[1], f[2], -dot(f, e)],
    ];
    to_cols(rows)
}

fn to_cols(rows: [[f64; 4]; 4]) -> [[f32; 4]; 4] {
    let mut m = [[0.0f32; 4]; 4];
    for (i, row) in rows.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            m[j][i] = *v as f32;
        }
    }
    m
}

/// The outside camera of the full-event video: beside the line from the observer to the
/// hazard's start, raised, aimed at everything that moves, with a field of view that
/// holds the observer and the hazard's whole path.
pub fn full_event_camera(
    spec: &SceneSpec,
    sim: &Simulation,
    width: u32,
    height: u32,
) -> CameraSpec {
    let o = &spec.observer;
    let mut pts: Vec<Vec3> = vec![[o.x, o.y, 0.0], [o.x, o.y, o.height]];
    let stride = (sim.steps() / 60).max(1);
    let mut k = 0;
    while k <= sim.steps() {
        pts.push(sim.hazard_position(k));
        k += stride;
    }
    pts.push(sim.hazard_position(sim.steps()));
    let n = pts.len() as f64;
    let c = scale(pts.iter().fold([0.0; 3], |a, p| add(a, *p)), 1.0 / n);
    let start = sim.hazard_position(0);
    let mut d = [start[0] - o.x, start[1] - o.y, 0.0];
    if norm(d) < 1e-3 {
        d = [o.yaw.cos(), o.yaw.sin(), 0.0];
    }
    let d = scale(d, 1.0 / norm(d));
    // Perpendicular, pulled back a little behind the observer.
    let side = [-d[1] * 0.87 - d[0] * 0.5, d[0] * 0.87 - d[1] * 0.5, 0.0];
    let aspect = width as f64 / height as f64;
    let mut dist = 3.0;
    let mut best = None;
    for _ in 0..8 {
        let position = [
            c[0] + side[0] * dist,
            c[1] + side[1] * dist,
            (c[2] + 0.9).max(1.7),
        ];
        let mut cam = CameraSpec {
            name: FULL_EVENT.into(),
            position,
            look_at: c,
            fov_y: 1.0,
            width,
            height,
        };
        let (r, u, f) = basis(&cam);
        let mut need = 0.0f64;
        let mut behind = false;
        for p in &pts {
            let v = sub(*p, position);
            let z = dot(v, f);
            if z < 0.3 {
                behind = true;
                break;
            }
            need = need
                .max((dot(v, u) / z).abs())
                .max((dot(v, r) / z).abs() / aspect);
        }
        if !behind {
            cam.fov_y = 2.0 * (need * 1.2).max(0.25).atan();
            let ok = cam.fov_y <= 1.4;
            best = Some(cam);
            if ok {
                break;
            }
        }
        dist *= 1.3;
    }
    best.unwrap_or(CameraSpec {
        name: FULL_EVENT.into(),
        position: [c[0] + side[0] * 6.0, c[1] + side[1] * 6.0, 2.5],
        look_at: c,
        fov_y: 1.2,
        width,
        height,
    })
}

// ---------------------------------------------------------------------------------------
// Scene geometry

/// One static mesh piece: its vertices in `statics`, its bounding box, and the
/// bounding boxes of its triangle pairs (meshes are built face by face, so a pair is
/// one quad: a table top apart from its legs), which bound where on it a shadow can
/// fall much tighter than the whole box.
struct Piece {
    range: Range<u32>,
    bounds: [Vec3; 2],
    receivers: Vec<[Vec3; 2]>,
}

const RECEIVER_TRIANGLES: usize = 2;

/// The piece made of `statics[from..]` (`None` when empty).
fn piece(statics: &[Vertex], from: usize) -> Option<Piece> {
    let verts = &statics[from..];
    bounds(verts).map(|whole| Piece {
        range: from as u32..statics.len() as u32,
        bounds: whole,
        receivers: verts
            .chunks(3 * RECEIVER_TRIANGLES)
            .filter_map(bounds)
            .collect(),
    })
}

/// A camera's per-scene constants for overlay frames (`SceneGeometry::fixed_view`).
struct FixedView<'a> {
    slot: usize,
    cam: &'a CameraSpec,
    uniforms: Uniforms,
    view: Option<View>,
    /// Static pieces the camera sees: vertex range and screen bounds.
    visible: Vec<(Range<u32>, [u32; 4])>,
    /// Their receiver boxes (`Piece::receivers`).
    receivers: Vec<[Vec3; 2]>,
}

struct Wall {
    range: Range<u32>,
    /// Visible from cameras with `axis` coordinate on this side: `sign * p[axis] < limit`.
    axis: usize,
    sign: f64,
    limit: f64,
}

struct DynamicBody {
    slot: usize,
    hazard: bool,
    mesh: Mesh,
}

struct Rope {
    a: (Option<usize>, Vec3),
    b: (usize, Vec3),
}

struct SceneGeometry {
    statics: Vec<Vertex>,
    /// Furniture and event geometry.
    fixed: Range<u32>,
    /// The observer's body and head.
    observer: Range<u32>,
    head_center: Vec3,
    floor: Range<u32>,
    walls: Vec<Wall>,
    ceiling: Range<u32>,
    ceiling_z: f64,
    dynamic: Vec<DynamicBody>,
    ropes: Vec<Rope>,
    max_dynamic: usize,
    light_vp: [[f32; 4]; 4],
    sun_dir: [f32; 4],
    sun_color: [f32; 4],
    ambient: [f32; 4],
    background: [f32; 4],
    /// The static pieces (each fixed body, the observer, floor, each wall, ceiling).
    pieces: Vec<Piece>,
    /// Distance (m) from a shadow volume within which shading may depend on it.
    shadow_reach: f64,
}

fn fixed_color(name: &str, wall: Rgba) -> Rgba {
    let has = |k: &str| name.contains(k);
    if has("table") || has("stool") || has("counter") || has("desk") {
        hex("#8d6e4a")
    } else if has("shelf") {
        hex("#a1887f")
    } else if has("wall") {
        shade(wall, 0.92)
    } else if has("ramp") {
        hex("#90a4ae")
    } else if has("step") || has("landing") || has("stair") {
        hex("#bcaaa4")
    } else if has("jamb") || has("frame") || has("door") {
        hex("#eeeeee")
    } else if has("mount") || has("hook") || has("bar") || has("rail") || has("beam") {
        mat(hex("#78909c"), MAT_GLOSSY)
    } else {
        hex("#9e9e9e")
    }
}

/// The observer: a humanoid with Unitree-G1 proportions (height 1.32 m, pelvis 0.79 m,
/// shoulders 1.10 m), in its body frame (x forward, y left, z up, origin on the floor).
/// Returns (body, head).
fn observer_mesh(height: f64, pelvis: f64, shoulder: f64) -> (Mesh, Mesh) {
    let (h, pz, sz) = (height as f32, pelvis as f32, shoulder as f32);
    let shell = hex("#c9cdd2");
    let dark = hex("#2b2f33");
    let accent = hex("#ff6f00");
    let mut m = Mesh::new();
    let id = Xf::ID;
    for sy in [-1.0f32, 1.0] {
        let y = sy * 0.1;
        m.boxy(
            &Xf::at([0.03, y, 0.03]),
            [0.1, 0.045, 0.03],
            1,
            &solid(dark),
        );
        m.rod(
            &id,
            [0.0, y, 0.08],
            [0.0, y, pz * 0.52],
            0.05,
            12,
            &solid(shell),
        );
        m.sphere(&Xf::at([0.0, y, pz * 0.54]), 0.055, 12, &solid(dark));
        m.rod(
            &id,
            [0.0, y, pz * 0.57],
            [0.0, y * 0.95, pz - 0.05],
            0.062,
            12,
            &solid(shell),
        );
        // Arms: shoulder → elbow → hand at rest (≈ pelvis height, 0.1 m forward).
        let shoulder_p = [0.0, sy * 0.2, sz - 0.02];
        let elbow = [-0.02, sy * 0.21, sz - 0.24];
        let hand = [0.11, sy * 0.17, pz + 0.02];
        m.sphere(&Xf::at(shoulder_p), 0.055, 12, &solid(dark));
        m.rod(&id, shoulder_p, elbow, 0.04, 10, &solid(shell));
        m.sphere(&Xf::at(elbow), 0.042, 10, &solid(dark));
        m.rod(&id, elbow, hand, 0.035, 10, &solid(shell));
        m.boxy(
            &Xf::at([hand[0] + 0.03, hand[1], hand[2] - 0.02]),
            [0.035, 0.02, 0.045],
            1,
            &solid(dark),
        );
    }
    m.boxy(&Xf::at([0.0, 0.0, pz]), [0.08, 0.14, 0.07], 1, &solid(dark));
    m.cylinder(
        &Xf::at([0.0, 0.0, pz + 0.09]),
        0.085,
        0.035,
        16,
        &solid(dark),
    );
    let torso_mid = (pz + 0.12 + sz + 0.02) / 2.0;
    let torso_half = (sz + 0.02 - pz - 0.12) / 2.0;
    let chest = move |p: V3| {
        if p[0] > 0.09 && (p[2] - torso_half * 0.3).abs() < 0.015 {
            accent
        } else {
            shell
        }
    };
    m.boxy(
        &Xf::at([0.0, 0.0, torso_mid]),
        [0.1, 0.15, torso_half],
        4,
        &chest,
    );
    m.cylinder(
        &Xf::at([0.0, 0.0, sz + 0.05]),
        0.035,
        0.04,
        10,
        &solid(dark),
    );
    let mut head = Mesh::new();
    let head_z = h - 0.075;
    head.ellipsoid(
        &Xf::at([0.0, 0.0, head_z]),
        [0.075, 0.07, 0.075],
        20,
        &solid(shell),
    );
    head.ellipsoid(
        &Xf::at([0.035, 0.0, head_z + 0.005]),
        [0.05, 0.06, 0.035],
        16,
        &solid(mat(hex("#101418"), MAT_GLOSSY)),
    );
    (m, head)
}

fn color_temperature(k: f64) -> [f32; 3] {
    let t = ((k - 3000.0) / 4000.0).clamp(0.0, 1.0) as f32;
    let warm = [1.0, 0.82, 0.62];
    let cool = [0.92, 0.96, 1.0];
    [0, 1, 2].map(|i| warm[i] + (cool[i] - warm[i]) * t)
}

impl SceneGeometry {
    fn build(spec: &SceneSpec, sim: &Simulation, catalog: &Catalog) -> SceneGeometry {
        let mut statics: Vec<Vertex> = Vec::new();
        // Each static piece's vertices and bounds: what a moving body's shadow can fall on
        // and what must be redrawn where it does (see `shadow_regions`).
        let mut pieces: Vec<Piece> = Vec::new();
        let room = &spec.room;
        let wall_c = hex(&room.wall_color);
        let floor_c = mat(hex(&room.floor_color), MAT_FLOOR);

        // Fixed bodies (furniture, event geometry) and the observer: shadow casters.
        for body in spec.bodies.iter().filter(|b| b.kind == BodyKind::Fixed) {
            let mesh = match body
                .catalog_id
                .as_deref()
                .and_then(|id| object_look_mesh(catalog, id, &body.parts))
            {
                Some(m) => m,
                None => {
                    let mut m = Mesh::new();
                    let c = fixed_color(&body.name, wall_c);
                    recipes::parts_mesh(&mut m, &body.parts, c, c);
                    m
                }
            };
            let from = statics.len();
            mesh.transformed_into(&Xf::from_quat(body.rotation, body.position), &mut statics);
            pieces.extend(piece(&statics, from));
        }
        let fixed = 0..statics.len() as u32;
        let o = &spec.observer;
        let (obody, ohead) = observer_mesh(o.height, o.pelvis_z, o.shoulder_z);
        let oxf = Xf::rot(2, o.yaw as f32, [o.x as f32, o.y as f32, 0.0]);
        obody.transformed_into(&oxf, &mut statics);
        ohead.transformed_into(&oxf, &mut statics);
        let observer = fixed.end..statics.len() as u32;
        pieces.extend(piece(&statics, observer.start as usize));
        let head_center = [o.x, o.y, o.height - 0.075];

        // Room shell.
        let (hx, hy, ch) = (
            room.size[0] as f32 / 2.0,
            room.size[1] as f32 / 2.0,
            room.ceiling_height as f32,
        );
        let start = statics.len() as u32;
        let mut floor = Mesh::new();
        floor.boxy(
            &Xf::at([0.0, 0.0, -0.02]),
            [hx, hy, 0.02],
            1,
            &solid(floor_c),
        );
        floor.transformed_into(&Xf::ID, &mut statics);
        let floor_r = start..statics.len() as u32;
        pieces.extend(piece(&statics, start as usize));
        let mut walls = Vec::new();
        let skirting = shade(wall_c, 0.55);
        let wall_paint = move |p: V3| if p[2] < 0.1 { skirting } else { wall_c };
        for (axis, sign) in [(0usize, 1.0f64), (0, -1.0), (1, 1.0), (1, -1.0)] {
            let s = statics.len() as u32;
            let mut m = Mesh::new();
            let (half_len, pos) = if axis == 0 {
                (
                    [0.02, hy + 0.04, ch / 2.0],
                    [sign as f32 * (hx + 0.02), 0.0, ch / 2.0],
                )
            } else {
                (
                    [hx + 0.04, 0.02, ch / 2.0],
                    [0.0, sign as f32 * (hy + 0.02), ch / 2.0],
                )
            };
            // Paint in world coordinates: the box is axis-aligned, so local z + centre.
            let paint = move |p: V3| wall_paint([p[0], p[1], p[2] + ch / 2.0]);
            // 24 cells along the wall: 12 up its height, so the skirting stays a low band.
            m.boxy(&Xf::at(pos), half_len, 24, &paint);
            m.transformed_into(&Xf::ID, &mut statics);
            pieces.extend(piece(&statics, s as usize));
            walls.push(Wall {
                range: s..statics.len() as u32,
                axis,
                sign,
                limit: if axis == 0 { hx as f64 } else { hy as f64 },
            });
        }
        let s = statics.len() as u32;
        let mut ceil = Mesh::new();
        ceil.boxy(
            &Xf::at([0.0, 0.0, ch + 0.02]),
            [hx, hy, 0.02],
            1,
            &solid(hex("#f4f4f0")),
        );
        ceil.transformed_into(&Xf::ID, &mut statics);
        let ceiling = s..statics.len() as u32;
        pieces.extend(piece(&statics, s as usize));

        // Moving bodies, meshed once in their body frames.
        let mut dynamic = Vec::new();
        let mut max_dynamic = 0;
        for (slot, &bi) in sim.dynamic_bodies.iter().enumerate() {
            let body = &spec.bodies[bi];
            let mesh = body
                .catalog_id
                .as_deref()
                .and_then(|id| object_look_mesh(catalog, id, &body.parts))
                .unwrap_or_else(|| {
                    let mut m = Mesh::new();
                    let c = if body.name.contains("rod") || body.name.contains("rope") {
                        hex("#424242")
                    } else {
                        hex("#5c6bc0")
                    };
                    recipes::parts_mesh(&mut m, &body.parts, c, c);
                    m
                });
            max_dynamic += mesh.verts.len();
            dynamic.push(DynamicBody {
                slot,
                hazard: bi == spec.hazard,
                mesh,
            });
        }
        let slot_of = |bi: usize| sim.dynamic_bodies.iter().position(|&b| b == bi);
        let mut ropes = Vec::new();
        for j in &spec.joints {
            if !matches!(
                j.kind,
                JointKind::Rope { .. } | JointKind::Spherical | JointKind::Revolute { .. }
            ) {
                continue;
            }
            let Some(sb) = slot_of(j.body_b) else {
                continue;
            };
            let a = match j.body_a {
                None => (None, j.anchor_a),
                Some(ba) => match slot_of(ba) {
                    Some(sa) => (Some(sa), j.anchor_a),
                    None => {
                        let b = &spec.bodies[ba];
                        (
                            None,
                            add(
                                crate::spec::quat::rotate(b.rotation, j.anchor_a),
                                b.position,
                            ),
                        )
                    }
                },
            };
            ropes.push(Rope {
                a,
                b: (sb, j.anchor_b),
            });
        }
        max_dynamic += ropes.len() * 200;

        // Lighting: the spec's sun (scaled into display range) and ambient.
        let l = &spec.lighting;
        let mut dir = l.sun_direction;
        let n = norm(dir);
        dir = if n > 1e-9 {
            scale(dir, 1.0 / n)
        } else {
            [0.3, 0.2, -0.93]
        };
        let tint = color_temperature(l.color_temperature_k);
        let sun = (l.sun_intensity * 0.25) as f32;
        let amb = (l.ambient * 1.3) as f32;
        let (light_vp, light_radius) = light_matrix(dir, room.size, room.ceiling_height);
        // How far from a moving body's shadow volume a static pixel's shading can still
        // see it: the shader's normal offset, the comparison filter's 2×2 texels (with a
        // texel to spare), and a centimetre of slack.
        let texel = 2.0 * light_radius / gpu::SHADOW_SIZE as f64;
        let shadow_reach = SHADOW_NORMAL_OFFSET + 3.0 * texel + 0.01;
        SceneGeometry {
            statics,
            fixed,
            observer,
            head_center,
            floor: floor_r,
            walls,
            ceiling,
            ceiling_z: room.ceiling_height,
            dynamic,
            ropes,
            max_dynamic,
            light_vp,
            sun_dir: [dir[0] as f32, dir[1] as f32, dir[2] as f32, 0.0],
            sun_color: [tint[0] * sun, tint[1] * sun, tint[2] * sun, 0.0],
            ambient: [
                amb * (0.9 + 0.1 * tint[0]),
                amb * (0.9 + 0.1 * tint[1]),
                amb * (0.9 + 0.1 * tint[2]),
                0.0,
            ],
            background: [0.04, 0.045, 0.05, 1.0],
            pieces,
            shadow_reach,
        }
    }

    fn pose(&self, sim: &Simulation, step: u32, slot: usize) -> Xf {
        let s = sim.state(step, slot);
        Xf::from_quat(s.rotation.map(f64::from), s.position.map(f64::from))
    }

    fn dynamic_at(&self, sim: &Simulation, step: u32, mask: bool) -> Vec<Vertex> {
        let mut out = Vec::with_capacity(self.max_dynamic);
        for d in &self.dynamic {
            let xf = self.pose(sim, step, d.slot);
            let from = out.len();
            d.mesh.transformed_into(&xf, &mut out);
            if mask && d.hazard {
                for v in &mut out[from..] {
                    v.color = [1.0, 0.0, 1.0, MAT_EMISSIVE];
                }
            }
        }
        let mut m = Mesh::new();
        for r in &self.ropes {
            let a = match r.a {
                (Some(slot), p) => self.pose(sim, step, slot).apply(p.map(|v| v as f32)),
                (None, p) => p.map(|v| v as f32),
            };
            let b = self.pose(sim, step, r.b.0).apply(r.b.1.map(|v| v as f32));
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() > 0.03 {
                m.rod(&Xf::ID, a, b, 0.008, 6, &solid(hex("#3a3a3a")));
            }
        }
        out.extend_from_slice(&m.verts);
        out
    }

    /// Static vertex ranges a camera sees: walls it stands behind are cut away, the
    /// ceiling only from below it, the observer not from inside its head.
    fn ranges_for(&self, cam: &CameraSpec) -> Vec<Range<u32>> {
        let p = cam.position;
        let mut r = vec![self.fixed.clone()];
        // The ego camera sits in the observer's head: its own body is left out (it would
        // only block the lower part of the view).
        if norm(sub(p, self.head_center)) > 0.25 {
            r.push(self.observer.clone());
        }
        r.push(self.floor.clone());
        for w in &self.walls {
            if w.sign * p[w.axis] < w.limit {
                r.push(w.range.clone());
            }
        }
        if p[2] < self.ceiling_z {
            r.push(self.ceiling.clone());
        }
        r
    }

    /// What a camera needs per overlay frame that does not change within the scene:
    /// its uniforms, camera model, and the static pieces it sees with their screen
    /// bounds and receiver boxes.
    fn fixed_view<'a>(&self, slot: usize, cam: &'a CameraSpec) -> FixedView<'a> {
        let seen = self.ranges_for(cam);
        let view = View::new(cam);
        let pieces: Vec<(&Piece, [u32; 4])> = self
            .pieces
            .iter()
            .filter(|p| {
                seen.iter()
                    .any(|r| r.start <= p.range.start && p.range.end <= r.end)
            })
            .filter_map(|p| screen_rect(cam, view.as_ref(), p.bounds).map(|r| (p, r)))
            .collect();
        FixedView {
            slot,
            cam,
            uniforms: self.uniforms(cam, Shading::Lit),
            receivers: pieces
                .iter()
                .flat_map(|(p, _)| p.receivers.iter().copied())
                .collect(),
            visible: pieces
                .into_iter()
                .map(|(p, rect)| (p.range.clone(), rect))
                .collect(),
            view,
        }
    }

    /// Where moving geometry with bounds `moving` may shade static surfaces in a view
    /// (`shadow_regions`), each rectangle with the static pieces it must redraw: those
    /// the camera sees whose screen bounds meet it.
    fn shadow_redraws(&self, v: &FixedView, moving: [Vec3; 2]) -> Vec<([u32; 4], Vec<Range<u32>>)> {
        shadow_regions(
            v.cam,
            v.view.as_ref(),
            moving,
            self.shadow_reach,
            self.sun_dir,
            &v.receivers,
        )
        .into_iter()
        .map(|rect| {
            let ranges = v
                .visible
                .iter()
                .filter(|(_, r)| rects_meet(*r, rect))
                .map(|(range, _)| range.clone())
                .collect();
            (rect, ranges)
        })
        .collect()
    }

    /// Fixed bodies and the observer: the shadow casters that never move.
    fn static_casters(&self) -> Vec<Range<u32>> {
        vec![self.fixed.clone(), self.observer.clone()]
    }

    fn view_job(
        &self,
        slot: usize,
        cam: &CameraSpec,
        shading: Shading,
        ranges: Vec<Range<u32>>,
        dynamic: Range<u32>,
    ) -> ViewJob {
        ViewJob {
            slot,
            width: cam.width,
            height: cam.height,
            uniforms: self.uniforms(cam, shading),
            ranges,
            dynamic,
        }
    }

    fn uniforms(&self, cam: &CameraSpec, shading: Shading) -> Uniforms {
        Uniforms {
            view_proj: view_proj(cam),
            light_vp: self.light_vp,
            cam_pos: [
                cam.position[0] as f32,
                cam.position[1] as f32,
                cam.position[2] as f32,
                1.0,
            ],
            sun_dir: self.sun_dir,
            sun_color: self.sun_color,
            ambient: [
                self.ambient[0],
                self.ambient[1],
                self.ambient[2],
                if shading == Shading::HazardMask {
                    1.0
                } else {
                    0.0
                },
            ],
            background: self.background,
            fill_rects: [[-1.0, -1.0, 1.0, 1.0]; gpu::MAX_REDRAW_RECTS],
        }
    }
}

fn object_look_mesh(catalog: &Catalog, id: &str, parts: &[crate::spec::PartSpec]) -> Option<Mesh> {
    let object = catalog.object(id)?;
    let source = catalog.appearance_source(object);
    let a = &source.appearance;
    let look = recipes::Look {
        recipe: &a.recipe,
        color: hex(&a.color),
        secondary: a.secondary_color.as_deref().map(hex),
        description: a.description.as_deref().unwrap_or(""),
        parts,
    };
    Some(recipes::object_mesh(&look))
}

/// The sun's orthographic view-projection covering the room (and a margin) along its
/// direction, and its half-width (m).
fn light_matrix(dir: Vec3, size: [f64; 2], ceiling: f64) -> ([[f32; 4]; 4], f64) {
    let center = [0.0, 0.0, ceiling / 2.0];
    let radius = 0.5 * (size[0].hypot(size[1])).hypot(ceiling) + 0.5;
    let eye = sub(center, scale(dir, radius + 2.0));
    let hint = if dir[2].abs() > 0.95 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let r = cross(dir, hint);
    let r = scale(r, 1.0 / norm(r));
    let u = cross(r, dir);
    let depth = 2.0 * radius + 4.0;
    let rows = [
        [
            r[0] / radius,
            r[1] / radius,
            r[2] / radius,
            -dot(r, eye) / radius,
        ],
        [
            u[0] / radius,
            u[1] / radius,
            u[2] / radius,
            -dot(u, eye) / radius,
        ],
        [
            dir[0] / depth,
            dir[1] / depth,
            dir[2] / depth,
            -dot(dir, eye) / depth,
        ],
        [0.0, 0.0, 0.0, 1.0],
    ];
    (to_cols(rows), radius)
}

/// The shader's shadow lookup offset along the surface normal (m; `shadow_factor`).
const SHADOW_NORMAL_OFFSET: f64 = 0.025;

// ---------------------------------------------------------------------------------------
// Contact sheet

/// Columns of a contact sheet of `n` tiles: 3 to 5 (fewer when there are fewer tiles),
/// the count that leaves the fewest empty places in the last row, the most columns on a tie.
fn sheet_columns(n: u32) -> u32 {
    if n <= 3 {
        return n.max(1);
    }
    (3..=5u32)
        .min_by_key(|&c| (n.div_ceil(c) * c - n, u32::MAX - c))
        .unwrap_or(5)
}

/// What `contact_sheet` drew.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSheet {
    /// Family and scene id per tile, in tile order.
    pub tiles: Vec<(String, String)>,
    pub width: u32,
    pub height: u32,
}

/// Tiles one frame per family (the close-up frame at t = 0.30 s of the family's first
/// scene by index; the ego frame when there is no close-up) with a label, so a person can
/// eyeball every family at once. Reads `DIR/specs/*.json` and `DIR/frames/`.
pub fn contact_sheet(dataset_dir: &Path, out_png: &Path) -> Result<ContactSheet, RenderError> {
    let specs_dir = dataset_dir.join("specs");
    let entries = std::fs::read_dir(&specs_dir)
        .map_err(|e| RenderError::Io(format!("{}: {e}", specs_dir.display())))?;
    let mut first: BTreeMap<String, (u64, String, PathBuf)> = BTreeMap::new();
    for entry in entries {
        let path = entry.map_err(|e| RenderError::Io(e.to_string()))?.path();
        if path.extension().and_then(|e| e.to_str()) != Some("json") {
            continue;
        }
        let text = std::fs::read_to_string(&path)
            .map_err(|e| RenderError::Io(format!("{}: {e}", path.display())))?;
        let spec = SceneSpec::from_json(&text)
            .map_err(|e| RenderError::Io(format!("{}: {e}", path.display())))?;
        // The close-up frame at 0.30 s, or the ego one when there is no close-up.
        let Some(frame) = ["closeup", "ego"]
            .into_iter()
            .map(|cam| dataset_dir.join(frame_path(&spec.scene_id, cam, 0.30)))
            .find(|p| p.exists())
        else {
            continue;
        };
        let e =
            first
                .entry(spec.family.clone())
                .or_insert((u64::MAX, String::new(), PathBuf::new()));
        if spec.scene_index < e.0 {
            *e = (spec.scene_index, spec.scene_id.clone(), frame);
        }
    }
    if first.is_empty() {
        return Err(RenderError::Io(format!(
            "{}: no rendered scenes (specs with frames/<id>/closeup_t0.300.png)",
            dataset_dir.display()
        )));
    }
    // Canonical family order, then any others.
    let mut order: Vec<String> = rh_catalog::FAMILIES
        .iter()
        .filter(|f| first.contains_key(**f))
        .map(|f| f.to_string())
        .collect();
    for f in first.keys() {
        if !order.contains(f) {
            order.push(f.clone());
        }
    }
    // Label strip: 4 px, the 9-row font at scale 2 (descenders included), 4 px.
    let (tw, th, label) = (384u32, 216u32, 8 + 2 * font::ROWS);
    let n = order.len() as u32;
    let cols = sheet_columns(n);
    let rows = n.div_ceil(cols);
    let (w, h) = (cols * tw, rows * (th + label));
    let mut sheet = image::RgbImage::from_pixel(w, h, image::Rgb([24, 24, 28]));
    let mut tiles = Vec::new();
    for (i, family) in order.iter().enumerate() {
        let (_, id, path) = &first[family];
        let img = image::open(path)
            .map_err(|e| RenderError::Io(format!("{}: {e}", path.display())))?
            .to_rgb8();
        let tile = image::imageops::resize(&img, tw, th, image::imageops::FilterType::Triangle);
        // A short last row is centred rather than leaving empty tiles at its end.
        let (row, col) = (i as u32 / cols, i as u32 % cols);
        let in_row = if row + 1 == rows {
            n - row * cols
        } else {
            cols
        };
        let x = col * tw + (cols - in_row) * tw / 2;
        let y = row * (th + label);
        image::imageops::replace(&mut sheet, &tile, x as i64, (y + label) as i64);
        font::draw_text(
            &mut sheet,
            x + 6,
            y + 4,
            &format!("{family} {id}"),
            2,
            [235, 235, 235],
        );
        tiles.push((family.clone(), id.clone()));
    }
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgb8(sheet)
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| RenderError::Io(format!("{}: {e}", out_png.display())))?;
    crate::dataset::write_atomic(out_png, &bytes)
        .map_err(|e| RenderError::Io(format!("{}: {e}", out_png.display())))?;
    Ok(ContactSheet {
        tiles,
        width: w,
        height: h,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cameras::View;

    fn object_parts(catalog: &Catalog, id: &str) -> Vec<crate::spec::PartSpec> {
        crate::families::object_parts(catalog.object(id).unwrap())
    }

    #[test]
    fn every_catalog_object_meshes_and_every_recipe_in_use_is_specific() {
        let catalog = Catalog::embedded().unwrap();
        for o in catalog.objects.iter() {
            let parts = object_parts(&catalog, &o.id);
            let mesh = object_look_mesh(&catalog, &o.id, &parts).unwrap();
            assert!(!mesh.verts.is_empty(), "{}", o.id);
            assert!(
                mesh.verts
                    .iter()
                    .all(|v| v.pos.iter().all(|c| c.is_finite())),
                "{}",
                o.id
            );
            assert!(
                recipes::SPECIFIC.contains(&o.appearance.recipe.as_str()),
                "{}: recipe '{}' falls back to plain parts",
                o.id,
                o.appearance.recipe
            );
        }
    }

    #[test]
    fn adversarial_objects_render_exactly_like_their_look_alike() {
        let catalog = Catalog::embedded().unwrap();
        let mut n = 0;
        for o in catalog.objects.iter().filter(|o| o.is_adversarial()) {
            let twin = o.looks_like.as_deref().unwrap();
            let a = object_look_mesh(&catalog, &o.id, &object_parts(&catalog, &o.id)).unwrap();
            let b = object_look_mesh(&catalog, twin, &object_parts(&catalog, twin)).unwrap();
            assert_eq!(
                bytemuck::cast_slice::<Vertex, u8>(&a.verts),
                bytemuck::cast_slice::<Vertex, u8>(&b.verts),
                "{} vs {twin}",
                o.id
            );
            n += 1;
        }
        assert!(n >= 14);
    }

    #[test]
    fn contact_sheet_columns_leave_the_fewest_gaps() {
        assert_eq!(sheet_columns(1), 1);
        assert_eq!(sheet_columns(2), 2);
        assert_eq!(sheet_columns(15), 5);
        assert_eq!(sheet_columns(16), 4);
        assert_eq!(sheet_columns(17), 3);
        assert_eq!(sheet_columns(10), 5);
    }

    #[test]
    fn unknown_recipes_fall_back_to_the_collision_parts() {
        let parts = vec![crate::spec::PartSpec {
            shape: crate::spec::ShapeSpec::Sphere { radius: 0.1 },
            offset: [0.0; 3],
            rotation: crate::spec::IDENTITY,
        }];
        let look = recipes::Look {
            recipe: "no_such_recipe",
            color: hex("#ff0000"),
            secondary: None,
            description: "",
            parts: &parts,
        };
        assert!(!recipes::object_mesh(&look).verts.is_empty());
    }

    #[test]
    fn projection_matrix_agrees_with_the_validator_camera_model() {
        let cam = CameraSpec {
            name: "t".into(),
            position: [0.3, -2.0, 1.4],
            look_at: [0.5, 0.6, 0.8],
            fov_y: 0.9,
            width: 1280,
            height: 720,
        };
        let m = view_proj(&cam);
        let view = View::new(&cam).unwrap();
        for p in [
            [0.5, 0.6, 0.8],
            [1.0, 1.0, 0.2],
            [-0.4, 0.9, 1.9],
            [0.2, -0.5, 1.0],
        ] {
            let [x, y] = view.project(p).unwrap();
            let v = [p[0] as f32, p[1] as f32, p[2] as f32, 1.0];
            let clip: Vec<f32> = (0..4)
                .map(|r| (0..4).map(|c| m[c][r] * v[c]).sum())
                .collect();
            assert!((clip[0] / clip[3] - x as f32).abs() < 1e-4, "{p:?}");
            assert!((clip[1] / clip[3] - y as f32).abs() < 1e-4, "{p:?}");
            let z = clip[2] / clip[3];
            assert!((0.0..=1.0).contains(&z));
        }
    }
}
