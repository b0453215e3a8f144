//! `--execute` after scoring (beside `score` and `execution`, which it joins): runs the decisions a [`Scoring`] collected, draws their
//! videos when asked, completes the held-back `--decisions` lines with each outcome, and
//! builds the report's execution part.

use crate::config::Config;
use crate::dataset::Dataset;
use crate::execution::{ExecutionReport, VideoRequest};
use crate::score::Scoring;
use anyhow::Result;
use std::path::Path;

/// Executes the decisions `scoring` collected (it must have been built
/// `with_execution`), with the outcome cache in `cache`, and draws `videos` when given.
#[cfg(feature = "execute")]
pub fn execute_scored(
    scoring: &mut Scoring,
    ds: &Dataset,
    cfg: &Config,
    cache: Option<&Path>,
    videos: Option<VideoRequest>,
) -> Result<ExecutionReport> {
    use crate::execution::execute_all;
    let (collected, names) = scoring
        .take_execution()
        .expect("execution was enabled before scoring");
    let (outcomes, stats) = execute_all(ds, &collected.pending, &cfg.execution, cache)?;
    if let Some(v) = videos {
        write_videos(ds, &collected.pending, &outcomes, &names, cfg, v)?;
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

/// Without the `execute` feature: refused (the command line refuses `--execute` before
/// scoring in such a build).
#[cfg(not(feature = "execute"))]
pub fn execute_scored(
    _: &mut Scoring,
    _: &Dataset,
    _: &Config,
    _: Option<&Path>,
    _: Option<VideoRequest>,
) -> Result<ExecutionReport> {
    Err(crate::error::InputError(
        "--execute: this rh-score was built without the `execute` feature (no simulator)".into(),
    )
    .into())
}

/// Draws the execution videos (`--execute-videos`) and says what was written.
#[cfg(feature = "videos")]
fn write_videos(
    ds: &Dataset,
    pending: &[crate::execution::Pending],
    outcomes: &[Option<rh_contract::execution::Outcome>],
    names: &[String],
    cfg: &Config,
    req: VideoRequest,
) -> Result<()> {
    let started = std::time::Instant::now();
    let index = crate::execution::videos::write_videos(
        ds,
        pending,
        outcomes,
        names,
        &cfg.execution,
        &cfg.execution_video,
        &req,
    )?;
    let decisions: usize = index.scenes.iter().map(|s| s.decisions.len()).sum();
    let secs = started.elapsed().as_secs_f64();
    rh_contract::note!(
        "rh-score: execution videos of {decisions} decisions in {} scenes ({:.2} s per decision) in {}; see {}",
        index.scenes.len(),
        secs / decisions.max(1) as f64,
        req.dir.display(),
        req.dir.join("index.json").display()
    );
    Ok(())
}

/// Without the `videos` feature: refused.
#[cfg(all(feature = "execute", not(feature = "videos")))]
fn write_videos(
    _: &Dataset,
    _: &[crate::execution::Pending],
    _: &[Option<rh_contract::execution::Outcome>],
    _: &[String],
    _: &Config,
    _: VideoRequest,
) -> Result<()> {
    Err(crate::error::InputError(
        "--execute-videos: this rh-score was built without the `videos` feature (no renderer)"
            .into(),
    )
    .into())
}
