//! A build's per-group records (`.rh-build/groups/<g>.parquet`, with the SHA-256 of every
//! file the group wrote beside it in `<g>.sha256.json`): writing them, loading them on
//! resume (only when every file still has its recorded checksum), gathering their sums
//! for `build.json`, and turning a damaged finished build back into records so that only
//! the damaged groups are computed again.

use crate::integrity::{self, FileSums};
use crate::manifest::Manifest;
use crate::table;
use arrow::array::RecordBatch;
use rh_catalog::Catalog;
use rh_contract::fsio::{write_unsynced, Unsynced};
use rh_scenes::driver::{Rejections, SceneResult};
use rh_scenes::validate::VALIDATOR_COLUMNS;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Work-in-progress folder of an unfinished build (removed when the build completes).
pub const WORK_DIR: &str = ".rh-build";

/// Path of group `g`'s record.
pub fn record_path(out: &Path, g: u64) -> PathBuf {
    out.join(WORK_DIR)
        .join("groups")
        .join(format!("{g:08}.parquet"))
}

/// Why a group's records could not be written, gathered or restored; the message names
/// the file.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// `FILE: WHAT` (writing it, or reading back what it names).
    #[error("{}: {message}", .path.display())]
    File { path: PathBuf, message: String },
    /// A finished group without its `<g>.sha256.json`.
    #[error("{}: checksums missing", .path.display())]
    ChecksumsMissing { path: PathBuf },
}

/// The message, for callers that pass errors on as text.
impl From<RecordError> for String {
    fn from(e: RecordError) -> String {
        e.to_string()
    }
}

fn internal(path: &Path, e: impl std::fmt::Display) -> RecordError {
    RecordError::File {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Group `g`'s files, written under temporary names for the syncer to make durable in
/// this order: its specs, then the checksums of every file its rows name (specs from
/// memory; videos and frames, already in place, read back), and its record last: the
/// record's presence says the group (specs, media, sums) is done.
pub fn group_files(
    out: &Path,
    g: u64,
    results: &[SceneResult],
    rejections: &Rejections,
    catalog: &Catalog,
) -> Result<Vec<Unsynced>, RecordError> {
    let mut files = Vec::with_capacity(results.len() + 3);
    let mut spec_sums = FileSums::new();
    for r in results {
        let rel = table::spec_path(&r.spec.scene_id);
        let path = out.join(&rel);
        let json = r.spec.to_json();
        spec_sums.insert(rel, rh_contract::digest::sha256_hex(json.as_bytes()));
        files.push(write_unsynced(&path, json.as_bytes()).map_err(|e| internal(&path, e))?);
    }
    let path = record_path(out, g);
    let batch = crate::rows::record_batch(results, catalog);
    let sums = integrity::group_sums_known(out, &batch, spec_sums).map_err(|e| internal(out, e))?;
    let sums_path = integrity::group_sums_path(&path);
    let text = integrity::sums_json(&sums);
    files.push(write_unsynced(&sums_path, text.as_bytes()).map_err(|e| internal(&sums_path, e))?);
    if let Some(first) = results.first() {
        let attempts = GroupRejections::of(&first.spec.family, rejections);
        let rej_path = rejections_path(out, g);
        let text = serde_json::to_string(&attempts).expect("rejections serialize");
        files.push(write_unsynced(&rej_path, text.as_bytes()).map_err(|e| internal(&rej_path, e))?);
    }
    let bytes = table::parquet_bytes(&batch);
    files.push(write_unsynced(&path, &bytes).map_err(|e| internal(&path, e))?);
    Ok(files)
}

/// How a group's rejection-sampling attempts went, kept beside its record
/// (`<g>.rejections.json`) for the build summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupRejections {
    pub family: String,
    pub attempts: u32,
    /// Validator column → attempts it rejected.
    pub rejected_by: BTreeMap<String, u32>,
    /// Times the group was planned afresh.
    #[serde(default)]
    pub replans: u32,
}

impl GroupRejections {
    pub fn of(family: &str, r: &Rejections) -> GroupRejections {
        GroupRejections {
            family: family.to_string(),
            attempts: r.attempts,
            rejected_by: VALIDATOR_COLUMNS
                .iter()
                .zip(r.rejected_by)
                .map(|(c, n)| (c.to_string(), n))
                .collect(),
            replans: r.replans,
        }
    }
}

/// One family's attempts over a build: scene-group attempts made and, per validator
/// column, how many of them it rejected.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FamilyRejections {
    pub attempts: u32,
    pub rejected_by: BTreeMap<String, u32>,
    /// Groups planned afresh (N means N: another object or room of the family).
    pub replans: u32,
}

/// Path of group `g`'s attempt counts.
pub fn rejections_path(out: &Path, g: u64) -> PathBuf {
    out.join(WORK_DIR)
        .join("groups")
        .join(format!("{g:08}.rejections.json"))
}

