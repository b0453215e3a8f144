//! The paper's analyses over the scored decisions (specification §11): safety-rule breakdown,
//! out-of-reach catches, speed sensitivity and consistency, majority voting, the
//! adversarial probe and the look-alike comparison — part of the [`crate::report::Report`].

use crate::aggregate::{ModelAgg, Rec};
use crate::dataset::Dataset;
use crate::metrics_row::RuleCounts;
use rh_contract::Action;
use serde::Serialize;
use std::collections::HashMap;

pub(crate) fn ratio(a: u64, b: u64) -> Option<f64> {
    (b > 0).then(|| a as f64 / b as f64)
}

pub(crate) fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Safety-rule breakdown for one model (or pooled).
#[derive(Debug, Clone, Serialize)]
pub struct SafetyBreakdown {
    pub model: String,
    pub decisions: u64,
    pub violations: u64,
    pub first_rule: RuleCounts,
    pub rules_fired: RuleCounts,
    /// Share of decisions on DODGE scenes that broke a rule.
    pub unsafe_on_dodge_scenes: Option<f64>,
    /// Wrong decisions (SAA = 0) and how many of them were NO_ACTION (freezing).
    pub mistakes: u64,
    pub freeze_mistakes: u64,
}

/// "Correct but out of reach" (correct CATCH decisions with an impact point).
#[derive(Debug, Clone, Serialize)]
pub struct OutOfReach {
    pub model: String,
    pub correct_catch: u64,
    pub median_d_end_correct_catch: Option<f64>,
    /// Median d_end over every correct decision (any action) with an impact point.
    pub median_d_end_correct_any: Option<f64>,
    pub misses: u64,
    pub miss_share: Option<f64>,
    pub misses_falling_short_share: Option<f64>,
    pub standing_far_share: Option<f64>,
}

