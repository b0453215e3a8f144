//! The `--dataset` argument: a directory, a Hub dataset id, `$RH_DATASET` or the released
//! dataset, resolved to a local directory (`crate::dataset::resolve_dir`, which the Python
//! package's `Dataset(...)` uses too).

use anyhow::Result;
use std::path::PathBuf;

/// Resolves `--dataset` / `$RH_DATASET` / the released dataset to a local directory.
pub fn resolve_dataset(arg: Option<String>) -> Result<PathBuf> {
    crate::dataset::resolve_dir(arg)
}
