//! ReactHuman dataset builder: the staged DAG `plan → randomize → simulate → render →
//! label` (render is a later stage), dataset writing, and replay verification.
//!
//! Each stage is a module with one entry point over plain data:
//! `plan::plan_group` / `plan::LexiconPlanner`, `randomize::randomize`,
//! `simulate::simulate`, `label::label`; `scene::produce_group` chains them for one
//! scene group, and `build::build` runs the groups in parallel.

pub mod balance;
pub mod build;
pub mod cameras;
pub mod card;
pub mod cli;
pub mod config;
pub mod dataset;
pub mod families;
pub mod integrity;
pub mod label;
pub mod manifest;
pub mod merge;
pub mod plan;
pub mod randomize;
pub mod render;
pub mod scene;
pub mod seeds;
pub mod simulate;
pub mod spec;
pub mod validate;
pub mod verify;
