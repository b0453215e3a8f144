//! The scene table (specification §8): one row per scene, its columns in order, each with its
//! type, nullability and meaning. The dataset writer builds its schema from [`COLUMNS`],
//! the dataset card its feature table, and both readers (builder and scorer) look
//! columns up by the names in [`col`].

/// A column's value type (see `arrow_schema` for the Arrow types).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    Utf8,
    Bool,
    UInt64,
    UInt32,
    Float64,
    /// Fixed-size list of 3 non-null float64: a point or pose.
    Vec3,
    /// List of strings.
    Utf8List,
    /// List of uint32.
    UInt32List,
    /// List of float64.
    Float64List,
    /// List of fixed-size lists of 4 non-null float32 (`[t, x, y, z]` samples).
    Vec4F32List,
    /// List of images, each a struct of the encoded file's `bytes` and its relative
    /// `path` (Hugging Face `datasets`' `Image` feature).
    ImageList,
}

/// One column of the scene table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    pub name: &'static str,
    pub ty: ColumnType,
    pub nullable: bool,
    /// What the column means (the dataset card's feature table).
    pub description: &'static str,
}

/// Column names, for readers and writers (`col::SCENE_ID == "scene_id"`).
pub mod col {
    pub const SCENE_ID: &str = "scene_id";
    pub const GROUP_ID: &str = "group_id";
    pub const SCENE_INDEX: &str = "scene_index";
    pub const SEED: &str = "seed";
    pub const ATTEMPT: &str = "attempt";
    pub const FAMILY: &str = "family";
    pub const SPEED_BAND: &str = "speed_band";
    pub const SPEED_SWEEP: &str = "speed_sweep";
    pub const SPEED_PARAMETER: &str = "speed_parameter";
    pub const SPEED_VALUE: &str = "speed_value";
    pub const OBJECT_ID: &str = "object_id";
    pub const OBJECT_NAME: &str = "object_name";
    pub const OBJECT_CATEGORY: &str = "object_category";
    pub const LOOKS_LIKE: &str = "looks_like";
    pub const ADVERSARIAL: &str = "adversarial";
    pub const TWIN_SCENE_ID: &str = "twin_scene_id";
    pub const OBJECT_MASS_KG: &str = "object_mass_kg";
    pub const HAZARDS: &str = "hazards";
    pub const ROOM: &str = "room";
    pub const DESCRIPTION: &str = "description";
    pub const GT_ACTION: &str = "gt_action";
    pub const DANGEROUS: &str = "dangerous";
    pub const DANGER_PRESENT: &str = "danger_present";
    pub const DANGER_REASONS: &str = "danger_reasons";
    pub const IMPACT_POINT: &str = "impact_point";
    pub const IMPACT_KIND: &str = "impact_kind";
    pub const TIME_TO_IMPACT: &str = "time_to_impact";
    pub const TIME_TO_FLOOR: &str = "time_to_floor";
    pub const IMPACT_SPEED: &str = "impact_speed";
    pub const CLOSEST_APPROACH: &str = "closest_approach";
    pub const TIME_TO_REACH: &str = "time_to_reach";
    pub const STRIKE_SPEED: &str = "strike_speed";
    pub const STRIKE_IMPULSE: &str = "strike_impulse";
    pub const HARM_REGION: &str = "harm_region";
    pub const HARM_ENERGY: &str = "harm_energy";
    pub const HARM_FORCE: &str = "harm_force";
    pub const HARM_RATIO: &str = "harm_ratio";
    pub const OBJECT_START: &str = "object_start";
    pub const OBSERVER_POSE: &str = "observer_pose";
    pub const EGO_FOV_Y: &str = "ego_fov_y";
    pub const EGO_FOV_X: &str = "ego_fov_x";
    pub const EGO_INTRINSICS: &str = "ego_intrinsics";
    pub const EGO_POSITION_BODY: &str = "ego_position_body";
    pub const EGO_YAW_BODY: &str = "ego_yaw_body";
    pub const EGO_PITCH_BODY: &str = "ego_pitch_body";
    pub const EGO_ROTATION_BODY: &str = "ego_rotation_body";
    pub const EGO_POSITION_WORLD: &str = "ego_position_world";
    pub const EGO_ROTATION_WORLD: &str = "ego_rotation_world";
    pub const EGO_MOTION_PX: &str = "ego_motion_px";
    pub const LABEL_RULE: &str = "label_rule";
    pub const STATE_HASH: &str = "state_hash";
    pub const DECISION_STATE_HASH: &str = "decision_state_hash";
    pub const SIM_STEPS: &str = "sim_steps";
    pub const VALID: &str = "valid";
    pub const VALID_NO_INTERPENETRATION: &str = "valid_no_interpenetration";
    pub const VALID_ENERGY: &str = "valid_energy";
    pub const VALID_NO_TUNNELLING: &str = "valid_no_tunnelling";
    pub const VALID_IN_FRAME: &str = "valid_in_frame";
    pub const VALID_VISIBLE: &str = "valid_visible";
    pub const VALID_INTENDED_EVENT: &str = "valid_intended_event";
    pub const VALID_REACTION_TIME: &str = "valid_reaction_time";
    pub const VALID_ESCAPABLE: &str = "valid_escapable";
    pub const VALID_MOTION: &str = "valid_motion";
    pub const SPEC_FILE: &str = "spec_file";
    pub const EGO_FILE_NAME: &str = "ego_file_name";
    pub const CLOSEUP_FILE_NAME: &str = "closeup_file_name";
    pub const OVERHEAD_FILE_NAME: &str = "overhead_file_name";
    pub const FULL_EVENT_FILE_NAME: &str = "full_event_file_name";
    pub const FRAME_STEPS: &str = "frame_steps";
    pub const TRAJECTORY: &str = "trajectory";
}

