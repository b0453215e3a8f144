//! Render stage (issue 4): videos that ffprobe agrees with, PNG frames equal to the
//! video's frames, the picture agreeing with the camera model, and the contact sheet.
//!
//! One small render (320×180, three families) is shared by the tests.

use rh_catalog::Catalog;
use rh_contract::fsio::write_atomic;
use rh_physics::simulate::{simulate, SimOptions, Simulation};
use rh_physics::spec::SceneSpec;
use rh_render::{
    contact_sheet, frame_file_name, RenderOptions, RenderedScene, Renderer, Shading, SheetTile,
    CAMERAS, FRAME_TIMES, HAZARD_MASK_RGB,
};
use rh_scenes::config::Config;
use rh_scenes::driver::{full_event_simulation, produce_group};
use rh_scenes::selection::plan_group;
use rh_scenes::view::View;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, OnceLock};

const FAMILIES: [&str; 3] = ["object_drop", "rolling_ball", "thrown_object"];
const W: u32 = 320;
const H: u32 = 180;

struct Fixture {
    dir: PathBuf,
    scenes: Vec<(SceneSpec, Simulation, RenderedScene)>,
    options: RenderOptions,
}

fn small_config() -> Config {
    let mut config = Config::embedded().unwrap();
    config.render.width = W;
    config.render.height = H;
    config.render.full_width = W;
    config.render.full_height = H;
    config
}

fn scene_of(family: &str, config: &Config, catalog: &Catalog) -> (SceneSpec, Simulation) {
    let families: Vec<String> = FAMILIES.iter().map(|s| s.to_string()).collect();
    let fi = families.iter().position(|f| f == family).unwrap() as u64;
    let selection = plan_group(catalog, &families, 11, fi).unwrap();
    let results = produce_group(&selection, 11, fi * 4, 1, catalog, config).unwrap();
    let spec = results[0].spec.clone();
    assert!(!spec.cameras.is_empty(), "{family}: framing failed");
    let sim = simulate(&spec, SimOptions::default());
    (spec, sim)
}

fn renderer() -> &'static Mutex<Renderer> {
    static R: OnceLock<Mutex<Renderer>> = OnceLock::new();
    R.get_or_init(|| {
        let opts = RenderOptions::from_config(&small_config().render);
        Mutex::new(Renderer::new(opts).expect("a Vulkan adapter (lavapipe) for rendering"))
    })
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let config = small_config();
        let catalog = Catalog::embedded().unwrap();
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("render-test");
        let _ = std::fs::remove_dir_all(&dir);
        let mut r = renderer().lock().unwrap();
        let mut scenes = Vec::new();
        for family in FAMILIES {
            let (spec, sim) = scene_of(family, &config, &catalog);
            write_atomic(
                &dir.join(format!("specs/{}.json", spec.scene_id)),
                spec.to_json().as_bytes(),
            )
            .unwrap();
            let rendered = r.render_scene(&spec, &sim, &catalog, &dir).unwrap();
            scenes.push((spec, sim, rendered));
        }
        Fixture {
            dir,
            scenes,
            options: RenderOptions::from_config(&config.render),
        }
    })
}

fn ffprobe(path: &Path) -> serde_json::Value {
    let out = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-select_streams",
            "v:0",
            "-count_frames",
            "-show_entries",
            "stream=codec_name,pix_fmt,width,height,r_frame_rate,avg_frame_rate,nb_read_frames",
            "-of",
            "json",
        ])
        .arg(path)
        .output()
        .expect("ffprobe on PATH");
    assert!(
        out.status.success(),
        "ffprobe {}: {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["streams"][0].clone()
}

