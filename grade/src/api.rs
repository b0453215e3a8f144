//! The one scoring sequence — expected scenes, the streaming scorer, the refusal check,
//! the report, `--compare` — that the binary (`rh-score PREDS`) and every other front end
//! (the Python package's `reacthuman.score`) run, so the numbers are the same.
//! `--execute` and the output files are the caller's, after it.

use crate::config::Config;
use crate::coverage::Expected;
use crate::dataset::{Dataset, Subset};
use crate::report::Report;
use crate::score::Scoring;
use anyhow::Result;
use std::io::Write;
use std::path::Path;

/// Where the predictions come from.
pub enum Preds<'a> {
    /// A `preds.jsonl` file (its path is the report's `preds_file`, as the binary prints it).
    Path(&'a Path),
    /// Standard input (`rh-score -`), reported as `-`.
    Stdin,
    /// JSON Lines text in memory, reported under `name`.
    Text { name: &'a str, text: &'a str },
}

/// Opens the `--decisions` output.
pub type OpenDecisions<'a> = Box<dyn FnOnce() -> Result<Box<dyn Write + 'a>> + 'a>;

/// What a run asks for besides the report.
#[derive(Default)]
pub struct ScoreOptions<'a> {
    /// `--subset`: the expected scenes (default: the dataset's eval subset, or all).
    pub subset: Option<Subset>,
    /// `--answered-only`: metrics over the answered scenes only.
    pub answered_only: bool,
    /// `--decisions`: where one JSON line per input decision goes, opened once the
    /// expected scenes are resolved (a refused subset leaves no file).
    pub decisions: Option<OpenDecisions<'a>>,
    /// `--execute`: the scorer keeps each scored plan for the executor.
    pub execution: bool,
    /// `--compare A B`: the paired comparison of two models.
    pub compare: Option<[String; 2]>,
}

/// A scored run: the scorer's state (for `--execute` and the results file) and the report.
pub struct Scored<'a> {
    pub scoring: Scoring<'a>,
    pub report: Report,
}

/// Scores `preds` against `ds` under `cfg` with `opts`: the binary's steps in the
/// binary's order.
pub fn score<'a>(
    ds: &'a Dataset,
    cfg: &'a Config,
    preds: Preds,
    opts: ScoreOptions<'a>,
) -> Result<Scored<'a>> {
    let expected = Expected::resolve(ds, opts.subset)?;
    let mut scoring = Scoring::new(ds, cfg).with_expected(expected);
    if let Some(open) = opts.decisions {
        scoring = scoring.with_decisions_output(open()?);
    }
    if opts.execution {
        scoring = scoring.with_execution();
    }
    let name = match preds {
        Preds::Path(p) => {
            scoring.score_path(p)?;
            p.display().to_string()
        }
        Preds::Stdin => {
            scoring.score_reader(std::io::BufReader::with_capacity(1 << 20, std::io::stdin()))?;
            "-".to_string()
        }
        Preds::Text { name, text } => {
            scoring.score_reader(std::io::Cursor::new(text.as_bytes()))?;
            name.to_string()
        }
    };
    crate::refusal::check_scored(&scoring, &name)?;
    let mut report = Report::build_with(&scoring, &name, opts.answered_only);
    if let Some([a, b]) = &opts.compare {
        report
            .comparisons
            .push(crate::compare::compare(&scoring, a, b)?);
    }
    Ok(Scored { scoring, report })
}

/// The report `rh-score PREDS --dataset DIR [--subset S] [--answered-only] --json -` prints.
pub fn score_report(
    ds: &Dataset,
    cfg: &Config,
    subset: Option<Subset>,
    answered_only: bool,
    preds: Preds,
) -> Result<Report> {
    let opts = ScoreOptions {
        subset,
        answered_only,
        ..ScoreOptions::default()
    };
    Ok(score(ds, cfg, preds, opts)?.report)
}
