//! `--dataset` (and the Python package's `Dataset(...)`) as a local directory: a path, or
//! a Hugging Face Hub dataset id fetched by rh-hub (reqwest) — kept out of the grading
//! core, which reads local directories only.

use anyhow::Result;
use rh_grade::error::InputError;
use std::path::PathBuf;

/// The dataset directory of `--dataset` (also the Python package's `Dataset(...)`): an
/// existing directory, else a Hugging Face Hub dataset id `owner/name[@revision]`
/// downloaded once into the HF cache and checked (`rh_dataset::release::check_download`);
/// `None`: `$RH_DATASET`, else the project's release (`configs/hub.toml`).
pub fn resolve_dir(arg: Option<String>) -> Result<PathBuf> {
    let given = arg.or_else(|| std::env::var("RH_DATASET").ok().filter(|s| !s.is_empty()));
    let id = match given {
        Some(d) => {
            let path = PathBuf::from(&d);
            if path.exists() {
                return Ok(path);
            }
            let (repo, _) = d.split_once('@').unwrap_or((&d, ""));
            if !rh_hub::is_repo_id(repo) {
                return Err(InputError(format!(
                    "dataset directory {d} does not exist (nor is it a Hub dataset id owner/name)"
                ))
                .into());
            }
            d
        }
        None => rh_hub::released_dataset(),
    };
    let (repo, revision) = match id.split_once('@') {
        Some((r, rev)) => (r, Some(rev)),
        None => (id.as_str(), None),
    };
    match rh_hub::fetch(repo, revision) {
        Ok(snapshot) => {
            if let Some(note) = snapshot.cache_note(repo) {
                rh_contract::note!("rh-score: {note}");
            }
            // No tables (a metadata-only repository), or a copy of the release that is not
            // the release: exit 2 before anything reads it.
            let released = rh_hub::released_dataset();
            match rh_dataset::release::check_download(repo, &snapshot.path, &released) {
                Ok(Some(note)) => rh_contract::note!("rh-score: {note}"),
                Ok(None) => {}
                Err(e) => {
                    let paper = rh_grade::dataset_diagnosis::paper_scene_folders(&snapshot.path);
                    return Err(InputError(match paper {
                        0 => e.to_string(),
                        _ => format!("{e} ({paper} scene folders <family>/<family>__dN_vM/: the paper's metadata-only layout)"),
                    })
                    .into());
                }
            }
            Ok(snapshot.path)
        }
        Err(e) if e.exit_code() == 2 => Err(InputError(e.to_string()).into()),
        Err(e) => Err(anyhow::anyhow!("{e}")),
    }
}
