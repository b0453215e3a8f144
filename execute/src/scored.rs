//! `--execute` after scoring: runs the decisions a [`Scoring`] collected, draws their
//! videos when asked, completes the held-back `--decisions` lines with each outcome, and
//! builds the report's execution part.

use crate::{execute_all, ExecutionReport, Pending};
use anyhow::Result;
use rh_contract::execution::Outcome;
use rh_grade::config::Config;
use rh_grade::dataset::Dataset;
use rh_grade::score::Scoring;
use std::path::Path;

/// Draws the execution videos of the executed decisions (`--execute-videos`; the
/// renderer's, rh-execute-videos): the pending decisions, their outcomes (aligned) and the
/// model names.
pub type DrawVideos<'a> =
    &'a mut dyn FnMut(&[Pending], &[Option<Outcome>], &[String]) -> Result<()>;

/// Executes the decisions `scoring` collected (it must have been built
/// `with_execution`), with the outcome cache in `cache`, and draws the videos when given.
pub fn execute_scored(
    scoring: &mut Scoring,
    ds: &Dataset,
    cfg: &Config,
    cache: Option<&Path>,
    videos: Option<DrawVideos>,
) -> Result<ExecutionReport> {
    let (collected, names) = scoring
        .take_execution()
        .expect("execution was enabled before scoring");
    let (outcomes, stats) = execute_all(ds, &collected.pending, &cfg.execution, cache)?;
    if let Some(draw) = videos {
        draw(&collected.pending, &outcomes, &names)?;
    }
    if let Some(w) = scoring.decisions_output() {
        let by_key: std::collections::BTreeMap<(usize, u32), usize> = collected
            .pending
            .iter()
            .enumerate()
            .map(|(i, p)| ((p.model, p.scene), i))
            .collect();
        for (model, scene, mut line) in collected.deferred {
            let scored = line.get("status").and_then(|s| s.as_str()) == Some("scored");
            if let (true, Some(&i), Some(obj)) =
                (scored, by_key.get(&(model, scene)), line.as_object_mut())
            {
                let value = match &outcomes[i] {
                    Some(o) => serde_json::to_value(o)?,
                    None => serde_json::json!({"outcome": null, "reason": "not executed (R1)"}),
                };
                obj.insert("execution".into(), value);
            }
            serde_json::to_writer(&mut *w, &line)?;
            w.write_all(b"\n")?;
        }
        w.flush()?;
    }
    Ok(ExecutionReport::build(
        ds,
        &names,
        &collected.pending,
        &outcomes,
        &cfg.execution,
        stats,
    ))
}
