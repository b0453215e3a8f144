//! The benchmark's canonical release (specification §8, "The release"): its definition
//! (`configs/release.toml`: id, seed, scene count, render flags, the pins its build must
//! run under and the fingerprint the result must have), the fingerprint of a dataset, and
//! the checks `rh-score` runs on a dataset downloaded from the Hub: that it holds
//! ReactHuman tables at all, and that a copy of the release has the release's content.
//!
//! The fingerprint covers what does not depend on the render adapter (decisions.md,
//! 2026-12-02): the scene table's rows without the rendered-media columns, the
//! evaluation subset's rows likewise, and every spec file's bytes. Frames, videos,
//! measured pixels and the card (which names the adapter) are covered by `build.json`'s
//! per-file SHA-256 sums and the Hub's hashes instead. A label-only build of the release
//! has the same fingerprint as the rendered one.
//!
//! Needs no scene crates: the scorer (the table reader alone) runs the download checks.

use arrow::array::RecordBatch;
use arrow::util::display::{ArrayFormatter, FormatOptions};
use rh_contract::columns::{
    depth_paths_column, frames_column, mask_paths_column, unoccluded_column, video_column,
    visible_px_column,
};
use rh_contract::digest::{hex, sha256_file};
use rh_contract::CAMERAS;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Why a release file, a dataset's fingerprint or a downloaded dataset is unusable; the
/// message names the file, the field or the repository.
#[derive(Debug, thiserror::Error)]
pub enum ReleaseError {
    /// The release file is not valid TOML of a release.
    #[error("{origin}: {message}")]
    Parse { origin: String, message: String },
    #[error("{origin}: {field} must be a SHA-256 in lowercase hex (64 digits), not '{value}'")]
    NotSha256 {
        origin: String,
        field: String,
        value: String,
    },
    #[error("{origin}: id must be set and n at least 1")]
    NoIdentity { origin: String },
    #[error("cannot read the release file {origin}: {source}")]
    ReadRelease {
        origin: String,
        source: std::io::Error,
    },
    #[error(transparent)]
    Read(#[from] crate::read::ReadError),
    #[error(transparent)]
    Manifest(#[from] crate::manifest::ManifestError),
    #[error("{} holds no Parquet table", .folder.display())]
    NoTable { folder: PathBuf },
    /// A file of the fingerprint: `FILE: WHAT`.
    #[error("{}: {what}", .file.display())]
    Rows { file: PathBuf, what: String },
    /// A spec file or the `specs/` folder.
    #[error("cannot read {}: {source}", .path.display())]
    Specs {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "the Hub dataset {repo} holds no ReactHuman tables (no data/*.parquet), so nothing in it can be scored or run: it holds {holds}. \
         The paper's metadata-only release is such a repository. A dataset that scores: the project's release {released} \
         (what rh-score uses without --dataset), or the same release built here with `rh-pipeline build --release --out DIR`, then --dataset DIR"
    )]
    NoTables {
        repo: String,
        holds: String,
        released: String,
    },
    /// The release's repository holds a build that names another release (`named`: "no
    /// release" or "release ID").
    #[error("{repo} should hold release {id} ({origin}) but its build.json names {named}: build and upload it with `rh-pipeline build --release`")]
    WrongRelease {
        repo: String,
        id: String,
        origin: String,
        named: String,
    },
    #[error(
        "{repo} is not release {id} as {origin} pins it (a changed or damaged copy): {differences}"
    )]
    Differs {
        repo: String,
        id: String,
        origin: String,
        differences: String,
    },
}

/// The message, for callers that pass errors on as text.
impl From<ReleaseError> for String {
    fn from(e: ReleaseError) -> String {
        e.to_string()
    }
}

/// The embedded `configs/release.toml`.
pub const EMBEDDED_RELEASE: &str = include_str!("../../configs/release.toml");
/// The embedded `configs/prompt.toml` (only its `version` is read here).
pub const EMBEDDED_PROMPT: &str = include_str!("../../configs/prompt.toml");
/// Environment variable naming another release file (a test release, a fork's release)
/// for `rh-score`'s checks and `rh-pipeline build --release`.
pub const RELEASE_ENV: &str = "RH_RELEASE_CONFIG";

/// A release: what `rh-pipeline build --release` builds and what a copy of it must be.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Release {
    /// The release's name, recorded in `build.json` (`release`) and the card.
    pub id: String,
    pub seed: u64,
    /// Scenes in the build.
    pub n: u64,
    /// Families; absent: the configuration's `build.families`.
    #[serde(default)]
    pub families: Option<Vec<String>>,
    /// Videos and frames (the models' inputs) are rendered.
    pub render: bool,
    /// Segmentation and depth PNGs of the observation frames (`--masks`).
    #[serde(default)]
    pub masks: bool,
    pub pins: Pins,
    pub fingerprint: Fingerprint,
}

