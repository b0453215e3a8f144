//! Uncertainty: 95% intervals on the report's numbers (SPEC §11).
//!
//! * Proportions (SAA, safety, per-class recall, freeze rate): the Wilson score interval,
//!   closed form, no randomness.
//! * Means (d_end, HDE d_min, AIA) and balanced accuracy: percentile bootstrap over
//!   scenes, seeded from `[statistics] seed` and the row's name, so a report is the same
//!   on every run and does not depend on the order rows are computed in. Balanced accuracy
//!   resamples within each ground-truth class (stratified).
//! * Paired comparison of two models on the scenes both answered: McNemar's exact test
//!   (two-sided binomial on the discordant pairs) and Newcombe's hybrid score interval for
//!   the difference of paired proportions (method 10, Newcombe 1998).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The normal quantile of a two-sided 95% interval.
pub const Z95: f64 = 1.959_963_984_540_054;

/// `[statistics]` of `configs/scoring.toml`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StatsConfig {
    /// Bootstrap resamples per interval.
    pub bootstrap_resamples: usize,
    /// Base seed of every bootstrap (each interval mixes in its model, row and metric).
    pub seed: u64,
    /// Most values × resamples one bootstrap draws; larger samples use fewer resamples.
    pub max_bootstrap_draws: u64,
}

impl Default for StatsConfig {
    fn default() -> Self {
        StatsConfig {
            bootstrap_resamples: 2000,
            seed: 0,
            max_bootstrap_draws: 200_000_000,
        }
    }
}

