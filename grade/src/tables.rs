//! Report text tables: terminal table, Markdown, CSV (JSON is `serde_json` of [`Report`]).
//! (Named `tables`, not `render`, which in this project means the video renderer.)

use crate::report::{MetricsRow, ModelReport, Report};
use crate::safety_rule::SafetyRule;
use std::fmt::Write as _;

use crate::text_table::{num, num_ci, pct, pct_ci, Table};

/// The report's models, then the pooled row when there is more than one model (the
/// order of every per-model table).
fn model_rows(r: &Report) -> impl Iterator<Item = &ModelReport> {
    r.models
        .iter()
        .chain((r.models.len() > 1).then_some(&r.pooled))
}

/// "answered/expected", marked when incomplete.
fn coverage_cell(m: &ModelReport) -> String {
    let c = &m.coverage;
    if c.complete {
        format!("{}/{}", c.answered, c.expected)
    } else {
        format!("{}/{} INCOMPLETE", c.answered, c.expected)
    }
}

/// The CATCH row of a per-GT-action breakdown.
fn catch_row(rows: &[MetricsRow]) -> Option<&MetricsRow> {
    rows.iter()
        .find(|g| g.group == rh_contract::Action::Catch.as_str())
}

const MAIN_NOTE: &str = "d_end and HDE (hand-distance error: d_min and d1-d_min over the keyframes) are over CATCH scenes, \
where meeting the object is the right action; n = CATCH decisions with a distance. They are per GT action below. \
Answered = scenes with a scored decision out of those expected; Unanswered = expected scenes without one (lost or never \
asked), counted as failed, never as R1. CI = 95% interval (Wilson for rates, seeded bootstrap over scenes for means and \
balanced accuracy). Bal. acc = mean recall over CATCH, DODGE, NO_ACTION.";

/// The coverage lines of the header: the expected set, the view, incomplete models.
fn coverage_text(r: &Report) -> String {
    let c = &r.coverage;
    let mut s = format!(
        "coverage: {} expected scenes per model — {}; {}\n",
        c.expected_scenes,
        c.note,
        if c.answered_only {
            "ANSWERED-ONLY VIEW: metrics over each model's answered scenes, unanswered ones left out (--answered-only)"
        } else {
            "metrics over the expected scenes, an unanswered scene counting as failed"
        }
    );
    for m in r.models.iter().filter(|m| !m.coverage.complete) {
        let _ = writeln!(
            s,
            "INCOMPLETE: {} answered {} of {} expected scenes ({} unanswered, {} of them lost to API errors)",
            m.model,
            m.coverage.answered,
            m.coverage.expected,
            m.coverage.unanswered,
            m.coverage.lost
        );
    }
    s
}

fn main_table(r: &Report) -> Table {
    let mut t = Table::new(&[
        "Model",
        "Prompt",
        "Answered",
        "Lost",
        "Unanswered",
        "SAA %",
        "SAA CI",
        "Bal. acc %",
        "Bal. acc CI",
        "Safety %",
        "Safety CI",
        "AIA",
        "AIA CI",
        "d_end CATCH (m)",
        "d_end CI",
        "HDE d_min CATCH (m)",
        "HDE d1-d_min CATCH (m)",
        "n CATCH",
        "R1",
        "R2",
        "R3",
        "R4",
    ]);
    let mut add = |name: &str, prompt: &str, lost: u64, m: &ModelReport| {
        let o = &m.overall;
        let c = catch_row(&m.by_gt_action);
        t.row(vec![
            name.to_string(),
            prompt.to_string(),
            coverage_cell(m),
            lost.to_string(),
            o.unanswered.to_string(),
            pct(o.saa),
            pct_ci(o.saa_ci),
            pct(m.balanced_accuracy),
            pct_ci(m.balanced_accuracy_ci),
            pct(o.safety),
            pct_ci(o.safety_ci),
            num(o.aia, 2),
            num_ci(o.aia_ci, 2),
            num(c.and_then(|c| c.d_end), 2),
            num_ci(c.and_then(|c| c.d_end_ci), 2),
            num(c.and_then(|c| c.d_min), 2),
            num(c.and_then(|c| c.closing), 2),
            c.map_or(0, |c| c.d_end_n).to_string(),
            o.first_rule.r1.to_string(),
            o.first_rule.r2.to_string(),
            o.first_rule.r3.to_string(),
            o.first_rule.r4.to_string(),
        ]);
    };
    for m in &r.models {
        add(&m.model, &m.prompt_version, m.lost, m);
    }
    if r.models.len() > 1 {
        add("ALL (pooled)", "", r.pooled.lost, &r.pooled);
    }
    t
}