#[test]
fn every_video_has_the_stated_codec_size_rate_and_frame_count() {
    let f = fixture();
    for (spec, _, r) in &f.scenes {
        let mut videos: Vec<(String, u32, u32, u32, usize)> = CAMERAS
            .iter()
            .map(|c| {
                (
                    r.video(c).unwrap().to_string(),
                    spec.video.width,
                    spec.video.height,
                    spec.video.fps,
                    r.frame_steps.len(),
                )
            })
            .collect();
        videos.push((
            r.full_event.clone(),
            f.options.full_width,
            f.options.full_height,
            f.options.full_fps,
            r.full_event_steps.len(),
        ));
        let expected_frames =
            (spec.observation_window_s * spec.video.fps as f64).round() as usize + 1;
        assert_eq!(r.frame_steps.len(), expected_frames);
        for (k, &s) in r.frame_steps.iter().enumerate() {
            assert_eq!(s, spec.frame_step(k as u32));
        }
        for (rel, w, h, fps, frames) in videos {
            let path = f.dir.join(&rel);
            let s = ffprobe(&path);
            assert_eq!(s["codec_name"], "h264", "{rel}");
            assert_eq!(s["pix_fmt"], "yuv420p", "{rel}");
            assert_eq!(s["width"], w, "{rel}");
            assert_eq!(s["height"], h, "{rel}");
            assert_eq!(s["r_frame_rate"], format!("{fps}/1"), "{rel}");
            assert_eq!(s["avg_frame_rate"], format!("{fps}/1"), "{rel}");
            assert_eq!(s["nb_read_frames"], frames.to_string(), "{rel}");
            // Browser-playable: the index (moov) precedes the media data (faststart).
            let bytes = std::fs::read(&path).unwrap();
            let find = |tag: &[u8]| bytes.windows(4).position(|w| w == tag).unwrap();
            assert!(find(b"moov") < find(b"mdat"), "{rel}: not faststart");
        }
    }
    // No temporary files left behind.
    let mut stack = vec![f.dir.clone()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                assert!(!p.to_string_lossy().contains(".tmp"), "{}", p.display());
            }
        }
    }
}

/// All frames of a video as RGB24 (ffmpeg CLI).
fn decode(path: &Path, w: u32, h: u32) -> Vec<Vec<u8>> {
    let out = Command::new("ffmpeg")
        .args(["-v", "error", "-i"])
        .arg(path)
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-"])
        .output()
        .expect("ffmpeg on PATH");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
        .chunks_exact((w * h * 3) as usize)
        .map(|c| c.to_vec())
        .collect()
}

/// The full-event video shows the counterfactual run (`scene::full_event_simulation`,
/// the observer as a body) to its end; the observation videos the plain run.
#[test]
fn the_full_event_video_shows_the_counterfactual_run_to_its_end() {
    let f = fixture();
    for (spec, sim, r) in &f.scenes {
        let full = full_event_simulation(spec, sim);
        let full_steps = full.as_ref().map_or(sim.steps(), |s| s.steps());
        let duration = full_steps as f64 * sim.dt;
        let frames = (duration * f.options.full_fps as f64 + 1e-9).floor() as usize + 1;
        assert_eq!(r.full_event_steps.len(), frames, "{}", spec.scene_id);
        assert_eq!(
            *r.full_event_steps.last().unwrap() as f64,
            (((frames - 1) as f64 / f.options.full_fps as f64 / sim.dt).round())
                .min(full_steps as f64),
            "{}",
            spec.scene_id
        );
    }
}

#[test]
fn png_frames_decode_and_match_the_video_at_the_same_time() {
    let f = fixture();
    for (spec, _, r) in &f.scenes {
        assert_eq!(r.frames.len(), CAMERAS.len() * FRAME_TIMES.len());
        for (ci, cam) in CAMERAS.iter().enumerate() {
            let video = decode(&f.dir.join(r.video(cam).unwrap()), W, H);
            assert_eq!(video.len(), r.frame_steps.len());
            for (ti, &t) in FRAME_TIMES.iter().enumerate() {
                let rel = &r.frames[ci * FRAME_TIMES.len() + ti];
                assert_eq!(
                    rel,
                    &format!("frames/{}/{}", spec.scene_id, frame_file_name(cam, t))
                );
                let png = image::open(f.dir.join(rel)).unwrap().to_rgb8();
                assert_eq!((png.width(), png.height()), (W, H));
                let k = (t * spec.video.fps as f64).round() as usize;
                let mad = png
                    .as_raw()
                    .iter()
                    .zip(&video[k])
                    .map(|(a, b)| (*a as i32 - *b as i32).unsigned_abs() as u64)
                    .sum::<u64>() as f64
                    / png.as_raw().len() as f64;
                assert!(
                    mad < 6.0,
                    "{rel}: mean abs diff {mad:.2} vs video frame {k}"
                );
                // And it is not some other frame: a different time differs more (when
                // anything moved), or at least as much.
                if k > 0 {
                    let other = png
                        .as_raw()
                        .iter()
                        .zip(&video[0])
                        .map(|(a, b)| (*a as i32 - *b as i32).unsigned_abs() as u64)
                        .sum::<u64>() as f64
                        / png.as_raw().len() as f64;
                    assert!(
                        other + 0.5 >= mad,
                        "{rel}: frame 0 matches better ({other:.2} < {mad:.2})"
                    );
                }
            }
        }
    }
}

