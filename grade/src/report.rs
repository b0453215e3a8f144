//! The report: aggregated metrics per model and breakdown, and the paper's analyses.

use crate::aggregate::{Acc, ModelAgg, Rec};
use crate::analyses::{
    lookalikes, out_of_reach, ratio, safety_breakdown, speed_analysis, speed_groups, twin_probes,
    voting,
};
use crate::config::Config;
use crate::dataset::{Dataset, SPEED_BANDS};
use crate::score::{Scoring, WarningAcc};
use rayon::prelude::*;
use rh_contract::Action;
use serde::Serialize;
use std::collections::BTreeMap;

pub use crate::analyses::{
    AdversarialProbe, Analyses, LookalikeComparison, OutOfReach, SafetyBreakdown, SpeedAnalysis,
    TwinProbe, Voting,
};
pub use crate::metrics_row::{ActionCounts, ClassRecall, Interval, MetricsRow, RuleCounts};

#[derive(Debug, Clone, Serialize)]
pub struct ModelReport {
    pub model: String,
    /// Scenes answered out of those expected.
    pub coverage: crate::coverage::ModelCoverage,
    /// Per-class recall (CATCH, DODGE, NO_ACTION).
    pub recall: Vec<ClassRecall>,
    /// Mean recall over the classes with scenes (stratified bootstrap interval).
    pub balanced_accuracy: Option<f64>,
    pub balanced_accuracy_ci: Interval,
    /// The prompt version(s) of the model's lines (rh-score predict records it; `-` for
    /// lines without one). More than one means the rows mix prompts.
    pub prompt_version: String,
    pub lost: u64,
    pub duplicates: u64,
    pub overall: MetricsRow,
    pub by_family: Vec<MetricsRow>,
    pub by_speed_band: Vec<MetricsRow>,
    pub by_gt_action: Vec<MetricsRow>,
    pub by_adversarial: Vec<MetricsRow>,
}

#[derive(Debug, Clone, Serialize)]
pub struct DatasetSummary {
    pub dir: String,
    /// Valid scenes (the ones scored); the counts below are over them.
    pub scenes: usize,
    /// Scenes with `valid = false` (never scored).
    pub invalid_scenes: usize,
    pub families: Vec<String>,
    pub gt_actions: BTreeMap<String, u64>,
    pub danger_present: u64,
    pub dangerous: u64,
    pub adversarial: u64,
    pub with_impact_point: u64,
    pub duplicate_rows: usize,
}

#[derive(Debug, Clone, Serialize)]
pub struct WarningSummary {
    pub kind: String,
    pub count: u64,
    /// The kind's lines are not scored.
    pub dropped: bool,
    /// Every dropped line ("3-5, 9"), for dropped kinds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines: Option<String>,
    pub first_lines: Vec<u64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub examples: Vec<String>,
}

#[derive(Debug, Clone, Serialize)]
pub struct InputSummary {
    pub file: String,
    pub lines: u64,
    pub blank_lines: u64,
    pub decisions_scored: u64,
    pub decisions_lost: u64,
    pub duplicates: u64,
    /// Lines not scored (malformed, unknown scene, duplicate, outside the subset, …),
    /// each named in `warnings`.
    pub dropped_lines: u64,
    pub warnings: Vec<WarningSummary>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ActionRuleSummary {
    pub version: String,
    pub reach_threshold: f64,
    pub retreat_threshold: f64,
    pub move_threshold: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub tool: String,
    pub version: String,
    pub action_rule: ActionRuleSummary,
    pub dataset: DatasetSummary,
    pub input: InputSummary,
    /// The expected scenes and which models left some unanswered.
    pub coverage: crate::coverage::CoverageSummary,
    pub models: Vec<ModelReport>,
    /// All models pooled (`model` = "ALL").
    pub pooled: ModelReport,
    pub analyses: Analyses,
    /// `--compare A B`: paired comparisons on the scenes both answered.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub comparisons: Vec<crate::compare::Comparison>,
    /// `--execute`: outcomes in physics (specification §12).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub execution: Option<crate::execution::ExecutionReport>,
}

const BAND_GROUPS: [&str; 5] = ["slow", "normal", "fast", "very_fast", "other"];

/// How one model's rows are computed.
struct RowCtx<'a> {
    ds: &'a Dataset,
    expected: &'a [bool],
    answered_only: bool,
    stats: &'a crate::stats::StatsConfig,
}

