//! The renderer: one scene's observation videos, frames and full-event video
//! ([`Renderer::render_scene`]), single frames and hazard masks.

use super::camera::full_event_camera;
use super::encode::{self, VideoJob};
use super::geometry::{FixedView, SceneGeometry};
use super::gpu::{Gpu, OverlayJob, ViewJob};
use super::regions::bounds;
use super::{RenderError, RenderOptions, RenderedScene, Shading, CAMERAS, FRAME_TIMES, FULL_EVENT};
use rh_catalog::Catalog;
use rh_contract::layout::{frame_path, video_path};
use rh_physics::simulate::{simulate, SimOptions, Simulation};
use rh_physics::spec::{CameraSpec, SceneSpec};
use rh_scenes::driver::{full_event_simulation, SceneMedia, SceneResult};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One worker's renderer (its targets and encoders, on its thread's wgpu device
/// and pipelines: see `gpu::Gpu`); create one per worker thread and reuse it.
pub struct Renderer {
    pub(super) gpu: Gpu,
    opts: RenderOptions,
    /// The instance-id pass (`measure`), built on first use.
    pub(super) ids: Option<super::gpu::IdPass>,
}

thread_local! {
    static THREAD_RENDERER: RefCell<Option<Renderer>> = const { RefCell::new(None) };
}

/// Runs `f` with this thread's renderer, creating it on first use (so a rayon worker
/// keeps its targets for all its scenes; the device is the process's).
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

/// Drops this thread's renderer (its targets, buffers and encoders), if it has one. A
/// thread pool calls it on each worker (`ThreadPool::broadcast`) before the pool goes:
/// a worker of a dropped pool ends on its own time, and its renderer torn down then can
/// meet the process's exit. NVIDIA's Vulkan driver then hung the exiting process
/// now and then (docs/rendering.md, "On a GPU machine"); afterwards a worker's end
/// touches no driver (its device stays open: `gpu::Shared`).
pub fn release_thread_renderer() {
    let renderer = THREAD_RENDERER.with(|cell| cell.borrow_mut().take());
    drop(renderer);
}

impl Renderer {
    /// Opens the GPU (a clear `RenderError::NoAdapter` when there is none) and checks
    /// that FFmpeg has an H.264 encoder.
    pub fn new(opts: RenderOptions) -> Result<Renderer, RenderError> {
        encode::init().map_err(RenderError::Encode)?;
        crate::models::set_config(&opts.models);
        let gpu = Gpu::new(opts.msaa, opts.msaa_cpu, opts.fxaa)?;
        Ok(Renderer {
            gpu,
            opts,
            ids: None,
        })
    }

    pub fn adapter_name(&self) -> &str {
        &self.gpu.adapter_name
    }

