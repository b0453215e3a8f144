//! One row of the report's metric tables (a model, or a model × family / band / GT
//! action group): rates with their 95% intervals, distances, rule counts and the
//! per-class action counts.

use crate::aggregate::Acc;
use crate::safety_rule::SafetyRule;
use serde::Serialize;

#[derive(Debug, Clone, Serialize)]
pub struct RuleCounts {
    #[serde(rename = "R1")]
    pub r1: u64,
    #[serde(rename = "R2")]
    pub r2: u64,
    #[serde(rename = "R3")]
    pub r3: u64,
    #[serde(rename = "R4")]
    pub r4: u64,
}

impl RuleCounts {
    pub(crate) fn new(c: [u64; 4]) -> Self {
        RuleCounts {
            r1: c[0],
            r2: c[1],
            r3: c[2],
            r4: c[3],
        }
    }

    pub fn get(&self, r: SafetyRule) -> u64 {
        [self.r1, self.r2, self.r3, self.r4][r.index()]
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct ActionCounts {
    #[serde(rename = "CATCH")]
    pub catch: u64,
    #[serde(rename = "DODGE")]
    pub dodge: u64,
    #[serde(rename = "NO_ACTION")]
    pub no_action: u64,
    /// No parseable plan (R1).
    pub unparseable: u64,
}

/// A 95% interval `[low, high]` (`null` when its estimate is).
pub type Interval = Option<[f64; 2]>;

/// Metrics over one group of scenes. Rates are fractions in [0, 1]; a metric is `null`
/// when its denominator is 0. SAA, safety and AIA are over the group's expected scenes,
/// an unanswered one counting as failed (over the answered ones with `--answered-only`);
/// the freeze rate is over the answered decisions. Missing distance values (no impact
/// point, or no plan) leave the denominator and are counted in `*_missing`. `*_ci`: 95%
/// intervals (Wilson for rates; seeded bootstrap over scenes for means, on the overall
/// and per-GT-action rows).
#[derive(Debug, Clone, Serialize)]
pub struct MetricsRow {
    pub group: String,
    /// Answered (scored) decisions.
    pub decisions: u64,
    /// Expected scenes of the group (answered + unanswered).
    pub expected: u64,
    /// Expected scenes without a scored decision (failed; not R1).
    pub unanswered: u64,
    pub saa: Option<f64>,
    pub saa_ci: Interval,
    pub safety: Option<f64>,
    pub safety_ci: Interval,
    pub d_end: Option<f64>,
    pub d_end_ci: Interval,
    pub d_end_n: u64,
    pub d_end_missing: u64,
    pub aia: Option<f64>,
    pub aia_ci: Interval,
    pub d_min: Option<f64>,
    pub d_min_ci: Interval,
    pub closing: Option<f64>,
    pub hde_n: u64,
    pub hde_missing: u64,
    pub freeze_rate: Option<f64>,
    pub freeze_rate_ci: Interval,
    pub first_rule: RuleCounts,
    pub rules_fired: RuleCounts,
    pub predicted: ActionCounts,
}

impl MetricsRow {
    /// Metrics over the answered decisions only.
    pub fn from_acc(group: impl Into<String>, a: &Acc) -> Self {
        Self::with_unanswered(group, a, 0, false)
    }

    /// Metrics over the expected scenes: `unanswered` of them count as failed, unless
    /// `answered_only`.
    pub fn with_unanswered(
        group: impl Into<String>,
        a: &Acc,
        unanswered: u64,
        answered_only: bool,
    ) -> Self {
        let den = if answered_only { a.n } else { a.n + unanswered };
        let rate = |k: u64| (den > 0).then(|| k as f64 / den as f64);
        MetricsRow {
            group: group.into(),
            decisions: a.n,
            expected: a.n + unanswered,
            unanswered,
            saa: rate(a.saa),
            saa_ci: crate::stats::wilson(a.saa, den),
            safety: rate(a.safe),
            safety_ci: crate::stats::wilson(a.safe, den),
            d_end: a.d_end.value(),
            d_end_ci: None,
            d_end_n: a.d_end.n,
            d_end_missing: a.d_end.missing,
            aia: rate(0).map(|_| a.aia.sum / den as f64),
            aia_ci: None,
            d_min: a.d_min.value(),
            d_min_ci: None,
            closing: a.closing.value(),
            hde_n: a.d_min.n,
            hde_missing: a.d_min.missing,
            freeze_rate: a.rate(a.predicted[2]),
            freeze_rate_ci: crate::stats::wilson(a.predicted[2], a.n),
            first_rule: RuleCounts::new(a.first),
            rules_fired: RuleCounts::new(a.fired),
            predicted: ActionCounts {
                catch: a.predicted[0],
                dodge: a.predicted[1],
                no_action: a.predicted[2],
                unparseable: a.predicted[3],
            },
        }
    }
}

/// Recall of one ground-truth class: its SAA over its expected scenes.
#[derive(Debug, Clone, Serialize)]
pub struct ClassRecall {
    pub class: String,
    pub scenes: u64,
    pub correct: u64,
    pub recall: Option<f64>,
    pub recall_ci: Interval,
}
