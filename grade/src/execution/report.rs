//! The execution part of the report: outcome counts per model and per family / speed
//! band / ground-truth action / adversarial flag, the paper-style analyses ("correct but
//! failed", "wrong but harmless"), agreement with the labels and the list of
//! disagreements; as JSON (serde), terminal text, Markdown and CSV rows.

use super::{Pending, RunStats};
use crate::dataset::Dataset;
use crate::text_table::{Align, Table, TextStyle};
use rh_contract::execution::{ExecConfig, Outcome, OutcomeKind, EXECUTOR_VERSION};
use rh_contract::Action;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;

/// Outcome counts of a set of decisions.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Counts {
    /// Decisions (executed + not executed).
    pub n: u64,
    pub caught: u64,
    pub struck: u64,
    pub missed: u64,
    pub clear: u64,
    /// No parseable plan (R1): not executed.
    pub not_executed: u64,
}

impl Counts {
    fn add(&mut self, o: Option<&Outcome>) {
        self.n += 1;
        match o.map(|o| o.outcome) {
            Some(OutcomeKind::Caught) => self.caught += 1,
            Some(OutcomeKind::Struck) => self.struck += 1,
            Some(OutcomeKind::Missed) => self.missed += 1,
            Some(OutcomeKind::Clear) => self.clear += 1,
            None => self.not_executed += 1,
        }
    }

    pub fn executed(&self) -> u64 {
        self.n - self.not_executed
    }

    /// Share of executed decisions with this outcome.
    pub fn rate(&self, kind: OutcomeKind) -> Option<f64> {
        let k = match kind {
            OutcomeKind::Caught => self.caught,
            OutcomeKind::Struck => self.struck,
            OutcomeKind::Missed => self.missed,
            OutcomeKind::Clear => self.clear,
        };
        (self.executed() > 0).then(|| k as f64 / self.executed() as f64)
    }
}

/// One model's outcomes.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ModelOutcomes {
    pub model: String,
    pub all: Counts,
    pub by_family: BTreeMap<String, Counts>,
    pub by_speed_band: BTreeMap<String, Counts>,
    pub by_gt_action: BTreeMap<String, Counts>,
    pub by_adversarial: BTreeMap<String, Counts>,
    /// SAA = 1 decisions, and those that failed in physics: a correct CATCH not caught, or
    /// a correct DODGE / NO_ACTION struck.
    pub correct: u64,
    pub correct_but_failed: u64,
    /// SAA = 0 decisions (executed), and those that came to no harm (not struck).
    pub wrong: u64,
    pub wrong_but_harmless: u64,
}

/// Does execution agree with the labels?
#[derive(Debug, Clone, Default, Serialize)]
pub struct Agreement {
    /// Standing decisions (the rule reads NO_ACTION: the body stays put, arms in) on
    /// `danger_present` scenes, and how many were struck.
    pub standing_danger: u64,
    pub standing_danger_struck: u64,
    /// Standing decisions on scenes without `danger_present`, and how many were struck.
    pub standing_safe: u64,
    pub standing_safe_struck: u64,
    /// Correct CATCH decisions, and how many were caught.
    pub correct_catch: u64,
    pub correct_catch_caught: u64,
    /// Correct DODGE decisions, and how many were struck.
    pub correct_dodge: u64,
    pub correct_dodge_struck: u64,
}

/// A decision whose outcome contradicts the labels: a label bug or an execution bug.
#[derive(Debug, Clone, Serialize)]
pub struct Disagreement {
    pub model: String,
    pub scene_id: String,
    pub family: String,
    pub speed_band: String,
    pub gt_action: String,
    pub danger_present: bool,
    pub outcome: String,
    /// `standing_struck_without_danger`, `standing_not_struck_with_danger`,
    /// `correct_catch_not_caught` or `correct_dodge_struck`.
    pub kind: String,
    pub struck_part: Option<String>,
    pub impulse: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ExecutionReport {
    pub executor: String,
    pub config: ExecConfig,
    pub run: RunStats,
    pub models: Vec<ModelOutcomes>,
    pub agreement: Agreement,
    pub disagreements: Vec<Disagreement>,
    /// Per decision: (model, scene id) → outcome (for `--html`; the JSON report has the
    /// aggregates, `--decisions` the per-decision fields).
    #[serde(skip)]
    pub decisions: BTreeMap<(String, String), Outcome>,
}

impl ExecutionReport {
    /// A model's outcome rates over its executed decisions (`caught` … `clear`).
    pub fn rates(&self, model: &str) -> Option<BTreeMap<&'static str, Option<f64>>> {
        let m = self.models.iter().find(|m| m.model == model)?;
        Some(
            OutcomeKind::ALL
                .iter()
                .map(|&k| (k.name(), m.all.rate(k)))
                .collect(),
        )
    }
}

