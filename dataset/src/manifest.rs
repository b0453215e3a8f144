//! `build.json`: the manifest every build (and every shard, and every merge) writes into
//! its output directory before any other file. It names what the directory holds — the
//! build seed, scene count, families, shard, render flag, and the exact configuration and
//! catalog — so that a restarted build can tell its own half-finished work from another
//! build's, and `rh-pipeline merge` can check that shards belong together.
//!
//! Reading it ([`Manifest::read`], the identity fields, [`Manifest::differences`]) needs
//! no scene crates, so the table reader alone (without feature `write`) has it too:
//! `rh-score` names the build it scored from it. Making one, the typed configuration and
//! the planned selections need `write`.

#[cfg(feature = "write")]
use rh_catalog::Catalog;
#[cfg(feature = "write")]
use rh_contract::digest::sha256_hex;
#[cfg(feature = "write")]
use rh_scenes::config::Config;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A planned selection of a build from descriptions: typed with `write`; without it (the
/// table reader alone) kept as the JSON it was written as.
#[cfg(feature = "write")]
pub type PlannedSelection = rh_physics::spec::Selection;
/// A planned selection of a build from descriptions: typed with `write`; without it (the
/// table reader alone) kept as the JSON it was written as.
#[cfg(not(feature = "write"))]
pub type PlannedSelection = serde_json::Value;

pub const MANIFEST_FILE: &str = "build.json";

/// Why `build.json` (or the configuration it records) cannot be used; the message names
/// the file.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("cannot read {}: {source}", .path.display())]
    Read {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("{} is not an rh-pipeline build manifest: {message}", .path.display())]
    NotAManifest {
        path: std::path::PathBuf,
        message: String,
    },
    /// The recorded configuration does not parse as this version's `Config`.
    #[error("{MANIFEST_FILE}: its configuration cannot be read: {message}")]
    Config { message: String },
}

/// The message, for callers that pass errors on as text.
impl From<ManifestError> for String {
    fn from(e: ManifestError) -> String {
        e.to_string()
    }
}
pub const FORMAT: &str = "rh-build/1";

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Manifest format version.
    pub format: String,
    /// `rh-pipeline` version that wrote the build.
    pub rh_pipeline_version: String,
    /// Build seed.
    pub seed: u64,
    /// Scenes in the whole (unsharded) build.
    pub n: u64,
    /// Families, in the order groups are assigned to them.
    pub families: Vec<String>,
    /// `[i, N]`: this directory holds shard i of N (`[0, 1]`: the whole build).
    pub shard: [u64; 2],
    /// Whether videos and frames were requested.
    pub render: bool,
    /// Whether the observation frames' mask and depth PNGs were requested (`--masks`;
    /// absent when not, so manifests without masks read as before).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub masks: bool,
    /// SHA-256 of the configuration below, as JSON.
    pub config_sha256: String,
    /// SHA-256 of the catalog (objects and rooms) the scenes were drawn from.
    pub catalog_sha256: String,
    /// The whole build configuration (label thresholds included).
    pub config: serde_json::Value,
    /// SHA-256 of every file the build wrote (this one aside), by path: written when the
    /// build is finished (`finalize::finalize`); absent while it runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub files: Option<std::collections::BTreeMap<String, String>>,
    /// The planned selections of a build from descriptions (`--descriptions`), one per
    /// description with its planner record; group g takes selection g mod len.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selections: Option<Vec<PlannedSelection>>,
    /// The adapter that drew the videos and frames (`null` for a label-only build, and
    /// read as `null` from manifests written before it was recorded). Shards rendered on
    /// different adapters do not merge: their pixels, the models' inputs, may differ.
    #[serde(default)]
    pub render_adapter: Option<rh_contract::adapter::RenderAdapter>,
    /// The release this is a build of (`rh-pipeline build --release`: the `id` of
    /// `configs/release.toml`); absent for any other build.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub release: Option<String>,
}

/// A fingerprint of a configuration (also used to tell the embedded default apart).
#[cfg(feature = "write")]
pub fn config_sha256(config: &Config) -> String {
    sha256_hex(
        serde_json::to_string(config)
            .expect("config serializes")
            .as_bytes(),
    )
}

/// A fingerprint of a catalog's validated content.
#[cfg(feature = "write")]
pub fn catalog_sha256(catalog: &Catalog) -> String {
    sha256_hex(format!("{:?}\n{:?}", catalog.objects, catalog.rooms).as_bytes())
}