/// d_end and HDE per model and GT action (scenes with an impact point).
fn distance_table(r: &Report) -> Table {
    let mut t = Table::new(&[
        "Model",
        "GT action",
        "Decisions",
        "d_end (m)",
        "HDE d_min (m)",
        "HDE d1-d_min (m)",
        "n/missing",
    ]);
    for m in model_rows(r) {
        for g in &m.by_gt_action {
            if g.decisions == 0 {
                continue;
            }
            t.row(vec![
                if m.model == "ALL" {
                    "ALL (pooled)".into()
                } else {
                    m.model.clone()
                },
                g.group.clone(),
                g.decisions.to_string(),
                num(g.d_end, 2),
                num(g.d_min, 2),
                num(g.closing, 2),
                format!("{}/{}", g.d_end_n, g.d_end_missing),
            ]);
        }
    }
    t
}

/// d_end and AIA per group (family or speed band) and model: "d_end / AIA (n)".
fn distance_aia_table(r: &Report, title: &str, pick: Pick) -> Table {
    group_table(r, title, pick, "d_end m / AIA", |x| {
        format!("{} / {} (n={})", num(x.d_end, 2), num(x.aia, 2), x.d_end_n)
    })
}

type Pick = fn(&ModelReport) -> &Vec<MetricsRow>;

/// The per-family and per-band d_end / AIA tables: (title, first column, picker).
fn distance_breakdowns() -> [(&'static str, &'static str, Pick); 2] {
    [
        (
            "d_end and AIA by family (d_end over all scenes of the family with an impact point)",
            "Family",
            |m| &m.by_family,
        ),
        ("d_end and AIA by speed band", "Speed band", |m| {
            &m.by_speed_band
        }),
    ]
}

/// SAA and safety per group (family, speed band, …) and model: "SAA / Safety (n)".
fn breakdown_table(r: &Report, title: &str, pick: Pick) -> Table {
    group_table(r, title, pick, "SAA/Safety %", |x| {
        format!("{} / {} (n={})", pct(x.saa), pct(x.safety), x.decisions)
    })
}

/// One row per group of `pick` (in the pooled report's order), one column per model
/// (and the pooled one when there are several) headed "<model> <suffix>", each cell
/// `cell` of that model's group, or "—" when it has no decisions.
fn group_table(
    r: &Report,
    title: &str,
    pick: Pick,
    suffix: &str,
    cell: fn(&MetricsRow) -> String,
) -> Table {
    let models: Vec<&ModelReport> = model_rows(r).collect();
    let mut head = vec![title.to_string()];
    for m in &models {
        head.push(format!("{} {suffix}", m.model));
    }
    let mut t = Table::from_head(head);
    let groups: Vec<String> = pick(&r.pooled).iter().map(|g| g.group.clone()).collect();
    for (gi, g) in groups.iter().enumerate() {
        let mut row = vec![g.clone()];
        for m in &models {
            let x = &pick(m)[gi];
            row.push(if x.decisions == 0 {
                "—".into()
            } else {
                cell(x)
            });
        }
        t.row(row);
    }
    t
}

/// A titled table with an optional note below it.
type TitledTable = (String, Table, Option<String>);

fn analyses_tables(r: &Report) -> Vec<TitledTable> {
    let mut out = Vec::new();
    recall_and_comparison_tables(r, &mut out);
    safety_and_reach_tables(r, &mut out);
    speed_vote_and_adversarial_tables(r, &mut out);
    out
}

