//! ReactHuman dataset builder: the staged DAG `plan → randomize → simulate → (frame
//! cameras, validate, counterfactual simulate) → label → render`, dataset writing, and
//! replay verification.
//!
//! Each stage is a module with one entry point over plain data:
//! `selection::plan_group` / `selection::LexiconPlanner`, `randomize::randomize`,
//! `simulate::simulate`, `cameras::frame`, `validate::validate`, `label::label`,
//! `render::render_stage`. `scene::run_group` is the one place that chains them for a
//! scene group; `build::build` runs the groups in parallel and writes the dataset.
//! The data contract (families, columns, actions, file layout) is the `rh-contract`
//! crate. Rendering is the cargo feature `render` (default); without it the crate is
//! label-only and links neither Vulkan nor FFmpeg. ARCHITECTURE.md has the module graph.

pub mod balance;
pub mod build;
pub mod cameras;
pub mod card;
pub mod cli;
pub mod config;
pub mod dataset;
pub mod dataset_stream;
pub mod execute;
pub mod families;
pub mod fsio;
pub mod integrity;
pub mod label;
pub mod llm_plan;
pub mod manifest;
pub mod media;
pub mod merge;
pub mod selection;
/// The old name of [`selection`], kept so that code written against `plan` still builds.
pub use selection as plan;
pub mod randomize;
pub mod records;
#[cfg(feature = "render")]
pub mod render;
pub mod scene;
pub mod seeds;
pub mod simulate;
pub mod spec;
pub mod strike;
pub mod validate;
pub mod verify;
pub mod visibility;
