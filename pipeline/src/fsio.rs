//! Writing files so that no reader ever sees half of one.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically: a sibling temp file, fsync, then rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// A file written under its temporary name (`write_atomic`'s), not yet synced or renamed:
/// `write_atomic` in two halves, so the slow half (fsync) can run off the caller's path.
pub struct Unsynced {
    tmp: PathBuf,
    path: PathBuf,
}

/// Writes `bytes` to `path`'s temporary sibling; `Unsynced::commit` makes it durable and
/// renames it into place.
pub fn write_unsynced(path: &Path, bytes: &[u8]) -> std::io::Result<Unsynced> {
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    if let Err(e) = fs::write(&tmp, bytes) {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    Ok(Unsynced {
        tmp,
        path: path.to_path_buf(),
    })
}

impl Unsynced {
    /// fsync, then rename onto the final path.
    pub fn commit(self) -> std::io::Result<()> {
        fs::File::open(&self.tmp)?.sync_all()?;
        fs::rename(&self.tmp, &self.path)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}
