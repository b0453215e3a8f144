//! `rh-score PREDS`: scoring a predictions file ([`crate::score::Scoring`]), the report
//! ([`crate::report::Report`]), `--execute` ([`crate::execute_scored::execute_scored`]) and the
//! output files and terminal tables the arguments ask for.

use super::args::Cli;
use super::dataset_arg::resolve_dataset;
use super::output::{load_config, print_out, write_file, SharedFile};
use crate::error::InputError;
use crate::{Dataset, Report};
use anyhow::{Context, Result};
use std::path::Path;

/// `rh-score PREDS --dataset DIR`: scores, then writes each report asked for.
pub fn run(cli: Cli) -> Result<()> {
    let cfg = load_config(cli.config.as_deref())?;
    if cli.explain {
        print_out(&crate::explain::explain(&cfg))?;
        if cli.preds.is_none() {
            return Ok(());
        }
    }
    let Some(preds) = cli.preds.clone() else {
        return Err(InputError(
            "missing the predictions file: rh-score PREDS.jsonl --dataset DIR (see --help)".into(),
        )
        .into());
    };
    if cli.html.is_some() && preds.as_os_str() == "-" {
        return Err(InputError(
            "--html reads the predictions twice (per-decision details for the scene pages): give a file, not stdin".into(),
        )
        .into());
    }
    if cli.execute && !cfg!(feature = "execute") {
        return Err(InputError(
            "--execute: this rh-score was built without the `execute` feature (no simulator); build it with default features (cargo build --release -p rh-score)".into(),
        )
        .into());
    }
    if cli.execute_videos.is_some() && !cfg!(feature = "videos") {
        return Err(InputError(
            "--execute-videos: this rh-score was built without the `videos` feature (no renderer); build it with default features (cargo build --release -p rh-score)".into(),
        )
        .into());
    }
    let ds = Dataset::load(&resolve_dataset(cli.dataset.clone(), cli.allow_incomplete)?)?;
    // Written under a temporary name, renamed into place once every line is in (a run
    // refused before then leaves no file: the temporary is removed when dropped).
    let decisions = match &cli.decisions {
        Some(p) => Some(SharedFile::create(p, "the decision lines")?),
        None => None,
    };
    let open = decisions
        .clone()
        .map(|d| -> crate::api::OpenDecisions { Box::new(move || Ok(Box::new(d))) });
    let opts = crate::api::ScoreOptions {
        subset: cli.subset,
        answered_only: cli.answered_only,
        decisions: open,
        execution: cli.execute,
        compare: cli.compare.as_ref().map(|p| [p[0].clone(), p[1].clone()]),
    };
    let source = if preds.as_os_str() == "-" {
        crate::api::Preds::Stdin
    } else {
        crate::api::Preds::Path(&preds)
    };
    let crate::api::Scored {
        mut scoring,
        mut report,
    } = crate::api::score(&ds, &cfg, source, opts)?;
    if cli.results.is_some() {
        // A clash of results file names is found before any output is written.
        crate::results::check_file_names(scoring.models.iter().map(|m| m.name.as_str()))?;
    }
    if cli.execute {
        let cache = (!cli.no_exec_cache).then(|| {
            cli.exec_cache
                .clone()
                .unwrap_or_else(crate::execution::default_cache_dir)
        });
        let videos = cli
            .execute_videos
            .as_deref()
            .map(|dir| crate::execution::VideoRequest {
                dir,
                scenes: cli.video_scenes.as_deref(),
                tiled_scene: cli.tiled_scene.as_deref(),
                progress: !cli.quiet,
            });
        report.execution = Some(crate::execute_scored::execute_scored(
            &mut scoring,
            &ds,
            &cfg,
            cache.as_deref(),
            videos,
        )?);
    }
    let identity = match cli.results {
        Some(_) => Some(crate::results::DatasetIdentity::of(&ds, &scoring.expected)?),
        None => None,
    };
    drop(scoring);
    if let Some(d) = &decisions {
        d.commit()?;
    }
    if let (Some(dir), Some(identity)) = (&cli.results, &identity) {
        let scoring_id = crate::results::ScoringIdentity::of(&cfg, cli.answered_only);
        let files = crate::results::results_files(&report, identity, &scoring_id);
        for p in crate::results::write_results(dir, &files)? {
            rh_contract::note!("rh-score: results file {}", p.display());
        }
    }
    write_reports(&cli, &report, &ds, &cfg, &preds)
}

/// The report in every form the arguments ask for: files, the site, the terminal tables
/// and the notes on stderr.
fn write_reports(
    cli: &Cli,
    report: &Report,
    ds: &Dataset,
    cfg: &crate::Config,
    preds: &Path,
) -> Result<()> {
    let json_stdout = cli.json.as_deref() == Some(Path::new("-"));
    if let Some(p) = &cli.json {
        let text = serde_json::to_string_pretty(report).context("serializing the report")? + "\n";
        if json_stdout {
            print_out(&text)?;
        } else {
            write_file(p, "the JSON report", &text)?;
        }
    }
    if let Some(p) = &cli.csv {
        write_file(p, "the CSV report", &crate::tables::csv(report))?;
        if let Some(e) = &report.execution {
            // Outcome rates have other columns: their own file beside it, FILE.execution.csv.
            let q = p.with_extension("execution.csv");
            write_file(&q, "the execution CSV", &crate::execution::report::csv(e))?;
        }
    }
    if let Some(p) = &cli.markdown {
        write_file(p, "the Markdown report", &crate::tables::markdown(report))?;
    }
    if let Some(d) = &cli.figures {
        crate::figures::write_figures(report, d)?;
    }
    let site = match &cli.html {
        Some(dir) => Some(crate::html::write_site(report, ds, cfg, preds, dir)?),
        None => None,
    };
    if !cli.quiet && !json_stdout {
        print_out(&crate::tables::terminal(report))?;
        if let Some(e) = &report.execution {
            print_out(&crate::execution::report::terminal(e, 50))?;
        }
    } else if let Some(e) = &report.execution {
        // The disagreements are always listed (on stderr when stdout is taken).
        if !e.disagreements.is_empty() {
            rh_contract::note_part!("{}", crate::execution::report::terminal(e, 50));
        }
    }
    if let Some(site) = site {
        let index = site
            .dir
            .canonicalize()
            .unwrap_or(site.dir.clone())
            .join("index.html");
        rh_contract::note!(
            "rh-score: site with {} models and {} scenes ({} video files) in {}; open file://{}",
            site.models,
            site.scenes,
            site.media_files,
            site.dir.display(),
            index.display()
        );
    }
    rh_contract::note_part!("{}", crate::refusal::stderr_notes(report));
    Ok(())
}