/// Per-class recall with balanced accuracy, and the `--compare` pairs.
fn recall_and_comparison_tables(r: &Report, out: &mut Vec<TitledTable>) {
    let mut t = Table::new(&[
        "Model",
        "Recall CATCH %",
        "CI",
        "Recall DODGE %",
        "CI",
        "Recall NO_ACTION %",
        "CI",
        "Balanced accuracy %",
        "CI",
        "SAA %",
    ]);
    for m in model_rows(r) {
        let mut row = vec![m.model.clone()];
        for c in &m.recall {
            row.push(format!("{} (n={})", pct(c.recall), c.scenes));
            row.push(pct_ci(c.recall_ci));
        }
        row.push(pct(m.balanced_accuracy));
        row.push(pct_ci(m.balanced_accuracy_ci));
        row.push(pct(m.overall.saa));
        t.row(row);
    }
    out.push((
        "Per-class recall and balanced accuracy".into(),
        t,
        Some("Recall = SAA on the scenes of one ground-truth class (n = its expected scenes; Wilson 95% CI); balanced accuracy = their mean over the classes with scenes (stratified bootstrap CI). A majority baseline's SAA can look strong; its balanced accuracy cannot.".into()),
    ));
    for c in &r.comparisons {
        let mut t = Table::new(&[
            "Metric",
            &format!("{} %", c.a),
            &format!("{} %", c.b),
            "Difference (pp)",
            "95% CI (pp)",
            "Both",
            "Only A",
            "Only B",
            "Neither",
            "McNemar exact p",
        ]);
        for p in &c.metrics {
            t.row(vec![
                p.metric.clone(),
                pct(p.a),
                pct(p.b),
                p.difference
                    .map_or("—".into(), |d| format!("{:+.1}", 100.0 * d)),
                p.difference_ci.map_or("—".into(), |[a, b]| {
                    format!("{:+.1} to {:+.1}", 100.0 * a, 100.0 * b)
                }),
                p.both.to_string(),
                p.only_a.to_string(),
                p.only_b.to_string(),
                p.neither.to_string(),
                format!("{:.4}", p.mcnemar_p),
            ]);
        }
        out.push((
            format!("Paired comparison: {} vs {} ({} scenes both answered)", c.a, c.b, c.scenes),
            t,
            Some("A = the first model. Difference A − B on the expected scenes both models answered, with Newcombe's paired score interval; McNemar's exact test on the discordant scenes (Only A vs Only B).".into()),
        ));
    }
}

/// Safety-rule breakdown, disposition, and correct but out of reach.
fn safety_and_reach_tables(r: &Report, out: &mut Vec<TitledTable>) {
    let a = &r.analyses;

    let mut t = Table::new(&[
        "Model",
        "Decisions",
        "Violations",
        "first R1",
        "R2",
        "R3",
        "R4",
        "fired R1",
        "R2",
        "R3",
        "R4",
        "Unsafe on DODGE %",
        "Mistakes",
        "Freezing",
    ]);
    for s in &a.safety {
        let mut row = vec![
            s.model.clone(),
            s.decisions.to_string(),
            s.violations.to_string(),
        ];
        for rule in SafetyRule::ALL {
            row.push(s.first_rule.get(rule).to_string());
        }
        for rule in SafetyRule::ALL {
            row.push(s.rules_fired.get(rule).to_string());
        }
        row.push(pct(s.unsafe_on_dodge_scenes));
        row.push(s.mistakes.to_string());
        row.push(s.freeze_mistakes.to_string());
        t.row(row);
    }
    out.push((
        "Safety-rule breakdown".into(),
        t,
        Some("first = the first rule in order R1..R4 (one per unsafe decision); fired = every rule that fired. Freezing = NO_ACTION where the ground truth was not NO_ACTION.".into()),
    ));

    let mut t = Table::new(&[
        "Model",
        "SAA on CATCH scenes %",
        "SAA on DODGE scenes %",
        "SAA on NO_ACTION %",
    ]);
    for m in model_rows(r) {
        let g = &m.by_gt_action;
        t.row(vec![
            m.model.clone(),
            pct(g[0].saa),
            pct(g[1].saa),
            pct(g[2].saa),
        ]);
    }
    out.push((
        "Disposition".into(),
        t,
        Some("Models above the diagonal (DODGE > CATCH) prefer to retreat.".into()),
    ));

    let mut t = Table::new(&[
        "Model",
        "Correct CATCH",
        "median d_end (m)",
        "median d_end any correct (m)",
        "Misses %",
        "Misses falling short %",
        "Standing far %",
    ]);
    for o in &a.out_of_reach {
        t.row(vec![
            o.model.clone(),
            o.correct_catch.to_string(),
            num(o.median_d_end_correct_catch, 2),
            num(o.median_d_end_correct_any, 2),
            pct(o.miss_share),
            pct(o.misses_falling_short_share),
            pct(o.standing_far_share),
        ]);
    }
    out.push(("Correct but out of reach".into(), t, Some("Correct CATCH decisions with an impact point. Miss: d_end above the miss radius; falling short: the final hands are closer (horizontally) to the final pelvis than the impact point is; standing far: the final pelvis is farther than the far-standing distance from the impact point (horizontal).".into())));
}

