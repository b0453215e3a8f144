//! The ReactHuman dataset on the Hugging Face Hub (specification §8, §14): download a dataset
//! repository into the standard Hugging Face cache, checking every file, and resolve it
//! from that cache when the Hub cannot be reached.
//!
//! The cache is the one Python's `huggingface_hub` uses (`$HF_HUB_CACHE`, else
//! `$HF_HOME/hub`, else `~/.cache/huggingface/hub`; `datasets--owner--name/refs/<revision>`
//! names a commit, `snapshots/<commit>/` holds the files as links into `blobs/`), so a
//! dataset downloaded by either side is found by the other. `HF_ENDPOINT` selects the
//! server, `HF_TOKEN` / `HF_TOKEN_PATH` / `$HF_HOME/token` the token, and
//! `HF_HUB_OFFLINE=1` skips the network.
//!
//! Integrity (README "Reliability"): every request has a connect and a read timeout
//! (`configs/hub.toml`, `HF_HUB_ETAG_TIMEOUT`, `HF_HUB_DOWNLOAD_TIMEOUT`); every file is
//! checked against the size and hash the Hub's listing states before it enters `blobs/`;
//! every cached blob is checked against its name before it is used (fetched again online,
//! reported offline); a snapshot is only returned when every file it should hold is
//! there — the listing of a complete download is recorded in `rh-complete/<commit>.json`,
//! and a dataset's own `build.json` names its files and their SHA-256.

pub mod cache;
mod remote;

use cache::RepoCache;
use remote::{Remote, RemoteError};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The project's released dataset, `owner/name@revision` (`released_dataset` of the
/// embedded `configs/hub.toml`): what `rh-score` scores against when neither `--dataset`
/// nor `$RH_DATASET` is given.
pub fn released_dataset() -> String {
    Settings::parse(EMBEDDED_CONFIG, "configs/hub.toml")
        .expect("the embedded configs/hub.toml parses (unit-tested)")
        .released_dataset
}

/// The Hub's public address, used when `HF_ENDPOINT` is not set.
pub const DEFAULT_ENDPOINT: &str = "https://huggingface.co";

/// The embedded `configs/hub.toml`.
pub const EMBEDDED_CONFIG: &str = include_str!("../../configs/hub.toml");

/// Why a dataset could not be had.
#[derive(Debug, thiserror::Error)]
pub enum HubError {
    /// The repository or revision does not exist on the server (exit 2).
    #[error("{0}")]
    NotFound(String),
    /// The server wants a token, or refused the one given (exit 2).
    #[error("{0}")]
    Unauthorized(String),
    /// Only part of the dataset is in the cache and the Hub cannot supply the rest (exit 2).
    #[error("{0}")]
    Incomplete(String),
    /// Anything else: the network, the server, the cache (exit 1).
    #[error("{0}")]
    Failed(String),
}

impl HubError {
    /// The process exit status for this error (specification §14: 2 bad input, 1 internal failure).
    pub fn exit_code(&self) -> u8 {
        match self {
            HubError::NotFound(_) | HubError::Unauthorized(_) | HubError::Incomplete(_) => 2,
            HubError::Failed(_) => 1,
        }
    }
}

/// Network policy: `configs/hub.toml`, each value overridable from the environment.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Connect and read timeout of metadata requests (`HF_HUB_ETAG_TIMEOUT`).
    pub metadata_timeout: Duration,
    /// Connect timeout and longest pause between two reads of a download
    /// (`HF_HUB_DOWNLOAD_TIMEOUT`).
    pub download_timeout: Duration,
    /// Files downloaded at the same time.
    pub concurrent_downloads: usize,
    /// The project's released dataset, `owner/name@revision`.
    pub released_dataset: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SettingsFile {
    metadata_timeout_s: f64,
    download_timeout_s: f64,
    concurrent_downloads: usize,
    released_dataset: String,
}

/// Why the Hub settings (`configs/hub.toml` and the environment's overrides) are unusable.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    /// The file is not a valid `hub.toml` (TOML or a field).
    #[error("{origin}: {message}")]
    Parse { origin: String, message: String },
    #[error("{origin}: released_dataset must be owner/name[@revision], not '{value}'")]
    ReleasedDataset { origin: String, value: String },
    /// `what` (a field or an environment variable) is out of range.
    #[error("{what} must be a number of seconds in (0, 86400], not {value}")]
    Seconds { what: String, value: f64 },
    #[error("{var}={value} is not a number of seconds")]
    NotANumber { var: String, value: String },
}

