//! Writing files so that no reader ever sees half of one: every file of the project is
//! written under a temporary sibling name (`.NAME.PID.N.tmp`, unique per process and
//! call), synced, then renamed onto its path. One mechanism for bytes in memory
//! ([`write_atomic`], or [`write_file`] whose error names the file), for a stream
//! ([`AtomicFile`]: write, then [`AtomicFile::commit`]), for a file another library writes
//! ([`Unsynced::at`]: write to [`Unsynced::temp`], then [`Unsynced::commit`]), for a stream
//! several owners write ([`SharedFile`]) and for a file whose slow fsync runs off the
//! caller's path ([`write_unsynced`]).
//!
//! A failed write leaves the previous file as it was and removes the temporary one; it
//! is a [`CannotWrite`] naming the file, which both programs exit with
//! [`EXIT_CANNOT_WRITE`]. Two writers of one path never tear it: the last rename wins
//! with a whole file.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The exit status of both programs when an output (a file, or stdout) cannot be
/// written: a full disk, a read-only or missing directory, `/dev/full`.
pub const EXIT_CANNOT_WRITE: u8 = 3;

/// An output that could not be written: which one and why.
#[derive(Debug)]
pub struct CannotWrite {
    /// What it is ("the JSON report"), or empty.
    pub what: String,
    /// The file (or `stdout`).
    pub path: PathBuf,
    pub source: std::io::Error,
}

impl CannotWrite {
    pub fn new(what: impl Into<String>, path: &Path, source: std::io::Error) -> CannotWrite {
        CannotWrite {
            what: what.into(),
            path: path.to_path_buf(),
            source,
        }
    }
}

impl std::fmt::Display for CannotWrite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = if self.what.is_empty() {
            String::new()
        } else {
            format!("{} to ", self.what)
        };
        write!(
            f,
            "cannot write {what}{}: {}",
            self.path.display(),
            self.source
        )?;
        if self.path != Path::new("stdout") {
            write!(f, " (nothing written; any previous file is unchanged)")?;
        }
        Ok(())
    }
}

/// The cause is part of the message (not a `source`, which `{:#}` would print twice).
impl std::error::Error for CannotWrite {}

static TEMP_SERIAL: AtomicU64 = AtomicU64::new(0);

/// The temporary sibling a file is written under before it is renamed onto `path`:
/// unique per process and call, so concurrent writers never share one.
pub fn temp_sibling(path: &Path) -> PathBuf {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let n = TEMP_SERIAL.fetch_add(1, Ordering::Relaxed);
    dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// The directory a file goes in (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Writes `bytes` to `path` atomically: a sibling temp file, fsync, then rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes)?;
    f.commit()
}

/// [`write_atomic`], its error a [`CannotWrite`] naming `what` and the file.
pub fn write_file(path: &Path, what: &str, bytes: &[u8]) -> Result<(), CannotWrite> {
    write_atomic(path, bytes).map_err(|e| CannotWrite::new(what, path, e))
}

/// A file being written under its temporary name (buffered): [`AtomicFile::commit`]
/// syncs and renames it into place; dropped without a commit, it is removed. A path that
/// is not a regular file (`/dev/stdout`, a pipe, `/dev/full`) is written directly: there
/// is nothing to keep whole, and a device is never replaced by a file.
pub struct AtomicFile {
    out: Option<std::io::BufWriter<fs::File>>,
    /// `None`: written directly (not a regular file).
    tmp: Option<PathBuf>,
    path: PathBuf,
}

