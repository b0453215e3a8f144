//! `--execute` (specification §12): model plans executed in physics. The executor's plain
//! data is the core's ([`rh_grade::execution`], re-exported here); running plans with the
//! outcome cache and the replay check against the dataset's hashes ([`run`]), the
//! oracle's physics-checked dodges ([`dodges`]) and the scored decisions' outcomes
//! ([`execute_scored`]) link the simulator, so they live here, next to physics. The
//! execution videos are rh-execute-videos' (the renderer), handed in as a [`DrawVideos`].

pub use rh_grade::execution::*;

pub mod dodges;
mod run;
mod scored;

pub use dodges::physics_dodges_of;
pub use run::{cache_key, checked_replay, execute_all, replay_key};
pub use scored::{execute_scored, DrawVideos};
