//! Uncertainty: 95% intervals on the report's numbers (specification §11).
//!
//! * Proportions (SAA, safety, per-class recall, freeze rate): the Wilson score interval,
//!   closed form, no randomness.
//! * Means (d_end, HDE d_min, AIA) and balanced accuracy: the percentile bootstrap over
//!   scenes (balanced accuracy resampled within each ground-truth class, stratified).
//!   A sample of at most `[statistics] resample_up_to` values (scenes for balanced
//!   accuracy) is resampled `bootstrap_resamples` times, seeded from `seed` and the row's
//!   name, so a report is the same on every run and in any order rows are computed in.
//!   A larger sample takes the 2.5% and 97.5% quantiles of the same bootstrap
//!   distribution in closed form ([`expansion`]): its first four cumulants are exact
//!   functions of the sample (those of the mean of n draws from the sample, or of a sum of
//!   binomial class recalls), and the Cornish–Fisher expansion turns them into quantiles.
//!   That is what the resampling estimates, without its Monte Carlo error (about 3% of the
//!   half-width at 2,000 resamples) and in O(n) instead of O(n · resamples); a sample so
//!   skewed that the expansion is not trustworthy (|skewness of the statistic| >
//!   [`MAX_EXPANSION_SKEW`]) is resampled instead. Accuracy: docs/evaluation.md.
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
    /// Largest sample (values of a mean, scenes of a balanced accuracy) that is
    /// resampled; larger ones get the bootstrap's quantiles in closed form.
    #[serde(default = "default_resample_up_to")]
    pub resample_up_to: usize,
}

fn default_resample_up_to() -> usize {
    100
}

