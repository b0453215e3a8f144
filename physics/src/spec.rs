//! `SceneSpec` v1 (specification §3): the JSON document that fully determines a scene.
//!
//! Everything the simulator needs is here in plain numbers, so `simulate(&spec)`
//! replays a scene bit for bit in any process. Floats are f64 in the file (serde_json
//! with exact round-tripping) and converted to rapier's f32 at one place.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub const SCHEMA_VERSION: u32 = 1;

pub type Vec3 = [f64; 3];
/// Unit quaternion `[x, y, z, w]`.
pub type Quat = [f64; 4];
pub const IDENTITY: Quat = [0.0, 0.0, 0.0, 1.0];

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedBand {
    Slow,
    Normal,
    Fast,
    VeryFast,
}

impl SpeedBand {
    pub const ALL: [SpeedBand; 4] = [
        SpeedBand::Slow,
        SpeedBand::Normal,
        SpeedBand::Fast,
        SpeedBand::VeryFast,
    ];

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn name(self) -> &'static str {
        match self {
            SpeedBand::Slow => "slow",
            SpeedBand::Normal => "normal",
            SpeedBand::Fast => "fast",
            SpeedBand::VeryFast => "very_fast",
        }
    }
}

/// The planner's semantic choice (specification §3: the planner never sets a number).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Selection {
    pub family: String,
    pub object_id: String,
    pub room_id: String,
    /// The free-text description the selection came from, if any.
    #[serde(default)]
    pub description: Option<String>,
    /// Which planner chose it from the description, when a model was asked (absent for
    /// the embedded and the plain lexicon planner, so their specs are unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planner: Option<PlannerRecord>,
}

/// How an LLM-planned selection came about (stored in the spec).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannerRecord {
    /// "llm" when the model's selection was used; "lexicon" when the lexicon planner
    /// decided after the model gave no valid selection.
    pub planner: String,
    /// The model asked.
    pub model: Option<String>,
    /// The planner prompt's version (configs/planner.toml).
    pub version: Option<String>,
    /// Requests made to reach the answer (or given up after).
    pub tries: u32,
    /// Why the lexicon planner decided instead of the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ShapeSpec {
    Box {
        half_extents: Vec3,
    },
    Sphere {
        radius: f64,
    },
    /// Axis along the part's local z.
    Cylinder {
        half_height: f64,
        radius: f64,
    },
    /// Axis along the part's local z; `half_height` excludes the caps.
    Capsule {
        half_height: f64,
        radius: f64,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    pub shape: ShapeSpec,
    /// Pose of the part in the body frame.
    pub offset: Vec3,
    pub rotation: Quat,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyKind {
    Fixed,
    Dynamic,
}

/// What a body is for; the labeler and renderer read it, physics ignores it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyRole {
    /// The object the labels are about.
    Hazard,
    /// Furniture and fixtures the event happens on (tables, shelves, ramps, mounts).
    Support,
    /// Other moving objects (triggers, neighbours in a row).
    Prop,
    /// Furniture, fixtures, windows and doors that furnish the room (specification §3,
    /// "Decor"): fixed, placed clear of the event; `catalog_id` names the decor piece.
    /// A decor body without parts (a window, a door in the wall plane) is drawn only.
    Decor,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    pub role: BodyRole,
    pub kind: BodyKind,
    /// Catalog id for catalog objects; furniture has none.
    #[serde(default)]
    pub catalog_id: Option<String>,
    pub parts: Vec<PartSpec>,
    pub position: Vec3,
    pub rotation: Quat,
    /// Total mass (kg), spread over the parts by volume. Ignored for fixed bodies.
    pub mass: f64,
    pub friction: f64,
    pub restitution: f64,
    pub linvel: Vec3,
    pub angvel: Vec3,
    /// Continuous collision detection for fast bodies.
    pub ccd: bool,
    /// The launch is a push (label rule v6): `linvel` and `angvel` are what the push gives
    /// a body of this mass, so this body starts at them scaled by `push_mass / mass` — the
    /// same impulse (and, for the same shape, the same angular impulse) on a lighter or
    /// heavier body. Absent: the body starts at `linvel` and `angvel` as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub push_mass: Option<f64>,
}