/// What the release's build must run under.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pins {
    /// `build.json`'s `config_sha256` of the configuration.
    pub config_sha256: String,
    /// `build.json`'s `catalog_sha256` of the catalog.
    pub catalog_sha256: String,
    /// `labels.rule_version` of the configuration.
    pub label_rule: String,
    /// `version` of `configs/prompt.toml` (what `rh-score predict` sends).
    pub prompt_version: String,
}

/// SHA-256 digests of a dataset's adapter-independent content.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fingerprint {
    /// The rows of `data/*.parquet` in order, every column but the rendered media.
    pub scenes_sha256: String,
    /// The rows of `eval/*.parquet` likewise (the evaluation subset).
    pub eval_sha256: String,
    /// `specs/<scene_id>.json`, one `name<TAB>SHA-256` line per file, by name.
    pub specs_sha256: String,
}

fn is_sha256(s: &str) -> bool {
    s.len() == 64
        && s.bytes()
            .all(|b| b.is_ascii_hexdigit() && !b.is_ascii_uppercase())
}

impl Release {
    /// Parses a release file's text (`origin` names it in errors).
    pub fn parse(text: &str, origin: &str) -> Result<Release, ReleaseError> {
        let r: Release = toml::from_str(text).map_err(|e| ReleaseError::Parse {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        let hashes = [
            ("pins.config_sha256", &r.pins.config_sha256),
            ("pins.catalog_sha256", &r.pins.catalog_sha256),
            ("fingerprint.scenes_sha256", &r.fingerprint.scenes_sha256),
            ("fingerprint.eval_sha256", &r.fingerprint.eval_sha256),
            ("fingerprint.specs_sha256", &r.fingerprint.specs_sha256),
        ];
        for (field, value) in hashes {
            if !is_sha256(value) {
                return Err(ReleaseError::NotSha256 {
                    origin: origin.to_string(),
                    field: field.to_string(),
                    value: value.to_string(),
                });
            }
        }
        if r.id.trim().is_empty() || r.n == 0 {
            return Err(ReleaseError::NoIdentity {
                origin: origin.to_string(),
            });
        }
        Ok(r)
    }

    /// The release file `path`, else `$RH_RELEASE_CONFIG`, else the embedded
    /// `configs/release.toml`; with the name it was read from.
    pub fn load(path: Option<&Path>) -> Result<(Release, String), ReleaseError> {
        let path: Option<PathBuf> = path.map(Path::to_path_buf).or_else(|| {
            std::env::var_os(RELEASE_ENV)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        });
        match path {
            None => Ok((
                Release::parse(EMBEDDED_RELEASE, "configs/release.toml")?,
                "configs/release.toml".to_string(),
            )),
            Some(p) => {
                let origin = p.display().to_string();
                let text = match std::fs::read_to_string(&p) {
                    Ok(text) => text,
                    Err(source) => return Err(ReleaseError::ReadRelease { origin, source }),
                };
                Ok((Release::parse(&text, &origin)?, origin))
            }
        }
    }
}

/// The `version` of a `prompt.toml` text.
pub fn prompt_version(prompt_toml: &str) -> Option<String> {
    let v: toml::Value = toml::from_str(prompt_toml).ok()?;
    v.get("version")?.as_str().map(str::to_string)
}

/// The columns a rendered build fills and a label-only build leaves null: video file
/// names, measured visibility, mask and depth paths, the frames' images. They depend on
/// the render adapter (or on rendering at all), so the fingerprint leaves them out.
pub fn is_rendered_media(column: &str) -> bool {
    CAMERAS.iter().any(|cam| {
        [
            video_column(cam),
            visible_px_column(cam),
            unoccluded_column(cam),
            mask_paths_column(cam),
            depth_paths_column(cam),
            frames_column(cam),
        ]
        .iter()
        .any(|c| c == column)
    }) || column == video_column("full_event")
}

fn hash_rows(hasher: &mut Sha256, batch: &RecordBatch, file: &Path) -> Result<(), ReleaseError> {
    let options = FormatOptions::default().with_null("null");
    let schema = batch.schema();
    let formatters: Vec<ArrayFormatter> = batch
        .columns()
        .iter()
        .map(|c| ArrayFormatter::try_new(c.as_ref(), &options))
        .collect::<Result<_, _>>()
        .map_err(|e| ReleaseError::Rows {
            file: file.to_path_buf(),
            what: format!("a column cannot be read: {e}"),
        })?;
    for row in 0..batch.num_rows() {
        for (field, f) in schema.fields().iter().zip(&formatters) {
            hasher.update(format!("{}={}\x1f", field.name(), f.value(row)).as_bytes());
        }
        hasher.update(b"\n");
    }
    Ok(())
}

/// SHA-256 of the rows of the tables in `folder` (name order), media columns left out.
fn table_sha256(folder: &Path) -> Result<String, ReleaseError> {
    let files = crate::read::parquet_files(folder)?;
    if files.is_empty() {
        return Err(ReleaseError::NoTable {
            folder: folder.to_path_buf(),
        });
    }
    let mut hasher = Sha256::new();
    for file in &files {
        let reader = crate::read::open_columns(file, 256, |name| !is_rendered_media(name))?;
        for batch in reader {
            let batch = batch.map_err(|e| ReleaseError::Rows {
                file: file.to_path_buf(),
                what: format!("cannot be read: {e}"),
            })?;
            hash_rows(&mut hasher, &batch, file)?;
        }
    }
    Ok(hex(&hasher.finalize()))
}

/// SHA-256 of `name<TAB>SHA-256\n` for every file of `specs/`, by name.
fn specs_sha256(dir: &Path) -> Result<String, ReleaseError> {
    let specs = dir.join("specs");
    let mut names: Vec<String> = std::fs::read_dir(&specs)
        .map_err(|source| ReleaseError::Specs {
            path: specs.clone(),
            source,
        })?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut hasher = Sha256::new();
    for name in names {
        let sum = sha256_file(&specs.join(&name)).map_err(|source| ReleaseError::Specs {
            path: specs.join(&name),
            source,
        })?;
        hasher.update(format!("{name}\t{sum}\n").as_bytes());
    }
    Ok(hex(&hasher.finalize()))
}

impl Fingerprint {
    /// The fingerprint of the dataset in `dir`.
    pub fn of(dir: &Path) -> Result<Fingerprint, ReleaseError> {
        Ok(Fingerprint {
            scenes_sha256: table_sha256(&dir.join("data"))?,
            eval_sha256: table_sha256(&dir.join("eval"))?,
            specs_sha256: specs_sha256(dir)?,
        })
    }

    /// What differs from `pinned`, one phrase each (empty when equal).
    pub fn differences(&self, pinned: &Fingerprint) -> Vec<String> {
        let parts = [
            (
                "the scene table (data/)",
                &self.scenes_sha256,
                &pinned.scenes_sha256,
            ),
            (
                "the evaluation subset (eval/)",
                &self.eval_sha256,
                &pinned.eval_sha256,
            ),
            (
                "the scene specs (specs/)",
                &self.specs_sha256,
                &pinned.specs_sha256,
            ),
        ];
        parts
            .iter()
            .filter(|(_, a, b)| a != b)
            .map(|(what, a, b)| format!("{what}: {a} where the release pins {b}"))
            .collect()
    }
}

/// The files under `dir`, relative, by name (a snapshot's entries are links to blobs).
pub fn list_files(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if std::fs::metadata(&p).is_ok_and(|m| m.is_dir()) {
                stack.push(p);
            } else if let Ok(rel) = p.strip_prefix(dir) {
                out.push(rel.to_string_lossy().into_owned());
            }
        }
    }
    out.sort();
    out
}

