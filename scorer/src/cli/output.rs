//! What the commands share: the scoring configuration from `--config`, writing a report
//! file, and printing to stdout (a closed pipe is not an error).

use crate::error::InputError;
use crate::Config;
use anyhow::Result;
use std::io::Write;
use std::path::Path;

/// The scoring configuration: the file given, else the embedded configs/scoring.toml.
pub fn load_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => Config::load(p).map_err(|e| InputError(format!("{e:#}")).into()),
        None => Ok(Config::default()),
    }
}

pub fn write_file(path: &Path, what: &str, text: &str) -> Result<()> {
    std::fs::write(path, text)
        .map_err(|e| InputError(format!("cannot write {what} to {}: {e}", path.display())).into())
}

/// Prints to stdout; a reader that went away (`| head`) is not an error.
pub fn print_out(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r?),
    }
}
