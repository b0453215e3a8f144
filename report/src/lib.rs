//! ReactHuman's report writers over the grading core's report model ([`rh_grade::report`]):
//! figures (SVG + PNG, [`figures`]), the static site ([`html`]), results files
//! ([`results`]: what was measured, for leaderboards) and leaderboards merged from them
//! ([`leaderboard`]). The text tables (terminal, Markdown, CSV) are the core's
//! (`rh_grade::tables`).

// The core's modules under their own names inside this crate (`crate::report`,
// `crate::dataset` …), as the writers were written beside them.
#[cfg(test)]
use rh_grade::synthetic;
#[allow(unused_imports)]
use rh_grade::{
    action_rule, aia, baseline, config, coverage, dataset, error, execution, metrics, preds,
    report, safety_rule, score, stats, text_table,
};

pub mod figures;
pub mod html;
pub mod leaderboard;
pub mod results;