fn seconds(what: &str, v: f64) -> Result<Duration, SettingsError> {
    if v.is_finite() && v > 0.0 && v <= 86_400.0 {
        Ok(Duration::from_secs_f64(v))
    } else {
        Err(SettingsError::Seconds {
            what: what.to_string(),
            value: v,
        })
    }
}

impl Settings {
    /// Parses a `hub.toml` text (`origin` names it in errors).
    pub fn parse(text: &str, origin: &str) -> Result<Settings, SettingsError> {
        let f: SettingsFile = toml::from_str(text).map_err(|e| SettingsError::Parse {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        let (repo, revision) = f
            .released_dataset
            .split_once('@')
            .unwrap_or((&f.released_dataset, "main"));
        if !is_repo_id(repo) || revision.is_empty() {
            return Err(SettingsError::ReleasedDataset {
                origin: origin.to_string(),
                value: f.released_dataset,
            });
        }
        Ok(Settings {
            metadata_timeout: seconds(
                &format!("{origin}: metadata_timeout_s"),
                f.metadata_timeout_s,
            )?,
            download_timeout: seconds(
                &format!("{origin}: download_timeout_s"),
                f.download_timeout_s,
            )?,
            concurrent_downloads: f.concurrent_downloads.clamp(1, 64),
            released_dataset: f.released_dataset,
        })
    }

    /// The embedded configuration with the environment's overrides applied.
    pub fn from_env() -> Result<Settings, SettingsError> {
        let mut s = Settings::parse(EMBEDDED_CONFIG, "configs/hub.toml")?;
        for (var, slot) in [
            ("HF_HUB_ETAG_TIMEOUT", &mut s.metadata_timeout),
            ("HF_HUB_DOWNLOAD_TIMEOUT", &mut s.download_timeout),
        ] {
            if let Ok(v) = std::env::var(var) {
                if !v.trim().is_empty() {
                    let n: f64 = v.trim().parse().map_err(|_| SettingsError::NotANumber {
                        var: var.to_string(),
                        value: v.clone(),
                    })?;
                    *slot = seconds(var, n)?;
                }
            }
        }
        Ok(s)
    }
}

/// A dataset snapshot on local disk.
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// `.../datasets--owner--name/snapshots/<commit>`: a plain dataset directory.
    pub path: PathBuf,
    /// True when the Hub was not asked (offline mode) or could not be reached and the
    /// snapshot came from the cache.
    pub from_cache_only: bool,
    /// Why the cache was used (offline mode, or the Hub's failure).
    pub cache_reason: Option<String>,
    /// Files the snapshot holds (all checked).
    pub files: usize,
    /// Files this call downloaded.
    pub downloaded: usize,
}

impl Snapshot {
    /// When the snapshot came from the cache alone, the note that says so (for stderr):
    /// "the Hub at URL was not used (why); REPO comes from the Hugging Face cache, all N
    /// files checked".
    pub fn cache_note(&self, repo: &str) -> Option<String> {
        self.from_cache_only.then(|| {
            format!(
                "the Hub at {} was not used ({}); {repo} comes from the Hugging Face cache, all {} files checked",
                endpoint(),
                self.cache_reason.as_deref().unwrap_or("offline"),
                self.files
            )
        })
    }
}

/// Whether `text` has the form of a Hub repository id, `owner/name`.
pub fn is_repo_id(text: &str) -> bool {
    let Some((owner, name)) = text.split_once('/') else {
        return false;
    };
    let part_ok = |p: &str| {
        !p.is_empty()
            && !p.starts_with('.')
            && !p.starts_with('-')
            && p.len() <= 96
            && p.chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
    };
    part_ok(owner) && part_ok(name) && !name.contains("..")
}

/// The Hub endpoint in force (`HF_ENDPOINT`, else the public Hub).
pub fn endpoint() -> String {
    std::env::var("HF_ENDPOINT")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .unwrap_or_else(|| DEFAULT_ENDPOINT.to_string())
        .trim_end_matches('/')
        .to_string()
}

fn offline_mode() -> bool {
    std::env::var("HF_HUB_OFFLINE")
        .map(|v| {
            matches!(
                v.trim().to_ascii_lowercase().as_str(),
                "1" | "true" | "yes" | "on"
            )
        })
        .unwrap_or(false)
}

/// The token: `HF_TOKEN` (or the older `HUGGING_FACE_HUB_TOKEN`), else the file
/// `HF_TOKEN_PATH`, else `$HF_HOME/token`.
pub fn token() -> Option<String> {
    let env = |k: &str| {
        std::env::var(k)
            .ok()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
    };
    if let Some(t) = env("HF_TOKEN").or_else(|| env("HUGGING_FACE_HUB_TOKEN")) {
        return Some(t);
    }
    let path = env("HF_TOKEN_PATH")
        .map(PathBuf::from)
        .unwrap_or_else(|| cache::hf_home().join("token"));
    std::fs::read_to_string(path)
        .ok()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
}

/// Downloads every file of dataset `repo_id` at `revision` (default `main`) into the HF
/// cache and returns the snapshot directory. Files already in the cache (and matching
/// their hash) are not fetched again. When the Hub cannot be reached, hangs past the
/// timeouts, fails, or serves a corrupt file (or `HF_HUB_OFFLINE` is set), the snapshot
/// that the cache's `refs/<revision>` names is used instead, if it is complete.
pub fn fetch(repo_id: &str, revision: Option<&str>) -> Result<Snapshot, HubError> {
    let settings = Settings::from_env().map_err(|e| HubError::Failed(e.to_string()))?;
    fetch_with(repo_id, revision, &settings)
}

/// `fetch` with explicit network settings.
pub fn fetch_with(
    repo_id: &str,
    revision: Option<&str>,
    settings: &Settings,
) -> Result<Snapshot, HubError> {
    let endpoint = endpoint();
    let revision = revision.unwrap_or("main");
    let what = format!("dataset {repo_id} (revision {revision}) on {endpoint}");
    if !is_repo_id(repo_id) {
        return Err(HubError::NotFound(format!(
            "'{repo_id}' is not a Hub dataset id (expected owner/name)"
        )));
    }
    let cache_root = cache::cache_dir();
    let repo_cache = RepoCache::new(&cache_root, repo_id);

    let reason = if offline_mode() {
        "HF_HUB_OFFLINE is set".to_string()
    } else {
        match download(&endpoint, repo_id, revision, settings, &repo_cache) {
            Ok(snapshot) => return Ok(snapshot),
            Err(RemoteError::NotFound(e)) => {
                return Err(HubError::NotFound(format!("{what} was not found: {e}")))
            }
            Err(RemoteError::Unauthorized(e)) => {
                return Err(HubError::Unauthorized(format!(
                    "{what} needs a token with access (set HF_TOKEN or run `huggingface-cli login`): {e}"
                )))
            }
            Err(RemoteError::Unreachable(e)) => format!("cannot reach {what}: {e}"),
            Err(RemoteError::Bad(e)) => format!("the Hub failed for {what}: {e}"),
        }
    };
    from_cache(&repo_cache, revision, &what, &reason)
}

fn download(
    endpoint: &str,
    repo_id: &str,
    revision: &str,
    settings: &Settings,
    repo_cache: &RepoCache,
) -> Result<Snapshot, RemoteError> {
    let remote = Remote::new(endpoint, repo_id, settings).map_err(RemoteError::Bad)?;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| RemoteError::Bad(format!("cannot start the async runtime: {e}")))?;
    runtime.block_on(async {
        let commit = remote.commit(revision).await?;
        let entries = remote.files(&commit).await?;
        let downloaded = remote.download_all(repo_cache, &commit, &entries).await?;
        let io = |e: std::io::Error| {
            RemoteError::Bad(format!(
                "cannot write to the cache {}: {e}",
                repo_cache.root.display()
            ))
        };
        repo_cache.write_record(&commit, &entries).map_err(io)?;
        repo_cache.write_ref(revision, &commit).map_err(io)?;
        Ok(Snapshot {
            path: repo_cache.snapshot_dir(&commit),
            from_cache_only: false,
            cache_reason: None,
            files: entries.len(),
            downloaded,
        })
    })
}