impl Default for StatsConfig {
    fn default() -> Self {
        StatsConfig {
            bootstrap_resamples: 2000,
            seed: 0,
            max_bootstrap_draws: 200_000_000,
            resample_up_to: default_resample_up_to(),
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

/// Largest |skewness| of a statistic's bootstrap distribution for which [`expansion`]
/// is used (beyond it the Cornish–Fisher polynomial loses accuracy and, far beyond,
/// monotonicity); a sample that skewed is resampled. Not policy: the expansion's range.
pub const MAX_EXPANSION_SKEW: f64 = 0.25;

/// The documented accuracy of the closed form (docs/evaluation.md): each end of a
/// closed-form interval lies within this many half-widths of the percentile bootstrap's
/// with many resamples (measured: at most 0.056; the 2,000-resample bootstrap it
/// replaces strays up to 0.105).
pub const TOLERANCE: f64 = 0.075;

/// The 2.5% and 97.5% quantiles of a distribution with cumulants `[κ1, κ2, κ3, κ4]` by
/// the Cornish–Fisher expansion with its terms to order 1/n (skewness, excess kurtosis,
/// skewness²); `None` when its skewness is beyond [`MAX_EXPANSION_SKEW`]. A distribution
/// without spread is its mean.
pub fn expansion([k1, k2, k3, k4]: [f64; 4]) -> Option<[f64; 2]> {
    if !(k2 > 0.0) {
        return Some([k1, k1]);
    }
    let sd = k2.sqrt();
    let g1 = k3 / (k2 * sd);
    let g2 = k4 / (k2 * k2);
    if !(g1.abs() <= MAX_EXPANSION_SKEW) || !g2.is_finite() {
        return None;
    }
    let q = |z: f64| {
        let z3 = z * z * z;
        let w = z + g1 / 6.0 * (z * z - 1.0) + g2 / 24.0 * (z3 - 3.0 * z)
            - g1 * g1 / 36.0 * (2.0 * z3 - 5.0 * z);
        k1 + sd * w
    };
    Some([q(-Z95), q(Z95)])
}

/// The cumulants of the bootstrap distribution of the mean of `values` (the mean of n
/// draws with replacement): κ_r of one draw (the sample's own) divided by n^(r−1).
pub fn mean_cumulants(values: &[f64]) -> [f64; 4] {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let (mut m2, mut m3, mut m4) = (0.0, 0.0, 0.0);
    for &v in values {
        let d = v - mean;
        let d2 = d * d;
        m2 += d2;
        m3 += d2 * d;
        m4 += d2 * d2;
    }
    let (m2, m3, m4) = (m2 / n, m3 / n, m4 / n);
    [
        mean,
        m2 / n,
        m3 / (n * n),
        (m4 - 3.0 * m2 * m2) / (n * n * n),
    ]
}

/// 95% interval of the mean of `values` (the percentile bootstrap's; see the module
/// notes): resampled up to `cfg.resample_up_to` values, closed form above; `None` for no
/// values.
pub fn mean_interval(values: &[f64], cfg: &StatsConfig, seed: u64) -> Option<[f64; 2]> {
    if values.len() <= cfg.resample_up_to {
        return bootstrap_mean(values, cfg, seed);
    }
    let Some([lo, hi]) = expansion(mean_cumulants(values)) else {
        return bootstrap_mean(values, cfg, seed);
    };
    // The bootstrap's means never leave the sample's range.
    let (min, max) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    Some([lo.clamp(min, max), hi.clamp(min, max)])
}

/// The cumulants of the stratified bootstrap distribution of the balanced accuracy: the
/// mean over the C classes with scenes of independent recalls Binomial(n, k/n)/n.
pub fn balanced_cumulants(classes: &[(u64, u64)]) -> [f64; 4] {
    let present: Vec<(f64, f64)> = classes
        .iter()
        .filter(|c| c.1 > 0)
        .map(|&(k, n)| (k.min(n) as f64 / n as f64, n as f64))
        .collect();
    let c = present.len() as f64;
    let mut k = [0.0f64; 4];
    for &(p, n) in &present {
        let pq = p * (1.0 - p);
        k[0] += p;
        k[1] += pq / n;
        k[2] += pq * (1.0 - 2.0 * p) / (n * n);
        k[3] += pq * (1.0 - 6.0 * pq) / (n * n * n);
    }
    [
        k[0] / c,
        k[1] / (c * c),
        k[2] / (c * c * c),
        k[3] / (c * c * c * c),
    ]
}

/// 95% interval of the balanced accuracy (the stratified bootstrap's; see the module
/// notes): resampled up to `cfg.resample_up_to` scenes, closed form above; `None` when
/// no class has a scene.
pub fn balanced_interval(classes: &[(u64, u64)], cfg: &StatsConfig, seed: u64) -> Option<[f64; 2]> {
    balanced_accuracy(classes)?;
    let total: u64 = classes.iter().map(|c| c.1).sum();
    if total <= cfg.resample_up_to as u64 {
        return bootstrap_balanced(classes, cfg, seed);
    }
    match expansion(balanced_cumulants(classes)) {
        Some([lo, hi]) => Some([lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0)]),
        None => bootstrap_balanced(classes, cfg, seed),
    }
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

    /// Deterministic skewed, discrete and bimodal samples (a small LCG, no seeds shared
    /// with the intervals).
    fn samples() -> Vec<(&'static str, Vec<f64>)> {
        let mut x: u64 = 12345;
        let mut u = move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let exp: Vec<f64> = (0..400).map(|_| -(1.0 - u()).ln() * 0.4).collect();
        let aia: Vec<f64> = (0..300)
            .map(|_| match u() {
                v if v < 0.5 => 0.0,
                v if v < 0.7 => 0.5,
                _ => 1.0,
            })
            .collect();
        let bimodal: Vec<f64> = (0..250)
            .map(|_| if u() < 0.3 { 1.5 + u() } else { 0.2 * u() })
            .collect();
        vec![("exponential", exp), ("aia", aia), ("bimodal", bimodal)]
    }

    /// The reference: the percentile bootstrap with 40,000 resamples (Monte Carlo error
    /// about 0.8% of the half-width).
    fn reference_cfg() -> StatsConfig {
        StatsConfig {
            bootstrap_resamples: 40_000,
            max_bootstrap_draws: u64::MAX,
            resample_up_to: usize::MAX,
            ..StatsConfig::default()
        }
    }

    /// Each end within `tol` half-widths of the reference's.
    fn within(new: [f64; 2], reference: [f64; 2], tol: f64) -> bool {
        let half = (reference[1] - reference[0]) / 2.0;
        (new[0] - reference[0]).abs() <= tol * half && (new[1] - reference[1]).abs() <= tol * half
    }

    #[test]
    fn closed_form_mean_interval_is_the_bootstrap_within_tolerance() {
        let cfg = StatsConfig::default();
        for (name, v) in samples() {
            assert!(v.len() > cfg.resample_up_to);
            let new = mean_interval(&v, &cfg, 5).unwrap();
            let reference = bootstrap_mean(&v, &reference_cfg(), 11).unwrap();
            assert!(
                within(new, reference, TOLERANCE),
                "{name}: {new:?} vs {reference:?}"
            );
            // The expansion adds what the normal interval misses: the skewed sample's
            // interval is shifted right of mean ± z·sd.
            if name == "exponential" {
                let [m, var, _, _] = mean_cumulants(&v);
                let normal = [m - Z95 * var.sqrt(), m + Z95 * var.sqrt()];
                assert!(
                    new[0] > normal[0] && new[1] > normal[1],
                    "{new:?} {normal:?}"
                );
            }
        }
    }

    #[test]
    fn closed_form_balanced_interval_is_the_bootstrap_within_tolerance() {
        let cfg = StatsConfig::default();
        for classes in [
            vec![(200, 300), (150, 260), (30, 120)],
            vec![(640, 650), (300, 640), (0, 640)],
        ] {
            let new = balanced_interval(&classes, &cfg, 5).unwrap();
            let reference = bootstrap_balanced(&classes, &reference_cfg(), 11).unwrap();
            assert!(
                within(new, reference, TOLERANCE),
                "{classes:?}: {new:?} vs {reference:?}"
            );
        }
        // Every class at 0 or 1: no spread, as the resampling says.
        let ci = balanced_interval(&[(400, 400), (0, 300), (0, 100)], &cfg, 1).unwrap();
        assert!(
            close(ci[0], 1.0 / 3.0, 1e-12) && close(ci[1], 1.0 / 3.0, 1e-12),
            "{ci:?}"
        );
    }

    #[test]
    fn small_samples_are_resampled_as_before() {
        let cfg = StatsConfig::default();
        let v: Vec<f64> = (0..cfg.resample_up_to)
            .map(|i| (i % 9) as f64 * 0.3)
            .collect();
        assert_eq!(mean_interval(&v, &cfg, 3), bootstrap_mean(&v, &cfg, 3));
        let classes = [(30, 50), (10, 30), (5, 20)];
        assert_eq!(
            balanced_interval(&classes, &cfg, 3),
            bootstrap_balanced(&classes, &cfg, 3)
        );
        // A sample too skewed for the expansion (one outlier in 500) is resampled too.
        let mut w = vec![0.0; 499];
        w.push(100.0);
        assert!(expansion(mean_cumulants(&w)).is_none());
        assert_eq!(mean_interval(&w, &cfg, 3), bootstrap_mean(&w, &cfg, 3));
    }
}
