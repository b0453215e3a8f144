//! The native module of the `reacthuman` Python package (issue 26): a thin PyO3 layer
//! over the grading core (`rh_grade`), the executor (`rh_execute`), the canonical prompt
//! (`rh_prompt`) and the physics (`rh_physics`). The Python side
//! (`python/reacthuman/`) holds the public API, the Gymnasium environment and the docs.
//!
//! * [`dataset`] — `NativeDataset`: load, score, classify, prompt, execute;
//! * [`session`] — `NativeSession`: one closed-loop episode (`rh_physics::control`);
//! * [`ego`] — `NativeEgoCamera`: the episode's ego camera image (`rh_render::EgoCamera`,
//!   feature `render`; `RendererUnavailableError` without a renderer);
//! * [`errors`] — Rust errors and panics as named Python exceptions, the GIL released
//!   around the work.
//!
//! Module graph: `ego → session → dataset → errors`.

pub mod dataset;
pub mod ego;
pub mod errors;
pub mod session;

use pyo3::prelude::*;

/// `classify` with no dataset (the neutral scene: no hazard direction).
#[pyfunction]
fn classify_plan(py: Python<'_>, plan: String) -> PyResult<String> {
    errors::run(py, || {
        dataset::classify_json(&rh_grade::Config::default(), &plan, None)
    })
}

/// Versions the results depend on: action rule, executor, prompt.
#[pyfunction]
fn versions() -> PyResult<(String, String, String)> {
    errors::guard(|| {
        let cfg = rh_grade::Config::default();
        let prompt = rh_prompt::PromptConfig::load(None)?;
        Ok((
            cfg.action_rule.version.clone(),
            cfg.execution.version.clone(),
            prompt.version.clone(),
        ))
    })
}

/// `rh-score predict`'s generation parameters (`[generation]` of configs/predict.toml,
/// JSON text): the temperature and max_tokens of the canonical request.
#[pyfunction]
fn generation_config() -> PyResult<String> {
    errors::guard(|| {
        let generation = rh_prompt::canonical_generation()?;
        serde_json::to_string(&generation).map_err(|e| errors::Error::Internal(e.to_string()))
    })
}

/// The executor's `[execution]` table (JSON text): the limits the environment runs under.
#[pyfunction]
fn execution_config() -> PyResult<String> {
    errors::guard(|| {
        serde_json::to_string(&rh_grade::Config::default().execution)
            .map_err(|e| errors::Error::Internal(e.to_string()))
    })
}

/// Panics in Rust (for the tests: a panic becomes `RuntimeError`, the interpreter lives).
#[pyfunction]
fn _panic_for_tests(py: Python<'_>) -> PyResult<()> {
    errors::run(py, || -> errors::Result<()> {
        panic!("a deliberate panic")
    })
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<dataset::NativeDataset>()?;
    m.add_class::<session::NativeSession>()?;
    m.add_class::<ego::NativeEgoCamera>()?;
    m.add(
        "RendererUnavailableError",
        m.py().get_type::<errors::RendererUnavailableError>(),
    )?;
    m.add("HAS_RENDERER", cfg!(feature = "render"))?;
    m.add_function(wrap_pyfunction!(classify_plan, m)?)?;
    m.add_function(wrap_pyfunction!(versions, m)?)?;
    m.add_function(wrap_pyfunction!(execution_config, m)?)?;
    m.add_function(wrap_pyfunction!(generation_config, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_tests, m)?)?;
    m.add_function(wrap_pyfunction!(session::plan_action, m)?)?;
    m.add_function(wrap_pyfunction!(session::rest_action, m)?)?;
    m.add_function(wrap_pyfunction!(session::state_lengths, m)?)?;
    Ok(())
}
