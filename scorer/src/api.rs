//! One call for what `rh-score PREDS --dataset DIR --json FILE` computes (no `--execute`,
//! `--compare` or side outputs), for front ends other than the binary: the Python
//! package's `reacthuman.score`. It takes the binary's own steps in the binary's order
//! (expected scenes, streaming scorer, refusal check, report), so the numbers are the
//! same.

use crate::config::Config;
use crate::coverage::Expected;
use crate::dataset::{Dataset, Subset};
use crate::report::Report;
use crate::score::Scoring;
use anyhow::Result;
use std::path::Path;

/// Where the predictions come from.
pub enum Preds<'a> {
    /// A `preds.jsonl` file (its path is the report's `preds_file`, as the binary prints it).
    Path(&'a Path),
    /// JSON Lines text in memory, reported under `name`.
    Text { name: &'a str, text: &'a str },
}

/// The report `rh-score PREDS --dataset DIR [--subset S] [--answered-only] --json -` prints.
pub fn score_report(
    ds: &Dataset,
    cfg: &Config,
    subset: Option<Subset>,
    answered_only: bool,
    preds: Preds,
) -> Result<Report> {
    let expected = Expected::resolve(ds, subset)?;
    let mut scoring = Scoring::new(ds, cfg).with_expected(expected);
    let name = match preds {
        Preds::Path(p) => {
            scoring.score_path(p)?;
            p.display().to_string()
        }
        Preds::Text { name, text } => {
            scoring.score_reader(std::io::Cursor::new(text.as_bytes()))?;
            name.to_string()
        }
    };
    crate::refusal::check_scored(&scoring, &name)?;
    Ok(Report::build_with(&scoring, &name, answered_only))
}
