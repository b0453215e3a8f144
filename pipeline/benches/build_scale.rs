//! Scale benchmark (issue 17): the real `rh-pipeline build --no-render` at n = 1,000 and
//! n = 10,000 (or the sizes given), each in a fresh output directory: wall-clock scenes/s
//! and the process's peak RSS. Then the physics-only ceiling for the same scenes: plan →
//! randomize → simulate (plain + counterfactual) → validate → label on the same number of
//! threads, nothing written, nothing kept (run before and after each build, averaged).
//! Prints how close the build comes to it.
//! Goals: RSS at 10 k ≤ 1.2 × RSS at 1 k; build ≥ 90% of the physics-only rate.
//!
//! `cargo bench -p rh-pipeline --bench build_scale [-- N...] [--jobs J] [--seed S]`

use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_scenes::config::Config;
use rh_scenes::driver::produce_group;
use rh_scenes::selection::plan_group;
use std::process::Command;
use std::time::Instant;

struct Args {
    sizes: Vec<u64>,
    jobs: usize,
    seed: u64,
}

fn parse_args() -> Args {
    let mut args = Args {
        sizes: vec![],
        jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
        seed: 0,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--jobs" => args.jobs = it.next().and_then(|v| v.parse().ok()).expect("--jobs J"),
            "--seed" => args.seed = it.next().and_then(|v| v.parse().ok()).expect("--seed S"),
            other => {
                if let Ok(n) = other.parse() {
                    args.sizes.push(n)
                }
                // Anything else is cargo's (e.g. --bench).
            }
        }
    }
    if args.sizes.is_empty() {
        args.sizes = vec![1000, 10_000];
    }
    args
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

/// Runs `rh-pipeline build --no-render` into a new temp dir; returns (seconds, peak RSS
/// in bytes) of that process.
fn run_build(n: u64, args: &Args) -> (f64, u64) {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("build");
    let start = Instant::now();
    let child = Command::new(env!("CARGO_BIN_EXE_rh-pipeline"))
        .args(["build", "--no-render", "--quiet", "--n"])
        .arg(n.to_string())
        .arg("--seed")
        .arg(args.seed.to_string())
        .arg("--jobs")
        .arg(args.jobs.to_string())
        .arg("--out")
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("rh-pipeline starts");
    // wait4 reaps the child and reports its own peak RSS (kB on Linux).
    let mut status = 0;
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = child.id() as libc::pid_t;
    let reaped = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    let secs = start.elapsed().as_secs_f64();
    assert_eq!(reaped, pid, "wait4 failed");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "rh-pipeline build --n {n} failed (status {status})"
    );
    let data = out.join("data/test-00000-of-00001.parquet");
    assert!(data.is_file(), "no {}", data.display());
    (secs, usage.ru_maxrss as u64 * 1024)
}

/// The same scenes, physics and labels only, on `jobs` threads: seconds.
fn run_physics(n: u64, args: &Args, catalog: &Catalog, config: &Config) -> f64 {
    let families = config.build.families.clone();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs)
        .build()
        .expect("thread pool");
    let groups = n.div_ceil(4);
    let start = Instant::now();
    let scenes: u64 = pool.install(|| {
        (0..groups)
            .into_par_iter()
            .map(|g| {
                let count = (n - g * 4).min(4);
                let selection = plan_group(catalog, &families, args.seed, g).expect("plan");
                let results = produce_group(&selection, args.seed, g * 4, count, catalog, config)
                    .expect("produce");
                results.len() as u64
            })
            .sum()
    });
    assert_eq!(scenes, n);
    start.elapsed().as_secs_f64()
}

fn main() {
    let args = parse_args();
    let catalog = Catalog::embedded().expect("embedded catalog");
    let config = Config::embedded().expect("embedded config");
    println!(
        "build scale: rh-pipeline build --no-render, seed {}, {} threads, all {} default families; load average before: {}",
        args.seed,
        args.jobs,
        config.build.families.len(),
        load_average()
    );
    // Warm-up: page cache, allocator, the binary itself.
    run_build(40, &args);
    let mut rss = Vec::new();
    for &n in &args.sizes {
        // Physics-only right before and right after the build, averaged: on a shared
        // machine the load drifts, and the build should be compared with the same load.
        let before = run_physics(n, &args, &catalog, &config);
        let (secs, peak) = run_build(n, &args);
        let physics = (before + run_physics(n, &args, &catalog, &config)) / 2.0;
        let (rate, ceiling) = (n as f64 / secs, n as f64 / physics);
        println!(
            "  n = {n:>6}: build {secs:7.1} s = {rate:6.1} scenes/s, peak RSS {:6.1} MiB | physics-only {physics:7.1} s = {ceiling:6.1} scenes/s | build at {:.0}% of physics-only | load {}",
            peak as f64 / (1024.0 * 1024.0),
            100.0 * rate / ceiling,
            load_average()
        );
        rss.push((n, peak));
    }
    if let (Some(&(n0, r0)), Some(&(n1, r1))) = (rss.first(), rss.last()) {
        if n1 != n0 {
            println!(
                "  peak RSS at n = {n1} is {:.2}x that at n = {n0} (goal <= 1.2)",
                r1 as f64 / r0 as f64
            );
        }
    }
}
