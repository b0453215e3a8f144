//! Real meshes for catalog objects (issue 45): an entry may name a model of an installed
//! asset package (`[objects.model]`: package, archive, the model file inside it, the
//! file's SHA-256, an orientation fix, and the credit the licence asks for). The mesh is
//! drawn only; the collider stays the entry's primitive parts, so labels never depend on
//! a model or on the package being installed. Loading, fitting and checking the mesh is
//! the renderer's (`rh_render::models`); this module is the data and its validation.

use super::{CatalogError, EntryCheck, Object};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// An asset package the catalog may draw models from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Package {
    /// The Debian package name.
    pub name: &'static str,
    /// Where the package installs its archives.
    pub default_root: &'static str,
    /// The command that installs it.
    pub install: &'static str,
    /// The kind of archive the package holds (file-name extension).
    pub archive_ext: &'static str,
}

/// Every package the catalog knows. Sweet Home 3D's furniture libraries: ZIP archives
/// (`.sh3f`) of OBJ/MTL models and their textures, in centimetres, y up, front +z.
pub const PACKAGES: [Package; 1] = [Package {
    name: "sweethome3d-furniture",
    default_root: "/usr/share/sweethome3d/furniture",
    install: "sudo apt-get install sweethome3d-furniture",
    archive_ext: ".sh3f",
}];

/// The licences the catalog accepts for a model (SPDX identifiers).
pub const LICENSES: [&str; 3] = ["CC0-1.0", "CC-BY-3.0", "CC-BY-3.0-US"];

pub fn package(name: &str) -> Option<&'static Package> {
    PACKAGES.iter().find(|p| p.name == name)
}

/// A model of an asset package, as an object's `[objects.model]` table names it.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelRef {
    /// The package (one of [`PACKAGES`]).
    pub package: String,
    /// The archive file in the package's directory (e.g. `Scopia.sh3f`).
    pub archive: String,
    /// The OBJ file inside the archive.
    pub path: String,
    /// SHA-256 of the OBJ file's bytes (lowercase hex), checked when it is loaded.
    pub sha256: String,
    /// Only this OBJ object (`o` name) of the file, e.g. one apple of a bowl of apples.
    #[serde(default)]
    pub object: Option<String>,
    /// Orientation fix in degrees about the catalog frame's x, then y, then z, applied
    /// after the package's axis convention (Sweet Home 3D: y up, front +z, mapped to
    /// z up, front +y).
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Credit: the model's name, its creator and its licence (SPDX), as the package's
    /// catalog (`PluginFurnitureCatalog.properties`) states them.
    pub name: String,
    pub creator: String,
    pub license: String,
}

impl ModelRef {
    /// `archive:path` (and `#object`), how messages name the model file.
    pub fn file_label(&self) -> String {
        match &self.object {
            Some(o) => format!("{}:{}#{o}", self.archive, self.path),
            None => format!("{}:{}", self.archive, self.path),
        }
    }
}

/// How the renderer loads models (`[render.models]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelConfig {
    /// Most triangles one model is drawn with (meshopt simplifies larger ones).
    #[serde(default = "default_triangle_budget")]
    pub triangle_budget: usize,
    /// How far, as a fraction, any axis of a model's bounds (scaled uniformly to the
    /// parts' volume) may differ from the parts' bounds; the fit then scales each axis
    /// onto the parts exactly, so this bounds the distortion (and catches a wrong
    /// orientation fix).
    #[serde(default = "default_bounds_tolerance")]
    pub bounds_tolerance: f64,
    /// Texture resolution (square, pixels) and how many textures one renderer holds.
    #[serde(default = "default_texture_size")]
    pub texture_size: u32,
    #[serde(default = "default_texture_layers")]
    pub texture_layers: u32,
    /// The directory holding the package's archives (default: the package's install
    /// location, [`Package::default_root`]).
    #[serde(default)]
    pub package_root: Option<PathBuf>,
}

fn default_triangle_budget() -> usize {
    1500
}
fn default_bounds_tolerance() -> f64 {
    0.45
}
fn default_texture_size() -> u32 {
    128
}
fn default_texture_layers() -> u32 {
    96
}

