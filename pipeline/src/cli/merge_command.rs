//! `rh-pipeline merge`: shard outputs combined into one dataset.

use super::failure::{build_failure, print_json, println, Failure};
use std::path::{Path, PathBuf};

/// Merges `shards` into `out` and prints the summary.
pub fn run(out: &Path, shards: &[PathBuf], json: bool) -> Result<(), Failure> {
    let summary = rh_dataset::merge::merge(out, shards).map_err(build_failure)?;
    if json {
        print_json(&summary)?;
    } else {
        println(&format!(
            "merged {} shards: {} scenes ({} valid) into {} — {}",
            summary.shards, summary.scenes, summary.valid, summary.out, summary.data_file
        ))?;
    }
    Ok(())
}