/// Group `g`'s attempt counts, if written.
pub fn read_rejections(out: &Path, g: u64) -> Option<GroupRejections> {
    let text = std::fs::read_to_string(rejections_path(out, g)).ok()?;
    serde_json::from_str(&text).ok()
}

/// Every finished group's attempt counts, summed per family; None when some group's
/// are not known (a repaired finished build keeps its intact groups without them).
pub fn gather_rejections(out: &Path, groups: &[u64]) -> Option<BTreeMap<String, FamilyRejections>> {
    let mut per_family: BTreeMap<String, FamilyRejections> = BTreeMap::new();
    for &g in groups {
        let group = read_rejections(out, g)?;
        let family = per_family.entry(group.family).or_default();
        family.attempts += group.attempts;
        family.replans += group.replans;
        for (column, n) in group.rejected_by {
            *family.rejected_by.entry(column).or_default() += n;
        }
    }
    Some(per_family)
}

/// The checksums of every finished group's files, together.
pub fn gather_sums(out: &Path, groups: &[u64]) -> Result<FileSums, RecordError> {
    let mut sums = FileSums::new();
    for &g in groups {
        let path = record_path(out, g);
        let group =
            integrity::read_group_sums(&path).ok_or_else(|| RecordError::ChecksumsMissing {
                path: integrity::group_sums_path(&path),
            })?;
        sums.extend(group);
    }
    Ok(sums)
}

/// Reads group `g`'s record if it is there and whole (right rows, every file it names
/// present: specs, videos, frames).
pub fn load_record(out: &Path, manifest: &Manifest, g: u64) -> Option<RecordBatch> {
    let path = record_path(out, g);
    if !path.exists() {
        return None;
    }
    let batch = table::read_batch(&path).ok()?;
    let indices = table::u64_column(&batch, "scene_index");
    let expected: Vec<u64> = (g * 4..g * 4 + manifest.group_size(g)).collect();
    if indices != expected {
        return None;
    }
    // Every file the rows name, with the checksum recorded when the group finished.
    let sums = integrity::read_group_sums(&path)?;
    let named: Vec<String> = crate::rows::referenced_files(&batch);
    if named.len() != sums.len() || !named.iter().all(|f| sums.contains_key(f)) {
        return None;
    }
    let problems = integrity::check(out, &sums);
    if !problems.is_empty() {
        rh_contract::note!(
            "group {g}: {}; computing it again",
            integrity::describe(&problems, 3)
        );
        return None;
    }
    Some(batch)
}

/// A finished build whose files are not all what its manifest records: turns it back
/// into an unfinished one, keeping (as records) the groups whose files are intact, so
/// the run recomputes only the damaged groups. Returns the problems found (empty: the
/// build is intact and nothing was changed).
pub fn reopen_if_damaged(
    out: &Path,
    manifest: &Manifest,
) -> Result<Vec<integrity::FileProblem>, RecordError> {
    let Some(sums) = &manifest.files else {
        // A finished build of a version that recorded no checksums: nothing to compare.
        return Ok(vec![]);
    };
    let problems = integrity::check(out, sums);
    if problems.is_empty() {
        return Ok(problems);
    }
    let groups_dir = out.join(WORK_DIR).join("groups");
    std::fs::create_dir_all(&groups_dir).map_err(|e| internal(&groups_dir, e))?;
    let data_file = table::data_file_name(manifest.shard[0] as usize, manifest.shard[1] as usize);
    let data_ok = !problems.iter().any(|p| p.file == data_file);
    let rows = if data_ok {
        table::read_batch(&out.join(&data_file)).ok()
    } else {
        None
    };
    if let Some(rows) = rows {
        let bad: std::collections::BTreeSet<&str> =
            problems.iter().map(|p| p.file.as_str()).collect();
        let index = table::u64_column(&rows, "scene_index");
        for g in manifest.groups() {
            let picks: Vec<u32> = (0..rows.num_rows() as u32)
                .filter(|&i| index[i as usize] / 4 == g)
                .collect();
            let batch = table::take_rows(&rows, &picks);
            let files = crate::rows::referenced_files(&batch);
            if picks.is_empty()
                || files
                    .iter()
                    .any(|f| bad.contains(f.as_str()) || !sums.contains_key(f))
            {
                continue;
            }
            let group_sums: FileSums = files.iter().map(|f| (f.clone(), sums[f].clone())).collect();
            let record = record_path(out, g);
            integrity::write_group_sums(&record, &group_sums).map_err(|e| internal(&record, e))?;
            table::write_atomic(&record, &table::parquet_bytes(&batch))
                .map_err(|e| internal(&record, e))?;
        }
    }
    Ok(problems)
}
