//! The Hugging Face cache on disk, in the layout Python's `huggingface_hub` uses:
//!
//! ```text
//! <cache>/datasets--owner--name/refs/<revision>             the commit a revision named
//! <cache>/datasets--owner--name/blobs/<etag>                 file contents, named by their hash
//! <cache>/datasets--owner--name/snapshots/<commit>/<path>    relative links into blobs/
//! <cache>/datasets--owner--name/rh-complete/<commit>.json    (ours) the file list of a
//!                                                            snapshot downloaded in full
//! ```
//!
//! A blob's name is its hash: the SHA-256 of the content for LFS files (64 hex digits), the
//! git blob SHA-1 (`sha1("blob <len>\0" + content)`, 40 hex digits) for the others. So any
//! blob can be checked against its own name, with no other record.

use rh_contract::digest::{hash_reader, hex};
use serde::{Deserialize, Serialize};
use sha1::Sha1;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The cache root: `$HF_HUB_CACHE`, `$HUGGINGFACE_HUB_CACHE`, `$HF_HOME/hub`,
/// `$XDG_CACHE_HOME/huggingface/hub`, else `~/.cache/huggingface/hub`.
pub fn cache_dir() -> PathBuf {
    let env = |k: &str| std::env::var(k).ok().filter(|s| !s.trim().is_empty());
    if let Some(d) = env("HF_HUB_CACHE").or_else(|| env("HUGGINGFACE_HUB_CACHE")) {
        return PathBuf::from(d);
    }
    hf_home().join("hub")
}

/// `$HF_HOME`, else `$XDG_CACHE_HOME/huggingface`, else `~/.cache/huggingface`.
pub fn hf_home() -> PathBuf {
    let env = |k: &str| std::env::var(k).ok().filter(|s| !s.trim().is_empty());
    if let Some(h) = env("HF_HOME") {
        return PathBuf::from(h);
    }
    let base = env("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env("HOME").unwrap_or_else(|| ".".into())).join(".cache"));
    base.join("huggingface")
}

/// One file of a snapshot: its path in the repository, its size, and the blob name (hash)
/// its content must have.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Entry {
    pub path: String,
    pub size: u64,
    pub blob: String,
}

/// A dataset repository's folder in the cache.
#[derive(Debug, Clone)]
pub struct RepoCache {
    pub root: PathBuf,
}

impl RepoCache {
    pub fn new(cache: &Path, repo_id: &str) -> RepoCache {
        RepoCache {
            root: cache.join(format!("datasets--{}", repo_id.replace('/', "--"))),
        }
    }

    pub fn blob_path(&self, blob: &str) -> PathBuf {
        self.root.join("blobs").join(blob)
    }

    pub fn snapshot_dir(&self, commit: &str) -> PathBuf {
        self.root.join("snapshots").join(commit)
    }

    fn record_path(&self, commit: &str) -> PathBuf {
        self.root.join("rh-complete").join(format!("{commit}.json"))
    }

    /// The commit `refs/<revision>` names (a commit hash names itself).
    pub fn read_ref(&self, revision: &str) -> Option<String> {
        if is_commit(revision) {
            return Some(revision.to_string());
        }
        let text = std::fs::read_to_string(self.root.join("refs").join(revision)).ok()?;
        let commit = text.trim().to_string();
        is_commit(&commit).then_some(commit)
    }

    pub fn write_ref(&self, revision: &str, commit: &str) -> std::io::Result<()> {
        if is_commit(revision) {
            return Ok(());
        }
        write_atomic(&self.root.join("refs").join(revision), commit.as_bytes())
    }