/// `None` when `dir` holds a ReactHuman scene table (`data/*.parquet`); otherwise what it
/// holds instead, as a phrase naming its files (the first 20).
pub fn without_tables(dir: &Path) -> Option<String> {
    let data = dir.join("data");
    if crate::read::parquet_files(&data).is_ok_and(|f| !f.is_empty()) {
        return None;
    }
    let files = list_files(dir);
    let shown: Vec<&str> = files.iter().take(20).map(String::as_str).collect();
    Some(if files.is_empty() {
        "no files".to_string()
    } else {
        format!(
            "{} file(s): {}{}",
            files.len(),
            shown.join(", "),
            if files.len() > 20 { ", …" } else { "" }
        )
    })
}

/// The checks of a dataset downloaded from the Hub as `repo` into `dir` (by `rh-score`
/// and the Python package), before anything reads it; `released` is the project's release
/// repository (`configs/hub.toml`, `owner/name[@revision]`). Refused (the message says
/// why, for exit 2): a repository with no ReactHuman tables (the paper's metadata-only
/// release), and a copy of the release whose content differs from the release's pinned
/// fingerprint. A copy of the release that matches returns the note saying so.
pub fn check_download(
    repo: &str,
    dir: &Path,
    released: &str,
) -> Result<Option<String>, ReleaseError> {
    if let Some(holds) = without_tables(dir) {
        return Err(ReleaseError::NoTables {
            repo: repo.to_string(),
            holds,
            released: released.to_string(),
        });
    }
    let manifest = crate::manifest::Manifest::read(dir)?;
    let claimed = manifest.as_ref().and_then(|m| m.release.clone());
    let released_repo = released.split_once('@').map_or(released, |(r, _)| r);
    let is_release_repo = repo == released_repo;
    if !is_release_repo && claimed.is_none() {
        return Ok(None);
    }
    let (release, origin) = Release::load(None)?;
    match claimed.as_deref() {
        Some(id) if id == release.id => {}
        Some(id) if !is_release_repo => {
            return Ok(Some(format!(
                "{repo} is release {id}; this rh-score pins release {} ({origin}) only, so its fingerprint was not checked",
                release.id
            )))
        }
        other => {
            return Err(ReleaseError::WrongRelease {
                repo: repo.to_string(),
                id: release.id,
                origin,
                named: other.map_or("no release".to_string(), |id| format!("release {id}")),
            })
        }
    }
    let mut differs = Vec::new();
    if let Some(m) = &manifest {
        differs.extend(identity_differences(m, &release));
    }
    differs.extend(Fingerprint::of(dir)?.differences(&release.fingerprint));
    if !differs.is_empty() {
        return Err(ReleaseError::Differs {
            repo: repo.to_string(),
            id: release.id,
            origin,
            differences: differs.join("; "),
        });
    }
    Ok(Some(format!(
        "{repo} is release {}: its fingerprint matches {origin}",
        release.id
    )))
}

