//! Real meshes for catalog objects (issue 45): a catalog entry's `[objects.model]` names
//! an OBJ model inside an asset package's archive (`rh_catalog::models`). This module
//! reads it ([`load_model`]: the archive, the file's SHA-256, OBJ/MTL, textures), keeps a
//! triangle budget (meshopt), turns it into the catalog object frame and fits it onto
//! the entry's parts ([`fit_model`], with the bounds check), and caches what it loaded
//! for the process ([`drawn_mesh`]). The meshes only draw: colliders stay the parts.
//!
//! Textures go to a process-wide table ([`texture_layer`]): each distinct image gets a
//! layer of the renderer's texture array, which every GPU device uploads before it
//! draws (`gpu::Gpu::sync_textures`). Which layer an image gets depends on load order,
//! but no pixel does: a vertex names its layer, and every layer holds the same image in
//! any process.

mod fit;
mod obj;

pub use fit::{fit_model, parts_box, FitError};
pub use obj::{load_model, LoadedModel};

use crate::mesh::Mesh;
use rh_catalog::models::{drawn_model, ModelConfig, ModelRef};
use rh_catalog::{Catalog, Object};
use rh_physics::spec::PartSpec;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, RwLock};

/// Why a model could not be drawn. Every variant names what to fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    #[error(
        "the asset package '{package}' is not installed ({root} not found): install it with `{install}` (or build with --no-render)"
    )]
    PackageMissing {
        package: String,
        root: PathBuf,
        install: String,
    },
    #[error("{file}: its SHA-256 is {actual}, the catalog's entry '{entry}' expects {expected} (a different version of the package?)")]
    HashMismatch {
        file: String,
        entry: String,
        expected: String,
        actual: String,
    },
    #[error("{file}: {message}")]
    Bad { file: String, message: String },
    #[error("catalog entry '{entry}': model {file}: {message}")]
    Fit {
        entry: String,
        file: String,
        message: String,
    },
    #[error("{0}")]
    Catalog(String),
}

/// One texture image: sRGB RGBA8, `size`² pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureImage {
    pub size: u32,
    pub rgba: Vec<u8>,
}

/// Every texture loaded in this process, by `archive:path` and its layer.
#[derive(Default)]
struct Textures {
    layers: BTreeMap<String, u32>,
    images: Vec<Arc<TextureImage>>,
}

static TEXTURES: Mutex<Textures> = Mutex::new(Textures {
    layers: BTreeMap::new(),
    images: Vec::new(),
});

/// The layer of texture `key`, adding the image (made by `make`) the first time.
pub fn texture_layer(
    key: &str,
    make: impl FnOnce() -> Result<TextureImage, String>,
) -> Result<u32, String> {
    let mut t = TEXTURES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&l) = t.layers.get(key) {
        return Ok(l);
    }
    let image = make()?;
    let layer = t.images.len() as u32;
    t.images.push(Arc::new(image));
    t.layers.insert(key.to_string(), layer);
    Ok(layer)
}

/// The texture images from layer `from` on (what a device has not uploaded yet).
pub fn textures_from(from: usize) -> Vec<Arc<TextureImage>> {
    let t = TEXTURES.lock().unwrap_or_else(|e| e.into_inner());
    t.images.get(from..).map(|s| s.to_vec()).unwrap_or_default()
}

/// How many texture layers this process has filled.
pub fn texture_count() -> usize {
    TEXTURES
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .images
        .len()
}

/// The model settings of this process's renderers (`[render.models]`; `Renderer::new`
/// sets them).
static CONFIG: RwLock<Option<ModelConfig>> = RwLock::new(None);

pub fn set_config(config: &ModelConfig) {
    *CONFIG.write().unwrap_or_else(|e| e.into_inner()) = Some(config.clone());
}

pub fn config() -> ModelConfig {
    CONFIG
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
        .unwrap_or_default()
}

/// Models loaded in this process, by file label and settings.
type Cache = BTreeMap<(String, usize, u32, String), Arc<LoadedModel>>;
static CACHE: Mutex<Cache> = Mutex::new(BTreeMap::new());

/// The loaded model `m` (from the cache, else loaded and cached).
pub fn cached_model(
    m: &ModelRef,
    entry: &str,
    config: &ModelConfig,
) -> Result<Arc<LoadedModel>, ModelError> {
    let key = (
        m.file_label(),
        config.triangle_budget,
        config.texture_size,
        config.root(package_of(m)?).display().to_string(),
    );
    if let Some(hit) = CACHE.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Ok(hit.clone());
    }
    // Loaded outside the lock (another thread may load the same file meanwhile: the
    // result is the same, the first one inserted is kept).
    let loaded = Arc::new(load_model(m, entry, config)?);
    let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    Ok(cache.entry(key).or_insert(loaded).clone())
}

fn package_of(m: &ModelRef) -> Result<&'static rh_catalog::models::Package, ModelError> {
    rh_catalog::models::package(&m.package)
        .ok_or_else(|| ModelError::Catalog(format!("unknown package '{}'", m.package)))
}

/// The mesh `object` is drawn with when the catalog gives it a model (its own or its
/// look-alike's), fitted onto `parts`; `None` without a model.
pub fn drawn_mesh(
    catalog: &Catalog,
    object: &Object,
    parts: &[PartSpec],
    config: &ModelConfig,
) -> Result<Option<Mesh>, ModelError> {
    let Some(m) = drawn_model(catalog, object) else {
        return Ok(None);
    };
    let source = catalog.appearance_source(object);
    let loaded = cached_model(m, &source.id, config)?;
    fit_model(&loaded, parts, config.bounds_tolerance)
        .map(Some)
        .map_err(|e| ModelError::Fit {
            entry: source.id.clone(),
            file: m.file_label(),
            message: e.to_string(),
        })
}

/// Reports a model that could not be drawn, once per message per process.
pub fn warn_once(e: &ModelError) {
    static SEEN: Mutex<std::collections::BTreeSet<String>> =
        Mutex::new(std::collections::BTreeSet::new());
    let msg = e.to_string();
    if SEEN
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(msg.clone())
    {
        rh_contract::note!("warning: drawing a recipe instead of a model: {msg}");
    }
}

/// What a rendered build checks before any work: the package is installed, every model
/// the catalog names matches its hash, loads, and fits its entry's parts. Loads every
/// model into the process cache. Returns how many models and textures.
pub fn check_catalog(
    catalog: &Catalog,
    config: &ModelConfig,
    parts_of: impl Fn(&Object) -> Vec<PartSpec>,
) -> Result<(usize, usize), ModelError> {
    let mut models = 0;
    for o in catalog.objects.iter().filter(|o| o.model.is_some()) {
        drawn_mesh(catalog, o, &parts_of(o), config)?;
        models += 1;
    }
    let textures = texture_count();
    if textures > config.texture_layers as usize {
        return Err(ModelError::Catalog(format!(
            "the catalog's models use {textures} textures, more than render.models.texture_layers = {}",
            config.texture_layers
        )));
    }
    Ok((models, textures))
}

#[cfg(test)]
mod tests;
