//! How the geometric ego-pixel rule (`rh_scenes::ego`, part of `valid_visible`) agrees
//! with the renderer's instance-id pass (`Renderer::measure_hazard`) on the valid scenes
//! of builds: per model-input ego frame before the hazard reaches the observer, the
//! estimate against the measured pixels. Prints the frames checked, those the renderer
//! shows under `validators.visible_px_min` (a rendered build stops on such a scene), the
//! least measured / estimated ratio, and per family the least measured pixels.
//!
//! `cargo bench -p rh-render --bench ego_visibility` (lavapipe: about 0.15 s a scene);
//! `RH_EGO_SEEDS=0,1,2` (build seeds), `RH_EGO_GROUPS=16` (groups per seed).

use rh_catalog::Catalog;
use rh_physics::simulate::{simulate, SimOptions};
use rh_render::{RenderOptions, Renderer};
use rh_scenes::config::Config;
use rh_scenes::driver::plan_and_produce;
use rh_scenes::ego;
use std::collections::BTreeMap;

fn env_list(name: &str, default: &str) -> Vec<u64> {
    std::env::var(name)
        .unwrap_or_else(|_| default.into())
        .split(',')
        .map(|s| s.trim().parse().expect("a number"))
        .collect()
}

fn main() {
    let config = Config::embedded().unwrap();
    let catalog = Catalog::embedded().unwrap();
    let rules = config.validators.framing();
    let min = config.validators.visible_px_min;
    let seeds = env_list("RH_EGO_SEEDS", "0,1,2");
    let groups = env_list("RH_EGO_GROUPS", "16")[0];
    let mut renderer = Renderer::new(RenderOptions::from_config(&config.render))
        .expect("a Vulkan adapter (lavapipe) for rendering");
    let families = config.build.families.clone();
    let (mut scenes, mut frames, mut short) = (0, 0, Vec::new());
    let mut ratio = f64::MAX;
    let mut per_family: BTreeMap<String, (u32, f64)> = BTreeMap::new();
    for &seed in &seeds {
        for g in 0..groups {
            let (results, _) =
                plan_and_produce(&catalog, &families, None, seed, g, 4, &config).unwrap();
            for r in results.iter().filter(|r| r.verdicts.all()) {
                scenes += 1;
                let sim = simulate(&r.spec, SimOptions::default());
                let measured = renderer.measure_hazard(&r.spec, &sim, &catalog).unwrap();
                let px = &measured["ego"].visible_px;
                let cam = ego::ego_camera(&r.spec.cameras).unwrap();
                for (i, k) in ego::model_input_steps(&r.spec, &sim, rules.until_within) {
                    frames += 1;
                    let est = ego::visible_px(&r.spec, &sim, cam, k, &rules, f64::MAX);
                    ratio = ratio.min(px[i] as f64 / est.max(1.0));
                    let e = per_family
                        .entry(r.spec.family.clone())
                        .or_insert((u32::MAX, f64::MAX));
                    e.0 = e.0.min(px[i]);
                    e.1 = e.1.min(px[i] as f64 / est.max(1.0));
                    if px[i] < min {
                        short.push(format!(
                            "seed {seed} {} {} {} t={}: measured {} px, estimated {est:.0}",
                            r.spec.scene_id,
                            r.spec.family,
                            r.spec.selection.object_id,
                            rh_contract::FRAME_TIMES[i],
                            px[i]
                        ));
                    }
                }
            }
        }
    }
    println!(
        "ego visibility: seeds {seeds:?}, {groups} groups each: {scenes} valid scenes, \
         {frames} model-input ego frames checked; {} under visible_px_min = {min} px; \
         least measured/estimated ratio {ratio:.2}",
        short.len()
    );
    for s in &short {
        println!("  short: {s}");
    }
    println!("family            least px  least ratio");
    for (f, (px, r)) in &per_family {
        println!("{f:17} {px:8}  {r:11.2}");
    }
}
