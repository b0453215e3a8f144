//! Where things live in a dataset directory (specification §8), relative to its root:
//!
//! ```text
//! build.json                          the build manifest
//! data/test-00000-of-00001.parquet    the scene table (`columns`)
//! eval/…                              the evaluation subset (whole builds)
//! specs/<scene_id>.json               full, replayable scene specs
//! videos/<cam>/<scene_id>.mp4         observation-window videos (`CAMERAS`)
//! videos/full/<scene_id>.mp4          the full-event video (for people)
//! frames/<scene_id>/<cam>_t0.150.png  observation frames at `FRAME_TIMES`
//! masks/<scene_id>/<cam>_t0.150.png   16-bit instance ids of those frames (`build --masks`)
//! depth/<scene_id>/<cam>_t0.150.png   16-bit depth in millimetres of those frames (`--masks`)
//! ```
//!
//! Instance ids of the masks ([`instance`]): 0 = the room (floor, walls, ceiling) and
//! empty background; `i + 1` = the spec's body `bodies[i]` (so the hazard is
//! `hazard + 1`); [`instance::ROPE`] = ropes and rods drawn along joints;
//! [`instance::OBSERVER`] = the observer's body.

/// The cameras whose videos are model input, in column order.
pub const CAMERAS: [&str; 3] = ["ego", "closeup", "overhead"];
/// Name of the full-event video's folder under `videos/`.
pub const FULL_EVENT: &str = "full";
/// Observation frames written as PNG per camera (seconds after t0).
pub const FRAME_TIMES: [f64; 5] = [0.0, 0.15, 0.30, 0.45, 0.60];
/// The speed bands of specification §4, slowest first (the `speed_band` values).
pub const SPEED_BANDS: [&str; 4] = ["slow", "normal", "fast", "very_fast"];

/// `specs/<scene_id>.json`
pub fn spec_path(scene_id: &str) -> String {
    format!("specs/{scene_id}.json")
}

/// `videos/<cam>/<scene_id>.mp4` (`cam` is one of `CAMERAS` or `FULL_EVENT`).
pub fn video_path(camera: &str, scene_id: &str) -> String {
    format!("videos/{camera}/{scene_id}.mp4")
}

/// `<cam>_t0.150.png`
pub fn frame_file_name(camera: &str, t: f64) -> String {
    format!("{camera}_t{t:.3}.png")
}

/// `frames/<scene_id>/<cam>_t0.150.png`
pub fn frame_path(scene_id: &str, camera: &str, t: f64) -> String {
    format!("frames/{scene_id}/{}", frame_file_name(camera, t))
}

/// `masks/<scene_id>/<cam>_t0.150.png`: the instance-id image of an observation frame.
pub fn mask_path(scene_id: &str, camera: &str, t: f64) -> String {
    format!("masks/{scene_id}/{}", frame_file_name(camera, t))
}

/// `depth/<scene_id>/<cam>_t0.150.png`: the depth image (mm) of an observation frame.
pub fn depth_path(scene_id: &str, camera: &str, t: f64) -> String {
    format!("depth/{scene_id}/{}", frame_file_name(camera, t))
}

/// The instance ids of the segmentation masks (`masks/…png`, 16-bit grey).
pub mod instance {
    /// The room shell (floor, walls, ceiling) and empty background.
    pub const ROOM: u16 = 0;
    /// Ropes and rods drawn along the spec's joints (no body of their own).
    pub const ROPE: u16 = 65534;
    /// The observer's body (absent from the ego camera, which sits in its head).
    pub const OBSERVER: u16 = 65535;

    /// The id of the spec's body `bodies[index]`: `index + 1`.
    pub fn body(index: usize) -> u16 {
        assert!(
            index + 1 < ROPE as usize,
            "body index {index} has no instance id"
        );
        (index + 1) as u16
    }
}

/// Depth images: millimetres per unit (`depth/…png` holds round(distance · 1000), the
/// Euclidean distance from the camera centre; 0 = no surface, 65535 = 65.535 m or more).
pub const DEPTH_UNITS_PER_M: f64 = 1000.0;

/// A rendered scene's observation frames, camera-major, times in `FRAME_TIMES` order.
pub fn frame_files(scene_id: &str) -> Vec<String> {
    CAMERAS
        .iter()
        .flat_map(|cam| {
            FRAME_TIMES
                .iter()
                .map(move |&t| frame_path(scene_id, cam, t))
        })
        .collect()
}

/// The `data/` file of shard `i` of `n` (Hugging Face convention).
pub fn data_file_name(i: usize, n: usize) -> String {
    format!("data/test-{i:05}-of-{n:05}.parquet")
}
