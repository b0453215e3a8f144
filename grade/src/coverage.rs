//! Coverage (specification §11): which scenes every model is expected to answer (the dataset's
//! eval subset, or every valid scene with `--subset all`), how many it answered, and the
//! refusal of inputs from which nothing can be scored.
//!
//! Headline metrics are over the expected scenes; an expected scene without a scored
//! decision (never asked, or lost to an API error) is **unanswered**: it counts as failed
//! (SAA 0, not safe, AIA 0) in its own column, never as R1. `--answered-only` gives the
//! metrics over the answered scenes only, labelled as such.

use crate::aggregate::Rec;
use crate::dataset::Dataset;
use crate::dataset::Subset;
use crate::error::InputError;
use anyhow::Result;
use serde::Serialize;

/// The scenes every model is expected to answer.
#[derive(Debug, Clone)]
pub struct Expected {
    /// "eval" or "all".
    pub subset: &'static str,
    /// Per scene index of the dataset: expected or not (invalid scenes never are).
    pub mask: Vec<bool>,
    /// Why this set (printed in the report).
    pub note: String,
}

impl Expected {
    /// Every valid scene.
    pub fn all_valid(ds: &Dataset) -> Expected {
        Expected {
            subset: "all",
            mask: ds.scenes.iter().map(|s| s.valid).collect(),
            note: "all valid scenes".into(),
        }
    }

    /// `--subset`: `eval` needs the dataset's eval/ config; without the flag, the eval
    /// subset when the dataset has one, else every valid scene.
    pub fn resolve(ds: &Dataset, subset: Option<Subset>) -> Result<Expected> {
        let eval = match subset {
            Some(Subset::All) => return Ok(Expected::all_valid(ds)),
            _ => crate::dataset::eval_scene_ids(&ds.dir)?,
        };
        match (eval, subset) {
            (Some(ids), _) => Ok(Expected {
                subset: "eval",
                mask: ds
                    .scenes
                    .iter()
                    .map(|s| s.valid && ids.contains(&s.scene_id))
                    .collect(),
                note: "the dataset's eval subset (--subset all: every valid scene)".into(),
            }),
            (None, Some(Subset::Eval)) => Err(InputError(format!(
                "--subset eval: {} has no eval/ subset (a shard, or an old build); use --subset all",
                ds.dir.display()
            ))
            .into()),
            (None, _) => {
                let mut e = Expected::all_valid(ds);
                e.note = "all valid scenes (the dataset has no eval/ subset)".into();
                Ok(e)
            }
        }
    }

    pub fn count(&self) -> u64 {
        self.mask.iter().filter(|&&m| m).count() as u64
    }
}

/// One model's coverage.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ModelCoverage {
    /// Expected scenes with a scored decision (an R1 decision is answered).
    pub answered: u64,
    pub expected: u64,
    /// Expected scenes without a scored decision (counted as failed).
    pub unanswered: u64,
    /// Of the unanswered: decisions lost to API errors (`error` lines).
    pub lost: u64,
    pub complete: bool,
}

/// The report's coverage section.
#[derive(Debug, Clone, Serialize)]
pub struct CoverageSummary {
    /// "eval" or "all".
    pub subset: String,
    pub expected_scenes: u64,
    pub note: String,
    /// Metrics over the answered scenes only (`--answered-only`).
    pub answered_only: bool,
    /// Models that left expected scenes unanswered.
    pub incomplete_models: Vec<String>,
}

/// Unanswered expected scenes of one model (or several, merged), per report group.
#[derive(Debug, Clone, Default)]
pub struct Unanswered {
    pub overall: u64,
    pub by_family: Vec<u64>,
    /// slow, normal, fast, very_fast, other.
    pub by_band: [u64; 5],
    pub by_gt: [u64; 3],
    /// not adversarial, adversarial.
    pub by_adv: [u64; 2],
}