#[test]
fn hazard_pixels_agree_with_the_camera_model() {
    let f = fixture();
    let catalog = Catalog::embedded().unwrap();
    let mut r = renderer().lock().unwrap();
    let mut checked = 0;
    for (spec, sim, rendered) in &f.scenes {
        let visible = r.hazard_pixels(spec, sim, &catalog, 0).unwrap();
        assert_eq!(visible.len(), spec.cameras.len());
        assert!(
            visible.iter().any(|(_, n)| *n > 0),
            "{}: {visible:?}",
            spec.scene_id
        );
        for &step in [
            rendered.frame_steps[0],
            rendered.frame_steps[rendered.frame_steps.len() / 2],
        ]
        .iter()
        {
            let images = r
                .render_frame(
                    spec,
                    sim,
                    &catalog,
                    &spec.cameras,
                    step,
                    Shading::HazardMask,
                )
                .unwrap();
            for (cam, img) in spec.cameras.iter().zip(&images) {
                let view = View::new(cam).unwrap();
                let Some([x, y]) = view.project(sim.hazard_position(step)) else {
                    continue;
                };
                if x.abs() > 0.95 || y.abs() > 0.95 {
                    continue;
                }
                let px = ((x + 1.0) / 2.0 * cam.width as f64) as i64;
                let py = ((1.0 - y) / 2.0 * cam.height as f64) as i64;
                let is_mask = |p: &image::Rgba<u8>| {
                    (p[0] as i32 - HAZARD_MASK_RGB[0] as i32).abs() < 8
                        && (p[1] as i32 - HAZARD_MASK_RGB[1] as i32).abs() < 8
                        && (p[2] as i32 - HAZARD_MASK_RGB[2] as i32).abs() < 8
                };
                let mask: Vec<(i64, i64)> = img
                    .enumerate_pixels()
                    .filter(|(_, _, p)| is_mask(p))
                    .map(|(x, y, _)| (x as i64, y as i64))
                    .collect();
                assert!(
                    !mask.is_empty(),
                    "{} {} step {step}: hazard not visible",
                    spec.scene_id,
                    cam.name
                );
                let near = mask
                    .iter()
                    .any(|&(mx, my)| (mx - px).abs() <= 1 && (my - py).abs() <= 1);
                // The hazard may be partly hidden (behind the observer's hand, say): then
                // its projected centre must still sit inside the mask's bounding box.
                let (x0, x1) = (
                    mask.iter().map(|m| m.0).min().unwrap(),
                    mask.iter().map(|m| m.0).max().unwrap(),
                );
                let (y0, y1) = (
                    mask.iter().map(|m| m.1).min().unwrap(),
                    mask.iter().map(|m| m.1).max().unwrap(),
                );
                assert!(
                    near || (px >= x0 - 1 && px <= x1 + 1 && py >= y0 - 1 && py <= y1 + 1),
                    "{} {} step {step}: projected centre ({px}, {py}) outside the hazard mask [{x0}..{x1}]×[{y0}..{y1}]",
                    spec.scene_id,
                    cam.name
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 12, "only {checked} views checked");
}

#[test]
fn contact_sheet_draws_every_tile_with_its_frame() {
    let f = fixture();
    let out = f.dir.join("sheet.png");
    let tiles: Vec<SheetTile> = f
        .scenes
        .iter()
        .map(|(spec, _, _)| SheetTile {
            family: spec.family.clone(),
            scene_id: spec.scene_id.clone(),
            frame: f
                .dir
                .join(rh_contract::layout::frame_path(&spec.scene_id, "ego", 0.30)),
            lines: [spec.family.clone(), "ego t 0.30 s".into()],
        })
        .collect();
    let sheet = contact_sheet("ego frames", &tiles).unwrap();
    std::fs::write(&out, &sheet.png).unwrap();
    let families: Vec<&str> = sheet.tiles.iter().map(|t| t.0.as_str()).collect();
    assert_eq!(families, FAMILIES.to_vec());
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (sheet.width, sheet.height));
    // The frames are drawn (the sheet is far from its dark background: 24, 24, 28).
    let mean = |img: &image::RgbImage| {
        let sum: u64 = img.pixels().flat_map(|p| p.0).map(|c| c as u64).sum();
        sum / (img.width() as u64 * img.height() as u64)
    };
    assert!(
        mean(&img) > 76 + 40,
        "sheet mean {} (background 76)",
        mean(&img)
    );
    // Nothing to draw is an error.
    let err = contact_sheet("none", &[]).unwrap_err().to_string();
    assert!(err.contains("nothing to draw"), "{err}");
}

/// Writes PNG previews (ego, closeup, overhead, full-event view at t = 0.30 s) of one
/// scene per family for a person to look at:
/// `RH_PREVIEW_DIR=/tmp/p cargo test --release -p rh-pipeline --test render -- --ignored preview`
/// (`RH_PREVIEW_FAMILIES=a,b` and `RH_PREVIEW_SEED` narrow it down).
#[test]
#[ignore]
fn preview() {
    use rh_render::full_event_camera;
    let out = PathBuf::from(std::env::var("RH_PREVIEW_DIR").unwrap_or("/tmp/rh_preview".into()));
    let seed: u64 = std::env::var("RH_PREVIEW_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let catalog = Catalog::embedded().unwrap();
    let mut config = Config::embedded().unwrap();
    config.render.width = 640;
    config.render.height = 360;
    let families: Vec<String> = match std::env::var("RH_PREVIEW_FAMILIES") {
        Ok(list) => list.split(',').map(String::from).collect(),
        Err(_) => config.build.families.clone(),
    };
    let mut renderer = Renderer::new(RenderOptions::from_config(&config.render)).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    for (g, family) in families.iter().enumerate() {
        let fams = vec![family.clone()];
        let selection = plan_group(&catalog, &fams, seed, g as u64).unwrap();
        let r = produce_group(&selection, seed, g as u64 * 4, 1, &catalog, &config).unwrap();
        let spec = r[0].spec.clone();
        if spec.cameras.is_empty() {
            eprintln!("{family}: no cameras");
            continue;
        }
        let sim = simulate(&spec, SimOptions::default());
        let mut cams = spec.cameras.clone();
        cams.push(full_event_camera(&spec, &sim, 640, 360));
        let step = spec.frame_step(18);
        let images = renderer
            .render_frame(&spec, &sim, &catalog, &cams, step, Shading::Lit)
            .unwrap();
        for (cam, img) in cams.iter().zip(images) {
            img.save(out.join(format!("{family}_{}_{}.png", selection.object_id, cam.name)))
                .unwrap();
        }
        println!("{family}: {} ({})", selection.object_id, spec.scene_id);
    }
}

/// `render_scene` draws each frame over a cached image of the static scene, redrawing
/// static surfaces only where moving bodies can cast shadows. The observation frames
/// it writes must be pixel-identical to drawing the whole scene from scratch, in every
/// family (each has its own moving geometry, heights and shadow directions).
/// Four samples: the harder case for the redraw rectangles (multisampled scissor edges),
/// what a GPU draws.
#[test]
fn cached_static_frames_equal_whole_scene_frames_in_every_family() {
    cached_frames_equal_whole_frames(4, false);
}

/// The same with one sample and FXAA, what lavapipe draws: redraws re-shade only the
/// pixels whose cached surface lies in the moving casters' shadow sweep (`fs_mark`),
/// and the two-pass FXAA is redone around what changed.
#[test]
fn cached_static_frames_equal_whole_scene_frames_without_msaa() {
    cached_frames_equal_whole_frames(1, true);
}

/// The same at the default 1280×720 (one sample, FXAA) for the first families: small
/// frames miss what large ones show, e.g. two triangles of one piece at the same depth
/// along an edge (the re-shade must keep the one the static image kept).
#[test]
fn cached_static_frames_equal_whole_scene_frames_at_720p() {
    let config = Config::embedded().unwrap();
    assert_eq!((config.render.width, config.render.height), (1280, 720));
    cached_frames_equal_whole_frames_in(config, 1, true, 3);
}

fn cached_frames_equal_whole_frames(samples: u32, fxaa: bool) {
    let mut config = small_config();
    config.render.width = 192;
    config.render.height = 108;
    cached_frames_equal_whole_frames_in(config, samples, fxaa, 17);
}

/// Every observation frame of the first `families` families' first framed scenes, drawn
/// over the cached static image, equals the whole-scene render of that step.
fn cached_frames_equal_whole_frames_in(
    mut config: Config,
    samples: u32,
    fxaa: bool,
    families: usize,
) {
    config.render.msaa = samples;
    config.render.msaa_cpu = samples;
    config.render.fxaa = fxaa;
    let mut r = Renderer::new(RenderOptions::from_config(&config.render)).unwrap();
    assert_eq!(r.samples(), samples);
    let catalog = Catalog::embedded().unwrap();
    let all = config.build.families.clone();
    assert_eq!(all.len(), 17);
    let families = &all[..families];
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "render-cache-test-{samples}-{}",
        config.render.width
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let mut compared = 0;
    for (fi, family) in families.iter().enumerate() {
        // The family's first group whose scene has cameras (a valid draw): no family is
        // skipped — one without any in five groups fails the test.
        let spec = (0..5u64)
            .map(|k| {
                let g = fi as u64 + 17 * k;
                let selection = plan_group(&catalog, std::slice::from_ref(family), 23, g).unwrap();
                produce_group(&selection, 23, g * 4, 1, &catalog, &config)
                    .unwrap()
                    .remove(0)
                    .spec
            })
            .find(|spec| !spec.cameras.is_empty())
            .unwrap_or_else(|| panic!("{family}: no framed scene in five groups"));
        let spec = &spec;
        let sim = simulate(spec, SimOptions::default());
        let rendered = r.render_scene(spec, &sim, &catalog, &dir).unwrap();
        for (ti, &t) in FRAME_TIMES.iter().enumerate() {
            let k = (t * spec.video.fps as f64).round() as usize;
            let step = rendered.frame_steps[k];
            let whole = r
                .render_frame(spec, &sim, &catalog, &spec.cameras, step, Shading::Lit)
                .unwrap();
            for (ci, cam) in CAMERAS.iter().enumerate() {
                let in_spec = spec.cameras.iter().position(|c| c.name == *cam).unwrap();
                let rel = &rendered.frames[ci * FRAME_TIMES.len() + ti];
                let png = image::open(dir.join(rel)).unwrap().to_rgb8();
                let reference = image::DynamicImage::ImageRgba8(whole[in_spec].clone()).to_rgb8();
                let differing = png
                    .pixels()
                    .zip(reference.pixels())
                    .filter(|(a, b)| a != b)
                    .count();
                assert_eq!(
                    differing, 0,
                    "{family} {rel}: {differing} pixels differ from the whole-scene render at step {step}"
                );
                compared += 1;
            }
        }
    }
    assert_eq!(
        compared,
        families.len() * 15,
        "every family, every observation frame"
    );
}

/// The default video size (1280×720 at 60 fps, what a build writes unless configured
/// otherwise) probed on one scene: ffprobe agrees on codec, pixel format, size, rate and
/// frame count.
#[test]
fn default_720p_video_probes_as_stated() {
    let config = Config::embedded().unwrap();
    assert_eq!(
        (config.render.width, config.render.height, config.render.fps),
        (1280, 720, 60)
    );
    let catalog = Catalog::embedded().unwrap();
    let families = vec!["object_drop".to_string()];
    let selection = plan_group(&catalog, &families, 5, 0).unwrap();
    let spec = produce_group(&selection, 5, 0, 1, &catalog, &config)
        .unwrap()
        .remove(0)
        .spec;
    assert!(!spec.cameras.is_empty());
    let sim = simulate(&spec, SimOptions::default());
    let mut r = Renderer::new(RenderOptions::from_config(&config.render)).unwrap();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("render-720p-test");
    let _ = std::fs::remove_dir_all(&dir);
    let rendered = r.render_scene(&spec, &sim, &catalog, &dir).unwrap();
    for cam in CAMERAS {
        let v = ffprobe(&dir.join(rendered.video(cam).unwrap()));
        assert_eq!(v["codec_name"], "h264", "{cam}");
        assert_eq!(v["pix_fmt"], "yuv420p", "{cam}");
        assert_eq!(
            (v["width"].as_u64(), v["height"].as_u64()),
            (Some(1280), Some(720)),
            "{cam}"
        );
        assert_eq!(v["r_frame_rate"], "60/1", "{cam}");
        assert_eq!(v["nb_read_frames"].as_str(), Some("37"), "{cam}");
    }
    let full = ffprobe(&dir.join(&rendered.full_event));
    assert_eq!(
        (full["width"].as_u64(), full["height"].as_u64()),
        (Some(640), Some(360))
    );
    let png = image::open(dir.join(&rendered.frames[0])).unwrap();
    assert_eq!((png.width(), png.height()), (1280, 720));
}
