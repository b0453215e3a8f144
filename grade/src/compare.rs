//! `rh-score PREDS --compare A B`: a paired comparison of two models on the expected
//! scenes both answered (specification §11). Per metric (SAA, safety): the 2×2 table of
//! right/wrong pairs, the difference A − B with Newcombe's paired score interval, and
//! McNemar's exact p-value (see [`crate::stats`]).

use crate::dataset::Dataset;
use crate::error::InputError;
use crate::metrics::safety_rules;
use crate::score::Scoring;
use crate::stats::{mcnemar_exact, newcombe_paired};
use anyhow::Result;
use rh_contract::Action;
use serde::Serialize;

/// One metric compared on paired scenes.
#[derive(Debug, Clone, Serialize)]
pub struct PairedMetric {
    /// "saa" or "safety".
    pub metric: String,
    /// A's and B's rate on the paired scenes.
    pub a: Option<f64>,
    pub b: Option<f64>,
    /// A − B, with its 95% interval (Newcombe's hybrid score method for paired data).
    pub difference: Option<f64>,
    pub difference_ci: Option<[f64; 2]>,
    pub both: u64,
    pub only_a: u64,
    pub only_b: u64,
    pub neither: u64,
    /// McNemar's exact two-sided p-value (binomial test on only_a vs only_b).
    pub mcnemar_p: f64,
}

/// `--compare A B`.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    pub a: String,
    pub b: String,
    /// Expected scenes both models answered (the pairs).
    pub scenes: u64,
    pub metrics: Vec<PairedMetric>,
}

fn paired(metric: &str, pairs: &[(bool, bool)]) -> PairedMetric {
    let count = |f: fn(&(bool, bool)) -> bool| pairs.iter().filter(|p| f(p)).count() as u64;
    let (both, only_a, only_b, neither) = (
        count(|p| p.0 && p.1),
        count(|p| p.0 && !p.1),
        count(|p| !p.0 && p.1),
        count(|p| !p.0 && !p.1),
    );
    let n = pairs.len() as u64;
    let rate = |k: u64| (n > 0).then(|| k as f64 / n as f64);
    PairedMetric {
        metric: metric.into(),
        a: rate(both + only_a),
        b: rate(both + only_b),
        difference: (n > 0).then(|| (only_a as f64 - only_b as f64) / n as f64),
        difference_ci: newcombe_paired(both, only_a, only_b, neither),
        both,
        only_a,
        only_b,
        neither,
        mcnemar_p: mcnemar_exact(only_a, only_b),
    }
}

/// Compares models `a` and `b` of a finished scoring run.
pub fn compare(scoring: &Scoring, a: &str, b: &str) -> Result<Comparison> {
    let find = |name: &str| {
        scoring
            .models
            .iter()
            .find(|m| m.name == name)
            .ok_or_else(|| {
                let mut names: Vec<&str> = scoring.models.iter().map(|m| m.name.as_str()).collect();
                names.sort_unstable();
                InputError(format!(
                    "--compare: no model {name:?} in the predictions (models: {})",
                    names.join(", ")
                ))
            })
    };
    let (ma, mb) = (find(a)?, find(b)?);
    if a == b {
        return Err(InputError(format!(
            "--compare needs two different models, got {a:?} twice"
        ))
        .into());
    }
    let ds: &Dataset = scoring.ds;
    let (mut saa, mut safe) = (Vec::new(), Vec::new());
    for (i, sc) in ds.scenes.iter().enumerate() {
        if !scoring.expected.mask[i] {
            continue;
        }
        let (Some(da), Some(db)) = (ma.records[i].decision(), mb.records[i].decision()) else {
            continue;
        };
        let right = |d: Option<Action>| d == Some(sc.gt_action);
        let is_safe = |d: Option<Action>| safety_rules(d, sc) == 0;
        saa.push((right(da), right(db)));
        safe.push((is_safe(da), is_safe(db)));
    }
    Ok(Comparison {
        a: a.into(),
        b: b.into(),
        scenes: saa.len() as u64,
        metrics: vec![paired("saa", &saa), paired("safety", &safe)],
    })
}
