//! `rh-pipeline merge OUT SHARD_DIR...`: combines the outputs of `build --shard i/N`
//! (i = 0 … N−1) into one dataset equal, byte for byte, to the unsharded build: the same
//! `build.json`, `data/test-00000-of-00001.parquet`, `eval/`, `README.md` and specs.
//!
//! The shards must be finished builds of the same manifest (seed, n, families,
//! configuration, catalog, render flag) and cover every group exactly once; anything else
//! is a usage error naming the directory and the problem. The merged dataset is written
//! into a hidden sibling folder and renamed onto OUT at the end, so OUT appears whole or
//! not at all.

use crate::finalize::{finalize, BuildError, RowSink};
use crate::integrity::{self, FileSums};
use crate::manifest::{Manifest, MANIFEST_FILE};
use crate::records::WORK_DIR;
use crate::{stream, table};
use arrow::array::RecordBatch;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Serialize)]
pub struct MergeSummary {
    pub out: String,
    pub shards: usize,
    pub scenes: usize,
    pub valid: usize,
    pub data_file: String,
    pub eval_scenes: Option<usize>,
}

fn input(msg: String) -> BuildError {
    BuildError::Input(msg)
}

/// The columns a shard's checks and file copies read (`rows::referenced_files`: specs,
/// videos, and the mask/depth path lists); the full rows are streamed from the shard
/// files by `finalize` instead of held in memory.
fn file_columns() -> Vec<String> {
    [
        "scene_id",
        "scene_index",
        "spec_file",
        "ego_file_name",
        "closeup_file_name",
        "overhead_file_name",
        "full_event_file_name",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain(crate::media_columns::path_columns())
    .collect()
}

/// Reads and checks one shard directory; returns its manifest and its rows' scene ids,
/// indices and file columns.
fn read_shard(dir: &Path) -> Result<(Manifest, arrow::array::RecordBatch), BuildError> {
    let manifest = Manifest::read(dir)
        .map_err(|e| input(e.into()))?
        .ok_or_else(|| {
            input(format!(
                "{}: no {MANIFEST_FILE}; not a directory written by `rh-pipeline build`",
                dir.display()
            ))
        })?;
    let data = dir.join(table::data_file_name(
        manifest.shard[0] as usize,
        manifest.shard[1] as usize,
    ));
    if dir.join(WORK_DIR).exists() || !data.exists() {
        return Err(input(format!(
            "{}: shard {}/{} is unfinished; run its build command again to finish it",
            dir.display(),
            manifest.shard[0],
            manifest.shard[1]
        )));
    }
    let columns = file_columns();
    let names: Vec<&str> = columns.iter().map(String::as_str).collect();
    let rows = stream::read_columns(&data, &names).map_err(|e| input(e.into()))?;
    let indices = table::u64_column(&rows, "scene_index");
    let expected: Vec<u64> = manifest
        .groups()
        .iter()
        .flat_map(|&g| g * 4..g * 4 + manifest.group_size(g))
        .collect();
    if indices != expected {
        return Err(input(format!(
            "{}: {} does not hold exactly the scenes of shard {}/{} ({} rows, expected {})",
            dir.display(),
            data.display(),
            manifest.shard[0],
            manifest.shard[1],
            indices.len(),
            expected.len()
        )));
    }
    // Checksums first: every file the shard wrote must be what its manifest records.
    let Some(sums) = &manifest.files else {
        return Err(input(format!(
            "{}: its {MANIFEST_FILE} records no file checksums (unfinished, or built by an older rh-pipeline); run its build command again",
            dir.display()
        )));
    };
    let problems = integrity::check(dir, sums);
    if !problems.is_empty() {
        return Err(input(format!(
            "{}: {} file(s) are not what its {MANIFEST_FILE} records: {}; run its build command again to repair the shard",
            dir.display(),
            problems.len(),
            integrity::describe(&problems, 5)
        )));
    }
    for file in crate::rows::referenced_files(&rows) {
        if !sums.contains_key(&file) {
            return Err(input(format!(
                "{}: {file} is named by a row but has no recorded checksum",
                dir.display()
            )));
        }
    }
    Ok((manifest, rows))
}

/// Merges `shards` into `out`.
pub fn merge(out: &Path, shards: &[PathBuf]) -> Result<MergeSummary, BuildError> {
    if shards.is_empty() {
        return Err(input("merge needs at least one SHARD_DIR".into()));
    }
    let mut read = Vec::new();
    for dir in shards {
        if !dir.is_dir() {
            return Err(input(format!("{}: no such directory", dir.display())));
        }
        read.push((dir.clone(), read_shard(dir)?));
    }
    let (first_dir, (first, _)) = &read[0];
    let whole = first.whole();
    let n_shards = first.shard[1];
    let mut by_index: BTreeMap<u64, &Path> = BTreeMap::new();
    // One set of model inputs: every shard drawn on the same adapter (label-only shards
    // record none and merge freely).
    for (dir, (m, _)) in &read {
        if let Some(a) = first.adapter_difference(m) {
            return Err(input(format!(
                "{} and {} were rendered on different adapters ({a}): their frames may differ, \
                 so the merged dataset would not be one set of model inputs; render every shard \
                 on the same adapter",
                first_dir.display(),
                dir.display(),
            )));
        }
    }
    for (dir, (m, _)) in &read {
        let diff = whole.differences(&m.whole());
        if !diff.is_empty() {
            return Err(input(format!(
                "{} and {} are shards of different builds ({})",
                first_dir.display(),
                dir.display(),
                diff.join("; ")
            )));
        }
        if m.shard[1] != n_shards {
            return Err(input(format!(
                "{} is shard {}/{} but {} is shard {}/{}: all shards must split the build the same way",
                dir.display(),
                m.shard[0],
                m.shard[1],
                first_dir.display(),
                first.shard[0],
                first.shard[1]
            )));
        }
        if let Some(other) = by_index.insert(m.shard[0], dir.as_path()) {
            return Err(input(format!(
                "shard {}/{n_shards} is given twice: {} and {}",
                m.shard[0],
                other.display(),
                dir.display()
            )));
        }
    }
    let missing: Vec<String> = (0..n_shards)
        .filter(|i| !by_index.contains_key(i))
        .map(|i| format!("{i}/{n_shards}"))
        .collect();
    if !missing.is_empty() {
        return Err(input(format!(
            "the shards do not cover the build: missing shard(s) {}",
            missing.join(", ")
        )));
    }

    // OUT must be new or an empty directory.
    if out.exists() {
        let empty = std::fs::read_dir(out)
            .map(|mut d| d.next().is_none())
            .unwrap_or(false);
        if !empty {
            return Err(input(format!(
                "{} already exists and is not empty; merge writes a new directory",
                out.display()
            )));
        }
    }
    let out_name = out
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| input(format!("{}: not a usable output path", out.display())))?;
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&parent)
        .map_err(|e| input(format!("cannot create {}: {e}", parent.display())))?;
    remove_stale_staging(&parent, out_name);
    let staging = parent.join(format!(".{out_name}.rh-merge.{}", std::process::id()));
    let result = write_merged(&staging, &whole, &read);
    if let Err(e) = result {
        let _ = std::fs::remove_dir_all(&staging);
        return Err(e);
    }
    if out.exists() {
        std::fs::remove_dir(out)
            .map_err(|e| BuildError::Internal(format!("{}: {e}", out.display())))?;
    }
    std::fs::rename(&staging, out).map_err(|e| {
        let _ = std::fs::remove_dir_all(&staging);
        BuildError::Internal(format!(
            "cannot move the merged dataset to {}: {e}",
            out.display()
        ))
    })?;
    let rows = stream::read_columns(
        &out.join(table::data_file_name(0, 1)),
        &stream::SUMMARY_COLUMNS,
    )
    .map_err(|e| BuildError::Internal(e.into()))?;
    Ok(MergeSummary {
        out: out.display().to_string(),
        shards: read.len(),
        scenes: rows.num_rows(),
        valid: table::bool_column(&rows, "valid")
            .iter()
            .filter(|v| **v)
            .count(),
        data_file: table::data_file_name(0, 1),
        eval_scenes: out
            .join(crate::card::EVAL_FILE)
            .exists()
            .then(|| crate::card::manifest_eval_selection(&rows, &whole).0.len()),
    })
}

