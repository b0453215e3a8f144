//! Render throughput at the paper spec: three cameras at 1280×720 / 60 fps over the
//! observation window plus the full-event video, per scene, on this machine.
//!
//! `cargo bench -p rh-pipeline --bench render_throughput [-- N]` (N scenes, default 4).
//! `RH_BENCH_PRESET`, `RH_BENCH_THREADS`, `RH_BENCH_MSAA` override the encoder preset,
//! x264 threads per video and MSAA samples.

use rh_catalog::Catalog;
use rh_pipeline::config::Config;
use rh_pipeline::plan::plan_group;
use rh_pipeline::render::{RenderOptions, Renderer};
use rh_pipeline::scene::produce_group;
use rh_pipeline::simulate::{simulate, SimOptions};
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(4);
    let catalog = Catalog::embedded().unwrap();
    let mut config = Config::embedded().unwrap();
    if let Ok(p) = std::env::var("RH_BENCH_PRESET") {
        config.render.preset = p;
    }
    if let Some(t) = std::env::var("RH_BENCH_THREADS")
        .ok()
        .and_then(|t| t.parse().ok())
    {
        config.render.encoder_threads = t;
    }
    if let Some(m) = std::env::var("RH_BENCH_MSAA")
        .ok()
        .and_then(|t| t.parse().ok())
    {
        config.render.msaa = m;
    }
    let families = config.build.families.clone();
    let mut scenes = Vec::new();
    for g in 0..n as u64 {
        let selection = plan_group(&catalog, &families, 5, g).unwrap();
        let r = produce_group(&selection, 5, g * 4, 1, &catalog, &config).unwrap();
        let spec = r[0].spec.clone();
        if spec.cameras.is_empty() {
            continue;
        }
        let sim = simulate(&spec, SimOptions::default());
        scenes.push((spec, sim));
    }
    let opts = RenderOptions::from_config(&config.render);
    let t = Instant::now();
    let mut renderer = Renderer::new(opts.clone()).expect("a Vulkan adapter");
    let setup = t.elapsed().as_secs_f64();
    let dir = std::env::temp_dir().join(format!("rh-render-bench-{}", std::process::id()));
    let mut total = 0.0;
    let mut frames = 0usize;
    for (spec, sim) in &scenes {
        let t = Instant::now();
        let r = renderer.render_scene(spec, sim, &catalog, &dir).unwrap();
        let s = t.elapsed().as_secs_f64();
        total += s;
        frames += 3 * r.frame_steps.len() + r.full_event_steps.len();
        println!(
            "{} {:<16} {:.2} s ({} window frames x3 at {}x{}, {} full-event frames at {}x{}/{} fps)",
            spec.scene_id,
            spec.family,
            s,
            r.frame_steps.len(),
            spec.video.width,
            spec.video.height,
            r.full_event_steps.len(),
            opts.full_width,
            opts.full_height,
            opts.full_fps
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "render_throughput: {:.2} s/scene over {} scenes ({:.1} frames/s rendered+encoded; adapter {}, setup {:.2} s, preset {}, msaa {}, x264 threads {})",
        total / scenes.len().max(1) as f64,
        scenes.len(),
        frames as f64 / total.max(1e-9),
        renderer.adapter_name(),
        setup,
        opts.encode.preset,
        opts.msaa,
        opts.encode.threads
    );
}