/// Speed bands, majority vote, adversarial probes and look-alikes.
fn speed_vote_and_adversarial_tables(r: &Report, out: &mut Vec<TitledTable>) {
    let a = &r.analyses;
    let mut t = Table::new(&[
        "Model",
        "Decisions",
        "Freeze slow %",
        "normal %",
        "fast %",
        "very_fast %",
        "SAA slow %",
        "normal %",
        "fast %",
        "very_fast %",
        "Groups",
        "Same action all 4 %",
        "slow = very_fast %",
    ]);
    for s in &a.speed {
        let mut row = vec![s.model.clone(), s.decisions.to_string()];
        row.extend(s.freeze_rate_by_band.iter().map(|v| pct(*v)));
        row.extend(s.saa_by_band.iter().map(|v| pct(*v)));
        row.push(s.complete_groups.to_string());
        row.push(pct(s.consistency));
        row.push(pct(s.slow_vs_very_fast_agreement));
        t.row(row);
    }
    out.push(("Speed bands (speed-sweeping families only)".into(), t, Some("Freeze = share of NO_ACTION decisions. Consistency over scene groups with a scored decision at all four bands.".into())));

    let v = &a.voting;
    let mut t = Table::new(&[
        "Models",
        "Scenes (all models scored)",
        "Unanimous %",
        "Unanimous accuracy %",
        "Majority-vote SAA %",
        "Mean model SAA %",
        "Best model",
        "Best model SAA %",
    ]);
    t.row(vec![
        v.models.to_string(),
        v.scenes.to_string(),
        pct(v.unanimous_share),
        pct(v.unanimous_accuracy),
        pct(v.majority_vote_saa),
        pct(v.mean_model_saa),
        v.best_model.clone().unwrap_or_else(|| "—".into()),
        pct(v.best_model_saa),
    ]);
    out.push(("Majority vote and unanimity".into(), t, Some("Ties in the vote go to DODGE, then NO_ACTION, then CATCH; an unparseable plan never wins.".into())));

    let mut t = Table::new(&[
        "Model",
        "Adversarial decisions",
        "Intent questions material/weight",
        "Share %",
    ]);
    for p in &a.adversarial {
        t.row(vec![
            p.model.clone(),
            p.decisions.to_string(),
            p.questions_material.to_string(),
            pct(p.share),
        ]);
    }
    out.push(("Adversarial probes".into(), t, None));

    if !a.lookalikes.is_empty() {
        let mut t = Table::new(&[
            "Adversarial object",
            "Looks like",
            "Decisions",
            "CATCH %",
            "DODGE %",
            "Look-alike decisions",
            "Look-alike CATCH %",
            "Look-alike DODGE %",
        ]);
        for l in &a.lookalikes {
            t.row(vec![
                l.object_id.clone(),
                l.looks_like.clone(),
                l.decisions.to_string(),
                pct(l.catch_rate),
                pct(l.dodge_rate),
                l.lookalike_decisions.to_string(),
                pct(l.lookalike_catch_rate),
                pct(l.lookalike_dodge_rate),
            ]);
        }
        out.push((
            "Adversarial objects vs. their look-alikes (all models)".into(),
            t,
            None,
        ));
    }
}

fn header(r: &Report) -> String {
    let ar = &r.action_rule;
    let gt = &r.dataset.gt_actions;
    let g = |k: &str| gt.get(k).copied().unwrap_or(0);
    let i = &r.input;
    format!(
        "rh-score {} — action rule {} (CATCH: reach ≥ {:.2} m and not D·u ≤ −{:.2} m; DODGE: |D| ≥ {:.2} m)\n\
         dataset: {} — {} scenes ({} CATCH / {} DODGE / {} NO_ACTION; {} danger_present, {} adversarial){}\n\
         predictions: {} — {} lines, {} decisions scored, {} lost (API errors), {} duplicates, {} warnings\n",
        r.version, ar.version, ar.reach_threshold, ar.retreat_threshold, ar.move_threshold,
        r.dataset.dir, r.dataset.scenes, g("CATCH"), g("DODGE"), g("NO_ACTION"),
        r.dataset.danger_present, r.dataset.adversarial,
        if r.dataset.invalid_scenes > 0 { format!("; {} invalid scenes not scored", r.dataset.invalid_scenes) } else { String::new() },
        i.file, i.lines, i.decisions_scored, i.decisions_lost, i.duplicates,
        i.warnings.iter().map(|w| w.count).sum::<u64>(),
    ) + &dropped_text(r) + &coverage_text(r)
}

