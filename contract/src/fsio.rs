//! Writing files so that no reader ever sees half of one: every file of the project is
//! written under a temporary sibling name (`.NAME.PID.tmp`), synced, then renamed onto
//! its path. One mechanism for bytes in memory ([`write_atomic`]), for a file another
//! library writes ([`Unsynced::at`]: write to [`Unsynced::temp`], then
//! [`Unsynced::commit`]) and for a file whose slow fsync runs off the caller's path
//! ([`write_unsynced`]).

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The temporary sibling a file is written under before it is renamed onto `path`.
pub fn temp_sibling(path: &Path) -> PathBuf {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    dir.join(format!(".{name}.{}.tmp", std::process::id()))
}

/// Writes `bytes` to `path` atomically: a sibling temp file, fsync, then rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let pending = Unsynced::at(path)?;
    let result = (|| {
        let mut f = fs::File::create(pending.temp())?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(pending.temp(), path)
    })();
    if result.is_err() {
        pending.discard();
    }
    result
}

/// A file written under its temporary name, not yet synced or renamed.
pub struct Unsynced {
    tmp: PathBuf,
    path: PathBuf,
}

/// Writes `bytes` to `path`'s temporary sibling; `Unsynced::commit` makes it durable and
/// renames it into place.
pub fn write_unsynced(path: &Path, bytes: &[u8]) -> std::io::Result<Unsynced> {
    let pending = Unsynced::at(path)?;
    if let Err(e) = fs::write(pending.temp(), bytes) {
        pending.discard();
        return Err(e);
    }
    Ok(pending)
}

impl Unsynced {
    /// Prepares to write `path` (creating its directory): write the content to
    /// [`Unsynced::temp`], then [`Unsynced::commit`] (or [`Unsynced::discard`]).
    pub fn at(path: &Path) -> std::io::Result<Unsynced> {
        fs::create_dir_all(path.parent().unwrap_or(Path::new(".")))?;
        Ok(Unsynced {
            tmp: temp_sibling(path),
            path: path.to_path_buf(),
        })
    }

    /// fsync, then rename onto the final path.
    pub fn commit(self) -> std::io::Result<()> {
        fs::File::open(&self.tmp)?.sync_all()?;
        fs::rename(&self.tmp, &self.path)
    }

    /// Removes the temporary file (after a failed write).
    pub fn discard(self) {
        let _ = fs::remove_file(&self.tmp);
    }

    /// Where the content is written before the rename.
    pub fn temp(&self) -> &Path {
        &self.tmp
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}