impl Default for ModelConfig {
    fn default() -> Self {
        ModelConfig {
            triangle_budget: default_triangle_budget(),
            bounds_tolerance: default_bounds_tolerance(),
            texture_size: default_texture_size(),
            texture_layers: default_texture_layers(),
            package_root: None,
        }
    }
}

impl ModelConfig {
    /// The directory of `package`'s archives.
    pub fn root(&self, package: &Package) -> PathBuf {
        self.package_root
            .clone()
            .unwrap_or_else(|| PathBuf::from(package.default_root))
    }
}

/// One model's credit line, as the dataset card lists it.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Credit {
    pub name: String,
    pub creator: String,
    pub license: String,
    pub package: String,
    /// `archive:path`, which model exactly.
    pub file: String,
}

impl From<&ModelRef> for Credit {
    fn from(m: &ModelRef) -> Credit {
        Credit {
            name: m.name.clone(),
            creator: m.creator.clone(),
            license: m.license.clone(),
            package: m.package.clone(),
            file: format!("{}:{}", m.archive, m.path),
        }
    }
}

/// The model an object is drawn with: its own, or its look-alike's (adversarial entries
/// take exactly their look-alike's mesh and materials).
pub fn drawn_model<'a>(catalog: &'a super::Catalog, object: &'a Object) -> Option<&'a ModelRef> {
    catalog.appearance_source(object).model.as_ref()
}

/// The credits of the models drawn for `object_ids` (each model once, sorted).
pub fn credits<'a>(
    catalog: &super::Catalog,
    object_ids: impl IntoIterator<Item = &'a str>,
) -> Vec<Credit> {
    let mut out: Vec<Credit> = object_ids
        .into_iter()
        .filter_map(|id| catalog.object(id))
        .filter_map(|o| drawn_model(catalog, o))
        .map(Credit::from)
        .collect();
    out.sort();
    out.dedup();
    out
}

/// Checks one entry's model reference.
pub(super) fn check_model(
    check: &EntryCheck,
    model: &ModelRef,
    adversarial: bool,
) -> Result<(), CatalogError> {
    if adversarial {
        return Err(check.fail(
            "model",
            "an adversarial entry is drawn with its look-alike's model; give none",
        ));
    }
    let Some(p) = package(&model.package) else {
        let known: Vec<&str> = PACKAGES.iter().map(|p| p.name).collect();
        return Err(check.fail(
            "model.package",
            format!(
                "unknown package '{}' (known: {})",
                model.package,
                known.join(", ")
            ),
        ));
    };
    let plain = |s: &str| !s.is_empty() && !s.starts_with('/') && !s.split('/').any(|c| c == "..");
    if !plain(&model.archive)
        || model.archive.contains('/')
        || !model.archive.ends_with(p.archive_ext)
    {
        return Err(check.fail(
            "model.archive",
            format!(
                "must be a file name ending in {} (got '{}')",
                p.archive_ext, model.archive
            ),
        ));
    }
    if !plain(&model.path) || !model.path.ends_with(".obj") {
        return Err(check.fail(
            "model.path",
            format!(
                "must be a relative .obj path inside the archive (got '{}')",
                model.path
            ),
        ));
    }
    let hex = model.sha256.len() == 64
        && model
            .sha256
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
    if !hex {
        return Err(check.fail("model.sha256", "must be 64 lowercase hex digits"));
    }
    for &r in &model.rotation {
        check.range("model.rotation", r, -360.0, 360.0, "°")?;
    }
    for (field, v) in [
        ("model.name", &model.name),
        ("model.creator", &model.creator),
    ] {
        if v.trim().is_empty() {
            return Err(check.fail(field, "must not be empty (the licence asks for credit)"));
        }
    }
    if !LICENSES.contains(&model.license.as_str()) {
        return Err(check.fail(
            "model.license",
            format!(
                "must be one of {} (got '{}')",
                LICENSES.join(", "),
                model.license
            ),
        ));
    }
    Ok(())
}