type Shard = (PathBuf, (Manifest, arrow::array::RecordBatch));

fn write_merged(staging: &Path, whole: &Manifest, shards: &[Shard]) -> Result<(), BuildError> {
    let internal =
        |p: &Path, e: std::io::Error| BuildError::Internal(format!("{}: {e}", p.display()));
    std::fs::create_dir_all(staging.join("specs")).map_err(|e| internal(staging, e))?;
    table::write_atomic(&staging.join(MANIFEST_FILE), whole.to_json().as_bytes())
        .map_err(|e| internal(staging, e))?;
    let mut sums = FileSums::new();
    for (dir, (manifest, rows)) in shards {
        // Specs, videos and frames: every file a row names, with its checked checksum.
        let shard_sums = manifest.files.as_ref().expect("checked by read_shard");
        for file in crate::rows::referenced_files(rows) {
            sums.insert(file.clone(), shard_sums[&file].clone());
            let (from, to) = (dir.join(&file), staging.join(&file));
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent).map_err(|e| internal(parent, e))?;
            }
            std::fs::copy(&from, &to).map_err(|e| internal(&from, e))?;
        }
    }
    // Shard i holds the groups g = i, i + N, … in order: the merged table takes group g's
    // rows from shard g mod N, streaming every shard's file once per pass.
    let mut files: Vec<PathBuf> = vec![PathBuf::new(); shards.len()];
    for (dir, (m, _)) in shards {
        files[m.shard[0] as usize] = dir.join(table::data_file_name(
            m.shard[0] as usize,
            m.shard[1] as usize,
        ));
    }
    let rows = |sink: &mut RowSink| -> Result<(), BuildError> {
        let mut cursors: Vec<ShardCursor> = files
            .iter()
            .map(|f| ShardCursor::open(f))
            .collect::<Result<_, _>>()?;
        let n_shards = cursors.len() as u64;
        for g in whole.groups() {
            sink(cursors[(g % n_shards) as usize].take(whole.group_size(g) as usize)?)?;
        }
        Ok(())
    };
    finalize(staging, whole, &rows, sums)?;
    Ok(())
}