    /// Links `snapshots/<commit>/<path>` to `blobs/<blob>` (relative, as Python does).
    pub fn link(&self, commit: &str, entry: &Entry) -> std::io::Result<()> {
        let link = self.snapshot_dir(commit).join(&entry.path);
        let parent = link.parent().expect("a snapshot file has a parent");
        std::fs::create_dir_all(parent)?;
        let depth = entry.path.matches('/').count() + 2;
        let mut target = PathBuf::new();
        for _ in 0..depth {
            target.push("..");
        }
        target.push("blobs");
        target.push(&entry.blob);
        if std::fs::read_link(&link).ok().as_deref() == Some(target.as_path()) {
            return Ok(());
        }
        let tmp = parent.join(format!(
            ".{}.{}.link.tmp",
            file_name(&link),
            std::process::id()
        ));
        let _ = std::fs::remove_file(&tmp);
        symlink(&target, &tmp)?;
        std::fs::rename(&tmp, &link)
    }

    /// Records that every file of `entries` is in the snapshot, checked.
    pub fn write_record(&self, commit: &str, entries: &[Entry]) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(entries).expect("entries serialize");
        write_atomic(&self.record_path(commit), text.as_bytes())
    }

    /// The file list of `commit`'s snapshot: our record of a complete download, else the
    /// dataset's own `build.json` file checksums. None when neither says what it holds.
    pub fn expected_files(&self, commit: &str) -> Option<Vec<Entry>> {
        if let Ok(text) = std::fs::read_to_string(self.record_path(commit)) {
            if let Ok(entries) = serde_json::from_str::<Vec<Entry>>(&text) {
                return Some(entries);
            }
        }
        let manifest =
            std::fs::read_to_string(self.snapshot_dir(commit).join("build.json")).ok()?;
        let value: serde_json::Value = serde_json::from_str(&manifest).ok()?;
        let files = value.get("files")?.as_object()?;
        let mut entries = vec![Entry {
            path: "build.json".into(),
            size: manifest.len() as u64,
            blob: String::new(),
        }];
        for (path, sha) in files {
            entries.push(Entry {
                path: path.clone(),
                size: 0,
                blob: sha.as_str()?.to_string(),
            });
        }
        Some(entries)
    }
}

/// What is wrong with a snapshot on disk.
#[derive(Debug, Default)]
pub struct SnapshotCheck {
    pub missing: Vec<String>,
    pub corrupt: Vec<String>,
}

impl SnapshotCheck {
    pub fn ok(&self) -> bool {
        self.missing.is_empty() && self.corrupt.is_empty()
    }

    /// "3 files missing (a, b, c); 1 file altered (d)", at most 10 names each.
    pub fn describe(&self) -> String {
        let list = |v: &[String]| {
            let mut s = v.iter().take(10).cloned().collect::<Vec<_>>().join(", ");
            if v.len() > 10 {
                s.push_str(&format!(", … {} more", v.len() - 10));
            }
            s
        };
        let mut parts = vec![];
        if !self.missing.is_empty() {
            parts.push(format!(
                "{} file(s) missing: {}",
                self.missing.len(),
                list(&self.missing)
            ));
        }
        if !self.corrupt.is_empty() {
            parts.push(format!(
                "{} file(s) whose content does not match its hash: {}",
                self.corrupt.len(),
                list(&self.corrupt)
            ));
        }
        parts.join("; ")
    }
}

/// Checks that every expected file is in the snapshot and has the content its hash names.
/// An entry with an empty blob name is only checked for presence.
pub fn check_snapshot(dir: &Path, entries: &[Entry]) -> SnapshotCheck {
    let mut check = SnapshotCheck::default();
    for e in entries {
        let path = dir.join(&e.path);
        if std::fs::metadata(&path).is_err() {
            check.missing.push(e.path.clone());
            continue;
        }
        if !e.blob.is_empty() && !content_matches(&path, &e.blob).unwrap_or(false) {
            check.corrupt.push(e.path.clone());
        }
    }
    check
}

/// Whether 40/64 hex digits: a git SHA-1 / a SHA-256.
pub fn is_hash_name(name: &str) -> bool {
    (name.len() == 40 || name.len() == 64) && name.bytes().all(|b| b.is_ascii_hexdigit())
}

