//! `rh-pipeline verify`: the dataset checked end to end (or `--fast`), and the report.

use super::failure::{input, print_json, println, Failure};
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
    let adapter = adapter_lines(dir);
    if json {
        // The report on stdout stays one JSON object; the adapter lines go to stderr.
        for line in &adapter {
            rh_contract::note!("{line}");
        }
        print_json(&report)?;
    } else {
        for line in &adapter {
            println(line)?;
        }
        for p in &report.file_problems {
            println(&format!("FILE {}: {}", p.file, p.problem))?;
        }
        for m in &report.mismatches {
            println(&format!("MISMATCH {}: {}", m.scene_id, m.problem))?;
        }
        if report.mode == "full" {
            println(&format!(
                "verified {} files against build.json: {} problem(s); {} scenes derived again: {} match, {} differ",
                report.files_checked,
                report.file_problems.len(),
                report.scenes,
                report.matched,
                report.scenes - report.matched
            ))?;
        } else {
            println(&format!(
                "verified {} scenes: {} match, {} mismatch",
                report.scenes,
                report.matched,
                report.mismatches.len()
            ))?;
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

/// The adapter the build recorded and this machine's, and whether they differ (frames
/// rendered here would then not be the same model inputs).
fn adapter_lines(dir: &Path) -> Vec<String> {
    let recorded = match rh_dataset::manifest::Manifest::read(dir) {
        Ok(Some(m)) => m.render_adapter,
        _ => return Vec::new(),
    };
    let Some(recorded) = recorded else {
        return vec!["render adapter: none recorded (a label-only build, or an older one)".into()];
    };
    let mut lines = vec![format!(
        "render adapter (recorded): {}",
        recorded.describe()
    )];
    #[cfg(feature = "render")]
    match rh_render::probe_adapter() {
        Ok(here) if here == recorded => {
            lines.push(format!("render adapter (this machine): {} (the same)", here.describe()))
        }
        Ok(here) => lines.push(format!(
            "render adapter (this machine): {} (DIFFERS: frames rendered here may not be the same model inputs)",
            here.describe()
        )),
        Err(e) => lines.push(format!("render adapter (this machine): none ({e})")),
    }
    lines
}