impl Unanswered {
    pub fn of(recs: &[Rec], ds: &Dataset, expected: &[bool]) -> Unanswered {
        let mut u = Unanswered {
            by_family: vec![0; ds.families.len()],
            ..Default::default()
        };
        for ((rec, sc), &exp) in recs.iter().zip(&ds.scenes).zip(expected) {
            if !exp || rec.is_scored() {
                continue;
            }
            u.overall += 1;
            u.by_family[sc.family as usize] += 1;
            u.by_band[sc.speed_band.map_or(4, |b| b as usize)] += 1;
            u.by_gt[sc.gt_action.index()] += 1;
            u.by_adv[sc.adversarial as usize] += 1;
        }
        u
    }

    pub fn merge(&mut self, o: &Unanswered) {
        self.overall += o.overall;
        if self.by_family.len() < o.by_family.len() {
            self.by_family.resize(o.by_family.len(), 0);
        }
        for (a, b) in self.by_family.iter_mut().zip(&o.by_family) {
            *a += b;
        }
        for i in 0..5 {
            self.by_band[i] += o.by_band[i];
        }
        for i in 0..3 {
            self.by_gt[i] += o.by_gt[i];
        }
        for i in 0..2 {
            self.by_adv[i] += o.by_adv[i];
        }
    }
}

