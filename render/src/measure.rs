//! Measured visibility and the dense labels of the observation frames: the instance-id
//! pass (`gpu::IdPass`) at each `FRAME_TIMES` frame of every camera gives the hazard's
//! visible pixels and its unoccluded fraction ([`HazardVisibility`]), and with
//! `RenderOptions::masks` the 16-bit instance-id and depth PNGs
//! (`masks/<scene_id>/<cam>_t….png`, `depth/<scene_id>/<cam>_t….png`).
//!
//! The id pass draws exactly what the lit frame draws (the same static ranges per camera:
//! the ego camera leaves out the observer's body, as in its video), at the same physics
//! steps, with one sample per pixel and no lighting.

use super::camera::view_proj;
use super::geometry::SceneGeometry;
use super::gpu::{IdImage, IdPass, IdView};
use super::mesh::Vertex;
use super::{RenderError, Renderer, FRAME_TIMES};
use rh_catalog::Catalog;
use rh_contract::layout::{depth_path, instance, mask_path};
use rh_physics::simulate::Simulation;
use rh_physics::spec::{CameraSpec, SceneSpec};
use rh_scenes::driver::HazardVisibility;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What the id pass gave for one scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Observed {
    /// Camera name → the hazard in its observation frames.
    pub visibility: BTreeMap<String, HazardVisibility>,
    /// Camera name → mask files, `FRAME_TIMES` order (empty unless masks were asked for).
    pub masks: BTreeMap<String, Vec<String>>,
    /// Camera name → depth files, likewise.
    pub depth: BTreeMap<String, Vec<String>>,
}

/// A 16-bit grey PNG to write.
pub(super) struct Png16 {
    path: PathBuf,
    width: u32,
    height: u32,
    pixels: Vec<u16>,
}

impl Renderer {
    /// The hazard's visible pixels and unoccluded fraction in every spec camera at the
    /// observation frames (the id pass only: no videos, no files).
    pub fn measure_hazard(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        catalog: &Catalog,
    ) -> Result<BTreeMap<String, HazardVisibility>, RenderError> {
        let scene = SceneGeometry::build(spec, sim, catalog);
        self.gpu
            .reserve(scene.statics.len() + scene.max_dynamic + 1024);
        self.gpu.set_static(&scene.statics);
        let cams: Vec<&CameraSpec> = spec.cameras.iter().collect();
        let (observed, _) = self.observe(spec, sim, &scene, &cams, None)?;
        Ok(observed.visibility)
    }

    /// Runs the id pass at each observation time for `cams` over the scene already
    /// uploaded (`set_static`). With `masks_root`, also returns the mask and depth PNGs
    /// to write under it (paths relative to it in `Observed`).
    pub(super) fn observe(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        scene: &SceneGeometry,
        cams: &[&CameraSpec],
        masks_root: Option<&Path>,
    ) -> Result<(Observed, Vec<Png16>), RenderError> {
        let hazard = instance::body(spec.hazard);
        let images = self.id_images(spec, sim, scene, cams, true)?;
        let mut observed = Observed::default();
        let mut pngs = Vec::new();
        for (cam, images) in cams.iter().zip(images) {
            let mut counts = Vec::new();
            for (&t, img) in FRAME_TIMES.iter().zip(images) {
                let visible = img.ids.iter().filter(|&&id| id == hazard).count() as u32;
                counts.push((visible, img.covered));
                if let Some(root) = masks_root {
                    pngs.extend(mask_pngs(&mut observed, root, &spec.scene_id, cam, t, img));
                }
            }
            observed
                .visibility
                .insert(cam.name.clone(), HazardVisibility::from_counts(&counts));
        }
        Ok((observed, pngs))
    }

    /// The id images of each camera (`cams` order) at each `FRAME_TIMES` frame: drawn
    /// over the camera's static geometry drawn once (`cached`), or each whole (the
    /// reference the cached images are tested against). One camera at a time through
    /// one target (per worker, a 720p id target, its static image and its read-backs
    /// are about 20 MB).
    fn id_images(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        scene: &SceneGeometry,
        cams: &[&CameraSpec],
        cached: bool,
    ) -> Result<Vec<Vec<IdImage>>, RenderError> {
        let pass = match &mut self.ids {
            Some(p) => p,
            None => self.ids.insert(IdPass::new(&self.gpu)),
        };
        let hazard = instance::body(spec.hazard);
        let steps = spec.observation_frame_steps(sim.steps());
        let last = steps.len() as u32 - 1;
        // The moving geometry at each observation frame, uploaded again per camera.
        let moving: Vec<Vec<Vertex>> = FRAME_TIMES
            .iter()
            .map(|&t| {
                let k = ((t * spec.video.fps as f64).round() as u32).min(last);
                scene.dynamic_at(sim, steps[k as usize], false)
            })
            .collect();
        let mut out = Vec::new();
        for cam in cams {
            let statics = scene.id_ranges_for(cam);
            let view = |ranges: Vec<(Range<u32>, u16)>, alone| IdView {
                slot: 0,
                width: cam.width,
                height: cam.height,
                view_proj: view_proj(cam),
                cam_pos: cam.position.map(|c| c as f32),
                ranges,
                alone,
            };
            if cached {
                self.gpu
                    .cache_static_ids(pass, &view(statics.clone(), Vec::new()))?;
            }
            let mut images = Vec::new();
            for dynamic in &moving {
                let dyn_range = self.gpu.set_dynamic(dynamic)?;
                let dyn_ids = scene.dynamic_ids(&dyn_range);
                let alone = statics
                    .iter()
                    .chain(&dyn_ids)
                    .filter(|(_, id)| *id == hazard)
                    .map(|(r, _)| r.clone())
                    .collect();
                images.push(if cached {
                    self.gpu.draw_ids_over(pass, &view(dyn_ids, alone))?
                } else {
                    let all = statics.iter().chain(&dyn_ids).cloned().collect();
                    self.gpu.draw_ids(pass, &[view(all, alone)])?.remove(0)
                });
            }
            out.push(images);
        }
        Ok(out)
    }
}

