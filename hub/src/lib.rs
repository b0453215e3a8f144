//! The ReactHuman dataset on the Hugging Face Hub (SPEC §8, §14): download a dataset
//! repository into the standard Hugging Face cache with the `hf-hub` crate, and resolve it
//! from that cache when the Hub cannot be reached.
//!
//! The cache is the one Python's `huggingface_hub` uses (`$HF_HUB_CACHE`, else
//! `$HF_HOME/hub`, else `~/.cache/huggingface/hub`; `datasets--owner--name/refs/<revision>`
//! names a commit, `snapshots/<commit>/` holds the files as links into `blobs/`), so a
//! dataset downloaded by either side is found by the other. `HF_ENDPOINT` selects the
//! server, `HF_TOKEN` / `HF_TOKEN_PATH` / `$HF_HOME/token` the token, and
//! `HF_HUB_OFFLINE=1` skips the network.

use hf_hub::{split_id, HFClient, HFError};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The released dataset: what `rh-score` scores against when neither `--dataset` nor
/// `$RH_DATASET` is given.
pub const RELEASED_DATASET: &str = "Alan123/reacthuman-benchmark-scaled";

/// The Hub's public address, used when `HF_ENDPOINT` is not set.
pub const DEFAULT_ENDPOINT: &str = "https://huggingface.co";

/// Why a dataset could not be had.
#[derive(Debug, thiserror::Error)]
pub enum HubError {
    /// The repository or revision does not exist on the server (exit 2).
    #[error("{0}")]
    NotFound(String),
    /// The server wants a token, or refused the one given (exit 2).
    #[error("{0}")]
    Unauthorized(String),
    /// Anything else: the network, the server, the cache (exit 1).
    #[error("{0}")]
    Failed(String),
}

impl HubError {
    /// The process exit status for this error (SPEC §14: 2 bad input, 1 internal failure).
    pub fn exit_code(&self) -> u8 {
        match self {
            HubError::NotFound(_) | HubError::Unauthorized(_) => 2,
            HubError::Failed(_) => 1,
        }
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

/// Downloads every file of dataset `repo_id` at `revision` (default `main`) into the HF
/// cache and returns the snapshot directory. Files already in the cache are not fetched
/// again. When the Hub cannot be reached (or `HF_HUB_OFFLINE` is set), the snapshot
/// that the cache's `refs/<revision>` names is used instead.
pub fn fetch(repo_id: &str, revision: Option<&str>) -> Result<Snapshot, HubError> {
    let endpoint = endpoint();
    let revision = revision.unwrap_or("main");
    let what = format!("dataset {repo_id} (revision {revision}) on {endpoint}");
    if !is_repo_id(repo_id) {
        return Err(HubError::NotFound(format!(
            "'{repo_id}' is not a Hub dataset id (expected owner/name)"
        )));
    }
    let client = HFClient::builder()
        .endpoint(endpoint.clone())
        // Few, short retries: an unreachable Hub should fall back to the cache quickly.
        .retry_max_attempts(2)
        .retry_base_delay(Duration::from_millis(50))
        .build_sync()
        .map_err(|e| HubError::Failed(format!("cannot set up the Hub client for {what}: {e}")))?;
    let cache = hf_hub::resolve_cache_dir();
    let (owner, name) = split_id(repo_id);
    let repo = client.dataset(owner, name);

    let network_error = if offline_mode() {
        "HF_HUB_OFFLINE is set".to_string()
    } else {
        match repo
            .snapshot_download()
            .revision(revision.to_string())
            .send()
        {
            Ok(path) => {
                return Ok(Snapshot {
                    path,
                    from_cache_only: false,
                })
            }
            Err(e) => match classify(&e) {
                Class::NotFound => {
                    return Err(HubError::NotFound(format!("{what} was not found: {e}")))
                }
                Class::Unauthorized => {
                    return Err(HubError::Unauthorized(format!(
                        "{what} needs a token with access (set HF_TOKEN or run `huggingface-cli login`): {e}"
                    )))
                }
                Class::Unreachable => e.to_string(),
                Class::Other => return Err(HubError::Failed(format!("cannot download {what}: {e}"))),
            },
        }
    };
    match repo
        .snapshot_download()
        .revision(revision.to_string())
        .local_files_only(true)
        .send()
    {
        Ok(path) => Ok(Snapshot {
            path,
            from_cache_only: true,
        }),
        Err(_) if offline_mode() => Err(HubError::Failed(format!(
            "HF_HUB_OFFLINE is set and the Hugging Face cache {} holds no copy of {what}",
            cache.display()
        ))),
        Err(_) => Err(HubError::Failed(format!(
            "cannot reach {what} ({network_error}), and the Hugging Face cache {} holds no copy of it",
            cache.display()
        ))),
    }
}

enum Class {
    NotFound,
    Unauthorized,
    Unreachable,
    Other,
}

fn classify(e: &HFError) -> Class {
    match e {
        HFError::RepoNotFound { .. }
        | HFError::RevisionNotFound { .. }
        | HFError::EntryNotFound { .. } => Class::NotFound,
        HFError::AuthRequired { .. } | HFError::Forbidden { .. } => Class::Unauthorized,
        HFError::Request { .. } => Class::Unreachable,
        HFError::Http { context } if context.status.is_server_error() => Class::Unreachable,
        _ => Class::Other,
    }
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
            let dest = out.join(rel);
            let parent = dest.parent().expect("a file has a parent");
            std::fs::create_dir_all(parent)?;
            let tmp = parent.join(format!(
                ".{}.{}.tmp",
                dest.file_name().and_then(|n| n.to_str()).unwrap_or("file"),
                std::process::id()
            ));
            std::fs::copy(&path, &tmp)?;
            std::fs::rename(&tmp, &dest)?;
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
        assert!(is_repo_id(RELEASED_DATASET));
        assert!(is_repo_id("a/b.c_d"));
        assert!(!is_repo_id("name"));
        assert!(!is_repo_id("a/b/c"));
        assert!(!is_repo_id("./data"));
        assert!(!is_repo_id("/abs/path"));
        assert!(!is_repo_id("a/"));
        assert!(!is_repo_id("a/b c"));
    }

    #[test]
    fn exit_codes() {
        assert_eq!(HubError::NotFound(String::new()).exit_code(), 2);
        assert_eq!(HubError::Unauthorized(String::new()).exit_code(), 2);
        assert_eq!(HubError::Failed(String::new()).exit_code(), 1);
    }
}
