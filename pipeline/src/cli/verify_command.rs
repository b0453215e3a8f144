//! `rh-pipeline verify`: the dataset checked end to end (or `--fast`), and the report.

use super::failure::{input, print_json, Failure};
use rh_catalog::Catalog;
use rh_dataset::verify::{verify, verify_fast};
use std::path::Path;

/// `rh-pipeline verify`: replays every spec against its stored state hash.
pub fn run(dir: &Path, catalog: &Catalog, fast: bool, json: bool) -> Result<(), Failure> {
    let report = if fast {
        verify_fast(dir)
    } else {
        verify(dir, catalog)
    }
    .map_err(input)?;
    if json {
        print_json(&report);
    } else {
        for p in &report.file_problems {
            println!("FILE {}: {}", p.file, p.problem);
        }
        for m in &report.mismatches {
            println!("MISMATCH {}: {}", m.scene_id, m.problem);
        }
        if report.mode == "full" {
            println!(
                "verified {} files against build.json: {} problem(s); {} scenes derived again: {} match, {} differ",
                report.files_checked,
                report.file_problems.len(),
                report.scenes,
                report.matched,
                report.scenes - report.matched
            );
        } else {
            println!(
                "verified {} scenes: {} match, {} mismatch",
                report.scenes,
                report.matched,
                report.mismatches.len()
            );
        }
    }
    if report.ok() {
        Ok(())
    } else if report.mode == "full" {
        Err(input(format!(
            "{}: {} file problem(s), {} scene(s) differ from what their build derives",
            dir.display(),
            report.file_problems.len(),
            report.scenes - report.matched
        )))
    } else {
        Err(input(format!(
            "{} scene(s) did not replay to their stored state hash",
            report.mismatches.len()
        )))
    }
}