/// Wilson score interval of `k` successes in `n` trials (95%); `None` when `n` is 0.
pub fn wilson(k: u64, n: u64) -> Option<[f64; 2]> {
    if n == 0 {
        return None;
    }
    let (k, n) = (k.min(n) as f64, n as f64);
    let p = k / n;
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = Z95 * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
    // At k = 0 and k = n one end is exactly 0 or 1 (rounding would put it a hair inside).
    let lo = if k == 0.0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let hi = if k == n {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    Some([lo, hi])
}

/// A stable 64-bit seed from the base seed and names (FNV-1a).
pub fn seed_for(base: u64, parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ base;
    for p in parts {
        for b in p.bytes().chain(std::iter::once(0xff)) {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// The `q`-quantile of sorted values (linear interpolation between order statistics).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let pos = q * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

fn resamples(cfg: &StatsConfig, n: usize) -> usize {
    let cap = (cfg.max_bootstrap_draws / n.max(1) as u64) as usize;
    cfg.bootstrap_resamples.min(cap.max(200)).max(1)
}

fn percentile_interval(mut stats: Vec<f64>) -> Option<[f64; 2]> {
    if stats.is_empty() {
        return None;
    }
    stats.sort_by(f64::total_cmp);
    Some([quantile(&stats, 0.025), quantile(&stats, 0.975)])
}

/// Percentile bootstrap 95% interval of the mean of `values`; `None` for no values.
pub fn bootstrap_mean(values: &[f64], cfg: &StatsConfig, seed: u64) -> Option<[f64; 2]> {
    if values.is_empty() {
        return None;
    }
    let n = values.len();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let b = resamples(cfg, n);
    let stats = (0..b)
        .map(|_| (0..n).map(|_| values[rng.random_range(0..n)]).sum::<f64>() / n as f64)
        .collect();
    percentile_interval(stats)
}

/// Balanced accuracy: the mean recall over the classes that have scenes
/// (`classes` = (correct, scenes) per class); `None` when no class has a scene.
pub fn balanced_accuracy(classes: &[(u64, u64)]) -> Option<f64> {
    let present: Vec<f64> = classes
        .iter()
        .filter(|c| c.1 > 0)
        .map(|&(k, n)| k as f64 / n as f64)
        .collect();
    (!present.is_empty()).then(|| present.iter().sum::<f64>() / present.len() as f64)
}

/// Stratified percentile bootstrap interval of the balanced accuracy: each class's scenes
/// are resampled within the class.
pub fn bootstrap_balanced(
    classes: &[(u64, u64)],
    cfg: &StatsConfig,
    seed: u64,
) -> Option<[f64; 2]> {
    balanced_accuracy(classes)?;
    let total: u64 = classes.iter().map(|c| c.1).sum();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let b = resamples(cfg, total as usize);
    let stats = (0..b)
        .map(|_| {
            let drawn: Vec<(u64, u64)> = classes
                .iter()
                .map(|&(k, n)| {
                    (
                        (0..n).filter(|_| rng.random_range(0..n) < k).count() as u64,
                        n,
                    )
                })
                .collect();
            balanced_accuracy(&drawn).unwrap_or(0.0)
        })
        .collect();
    percentile_interval(stats)
}

/// McNemar's exact test: the two-sided p-value of `b` vs `c` discordant pairs under
/// Binomial(b + c, 1/2) (1 when there are none).
pub fn mcnemar_exact(b: u64, c: u64) -> f64 {
    let n = b + c;
    if n == 0 {
        return 1.0;
    }
    let k = b.min(c);
    // P(X <= k) for X ~ Binomial(n, 1/2), summed in log space for large n.
    let ln_half_n = -(n as f64) * std::f64::consts::LN_2;
    let mut ln_c = 0.0f64; // ln C(n, 0)
    let mut tail = 0.0f64;
    for i in 0..=k {
        if i > 0 {
            ln_c += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        tail += (ln_c + ln_half_n).exp();
    }
    (2.0 * tail).min(1.0)
}

/// Newcombe's hybrid score interval (method 10) for the difference p_A − p_B of two
/// paired proportions: `a` both right, `b` only A right, `c` only B right, `d` both
/// wrong. `None` without pairs.
pub fn newcombe_paired(a: u64, b: u64, c: u64, d: u64) -> Option<[f64; 2]> {
    let n = a + b + c + d;
    if n == 0 {
        return None;
    }
    let nf = n as f64;
    let (p1, p2) = ((a + b) as f64 / nf, (a + c) as f64 / nf);
    let [l1, u1] = wilson(a + b, n)?;
    let [l2, u2] = wilson(a + c, n)?;
    let (af, bf, cf, df) = (a as f64, b as f64, c as f64, d as f64);
    let den = ((a + b) as f64 * (c + d) as f64 * (a + c) as f64 * (b + d) as f64).sqrt();
    let phi = if den > 0.0 {
        (af * df - bf * cf) / den
    } else {
        0.0
    };
    let diff = p1 - p2;
    let delta =
        ((p1 - l1).powi(2) - 2.0 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2).powi(2)).max(0.0);
    let eps = ((u1 - p1).powi(2) - 2.0 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2).powi(2)).max(0.0);
    Some([
        (diff - delta.sqrt()).max(-1.0),
        (diff + eps.sqrt()).min(1.0),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn wilson_known_answers() {
        // 4/60: centre (4 + z²/2)/(60 + z²), half-width z·sqrt(4·56/60 + z²/4)/(60 + z²).
        let [lo, hi] = wilson(4, 60).unwrap();
        assert!(close(lo, 0.026_228_7, 1e-6), "{lo}");
        assert!(close(hi, 0.159_253_6, 1e-6), "{hi}");
        // 0/10 and 10/10: one end at the boundary.
        let [lo, hi] = wilson(0, 10).unwrap();
        assert_eq!(lo, 0.0);
        assert!(close(hi, 0.277_532_4, 1e-6), "{hi}");
        let [lo, hi] = wilson(10, 10).unwrap();
        assert!(close(lo, 0.722_467_6, 1e-6) && hi == 1.0, "{lo}");
        assert!(wilson(0, 0).is_none());
    }

    #[test]
    fn mcnemar_known_answers() {
        // b = 1, c = 9: 2 · (1 + 10) / 2^10 = 22/1024.
        assert!(close(mcnemar_exact(1, 9), 22.0 / 1024.0, 1e-12));
        // b = 0, c = 5: 2/32.
        assert!(close(mcnemar_exact(0, 5), 2.0 / 32.0, 1e-12));
        // Symmetric, and 1 when balanced or empty.
        assert_eq!(mcnemar_exact(9, 1), mcnemar_exact(1, 9));
        assert_eq!(mcnemar_exact(3, 3), 1.0);
        assert_eq!(mcnemar_exact(0, 0), 1.0);
        // Large n stays finite: b = 400, c = 600 is far from balanced.
        let p = mcnemar_exact(400, 600);
        assert!(p > 0.0 && p < 1e-8, "{p}");
    }

    #[test]
    fn newcombe_contains_difference_and_matches_hand_computation() {
        // a = 12, b = 9, c = 2, d = 21 (n = 44): difference 7/44 = 0.1591; Wilson
        // intervals of 21/44 and 14/44, phi = (12·21 − 9·2)/sqrt(21·23·14·30), computed by
        // hand from the method-10 formulas: (0.018210, 0.289157).
        let [lo, hi] = newcombe_paired(12, 9, 2, 21).unwrap();
        assert!(close(lo, 0.018_210_2, 1e-6), "{lo}");
        assert!(close(hi, 0.289_156_7, 1e-6), "{hi}");
        // Equal marginals: the interval straddles 0 symmetrically; with no discordant
        // pair at all (perfect correlation) it has zero width.
        let [lo, hi] = newcombe_paired(20, 5, 5, 30).unwrap();
        assert!(lo < 0.0 && hi > 0.0 && close(lo, -hi, 1e-12), "{lo} {hi}");
        assert_eq!(newcombe_paired(30, 0, 0, 30), Some([0.0, 0.0]));
        assert!(newcombe_paired(0, 0, 0, 0).is_none());
    }

    #[test]
    fn bootstrap_is_seeded_and_sane() {
        let cfg = StatsConfig::default();
        let v: Vec<f64> = (0..50).map(|i| (i % 7) as f64 * 0.1).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let a = bootstrap_mean(&v, &cfg, 7).unwrap();
        assert_eq!(
            a,
            bootstrap_mean(&v, &cfg, 7).unwrap(),
            "same seed, same interval"
        );
        assert!(a[0] < mean && mean < a[1], "{a:?} around {mean}");
        assert_ne!(a, bootstrap_mean(&v, &cfg, 8).unwrap());
        // A constant sample has a zero-width interval.
        let c = bootstrap_mean(&[0.3; 10], &cfg, 1).unwrap();
        assert!(close(c[0], 0.3, 1e-12) && close(c[1], 0.3, 1e-12), "{c:?}");
        assert!(bootstrap_mean(&[], &cfg, 1).is_none());
        assert_ne!(seed_for(0, &["a", "bc"]), seed_for(0, &["ab", "c"]));
    }

    #[test]
    fn balanced_accuracy_and_its_interval() {
        // A majority baseline: every CATCH right, every DODGE and NO_ACTION wrong.
        let classes = [(40, 40), (0, 15), (0, 5)];
        assert!(close(
            balanced_accuracy(&classes).unwrap(),
            1.0 / 3.0,
            1e-12
        ));
        // The resampled recalls of 40/40 and 0/n never move: a zero-width interval.
        let ci = bootstrap_balanced(&classes, &StatsConfig::default(), 3).unwrap();
        assert!(close(ci[0], 1.0 / 3.0, 1e-12) && close(ci[1], 1.0 / 3.0, 1e-12));
        // Absent classes are left out of the mean.
        assert_eq!(balanced_accuracy(&[(3, 4), (0, 0), (1, 4)]), Some(0.5));
        assert_eq!(balanced_accuracy(&[(0, 0); 3]), None);
        let ci = bootstrap_balanced(&[(3, 4), (0, 0), (1, 4)], &StatsConfig::default(), 3).unwrap();
        assert!(ci[0] < 0.5 && 0.5 < ci[1], "{ci:?}");
    }
}
