//! Measured visibility and the dense labels (issue 12, items 3 and 4), on lavapipe:
//!
//! * one scene of every family at the configured resolution, the instance-id pass only
//!   (no videos): every model-input frame (each camera at each observation time) shows
//!   at least `validators.visible_px_min` hazard pixels — the geometric visibility rule
//!   of the label stage really implies visibility;
//! * a small scene rendered with masks: the instance-id and depth PNGs read back as
//!   16-bit images of the frame size, the hazard's id covers exactly the pixels the
//!   `visible_px` measurement counted, and the depth of its pixels is its distance
//!   from the camera in the spec (within its bounding radius).

use rh_catalog::Catalog;
use rh_contract::layout::{depth_path, instance, mask_path};
use rh_physics::simulate::{simulate, SimOptions, Simulation};
use rh_physics::spec::SceneSpec;
use rh_render::{RenderOptions, Renderer, CAMERAS, FRAME_TIMES};
use rh_scenes::config::Config;
use rh_scenes::driver::plan_and_produce;
use std::fmt::Write;
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

const SEED: u64 = 12;

fn renderer() -> &'static Mutex<Renderer> {
    static R: OnceLock<Mutex<Renderer>> = OnceLock::new();
    R.get_or_init(|| {
        let opts = RenderOptions::from_config(&Config::embedded().unwrap().render);
        Mutex::new(Renderer::new(opts).expect("a Vulkan adapter (lavapipe) for rendering"))
    })
}

/// Scene `band` of group `g` (families dealt round-robin), labelled and validated.
fn scene(config: &Config, catalog: &Catalog, g: u64, band: u64) -> (SceneSpec, Simulation, bool) {
    let families = config.build.families.clone();
    // As a build: the whole group (one observer pose and camera set for its bands), replanned
    // if no attempt passes.
    let (r, _) = plan_and_produce(catalog, &families, None, SEED, g, 4, config).unwrap();
    let r = &r[band as usize];
    let sim = simulate(&r.spec, SimOptions::default());
    (r.spec.clone(), sim, r.verdicts.all())
}

