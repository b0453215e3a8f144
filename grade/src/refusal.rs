//! What `rh-score` tells the user about its input: refusing a predictions file from
//! which nothing could be scored (exit 2, naming why: empty, a JSON array, lines without
//! `model`, ids of another dataset, only lost decisions), and the notes after a report
//! (every dropped line named, incomplete models).

use crate::coverage::skip_reason;
use crate::error::InputError;
use crate::score::Scoring;
use anyhow::Result;

/// Refuses (exit 2) a predictions file from which no decision was scored: empty, a JSON
/// array, lines without `model`, ids of another dataset, only lost decisions.
pub fn check_scored(scoring: &Scoring, file: &str) -> Result<()> {
    // A file that opens a JSON array is refused even when a line inside it (a
    // pretty-printed element) happens to be a prediction object.
    if let Some(w) = scoring.warnings.get("json_array") {
        if w.first_lines
            .first()
            .is_some_and(|&l| Some(l) == scoring.first_content_line)
        {
            return Err(InputError(format!(
                "predictions {file} is a JSON array (line {}: `[`), not JSON Lines: write one \
                 prediction object per line (e.g. `jq -c '.[]' {file} > preds.jsonl`)",
                w.first_lines[0]
            ))
            .into());
        }
    }
    if scoring.scored > 0 {
        return Ok(());
    }
    if scoring.lines == scoring.blank_lines {
        return Err(InputError(format!(
            "predictions {file} is empty: no prediction lines (JSON Lines: one object with scene_id, model and plan or response per line)"
        ))
        .into());
    }
    let mut reasons: Vec<(u64, String)> = scoring
        .warnings
        .iter()
        .filter(|(_, w)| w.dropped)
        .map(|(k, w)| {
            let first = w.first_lines.first().copied().unwrap_or(0);
            let eg = w
                .examples
                .first()
                .map_or(String::new(), |e| format!(", e.g. {e}"));
            (
                w.count,
                format!(
                    "{} line(s) {} (first at line {first}{eg})",
                    w.count,
                    skip_reason(k, scoring.ds)
                ),
            )
        })
        .collect();
    if scoring.lost > 0 {
        reasons.push((
            scoring.lost,
            format!(
                "{} decision(s) lost to API errors (`error` lines; `rh-score predict --retry-errors` asks again)",
                scoring.lost
            ),
        ));
    }
    reasons.sort_by(|a, b| b.0.cmp(&a.0));
    let why: Vec<String> = reasons.into_iter().map(|r| r.1).collect();
    Err(InputError(format!(
        "no decision could be scored from predictions {file} ({} lines): {}",
        scoring.lines,
        if why.is_empty() {
            "no prediction lines".to_string()
        } else {
            why.join("; ")
        }
    ))
    .into())
}

/// What `rh-score` says on stderr after a report: the input warnings (every dropped line
/// named) and the incomplete models.
pub fn stderr_notes(report: &crate::report::Report) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let warned: u64 = report.input.warnings.iter().map(|w| w.count).sum();
    if warned > 0 {
        let _ = writeln!(
            s,
            "rh-score: {warned} input warning(s) in {}; see the report's warnings section",
            report.input.file
        );
        // One line per kind, naming its lines, so a user can go and look.
        for w in &report.input.warnings {
            let _ = match (&w.lines, w.first_lines.first()) {
                (Some(lines), _) => writeln!(
                    s,
                    "rh-score:   {} ×{} dropped (lines {lines})",
                    w.kind, w.count
                ),
                (None, Some(first)) => writeln!(
                    s,
                    "rh-score:   {} ×{} (first at line {first})",
                    w.kind, w.count
                ),
                (None, None) => writeln!(s, "rh-score:   {} ×{}", w.kind, w.count),
            };
        }
    }
    for m in report.models.iter().filter(|m| !m.coverage.complete) {
        let _ = writeln!(
            s,
            "rh-score: INCOMPLETE: {} answered {} of {} expected scenes (expected: {}); {}",
            m.model,
            m.coverage.answered,
            m.coverage.expected,
            report.coverage.note,
            if report.coverage.answered_only {
                "metrics over its answered scenes only (--answered-only)"
            } else {
                "its unanswered scenes count as failed"
            }
        );
    }
    s
}