fn disagreement(p: &Pending, o: &Outcome, ds: &Dataset) -> Option<&'static str> {
    let sc = &ds.scenes[p.scene as usize];
    let struck = o.outcome == OutcomeKind::Struck;
    match p.action {
        Some(Action::NoAction) if struck && !sc.danger_present => {
            Some("standing_struck_without_danger")
        }
        Some(Action::NoAction) if !struck && sc.danger_present => {
            Some("standing_not_struck_with_danger")
        }
        Some(Action::Catch) if p.saa && o.outcome != OutcomeKind::Caught => {
            Some("correct_catch_not_caught")
        }
        Some(Action::Dodge) if p.saa && struck => Some("correct_dodge_struck"),
        _ => None,
    }
}

impl ExecutionReport {
    /// Builds the report; `names[i]` is model `i`'s name.
    pub fn build(
        ds: &Dataset,
        names: &[String],
        pending: &[Pending],
        outcomes: &[Option<Outcome>],
        cfg: &ExecConfig,
        run: RunStats,
    ) -> ExecutionReport {
        let mut models: Vec<ModelOutcomes> = names
            .iter()
            .map(|n| ModelOutcomes {
                model: n.clone(),
                ..Default::default()
            })
            .collect();
        let mut agreement = Agreement::default();
        let mut disagreements = Vec::new();
        let mut decisions = BTreeMap::new();
        for (p, o) in pending.iter().zip(outcomes) {
            let sc = &ds.scenes[p.scene as usize];
            let m = &mut models[p.model];
            let o = o.as_ref();
            m.all.add(o);
            m.by_family
                .entry(ds.family_name(sc).to_string())
                .or_default()
                .add(o);
            m.by_speed_band
                .entry(sc.speed_band_name.clone())
                .or_default()
                .add(o);
            m.by_gt_action
                .entry(sc.gt_action.as_str().to_string())
                .or_default()
                .add(o);
            let adv = if sc.adversarial {
                "adversarial"
            } else {
                "regular"
            };
            m.by_adversarial.entry(adv.to_string()).or_default().add(o);
            let Some(o) = o else { continue };
            decisions.insert((names[p.model].clone(), sc.scene_id.clone()), o.clone());
            let struck = o.outcome == OutcomeKind::Struck;
            if p.saa {
                m.correct += 1;
                let failed = if sc.gt_action == Action::Catch {
                    o.outcome != OutcomeKind::Caught
                } else {
                    struck
                };
                m.correct_but_failed += failed as u64;
            } else {
                m.wrong += 1;
                m.wrong_but_harmless += (!struck) as u64;
            }
            match p.action {
                Some(Action::NoAction) if sc.danger_present => {
                    agreement.standing_danger += 1;
                    agreement.standing_danger_struck += struck as u64;
                }
                Some(Action::NoAction) => {
                    agreement.standing_safe += 1;
                    agreement.standing_safe_struck += struck as u64;
                }
                Some(Action::Catch) if p.saa => {
                    agreement.correct_catch += 1;
                    agreement.correct_catch_caught += (o.outcome == OutcomeKind::Caught) as u64;
                }
                Some(Action::Dodge) if p.saa => {
                    agreement.correct_dodge += 1;
                    agreement.correct_dodge_struck += struck as u64;
                }
                _ => {}
            }
            if let Some(kind) = disagreement(p, o, ds) {
                disagreements.push(Disagreement {
                    model: names[p.model].clone(),
                    scene_id: sc.scene_id.clone(),
                    family: ds.family_name(sc).to_string(),
                    speed_band: sc.speed_band_name.clone(),
                    gt_action: sc.gt_action.as_str().to_string(),
                    danger_present: sc.danger_present,
                    outcome: o.outcome.name().to_string(),
                    kind: kind.to_string(),
                    struck_part: o.strike.as_ref().map(|s| s.part.clone()),
                    impulse: o.strike.as_ref().map(|s| s.impulse),
                });
            }
        }
        models.sort_by(|a, b| a.model.cmp(&b.model));
        disagreements.sort_by(|a, b| (&a.model, &a.scene_id).cmp(&(&b.model, &b.scene_id)));
        ExecutionReport {
            executor: format!("{} / config {}", EXECUTOR_VERSION, cfg.version),
            config: cfg.clone(),
            run,
            models,
            agreement,
            disagreements,
            decisions,
        }
    }
}

fn pct(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_string(), |v| format!("{:.1}%", 100.0 * v))
}

fn frac(a: u64, b: u64) -> String {
    if b == 0 {
        "-".to_string()
    } else {
        format!("{a}/{b} ({:.1}%)", 100.0 * a as f64 / b as f64)
    }
}