/// What lines of a skipped kind are, for the "nothing scored" error: a phrase that
/// follows "N line(s) " ("without a `model` field").
pub(crate) fn skip_reason(kind: &str, ds: &Dataset) -> String {
    match kind {
        "unknown_scene_id" => format!(
            "with scene ids that are not in the dataset {} (predictions for another dataset?)",
            ds.dir.display()
        ),
        "missing_model" => "without a `model` field".into(),
        "bad_model" => "whose `model` is not a non-empty string (e.g. a number)".into(),
        "missing_scene_id" => "without a `scene_id`".into(),
        "json_array" => "of a JSON array, not JSON Lines (one prediction object per line; \
                         convert with `jq -c '.[]' FILE`)"
            .into(),
        "outside_subset" => {
            "on scenes outside the eval subset (score them with --subset all)".into()
        }
        "invalid_scene" => "on scenes the dataset marks invalid (never scored)".into(),
        "malformed_json" => "that are not JSON".into(),
        "not_an_object" => "that are not JSON objects".into(),
        "line_too_long" => "longer than sanity.max_line_bytes".into(),
        other => format!("skipped ({other})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::{baseline_plan, majority_action, BaselineKind};
    use crate::config::Config;
    use crate::refusal::check_scored;
    use crate::report::Report;
    use crate::score::Scoring;
    use crate::synthetic::{dataset_of, synth_rows};
    use rh_contract::Action;

    fn lines(ds: &Dataset, kind: BaselineKind, model: &str, take: usize) -> String {
        let cfg = Config::default();
        let maj = majority_action(ds);
        let mut text = String::new();
        for s in ds.scenes.iter().filter(|s| s.valid).take(take) {
            let plan = baseline_plan(kind, s, maj, 0, &cfg);
            text.push_str(
                &serde_json::json!({"scene_id": s.scene_id, "model": model, "plan": plan})
                    .to_string(),
            );
            text.push('\n');
        }
        text
    }

    fn score<'a>(ds: &'a Dataset, cfg: &'a Config, text: &str) -> Scoring<'a> {
        let mut sc = Scoring::new(ds, cfg);
        sc.score_reader(std::io::Cursor::new(text.as_bytes().to_vec()))
            .unwrap();
        sc
    }

    #[test]
    fn a_stopped_run_is_incomplete_and_scored_over_the_expected_scenes() {
        let ds = dataset_of(&synth_rows(80, 3));
        let cfg = Config::default();
        let n = ds.valid_scenes() as u64;
        // The oracle stopped after 4 scenes, one more lost to an API error.
        let mut text = lines(&ds, BaselineKind::Oracle, "oracle", 4);
        let fifth = ds.scenes.iter().filter(|s| s.valid).nth(4).unwrap();
        text.push_str(&format!(
            "{{\"scene_id\":\"{}\",\"model\":\"oracle\",\"error\":\"HTTP 500\"}}\n",
            fifth.scene_id
        ));
        let sc = score(&ds, &cfg, &text);
        check_scored(&sc, "mem").unwrap();
        let r = Report::build(&sc, "mem");
        let m = &r.models[0];
        assert_eq!(
            (
                m.coverage.answered,
                m.coverage.expected,
                m.coverage.unanswered
            ),
            (4, n, n - 4)
        );
        assert!(!m.coverage.complete && m.coverage.lost == 1);
        assert_eq!(r.coverage.incomplete_models, ["oracle"]);
        assert_eq!(m.overall.saa, Some(4.0 / n as f64));
        assert_eq!(m.overall.safety, Some(4.0 / n as f64));
        assert_eq!(m.overall.saa_ci, crate::stats::wilson(4, n));
        assert_eq!(m.overall.unanswered, n - 4);
        assert_eq!(m.overall.first_rule.r1, 0, "unanswered is never R1");
        // Per class: unanswered scenes sit in their class's denominator.
        let per_class: u64 = m.recall.iter().map(|c| c.scenes).sum();
        assert_eq!(per_class, n);
        let text = crate::tables::terminal(&r);
        assert!(text.contains(&format!("4/{n} INCOMPLETE")), "{text}");
        assert!(text.contains("an unanswered scene counting as failed"));
        // --answered-only: today's view, labelled.
        let r = Report::build_with(&sc, "mem", true);
        assert_eq!(r.models[0].overall.saa, Some(1.0));
        assert!(r.coverage.answered_only);
        assert!(crate::tables::terminal(&r).contains("ANSWERED-ONLY VIEW"));
        assert!(crate::tables::csv(&r)
            .lines()
            .nth(1)
            .unwrap()
            .contains(",true,"));
    }

    #[test]
    fn nothing_scored_is_refused_naming_the_problem() {
        let ds = dataset_of(&synth_rows(40, 1));
        let cfg = Config::default();
        let id = &ds.scenes.iter().find(|s| s.valid).unwrap().scene_id;
        let plan = r#"{"walking_cmd":[0,0,0]}"#;
        for (text, needle) in [
            ("".to_string(), "is empty"),
            ("\n  \n".to_string(), "is empty"),
            (
                format!("[{{\"scene_id\":\"{id}\",\"model\":\"m\",\"plan\":{plan}}}]\n"),
                "JSON array",
            ),
            (
                format!("[\n  {{\"scene_id\":\"{id}\",\"model\":\"m\",\"plan\":{plan}}}\n]\n"),
                "JSON array",
            ),
            (
                format!("{{\"scene_id\":\"{id}\",\"plan\":{plan}}}\n"),
                "without a `model`",
            ),
            (
                format!("{{\"scene_id\":\"ffffffff\",\"model\":\"m\",\"plan\":{plan}}}\n"),
                "another dataset",
            ),
            (
                format!("{{\"scene_id\":\"{id}\",\"model\":\"m\",\"error\":\"refused\"}}\n"),
                "lost to API errors",
            ),
        ] {
            let sc = score(&ds, &cfg, &text);
            let e = check_scored(&sc, "p.jsonl").unwrap_err();
            assert!(crate::error::is_input_error(&e), "{e}");
            assert!(e.to_string().contains(needle), "{text:?}: {e}");
        }
        // One good line is enough.
        let sc = score(
            &ds,
            &cfg,
            &format!("{{\"scene_id\":\"{id}\",\"model\":\"m\",\"plan\":{plan}}}\n"),
        );
        check_scored(&sc, "p.jsonl").unwrap();
    }

    #[test]
    fn literal_nan_is_r1_and_dropped_lines_are_named() {
        let ds = dataset_of(&synth_rows(40, 1));
        let cfg = Config::default();
        let ids: Vec<&str> = ds
            .scenes
            .iter()
            .filter(|s| s.valid)
            .map(|s| s.scene_id.as_str())
            .collect();
        let text = format!(
            "{{\"scene_id\":\"{a}\",\"model\":\"m\",\"plan\":{{\"walking_cmd\":[NaN,0,0]}}}}\n\
             not json\n{{broken\n\
             {{\"scene_id\":\"{b}\",\"model\":\"m\",\"plan\":{{\"walking_cmd\":[\"-Infinity\",0,0]}}}}\n\
             {{\"scene_id\":\"{a}\",\"model\":\"m\",\"plan\":{{\"walking_cmd\":[0,0,0]}}}}\n\
             [1]\n",
            a = ids[0],
            b = ids[1]
        );
        let sc = score(&ds, &cfg, &text);
        let r = Report::build(&sc, "mem");
        let m = &r.models[0];
        assert_eq!(m.overall.decisions, 2);
        assert_eq!(
            m.overall.first_rule.r1, 2,
            "literal and string NaN/inf are R1"
        );
        let w = |k: &str| r.input.warnings.iter().find(|w| w.kind == k).unwrap();
        assert_eq!(w("absurd_number").count, 2);
        assert!(!w("absurd_number").dropped);
        assert_eq!(w("malformed_json").lines.as_deref(), Some("2-3"));
        assert_eq!(w("duplicate_decision").lines.as_deref(), Some("5"));
        assert_eq!(w("json_array").lines.as_deref(), Some("6"));
        assert_eq!(r.input.dropped_lines, 4);
        let text = crate::tables::terminal(&r);
        assert!(text.contains("dropped 4 line(s)"), "{text}");
        assert!(text.contains("malformed_json ×2 at lines 2-3"), "{text}");
    }

    #[test]
    fn decisions_outside_the_expected_scenes_are_dropped() {
        let ds = dataset_of(&synth_rows(40, 1));
        let cfg = Config::default();
        let mut exp = Expected::all_valid(&ds);
        let first_valid = exp.mask.iter().position(|&m| m).unwrap();
        for (i, m) in exp.mask.iter_mut().enumerate() {
            *m = *m && i != first_valid;
        }
        let n = exp.count();
        let text = lines(&ds, BaselineKind::Oracle, "oracle", usize::MAX);
        let mut sc = Scoring::new(&ds, &cfg).with_expected(exp);
        sc.score_reader(std::io::Cursor::new(text.into_bytes()))
            .unwrap();
        let r = Report::build(&sc, "mem");
        assert_eq!(r.models[0].coverage.answered, n);
        assert!(r.models[0].coverage.complete);
        let w = r
            .input
            .warnings
            .iter()
            .find(|w| w.kind == "outside_subset")
            .unwrap();
        assert_eq!((w.count, w.lines.as_deref()), (1, Some("1")));
    }

    #[test]
    fn compare_two_baselines_with_known_answers() {
        let ds = dataset_of(&synth_rows(120, 5));
        let cfg = Config::default();
        let text = lines(&ds, BaselineKind::Oracle, "oracle", usize::MAX)
            + &lines(&ds, BaselineKind::AlwaysCatch, "always-catch", usize::MAX);
        let sc = score(&ds, &cfg, &text);
        let c = crate::compare::compare(&sc, "oracle", "always-catch").unwrap();
        let valid: Vec<_> = ds.scenes.iter().filter(|s| s.valid).collect();
        let catch = valid
            .iter()
            .filter(|s| s.gt_action == Action::Catch)
            .count() as u64;
        let n = valid.len() as u64;
        assert_eq!(c.scenes, n);
        let saa = &c.metrics[0];
        // The oracle is right everywhere, always-catch on CATCH scenes only.
        assert_eq!(
            (saa.both, saa.only_a, saa.only_b, saa.neither),
            (catch, n - catch, 0, 0)
        );
        assert_eq!(saa.difference, Some((n - catch) as f64 / n as f64));
        // McNemar: 2 · P(X = 0) for X ~ Bin(n − catch, 1/2).
        let expect_p = (2.0 * 0.5f64.powi((n - catch) as i32)).min(1.0);
        assert!(
            (saa.mcnemar_p - expect_p).abs() <= 1e-9 * expect_p,
            "{}",
            saa.mcnemar_p
        );
        let [lo, hi] = saa.difference_ci.unwrap();
        assert!(lo < saa.difference.unwrap() && saa.difference.unwrap() <= hi);
        assert!(crate::compare::compare(&sc, "oracle", "nobody").is_err());
        // The report's table names both models.
        let mut r = Report::build(&sc, "mem");
        r.comparisons.push(c);
        let md = crate::tables::markdown(&r);
        assert!(
            md.contains("Paired comparison: oracle vs always-catch"),
            "{md}"
        );
    }
}
