//! The ReactHuman data contract (specification §4, §8, §10), defined once and shared by the
//! builder (`rh-pipeline`: dataset writer and reader, dataset card) and the scorer
//! (`rh-score`: dataset reader, fixture, actions):
//!
//! * [`families`] — the seventeen event families, in canonical order;
//! * [`columns`] — the scene table's columns, their types, nullability and meaning;
//! * [`action`] — the three action primitives;
//! * [`camera`] — the head camera's calibration (intrinsics, pose in world and body frame);
//! * [`layout`] — where files live in a dataset directory (specs, videos, frames, data);
//! * [`digest`] — SHA-256 and hex, for fingerprints, file sums and cache keys;
//! * [`fsio`] — atomic file writing and the "cannot write" exit status; [`stdout`] —
//!   printing that never panics; [`progress`] — progress lines for logs (both programs).
//!
//! With the `arrow` feature, [`arrow_schema`] gives the Arrow schema of the scene table.
//! The crate has no heavy dependencies (serde; Arrow only behind the feature), so both
//! programs can depend on it without pulling in anything else.

pub mod action;
pub mod adapter;
pub mod camera;
pub mod columns;
pub mod digest;
pub mod execution;
pub mod families;
pub mod fsio;
pub mod layout;
#[cfg(feature = "png")]
pub mod png;
pub mod progress;
pub mod stdout;

#[cfg(feature = "arrow")]
pub mod arrow_schema;

pub use action::Action;
pub use columns::{Column, ColumnType, COLUMNS, VALIDATOR_COLUMNS};
pub use families::FAMILIES;
pub use layout::{CAMERAS, FRAME_TIMES, FULL_EVENT, SPEED_BANDS};
