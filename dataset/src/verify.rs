//! `rh-pipeline verify DIR`: proves a dataset is what its build wrote.
//!
//! Full check (the default):
//! 1. every file `build.json` records (Parquet, specs, videos, frames, card) is there with
//!    its SHA-256, and no dataset file is there that it does not record;
//! 2. every scene group is derived again from (selection, seed, configuration) — the
//!    manifest's configuration and the catalog — and each spec must equal the stored
//!    `specs/<id>.json` byte for byte (a label threshold or `selection.object_id` edited
//!    in a spec is caught even when the physics is unchanged);
//! 3. every column of every row (labels, validators, state hash, trajectory …) is
//!    re-derived from the replay and compared with the Parquet row.
//!
//! `--fast` keeps the replay-only check: each stored spec is simulated and its per-step
//! state hash compared with the stored one.

use crate::integrity::{self, FileProblem};
use crate::manifest::{catalog_sha256, Manifest, MANIFEST_FILE};
use crate::table;
use arrow::array::{Array, RecordBatch};
use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_physics::simulate::{simulate, SimOptions};
use rh_physics::spec::SceneSpec;
use rh_scenes::driver::{plan_and_produce, SceneResult};
use serde::Serialize;
use std::path::Path;

/// Why a dataset cannot be checked at all (its problems are in the [`VerifyReport`]).
#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    #[error(transparent)]
    Table(#[from] table::TableError),
    #[error(transparent)]
    Manifest(#[from] crate::manifest::ManifestError),
    #[error("{}: no {MANIFEST_FILE}; not a dataset written by `rh-pipeline build` (`verify --fast` replays specs without it)", .dir.display())]
    NoManifest { dir: std::path::PathBuf },
    #[error("{} was built from another catalog than the one loaded; pass the same --catalog DIR as the build", .dir.display())]
    OtherCatalog { dir: std::path::PathBuf },
    /// A scene group could not be derived again (`driver::plan_and_produce`'s message).
    #[error("{0}")]
    Derive(String),
}

/// The message, for callers that pass errors on as text.
impl From<VerifyError> for String {
    fn from(e: VerifyError) -> String {
        e.to_string()
    }
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Mismatch {
    pub scene_id: String,
    pub problem: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct VerifyReport {
    /// "full" or "fast".
    pub mode: String,
    pub scenes: usize,
    pub matched: usize,
    pub mismatches: Vec<Mismatch>,
    /// Files checked against their recorded SHA-256 (full mode).
    pub files_checked: usize,
    /// Files missing, altered, or not recorded (full mode).
    pub file_problems: Vec<FileProblem>,
}

impl VerifyReport {
    pub fn ok(&self) -> bool {
        self.mismatches.is_empty() && self.file_problems.is_empty()
    }
}

/// The replay-only check (`verify --fast`). Err only when the dataset itself cannot be read.
pub fn verify_fast(dir: &Path) -> Result<VerifyReport, VerifyError> {
    let rows = table::read_hashes(dir)?;
    let mut mismatches: Vec<Mismatch> = rows
        .par_iter()
        .filter_map(|(scene_id, spec_file, stored)| {
            let path = dir.join(spec_file);
            let problem = match std::fs::read_to_string(&path) {
                Err(e) => Some(format!("cannot read {}: {e}", path.display())),
                Ok(text) => match SceneSpec::from_json(&text) {
                    Err(e) => Some(format!("{}: invalid spec: {e}", path.display())),
                    Ok(spec) if &spec.scene_id != scene_id => Some(format!(
                        "{} holds scene '{}'",
                        path.display(),
                        spec.scene_id
                    )),
                    Ok(spec) => {
                        let replayed = simulate(&spec, SimOptions::default()).state_hash;
                        (replayed != *stored)
                            .then(|| format!("state hash {replayed} differs from stored {stored}"))
                    }
                },
            };
            problem.map(|problem| Mismatch {
                scene_id: scene_id.clone(),
                problem,
            })
        })
        .collect();
    mismatches.sort_by(|a, b| a.scene_id.cmp(&b.scene_id));
    Ok(VerifyReport {
        mode: "fast".into(),
        scenes: rows.len(),
        matched: rows.len() - mismatches.len(),
        mismatches,
        files_checked: 0,
        file_problems: vec![],
    })
}

/// The full check. Err when the dataset cannot be checked at all (no manifest, another
/// catalog than the one it was built from).
pub fn verify(dir: &Path, catalog: &Catalog) -> Result<VerifyReport, VerifyError> {
    let manifest = Manifest::read(dir)?.ok_or_else(|| VerifyError::NoManifest {
        dir: dir.to_path_buf(),
    })?;
    if catalog_sha256(catalog) != manifest.catalog_sha256 {
        return Err(VerifyError::OtherCatalog {
            dir: dir.to_path_buf(),
        });
    }
    let config = manifest.build_config()?;

    // 1. Files against their checksums.
    let (files_checked, mut file_problems) = match &manifest.files {
        Some(sums) => {
            let mut problems = integrity::check(dir, sums);
            problems.extend(integrity::unlisted(dir, sums).into_iter().map(|file| FileProblem {
                file,
                problem: format!("not recorded in {MANIFEST_FILE} (added after the build)"),
            }));
            (sums.len(), problems)
        }
        None => (
            0,
            vec![FileProblem {
                file: MANIFEST_FILE.into(),
                problem: "records no file checksums (an unfinished build, or one of an older rh-pipeline)".into(),
            }],
        ),
    };
    file_problems.sort_by(|a, b| a.file.cmp(&b.file));

    // 2–3. Specs and rows against the scenes derived again.
    let data_file = table::data_file_name(manifest.shard[0] as usize, manifest.shard[1] as usize);
    let rows = table::read_batch(&dir.join(&data_file));
    if let Err(e) = &rows {
        if !file_problems.iter().any(|p| p.file == data_file) {
            file_problems.push(FileProblem {
                file: data_file.clone(),
                problem: format!("unreadable: {e}"),
            });
        }
    }
    let rows = rows.ok();
    let index = rows.as_ref().map(|r| table::u64_column(r, "scene_index"));
    let groups = manifest.groups();
    let per_group: Vec<Result<(usize, Vec<Mismatch>), VerifyError>> = groups
        .par_iter()
        .map(|&g| {
            // As a build (`driver::plan_and_produce`): a build from descriptions stored
            // its planned selections; else the lexicon plans (and replans) the group.
            let (mut results, _) = plan_and_produce(
                catalog,
                &manifest.families,
                manifest.selections.as_deref(),
                manifest.seed,
                g,
                manifest.group_size(g),
                &config,
            )
            .map_err(VerifyError::Derive)?;
            let stored = match (&rows, &index) {
                (Some(rows), Some(index)) => {
                    let picks: Vec<u32> = (0..rows.num_rows() as u32)
                        .filter(|&i| index[i as usize] / 4 == g)
                        .collect();
                    Some(table::take_rows(rows, &picks))
                }
                _ => None,
            };
            Ok((
                results.len(),
                check_group(dir, &mut results, stored.as_ref(), catalog),
            ))
        })
        .collect();
    let mut scenes = 0;
    let mut mismatches = Vec::new();
    for r in per_group {
        let (n, m) = r?;
        scenes += n;
        mismatches.extend(m);
    }
    mismatches.sort_by(|a, b| a.scene_id.cmp(&b.scene_id));
    let bad_scenes: std::collections::BTreeSet<&str> =
        mismatches.iter().map(|m| m.scene_id.as_str()).collect();
    Ok(VerifyReport {
        mode: "full".into(),
        scenes,
        matched: scenes - bad_scenes.len(),
        mismatches,
        files_checked,
        file_problems,
    })
}

/// Compares one group's derived scenes with the stored specs and rows.
fn check_group(
    dir: &Path,
    results: &mut [SceneResult],
    stored: Option<&RecordBatch>,
    catalog: &Catalog,
) -> Vec<Mismatch> {
    let mut out = Vec::new();
    for r in results.iter() {
        let id = r.spec.scene_id.clone();
        let path = dir.join(table::spec_path(&id));
        let derived = r.spec.to_json();
        match std::fs::read_to_string(&path) {
            Err(e) => out.push(Mismatch {
                scene_id: id,
                problem: format!("cannot read {}: {e}", path.display()),
            }),
            Ok(text) if text != derived => {
                let at = json_difference(&text, &derived);
                out.push(Mismatch {
                    scene_id: id,
                    problem: format!(
                        "{} differs from the spec derived again from its selection, seed and configuration{at}",
                        table::spec_path(&r.spec.scene_id)
                    ),
                });
            }
            Ok(_) => {}
        }
    }
    let Some(stored) = stored else {
        return out;
    };
    let ids = table::string_column(stored, "scene_id");
    if ids.len() != results.len()
        || ids
            .iter()
            .zip(results.iter())
            .any(|(a, r)| *a != r.spec.scene_id)
    {
        out.push(Mismatch {
            scene_id: results
                .first()
                .map(|r| r.spec.scene_id.clone())
                .unwrap_or_default(),
            problem: format!(
                "the data rows of this group name scenes {ids:?}, not the ones the build derives"
            ),
        });
        return out;
    }
    // Media file names are not derived (rendering is not redone): take them from the
    // row; the files themselves are covered by their checksums.
    // So are the renderer's measurements (visible pixels) and the mask/depth files.
    for (row, r) in results.iter_mut().enumerate() {
        r.media = crate::media_columns::media_of_row(stored, row);
    }
    let derived = crate::rows::record_batch(results, catalog);
    for (i, field) in derived.schema().fields().iter().enumerate() {
        let (a, b) = (stored.column(i), derived.column(i));
        if a.as_ref() == b.as_ref() {
            continue;
        }
        for row in 0..a.len().min(b.len()) {
            if a.slice(row, 1).as_ref() != b.slice(row, 1).as_ref() {
                out.push(Mismatch {
                    scene_id: ids[row].clone(),
                    problem: format!(
                        "column {}: stored {}, derived from the replay {}",
                        field.name(),
                        value_text(a.as_ref(), row),
                        value_text(b.as_ref(), row)
                    ),
                });
            }
        }
    }
    out
}

fn value_text(a: &dyn Array, row: usize) -> String {
    let text = arrow::util::display::array_value_to_string(a, row)
        .unwrap_or_else(|_| "(unprintable)".into());
    if text.chars().count() > 120 {
        format!("{}…", text.chars().take(120).collect::<String>())
    } else {
        text
    }
}

/// Where two JSON texts first differ, as " (first difference at `a.b[2]`: x vs y)".
fn json_difference(stored: &str, derived: &str) -> String {
    let (Ok(a), Ok(b)) = (
        serde_json::from_str::<serde_json::Value>(stored),
        serde_json::from_str::<serde_json::Value>(derived),
    ) else {
        return " (it is not valid JSON)".into();
    };
    fn walk(a: &serde_json::Value, b: &serde_json::Value, path: String) -> Option<String> {
        use serde_json::Value::*;
        match (a, b) {
            (Object(x), Object(y)) => {
                for (k, v) in y {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    match x.get(k) {
                        Some(w) => {
                            if let Some(d) = walk(w, v, p) {
                                return Some(d);
                            }
                        }
                        None => return Some(format!("`{p}` missing")),
                    }
                }
                x.keys()
                    .find(|k| !y.contains_key(*k))
                    .map(|k| format!("`{path}.{k}` not expected"))
            }
            (Array(x), Array(y)) if x.len() == y.len() => x
                .iter()
                .zip(y)
                .enumerate()
                .find_map(|(i, (v, w))| walk(v, w, format!("{path}[{i}]"))),
            _ if a == b => None,
            _ => {
                let short = |v: &serde_json::Value| {
                    let s = v.to_string();
                    if s.len() > 60 {
                        format!("{}…", &s[..60])
                    } else {
                        s
                    }
                };
                Some(format!(
                    "`{path}`: stored {}, derived {}",
                    short(a),
                    short(b)
                ))
            }
        }
    }
    match walk(&a, &b, String::new()) {
        Some(d) => format!(" (first difference at {d})"),
        None => " (same values, different formatting)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_differences_name_the_field() {
        let a =
            r#"{"selection": {"object_id": "mug", "room": "k"}, "labels": {"reach_radius": 1.2}}"#;
        let b = r#"{"selection": {"object_id": "knife", "room": "k"}, "labels": {"reach_radius": 1.2}}"#;
        assert_eq!(
            json_difference(a, b),
            " (first difference at `selection.object_id`: stored \"mug\", derived \"knife\")"
        );
        assert_eq!(json_difference("{", b), " (it is not valid JSON)");
    }
}
