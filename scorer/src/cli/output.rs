//! What the commands share: the scoring configuration from `--config`, writing a report
//! file (whole or not at all, `rh_contract::fsio`), and printing to stdout (a closed pipe
//! is not an error, a full one is: `rh_contract::stdout`).

use crate::error::InputError;
use crate::Config;
use anyhow::Result;
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

/// A file written whole or not at all (`rh_contract::fsio::AtomicFile`) through a writer
/// another owner holds (the scoring's decision lines): a failed write is an `io::Error`
/// carrying a `CannotWrite` naming the file; [`SharedFile::commit`] puts it in place.
#[derive(Clone)]
pub struct SharedFile {
    file: std::sync::Arc<std::sync::Mutex<Option<rh_contract::fsio::AtomicFile>>>,
    what: &'static str,
    path: std::path::PathBuf,
}

impl SharedFile {
    pub fn create(path: &Path, what: &'static str) -> Result<SharedFile> {
        let file = rh_contract::fsio::AtomicFile::create(path)
            .map_err(|e| rh_contract::fsio::CannotWrite::new(what, path, e))?;
        Ok(SharedFile {
            file: std::sync::Arc::new(std::sync::Mutex::new(Some(file))),
            what,
            path: path.to_path_buf(),
        })
    }

    fn fail(&self, e: std::io::Error) -> std::io::Error {
        std::io::Error::other(rh_contract::fsio::CannotWrite::new(
            self.what, &self.path, e,
        ))
    }

    fn with<T>(
        &self,
        f: impl FnOnce(&mut rh_contract::fsio::AtomicFile) -> std::io::Result<T>,
    ) -> std::io::Result<T> {
        let mut guard = self.file.lock().unwrap_or_else(|p| p.into_inner());
        match guard.as_mut() {
            Some(file) => f(file).map_err(|e| self.fail(e)),
            None => Err(self.fail(std::io::Error::other("already closed"))),
        }
    }

    /// Syncs and renames the file into place.
    pub fn commit(&self) -> Result<()> {
        let file = self.file.lock().unwrap_or_else(|p| p.into_inner()).take();
        match file {
            Some(f) => f
                .commit()
                .map_err(|e| rh_contract::fsio::CannotWrite::new(self.what, &self.path, e).into()),
            None => Ok(()),
        }
    }
}

impl std::io::Write for SharedFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.with(|f| f.write(buf))
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.with(|f| f.flush())
    }
}