/// The validator verdict columns, in column order (each `true` when that check passed).
pub const VALIDATOR_COLUMNS: [&str; 9] = [
    col::VALID_NO_INTERPENETRATION,
    col::VALID_ENERGY,
    col::VALID_NO_TUNNELLING,
    col::VALID_IN_FRAME,
    col::VALID_VISIBLE,
    col::VALID_INTENDED_EVENT,
    col::VALID_REACTION_TIME,
    col::VALID_ESCAPABLE,
    col::VALID_MOTION,
];

/// The `<cam>_hazard_visible_px` column of a camera (`CAMERAS`).
pub fn visible_px_column(camera: &str) -> String {
    format!("{camera}_hazard_visible_px")
}

/// The `<cam>_hazard_unoccluded_fraction` column of a camera.
pub fn unoccluded_column(camera: &str) -> String {
    format!("{camera}_hazard_unoccluded_fraction")
}

/// The `<cam>_frames` column of a camera (the model-input frames as images).
pub fn frames_column(camera: &str) -> String {
    format!("{camera}_frames")
}

/// Whether a column is one of the `<cam>_frames` image columns.
pub fn is_frames_column(name: &str) -> bool {
    crate::layout::CAMERAS
        .iter()
        .any(|cam| frames_column(cam) == name)
}

/// The `<cam>_mask_paths` column of a camera (instance-id PNGs, `build --masks`).
pub fn mask_paths_column(camera: &str) -> String {
    format!("{camera}_mask_paths")
}

/// The `<cam>_depth_paths` column of a camera (depth PNGs, `build --masks`).
pub fn depth_paths_column(camera: &str) -> String {
    format!("{camera}_depth_paths")
}

/// The `<cam>_file_name` column of a camera (`CAMERAS`) or of `full_event`.
pub fn video_column(camera: &str) -> String {
    format!("{camera}_file_name")
}

const fn c(
    name: &'static str,
    ty: ColumnType,
    nullable: bool,
    description: &'static str,
) -> Column {
    Column {
        name,
        ty,
        nullable,
        description,
    }
}

use ColumnType::*;

