//! `--execute` and `--execute-videos` (specification §12): the executor's plain data is the core's
//! ([`rh_grade::execution`], re-exported here); running plans in physics with the outcome
//! cache and the replay check against the dataset's hashes ([`run`]), the oracle's
//! physics-checked dodges ([`dodges`]) and the execution videos ([`videos`]) link the
//! simulator and the renderer, so they live here.

pub use rh_grade::execution::*;

#[cfg(feature = "execute")]
pub mod dodges;
#[cfg(feature = "execute")]
mod run;
#[cfg(feature = "videos")]
pub mod videos;

#[cfg(feature = "execute")]
pub use dodges::physics_dodges_of;
#[cfg(feature = "execute")]
pub use run::{cache_key, execute_all};
#[cfg(feature = "execute")]
pub use run::{checked_replay, replay_key};
