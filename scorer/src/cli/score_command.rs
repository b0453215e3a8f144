//! `rh-score PREDS`: scoring a predictions file ([`rh_grade::score::Scoring`]), the report
//! ([`rh_grade::report::Report`]), `--execute` ([`rh_execute::execute_scored`]) and the
//! output files and terminal tables the arguments ask for.

use super::args::Cli;
use super::dataset_arg::resolve_dataset;
use super::output::{load_config, print_out, write_file};
use anyhow::{Context, Result};
use rh_contract::fsio::SharedFile;
use rh_grade::error::InputError;
use rh_grade::{Dataset, Report};
use std::path::Path;

/// `rh-score PREDS --dataset DIR`: scores, then writes each report asked for.
pub fn run(cli: Cli) -> Result<()> {
    let cfg = load_config(cli.config.as_deref())?;
    if cli.explain {
        print_out(&rh_grade::explain::explain(&cfg))?;
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
        .map(|d| -> rh_grade::api::OpenDecisions { Box::new(move || Ok(Box::new(d))) });
    let opts = rh_grade::api::ScoreOptions {
        subset: cli.subset,
        answered_only: cli.answered_only,
        decisions: open,
        execution: cli.execute,
        compare: cli.compare.as_ref().map(|p| [p[0].clone(), p[1].clone()]),
    };
    let source = if preds.as_os_str() == "-" {
        rh_grade::api::Preds::Stdin
    } else {
        rh_grade::api::Preds::Path(&preds)
    };
    let rh_grade::api::Scored {
        mut scoring,
        mut report,
    } = rh_grade::api::score(&ds, &cfg, source, opts)?;
    if cli.results.is_some() {
        // A clash of results file names is found before any output is written.
        rh_report::results::check_file_names(scoring.models.iter().map(|m| m.name.as_str()))?;
    }
    if cli.execute {
        let cache = (!cli.no_exec_cache).then(|| {
            cli.exec_cache
                .clone()
                .unwrap_or_else(rh_execute::default_cache_dir)
        });
        let videos = cli
            .execute_videos
            .as_deref()
            .map(|dir| rh_execute::VideoRequest {
                dir,
                scenes: cli.video_scenes.as_deref(),
                tiled_scene: cli.tiled_scene.as_deref(),
                progress: !cli.quiet,
            });
        #[cfg(feature = "videos")]
        let mut draw = |pending: &[_], outcomes: &[_], names: &[_]| match &videos {
            Some(req) => rh_execute_videos::draw_and_note(&ds, pending, outcomes, names, &cfg, req),
            None => Ok(()),
        };
        #[cfg(not(feature = "videos"))]
        let mut draw = |_: &[rh_execute::Pending],
                        _: &[Option<rh_contract::execution::Outcome>],
                        _: &[String]| {
            Ok(()) // --execute-videos was refused above
        };
        report.execution = Some(rh_execute::execute_scored(
            &mut scoring,
            &ds,
            &cfg,
            cache.as_deref(),
            videos
                .is_some()
                .then_some(&mut draw as rh_execute::DrawVideos),
        )?);
    }
    let identity = match cli.results {
        Some(_) => Some(rh_report::results::DatasetIdentity::of(
            &ds,
            &scoring.expected,
        )?),
        None => None,
    };
    drop(scoring);
    if let Some(d) = &decisions {
        d.commit()?;
    }
    if let (Some(dir), Some(identity)) = (&cli.results, &identity) {
        let scoring_id = rh_report::results::ScoringIdentity::of(&cfg, cli.answered_only);
        let files = rh_report::results::results_files(&report, identity, &scoring_id);
        for p in rh_report::results::write_results(dir, &files)? {
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
    cfg: &rh_grade::Config,
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
        write_file(p, "the CSV report", &rh_grade::tables::csv(report))?;
        if let Some(e) = &report.execution {
            // Outcome rates have other columns: their own file beside it, FILE.execution.csv.
            let q = p.with_extension("execution.csv");
            write_file(
                &q,
                "the execution CSV",
                &rh_grade::execution::report::csv(e),
            )?;
        }
    }
    if let Some(p) = &cli.markdown {
        write_file(
            p,
            "the Markdown report",
            &rh_grade::tables::markdown(report),
        )?;
    }
    if let Some(d) = &cli.figures {
        rh_report::figures::write_figures(report, d)?;
    }
    let site = match &cli.html {
        Some(dir) => Some(rh_report::html::write_site(report, ds, cfg, preds, dir)?),
        None => None,
    };
    if !cli.quiet && !json_stdout {
        print_out(&rh_grade::tables::terminal(report))?;
        if let Some(e) = &report.execution {
            print_out(&rh_grade::execution::report::terminal(e, 50))?;
        }
    } else if let Some(e) = &report.execution {
        // The disagreements are always listed (on stderr when stdout is taken).
        if !e.disagreements.is_empty() {
            rh_contract::note_part!("{}", rh_grade::execution::report::terminal(e, 50));
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
    rh_contract::note_part!("{}", rh_grade::refusal::stderr_notes(report));
    Ok(())
}