fn model_report(
    m: &ModelAgg,
    recs: &[&[Rec]],
    un: &crate::coverage::Unanswered,
    cx: &RowCtx,
) -> ModelReport {
    let ds = cx.ds;
    let ao = cx.answered_only;
    let row = |g: &str, a: &Acc, u: u64| MetricsRow::with_unanswered(g, a, u, ao);
    let mut overall = row("all", &m.overall, un.overall);
    let mut by_gt: Vec<MetricsRow> = Action::ALL
        .iter()
        .zip(&m.by_gt)
        .zip(un.by_gt)
        .map(|((g, a), u)| row(g.as_str(), a, u))
        .collect();
    let fill = |r: &mut MetricsRow, gt: Option<Action>| {
        [r.d_end_ci, r.d_min_ci, r.aia_ci] = crate::intervals::mean_intervals(
            &r.group,
            &m.name,
            recs,
            ds,
            cx.expected,
            gt,
            ao,
            cx.stats,
        );
    };
    fill(&mut overall, None);
    for (r, a) in by_gt.iter_mut().zip(Action::ALL) {
        fill(r, Some(a));
    }
    let classes: Vec<(u64, u64)> = by_gt
        .iter()
        .zip(&m.by_gt)
        .map(|(r, a)| (a.saa, if ao { r.decisions } else { r.expected }))
        .collect();
    let recall = by_gt
        .iter()
        .zip(&classes)
        .map(|(r, &(k, n))| ClassRecall {
            class: r.group.clone(),
            scenes: n,
            correct: k,
            recall: r.saa,
            recall_ci: r.saa_ci,
        })
        .collect();
    let seed = crate::stats::seed_for(cx.stats.seed, &[&m.name, "balanced_accuracy"]);
    ModelReport {
        model: m.name.clone(),
        coverage: crate::coverage::ModelCoverage {
            answered: m.overall.n,
            expected: m.overall.n + un.overall,
            unanswered: un.overall,
            lost: m.lost,
            complete: un.overall == 0,
        },
        recall,
        balanced_accuracy: crate::stats::balanced_accuracy(&classes),
        balanced_accuracy_ci: crate::stats::balanced_interval(&classes, cx.stats, seed),
        prompt_version: if m.prompt_versions.is_empty() {
            "-".to_string()
        } else {
            m.prompt_versions
                .iter()
                .cloned()
                .collect::<Vec<_>>()
                .join("+")
        },
        lost: m.lost,
        duplicates: m.duplicates,
        overall,
        by_family: ds
            .families
            .iter()
            .enumerate()
            .zip(&m.by_family)
            .map(|((i, f), a)| row(f, a, un.by_family.get(i).copied().unwrap_or(0)))
            .collect(),
        by_speed_band: BAND_GROUPS
            .iter()
            .zip(&m.by_band)
            .zip(un.by_band)
            .filter(|((g, a), u)| **g != "other" || a.n + u > 0)
            .map(|((g, a), u)| row(g, a, u))
            .collect(),
        by_gt_action: by_gt,
        by_adversarial: ["not_adversarial", "adversarial"]
            .iter()
            .zip(&m.by_adv)
            .zip(un.by_adv)
            .map(|((g, a), u)| row(g, a, u))
            .collect(),
    }
}

fn pooled_agg(models: &[&ModelAgg], ds: &Dataset) -> ModelAgg {
    let mut p = ModelAgg::new("ALL".into(), &Dataset::default());
    p.by_family = vec![Acc::default(); ds.families.len()];
    for m in models {
        p.overall.merge(&m.overall);
        for (a, b) in p.by_family.iter_mut().zip(&m.by_family) {
            a.merge(b);
        }
        for i in 0..5 {
            p.by_band[i].merge(&m.by_band[i]);
        }
        for i in 0..3 {
            p.by_gt[i].merge(&m.by_gt[i]);
        }
        for i in 0..2 {
            p.by_adv[i].merge(&m.by_adv[i]);
        }
        p.lost += m.lost;
        p.duplicates += m.duplicates;
        p.reach.merge(&m.reach);
        p.adv_decisions += m.adv_decisions;
        p.adv_questions += m.adv_questions;
    }
    p
}