/// The cached snapshot of `revision`, if the cache holds all of it, every file checked.
fn from_cache(
    repo_cache: &RepoCache,
    revision: &str,
    what: &str,
    reason: &str,
) -> Result<Snapshot, HubError> {
    let cache_root = repo_cache.root.parent().unwrap_or(Path::new("."));
    let Some(commit) = repo_cache.read_ref(revision) else {
        return Err(HubError::Failed(format!(
            "{reason}, and the Hugging Face cache {} holds no copy of {what}",
            cache_root.display()
        )));
    };
    let dir = repo_cache.snapshot_dir(&commit);
    if !dir.is_dir() {
        return Err(HubError::Failed(format!(
            "{reason}, and the Hugging Face cache {} holds no copy of {what}",
            cache_root.display()
        )));
    }
    let Some(entries) = repo_cache.expected_files(&commit) else {
        return Err(HubError::Incomplete(format!(
            "{reason}; the cached snapshot {} of {what} has no record of a complete download and no build.json listing its files, so it may be partial; download it once with the Hub reachable",
            dir.display()
        )));
    };
    let check = cache::check_snapshot(&dir, &entries);
    if !check.ok() {
        return Err(HubError::Incomplete(format!(
            "{reason}; the cached snapshot {} of {what} is not a whole dataset: {}",
            dir.display(),
            check.describe()
        )));
    }
    Ok(Snapshot {
        path: dir,
        from_cache_only: true,
        cache_reason: Some(reason.to_string()),
        files: entries.len(),
        downloaded: 0,
    })
}