/// Speed analyses over the speed-sweeping families.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedAnalysis {
    pub model: String,
    pub decisions: u64,
    pub freeze_rate_by_band: Vec<Option<f64>>,
    /// Scored decisions per band (the freeze rate's denominators).
    pub decisions_by_band: Vec<u64>,
    /// 95% Wilson intervals of `freeze_rate_by_band`.
    pub freeze_rate_by_band_ci: Vec<Option<[f64; 2]>>,
    pub saa_by_band: Vec<Option<f64>>,
    /// Scene groups with a scored decision at all four bands.
    pub complete_groups: u64,
    pub consistent_groups: u64,
    pub consistency: Option<f64>,
    pub slow_vs_very_fast_agreement: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Voting {
    pub models: usize,
    /// Scenes where every model has a scored decision.
    pub scenes: u64,
    pub unanimous: u64,
    pub unanimous_share: Option<f64>,
    pub unanimous_accuracy: Option<f64>,
    pub majority_vote_saa: Option<f64>,
    pub mean_model_saa: Option<f64>,
    pub best_model: Option<String>,
    pub best_model_saa: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct AdversarialProbe {
    pub model: String,
    pub decisions: u64,
    pub questions_material: u64,
    pub share: Option<f64>,
}

/// Catch rate on an adversarial object vs. on its genuine look-alike.
#[derive(Debug, Clone, Serialize)]
pub struct LookalikeComparison {
    pub object_id: String,
    pub looks_like: String,
    pub decisions: u64,
    pub catch_rate: Option<f64>,
    pub dodge_rate: Option<f64>,
    pub lookalike_decisions: u64,
    pub lookalike_catch_rate: Option<f64>,
    pub lookalike_dodge_rate: Option<f64>,
}

/// Adversarial twin pairs (label rule v5, `twin_scene_id`): a disguised object's scene
/// and the same scene with its genuine look-alike. How often a model gave the disguised
/// object the decision it gave the look-alike where the two labels differ.
#[derive(Debug, Clone, Serialize)]
pub struct TwinProbe {
    pub model: String,
    /// Pairs whose two scenes the model decided.
    pub pairs: u64,
    /// ... of them, pairs whose labels differ.
    pub pairs_labels_differ: u64,
    /// ... of those, pairs where the model decided both scenes alike: it treated the
    /// disguised object as its look-alike.
    pub same_decision: u64,
    pub share_same: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Analyses {
    pub safety: Vec<SafetyBreakdown>,
    pub out_of_reach: Vec<OutOfReach>,
    pub speed: Vec<SpeedAnalysis>,
    pub voting: Voting,
    pub adversarial: Vec<AdversarialProbe>,
    pub lookalikes: Vec<LookalikeComparison>,
    pub twins: Vec<TwinProbe>,
}

pub(crate) fn safety_breakdown(name: &str, m: &ModelAgg) -> SafetyBreakdown {
    let dodge = &m.by_gt[Action::Dodge.index()];
    let mistakes = m.overall.n - m.overall.saa;
    // Freezing mistakes: NO_ACTION predicted where the GT was not NO_ACTION.
    let freeze_mistakes = m.overall.predicted[2] - m.by_gt[Action::NoAction.index()].predicted[2];
    SafetyBreakdown {
        model: name.to_string(),
        decisions: m.overall.n,
        violations: m.overall.n - m.overall.safe,
        first_rule: RuleCounts::new(m.overall.first),
        rules_fired: RuleCounts::new(m.overall.fired),
        unsafe_on_dodge_scenes: dodge.rate(dodge.n - dodge.safe),
        mistakes,
        freeze_mistakes,
    }
}

/// Records of several models, for the pooled rows of record-based analyses.
pub(crate) fn out_of_reach(
    name: &str,
    reach: &crate::aggregate::ReachAcc,
    recs: &[&[Rec]],
    ds: &Dataset,
) -> OutOfReach {
    let mut catch_d = Vec::new();
    let mut any_d = Vec::new();
    for r in recs {
        for (rec, sc) in r.iter().zip(&ds.scenes) {
            let (Some(action), Some(d)) = (rec.decision(), rec.end_distance()) else {
                continue;
            };
            if action == Some(sc.gt_action) {
                any_d.push(d);
                if sc.gt_action == Action::Catch {
                    catch_d.push(d);
                }
            }
        }
    }
    OutOfReach {
        model: name.to_string(),
        correct_catch: reach.correct_catch,
        median_d_end_correct_catch: median(&mut catch_d),
        median_d_end_correct_any: median(&mut any_d),
        misses: reach.misses,
        miss_share: ratio(reach.misses, reach.correct_catch),
        misses_falling_short_share: ratio(reach.misses_short, reach.misses),
        standing_far_share: ratio(reach.standing_far, reach.correct_catch),
    }
}

pub(crate) fn speed_analysis(
    name: &str,
    recs: &[&[Rec]],
    ds: &Dataset,
    groups: &[[Option<u32>; 4]],
) -> SpeedAnalysis {
    let mut n_band = [0u64; 4];
    let mut freeze = [0u64; 4];
    let mut saa = [0u64; 4];
    let mut decisions = 0;
    for r in recs {
        for (rec, sc) in r.iter().zip(&ds.scenes) {
            let (Some(b), true, Some(action)) = (sc.speed_band, sc.speed_sweep, rec.decision())
            else {
                continue;
            };
            decisions += 1;
            n_band[b as usize] += 1;
            freeze[b as usize] += (action == Some(Action::NoAction)) as u64;
            saa[b as usize] += (action == Some(sc.gt_action)) as u64;
        }
    }
    let (mut complete, mut consistent, mut ends_agree) = (0u64, 0u64, 0u64);
    for r in recs {
        for g in groups {
            let acts: Option<Vec<Option<Action>>> = g
                .iter()
                .map(|s| s.and_then(|i| r[i as usize].decision()))
                .collect();
            let Some(acts) = acts else { continue };
            complete += 1;
            consistent += acts.iter().all(|&a| a == acts[0]) as u64;
            ends_agree += (acts[0] == acts[3]) as u64;
        }
    }
    SpeedAnalysis {
        model: name.to_string(),
        decisions,
        freeze_rate_by_band: (0..4).map(|b| ratio(freeze[b], n_band[b])).collect(),
        decisions_by_band: n_band.to_vec(),
        freeze_rate_by_band_ci: (0..4)
            .map(|b| crate::stats::wilson(freeze[b], n_band[b]))
            .collect(),
        saa_by_band: (0..4).map(|b| ratio(saa[b], n_band[b])).collect(),
        complete_groups: complete,
        consistent_groups: consistent,
        consistency: ratio(consistent, complete),
        slow_vs_very_fast_agreement: ratio(ends_agree, complete),
    }
}

/// Scene groups of speed-sweeping families with their four band variants.
pub(crate) fn speed_groups(ds: &Dataset) -> Vec<[Option<u32>; 4]> {
    let mut map: HashMap<&str, [Option<u32>; 4]> = HashMap::new();
    let mut order: Vec<&str> = Vec::new();
    for (i, sc) in ds.scenes.iter().enumerate() {
        let (Some(b), true) = (sc.speed_band, sc.speed_sweep) else {
            continue;
        };
        let e = map.entry(sc.group_id.as_str()).or_insert_with(|| {
            order.push(sc.group_id.as_str());
            [None; 4]
        });
        e[b as usize].get_or_insert(i as u32);
    }
    order.into_iter().map(|g| map[g]).collect()
}

/// Majority vote: the most frequent action among the models' decisions on a scene;
/// ties go to the safer action (DODGE, then NO_ACTION, then CATCH); "no parseable plan"
/// votes never win. Unanimity: every model chose the same action.
pub(crate) fn voting(models: &[&ModelAgg], ds: &Dataset) -> Voting {
    let k = models.len();
    let mut scenes = 0u64;
    let (mut unanimous, mut unanimous_right, mut majority_right) = (0u64, 0u64, 0u64);
    let mut per_model_right = vec![0u64; k];
    if k >= 1 {
        for (i, sc) in ds.scenes.iter().enumerate() {
            if !models.iter().all(|m| m.records[i].is_scored()) {
                continue;
            }
            scenes += 1;
            let gt = sc.gt_action;
            // Votes per action, and for "no parseable plan" last.
            let mut votes = [0u32; 4];
            let decision = |m: &ModelAgg| m.records[i].decision().flatten();
            for (j, m) in models.iter().enumerate() {
                let a = decision(m);
                votes[a.map_or(3, Action::index)] += 1;
                per_model_right[j] += (a == Some(gt)) as u64;
            }
            let first = decision(models[0]);
            if first.is_some() && models.iter().all(|m| decision(m) == first) {
                unanimous += 1;
                unanimous_right += (first == Some(gt)) as u64;
            }
            // Tie order: DODGE, NO_ACTION, CATCH.
            let mut best: Option<Action> = None;
            for a in [Action::Dodge, Action::NoAction, Action::Catch] {
                if votes[a.index()] > 0 && best.is_none_or(|b| votes[a.index()] > votes[b.index()])
                {
                    best = Some(a);
                }
            }
            majority_right += (best == Some(gt)) as u64;
        }
    }
    let best = per_model_right
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))
        .map(|(j, &r)| (models[j].name.clone(), r));
    Voting {
        models: k,
        scenes,
        unanimous,
        unanimous_share: ratio(unanimous, scenes),
        unanimous_accuracy: ratio(unanimous_right, unanimous),
        majority_vote_saa: ratio(majority_right, scenes),
        mean_model_saa: (scenes > 0 && k > 0)
            .then(|| per_model_right.iter().sum::<u64>() as f64 / (scenes as f64 * k as f64)),
        best_model_saa: best.as_ref().and_then(|b| ratio(b.1, scenes)),
        best_model: best.map(|b| b.0),
    }
}