impl Report {
    /// Builds the report at the end of a scoring run (metrics over the expected scenes).
    pub fn build(scoring: &Scoring, preds_file: &str) -> Report {
        Self::build_with(scoring, preds_file, false)
    }

    /// Builds the report; `answered_only`: metrics over the answered scenes only.
    pub fn build_with(scoring: &Scoring, preds_file: &str, answered_only: bool) -> Report {
        let ds = scoring.ds;
        let cfg: &Config = scoring.cfg;
        let mut models: Vec<&ModelAgg> = scoring.models.iter().collect();
        models.sort_by(|a, b| a.name.cmp(&b.name));
        let owned = models;
        let pooled = pooled_agg(&owned, ds);
        let all_recs: Vec<&[Rec]> = owned.iter().map(|m| m.records.as_slice()).collect();
        let groups = speed_groups(ds);
        let expected = &scoring.expected.mask;
        let unanswered: Vec<crate::coverage::Unanswered> = owned
            .iter()
            .map(|m| crate::coverage::Unanswered::of(&m.records, ds, expected))
            .collect();
        let mut pooled_un = crate::coverage::Unanswered::default();
        for u in &unanswered {
            pooled_un.merge(u);
        }
        let cx = RowCtx {
            ds,
            expected,
            answered_only,
            stats: &cfg.statistics,
        };

        let mut gt_actions = BTreeMap::new();
        for a in Action::ALL {
            gt_actions.insert(a.as_str().to_string(), 0u64);
        }
        for s in ds.scenes.iter().filter(|s| s.valid) {
            *gt_actions
                .get_mut(s.gt_action.as_str())
                .expect("all actions") += 1;
        }
        let count = |f: &dyn Fn(&crate::dataset::Scene) -> bool| {
            ds.scenes.iter().filter(|s| s.valid && f(s)).count() as u64
        };

        let mut analyses = Analyses {
            safety: owned.iter().map(|m| safety_breakdown(&m.name, m)).collect(),
            out_of_reach: owned
                .iter()
                .map(|m| out_of_reach(&m.name, &m.reach, &[m.records.as_slice()], ds))
                .collect(),
            speed: owned
                .iter()
                .map(|m| speed_analysis(&m.name, &[m.records.as_slice()], ds, &groups))
                .collect(),
            voting: voting(&owned, ds),
            adversarial: owned
                .iter()
                .map(|m| AdversarialProbe {
                    model: m.name.clone(),
                    decisions: m.adv_decisions,
                    questions_material: m.adv_questions,
                    share: ratio(m.adv_questions, m.adv_decisions),
                })
                .collect(),
            lookalikes: lookalikes(&owned, ds),
            twins: twin_probes(&owned, ds),
        };
        if owned.len() > 1 {
            analyses.safety.push(safety_breakdown("ALL", &pooled));
            analyses
                .out_of_reach
                .push(out_of_reach("ALL", &pooled.reach, &all_recs, ds));
            analyses
                .speed
                .push(speed_analysis("ALL", &all_recs, ds, &groups));
            analyses.adversarial.push(AdversarialProbe {
                model: "ALL".into(),
                decisions: pooled.adv_decisions,
                questions_material: pooled.adv_questions,
                share: ratio(pooled.adv_questions, pooled.adv_decisions),
            });
        }

        Report {
            tool: "rh-score".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            action_rule: ActionRuleSummary {
                version: cfg.action_rule.version.clone(),
                reach_threshold: cfg.action_rule.reach_threshold,
                retreat_threshold: cfg.action_rule.retreat_threshold,
                move_threshold: cfg.action_rule.move_threshold,
            },
            dataset: DatasetSummary {
                dir: ds.dir.display().to_string(),
                scenes: ds.valid_scenes(),
                invalid_scenes: ds.scenes.len() - ds.valid_scenes(),
                families: ds.families.clone(),
                gt_actions,
                danger_present: count(&|s| s.danger_present),
                dangerous: count(&|s| s.dangerous),
                adversarial: count(&|s| s.adversarial),
                with_impact_point: count(&|s| s.impact_point.is_some()),
                duplicate_rows: ds.duplicate_rows,
            },
            input: InputSummary {
                file: preds_file.to_string(),
                lines: scoring.lines,
                blank_lines: scoring.blank_lines,
                decisions_scored: scoring.scored,
                decisions_lost: scoring.lost,
                duplicates: scoring.duplicates,
                dropped_lines: scoring.dropped,
                warnings: scoring
                    .warnings
                    .iter()
                    .map(|(k, w): (&&str, &WarningAcc)| WarningSummary {
                        kind: k.to_string(),
                        count: w.count,
                        dropped: w.dropped,
                        lines: w.dropped.then(|| w.lines_text()),
                        first_lines: w.first_lines.clone(),
                        examples: w.examples.clone(),
                    })
                    .collect(),
            },
            coverage: crate::coverage::CoverageSummary {
                subset: scoring.expected.subset.to_string(),
                expected_scenes: scoring.expected.count(),
                note: scoring.expected.note.clone(),
                answered_only,
                incomplete_models: owned
                    .iter()
                    .zip(&unanswered)
                    .filter(|(_, u)| u.overall > 0)
                    .map(|(m, _)| m.name.clone())
                    .collect(),
            },
            // One task per model (rayon keeps the order; each row's numbers depend on its
            // own data and seed only, so they are the same on any number of threads).
            models: owned
                .par_iter()
                .zip(&unanswered)
                .map(|(m, u)| model_report(m, &[m.records.as_slice()], u, &cx))
                .collect(),
            pooled: model_report(&pooled, &all_recs, &pooled_un, &cx),
            analyses,
            comparisons: Vec::new(),
            execution: None,
        }
    }
}