/// Copies a snapshot (whose files may be links into the cache's blobs) into `out` as a
/// plain dataset directory; each file is written to a temporary name and renamed, so a
/// reader never sees half a file. Returns the number of files copied.
pub fn copy_snapshot(snapshot: &Path, out: &Path) -> std::io::Result<usize> {
    let mut count = 0;
    let mut stack = vec![snapshot.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(&dir)?
            .map(|e| e.map(|e| e.path()))
            .collect::<Result<_, _>>()?;
        entries.sort();
        for path in entries {
            let rel = path.strip_prefix(snapshot).expect("under the snapshot");
            // `metadata` follows links: a snapshot entry is a link to a blob file.
            if std::fs::metadata(&path)?.is_dir() {
                stack.push(path);
                continue;
            }
            let dest = rh_contract::fsio::Unsynced::at(&out.join(rel))?;
            if let Err(e) = std::fs::copy(&path, dest.temp()) {
                dest.discard();
                return Err(e);
            }
            dest.commit()?;
            count += 1;
        }
    }
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repo_ids() {
        assert!(is_repo_id("Alan123/reacthuman-benchmark-scaled"));
        let released = released_dataset();
        assert!(
            is_repo_id(released.split_once('@').unwrap().0),
            "{released}"
        );
        assert!(is_repo_id("a/b.c_d"));
        assert!(!is_repo_id("name"));
        assert!(!is_repo_id("a/b/c"));
        assert!(!is_repo_id("./data"));
        assert!(!is_repo_id("/abs/path"));
        assert!(!is_repo_id("a/"));
        assert!(!is_repo_id("a/b c"));
    }

    #[test]
    fn settings_from_config_and_environment() {
        let s = Settings::parse(EMBEDDED_CONFIG, "hub.toml").unwrap();
        assert_eq!(s.metadata_timeout, Duration::from_secs(10));
        assert_eq!(s.download_timeout, Duration::from_secs(10));
        let text = "metadata_timeout_s = 1\ndownload_timeout_s = 1\nconcurrent_downloads = 1\n";
        assert!(
            Settings::parse(&format!("{text}released_dataset = \"a b\""), "x.toml")
                .unwrap_err()
                .to_string()
                .contains("x.toml: released_dataset")
        );
        assert!(Settings::parse(
            "metadata_timeout_s = 0\ndownload_timeout_s = 1\nconcurrent_downloads = 1\nreleased_dataset = \"a/b\"",
            "x.toml"
        )
        .unwrap_err()
        .to_string()
        .contains("x.toml: metadata_timeout_s"));
        assert!(Settings::parse("metadata_timeout_s = 1\n", "x.toml")
            .unwrap_err()
            .to_string()
            .contains("x.toml"));
    }

    #[test]
    fn exit_codes() {
        assert_eq!(HubError::NotFound(String::new()).exit_code(), 2);
        assert_eq!(HubError::Unauthorized(String::new()).exit_code(), 2);
        assert_eq!(HubError::Incomplete(String::new()).exit_code(), 2);
        assert_eq!(HubError::Failed(String::new()).exit_code(), 1);
    }
}
