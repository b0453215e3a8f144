//! Errors across the Python boundary. Work runs with the GIL released and returns
//! [`Error`] (plain data, `Send`); [`run`] turns it into the Python exception it names,
//! and a Rust panic into `RuntimeError` (never an abort of the interpreter: the crate is
//! built with `panic = "unwind"`, and `catch_unwind` stops the panic at the boundary).

use pyo3::exceptions::{PyFileNotFoundError, PyKeyError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    _native,
    RendererUnavailableError,
    PyRuntimeError,
    "No renderer for the ego camera image: no GPU adapter (no Vulkan driver, not even Mesa's lavapipe), or a build without the `render` feature."
);
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What went wrong, by the Python exception it becomes.
#[derive(Debug)]
pub enum Error {
    /// Bad input (a malformed plan, a bad option, a dataset that is not one): `ValueError`.
    Value(String),
    /// An unknown scene id: `KeyError`.
    Key(String),
    /// A missing dataset or file: `FileNotFoundError`.
    NotFound(String),
    /// No renderer (no adapter, or not built in): `RendererUnavailableError`.
    NoRenderer(String),
    /// Anything else (an I/O failure, a bug): `RuntimeError`.
    Internal(String),
}

pub type Result<T> = std::result::Result<T, Error>;

impl From<anyhow::Error> for Error {
    /// The scorer's input errors (`rh_grade::InputError`) are bad input; the rest internal.
    fn from(e: anyhow::Error) -> Error {
        if rh_grade::error::is_input_error(&e) {
            Error::Value(format!("{e:#}"))
        } else {
            Error::Internal(format!("{e:#}"))
        }
    }
}

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        match e {
            Error::Value(m) => PyValueError::new_err(m),
            Error::Key(m) => PyKeyError::new_err(m),
            Error::NotFound(m) => PyFileNotFoundError::new_err(m),
            Error::NoRenderer(m) => RendererUnavailableError::new_err(m),
            Error::Internal(m) => PyRuntimeError::new_err(m),
        }
    }
}

fn panic_text(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Runs `f` with the GIL released, a panic becoming `RuntimeError`.
pub fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> Result<T> + Send) -> PyResult<T> {
    let out = py.detach(|| catch_unwind(AssertUnwindSafe(f)));
    match out {
        Ok(r) => r.map_err(PyErr::from),
        Err(p) => Err(PyRuntimeError::new_err(format!(
            "internal error in ReactHuman's Rust code (a bug; please report it): {}",
            panic_text(p)
        ))),
    }
}

/// [`run`] without releasing the GIL (for short calls on objects that hold Python state).
pub fn guard<T>(f: impl FnOnce() -> Result<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r.map_err(PyErr::from),
        Err(p) => Err(PyRuntimeError::new_err(format!(
            "internal error in ReactHuman's Rust code (a bug; please report it): {}",
            panic_text(p)
        ))),
    }
}