/// Whether `path` exists as something other than a regular file or a directory (a
/// device, a pipe, a socket), following links.
fn is_special(path: &Path) -> bool {
    fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

impl AtomicFile {
    /// Opens the temporary sibling of `path` (creating the directory).
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        let (file, tmp) = if is_special(path) {
            (fs::OpenOptions::new().write(true).open(path)?, None)
        } else {
            fs::create_dir_all(parent_of(path))?;
            let tmp = temp_sibling(path);
            (fs::File::create(&tmp)?, Some(tmp))
        };
        Ok(AtomicFile {
            out: Some(std::io::BufWriter::with_capacity(1 << 16, file)),
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// The file it will become.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> std::io::Result<()> {
        let out = self.out.take().expect("not yet committed");
        let file = out.into_inner().map_err(|e| e.into_error())?;
        let Some(tmp) = &self.tmp else {
            return Ok(());
        };
        file.sync_all()?;
        drop(file);
        fs::rename(tmp, &self.path)?;
        sync_dir(parent_of(&self.path));
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.out.as_mut().expect("open").write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.out.as_mut().expect("open").flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Not committed, or the commit failed: the temporary goes (the old file stays).
        self.out = None;
        if let Some(tmp) = &self.tmp {
            if tmp.exists() {
                let _ = fs::remove_file(tmp);
            }
        }
    }
}

/// Makes a rename durable (best effort: not every file system syncs a directory).
fn sync_dir(dir: &Path) {
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
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
        fs::create_dir_all(parent_of(path))?;
        Ok(Unsynced {
            tmp: temp_sibling(path),
            path: path.to_path_buf(),
        })
    }

    /// fsync, then rename onto the final path (the temporary file is removed if either
    /// fails).
    pub fn commit(self) -> std::io::Result<()> {
        let r = fs::File::open(&self.tmp)
            .and_then(|f| f.sync_all())
            .and_then(|_| fs::rename(&self.tmp, &self.path));
        if r.is_err() {
            let _ = fs::remove_file(&self.tmp);
        }
        r
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

/// A file written whole or not at all ([`AtomicFile`]) through a writer
/// another owner holds (the scoring's decision lines): a failed write is an `io::Error`
/// carrying a `CannotWrite` naming the file; [`SharedFile::commit`] puts it in place.
#[derive(Clone)]
pub struct SharedFile {
    file: std::sync::Arc<std::sync::Mutex<Option<AtomicFile>>>,
    what: &'static str,
    path: std::path::PathBuf,
}

impl SharedFile {
    pub fn create(path: &Path, what: &'static str) -> Result<SharedFile, CannotWrite> {
        let file = AtomicFile::create(path).map_err(|e| CannotWrite::new(what, path, e))?;
        Ok(SharedFile {
            file: std::sync::Arc::new(std::sync::Mutex::new(Some(file))),
            what,
            path: path.to_path_buf(),
        })
    }

    fn fail(&self, e: std::io::Error) -> std::io::Error {
        std::io::Error::other(CannotWrite::new(self.what, &self.path, e))
    }

    fn with<T>(&self, f: impl FnOnce(&mut AtomicFile) -> std::io::Result<T>) -> std::io::Result<T> {
        let mut guard = self.file.lock().unwrap_or_else(|p| p.into_inner());
        match guard.as_mut() {
            Some(file) => f(file).map_err(|e| self.fail(e)),
            None => Err(self.fail(std::io::Error::other("already closed"))),
        }
    }

    /// Syncs and renames the file into place.
    pub fn commit(&self) -> Result<(), CannotWrite> {
        let file = self.file.lock().unwrap_or_else(|p| p.into_inner()).take();
        match file {
            Some(f) => f
                .commit()
                .map_err(|e| CannotWrite::new(self.what, &self.path, e)),
            None => Ok(()),
        }
    }
}

impl Write for SharedFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.with(|f| f.write(buf))
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.with(|f| f.flush())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shared_file_appears_whole_on_commit_only() {
        let dir = std::env::temp_dir().join(format!("rh-shared-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("lines.jsonl");
        let f = SharedFile::create(&path, "the lines").unwrap();
        let mut other = f.clone();
        other.write_all(b"one\n").unwrap();
        assert!(!path.exists());
        f.commit().unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"one\n");
        let e = other.write_all(b"two\n").unwrap_err();
        assert!(e.to_string().contains("already closed"), "{e}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writes_whole_files_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("rh-fsio-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let p = dir.join("sub/report.json");
        write_atomic(&p, b"old").unwrap();
        let mut f = AtomicFile::create(&p).unwrap();
        f.write_all(b"new, half").unwrap();
        drop(f); // not committed: the old file stays, the temporary goes
        assert_eq!(fs::read(&p).unwrap(), b"old");
        write_file(&p, "the report", b"new").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
        let names: Vec<String> = fs::read_dir(p.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["report.json"]);
        assert_ne!(temp_sibling(&p), temp_sibling(&p));
        // A device is written, never replaced by a file.
        if Path::new("/dev/full").exists() {
            let e = write_file(Path::new("/dev/full"), "the JSON report", b"{}").unwrap_err();
            assert!(e.to_string().contains("/dev/full"), "{e}");
            assert!(!fs::metadata("/dev/full").unwrap().is_file());
            write_file(Path::new("/dev/null"), "a report", b"{}").unwrap();
            assert!(!fs::metadata("/dev/null").unwrap().is_file());
        }
        let e = write_file(&dir.join("sub/report.json/x"), "the CSV", b"x").unwrap_err();
        let text = e.to_string();
        assert!(text.starts_with("cannot write the CSV to "), "{text}");
        assert!(text.contains("report.json/x"), "{text}");
        let _ = fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_full_device_fails_naming_the_file() {
        if !Path::new("/dev/full").exists() {
            return;
        }
        // /dev/full is a file whose every write fails with ENOSPC.
        let mut f = fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let e = f.write_all(b"x").and_then(|_| f.flush()).unwrap_err();
        let c = CannotWrite::new("the report", Path::new("out.json"), e);
        assert!(c.to_string().contains("out.json"), "{c}");
        assert!(c.to_string().contains("previous file is unchanged"), "{c}");
    }
}
