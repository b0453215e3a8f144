//! Label-only throughput of the real build path: for every scene group,
//! `driver::plan_and_produce` — what `rh-pipeline build --no-render` runs per group
//! (plan, replans up to `[validators] replans`, adversarial probe/twin groups, aimed
//! tries, randomize → simulate → frame → counterfactual → label → validate, resampling),
//! on all cores, without writing files. Prints scenes per second (wall clock) and the
//! process's CPU time per scene (user + system, `/proc/self/stat`), which does not depend
//! on the machine's load. Target (issue #23): ≥ 150 scenes/s on 2 idle cores.
//!
//! `cargo bench -p rh-scenes --bench label_throughput [-- N]` (default 800 scenes)

use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_scenes::config::Config;
use rh_scenes::driver::plan_and_produce;
use std::time::Instant;

/// User + system CPU seconds of this process so far (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which is in parentheses): utime and stime are the
    // 12th and 13th of them, in clock ticks (100 per second on Linux).
    let rest = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

#[derive(Default, Clone, Copy)]
struct Tally {
    scenes: u64,
    valid: u64,
    steps: u64,
    attempts: u64,
}

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
        let (wall, cpu) = (Instant::now(), cpu_seconds());
        let tally = (0..groups)
            .into_par_iter()
            .map(|g| {
                let count = (n - g * 4).min(4);
                let (results, rejections) =
                    plan_and_produce(&catalog, &families, None, seed, g, count, &config)
                        .expect("plan and produce");
                Tally {
                    scenes: results.len() as u64,
                    valid: results.iter().filter(|r| r.verdicts.all()).count() as u64,
                    steps: results.iter().map(|r| r.steps as u64).sum(),
                    attempts: rejections.attempts as u64,
                }
            })
            .reduce(Tally::default, |a, b| Tally {
                scenes: a.scenes + b.scenes,
                valid: a.valid + b.valid,
                steps: a.steps + b.steps,
                attempts: a.attempts + b.attempts,
            });
        (tally, wall.elapsed().as_secs_f64(), cpu_seconds() - cpu)
    };
    // Warm-up (page faults, allocator), then the measured run on a different seed.
    run(1);
    let (t, secs, cpu) = run(2);
    println!(
        "label throughput (driver::plan_and_produce per group, as build --no-render, no files): \
         {} scenes in {secs:.3} s on {threads} threads = {:.1} scenes/s",
        t.scenes,
        t.scenes as f64 / secs
    );
    println!(
        "  CPU (user + system): {cpu:.2} s = {:.2} ms per scene, {:.1} scenes per CPU-second",
        1000.0 * cpu / t.scenes as f64,
        t.scenes as f64 / cpu
    );
    println!(
        "  valid {} of {}; mean simulated steps per scene: {:.0}; group attempts: {} for {groups} groups",
        t.valid,
        t.scenes,
        t.steps as f64 / t.scenes as f64,
        t.attempts
    );
    println!("  families: {}", families.join(", "));
}
