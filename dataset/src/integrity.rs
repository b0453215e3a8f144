//! File checksums of a dataset: the SHA-256 of every file a build writes (specs, videos,
//! frames, Parquet, card). Each finished group records its own files' sums next to its
//! record (`.rh-build/groups/<g>.sha256.json`); `finalize` gathers them, adds the files it
//! writes itself, and stores the lot in `build.json` (`files`). A resumed build, a rerun
//! of a finished build, `merge` and `verify` check files against these sums.

use crate::table;
use arrow::array::RecordBatch;
use rayon::prelude::*;
use rh_contract::digest::sha256_file;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Relative path → SHA-256 (hex), in path order.
pub type FileSums = BTreeMap<String, String>;

/// The sums of `files` (relative to `root`), hashed in parallel.
pub fn sums_of(root: &Path, files: &[String]) -> std::io::Result<FileSums> {
    files
        .par_iter()
        .map(|f| Ok((f.clone(), sha256_file(&root.join(f))?)))
        .collect()
}

/// The sums of every file the rows of `batch` refer to (specs, videos, frames).
pub fn group_sums(root: &Path, batch: &RecordBatch) -> std::io::Result<FileSums> {
    sums_of(root, &crate::rows::referenced_files(batch))
}

/// As `group_sums`, but files whose sums are already `known` (written from memory and
/// perhaps not yet renamed into place) are taken from there instead of read back.
pub fn group_sums_known(
    root: &Path,
    batch: &RecordBatch,
    known: FileSums,
) -> std::io::Result<FileSums> {
    let rest: Vec<String> = crate::rows::referenced_files(batch)
        .into_iter()
        .filter(|f| !known.contains_key(f))
        .collect();
    let mut sums = sums_of(root, &rest)?;
    sums.extend(known);
    Ok(sums)
}

/// A file that is not what the sums say.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FileProblem {
    pub file: String,
    /// "missing", or "altered (sha256 … , recorded …)".
    pub problem: String,
}

/// Checks each file of `sums` under `root`: present, and with that SHA-256.
pub fn check(root: &Path, sums: &FileSums) -> Vec<FileProblem> {
    let entries: Vec<(&String, &String)> = sums.iter().collect();
    let mut problems: Vec<FileProblem> = entries
        .par_iter()
        .filter_map(|(file, want)| {
            let problem = match sha256_file(&root.join(file)) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => "missing".to_string(),
                Err(e) => format!("unreadable: {e}"),
                Ok(got) if got == **want => return None,
                Ok(got) => format!("altered (sha256 {got}, recorded {want})"),
            };
            Some(FileProblem {
                file: (*file).clone(),
                problem,
            })
        })
        .collect();
    problems.sort_by(|a, b| a.file.cmp(&b.file));
    problems
}

/// One line per problem, at most `max`, then a count of the rest.
pub fn describe(problems: &[FileProblem], max: usize) -> String {
    let mut lines: Vec<String> = problems
        .iter()
        .take(max)
        .map(|p| format!("{}: {}", p.file, p.problem))
        .collect();
    if problems.len() > max {
        lines.push(format!("… and {} more", problems.len() - max));
    }
    lines.join("; ")
}

/// Path of group `g`'s sums, beside its record.
pub fn group_sums_path(record: &Path) -> PathBuf {
    record.with_extension("sha256.json")
}

/// The text of a group's sums file.
pub fn sums_json(sums: &FileSums) -> String {
    serde_json::to_string_pretty(sums).expect("sums serialize") + "\n"
}

pub fn write_group_sums(record: &Path, sums: &FileSums) -> std::io::Result<()> {
    table::write_atomic(&group_sums_path(record), sums_json(sums).as_bytes())
}

pub fn read_group_sums(record: &Path) -> Option<FileSums> {
    let text = std::fs::read_to_string(group_sums_path(record)).ok()?;
    serde_json::from_str(&text).ok()
}

/// Dataset files under `root` that the sums do not name (the manifest itself aside):
/// someone added them after the build.
pub fn unlisted(root: &Path, sums: &FileSums) -> Vec<String> {
    let mut extra = Vec::new();
    for top in [
        "data", "eval", "specs", "videos", "frames", "masks", "depth",
    ] {
        let mut stack = vec![root.join(top)];
        while let Some(dir) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for e in entries.flatten() {
                let path = e.path();
                if path.is_dir() {
                    stack.push(path);
                } else if let Ok(rel) = path.strip_prefix(root) {
                    let rel = rel.to_string_lossy().replace('\\', "/");
                    if !sums.contains_key(&rel) {
                        extra.push(rel);
                    }
                }
            }
        }
    }
    extra.sort();
    extra
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_find_missing_and_altered_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("specs")).unwrap();
        std::fs::write(dir.path().join("specs/a.json"), b"{}").unwrap();
        std::fs::write(dir.path().join("specs/b.json"), b"[]").unwrap();
        let files = vec!["specs/a.json".to_string(), "specs/b.json".to_string()];
        let sums = sums_of(dir.path(), &files).unwrap();
        assert!(check(dir.path(), &sums).is_empty());
        std::fs::write(dir.path().join("specs/a.json"), b"{ }").unwrap();
        std::fs::remove_file(dir.path().join("specs/b.json")).unwrap();
        std::fs::write(dir.path().join("specs/c.json"), b"1").unwrap();
        let problems = check(dir.path(), &sums);
        assert_eq!(problems.len(), 2);
        assert!(problems[0].problem.starts_with("altered"));
        assert_eq!(problems[1].problem, "missing");
        assert_eq!(
            unlisted(dir.path(), &sums),
            vec!["specs/c.json".to_string()]
        );
    }
}