impl Manifest {
    #[cfg(feature = "write")]
    pub fn new(
        seed: u64,
        n: u64,
        families: &[String],
        shard: (u64, u64),
        render: bool,
        catalog: &Catalog,
        config: &Config,
    ) -> Manifest {
        Manifest {
            format: FORMAT.to_string(),
            rh_pipeline_version: env!("CARGO_PKG_VERSION").to_string(),
            seed,
            n,
            families: families.to_vec(),
            shard: [shard.0, shard.1],
            render,
            masks: false,
            config_sha256: config_sha256(config),
            catalog_sha256: catalog_sha256(catalog),
            config: serde_json::to_value(config).expect("config serializes"),
            files: None,
            selections: None,
            render_adapter: None,
            release: None,
        }
    }

    /// Scene groups of the whole build (four speed bands each; the last may be partial).
    pub fn n_groups(&self) -> u64 {
        self.n.div_ceil(4)
    }

    /// The groups this directory holds: `g mod N == i`.
    pub fn groups(&self) -> Vec<u64> {
        (0..self.n_groups())
            .filter(|g| g % self.shard[1] == self.shard[0])
            .collect()
    }

    /// Scenes in group `g` (4, or fewer for the last group).
    pub fn group_size(&self, g: u64) -> u64 {
        (self.n - g * 4).min(4)
    }

    pub fn is_whole(&self) -> bool {
        self.shard == [0, 1]
    }

    /// The same build, unsharded (what a merge of its shards is).
    pub fn whole(&self) -> Manifest {
        Manifest {
            shard: [0, 1],
            files: None,
            ..self.clone()
        }
    }

    /// The label rule's version (`labels.rule_version` of the configuration), if any.
    pub fn label_rule(&self) -> Option<&str> {
        self.config.pointer("/labels/rule_version")?.as_str()
    }

    /// The label thresholds of the build.
    #[cfg(feature = "write")]
    pub fn labels(&self) -> Option<rh_physics::spec::LabelConfig> {
        serde_json::from_value(self.config.get("labels")?.clone()).ok()
    }

    /// The configuration the build ran with.
    #[cfg(feature = "write")]
    pub fn build_config(&self) -> Result<Config, ManifestError> {
        serde_json::from_value(self.config.clone()).map_err(|e| ManifestError::Config {
            message: e.to_string(),
        })
    }

    /// Names the fields in which `other` differs from `self` (empty when equal; the
    /// file checksums are not part of a build's identity).
    pub fn differences(&self, other: &Manifest) -> Vec<String> {
        let mut d = Vec::new();
        let mut cmp = |name: &str, a: String, b: String| {
            if a != b {
                d.push(format!("{name} {a} vs {b}"));
            }
        };
        cmp("format", self.format.clone(), other.format.clone());
        cmp(
            "rh-pipeline version",
            self.rh_pipeline_version.clone(),
            other.rh_pipeline_version.clone(),
        );
        cmp("seed", self.seed.to_string(), other.seed.to_string());
        cmp(
            "planned selections (--descriptions)",
            serde_json::to_string(&self.selections).unwrap_or_default(),
            serde_json::to_string(&other.selections).unwrap_or_default(),
        );
        cmp("n", self.n.to_string(), other.n.to_string());
        cmp(
            "families",
            self.families.join(","),
            other.families.join(","),
        );
        cmp(
            "shard",
            format!("{}/{}", self.shard[0], self.shard[1]),
            format!("{}/{}", other.shard[0], other.shard[1]),
        );
        cmp("render", self.render.to_string(), other.render.to_string());
        cmp("masks", self.masks.to_string(), other.masks.to_string());
        cmp(
            "release",
            format!("{:?}", self.release),
            format!("{:?}", other.release),
        );
        if self.config_sha256 != other.config_sha256 || self.config != other.config {
            d.push("configuration".into());
        }
        if self.catalog_sha256 != other.catalog_sha256 {
            d.push("catalog".into());
        }
        if let Some(a) = self.adapter_difference(other) {
            d.push(a);
        }
        d
    }

    /// "render adapter A vs B" when the two builds were rendered on different adapters
    /// (None when equal, or when either records none: a label-only build).
    pub fn adapter_difference(&self, other: &Manifest) -> Option<String> {
        match (&self.render_adapter, &other.render_adapter) {
            (Some(a), Some(b)) if a != b => Some(format!(
                "render adapter {} vs {}",
                a.describe(),
                b.describe()
            )),
            _ => None,
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("manifest serializes") + "\n"
    }

    /// Reads `DIR/build.json`; `Ok(None)` when there is none.
    pub fn read(dir: &Path) -> Result<Option<Manifest>, ManifestError> {
        let path = dir.join(MANIFEST_FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => return Err(ManifestError::Read { path, source }),
        };
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| ManifestError::NotAManifest {
                path,
                message: e.to_string(),
            })
    }
}

