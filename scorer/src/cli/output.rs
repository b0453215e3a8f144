//! What the commands share: the scoring configuration from `--config`, writing a report
//! file (whole or not at all, `rh_contract::fsio`), and printing to stdout (a closed pipe
//! is not an error, a full one is: `rh_contract::stdout`).

use anyhow::Result;
use rh_grade::error::InputError;
use rh_grade::Config;
use std::path::Path;

/// The scoring configuration: the file given, else the embedded configs/scoring.toml.
pub fn load_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => Config::load(p).map_err(|e| InputError(format!("{e:#}")).into()),
        None => Ok(Config::default()),
    }
}

/// Writes a report file atomically; a failure is a `CannotWrite` naming it (exit 3).
pub fn write_file(path: &Path, what: &str, text: &str) -> Result<()> {
    Ok(rh_contract::fsio::write_file(path, what, text.as_bytes())?)
}

/// Prints to stdout; a reader that went away (`| head`) is not an error.
pub fn print_out(text: &str) -> Result<()> {
    Ok(rh_contract::stdout::print(text)?)
}