    /// The adapter's record (name, backend, driver, CPU features) for `build.json`.
    pub fn adapter(&self) -> &rh_contract::adapter::RenderAdapter {
        &self.gpu.adapter
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
        let cams = observation_cameras(spec)?;
        let scene = SceneGeometry::build(spec, sim, catalog);
        self.gpu
            .reserve(scene.statics.len() + scene.max_dynamic + 1024);
        self.gpu.set_static(&scene.statics);
        // The full-event video shows the counterfactual run (the observer as a body),
        // the observation videos the plain run (`scene::full_event_simulation`).
        let counterfactual = full_event_simulation(spec, sim);
        let full_sim = counterfactual.as_ref().unwrap_or(sim);
        let full_cam =
            full_event_camera(spec, full_sim, self.opts.full_width, self.opts.full_height);
        // The id pass at the observation frames: measured visibility, and the mask and
        // depth PNGs (written on their own thread while the frames below render).
        let masks_root = self.opts.masks.then_some(out_dir);
        let (observed, pngs) = self.observe(spec, sim, &scene, &cams, masks_root)?;
        let mask_thread = super::measure::write_pngs(pngs);
        // Memory: only what the current phase draws into stays allocated (the id pass's
        // target, the observation slot, the full-event slot are each made again per
        // scene), so the other worker's peak does not meet idle targets of this one.
        if let Some(ids) = &mut self.ids {
            ids.release();
        }
        self.gpu.release_target(1);

        let fps = spec.video.fps;
        let frame_steps = spec.observation_frame_steps(sim.steps());
        let frames = frame_steps.len() as u32 - 1;
        let png_frames: Vec<(u32, f64)> = FRAME_TIMES
            .iter()
            .map(|&t| (((t * fps as f64).round() as u32).min(frames), t))
            .collect();
        let mut videos = BTreeMap::new();
        let mut frame_files = vec![String::new(); cams.len() * FRAME_TIMES.len()];
        let (png_tx, png_thread) = png_writer();
        let mut errors = Vec::new();

        let debug = std::env::var_os("RH_RENDER_DEBUG").is_some();
        let t_start = std::time::Instant::now();
        let mut t_draw = 0.0;
        // One video at a time (memory: a 720p libx264 encoder holds about 50 MB, and a
        // view's targets about 27 MB): each camera's static image is cached in the same
        // target slot, its frames drawn and encoded, and its encoder finished before the
        // next camera starts. The pixels are those of drawing all cameras per frame.
        for (ci, cam) in cams.iter().enumerate() {
            let view = self.cache_view(&scene, 0, cam)?;
            let rel = video_path(&cam.name, id);
            let job = self.spawn_video(out_dir.join(&rel), cam.width, cam.height, fps);
            for (k, &step) in frame_steps.iter().enumerate() {
                let t = std::time::Instant::now();
                let img = self.draw_view_step(&scene, sim, step, &view)?;
                t_draw += t.elapsed().as_secs_f64();
                for (ti, &(pk, t)) in png_frames.iter().enumerate() {
                    if pk as usize == k {
                        let rel = frame_path(id, &cam.name, t);
                        let _ = png_tx.send((out_dir.join(&rel), cam.width, cam.height, rgb(&img)));
                        frame_files[ci * FRAME_TIMES.len() + ti] = rel;
                    }
                }
                if !job.send(img) {
                    break;
                }
            }
            finish_video(job, &cam.name, frame_steps.len(), &mut errors);
            videos.insert(cam.name.clone(), rel);
            if !errors.is_empty() {
                break;
            }
        }

        // Full-event video: the whole (counterfactual) simulation from outside.
        let full_fps = self.opts.full_fps.max(1);
        let full_event_steps = full_event_steps(full_sim, full_fps);
        let full_rel = video_path(FULL_EVENT, id);
        self.gpu.release_target(0);
        if errors.is_empty() {
            let view = self.cache_view(&scene, 1, &full_cam)?;
            let full_job = self.spawn_video(
                out_dir.join(&full_rel),
                full_cam.width,
                full_cam.height,
                full_fps,
            );
            for &step in &full_event_steps {
                let img = self.draw_view_step(&scene, full_sim, step, &view)?;
                if !full_job.send(img) {
                    break;
                }
            }
            finish_video(full_job, "full", full_event_steps.len(), &mut errors);
        }
        drop(png_tx);
        self.gpu.frames.clear();
        if debug {
            eprintln!(
                "render {id}: {} static + {} dynamic vertices; window draw {:.2} s, all frames {:.2} s",
                scene.statics.len(),
                scene.max_dynamic,
                t_draw,
                t_start.elapsed().as_secs_f64()
            );
        }
        for thread in [png_thread, mask_thread] {
            match thread.join() {
                Ok(Ok(())) => {}
                Ok(Err(e)) => errors.push(e),
                Err(_) => errors.push("PNG writer panicked".into()),
            }
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
            observed,
        })
    }

    /// Starts an encoder for one video (`out`, an absolute path).
    fn spawn_video(&self, out: PathBuf, width: u32, height: u32, fps: u32) -> VideoJob {
        VideoJob::spawn(
            out,
            width,
            height,
            fps,
            self.opts.encode.clone(),
            self.gpu.frames.clone(),
        )
    }

    /// Draws `cam`'s static scene into target `slot` and keeps it as the view's cached
    /// image (see `Gpu::cache_static`); returns what its frames need per step.
    fn cache_view<'a>(
        &mut self,
        scene: &SceneGeometry,
        slot: usize,
        cam: &'a CameraSpec,
    ) -> Result<FixedView<'a>, RenderError> {
        let job = scene.view_job(slot, cam, Shading::Lit, scene.ranges_for(cam), 0..0);
        self.gpu.cache_static(
            scene.light_vp,
            &scene.static_casters(),
            std::slice::from_ref(&job),
        )?;
        let mut view = scene.fixed_view(slot, cam);
        if let Some(depth) = self.gpu.cached_depth(slot)? {
            view.set_surface(&depth, scene.sun());
        }
        Ok(view)
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

    /// The same pixels as `draw_step` with `Shading::Lit`, drawn over the view cached
    /// by `cache_view`: only the moving bodies and the static surfaces their shadows can
    /// reach are drawn.
    fn draw_view_step(
        &mut self,
        scene: &SceneGeometry,
        sim: &Simulation,
        step: u32,
        view: &FixedView,
    ) -> Result<Vec<u8>, RenderError> {
        let dynamic = scene.dynamic_at(sim, step, false);
        let dyn_range = self.gpu.set_dynamic(&dynamic)?;
        let moving = bounds(&dynamic);
        let redraw = moving
            .map(|m| scene.shadow_redraws(view, m, &dynamic))
            .unwrap_or_default();
        let post_rects = moving
            .map(|m| scene.post_rects(view, m, &redraw))
            .unwrap_or_default();
        let job = OverlayJob {
            slot: view.slot,
            uniforms: view.uniforms,
            redraw,
            dynamic: dyn_range.clone(),
            post_rects,
        };
        let mut images =
            self.gpu
                .draw_overlay(scene.light_vp, std::slice::from_ref(&dyn_range), &[job])?;
        Ok(images.remove(0))
    }
}

