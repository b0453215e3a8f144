//! How far the report's mean and balanced-accuracy intervals are from the percentile
//! bootstrap they stand for, printed per method (`cargo bench -p rh-grade --bench
//! interval_accuracy`; `-- SCENES` for another dataset size).
//!
//! Synthetic datasets (the fixture generator, in memory) of several seeds, scored with
//! predictions of 4 random models per dataset (a plan drawn per (model, scene): catch,
//! dodge or stay, random hands, walk and intent wording), then reported three ways:
//! * `new`: the report as it is (`[statistics]` defaults: closed form above
//!   `resample_up_to` values, the 2,000-resample bootstrap below);
//! * `old`: every interval by the 2,000-resample bootstrap (`resample_up_to` = ∞, the
//!   scorer's method before the closed form);
//! * `reference`: every interval by a 50,000-resample bootstrap with another seed (its
//!   own Monte Carlo error is about 0.6% of a half-width).
//!
//! For each interval of the report (models × rows × d_end, d_min, AIA, and balanced
//! accuracy) it prints the distance of each end from the reference in reference
//! half-widths: the largest, the 99th percentile and the median, for `new` and `old`.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rh_grade::synthetic::{dataset_of, synth_rows};
use rh_grade::{Config, Dataset, Report, Scoring};

const INTENTS: [&str; 6] = [
    "catch the falling object with both hands",
    "dodge by stepping back out of its path",
    "stay still, no action needed",
    "do not catch the knife; move aside",
    "grab it before it lands",
    "evade to the left",
];

fn preds(ds: &Dataset, models: usize, seed: u64) -> String {
    let mut out = String::new();
    for m in 0..models {
        let mut rng = ChaCha8Rng::seed_from_u64(seed * 100 + m as u64);
        for s in ds.scenes.iter().filter(|s| s.valid) {
            let kind = rng.random_range(0..3u32);
            let intent = INTENTS[rng.random_range(0..INTENTS.len())];
            let f = |rng: &mut ChaCha8Rng, a: f64, b: f64| a + (b - a) * rng.random::<f64>();
            let walk = match kind {
                0 => [f(&mut rng, 0.0, 0.6), 0.0, 0.0],
                1 => [f(&mut rng, -0.9, 0.0), f(&mut rng, -0.9, 0.9), 0.0],
                _ => [0.0, 0.0, 0.0],
            };
            let reach = if kind == 0 {
                f(&mut rng, 0.2, 0.6)
            } else {
                0.1
            };
            let (hx, hz) = (reach, f(&mut rng, -0.1, 0.4));
            let dur = f(&mut rng, 0.3, 1.5);
            out += &serde_json::json!({
                "scene_id": s.scene_id,
                "model": format!("model-{m}"),
                "plan": {
                    "intent": intent,
                    "confidence": 0.7,
                    "walking_cmd": walk,
                    "walking_duration": dur,
                    "keyframes": [
                        {"t": 0.4, "left_hand": [hx, 0.15, hz], "right_hand": [hx, -0.15, hz]},
                    ],
                },
            })
            .to_string();
            out.push('\n');
        }
    }
    out
}

fn report(ds: &Dataset, text: &str, cfg: &Config) -> Report {
    let mut scoring = Scoring::new(ds, cfg);
    scoring
        .score_reader(std::io::Cursor::new(text.as_bytes()))
        .expect("scoring");
    Report::build(&scoring, "preds.jsonl")
}

/// Every mean and balanced-accuracy interval of the report, in a fixed order.
fn intervals(r: &Report) -> Vec<Option<[f64; 2]>> {
    let mut v = Vec::new();
    for m in r.models.iter().chain(std::iter::once(&r.pooled)) {
        v.push(m.balanced_accuracy_ci);
        for row in std::iter::once(&m.overall).chain(&m.by_gt_action) {
            v.extend([row.d_end_ci, row.d_min_ci, row.aia_ci]);
        }
    }
    v
}

/// Distances of both ends from the reference, in reference half-widths.
fn errors(new: &[Option<[f64; 2]>], reference: &[Option<[f64; 2]>]) -> Vec<f64> {
    let mut e = Vec::new();
    for (a, b) in new.iter().zip(reference) {
        if let (Some(a), Some(b)) = (a, b) {
            let half = (b[1] - b[0]) / 2.0;
            if half > 1e-12 {
                e.push((a[0] - b[0]).abs() / half);
                e.push((a[1] - b[1]).abs() / half);
            }
        }
    }
    e.sort_by(f64::total_cmp);
    e
}

fn summary(e: &[f64]) -> String {
    let q = |p: f64| e[((e.len() - 1) as f64 * p).round() as usize];
    format!(
        "max {:.3}, p99 {:.3}, median {:.3}",
        q(1.0),
        q(0.99),
        q(0.5)
    )
}

fn main() {
    let scenes: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(2000);
    let new_cfg = Config::default();
    let mut old_cfg = Config::default();
    old_cfg.statistics.resample_up_to = usize::MAX;
    let mut ref_cfg = old_cfg.clone();
    ref_cfg.statistics.bootstrap_resamples = 50_000;
    ref_cfg.statistics.max_bootstrap_draws = u64::MAX;
    ref_cfg.statistics.seed = 7;
    let (mut all_new, mut all_old) = (Vec::new(), Vec::new());
    for seed in [1u64, 2, 3] {
        let ds = dataset_of(&synth_rows(scenes, seed));
        let text = preds(&ds, 4, seed);
        let reference = intervals(&report(&ds, &text, &ref_cfg));
        let new = errors(&intervals(&report(&ds, &text, &new_cfg)), &reference);
        let old = errors(&intervals(&report(&ds, &text, &old_cfg)), &reference);
        println!(
            "interval_accuracy: {scenes} scenes, seed {seed}, {} interval ends: new {}; old {}",
            new.len(),
            summary(&new),
            summary(&old)
        );
        all_new.extend(new);
        all_old.extend(old);
    }
    all_new.sort_by(f64::total_cmp);
    all_old.sort_by(f64::total_cmp);
    println!(
        "interval_accuracy: all: new (closed form) {}; old (2,000 resamples) {}; tolerance {}",
        summary(&all_new),
        summary(&all_old),
        rh_grade::stats::TOLERANCE
    );
}