/// Reads a shard's data file front to back, a few rows at a time.
struct ShardCursor {
    path: PathBuf,
    reader: parquet::arrow::arrow_reader::ParquetRecordBatchReader,
    /// Rows read but not yet taken.
    buffer: Option<RecordBatch>,
}

impl ShardCursor {
    fn open(path: &Path) -> Result<ShardCursor, BuildError> {
        // Every column, in small batches: a rendered shard's rows carry ~1 MB of frame
        // images each.
        let batch = crate::frames::IMAGE_ROW_GROUP_SIZE * 4;
        let reader =
            crate::read::open_columns(path, batch, |_| true).map_err(|e| input(e.into()))?;
        Ok(ShardCursor {
            path: path.to_path_buf(),
            reader,
            buffer: None,
        })
    }

    /// The next `k` rows.
    fn take(&mut self, k: usize) -> Result<RecordBatch, BuildError> {
        let mut parts = Vec::new();
        let mut need = k;
        while need > 0 {
            let batch = match self.buffer.take() {
                Some(b) => b,
                None => match self.reader.next() {
                    Some(b) => b.map_err(|e| input(format!("{}: {e}", self.path.display())))?,
                    None => {
                        return Err(input(format!(
                            "{}: ended before its last scene group",
                            self.path.display()
                        )))
                    }
                },
            };
            let used = need.min(batch.num_rows());
            parts.push(batch.slice(0, used));
            if used < batch.num_rows() {
                self.buffer = Some(batch.slice(used, batch.num_rows() - used));
            }
            need -= used;
        }
        table::concat(&parts).map_err(|e| input(format!("{}: {e}", self.path.display())))
    }
}

/// Removes staging folders (`.OUT.rh-merge.PID`) that a killed merge into the same OUT
/// left behind; a folder whose process still runs is left alone.
fn remove_stale_staging(parent: &Path, out_name: &str) {
    let prefix = format!(".{out_name}.rh-merge.");
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = name
            .strip_prefix(&prefix)
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        let alive = pid != std::process::id() && Path::new(&format!("/proc/{pid}")).exists();
        if !alive {
            rh_contract::note!(
                "removing {} (left by a merge that was stopped)",
                e.path().display()
            );
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}