/// "dropped N lines: …" naming every dropped line, or nothing.
fn dropped_text(r: &Report) -> String {
    let i = &r.input;
    if i.dropped_lines == 0 {
        return String::new();
    }
    let parts: Vec<String> = i
        .warnings
        .iter()
        .filter_map(|w| {
            w.lines
                .as_ref()
                .map(|l| format!("{} ×{} at lines {l}", w.kind, w.count))
        })
        .collect();
    format!(
        "dropped {} line(s), not scored: {}\n",
        i.dropped_lines,
        parts.join("; ")
    )
}

fn warnings_text(r: &Report) -> String {
    let mut s = String::new();
    for w in &r.input.warnings {
        let lines: Vec<String> = w.first_lines.iter().map(|l| l.to_string()).collect();
        let _ = write!(
            s,
            "  {:<28} {:>8}  first at line {}",
            w.kind,
            w.count,
            lines.join(", ")
        );
        if !w.examples.is_empty() {
            let _ = write!(s, "  (e.g. {})", w.examples.join("; "));
        }
        if let Some(l) = &w.lines {
            let _ = write!(s, "\n  {:<28} dropped lines: {l}", "");
        }
        s.push('\n');
    }
    s
}

/// The terminal report.
pub fn terminal(r: &Report) -> String {
    let mut s = header(r);
    s.push('\n');
    s.push_str(&main_table(r).text());
    let _ = writeln!(s, "({MAIN_NOTE})");
    s.push_str("\nd_end and HDE per ground-truth action (scenes with an impact point)\n");
    s.push_str(&distance_table(r).text());
    for (title, column, pick) in distance_breakdowns() {
        let _ = write!(s, "\n{title}\n");
        s.push_str(&distance_aia_table(r, column, pick).text());
    }
    for (title, t, note) in analyses_tables(r) {
        let _ = write!(s, "\n{title}\n");
        if let Some(n) = note {
            let _ = writeln!(s, "  ({n})");
        }
        s.push_str(&t.text());
    }
    if !r.input.warnings.is_empty() {
        s.push_str("\nInput warnings (kind, count, first lines)\n");
        s.push_str(&warnings_text(r));
    }
    s
}

/// The Markdown report.
pub fn markdown(r: &Report) -> String {
    let mut s = String::from("# ReactHuman scores\n\n");
    for line in header(r).lines() {
        let _ = writeln!(s, "{line}  ");
    }
    s.push_str("\nRates in %, distances in metres. Missing values (no impact point, no plan) leave the denominator; their counts are shown.\n\n## Main results\n\n");
    s.push_str(&main_table(r).markdown());
    let _ = write!(
        s,
        "\n{MAIN_NOTE}\n\n## d_end and HDE per ground-truth action\n\n"
    );
    s.push_str(&distance_table(r).markdown());
    for (title, column, pick) in distance_breakdowns() {
        let _ = write!(s, "\n## {title}\n\n");
        s.push_str(&distance_aia_table(r, column, pick).markdown());
    }
    for (title, column, pick) in [
        (
            "By family",
            "Family",
            (|m: &ModelReport| &m.by_family) as fn(&ModelReport) -> &Vec<MetricsRow>,
        ),
        ("By speed band", "Speed band", |m: &ModelReport| {
            &m.by_speed_band
        }),
        (
            "By ground-truth action",
            "Ground truth",
            |m: &ModelReport| &m.by_gt_action,
        ),
        ("Adversarial vs. not", "Scenes", |m: &ModelReport| {
            &m.by_adversarial
        }),
    ] {
        let _ = write!(s, "\n## {title}\n\n");
        s.push_str(&breakdown_table(r, column, pick).markdown());
    }
    for (title, t, note) in analyses_tables(r) {
        let _ = write!(s, "\n## {title}\n\n");
        if let Some(n) = note {
            let _ = write!(s, "{n}\n\n");
        }
        s.push_str(&t.markdown());
    }
    if !r.input.warnings.is_empty() {
        s.push_str("\n## Input warnings\n\n```\n");
        s.push_str(&warnings_text(r));
        s.push_str("```\n");
    }
    if let Some(e) = &r.execution {
        s.push_str(&crate::execution::report::markdown(e));
    }
    s
}

