//! `rh-pipeline`: builds a ReactHuman dataset. The program's own parts are the command
//! line ([`cli`]), the build orchestration ([`build`]: scene groups in parallel with
//! resume, sharding and progress) and the LLM scene planner ([`llm_plan`]); the work
//! itself is done by the libraries: `rh-scenes` (scenes and labels), `rh-physics`,
//! `rh-render` (feature `render`, default) and `rh-dataset` (files). Without `render`
//! the program is label-only and links neither Vulkan nor FFmpeg. ARCHITECTURE.md has
//! the crate graph.

pub mod build;
pub mod cli;
pub mod llm_plan;
#[cfg(feature = "render")]
pub mod sheet;