/// Where a build's manifest differs from what the release pins (seed, n, configuration,
/// catalog, label rule), one phrase each.
pub fn identity_differences(m: &crate::manifest::Manifest, release: &Release) -> Vec<String> {
    let mut d = Vec::new();
    let mut cmp = |what: &str, found: String, pinned: String| {
        if found != pinned {
            d.push(format!("{what} {found} where the release pins {pinned}"));
        }
    };
    cmp("seed", m.seed.to_string(), release.seed.to_string());
    cmp("n", m.n.to_string(), release.n.to_string());
    cmp(
        "config_sha256",
        m.config_sha256.clone(),
        release.pins.config_sha256.clone(),
    );
    cmp(
        "catalog_sha256",
        m.catalog_sha256.clone(),
        release.pins.catalog_sha256.clone(),
    );
    cmp(
        "label rule",
        m.label_rule().unwrap_or("none").to_string(),
        release.pins.label_rule.clone(),
    );
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_release_parses_and_pins_the_embedded_prompt() {
        let r = Release::parse(EMBEDDED_RELEASE, "configs/release.toml").unwrap();
        assert_eq!(
            prompt_version(EMBEDDED_PROMPT).as_deref(),
            Some(r.pins.prompt_version.as_str())
        );
        let bad = EMBEDDED_RELEASE.replace(&r.fingerprint.specs_sha256, "abc");
        let e = Release::parse(&bad, "x.toml").unwrap_err().to_string();
        assert!(e.contains("x.toml: fingerprint.specs_sha256"), "{e}");
    }

    #[test]
    fn media_columns_are_the_rendered_ones() {
        assert!(is_rendered_media("ego_file_name"));
        assert!(is_rendered_media("full_event_file_name"));
        assert!(is_rendered_media("overhead_hazard_visible_px"));
        assert!(is_rendered_media("closeup_frames"));
        assert!(!is_rendered_media("gt_action"));
        assert!(!is_rendered_media("ego_intrinsics"));
        assert!(!is_rendered_media("spec_file"));
    }

    #[test]
    fn a_folder_without_tables_is_described_by_its_files() {
        let tmp = tempfile::tempdir().unwrap();
        assert_eq!(without_tables(tmp.path()).as_deref(), Some("no files"));
        std::fs::write(tmp.path().join("README.md"), "x").unwrap();
        std::fs::create_dir(tmp.path().join("meta")).unwrap();
        std::fs::write(tmp.path().join("meta/scenes.json"), "[]").unwrap();
        let what = without_tables(tmp.path()).unwrap();
        assert_eq!(what, "2 file(s): README.md, meta/scenes.json");
        let e = check_download("a/b", tmp.path(), "c/d@v1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a/b holds no ReactHuman tables") && e.contains(&what),
            "{e}"
        );
        assert!(e.contains("c/d@v1") && e.contains("build --release"), "{e}");
    }
}