pub fn is_commit(rev: &str) -> bool {
    rev.len() == 40 && rev.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

/// Both hashes of a content, computed in one pass. The git blob hash starts with the
/// length, so it is computed for the declared length; a body of another length fails the
/// size check anyway.
pub struct Hasher {
    sha256: Sha256,
    sha1: Sha1,
    len: u64,
}

impl Hasher {
    pub fn new(declared_len: u64) -> Hasher {
        let mut sha1 = Sha1::new();
        sha1.update(format!("blob {declared_len}\0").as_bytes());
        Hasher {
            sha256: Sha256::new(),
            sha1,
            len: 0,
        }
    }

    pub fn update(&mut self, bytes: &[u8]) {
        self.sha256.update(bytes);
        self.sha1.update(bytes);
        self.len += bytes.len() as u64;
    }

    /// Bytes seen so far.
    pub fn len(&self) -> u64 {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// (sha256 hex, git blob sha1 hex).
    pub fn finish(self) -> (String, String) {
        (hex(&self.sha256.finalize()), hex(&self.sha1.finalize()))
    }
}

/// The hash of the kind `name` is (SHA-256 for 64 digits, git blob SHA-1 for 40) of the
/// file at `path`, streamed.
pub fn hash_like(path: &Path, name: &str) -> std::io::Result<String> {
    let len = std::fs::metadata(path)?.len();
    let file = std::fs::File::open(path)?;
    if name.len() == 40 {
        let mut h = Sha1::new();
        h.update(format!("blob {len}\0").as_bytes());
        hash_reader(h, file)
    } else {
        hash_reader(Sha256::new(), file)
    }
}

/// Whether the file's content has the hash `name`.
pub fn content_matches(path: &Path, name: &str) -> std::io::Result<bool> {
    Ok(hash_like(path, name)? == name.to_ascii_lowercase())
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "file".into())
}

pub use rh_contract::fsio::write_atomic;

#[cfg(unix)]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    std::os::unix::fs::symlink(target, link)
}

#[cfg(not(unix))]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    // No links: copy the blob (the layout Python falls back to on such systems).
    let blob = link.parent().expect("parent").join(target);
    std::fs::copy(blob, link).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blob_names_check_content() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f");
        std::fs::write(&p, b"hello\n").unwrap();
        // `git hash-object` of "hello\n" and its sha256.
        assert!(content_matches(&p, "ce013625030ba8dba906f756967f9e9ca394464a").unwrap());
        assert!(content_matches(
            &p,
            "5891b5b522d5df086d0ff0b110fbd9d21bb4fc7163af34d08286a2e846f6be03"
        )
        .unwrap());
        assert!(!content_matches(&p, "ce013625030ba8dba906f756967f9e9ca394464b").unwrap());
        let mut h = Hasher::new(6);
        h.update(b"hel");
        h.update(b"lo\n");
        let (s256, s1) = h.finish();
        assert_eq!(s1, "ce013625030ba8dba906f756967f9e9ca394464a");
        assert_eq!(
            s256,
            "5891b5b522d5df086d0ff0b110fbd9d21bb4fc7163af34d08286a2e846f6be03"
        );
    }

    #[test]
    fn links_are_relative_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let repo = RepoCache::new(dir.path(), "o/n");
        let commit = "0123456789abcdef0123456789abcdef01234567";
        std::fs::create_dir_all(repo.root.join("blobs")).unwrap();
        let blob = "ce013625030ba8dba906f756967f9e9ca394464a";
        std::fs::write(repo.blob_path(blob), b"hello\n").unwrap();
        let e = Entry {
            path: "a/b.txt".into(),
            size: 6,
            blob: blob.into(),
        };
        repo.link(commit, &e).unwrap();
        let snap = repo.snapshot_dir(commit);
        assert_eq!(std::fs::read(snap.join("a/b.txt")).unwrap(), b"hello\n");
        let missing = Entry {
            path: "c.txt".into(),
            size: 1,
            blob: blob.into(),
        };
        let check = check_snapshot(&snap, &[e.clone(), missing]);
        assert_eq!(check.missing, vec!["c.txt".to_string()]);
        std::fs::write(repo.blob_path(blob), b"hellO\n").unwrap();
        let check = check_snapshot(&snap, &[e]);
        assert_eq!(check.corrupt, vec!["a/b.txt".to_string()]);
    }
}