/// Stage 4 for the DAG driver (`scene::run_group`): renders a valid scene's videos and
/// frames into `out` with this thread's renderer. Invalid scenes are not rendered (their
/// video columns stay null). The simulation is run again from the spec (milliseconds,
/// and identical by construction) rather than kept per group.
pub fn render_stage(
    r: &SceneResult,
    catalog: &Catalog,
    opts: &RenderOptions,
    out: &Path,
) -> Result<Option<SceneMedia>, RenderError> {
    if !r.verdicts.all() || r.spec.cameras.is_empty() {
        return Ok(None);
    }
    let sim = simulate(&r.spec, SimOptions::default());
    let rendered = with_thread_renderer(opts, |renderer| {
        renderer.render_scene(&r.spec, &sim, catalog, out)
    })
    .and_then(|x| x)?;
    Ok(Some(SceneMedia {
        videos: rendered.videos,
        full_event: rendered.full_event,
        visibility: rendered.observed.visibility,
        masks: rendered.observed.masks,
        depth: rendered.observed.depth,
    }))
}

/// The spec's observation cameras in `CAMERAS` order (an error names a missing one).
fn observation_cameras(spec: &SceneSpec) -> Result<Vec<&CameraSpec>, RenderError> {
    CAMERAS
        .iter()
        .map(|name| {
            spec.cameras
                .iter()
                .find(|c| c.name == *name)
                .ok_or_else(|| {
                    RenderError::Scene(
                        spec.scene_id.clone(),
                        format!("no '{name}' camera in the spec"),
                    )
                })
        })
        .collect()
}

/// Full-event frame `j` shows physics step `round(j / fps / dt)` (at most the last).
fn full_event_steps(sim: &Simulation, full_fps: u32) -> Vec<u32> {
    let duration = sim.steps() as f64 * sim.dt;
    let full_frames = (duration * full_fps as f64 + 1e-9).floor() as u32;
    (0..=full_frames)
        .map(|j| ((j as f64 / full_fps as f64 / sim.dt).round() as u32).min(sim.steps()))
        .collect()
}

/// Waits for an encoder and notes an error unless it wrote exactly `frames` frames.
fn finish_video(job: VideoJob, name: &str, frames: usize, errors: &mut Vec<String>) {
    match job.finish() {
        Ok(n) if n as usize == frames => {}
        Ok(n) => errors.push(format!("{name}: {n} frames written")),
        Err(e) => errors.push(format!("{name}: {e}")),
    }
}

/// A PNG frame to write: (path, width, height, RGB).
type PngJob = (PathBuf, u32, u32, Vec<u8>);

/// The RGB bytes of an RGBA image (what the PNG frames hold), made here rather than on
/// the writer's thread so that no copy of the RGBA frame waits there.
fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// A thread that writes the PNG frames sent to it (join it for the first error).
fn png_writer() -> (
    std::sync::mpsc::Sender<PngJob>,
    std::thread::JoinHandle<Result<(), String>>,
) {
    let (tx, rx) = std::sync::mpsc::channel::<PngJob>();
    let thread = std::thread::spawn(move || -> Result<(), String> {
        for (path, w, h, rgb) in rx {
            rh_contract::png::write_png(&path, &rgb, w, h, rh_contract::png::PngColor::Rgb8)?;
        }
        Ok(())
    });
    (tx, thread)
}
