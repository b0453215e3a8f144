//! Render throughput at the paper spec: three cameras at 1280×720 / 60 fps over the
//! observation window plus the full-event video, per scene, on this machine, rendered
//! the way `build` renders them (one renderer per worker thread, `--jobs` workers).
//!
//! `cargo bench -p rh-pipeline --bench render_throughput [-- N]` (N scenes, default 8,
//! taken round-robin over the families). Environment overrides: `RH_BENCH_JOBS`
//! (workers; default: all cores), `RH_BENCH_PRESET`, `RH_BENCH_THREADS` (x264 threads
//! per video), `RH_BENCH_MSAA` (samples on any adapter; default: the
//! configuration's `msaa`, or `msaa_cpu` on a CPU rasterizer), `RH_BENCH_FXAA` (0 or 1:
//! the post-process anti-aliasing pass; default: the configuration's `fxaa`).
//!
//! The process runs under the memory policy of a rendered build
//! (`rh_render::memory`), so the two measure the same thing.
//!
//! Prints each scene's own time and the figure that matters for a build: wall-clock
//! seconds per scene with every worker busy; and, independent of other load on the
//! machine, the CPU seconds per scene with the encoder threads' share (the encode-only
//! bound).
//!
//! `RH_BENCH_BUILD_SEED=S` takes instead the scenes `rh-pipeline build --n N --seed S`
//! renders (every speed band of each group, in order), so that the bench and a build
//! can be compared on the same scenes.
//!
//! `RH_BENCH_MASKS=1` also writes the mask and depth PNGs (as `build --masks`). The
//! instance-id pass alone (`Renderer::measure_hazard`: the five observation frames of
//! the three cameras), which every rendered scene runs, is timed last.

use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_physics::simulate::{simulate, SimOptions, Simulation};
use rh_physics::spec::SceneSpec;
use rh_render::{with_thread_renderer, RenderOptions};
use rh_scenes::config::Config;
use rh_scenes::driver::{plan_and_produce, produce_group};
use rh_scenes::selection::plan_group;
use std::time::Instant;

/// User + system CPU seconds of this process, all threads (`/proc/self/stat`).
fn process_cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

fn env_parse<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// The first speed band of groups 0, 1, … (seed 5) until `n` scenes with cameras.
fn first_bands(catalog: &Catalog, config: &Config, n: usize) -> Vec<(SceneSpec, Simulation)> {
    let families = &config.build.families;
    let mut scenes = Vec::new();
    let mut g = 0u64;
    while scenes.len() < n && g < 10 * n as u64 {
        let selection = plan_group(catalog, families, 5, g).unwrap();
        let r = produce_group(&selection, 5, g * 4, 1, catalog, config).unwrap();
        g += 1;
        let spec = r[0].spec.clone();
        if spec.cameras.is_empty() {
            continue;
        }
        let sim = simulate(&spec, SimOptions::default());
        scenes.push((spec, sim));
    }
    scenes
}

