//! The `--dataset` argument: a directory, a Hub dataset id, `$RH_DATASET` or the released
//! dataset, resolved to a local directory.

use crate::error::InputError;
use anyhow::Result;
use std::path::PathBuf;

/// Resolves `--dataset` / `$RH_DATASET` / the released dataset to a local directory: an
/// existing path is used as is; `owner/name[@revision]` is downloaded from the Hub into the
/// Hugging Face cache (or found there when the Hub is unreachable).
pub fn resolve_dataset(arg: Option<String>) -> Result<PathBuf> {
    let given = arg.or_else(|| std::env::var("RH_DATASET").ok().filter(|s| !s.is_empty()));
    let id = match given {
        Some(d) => {
            let path = PathBuf::from(&d);
            if path.exists() {
                return Ok(path);
            }
            let (repo, _) = d.split_once('@').unwrap_or((&d, ""));
            if !rh_hub::is_repo_id(repo) {
                return Err(InputError(format!(
                    "dataset directory {d} does not exist (nor is it a Hub dataset id owner/name)"
                ))
                .into());
            }
            d
        }
        None => rh_hub::RELEASED_DATASET.to_string(),
    };
    let (repo, revision) = match id.split_once('@') {
        Some((r, rev)) => (r, Some(rev)),
        None => (id.as_str(), None),
    };
    match rh_hub::fetch(repo, revision) {
        Ok(snapshot) => {
            if let Some(note) = snapshot.cache_note(repo) {
                eprintln!("rh-score: {note}");
            }
            Ok(snapshot.path)
        }
        Err(e) if e.exit_code() == 2 => Err(InputError(e.to_string()).into()),
        Err(e) => Err(anyhow::anyhow!("{e}")),
    }
}