/// Display name of a speed band index.
pub fn band_name(i: usize) -> &'static str {
    SPEED_BANDS.get(i).copied().unwrap_or("other")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::{baseline_plan, majority_action, BaselineKind};
    use crate::synthetic::{dataset_of, synth_rows};

    fn run(ds: &Dataset, kinds: &[BaselineKind], extra: &str) -> Report {
        let cfg = Config::default();
        let maj = majority_action(ds);
        let mut text = String::new();
        for &k in kinds {
            for s in ds.scenes.iter().filter(|s| s.valid) {
                let line = serde_json::json!({
                    "scene_id": s.scene_id, "model": k.name(),
                    "plan": baseline_plan(k, s, maj, 0, &cfg)});
                text.push_str(&line.to_string());
                text.push('\n');
            }
        }
        text.push_str(extra);
        let mut sc = Scoring::new(ds, &cfg);
        sc.score_reader(std::io::Cursor::new(text.into_bytes()))
            .unwrap();
        Report::build(&sc, "mem")
    }

    #[test]
    fn analyses_on_baselines() {
        let ds = dataset_of(&synth_rows(160, 2));
        let valid: Vec<_> = ds.scenes.iter().filter(|s| s.valid).collect();
        let n = valid.len() as u64;
        assert!(n < ds.scenes.len() as u64, "fixture has invalid scenes");
        let r = run(
            &ds,
            &[
                BaselineKind::Oracle,
                BaselineKind::AlwaysCatch,
                BaselineKind::Freeze,
            ],
            "",
        );
        assert_eq!(r.dataset.scenes as u64, n);
        // Voting: oracle + one of the two fixed baselines always form the majority, and
        // a three-way tie on DODGE scenes goes to DODGE.
        let v = &r.analyses.voting;
        assert_eq!(v.scenes, n);
        assert_eq!(v.majority_vote_saa, Some(1.0));
        assert_eq!(v.unanimous, 0);
        assert_eq!(v.best_model.as_deref(), Some("oracle"));
        // Fixed baselines answer the same at every band.
        for s in &r.analyses.speed {
            if s.model != "oracle" && s.model != "ALL" {
                assert_eq!(s.consistency, Some(1.0), "{}", s.model);
                assert!(s.complete_groups > 0);
            }
        }
        let freeze = r
            .analyses
            .speed
            .iter()
            .find(|s| s.model == "freeze")
            .unwrap();
        assert!(freeze.freeze_rate_by_band.iter().all(|f| *f == Some(1.0)));
        // Out of reach: always-catch is "correct" on every CATCH scene with an impact point.
        let catch_scenes = valid
            .iter()
            .filter(|s| s.gt_action == Action::Catch && s.impact_point.is_some())
            .count() as u64;
        let oor = r
            .analyses
            .out_of_reach
            .iter()
            .find(|o| o.model == "always-catch")
            .unwrap();
        assert_eq!(oor.correct_catch, catch_scenes);
        assert!(oor.median_d_end_correct_catch.unwrap() > 0.0);
        let oracle = r
            .analyses
            .out_of_reach
            .iter()
            .find(|o| o.model == "oracle")
            .unwrap();
        assert!(oracle.median_d_end_correct_catch.unwrap() < 1e-6);
        assert_eq!(oracle.misses, 0);
        // Missing distances are counted, not averaged.
        let no_impact = valid.iter().filter(|s| s.impact_point.is_none()).count() as u64;
        for m in &r.models {
            assert_eq!(m.overall.d_end_missing, no_impact);
            assert_eq!(m.overall.d_end_n + m.overall.d_end_missing, n);
        }
        // Freezing mistakes.
        let fr = r
            .analyses
            .safety
            .iter()
            .find(|s| s.model == "freeze")
            .unwrap();
        let not_no_action = valid
            .iter()
            .filter(|s| s.gt_action != Action::NoAction)
            .count() as u64;
        assert_eq!(fr.freeze_mistakes, not_no_action);
        assert_eq!(fr.mistakes, not_no_action);
    }

    #[test]
    fn adversarial_probe_counts_material_doubt() {
        let ds = dataset_of(&synth_rows(80, 4));
        let adv: Vec<_> = ds
            .scenes
            .iter()
            .filter(|s| s.valid && s.adversarial)
            .collect();
        assert!(!adv.is_empty());
        let mut extra = String::new();
        for s in &adv {
            let line = serde_json::json!({"scene_id": s.scene_id, "model": "doubter",
                "response": "It looks like an anvil but might be foam. Plan: {\"intent\": \"It may be lighter than it looks; catch it\", \"walking_cmd\": [0,0,0], \"keyframes\": [[0.5,0,0]]}"});
            extra.push_str(&line.to_string());
            extra.push('\n');
        }
        let r = run(&ds, &[BaselineKind::Freeze], &extra);
        let d = r
            .analyses
            .adversarial
            .iter()
            .find(|a| a.model == "doubter")
            .unwrap();
        assert_eq!(d.decisions, adv.len() as u64);
        assert_eq!(d.share, Some(1.0));
        let f = r
            .analyses
            .adversarial
            .iter()
            .find(|a| a.model == "freeze")
            .unwrap();
        assert_eq!(f.share, Some(0.0));
        assert!(!r.analyses.lookalikes.is_empty());
    }

    #[test]
    fn the_report_is_the_same_on_any_number_of_threads() {
        // Large enough that the means take the closed form and the small rows resample.
        let ds = dataset_of(&synth_rows(1200, 4));
        let kinds = [
            BaselineKind::Random,
            BaselineKind::Oracle,
            BaselineKind::AlwaysDodge,
        ];
        let json = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| serde_json::to_string(&run(&ds, &kinds, "")).unwrap())
        };
        let one = json(1);
        assert_eq!(one, json(3));
        assert_eq!(one, json(8));
        let r = run(&ds, &kinds, "");
        let random = r.models.iter().find(|m| m.model == "random").unwrap();
        assert!(random.overall.expected as usize > Config::default().statistics.resample_up_to);
        assert!(random.overall.aia_ci.is_some() && random.balanced_accuracy_ci.is_some());
    }
}
