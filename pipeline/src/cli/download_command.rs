//! `rh-pipeline download`: a dataset from the Hub (or the cache), checked.

use super::failure::{println, Failure};
use std::path::Path;

/// `download`: the dataset from the Hub (or a complete cached copy), checked; prints
/// its path.
pub fn run(repo: &str, revision: Option<&str>, out: Option<&Path>) -> Result<(), Failure> {
    let snapshot = rh_hub::fetch(repo, revision).map_err(|e| Failure {
        code: e.exit_code(),
        message: e.to_string(),
    })?;
    if let Some(note) = snapshot.cache_note(repo) {
        rh_contract::note!("{note}");
    }
    let path = match out {
        Some(dir) => {
            let files = rh_hub::copy_snapshot(&snapshot.path, dir).map_err(|e| Failure {
                code: 1,
                message: format!("cannot copy {repo} into {}: {e}", dir.display()),
            })?;
            rh_contract::note!("copied {files} files into {}", dir.display());
            dir.to_path_buf()
        }
        None => snapshot.path,
    };
    println(&path.display().to_string())?;
    Ok(())
}