/// What keeps `dir` from being a finished build (`None`: it is one, or it has no
/// `build.json` and so is not a build of `rh-pipeline` at all): `build.json` records no
/// file checksums (the build stopped before it finished: killed, out of disk), or files
/// it records are missing. The message names what is missing and the command that
/// finishes the build (`build` with the same arguments resumes). Only looks whether the
/// files are there; `rh-pipeline verify` checks their content.
pub fn unfinished(dir: &Path) -> Result<Option<String>, ManifestError> {
    let Some(m) = Manifest::read(dir)? else {
        return Ok(None);
    };
    let missing = match &m.files {
        None => format!(
            "its {MANIFEST_FILE} records no file checksums, so the build stopped before it finished (killed, or out of disk)"
        ),
        Some(sums) => {
            let gone: Vec<&String> = sums.keys().filter(|f| !dir.join(f).is_file()).collect();
            if gone.is_empty() {
                return Ok(None);
            }
            let shown: Vec<&str> = gone.iter().take(3).map(|s| s.as_str()).collect();
            format!(
                "{} file(s) its {MANIFEST_FILE} records are missing ({}{})",
                gone.len(),
                shown.join(", "),
                if gone.len() > 3 { ", …" } else { "" }
            )
        }
    };
    Ok(Some(format!(
        "{} is not a finished build: {missing}. Finish it with the command that made it, which resumes where it stopped: {}",
        dir.display(),
        m.build_command(dir)
    )))
}

impl Manifest {
    /// The `rh-pipeline build` command line of this build (its recorded arguments; a
    /// `--config`, `--catalog` or `--descriptions` it was given is named, not spelled out).
    pub fn build_command(&self, dir: &Path) -> String {
        let mut cmd = match &self.release {
            Some(_) => format!("rh-pipeline build --release --out {}", dir.display()),
            None => format!(
                "rh-pipeline build --n {} --seed {} --out {}",
                self.n,
                self.seed,
                dir.display()
            ),
        };
        if !self.render {
            cmd.push_str(" --no-render");
        }
        if self.masks {
            cmd.push_str(" --masks");
        }
        if self.shard[1] > 1 {
            cmd.push_str(&format!(" --shard {}/{}", self.shard[0], self.shard[1]));
        }
        if self.selections.is_some() {
            cmd.push_str(" --descriptions FILE");
        }
        cmd.push_str(" (with the same --config, --catalog and --families, if it had them)");
        cmd
    }
}

#[cfg(all(test, feature = "write"))]
mod tests {
    use super::*;

    #[test]
    fn manifest_round_trips_and_names_differences() {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let fams = vec!["object_drop".to_string()];
        let a = Manifest::new(7, 10, &fams, (1, 3), false, &catalog, &config);
        let back: Manifest = serde_json::from_str(&a.to_json()).unwrap();
        assert_eq!(a, back);
        assert_eq!(a.groups(), vec![1]);
        assert_eq!(a.group_size(2), 2);
        assert_eq!(a.labels().unwrap(), config.labels);
        assert_eq!(a.label_rule(), Some(config.labels.rule_version.as_str()));
        let b = Manifest::new(8, 10, &fams, (1, 3), false, &catalog, &config);
        assert_eq!(a.differences(&b), vec!["seed 7 vs 8".to_string()]);
        assert!(a.whole().is_whole());
        // Older manifests (no render_adapter) read as null; two adapters differ.
        let mut old: serde_json::Value = serde_json::from_str(&a.to_json()).unwrap();
        old.as_object_mut().unwrap().remove("render_adapter");
        let old: Manifest = serde_json::from_value(old).unwrap();
        assert_eq!(old.render_adapter, None);
        let adapter = |name: &str| rh_contract::adapter::RenderAdapter {
            name: name.into(),
            backend: "vulkan".into(),
            device_type: "cpu".into(),
            driver: "llvmpipe".into(),
            driver_info: "Mesa".into(),
            cpu_features: vec![],
            lp_native_vector_width: None,
        };
        let (mut x, mut y) = (a.clone(), a.clone());
        x.render_adapter = Some(adapter("one"));
        y.render_adapter = Some(adapter("two"));
        let diff = x.differences(&y);
        assert_eq!(diff.len(), 1, "{diff:?}");
        assert!(
            diff[0].contains("one") && diff[0].contains("two"),
            "{diff:?}"
        );
        assert_eq!(x.adapter_difference(&a), None, "label-only merges freely");
    }
}
