//! ReactHuman dataset files (specification §8).
//!
//! Always: [`table`] — the scene table's Arrow schema, its Parquet writer settings and
//! reading it back; [`stream`] — a Parquet file written row group by row group;
//! [`manifest`] — reading `build.json` (writing one needs `write`); [`release`] — the
//! canonical release (`configs/release.toml`), the dataset fingerprint, download checks.
//! With feature `write` (default): [`rows`] (scene rows from scene results),
//! [`camera_columns`] (the head camera's calibration and motion columns),
//! [`media_columns`] (the measured-visibility and mask columns), [`integrity`] (SHA-256 sums), [`records`] (finished scene groups of a
//! running build), [`finalize`] (data, eval subset, card and sums from the rows),
//! [`card`] (the dataset card), [`merge`] (shards into one dataset) and [`verify`].

pub mod frames;
pub mod manifest;
pub mod read;
pub mod release;
pub mod stream;
pub mod table;

#[cfg(feature = "write")]
pub mod camera_columns;
#[cfg(feature = "write")]
pub mod card;
#[cfg(feature = "write")]
pub mod card_credits;
#[cfg(feature = "write")]
pub mod card_teaser;
#[cfg(feature = "write")]
pub mod finalize;
#[cfg(feature = "write")]
pub mod integrity;
#[cfg(feature = "write")]
pub mod media_columns;
#[cfg(feature = "write")]
pub mod merge;
#[cfg(feature = "write")]
pub mod records;
#[cfg(feature = "write")]
pub mod rows;
#[cfg(feature = "write")]
pub mod verify;
