//! Milliseconds per executed decision (`rh-score --execute`, specification §12).
//!
//! `cargo bench -p rh-execute --bench execute_throughput [-- GROUPS]` (default 17: one scene
//! group of four speed bands per family, 68 scenes). Scenes come from the real pipeline
//! (label-only, in memory). Each scene is replayed once to Δ (timed separately), then
//! three plans are executed from a fork of it — freeze, arms-forward catch, step-back
//! dodge — single-threaded, each timed. Prints the median and mean ms per executed
//! decision, the replay ms per scene, and what the paper's 2,138 decisions would take on
//! this machine's cores (decisions run in parallel with rayon in `rh-score`).

use rh_physics::execute::{replay, ExecConfig, ExecKeyframe, ExecPlan};
use std::time::Instant;

fn plans() -> Vec<(&'static str, ExecPlan)> {
    let kf = |t: f64, x: f64, z: f64| ExecKeyframe {
        t,
        left: [x, 0.15, z],
        right: [x, -0.15, z],
        knee_bend: 0.0,
    };
    vec![
        (
            "freeze",
            ExecPlan {
                walking_cmd: [0.0; 3],
                walking_duration: 0.0,
                keyframes: vec![kf(0.25, 0.10, 0.0)],
            },
        ),
        (
            "catch",
            ExecPlan {
                walking_cmd: [0.0; 3],
                walking_duration: 0.0,
                keyframes: vec![kf(0.3, 0.45, 0.10)],
            },
        ),
        (
            "dodge",
            ExecPlan {
                walking_cmd: [-0.8, 0.0, 0.0],
                walking_duration: 1.0,
                keyframes: vec![kf(1.0, 0.10, 0.0)],
            },
        ),
    ]
}

fn main() {
    let groups: u64 = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(17);
    let catalog = rh_catalog::Catalog::embedded().expect("catalog");
    let config = rh_scenes::config::Config::embedded().expect("config");
    let families: Vec<String> = rh_contract::FAMILIES
        .iter()
        .map(|f| f.to_string())
        .collect();
    let mut specs = Vec::new();
    for g in 0..groups {
        // One group per family in turn.
        let fam = vec![families[(g as usize) % families.len()].clone()];
        let sel = rh_scenes::selection::plan_group(&catalog, &fam, 7, g).expect("plan");
        let scenes = rh_scenes::driver::produce_group(&sel, 7, g * 4, 4, &catalog, &config)
            .expect("produce");
        specs.extend(scenes.into_iter().map(|r| r.spec));
    }
    let cfg = ExecConfig::embedded_default();
    let plans = plans();
    let (mut replay_ms, mut exec_ms) = (Vec::new(), Vec::new());
    let mut outcomes = std::collections::BTreeMap::new();
    for spec in &specs {
        let t = Instant::now();
        let r = replay(spec);
        replay_ms.push(t.elapsed().as_secs_f64() * 1e3);
        for (name, plan) in &plans {
            let t = Instant::now();
            let o = r.execute(plan, &cfg);
            exec_ms.push(t.elapsed().as_secs_f64() * 1e3);
            *outcomes.entry((*name, o.outcome.name())).or_insert(0u32) += 1;
        }
    }
    let stats = |v: &mut Vec<f64>| {
        v.sort_by(|a, b| a.total_cmp(b));
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (v[v.len() / 2], mean, v[v.len() * 9 / 10])
    };
    let (em, ea, e90) = stats(&mut exec_ms);
    let (rm, ra, _) = stats(&mut replay_ms);
    let per_decision = ea + ra / plans.len() as f64;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "execute_throughput: {} scenes x {} plans = {} decisions",
        specs.len(),
        plans.len(),
        exec_ms.len()
    );
    println!("  execution: median {em:.2} ms, mean {ea:.2} ms, p90 {e90:.2} ms per decision (one thread)");
    println!("  replay to the decision moment: median {rm:.2} ms, mean {ra:.2} ms per scene (once per scene)");
    println!(
        "  per decision with the replay shared by {} plans: {per_decision:.2} ms; the paper's 2,138 decisions: {:.1} s on one core, {:.1} s on {cores} cores",
        plans.len(),
        2138.0 * per_decision / 1e3,
        2138.0 * per_decision / 1e3 / cores as f64
    );
    for ((plan, outcome), n) in &outcomes {
        println!("  {plan:<7} {outcome:<7} {n}");
    }
}