/// The CSV report: one row per (model, breakdown, group); rates are fractions; empty
/// cells are undefined values.
pub fn csv(r: &Report) -> String {
    let mut t = Table::new(&CSV_HEAD);
    let f = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x}"));
    let ci = |v: Option<[f64; 2]>| match v {
        Some([a, b]) => [format!("{a}"), format!("{b}")],
        None => [String::new(), String::new()],
    };
    let models: Vec<&ModelReport> = r.models.iter().chain(std::iter::once(&r.pooled)).collect();
    for m in models {
        let sets: [(&str, Vec<&MetricsRow>); 5] = [
            ("overall", vec![&m.overall]),
            ("family", m.by_family.iter().collect()),
            ("speed_band", m.by_speed_band.iter().collect()),
            ("gt_action", m.by_gt_action.iter().collect()),
            ("adversarial", m.by_adversarial.iter().collect()),
        ];
        for (bd, rows) in sets {
            let overall = bd == "overall";
            let only_overall = |v: String| if overall { v } else { String::new() };
            for x in rows {
                let mut row = vec![
                    m.model.clone(),
                    bd.to_string(),
                    x.group.clone(),
                    x.decisions.to_string(),
                    only_overall(m.lost.to_string()),
                    f(x.saa),
                    f(x.safety),
                    f(x.d_end),
                    x.d_end_n.to_string(),
                    x.d_end_missing.to_string(),
                    f(x.aia),
                    f(x.d_min),
                    f(x.closing),
                    x.hde_n.to_string(),
                    x.hde_missing.to_string(),
                    f(x.freeze_rate),
                ];
                let counts = [
                    x.first_rule.r1,
                    x.first_rule.r2,
                    x.first_rule.r3,
                    x.first_rule.r4,
                    x.rules_fired.r1,
                    x.rules_fired.r2,
                    x.rules_fired.r3,
                    x.rules_fired.r4,
                    x.predicted.catch,
                    x.predicted.dodge,
                    x.predicted.no_action,
                    x.predicted.unparseable,
                    x.expected,
                    x.unanswered,
                ];
                row.extend(counts.iter().map(|c| c.to_string()));
                row.push(only_overall(m.coverage.complete.to_string()));
                row.push(r.coverage.answered_only.to_string());
                for v in [
                    x.saa_ci,
                    x.safety_ci,
                    x.aia_ci,
                    x.d_end_ci,
                    x.d_min_ci,
                    x.freeze_rate_ci,
                ] {
                    row.extend(ci(v));
                }
                if overall {
                    row.push(f(m.balanced_accuracy));
                    row.extend(ci(m.balanced_accuracy_ci));
                } else {
                    row.extend([String::new(), String::new(), String::new()]);
                }
                t.row(row);
            }
        }
    }
    t.csv()
}

/// The CSV report's columns.
#[rustfmt::skip]
const CSV_HEAD: [&str; 47] = [
    "model", "breakdown", "group", "decisions", "lost", "saa", "safety", "d_end", "d_end_n",
    "d_end_missing", "aia", "d_min", "closing", "hde_n", "hde_missing", "freeze_rate",
    "first_R1", "first_R2", "first_R3", "first_R4", "fired_R1", "fired_R2", "fired_R3",
    "fired_R4", "pred_CATCH", "pred_DODGE", "pred_NO_ACTION", "pred_unparseable", "expected",
    "unanswered", "complete", "answered_only", "saa_lo", "saa_hi", "safety_lo", "safety_hi",
    "aia_lo", "aia_hi", "d_end_lo", "d_end_hi", "d_min_lo", "d_min_hi", "freeze_rate_lo",
    "freeze_rate_hi", "balanced_accuracy", "balanced_accuracy_lo", "balanced_accuracy_hi",
];