/// Records one frame's mask and depth files in `observed` and returns them to write.
fn mask_pngs(
    observed: &mut Observed,
    root: &Path,
    scene_id: &str,
    cam: &CameraSpec,
    t: f64,
    img: IdImage,
) -> [Png16; 2] {
    let (m, d) = (
        mask_path(scene_id, &cam.name, t),
        depth_path(scene_id, &cam.name, t),
    );
    let png = |rel: &str, pixels| Png16 {
        path: root.join(rel),
        width: img.width,
        height: img.height,
        pixels,
    };
    let pngs = [png(&m, img.ids), png(&d, img.depth_mm)];
    observed.masks.entry(cam.name.clone()).or_default().push(m);
    observed.depth.entry(cam.name.clone()).or_default().push(d);
    pngs
}

/// Writes the PNGs on a thread of their own (while the lit frames render); join it for
/// the first error.
pub(super) fn write_pngs(pngs: Vec<Png16>) -> std::thread::JoinHandle<Result<(), String>> {
    std::thread::spawn(move || pngs.iter().try_for_each(write_png16))
}

/// A 16-bit greyscale PNG, written atomically.
fn write_png16(p: &Png16) -> Result<(), String> {
    rh_contract::png::write_png(
        &p.path,
        bytemuck::cast_slice(&p.pixels),
        p.width,
        p.height,
        rh_contract::png::PngColor::L16,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RenderOptions;
    use rh_physics::simulate::{simulate, SimOptions};
    use rh_scenes::config::Config;
    use rh_scenes::driver::produce_group;
    use rh_scenes::selection::plan_group;

    /// The id images drawn over each camera's static geometry drawn once equal the
    /// whole-scene id images (ids, depth, coverage) pixel for pixel, at 720p.
    #[test]
    fn cached_static_id_images_equal_whole_scene_ones() {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let families = config.build.families.clone();
        let opts = RenderOptions::from_config(&config.render);
        let mut renderer = Renderer::new(opts).expect("a Vulkan adapter (lavapipe)");
        let (mut scenes, mut hazard_pixels) = (0, 0);
        for g in 0..4u64 {
            let selection = plan_group(&catalog, &families, 5, g).unwrap();
            let r = produce_group(&selection, 5, g * 4, 1, &catalog, &config).unwrap();
            let spec = &r[0].spec;
            if spec.cameras.is_empty() {
                continue;
            }
            let sim = simulate(spec, SimOptions::default());
            let scene = SceneGeometry::build(spec, &sim, &catalog);
            renderer
                .gpu
                .reserve(scene.statics.len() + scene.max_dynamic + 1024);
            renderer.gpu.set_static(&scene.statics);
            let cams: Vec<&CameraSpec> = spec.cameras.iter().collect();
            let cached = renderer.id_images(spec, &sim, &scene, &cams, true).unwrap();
            let whole = renderer
                .id_images(spec, &sim, &scene, &cams, false)
                .unwrap();
            let hazard = instance::body(spec.hazard);
            for (a, b) in cached.iter().flatten().zip(whole.iter().flatten()) {
                assert!(a.ids == b.ids, "{}: ids differ", spec.scene_id);
                assert!(a.depth_mm == b.depth_mm, "{}: depth differs", spec.scene_id);
                assert_eq!(a.covered, b.covered, "{}", spec.scene_id);
                hazard_pixels += a.ids.iter().filter(|&&id| id == hazard).count();
            }
            assert_eq!(
                cached.iter().flatten().count(),
                cams.len() * FRAME_TIMES.len()
            );
            scenes += 1;
        }
        assert!(scenes >= 3, "{scenes} scenes framed");
        assert!(
            hazard_pixels > 0,
            "the moving hazard is drawn over the static images"
        );
    }
}