impl ShapeSpec {
    /// Radius of the smallest sphere around the shape's centre holding it.
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            ShapeSpec::Box { half_extents: h } => (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt(),
            ShapeSpec::Sphere { radius } => radius,
            ShapeSpec::Cylinder {
                half_height,
                radius,
            } => (half_height * half_height + radius * radius).sqrt(),
            ShapeSpec::Capsule {
                half_height,
                radius,
            } => half_height + radius,
        }
    }
}

impl BodySpec {
    /// The factor the push scales the initial velocities by (`push_mass / mass`; 1 without
    /// a push, for a fixed body, or where the masses agree).
    pub fn push_scale(&self) -> f64 {
        match self.push_mass {
            Some(m) if self.kind == BodyKind::Dynamic && m != self.mass && self.mass > 0.0 => {
                m / self.mass
            }
            _ => 1.0,
        }
    }

    /// Radius of the smallest sphere around the body's origin holding all its parts.
    pub fn bounding_radius(&self) -> f64 {
        self.parts
            .iter()
            .map(|p| {
                let o = p.offset;
                (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt() + p.shape.bounding_radius()
            })
            .fold(0.0, f64::max)
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum JointKind {
    /// Hinge about `axis` (in both bodies' frames).
    Revolute {
        axis: Vec3,
    },
    Spherical,
    /// Keeps the anchors at most `max_length` apart.
    Rope {
        max_length: f64,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    pub kind: JointKind,
    /// Body indices; `None` for `body_a` means the world (a fixed anchor at `anchor_a`).
    pub body_a: Option<usize>,
    pub body_b: usize,
    pub anchor_a: Vec3,
    pub anchor_b: Vec3,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoomSpec {
    pub id: String,
    pub size: [f64; 2],
    pub ceiling_height: f64,
    pub floor_friction: f64,
    pub floor_restitution: f64,
    pub wall_color: String,
    pub floor_color: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserverSpec {
    pub x: f64,
    pub y: f64,
    /// Heading about +z (rad); the observer faces the event.
    pub yaw: f64,
    pub height: f64,
    pub pelvis_z: f64,
    pub shoulder_z: f64,
    pub torso_radius: f64,
}

impl ObserverSpec {
    /// Distance from a point to the observer's torso axis: the vertical segment from the
    /// floor to the top of the head.
    pub fn torso_axis_distance(&self, p: Vec3) -> f64 {
        let dz = if p[2] < 0.0 {
            -p[2]
        } else if p[2] > self.height {
            p[2] - self.height
        } else {
            0.0
        };
        ((p[0] - self.x).powi(2) + (p[1] - self.y).powi(2) + dz * dz).sqrt()
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    pub name: String,
    pub position: Vec3,
    pub look_at: Vec3,
    /// Vertical field of view (rad).
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
}

/// Video settings; video frame `k` shows physics step `frame_step(k)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VideoSpec {
    pub width: u32,
    pub height: u32,
    pub fps: u32,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingSpec {
    /// Direction the sun light travels (unit vector, pointing down).
    pub sun_direction: Vec3,
    pub sun_intensity: f64,
    pub ambient: f64,
    pub color_temperature_k: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicsSpec {
    pub dt: f64,
    pub gravity: Vec3,
    pub solver_iterations: usize,
    pub min_steps: u32,
    pub max_steps: u32,
    pub settle_speed: f64,
    pub settle_steps: u32,
    /// Quadratic air drag on large light bodies (label rule v6); absent: none (specs
    /// before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag: Option<DragSpec>,
}

/// Quadratic air drag, `F = -½ ρ C_d A(v̂) |v| v` through the centre of mass every step,
/// `A(v̂)` the body's area projected along its velocity (the sum over its parts). Applied
/// to a dynamic body only when its terminal speed with its largest projected area,
/// `sqrt(2 m g / (ρ C_d A_max))`, is below `terminal_speed_max`: large light bodies, for
/// which it decides what the window shows (a foam ceiling panel falls slower than the
/// real one); for dense bodies it is below the solver's own error over a scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DragSpec {
    /// kg/m³.
    pub air_density: f64,
    /// Drag coefficient of spheres and capsules.
    pub sphere_coefficient: f64,
    /// Drag coefficient of boxes and cylinders (a flat plate broadside ≈ 1.1).
    pub flat_coefficient: f64,
    /// m/s.
    pub terminal_speed_max: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    pub schema_version: u32,
    pub scene_id: String,
    pub group_id: String,
    pub build_seed: u64,
    pub scene_index: u64,
    /// The group's randomization seed (shared by its four speed bands).
    pub seed: u64,
    /// Rejection-sampling attempt that produced this scene (0 = first try).
    pub attempt: u32,
    pub family: String,
    pub speed_band: SpeedBand,
    pub speed_sweep: bool,
    pub speed_parameter: String,
    pub speed_value: f64,
    pub selection: Selection,
    pub room: RoomSpec,
    pub physics: PhysicsSpec,
    pub bodies: Vec<BodySpec>,
    pub joints: Vec<JointSpec>,
    /// Index of the hazard body in `bodies`.
    pub hazard: usize,
    /// The body whose separation from the hazard marks the event's start (e.g. the table).
    #[serde(default)]
    pub source_support: Option<usize>,
    /// The hazard's true hazard flags (catalog `hazards` of the object itself, not of
    /// what it looks like).
    pub hazard_flags: Vec<String>,
    pub observer: ObserverSpec,
    pub observation_window_s: f64,
    pub video: VideoSpec,
    pub cameras: Vec<CameraSpec>,
    pub lighting: LightingSpec,
    /// Family-specific numbers worth recording (drop height, ramp angle, …).
    pub family_params: BTreeMap<String, f64>,
    pub labels: LabelConfig,
}

impl SceneSpec {
    pub fn hazard_body(&self) -> &BodySpec {
        &self.bodies[self.hazard]
    }

    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("a spec always serializes");
        text.push('\n');
        text
    }

    pub fn from_json(text: &str) -> Result<SceneSpec, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// The physics step shown by video frame `frame` (exact: frame time / dt, rounded).
    pub fn frame_step(&self, frame: u32) -> u32 {
        (frame as f64 / self.video.fps as f64 / self.physics.dt).round() as u32
    }

    /// The physics step of every frame of the observation videos, `[0, Δ]` both ends
    /// included, for a simulation of `steps` steps (a scene that ends early holds its
    /// last state).
    pub fn observation_frame_steps(&self, steps: u32) -> Vec<u32> {
        let frames = (self.observation_window_s * self.video.fps as f64).round() as u32;
        (0..=frames)
            .map(|k| self.frame_step(k).min(steps))
            .collect()
    }
}

/// Vector helpers for the spec's plain `[f64; 3]` arrays.
pub mod vec3 {
    use super::Vec3;

    pub fn add(a: Vec3, b: Vec3) -> Vec3 {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }
    pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    pub fn dot(a: Vec3, b: Vec3) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
    pub fn norm(a: Vec3) -> f64 {
        dot(a, a).sqrt()
    }
    pub fn scale(a: Vec3, s: f64) -> Vec3 {
        [a[0] * s, a[1] * s, a[2] * s]
    }
}

/// Quaternion helpers (the spec keeps rotations as plain arrays).
pub mod quat {
    use super::vec3::cross;
    use super::{Quat, Vec3};

    /// Rotation of `angle` radians about a unit `axis`.
    pub fn from_axis_angle(axis: Vec3, angle: f64) -> Quat {
        let (s, c) = (angle / 2.0).sin_cos();
        [axis[0] * s, axis[1] * s, axis[2] * s, c]
    }

    pub fn mul(a: Quat, b: Quat) -> Quat {
        let [ax, ay, az, aw] = a;
        let [bx, by, bz, bw] = b;
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    }

    pub fn rotate(q: Quat, v: Vec3) -> Vec3 {
        let [x, y, z, w] = q;
        // v' = v + 2w (u × v) + 2 u × (u × v), u = (x, y, z)
        let u = [x, y, z];
        let uv = cross(u, v);
        let uuv = cross(u, uv);
        [
            v[0] + 2.0 * (w * uv[0] + uuv[0]),
            v[1] + 2.0 * (w * uv[1] + uuv[1]),
            v[2] + 2.0 * (w * uv[2] + uuv[2]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_rotates_x_to_y_about_z() {
        let q = quat::from_axis_angle([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
        let v = quat::rotate(q, [1.0, 0.0, 0.0]);
        assert!((v[0]).abs() < 1e-12 && (v[1] - 1.0).abs() < 1e-12 && v[2].abs() < 1e-12);
    }

    #[test]
    fn floats_round_trip_exactly_through_json() {
        let values = [
            0.1f64,
            1.0 / 3.0,
            2.0f64.sqrt(),
            1e-300,
            123456.789e10,
            -0.0,
        ];
        for v in values {
            let text = serde_json::to_string(&v).unwrap();
            let back: f64 = serde_json::from_str(&text).unwrap();
            assert_eq!(v.to_bits(), back.to_bits(), "{v} -> {text}");
        }
    }
}

/// Label thresholds (specification §6); stored whole in every spec so a scene says which rule made it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelConfig {
    pub rule_version: String,
    pub envelope_shoulder_offset: f64,
    pub envelope_step: f64,
    pub envelope_arm_reach: f64,
    pub envelope_crouch: f64,
    /// Lowest height of the envelope (rule v4; absent in older specs: no limit).
    #[serde(default)]
    pub envelope_min_height: f64,
    /// Rule v4's walking limits and hand preparation time for `label::time_to_hands`
    /// (absent in older specs: no timing).
    #[serde(default)]
    pub catch_walk_speed: f64,
    #[serde(default)]
    pub catch_walk_accel: f64,
    #[serde(default)]
    pub catch_prepare_s: f64,
    /// Rule v4: the largest hazard the arms close around (bounding radius, m; absent in
    /// older specs: any).
    #[serde(default)]
    pub catch_radius_max: f64,
    /// Rule v4's escape walks (`execute::escape`; absent in older specs: none).
    #[serde(default)]
    pub escape_directions: u32,
    #[serde(default)]
    pub escape_speed: f64,
    #[serde(default)]
    pub escape_distance: f64,
    #[serde(default)]
    pub escape_check_within_s: f64,
    pub interception_tolerance: f64,
    pub closest_approach_max: f64,
    pub reach_radius: f64,
    pub reaction_time_min: f64,
    pub floor_contact_eps: f64,
    pub heavy_mass_kg: f64,
    pub heavy_momentum: f64,
    pub catch_speed_max: f64,
    pub catch_energy_max: f64,
    /// Rule v5's harm test (`crate::strike`): a touch's window (s), the factor by which
    /// transient contact may exceed the quasi-static force, and per body region the
    /// limits of ISO/TS 15066 Annex A (`[harm.<region>]`, every region of
    /// `strike::Region::ALL`).
    pub strike_window_s: f64,
    pub harm_transient_factor: f64,
    pub harm: BTreeMap<String, HarmLimit>,
}

/// One body region's numbers (ISO/TS 15066 Annex A, Table A.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarmLimit {
    /// Maximum permissible quasi-static force (N).
    pub force_n: f64,
    /// Effective spring constant of the region (N/mm).
    pub spring_n_per_mm: f64,
    /// Effective mass of the region (kg).
    pub body_mass_kg: f64,
}

/// The label rule's thresholds of the embedded `configs/labels.toml`.
pub const LABELS_TOML: &str = include_str!("../../configs/labels.toml");

impl LabelConfig {
    /// The embedded `configs/labels.toml` (the default label rule).
    pub fn embedded() -> LabelConfig {
        toml::from_str(LABELS_TOML).expect("the embedded labels.toml parses")
    }
}

impl SceneSpec {
    /// The physics step of the decision moment Δ (the end of the observation window).
    pub fn decision_step(&self) -> u32 {
        (self.observation_window_s / self.physics.dt).round() as u32
    }
}
