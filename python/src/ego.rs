//! `reacthuman._native.NativeEgoCamera`: the humanoid's ego camera image of a running
//! episode (`rh_render::EgoCamera`, feature `render`). Without the feature, or without a
//! GPU adapter (no Vulkan driver, not even lavapipe), construction raises
//! `RendererUnavailableError`.

use crate::errors::{run, Error, Result};
use crate::session::NativeSession;
use pyo3::prelude::*;
use pyo3::types::PyByteArray;

/// Largest image side accepted (pixels).
const MAX_SIDE: u32 = 4096;

#[cfg(feature = "render")]
mod imp {
    use crate::errors::{Error, Result};
    use rh_physics::execute::Replay;
    use std::sync::{Arc, OnceLock};

    /// The camera and the replay whose scene it holds (compared by identity: a dataset
    /// caches one replay per scene, so a new episode of the same scene keeps the meshes).
    pub struct Ego {
        cam: rh_render::EgoCamera,
        scene: Option<Arc<Replay>>,
    }

    fn catalog() -> Result<&'static rh_catalog::Catalog> {
        static CATALOG: OnceLock<std::result::Result<rh_catalog::Catalog, String>> =
            OnceLock::new();
        CATALOG
            .get_or_init(|| rh_catalog::Catalog::embedded().map_err(|e| e.to_string()))
            .as_ref()
            .map_err(|e| Error::Internal(format!("the embedded catalog: {e}")))
    }

    fn render_error(e: rh_render::RenderError) -> Error {
        match e {
            rh_render::RenderError::NoAdapter(m) => Error::NoRenderer(format!(
                "no renderer for the ego camera image: {m}; state observations need none (image=False)"
            )),
            e => Error::Internal(format!("ego camera: {e}")),
        }
    }

    impl Ego {
        /// Opens the adapter with the dataset renderer's anti-aliasing (`[render]` of
        /// configs/default.toml: MSAA on a GPU, FXAA on lavapipe).
        pub fn open(width: u32, height: u32) -> Result<Ego> {
            let cfg = rh_scenes::config::Config::embedded()
                .map_err(|e| Error::Internal(format!("the embedded config: {e}")))?;
            let opts = rh_render::RenderOptions::from_config(&cfg.render);
            let cam = rh_render::EgoCamera::new(width, height, &opts).map_err(render_error)?;
            Ok(Ego { cam, scene: None })
        }

        pub fn adapter_name(&self) -> String {
            self.cam.adapter_name().to_string()
        }

        /// RGB bytes of the ego view of `frame` in `replay`'s scene.
        pub fn draw(
            &mut self,
            frame: &rh_physics::execute::ExecFrame,
            replay: &Arc<Replay>,
        ) -> Result<Vec<u8>> {
            if !self.scene.as_ref().is_some_and(|r| Arc::ptr_eq(r, replay)) {
                self.cam
                    .set_scene(replay.spec(), catalog()?)
                    .map_err(render_error)?;
                self.scene = Some(replay.clone());
            }
            self.cam.draw(frame).map_err(render_error)
        }
    }
}

#[cfg(not(feature = "render"))]
mod imp {
    use crate::errors::{Error, Result};
    use rh_physics::execute::{ExecFrame, Replay};
    use std::sync::Arc;

    /// No renderer in this build: the type has no values, and `open` refuses.
    pub enum Ego {}

    impl Ego {
        pub fn open(_width: u32, _height: u32) -> Result<Ego> {
            Err(Error::NoRenderer(
                "this build of reacthuman has no renderer (built without the `render` feature); image observations are unavailable".into(),
            ))
        }

        pub fn adapter_name(&self) -> String {
            match *self {}
        }

        pub fn draw(&mut self, _frame: &ExecFrame, _replay: &Arc<Replay>) -> Result<Vec<u8>> {
            match *self {}
        }
    }
}

/// The ego camera of one environment, reused across its episodes.
#[pyclass(module = "reacthuman._native", frozen)]
pub struct NativeEgoCamera {
    ego: std::sync::Mutex<imp::Ego>,
    width: u32,
    height: u32,
}

impl NativeEgoCamera {
    fn with<T>(&self, f: impl FnOnce(&mut imp::Ego) -> Result<T>) -> Result<T> {
        let mut e = self.ego.lock().map_err(|_| {
            Error::Internal("the ego camera was poisoned by an earlier panic".into())
        })?;
        f(&mut e)
    }
}

#[pymethods]
impl NativeEgoCamera {
    /// Opens the renderer for `width` × `height` RGB images; `RendererUnavailableError`
    /// when there is none, `ValueError` for a size outside 1..=4096.
    #[new]
    fn new(py: Python<'_>, width: i64, height: i64) -> PyResult<Self> {
        run(py, || {
            let side = |name: &str, v: i64| -> Result<u32> {
                if (1..=MAX_SIDE as i64).contains(&v) {
                    Ok(v as u32)
                } else {
                    Err(Error::Value(format!(
                        "{name} must be 1..={MAX_SIDE} pixels, got {v}"
                    )))
                }
            };
            let (w, h) = (side("image width", width)?, side("image height", height)?);
            Ok(NativeEgoCamera {
                ego: std::sync::Mutex::new(imp::Ego::open(w, h)?),
                width: w,
                height: h,
            })
        })
    }

    /// `(width, height)` of the images.
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The adapter drawing the images (`llvmpipe (LLVM …)` for lavapipe).
    fn adapter_name(&self, py: Python<'_>) -> PyResult<String> {
        run(py, || self.with(|e| Ok(e.adapter_name())))
    }

    /// The ego view of `session` now: `height * width * 3` bytes (RGB rows, top first).
    fn draw<'py>(
        &self,
        py: Python<'py>,
        session: &NativeSession,
    ) -> PyResult<Bound<'py, PyByteArray>> {
        let rgb = run(py, || {
            let (frame, replay) = session.frame()?;
            self.with(|e| e.draw(&frame, &replay))
        })?;
        Ok(PyByteArray::new(py, &rgb))
    }
}
