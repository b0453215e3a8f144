//! `rh-score`'s command line: the arguments ([`args`]) and one module per command, each
//! with one entry point `run` over the parsed arguments; [`main`] is the binary.
//! Exit status: 0 success, 2 bad input or usage ([`rh_grade::error::InputError`]), 3 an
//! output that cannot be written ([`rh_contract::fsio::CannotWrite`]), 1 internal error.

pub mod args;
pub mod baseline_command;
pub mod dataset_arg;
pub mod export_command;
pub mod leaderboard_command;
pub mod output;
pub mod predict_command;
pub mod score_command;

use anyhow::Result;
use args::{Cli, Cmd};
use clap::Parser;
use rh_grade::error::{is_cannot_write, is_input_error};
use std::process::ExitCode;

/// Runs the command `cli` names.
pub fn run(cli: Cli) -> Result<()> {
    match cli.cmd {
        None => score_command::run(cli),
        Some(Cmd::Baseline {
            kind,
            dataset,
            allow_incomplete,
            seed,
            model,
            config,
        }) => {
            let dataset = dataset_arg::resolve_dataset(dataset, allow_incomplete)?;
            baseline_command::run(kind, &dataset, seed, model, config.as_deref())
        }
        Some(Cmd::Leaderboard {
            files,
            html,
            markdown,
            json,
        }) => leaderboard_command::run(&files, html.as_deref(), markdown.as_deref(), json),
        Some(Cmd::Predict(a)) => predict_command::run(*a),
        Some(Cmd::Export(a)) => export_command::run(*a),
        Some(Cmd::MakeFixture { out, n, seed, drop }) => {
            if !(1..=1_000_000).contains(&n) {
                return Err(
                    rh_grade::error::InputError(format!("--n {n}: must be 1-1000000")).into(),
                );
            }
            let rows = rh_grade::synthetic::synth_rows(n, seed);
            let drop: Vec<&str> = drop.iter().map(String::as_str).collect();
            rh_grade::synthetic::write_dataset(&out, &rows, &drop)?;
            output::print_out(&format!(
                "wrote {n} synthetic scenes to {}\n",
                out.display()
            ))
        }
    }
}

/// The `rh-score` binary: parses the arguments, runs the command, maps an error to its
/// exit status.
pub fn main() -> ExitCode {
    let args = rh_contract::stdout::help_help_as_help(std::env::args_os().collect());
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code =
                rh_contract::stdout::parser_print_status(e.exit_code(), e.print(), "rh-score");
            return ExitCode::from(code);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            rh_contract::note!("rh-score: error: {e:#}");
            if is_cannot_write(&e) {
                ExitCode::from(rh_contract::fsio::EXIT_CANNOT_WRITE)
            } else if is_input_error(&e) {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
