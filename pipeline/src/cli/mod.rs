//! The `rh-pipeline` command line (specification §14): the arguments ([`args`]) and one module per
//! command, each with one entry point `run`. Exit status: 0 success, 2 bad input or usage
//! (with a message naming what is wrong), 3 an output that cannot be written (the file
//! named), 1 internal failure ([`failure`]).

pub mod args;
pub mod balance_command;
pub mod build_command;
pub mod download_command;
pub mod failure;
pub mod llm_planner;
pub mod merge_command;
pub mod plan_command;
pub mod release_command;
pub mod sheet_command;
pub mod verify_command;

use args::{Cli, Command};
use clap::Parser;
use failure::{input, Failure};
use rh_catalog::Catalog;
use rh_scenes::config::Config;
use std::process::ExitCode;

/// The catalog and the build configuration of `--catalog` and `--config` (else the
/// embedded ones).
fn load(cli: &Cli) -> Result<(Catalog, Config), Failure> {
    let catalog = match &cli.catalog {
        Some(dir) => Catalog::load_dir(dir),
        None => Catalog::embedded(),
    }
    .map_err(|e| input(format!("catalog: {e}")))?;
    let config = match &cli.config {
        Some(path) => Config::load(path),
        None => Config::embedded(),
    }
    .map_err(|e| input(format!("config: {e}")))?;
    Ok((catalog, config))
}

/// Runs the command `cli` names.
pub fn run(cli: Cli) -> Result<(), Failure> {
    // Commands that need neither the catalog nor the configuration.
    match &cli.command {
        Command::Merge { out, shards, json } => return merge_command::run(out, shards, *json),
        Command::Sheet {
            dir,
            out,
            camera,
            json,
        } => return sheet_command::run(dir, out, camera, *json),
        Command::Download {
            repo,
            revision,
            out,
        } => return download_command::run(repo, revision.as_deref(), out.as_deref()),
        Command::Fingerprint { dir, json } => return release_command::fingerprint(dir, *json),
        _ => {}
    }
    let (catalog, config) = load(&cli)?;
    match cli.command {
        Command::Merge { .. }
        | Command::Download { .. }
        | Command::Sheet { .. }
        | Command::Fingerprint { .. } => {
            unreachable!("handled above")
        }
        Command::Build(args) => build_command::run(args, &catalog, &config),
        Command::Balance {
            seed,
            per_family,
            pool,
            families,
            json,
        } => balance_command::run(&catalog, &config, seed, per_family, pool, families, json),
        Command::Plan {
            description,
            seed,
            llm,
            llm_args,
        } => plan_command::run(&catalog, &description, seed, llm, &llm_args),
        Command::Verify { dir, fast, json } => verify_command::run(&dir, &catalog, fast, json),
    }
}

/// Entry point of the binary.
pub fn main() -> ExitCode {
    let args = rh_contract::stdout::help_help_as_help(std::env::args_os().collect());
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code =
                rh_contract::stdout::parser_print_status(e.exit_code(), e.print(), "rh-pipeline");
            return ExitCode::from(code);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            rh_contract::note!("rh-pipeline: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}
