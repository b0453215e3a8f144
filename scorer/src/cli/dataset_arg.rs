//! The `--dataset` argument: a directory, a Hub dataset id, `$RH_DATASET` or the released
//! dataset, resolved to a local directory (`rh_locate::resolve_dir`, which the Python
//! package's `Dataset(...)` uses too); an unfinished build is refused unless
//! `--allow-incomplete` ([`crate::dataset::check_finished`]).

use anyhow::Result;
use std::path::PathBuf;

/// Resolves `--dataset` / `$RH_DATASET` / the released dataset to a local directory
/// holding a finished build (or, with `allow_incomplete`, any build: said on stderr).
pub fn resolve_dataset(arg: Option<String>, allow_incomplete: bool) -> Result<PathBuf> {
    let dir = rh_locate::resolve_dir(arg)?;
    rh_grade::dataset::check_finished(&dir, allow_incomplete)?;
    Ok(dir)
}
