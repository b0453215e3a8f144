//! ReactHuman scenes: from a seed to labelled, validated scene specs, without file I/O.
//!
//! The stages, each a module with one entry point over plain data:
//! [`selection::plan_group`] (what a scene group shows) → [`randomize::randomize`]
//! (its `SceneSpec`, one per speed band) → `rh_physics::simulate` → [`aim::aim_group`]
//! (the observer stands on the hazard's path) → [`cameras::frame`]
//! → [`label::label`] (ground truth from the counterfactual run,
//! [`counterfactual::counterfactual_run`]) →
//! [`validate::validate`] (one verdict per validator column). [`driver::run_group`] chains
//! them for a group and hands each valid scene to a render stage given as a plain
//! function. [`config::Config`] is the build policy (`configs/default.toml` +
//! `configs/labels.toml`); [`families`] holds one file per event family behind one trait.

pub mod aim;
pub mod balance;
pub mod cameras;
pub mod config;
pub mod counterfactual;
pub mod decor;
pub mod driver;
pub mod ego;
pub mod eval_subset;
pub mod families;
pub mod intent;
pub mod label;
pub mod randomize;
pub mod result;
pub mod selection;
pub mod shared;
pub mod twins;
pub mod validate;
pub mod view;
pub mod visibility;