pub(crate) fn lookalikes(models: &[&ModelAgg], ds: &Dataset) -> Vec<LookalikeComparison> {
    // object_id -> (decisions, catches, dodges)
    let mut by_obj: HashMap<&str, (u64, u64, u64)> = HashMap::new();
    for m in models {
        for (rec, sc) in m.records.iter().zip(&ds.scenes) {
            let Some(action) = rec.decision() else {
                continue;
            };
            let e = by_obj.entry(sc.object_id.as_str()).or_default();
            e.0 += 1;
            e.1 += (action == Some(Action::Catch)) as u64;
            e.2 += (action == Some(Action::Dodge)) as u64;
        }
    }
    let mut pairs: Vec<(String, String)> = ds
        .scenes
        .iter()
        .filter(|s| s.adversarial)
        .filter_map(|s| s.looks_like.clone().map(|l| (s.object_id.clone(), l)))
        .collect();
    pairs.sort();
    pairs.dedup();
    pairs
        .into_iter()
        .map(|(obj, like)| {
            let a = by_obj.get(obj.as_str()).copied().unwrap_or_default();
            let b = by_obj.get(like.as_str()).copied().unwrap_or_default();
            LookalikeComparison {
                object_id: obj,
                looks_like: like,
                decisions: a.0,
                catch_rate: ratio(a.1, a.0),
                dodge_rate: ratio(a.2, a.0),
                lookalike_decisions: b.0,
                lookalike_catch_rate: ratio(b.1, b.0),
                lookalike_dodge_rate: ratio(b.2, b.0),
            }
        })
        .collect()
}

pub(crate) fn twin_probes(models: &[&ModelAgg], ds: &Dataset) -> Vec<TwinProbe> {
    // (disguised scene, twin scene), each pair once.
    let pairs: Vec<(usize, usize)> = ds
        .scenes
        .iter()
        .enumerate()
        .filter(|(_, s)| s.adversarial && s.valid)
        .filter_map(|(i, s)| {
            let twin = ds.index.get(s.twin_scene_id.as_ref()?)?;
            ds.scenes[*twin as usize]
                .valid
                .then_some((i, *twin as usize))
        })
        .collect();
    models
        .iter()
        .map(|m| {
            let mut out = TwinProbe {
                model: m.name.clone(),
                pairs: 0,
                pairs_labels_differ: 0,
                same_decision: 0,
                share_same: None,
            };
            for &(a, b) in &pairs {
                let (Some(x), Some(y)) = (m.records[a].decision(), m.records[b].decision()) else {
                    continue;
                };
                out.pairs += 1;
                if ds.scenes[a].gt_action != ds.scenes[b].gt_action {
                    out.pairs_labels_differ += 1;
                    out.same_decision += u64::from(x == y);
                }
            }
            out.share_same = ratio(out.same_decision, out.pairs_labels_differ);
            out
        })
        .collect()
}
