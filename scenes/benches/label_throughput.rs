//! Label-only throughput: plan → randomize → simulate (plain + counterfactual) →
//! validate → label for a batch of scenes on all cores, without writing files.
//! Prints scenes per second. Target (issue 2): ≥ 200 scenes/s on 2 cores.
//!
//! `cargo bench -p rh-pipeline --bench label_throughput [-- N]`

use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_scenes::config::Config;
use rh_scenes::driver::produce_group;
use rh_scenes::selection::plan_group;
use std::time::Instant;

fn main() {
    let n: u64 = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(800);
    let catalog = Catalog::embedded().expect("embedded catalog");
    let config = Config::embedded().expect("embedded config");
    let families = config.build.families.clone();
    let groups = n.div_ceil(4);
    let threads = rayon::current_num_threads();

    let run = |seed: u64| {
        let start = Instant::now();
        let (scenes, steps, attempts): (u64, u64, u64) = (0..groups)
            .into_par_iter()
            .map(|g| {
                let selection = plan_group(&catalog, &families, seed, g).expect("plan");
                let results =
                    produce_group(&selection, seed, g * 4, 4, &catalog, &config).expect("produce");
                let steps: u64 = results.iter().map(|r| r.steps as u64).sum();
                let attempts: u64 = results.iter().map(|r| r.spec.attempt as u64).sum();
                (results.len() as u64, steps, attempts)
            })
            .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
        (scenes, steps, attempts, start.elapsed().as_secs_f64())
    };
    // Warm-up (page faults, allocator), then the measured run on a different seed.
    run(1);
    let (scenes, steps, attempts, secs) = run(2);
    println!(
        "label throughput: {scenes} scenes in {secs:.3} s on {threads} threads = {:.1} scenes/s",
        scenes as f64 / secs
    );
    println!(
        "  mean simulated steps per scene: {:.0}; resampling attempts beyond the first: {attempts}",
        steps as f64 / scenes as f64
    );
    println!("  families: {}", families.join(", "));
}