#[test]
fn every_model_input_frame_shows_the_hazard_in_every_family() {
    let config = Config::embedded().unwrap();
    let catalog = Catalog::embedded().unwrap();
    let min = config.validators.visible_px_min;
    let mut r = renderer().lock().unwrap();
    let mut table = String::new();
    let mut failures = Vec::new();
    for (g, family) in config.build.families.iter().enumerate() {
        // One band per family, rotating so that every band is exercised.
        let (spec, sim, valid) = scene(&config, &catalog, g as u64, g as u64 % 4);
        assert_eq!(&spec.family, family);
        if !valid || spec.cameras.is_empty() {
            failures.push(format!("{family} {}: not a valid scene", spec.scene_id));
            continue;
        }
        let vis = r.measure_hazard(&spec, &sim, &catalog).unwrap();
        for cam in CAMERAS {
            let v = &vis[cam];
            let _ = writeln!(
                table,
                "{family:16} {} {:8} {} px={:?} unoccluded={:?}",
                spec.scene_id,
                cam,
                spec.speed_band.name(),
                v.visible_px,
                v.unoccluded
                    .iter()
                    .map(|f| format!("{f:.2}"))
                    .collect::<Vec<_>>()
            );
            for (i, &px) in v.visible_px.iter().enumerate() {
                if px < min {
                    failures.push(format!(
                        "{family} {} {cam} t={:.2}: {px} px (need {min}), unoccluded {:.2}",
                        spec.scene_id, FRAME_TIMES[i], v.unoccluded[i]
                    ));
                }
            }
        }
    }
    eprintln!("hazard pixels per model-input frame (seed {SEED}):\n{table}");
    assert!(
        failures.is_empty(),
        "{} model-input frame(s) show the hazard below {min} px:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

fn read_luma16(path: &std::path::Path) -> image::ImageBuffer<image::Luma<u16>, Vec<u16>> {
    match image::open(path).unwrap() {
        image::DynamicImage::ImageLuma16(img) => img,
        other => panic!("{}: {:?}, not 16-bit grey", path.display(), other.color()),
    }
}

#[test]
fn masks_and_depth_read_back_and_agree_with_the_spec() {
    let mut config = Config::embedded().unwrap();
    config.render.width = 320;
    config.render.height = 180;
    config.render.full_width = 160;
    config.render.full_height = 96;
    let catalog = Catalog::embedded().unwrap();
    let (spec, sim, valid) = scene(&config, &catalog, 0, 1); // object_drop
    assert!(valid && !spec.cameras.is_empty());
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("masks-test");
    let _ = std::fs::remove_dir_all(&dir);
    let opts = RenderOptions {
        masks: true,
        ..RenderOptions::from_config(&config.render)
    };
    let mut masked = Renderer::new(opts).unwrap();
    let rendered = masked.render_scene(&spec, &sim, &catalog, &dir).unwrap();
    let hazard = instance::body(spec.hazard);
    let radius = spec.hazard_body().bounding_radius();
    let steps = spec.observation_frame_steps(sim.steps());
    let mut hazard_seen = 0;
    for cam in &spec.cameras {
        let vis = &rendered.observed.visibility[&cam.name];
        assert_eq!(rendered.observed.masks[&cam.name].len(), FRAME_TIMES.len());
        for (i, &t) in FRAME_TIMES.iter().enumerate() {
            let m = mask_path(&spec.scene_id, &cam.name, t);
            let d = depth_path(&spec.scene_id, &cam.name, t);
            assert_eq!(rendered.observed.masks[&cam.name][i], m);
            assert_eq!(rendered.observed.depth[&cam.name][i], d);
            let (ids, depth) = (read_luma16(&dir.join(&m)), read_luma16(&dir.join(&d)));
            assert_eq!(ids.dimensions(), (cam.width, cam.height), "{m}");
            assert_eq!(depth.dimensions(), (cam.width, cam.height), "{d}");
            // The mask's hazard pixels are the ones the measurement counted.
            let hazard_px: Vec<u16> = ids
                .pixels()
                .zip(depth.pixels())
                .filter(|(id, _)| id[0] == hazard)
                .map(|(_, d)| d[0])
                .collect();
            assert_eq!(hazard_px.len() as u32, vis.visible_px[i], "{m}");
            // Every pixel that shows a surface has a depth; the room is there.
            assert!(ids
                .pixels()
                .zip(depth.pixels())
                .all(|(id, d)| id[0] == instance::ROOM || d[0] > 0));
            if hazard_px.is_empty() {
                continue;
            }
            hazard_seen += 1;
            // Depth: the hazard's surface lies within its bounding sphere, so each of its
            // pixels is at most `radius` nearer or farther than its centre; the nearest
            // is nearer than the centre.
            let k = ((t * spec.video.fps as f64).round() as usize).min(steps.len() - 1);
            let c = sim.hazard_com(steps[k]);
            let p = cam.position;
            let dist = ((c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2) + (c[2] - p[2]).powi(2))
                .sqrt()
                * 1000.0;
            let tol = radius * 1000.0 + 5.0;
            let (lo, hi) = (
                *hazard_px.iter().min().unwrap() as f64,
                *hazard_px.iter().max().unwrap() as f64,
            );
            assert!(
                lo >= dist - tol && hi <= dist + tol && lo < dist,
                "{m}: hazard depth {lo}..{hi} mm, centre at {dist:.0} mm, radius {:.0} mm",
                radius * 1000.0
            );
        }
    }
    assert!(
        hazard_seen >= 10,
        "the hazard shows in only {hazard_seen} frames"
    );
    // The observer is drawn in the outside cameras, never in the ego camera.
    let ego = read_luma16(&dir.join(mask_path(&spec.scene_id, "ego", 0.0)));
    assert!(ego.pixels().all(|p| p[0] != instance::OBSERVER));
    // Rendering again gives the same bytes.
    let again = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("masks-test-again");
    let _ = std::fs::remove_dir_all(&again);
    masked.render_scene(&spec, &sim, &catalog, &again).unwrap();
    for cam in CAMERAS {
        for &t in &FRAME_TIMES {
            for rel in [
                mask_path(&spec.scene_id, cam, t),
                depth_path(&spec.scene_id, cam, t),
            ] {
                assert!(
                    std::fs::read(dir.join(&rel)).unwrap()
                        == std::fs::read(again.join(&rel)).unwrap(),
                    "{rel} differs between two renders"
                );
            }
        }
    }
}