/// The outcome table: one row per (model, group kind, group), each rate a cell `rate`.
fn outcome_table(r: &ExecutionReport, head: &[&str], rate: fn(Option<f64>) -> String) -> Table {
    use Align::{Left, Right};
    let mut t = Table::new(head)
        .aligned(&[Left, Left, Left, Right, Right, Right, Right, Right, Right])
        .min_widths(&[24, 12, 18, 6, 8, 8, 8, 8, 6])
        .compact_markdown();
    let mut add = |model: &str, kind: &str, group: &str, c: &Counts| {
        let mut row = vec![model.to_string(), kind.to_string(), group.to_string()];
        row.push(c.n.to_string());
        row.extend(OutcomeKind::ALL.iter().map(|&k| rate(c.rate(k))));
        row.push(c.not_executed.to_string());
        t.row(row);
    };
    for m in &r.models {
        add(&m.model, "all", "all", &m.all);
        for (kind, map) in [
            ("gt_action", &m.by_gt_action),
            ("speed_band", &m.by_speed_band),
            ("adversarial", &m.by_adversarial),
            ("family", &m.by_family),
        ] {
            for (g, c) in map {
                add(&m.model, kind, g, c);
            }
        }
    }
    t
}

/// The head of the outcome table in the terminal and Markdown.
const OUTCOME_HEAD: [&str; 9] = [
    "model", "by", "group", "n", "caught", "struck", "missed", "clear", "R1",
];

/// Plain-text section for the terminal report.
pub fn terminal(r: &ExecutionReport, max_disagreements: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\nExecution in physics (specification §12; executor {})",
        r.executor
    );
    let _ = writeln!(
        s,
        "  {} executed ({} from the cache), {} not executed (R1); {} scenes replayed and checked ({} at Δ, {} by full replay)",
        r.run.executed + r.run.from_cache,
        r.run.from_cache,
        r.run.not_executed,
        r.run.scenes_replayed,
        r.run.checked_at_decision,
        r.run.checked_full
    );
    let style = TextStyle {
        indent: "  ",
        gap: " ",
        rule: false,
    };
    s.push_str(&outcome_table(r, &OUTCOME_HEAD, pct).text_with(style));
    let _ = writeln!(s, "  Correct but failed / wrong but harmless:");
    for m in &r.models {
        let _ = writeln!(
            s,
            "    {:<24} correct but failed {}   wrong but harmless {}",
            m.model,
            frac(m.correct_but_failed, m.correct),
            frac(m.wrong_but_harmless, m.wrong)
        );
    }
    let a = &r.agreement;
    let _ = writeln!(s, "  Agreement with the labels:");
    let _ = writeln!(
        s,
        "    standing on danger_present scenes: struck {}\n    standing on other scenes: struck {}\n    correct CATCH: caught {}\n    correct DODGE: struck {}",
        frac(a.standing_danger_struck, a.standing_danger),
        frac(a.standing_safe_struck, a.standing_safe),
        frac(a.correct_catch_caught, a.correct_catch),
        frac(a.correct_dodge_struck, a.correct_dodge)
    );
    let _ = writeln!(
        s,
        "  Disagreements with the labels (each a label bug or an execution bug): {}",
        r.disagreements.len()
    );
    for d in r.disagreements.iter().take(max_disagreements) {
        let _ = writeln!(
            s,
            "    {} {} {}/{} gt {} danger_present {}: {} ({}{})",
            d.model,
            d.scene_id,
            d.family,
            d.speed_band,
            d.gt_action,
            d.danger_present,
            d.outcome,
            d.kind,
            d.struck_part
                .as_ref()
                .map(|p| format!(", {p} {:.3} N·s", d.impulse.unwrap_or(0.0)))
                .unwrap_or_default()
        );
    }
    if r.disagreements.len() > max_disagreements {
        let _ = writeln!(
            s,
            "    … {} more in the JSON report (execution.disagreements)",
            r.disagreements.len() - max_disagreements
        );
    }
    s
}

/// Markdown section.
pub fn markdown(r: &ExecutionReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "\n## Execution in physics\n\nExecutor {}.\n", r.executor);
    s.push_str(&outcome_table(r, &OUTCOME_HEAD, pct).markdown());
    let mut t =
        Table::new(&["model", "correct but failed", "wrong but harmless"]).compact_markdown();
    for m in &r.models {
        t.row(vec![
            m.model.clone(),
            frac(m.correct_but_failed, m.correct),
            frac(m.wrong_but_harmless, m.wrong),
        ]);
    }
    s.push('\n');
    s.push_str(&t.markdown());
    let a = &r.agreement;
    let _ = writeln!(
        s,
        "\nAgreement with the labels: standing on `danger_present` scenes struck {}; standing elsewhere struck {}; correct CATCH caught {}; correct DODGE struck {}. Disagreements: {} (listed in the JSON report).",
        frac(a.standing_danger_struck, a.standing_danger),
        frac(a.standing_safe_struck, a.standing_safe),
        frac(a.correct_catch_caught, a.correct_catch),
        frac(a.correct_dodge_struck, a.correct_dodge),
        r.disagreements.len()
    );
    s
}

/// The outcome table as CSV (rates as fractions), written beside the metrics CSV.
pub fn csv(r: &ExecutionReport) -> String {
    let head = [
        "model",
        "breakdown",
        "group",
        "n",
        "caught_rate",
        "struck_rate",
        "missed_rate",
        "clear_rate",
        "not_executed",
    ];
    let rate = |x: Option<f64>| x.map_or_else(String::new, |v| format!("{v:.6}"));
    outcome_table(r, &head, rate).csv()
}
