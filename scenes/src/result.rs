//! What the driver returns for one finished scene (plain data): the spec, its labels and
//! verdicts, the hashes, and after rendering its media.

use crate::label::Labels;
use crate::validate::Verdicts;
use rh_physics::spec::SceneSpec;

/// Everything the dataset needs about one finished scene.
#[derive(Debug, Clone)]
pub struct SceneResult {
    pub spec: SceneSpec,
    pub labels: Labels,
    pub verdicts: Verdicts,
    pub state_hash: String,
    /// The state hash of steps 0..=Δ (`Simulation::state_hash_through`).
    pub decision_state_hash: String,
    /// The hazard's centre of mass at each video frame: `[t, x, y, z]` until the scene ends.
    pub trajectory: Vec<[f32; 4]>,
    pub steps: u32,
    /// How far the event moves in the ego image between t = 0 and Δ (`ego::motion_px`;
    /// None without cameras).
    pub ego_motion_px: Option<f64>,
    /// The model-input frames (indices into `FRAME_TIMES`) before the hazard reaches the
    /// observer, where the renderer's measured ego pixels are checked (`ego::check_measured`).
    pub ego_checked_frames: Vec<usize>,
    /// What the render stage wrote (`None` until rendered, and for unrendered scenes).
    pub media: Option<SceneMedia>,
}

/// A rendered scene's files, relative to the dataset root.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneMedia {
    /// Camera name → `videos/<cam>/<scene_id>.mp4`.
    pub videos: std::collections::BTreeMap<String, String>,
    /// `videos/full/<scene_id>.mp4`.
    pub full_event: String,
    /// Camera name → the hazard measured in its observation frames (instance-id pass).
    pub visibility: std::collections::BTreeMap<String, HazardVisibility>,
    /// Camera name → `masks/<scene_id>/<cam>_t….png` at `FRAME_TIMES` (empty without
    /// `build --masks`).
    pub masks: std::collections::BTreeMap<String, Vec<String>>,
    /// Camera name → `depth/<scene_id>/<cam>_t….png` at `FRAME_TIMES` (likewise).
    pub depth: std::collections::BTreeMap<String, Vec<String>>,
}

/// The hazard as one camera's observation frames show it (one entry per `FRAME_TIMES`).
#[derive(Debug, Clone, PartialEq)]
pub struct HazardVisibility {
    /// Pixels of the image whose instance id is the hazard's.
    pub visible_px: Vec<u32>,
    /// `visible_px` over the pixels the hazard covers drawn alone (0 when it covers none).
    pub unoccluded: Vec<f64>,
}

impl HazardVisibility {
    /// From per-time (visible, covered-alone) pixel counts.
    pub fn from_counts(counts: &[(u32, u32)]) -> HazardVisibility {
        HazardVisibility {
            visible_px: counts.iter().map(|&(v, _)| v).collect(),
            unoccluded: counts
                .iter()
                .map(|&(v, c)| if c == 0 { 0.0 } else { v as f64 / c as f64 })
                .collect(),
        }
    }
}