/// Every column of the scene table, in order.
pub const COLUMNS: &[Column] = &[
    c(
        col::SCENE_ID,
        Utf8,
        false,
        "Stable scene id: 8 hex chars from SHA-256 of (build seed, scene index)",
    ),
    c(
        col::GROUP_ID,
        Utf8,
        false,
        "Scene group id; the four speed bands of a group share it and differ only in the speed parameter",
    ),
    c(
        col::SCENE_INDEX,
        UInt64,
        false,
        "Index of the scene in the build (scene i is band i mod 4 of group i div 4)",
    ),
    c(
        col::SEED,
        UInt64,
        false,
        "Build seed the scene was derived from",
    ),
    c(
        col::ATTEMPT,
        UInt32,
        false,
        "Resampling attempt that passed every validator (0 = first draw)",
    ),
    c(
        col::FAMILY,
        Utf8,
        false,
        "Event family (specification §4), e.g. object_drop, thrown_object",
    ),
    c(
        col::SPEED_BAND,
        Utf8,
        false,
        "slow, normal, fast or very_fast",
    ),
    c(
        col::SPEED_SWEEP,
        Bool,
        false,
        "Whether the family's pace follows the speed parameter (false: gravity sets it; excluded from speed analyses)",
    ),
    c(
        col::SPEED_PARAMETER,
        Utf8,
        false,
        "What the speed band sets for this family (e.g. launch speed)",
    ),
    c(
        col::SPEED_VALUE,
        Float64,
        false,
        "Value of the speed parameter in SI units",
    ),
    c(
        col::OBJECT_ID,
        Utf8,
        false,
        "Catalog id of the hazard object",
    ),
    c(
        col::OBJECT_NAME,
        Utf8,
        false,
        "Display name of the hazard object",
    ),
    c(
        col::OBJECT_CATEGORY,
        Utf8,
        false,
        "Catalog category of the hazard object",
    ),
    c(
        col::LOOKS_LIKE,
        Utf8,
        true,
        "For adversarial objects: the catalog id it is rendered exactly as; null otherwise",
    ),
    c(
        col::ADVERSARIAL,
        Bool,
        false,
        "The object looks like another one but has its own physics (e.g. a foam anvil)",
    ),
    c(
        col::TWIN_SCENE_ID,
        Utf8,
        true,
        "Adversarial probe pair (label rule v5): the scene that is this one's spec with only the object replaced by its look-alike (or back); null outside probe pairs",
    ),
    c(
        col::OBJECT_MASS_KG,
        Float64,
        false,
        "True mass of the hazard (kg)",
    ),
    c(
        col::HAZARDS,
        Utf8List,
        false,
        "Hazard flags of the object's true physics: sharp, hot, heavy, fragile, large",
    ),
    c(
        col::ROOM,
        Utf8,
        false,
        "Room id from the catalog",
    ),
    c(
        col::DESCRIPTION,
        Utf8,
        true,
        "Free-text description the scene was planned from; null when none",
    ),
    c(
        col::GT_ACTION,
        Utf8,
        false,
        "Ground-truth action: CATCH, DODGE or NO_ACTION (label rule below)",
    ),
    c(
        col::DANGEROUS,
        Bool,
        false,
        "The object is dangerous by its true physical properties (rule below)",
    ),
    c(
        col::DANGER_PRESENT,
        Bool,
        false,
        "The hazard would harm the observer standing still (counterfactual simulation; label rule v5: a touch over the per-body-region limits of ISO/TS 15066 Annex A, or any touch of a sharp or hot hazard; rule below)",
    ),
    c(
        col::DANGER_REASONS,
        Utf8List,
        false,
        "Why `dangerous` holds (sharp, hot, large_fragile, heavy_mass, momentum); empty if not",
    ),
    c(
        col::IMPACT_POINT,
        Vec3,
        true,
        "World [x, y, z] (m) of the hazard's centre of mass where it meets the observer at or after the decision moment Δ: the interception in the reach envelope, else the closest approach within the limit; null if none (rule below)",
    ),
    c(
        col::IMPACT_KIND,
        Utf8,
        true,
        "envelope or closest_approach: how `impact_point` was found; null if none",
    ),
    c(
        col::TIME_TO_IMPACT,
        Float64,
        true,
        "Seconds from the event onset (t = 0) to the impact point (at least Δ + the reaction minimum in a valid scene); null if none",
    ),
    c(
        col::TIME_TO_FLOOR,
        Float64,
        true,
        "Seconds from the onset to the hazard's first floor contact (for a body that starts on the floor: its top first touching the floor); null if none",
    ),
    c(
        col::IMPACT_SPEED,
        Float64,
        true,
        "Speed of the hazard's centre of mass at the impact point (m/s); null if none",
    ),
    c(
        col::CLOSEST_APPROACH,
        Float64,
        false,
        "Closest distance of the hazard's centre of mass to the observer's torso axis at or after Δ (m)",
    ),
    c(
        col::TIME_TO_REACH,
        Float64,
        true,
        "Seconds from the onset to when the hazard first reaches the observer over the whole run (interception, closest approach within reach, or a strike); null if never",
    ),
    c(
        col::STRIKE_SPEED,
        Float64,
        true,
        "Counterfactual (observer standing still, label rule v3: the humanoid's rest-pose links): largest speed of the hazard's contact point relative to the body over the harm test's window — the harming one, else the first touch's (m/s); null if it never touches the body",
    ),
    c(
        col::STRIKE_IMPULSE,
        Float64,
        true,
        "Counterfactual: impulse the standing body receives within the strike window — the strike's, else the first touch's (N·s); null if never touched",
    ),
    c(
        col::HARM_REGION,
        Utf8,
        true,
        "Counterfactual, same window (label rule v5): the body region of ISO/TS 15066 Annex A that came closest to (or over) its limits — skull_forehead, face, neck, back_shoulders, chest, abdomen, pelvis, upper_arm, forearm, hand, thigh, lower_leg; null if never touched",
    ),
    c(
        col::HARM_ENERGY,
        Float64,
        true,
        "Counterfactual: largest transient energy of a touch of that region, ½ μ v² (μ the reduced mass of the hazard's effective mass and the region's, v the contact point's normal speed) (J); null if never touched",
    ),
    c(
        col::HARM_FORCE,
        Float64,
        true,
        "Counterfactual: sustained force on that region, its impulse over the window divided by the window's length (N); null if never touched",
    ),
    c(
        col::HARM_RATIO,
        Float64,
        true,
        "Counterfactual: the larger of harm_energy and harm_force over the region's permissible transient energy and quasi-static force (≥ 1: harm); null if never touched",
    ),
    c(
        col::OBJECT_START,
        Vec3,
        false,
        "Hazard's centre at t = 0, world [x, y, z] (m)",
    ),
    c(
        col::OBSERVER_POSE,
        Vec3,
        false,
        "Observer on the floor: [x (m), y (m), yaw (rad)]",
    ),
    c(
        col::EGO_FOV_Y,
        Float64,
        true,
        "Head (`ego`) camera, a pinhole without distortion (the calibration the prompt states): vertical field of view (rad); null when the scene has no cameras",
    ),
    c(
        col::EGO_FOV_X,
        Float64,
        true,
        "Head camera: horizontal field of view (rad), 2·atan(tan(ego_fov_y / 2)·width / height)",
    ),
    c(
        col::EGO_INTRINSICS,
        Float64List,
        true,
        "Head camera intrinsics [fx, fy, cx, cy] (px, at the frames' resolution 2cx × 2cy): pixel u = fx·x/z + cx (right), v = fy·y/z + cy (down, from the top-left corner) of the camera-frame point [x, y, z] (x right, y down, z forward)",
    ),
    c(
        col::EGO_POSITION_BODY,
        Vec3,
        true,
        "Head camera's optical centre in the body frame (origin at the pelvis, x forward, y left, z up; m)",
    ),
    c(
        col::EGO_YAW_BODY,
        Float64,
        true,
        "Head camera's optical axis in the body frame: yaw from the body's forward axis (rad, positive to the left); the camera never rolls",
    ),
    c(
        col::EGO_PITCH_BODY,
        Float64,
        true,
        "Head camera's optical axis: pitch above the horizontal (rad, negative looking down)",
    ),
    c(
        col::EGO_ROTATION_BODY,
        Float64List,
        true,
        "Head camera orientation in the body frame: 3 × 3 row-major matrix R whose columns are the camera's x, y, z axes; a body-frame point p is at Rᵀ(p − ego_position_body) in camera coordinates",
    ),
    c(
        col::EGO_POSITION_WORLD,
        Vec3,
        true,
        "Head camera's optical centre in the world frame (m)",
    ),
    c(
        col::EGO_ROTATION_WORLD,
        Float64List,
        true,
        "Head camera orientation in the world frame: as ego_rotation_body (columns = camera axes), a world point p is at Rᵀ(p − ego_position_world)",
    ),
    c(
        col::EGO_MOTION_PX,
        Float64,
        true,
        "How far the event moves in the head camera's image between t = 0 and Δ (px at the frames' resolution): the largest displacement of a point sampled on the hazard's (or a moving prop's, e.g. a chain's trigger) collision shapes; validator `valid_motion` needs `validators.motion_px_min`; null without cameras",
    ),
    c(
        col::LABEL_RULE,
        Utf8,
        false,
        "Version of the label rule that produced the labels",
    ),
    c(
        col::STATE_HASH,
        Utf8,
        false,
        "SHA-256 (first 16 bytes, hex) of every dynamic body's state at every physics step; `rh-pipeline verify` replays specs against it",
    ),
    c(
        col::DECISION_STATE_HASH,
        Utf8,
        false,
        "The same hash over steps 0 to the decision moment Δ only (or to sim_steps if the scene ended earlier); `rh-score --execute` checks its replay up to Δ against it",
    ),
    c(
        col::SIM_STEPS,
        UInt32,
        false,
        "Physics steps simulated (240 Hz)",
    ),
    c(
        col::VALID,
        Bool,
        false,
        "Every validator passed (invalid scenes are kept, visible, and not scored)",
    ),
    c(
        col::VALID_NO_INTERPENETRATION,
        Bool,
        false,
        "Validator: no two bodies overlap at t = 0 beyond tolerance",
    ),
    c(
        col::VALID_ENERGY,
        Bool,
        false,
        "Validator: total mechanical energy never rises beyond tolerance",
    ),
    c(
        col::VALID_NO_TUNNELLING,
        Bool,
        false,
        "Validator: the hazard never sinks through the floor",
    ),
    c(
        col::VALID_IN_FRAME,
        Bool,
        false,
        "Validator: the hazard stays in all three cameras' frames during the observation window",
    ),
    c(
        col::VALID_VISIBLE,
        Bool,
        false,
        "Validator: every camera sees enough of the hazard (share of sample points on its collision shapes in the image and in sight, past fixed bodies and the observer's body), large enough in pixels, during the observation window; and every model-input ego frame before the hazard reaches the observer shows it with at least `validators.visible_px_min` pixels times a safety factor (ray-cast estimate over its shrunk shapes; the renderer checks its measured pixels)",
    ),
    c(
        col::VALID_INTENDED_EVENT,
        Bool,
        false,
        "Validator: the family's intended event really happened",
    ),
    c(
        col::VALID_REACTION_TIME,
        Bool,
        false,
        "Validator: the hazard reaches the observer no earlier than Δ plus the minimum reaction time (label rule v2)",
    ),
    c(
        col::VALID_ESCAPABLE,
        Bool,
        false,
        "Validator: a DODGE scene whose hazard would strike the standing body has an escape walk that physics does not strike (label rule v4)",
    ),
    c(
        col::VALID_MOTION,
        Bool,
        false,
        "Validator: the event is under way in the window: `ego_motion_px` is at least `validators.motion_px_min`",
    ),
    c(
        col::SPEC_FILE,
        Utf8,
        false,
        "Relative path of the scene's full, replayable SceneSpec JSON",
    ),
    c(
        col::EGO_FILE_NAME,
        Utf8,
        true,
        "Relative path `videos/ego/<scene_id>.mp4` of the `ego` camera's observation-window video; null when not rendered (`--no-render`, or an invalid scene)",
    ),
    c(
        col::CLOSEUP_FILE_NAME,
        Utf8,
        true,
        "Relative path `videos/closeup/<scene_id>.mp4` of the `closeup` camera's observation-window video; null when not rendered (`--no-render`, or an invalid scene)",
    ),
    c(
        col::OVERHEAD_FILE_NAME,
        Utf8,
        true,
        "Relative path `videos/overhead/<scene_id>.mp4` of the `overhead` camera's observation-window video; null when not rendered (`--no-render`, or an invalid scene)",
    ),
    c(
        col::FULL_EVENT_FILE_NAME,
        Utf8,
        true,
        "Relative path of the full-event MP4 from an outside view, for people (never model input): `videos/full/<scene_id>.mp4`; null when not rendered (`--no-render`, or an invalid scene)",
    ),
    c(
        col::FRAME_STEPS,
        UInt32List,
        false,
        "Physics step shown by each frame k of the camera videos (observation window, both ends included): round(k / video.fps / physics.dt), at most sim_steps",
    ),
    c(
        col::TRAJECTORY,
        Vec4F32List,
        false,
        "Hazard centre of mass [t (s), x, y, z (m)] over the whole simulation (t = 0 to its last step), sampled at the video rate (every 1/fps s, physics step round(t / dt)); the first entries, t ≤ the observation window, match the camera videos' frames (float32)",
    ),
    c(
        "ego_hazard_visible_px",
        UInt32List,
        true,
        "Measured by the renderer's instance-id pass: pixels of the `ego` camera's image that show the hazard at each observation time t = 0, 0.15, 0.30, 0.45, 0.60 s (one value per time; the PNG frames' times); null when not rendered",
    ),
    c(
        "closeup_hazard_visible_px",
        UInt32List,
        true,
        "Measured by the renderer's instance-id pass: pixels of the `closeup` camera's image that show the hazard at each observation time t = 0, 0.15, 0.30, 0.45, 0.60 s (one value per time; the PNG frames' times); null when not rendered",
    ),
    c(
        "overhead_hazard_visible_px",
        UInt32List,
        true,
        "Measured by the renderer's instance-id pass: pixels of the `overhead` camera's image that show the hazard at each observation time t = 0, 0.15, 0.30, 0.45, 0.60 s (one value per time; the PNG frames' times); null when not rendered",
    ),
    c(
        "ego_hazard_unoccluded_fraction",
        Float64List,
        true,
        "Per observation time: `ego_hazard_visible_px` divided by the pixels the hazard covers in the `ego` image when drawn with nothing else (1 = nothing in front of it; 0 when it covers no pixel of the image); null when not rendered",
    ),
    c(
        "closeup_hazard_unoccluded_fraction",
        Float64List,
        true,
        "Per observation time: `closeup_hazard_visible_px` divided by the pixels the hazard covers in the `closeup` image when drawn with nothing else (1 = nothing in front of it; 0 when it covers no pixel of the image); null when not rendered",
    ),
    c(
        "overhead_hazard_unoccluded_fraction",
        Float64List,
        true,
        "Per observation time: `overhead_hazard_visible_px` divided by the pixels the hazard covers in the `overhead` image when drawn with nothing else (1 = nothing in front of it; 0 when it covers no pixel of the image); null when not rendered",
    ),
    c(
        "ego_mask_paths",
        Utf8List,
        true,
        "Relative paths `masks/<scene_id>/ego_t0.000.png` … `_t0.600.png`: 16-bit instance-id images of the `ego` observation frames (0 = room and background, i + 1 = spec body i, 65534 = ropes, 65535 = observer); null unless built with `--masks`",
    ),
    c(
        "closeup_mask_paths",
        Utf8List,
        true,
        "Relative paths `masks/<scene_id>/closeup_t0.000.png` … `_t0.600.png`: 16-bit instance-id images of the `closeup` observation frames (0 = room and background, i + 1 = spec body i, 65534 = ropes, 65535 = observer); null unless built with `--masks`",
    ),
    c(
        "overhead_mask_paths",
        Utf8List,
        true,
        "Relative paths `masks/<scene_id>/overhead_t0.000.png` … `_t0.600.png`: 16-bit instance-id images of the `overhead` observation frames (0 = room and background, i + 1 = spec body i, 65534 = ropes, 65535 = observer); null unless built with `--masks`",
    ),
    c(
        "ego_depth_paths",
        Utf8List,
        true,
        "Relative paths `depth/<scene_id>/ego_t0.000.png` … `_t0.600.png`: 16-bit depth images of the `ego` observation frames, Euclidean distance from the camera centre in millimetres (0 = no surface); null unless built with `--masks`",
    ),
    c(
        "closeup_depth_paths",
        Utf8List,
        true,
        "Relative paths `depth/<scene_id>/closeup_t0.000.png` … `_t0.600.png`: 16-bit depth images of the `closeup` observation frames, Euclidean distance from the camera centre in millimetres (0 = no surface); null unless built with `--masks`",
    ),
    c(
        "overhead_depth_paths",
        Utf8List,
        true,
        "Relative paths `depth/<scene_id>/overhead_t0.000.png` … `_t0.600.png`: 16-bit depth images of the `overhead` observation frames, Euclidean distance from the camera centre in millimetres (0 = no surface); null unless built with `--masks`",
    ),
    c(
        "ego_frames",
        ImageList,
        true,
        "The `ego` model-input frames at t = 0.000 … 0.600 s as images (`datasets` `Image`: the PNG bytes of `frames/<scene_id>/ego_t….png` and that path), in time order; what `rh-score predict` sends; null when not rendered",
    ),
    c(
        "closeup_frames",
        ImageList,
        true,
        "The `closeup` model-input frames at t = 0.000 … 0.600 s as images (`datasets` `Image`: the PNG bytes of `frames/<scene_id>/closeup_t….png` and that path), in time order; null when not rendered",
    ),
    c(
        "overhead_frames",
        ImageList,
        true,
        "The `overhead` model-input frames at t = 0.000 … 0.600 s as images (`datasets` `Image`: the PNG bytes of `frames/<scene_id>/overhead_t….png` and that path), in time order; null when not rendered",
    ),
];

/// The column called `name`.
pub fn column(name: &str) -> Option<&'static Column> {
    COLUMNS.iter().find(|c| c.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::CAMERAS;

    #[test]
    fn names_are_unique_and_every_video_and_validator_column_exists() {
        for (i, a) in COLUMNS.iter().enumerate() {
            assert!(
                COLUMNS[i + 1..].iter().all(|b| b.name != a.name),
                "{}",
                a.name
            );
            assert!(!a.description.is_empty(), "{}", a.name);
        }
        for cam in CAMERAS.iter().chain(&["full_event"]) {
            let c = column(&video_column(cam)).unwrap();
            assert!(c.nullable && c.ty == Utf8);
        }
        for v in VALIDATOR_COLUMNS {
            assert_eq!(column(v).unwrap().ty, Bool);
        }
        for cam in CAMERAS {
            assert_eq!(column(&visible_px_column(cam)).unwrap().ty, UInt32List);
            assert_eq!(column(&unoccluded_column(cam)).unwrap().ty, Float64List);
            assert_eq!(column(&mask_paths_column(cam)).unwrap().ty, Utf8List);
            assert_eq!(column(&depth_paths_column(cam)).unwrap().ty, Utf8List);
        }
    }
}
