//! Stage 2 — randomize: a pure function of (selection, seed) to a full `SceneSpec`.
//!
//! Every number comes from a named ChaCha8 sub-stream of the group seed at the current
//! rejection-sampling attempt: "observer" (near or far), "placement" (the family's
//! geometry and initial conditions), "lighting". Cameras are framed after simulation
//! (see `cameras`), from their own stream.

use crate::config::RandomizeConfig;
use crate::families::{self, FamilyInput};
use crate::intent::Intent;
use rand::RngExt;
use rh_catalog::Catalog;
use rh_physics::seeds;
use rh_physics::spec::{
    LightingSpec, ObserverSpec, PhysicsSpec, RoomSpec, SceneSpec, Selection, SpeedBand,
    SCHEMA_VERSION,
};

/// Identifies one scene of a build: which group and band, at which attempt.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneKey {
    pub build_seed: u64,
    pub scene_index: u64,
    pub group_index: u64,
    pub attempt: u32,
    pub band: SpeedBand,
}

impl SceneKey {
    pub fn new(build_seed: u64, scene_index: u64, attempt: u32) -> SceneKey {
        SceneKey {
            build_seed,
            scene_index,
            group_index: scene_index / 4,
            attempt,
            band: SpeedBand::ALL[(scene_index % 4) as usize],
        }
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RandomizeError {
    #[error("unknown object '{0}'")]
    UnknownObject(String),
    #[error("unknown room '{0}'")]
    UnknownRoom(String),
    #[error("family '{family}' is not implemented in this build (implemented: {implemented})")]
    FamilyNotImplemented { family: String, implemented: String },
    #[error("the configuration has no speed bands for family '{0}'")]
    NoSpeedBands(String),
    #[error("object '{object}' is not listed for family '{family}'")]
    ObjectNotInFamily { object: String, family: String },
}

pub fn implemented_families() -> String {
    families::all()
        .iter()
        .map(|f| f.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Who the groups of an adversarial probe pair are laid out as (`twins`): set by the
/// driver for one group's attempts — runtime state, not policy, so not in any config.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StandIn {
    /// Their intent (`intent::Intent::for_object`) is this catalog object's, the pair's
    /// benign member, whichever object they show.
    pub aimed_as: Option<String>,
    /// Label rule v6, twin pairs: every launch is the push that gives this catalog object
    /// (the pair's benign member) the layout's velocities, whichever object is shown.
    pub pushed_as: Option<String>,
    /// A probe pair's groups are never drawn as a near miss (`build.far_observer_share`
    /// does not apply).
    pub never_far: bool,
}

/// Lays out the scene `key` of the group planned as `selection` (`config`: the stage's
/// sections, or a whole build configuration).
pub fn randomize<'a>(
    selection: &Selection,
    key: &SceneKey,
    catalog: &Catalog,
    config: impl Into<RandomizeConfig<'a>>,
) -> Result<SceneSpec, RandomizeError> {
    randomize_as(selection, key, catalog, &config.into(), &StandIn::default())
}

/// [`randomize`] for a group laid out as `stand_in` says (an adversarial probe pair's).
pub fn randomize_as(
    selection: &Selection,
    key: &SceneKey,
    catalog: &Catalog,
    config: &RandomizeConfig,
    stand_in: &StandIn,
) -> Result<SceneSpec, RandomizeError> {
    let family =
        families::get(&selection.family).ok_or_else(|| RandomizeError::FamilyNotImplemented {
            family: selection.family.clone(),
            implemented: implemented_families(),
        })?;
    let object = catalog
        .object(&selection.object_id)
        .ok_or_else(|| RandomizeError::UnknownObject(selection.object_id.clone()))?;
    if !object.families.contains(&selection.family) {
        return Err(RandomizeError::ObjectNotInFamily {
            object: object.id.clone(),
            family: selection.family.clone(),
        });
    }
    let room = catalog
        .room(&selection.room_id)
        .ok_or_else(|| RandomizeError::UnknownRoom(selection.room_id.clone()))?;
    let bands = config
        .speed_bands
        .get(&selection.family)
        .ok_or_else(|| RandomizeError::NoSpeedBands(selection.family.clone()))?;

    let seed = seeds::group_seed(key.build_seed, key.group_index);
    // Drawn once per group, not per attempt: resampling must not favour near misses
    // (which never fail the reaction-time validator).
    let far_share = if stand_in.never_far {
        0.0
    } else {
        config.far_observer_share
    };
    let far_observer = seeds::stream(seed, 0, "observer").random_bool(far_share);
    // An adversarial probe pair's groups are aimed as its benign member would be (`twins`).
    let aimed_as = stand_in
        .aimed_as
        .as_deref()
        .and_then(|id| catalog.object(id))
        .unwrap_or(object);
    let input = FamilyInput {
        object,
        room,
        speed: bands[key.band.index()],
        band_speeds: *bands,
        far_observer,
        observer_height: config.observer.height,
        intent: Intent::for_object(
            aimed_as,
            far_observer,
            config.labels,
            config.hands_half_length_max,
        ),
    };
    let mut layout = family.sample(&input, &mut seeds::stream(seed, key.attempt, "placement"));
    let pushed_as = stand_in
        .pushed_as
        .as_deref()
        .and_then(|id| catalog.object(id))
        .unwrap_or(object);
    push_launch(&mut layout.bodies, &object.id, pushed_as.mass);

    let mut lighting_rng = seeds::stream(seed, key.attempt, "lighting");
    let elevation: f64 = lighting_rng.random_range(0.6..1.3);
    let azimuth: f64 = lighting_rng.random_range(0.0..std::f64::consts::TAU);
    let lighting = LightingSpec {
        sun_direction: [
            -elevation.cos() * azimuth.cos(),
            -elevation.cos() * azimuth.sin(),
            -elevation.sin(),
        ],
        sun_intensity: lighting_rng.random_range(2.5..4.0),
        ambient: lighting_rng.random_range(0.2..0.4),
        color_temperature_k: lighting_rng.random_range(3500.0..6500.0),
    };

    let dt = config.physics.dt;
    let steps = |seconds: f64| (seconds / dt).round() as u32;
    let mut family_params = layout.params;
    family_params.insert("far_observer".into(), if far_observer { 1.0 } else { 0.0 });
    family_params.insert(crate::intent::PARAM.into(), input.intent.code());

    Ok(SceneSpec {
        schema_version: SCHEMA_VERSION,
        scene_id: seeds::scene_id(key.build_seed, key.scene_index),
        group_id: seeds::group_id(key.build_seed, key.group_index),
        build_seed: key.build_seed,
        scene_index: key.scene_index,
        seed,
        attempt: key.attempt,
        family: selection.family.clone(),
        speed_band: key.band,
        speed_sweep: family.speed_sweep(),
        speed_parameter: family.speed_parameter().to_string(),
        speed_value: input.speed,
        selection: selection.clone(),
        room: RoomSpec {
            id: room.id.clone(),
            size: room.size,
            ceiling_height: room.ceiling_height,
            floor_friction: room.floor_friction,
            floor_restitution: room.floor_restitution,
            wall_color: room.wall_color.clone(),
            floor_color: room.floor_color.clone(),
        },
        physics: PhysicsSpec {
            dt,
            gravity: [0.0, 0.0, -families::GRAVITY],
            solver_iterations: config.physics.solver_iterations,
            min_steps: steps(config.physics.min_duration_s),
            max_steps: steps(config.physics.horizon_s),
            settle_speed: config.physics.settle_speed,
            settle_steps: steps(config.physics.settle_time_s).max(1),
            drag: config.physics.drag,
        },
        bodies: layout.bodies,
        joints: layout.joints,
        hazard: layout.hazard,
        source_support: layout.source_support,
        hazard_flags: object.hazards.iter().cloned().collect(),
        observer: ObserverSpec {
            x: layout.observer.x,
            y: layout.observer.y,
            yaw: layout.observer.yaw,
            height: config.observer.height,
            pelvis_z: config.observer.pelvis_z,
            shoulder_z: config.observer.shoulder_z,
            torso_radius: config.observer.torso_radius,
        },
        observation_window_s: config.observation.window_s,
        video: config.video.clone(),
        cameras: vec![],
        lighting,
        family_params,
        labels: config.labels.clone(),
    })
}

/// Every launch is a push (label rule v6): each body showing the object that starts
/// moving gets the push that gives a body of `push_mass` its velocities — the object's own
/// mass, or for an adversarial twin pair's probe the benign member's (`twins`), so the
/// pair's twins, which differ only in the object, leave at speeds in the inverse ratio of
/// their masses.
fn push_launch(bodies: &mut [rh_physics::spec::BodySpec], object_id: &str, push_mass: f64) {
    for b in bodies
        .iter_mut()
        .filter(|b| b.catalog_id.as_deref() == Some(object_id))
        .filter(|b| b.linvel != [0.0; 3] || b.angvel != [0.0; 3])
    {
        b.push_mass = Some(push_mass);
    }
}