/// The scenes a rendered `build --n n --seed seed` renders: every valid scene with
/// cameras of groups 0 … ⌈n/4⌉ − 1, the last group cut at n (as the build's manifest).
fn build_scenes(
    catalog: &Catalog,
    config: &Config,
    n: usize,
    seed: u64,
) -> Vec<(SceneSpec, Simulation)> {
    let families = &config.build.families;
    let mut scenes = Vec::new();
    for g in 0..n.div_ceil(4) as u64 {
        let count = (n as u64 - 4 * g).min(4);
        let (results, _) =
            plan_and_produce(catalog, families, None, seed, g, count, config).unwrap();
        for r in results {
            if r.verdicts.all() && !r.spec.cameras.is_empty() {
                let sim = simulate(&r.spec, SimOptions::default());
                scenes.push((r.spec, sim));
            }
        }
    }
    scenes
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(8);
    let catalog = Catalog::embedded().unwrap();
    let mut config = Config::embedded().unwrap();
    if let Ok(p) = std::env::var("RH_BENCH_PRESET") {
        config.render.preset = p;
    }
    if let Some(t) = env_parse("RH_BENCH_THREADS") {
        config.render.encoder_threads = t;
    }
    if let Some(m) = env_parse("RH_BENCH_MSAA") {
        config.render.msaa = m;
        config.render.msaa_cpu = m;
    }
    if let Some(f) = env_parse::<u8>("RH_BENCH_FXAA") {
        config.render.fxaa = f != 0;
    }
    let jobs: usize = env_parse("RH_BENCH_JOBS").unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let scenes = match env_parse::<u64>("RH_BENCH_BUILD_SEED") {
        Some(seed) => build_scenes(&catalog, &config, n, seed),
        None => first_bands(&catalog, &config, n),
    };
    let opts = RenderOptions {
        masks: std::env::var_os("RH_BENCH_MASKS").is_some(),
        ..RenderOptions::from_config(&config.render)
    };
    let dir = std::env::temp_dir().join(format!("rh-render-bench-{}", std::process::id()));
    // The process a rendered build is (before any rendering thread starts).
    rh_render::memory::set_render_policy();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .unwrap();
    // Open each worker's device before timing (once per build, not per scene).
    let t = Instant::now();
    let adapters: Vec<(String, u32)> = pool.broadcast(|_| {
        with_thread_renderer(&opts, |r| (r.adapter_name().to_string(), r.samples()))
            .expect("a Vulkan adapter")
    });
    let setup = t.elapsed().as_secs_f64();
    let (cpu0, enc0) = (
        process_cpu_seconds(),
        rh_render::encode::encode_cpu_seconds(),
    );
    let t = Instant::now();
    let times: Vec<(f64, String)> = pool.install(|| {
        scenes
            .par_iter()
            .map(|(spec, sim)| {
                let t = Instant::now();
                let r = with_thread_renderer(&opts, |r| r.render_scene(spec, sim, &catalog, &dir))
                    .unwrap()
                    .unwrap();
                rh_render::memory::release_free_pages();
                let s = t.elapsed().as_secs_f64();
                let line = format!(
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
                (s, line)
            })
            .collect()
    });
    let wall = t.elapsed().as_secs_f64();
    let cpu = process_cpu_seconds() - cpu0;
    let enc = rh_render::encode::encode_cpu_seconds() - enc0;
    let _ = std::fs::remove_dir_all(&dir);
    // The id pass alone, one scene after another on this thread.
    let t = Instant::now();
    for (spec, sim) in &scenes {
        with_thread_renderer(&opts, |r| r.measure_hazard(spec, sim, &catalog))
            .unwrap()
            .unwrap();
    }
    let id_pass = t.elapsed().as_secs_f64() / scenes.len().max(1) as f64;
    // Every renderer goes before the pool and the process do (see the function).
    pool.broadcast(|_| rh_render::release_thread_renderer());
    rh_render::release_thread_renderer();
    for (_, line) in &times {
        println!("{line}");
    }
    let count = times.len().max(1) as f64;
    println!(
        "render_throughput: {:.2} s/scene wall-clock over {} scenes with {jobs} workers \
         (each scene {:.2} s on average; adapter {}, device setup {:.2} s, preset {}, msaa {}, fxaa {}, x264 threads {})",
        wall / count,
        times.len(),
        times.iter().map(|(s, _)| s).sum::<f64>() / count,
        adapters[0].0,
        setup,
        opts.encode.preset,
        adapters[0].1,
        opts.fxaa,
        opts.encode.threads
    );
    println!(
        "render_throughput: masks {}; instance-id pass alone {id_pass:.3} s/scene on one worker",
        opts.masks
    );
    // CPU time does not depend on what else runs on the machine (wall time does): the
    // process's CPU per scene, and the encoder threads' share of it — the encode-only
    // bound, what a scene costs if drawing were free.
    println!(
        "render_throughput: {:.2} CPU-s/scene (process, user + system), of which encoding \
         {:.2} CPU-s/scene: encode-only bound {:.2} s/scene wall on {jobs} cores; all of it \
         on {jobs} idle cores: {:.2} s/scene",
        cpu / count,
        enc / count,
        enc / count / jobs as f64,
        cpu / count / jobs as f64
    );
}
