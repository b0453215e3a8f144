//! Build configuration (`configs/*.toml`): every policy number of the pipeline.
//!
//! The default configuration is compiled in, so `rh-pipeline build` needs no files;
//! `--config FILE` loads another one (its `labels` path is relative to that file).

use crate::aim::AimConfig;
use rh_physics::spec::{LabelConfig, LABELS_TOML};
use rh_render_config::RenderConfig;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const DEFAULT_TOML: &str = include_str!("../../configs/default.toml");

#[derive(Debug, thiserror::Error)]
#[error("{location}: {message}")]
pub struct ConfigError {
    pub location: String,
    pub message: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildSection {
    pub seed: u64,
    pub families: Vec<String>,
    pub far_observer_share: f64,
    /// Label rule v5: the share of a family's groups the embedded planner gives a benign
    /// object (the planner's policy). Absent (older builds): objects are drawn
    /// uniformly, whatever their kind.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub benign_share: Option<f64>,
    /// Per family, instead of `benign_share`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub benign_share_by_family: BTreeMap<String, f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicsConfig {
    pub dt: f64,
    pub min_duration_s: f64,
    pub horizon_s: f64,
    pub settle_speed: f64,
    pub settle_time_s: f64,
    pub solver_iterations: usize,
    /// `[physics.drag]`: quadratic air drag on large light bodies (label rule v6); absent:
    /// none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag: Option<rh_physics::spec::DragSpec>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObservationConfig {
    pub window_s: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserverConfig {
    pub height: f64,
    pub pelvis_z: f64,
    pub shoulder_z: f64,
    pub arm_reach: f64,
    pub torso_radius: f64,
    pub max_walk_speed: f64,
}

fn default_visible_px_min() -> u32 {
    64
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValidatorConfig {
    pub max_attempts: u32,
    /// A group whose `max_attempts` all fail is planned afresh (another object and room of
    /// its family) up to this many times (label rule v5).
    #[serde(default)]
    pub replans: u32,
    /// N means N: a group still invalid after `replans` is planned afresh again, up to
    /// this many plans in all beyond its first (0: no more than `replans`).
    #[serde(default)]
    pub replans_max: u32,
    pub penetration_tolerance: f64,
    pub energy_gain_relative: f64,
    pub energy_gain_absolute: f64,
    pub tunnel_tolerance: f64,
    /// Hazard pixels the renderer's instance-id pass must count in every model-input
    /// frame (the measured check of the visibility rule: test `render_visibility`).
    #[serde(default = "default_visible_px_min")]
    pub visible_px_min: u32,
    pub frame_margin: f64,
    pub frame_check_until_within: f64,
    /// The widest vertical field of view a camera may be given (rad); a camera draw
    /// that would need more is redrawn.
    #[serde(default = "default_max_fov_y")]
    pub max_fov_y: f64,
    /// Visibility rule (`visibility`): the share of the hazard's sample points that must
    /// be in the image and in sight of every camera at every checked frame.
    #[serde(default = "default_visible_fraction_min")]
    pub visible_fraction_min: f64,
    /// Visibility rule: the smallest projected size of the hazard (px at the configured
    /// resolution, largest side of its projected sample points' box).
    #[serde(default = "default_visible_size_px_min")]
    pub visible_size_px_min: f64,
    /// Visibility rule: widening of the observer's collision capsule for line of sight
    /// (m), so that it also covers the drawn shoulders and arms.
    #[serde(default = "default_visibility_observer_margin")]
    pub visibility_observer_margin: f64,
    /// Camera placement: the band of projected hazard sizes (px) that a camera's field of
    /// view aims for — wide enough that the hazard never fills the frame, no wider than
    /// its path needs.
    #[serde(default = "default_frame_size_px")]
    pub frame_size_px: [f64; 2],
    /// What the renderer measures, the validator guarantees (`ego`): every model-input ego
    /// frame before the hazard reaches the observer must show, by a ray-cast estimate over
    /// the hazard's collision shapes shrunk to `visible_px_inset` of their size, at least
    /// `visible_px_min` × this many pixels (0, as in older configurations: not checked).
    #[serde(default)]
    pub visible_px_safety: f64,
    #[serde(default = "default_visible_px_inset")]
    pub visible_px_inset: f64,
    /// The event is under way in the window (`ego::motion_px`, validator `valid_motion`):
    /// the least motion (px) of the hazard or a moving prop in the ego image between t = 0
    /// and Δ (0, as in older configurations: not checked).
    #[serde(default)]
    pub motion_px_min: f64,
}

fn default_visible_px_inset() -> f64 {
    0.9
}

fn default_max_fov_y() -> f64 {
    2.1
}
fn default_visible_fraction_min() -> f64 {
    0.5
}
fn default_visible_size_px_min() -> f64 {
    8.0
}
fn default_visibility_observer_margin() -> f64 {
    0.08
}
fn default_frame_size_px() -> [f64; 2] {
    [24.0, 400.0]
}

/// Framing policy (from the `[validators]` config), for `cameras::frame`.
#[derive(Debug, Clone, Copy)]
pub struct FramingRules {
    /// Margin kept inside the image border (fraction of the half-size).
    pub margin: f64,
    /// Stop checking once the hazard is this close to the observer's torso axis (m).
    pub until_within: f64,
    /// The widest vertical field of view a camera may get (rad).
    pub max_fov_y: f64,
    /// Least share of the hazard's sample points in the image and in sight.
    pub visible_fraction: f64,
    /// Least projected size of the hazard (px).
    pub min_size_px: f64,
    /// Widening of the observer's capsule for line of sight (m).
    pub observer_margin: f64,
    /// Band of projected hazard sizes (px) that placement aims for.
    pub size_band_px: [f64; 2],
    /// Least estimated hazard pixels in each model-input ego frame (0: not checked).
    pub ego_px_min: f64,
    /// The hazard's shapes are shrunk to this share of their size for that estimate.
    pub px_inset: f64,
}

impl ValidatorConfig {
    pub fn framing(&self) -> FramingRules {
        FramingRules {
            margin: self.frame_margin,
            until_within: self.frame_check_until_within,
            max_fov_y: self.max_fov_y,
            visible_fraction: self.visible_fraction_min,
            min_size_px: self.visible_size_px_min,
            observer_margin: self.visibility_observer_margin,
            size_band_px: self.frame_size_px,
            ego_px_min: self.visible_px_min as f64 * self.visible_px_safety,
            px_inset: self.visible_px_inset,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    labels: PathBuf,
    build: BuildSection,
    physics: PhysicsConfig,
    observation: ObservationConfig,
    observer: ObserverConfig,
    validators: ValidatorConfig,
    render: RenderConfig,
    speed_bands: BTreeMap<String, [f64; 4]>,
    aim: AimConfig,
    #[serde(default)]
    eval: crate::eval_subset::EvalConfig,
    #[serde(default)]
    probes: ProbeConfig,
    #[serde(default)]
    decor: DecorConfig,
}

/// The whole, validated build configuration (`Deserialize` reads back the copy a build
/// manifest stores).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Config {
    pub build: BuildSection,
    pub physics: PhysicsConfig,
    pub observation: ObservationConfig,
    pub observer: ObserverConfig,
    pub validators: ValidatorConfig,
    pub render: RenderConfig,
    pub speed_bands: BTreeMap<String, [f64; 4]>,
    pub labels: LabelConfig,
    /// Label rule v5's aimed events (absent in manifests of older builds: not aimed).
    #[serde(default)]
    pub aim: AimConfig,
    /// Which scenes form the evaluation subset (absent in manifests of older builds:
    /// label-blind, whole groups first).
    #[serde(default)]
    pub eval: crate::eval_subset::EvalConfig,
    /// Adversarial probe pairs and their twins (absent in manifests of older builds: none).
    #[serde(default)]
    pub probes: ProbeConfig,
    /// How rooms are furnished (`decor`; absent in manifests of older builds: bare rooms).
    #[serde(default)]
    pub decor: DecorConfig,
    /// Where the configuration came from (for messages; not part of its content).
    #[serde(skip)]
    pub source: String,
}

impl Config {
    /// The configuration compiled into the binary (`configs/default.toml`).
    pub fn embedded() -> Result<Config, ConfigError> {
        let raw: RawConfig = parse("configs/default.toml", DEFAULT_TOML)?;
        let labels: LabelConfig = parse("configs/labels.toml", LABELS_TOML)?;
        Config::assemble("configs/default.toml", "configs/labels.toml", raw, labels)
    }

    /// Loads a configuration file and the labels file it names.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let name = path.display().to_string();
        let text = read(path)?;
        let raw: RawConfig = parse(&name, &text)?;
        let labels_path = path.parent().unwrap_or(Path::new(".")).join(&raw.labels);
        let labels_text = read(&labels_path)?;
        let labels_name = labels_path.display().to_string();
        let labels: LabelConfig = parse(&labels_name, &labels_text)?;
        Config::assemble(&name, &labels_name, raw, labels)
    }

    /// The configuration of `name` with the label thresholds of `labels_name` (each named
    /// in the errors of its own fields).
    fn assemble(
        name: &str,
        labels_name: &str,
        raw: RawConfig,
        labels: LabelConfig,
    ) -> Result<Config, ConfigError> {
        let config = Config {
            build: raw.build,
            physics: raw.physics,
            observation: raw.observation,
            observer: raw.observer,
            validators: raw.validators,
            render: raw.render,
            speed_bands: raw.speed_bands,
            labels,
            aim: raw.aim,
            eval: raw.eval,
            probes: raw.probes,
            decor: raw.decor,
            source: name.to_string(),
        };
        config.validate(name, labels_name)?;
        Ok(config)
    }

    fn validate(&self, name: &str, labels_name: &str) -> Result<(), ConfigError> {
        let fail = |field: &str, message: String| field_error(name, field, message);
        let positive = |field: &str, v: f64| positive_field(name, field, v);
        positive("physics.dt", self.physics.dt)?;
        self.validate_bounds(name, labels_name)?;
        self.validate_aim(name)?;
        if self.eval.per_family == 0 {
            return Err(fail("eval.per_family", "must be at least 1".into()));
        }
        if self
            .eval
            .catch_share
            .is_some_and(|c| !(0.0..=1.0).contains(&c))
        {
            return Err(fail("eval.catch_share", "must be within [0, 1]".into()));
        }
        if !(0.0..=1.0).contains(&self.eval.no_action_fill_share) {
            return Err(fail(
                "eval.no_action_fill_share",
                "must be within [0, 1]".into(),
            ));
        }
        positive("physics.horizon_s", self.physics.horizon_s)?;
        positive("physics.min_duration_s", self.physics.min_duration_s)?;
        positive("observation.window_s", self.observation.window_s)?;
        self.validate_labels(labels_name)?;
        if self.physics.horizon_s < self.physics.min_duration_s {
            return Err(fail(
                "physics.horizon_s",
                "must be at least physics.min_duration_s".into(),
            ));
        }
        if self.physics.min_duration_s < self.observation.window_s {
            return Err(fail(
                "physics.min_duration_s",
                "must cover the observation window".into(),
            ));
        }
        let v = &self.validators;
        if !(0.0..=1.0).contains(&v.visible_fraction_min) {
            return Err(fail(
                "validators.visible_fraction_min",
                "must be within [0, 1]".into(),
            ));
        }
        if !(v.visibility_observer_margin >= 0.0) {
            return Err(fail(
                "validators.visibility_observer_margin",
                "must not be negative".into(),
            ));
        }
        if !(v.visible_px_safety >= 0.0 && v.motion_px_min >= 0.0) {
            return Err(fail(
                "validators.visible_px_safety",
                "visible_px_safety and motion_px_min must not be negative".into(),
            ));
        }
        if !(v.visible_px_inset > 0.0 && v.visible_px_inset <= 1.0) {
            return Err(fail(
                "validators.visible_px_inset",
                "must be within (0, 1]".into(),
            ));
        }
        let [lo, hi] = v.frame_size_px;
        if !(v.visible_size_px_min >= 0.0 && lo >= v.visible_size_px_min && hi > lo) {
            return Err(fail(
                "validators.frame_size_px",
                "needs visible_size_px_min <= min < max".into(),
            ));
        }
        if self.validators.max_attempts == 0 {
            return Err(fail("validators.max_attempts", "must be at least 1".into()));
        }
        if self.labels.reach_radius > self.labels.closest_approach_max {
            return Err(field_error(
                labels_name,
                "labels.reach_radius",
                "must not exceed labels.closest_approach_max (a reachable hazard needs an impact point)".into(),
            ));
        }
        if self
            .build
            .benign_share
            .is_some_and(|b| !(0.0..=1.0).contains(&b))
        {
            return Err(fail("build.benign_share", "must be within [0, 1]".into()));
        }
        for (family, b) in &self.build.benign_share_by_family {
            if !(0.0..=1.0).contains(b) {
                return Err(fail(
                    &format!("build.benign_share_by_family.{family}"),
                    "must be within [0, 1]".into(),
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.build.far_observer_share) {
            return Err(fail(
                "build.far_observer_share",
                "must be within [0, 1]".into(),
            ));
        }
        if let Some((field, message)) = self.render.problem() {
            return Err(fail(field, message.into()));
        }
        for family in &self.build.families {
            if !rh_contract::FAMILIES.contains(&family.as_str()) {
                return Err(fail("build.families", format!("unknown family '{family}'")));
            }
        }
        for (family, bands) in &self.speed_bands {
            if !rh_contract::FAMILIES.contains(&family.as_str()) {
                return Err(fail("speed_bands", format!("unknown family '{family}'")));
            }
            if bands.iter().any(|v| !v.is_finite() || *v < 0.0) {
                return Err(fail(
                    &format!("speed_bands.{family}"),
                    "must be four finite, non-negative numbers".into(),
                ));
            }
        }
        Ok(())
    }

    /// The upper bounds of the numbers that set how much work or memory a build takes
    /// (docs/reliability.md, "Bounds"), checked before any work starts: no configuration
    /// reaches an allocation failure.
    fn validate_bounds(&self, name: &str, labels_name: &str) -> Result<(), ConfigError> {
        let p = &self.physics;
        let within = |file: &str, field: &str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(field_error(
                    file,
                    field,
                    format!("must be within [{lo}, {hi}] (got {v})"),
                ))
            }
        };
        within(name, "physics.dt", p.dt, 1e-4, 0.1)?;
        within(name, "physics.horizon_s", p.horizon_s, 0.0, 60.0)?;
        within(name, "physics.settle_time_s", p.settle_time_s, 0.0, 60.0)?;
        let counts = [
            (
                "physics.solver_iterations",
                p.solver_iterations as f64,
                1.0,
                64.0,
            ),
            (
                "validators.max_attempts",
                self.validators.max_attempts as f64,
                1.0,
                1000.0,
            ),
            (
                "eval.per_family",
                self.eval.per_family as f64,
                1.0,
                100_000.0,
            ),
        ];
        for (field, v, lo, hi) in counts.into_iter().chain(self.render.bounds()) {
            within(name, field, v, lo, hi)?;
        }
        let directions = self.labels.escape_directions as f64;
        within(
            labels_name,
            "labels.escape_directions",
            directions,
            1.0,
            360.0,
        )
    }

    fn validate_aim(&self, name: &str) -> Result<(), ConfigError> {
        let fail = |field: &str, message: String| field_error(name, field, message);
        let a = &self.aim;
        let range = |field: &str, r: [f64; 2]| {
            if r[0].is_finite() && r[1].is_finite() && r[0] <= r[1] {
                Ok(())
            } else {
                Err(fail(
                    field,
                    format!("must be [low, high] with low <= high (got {r:?})"),
                ))
            }
        };
        range("aim.meet_height", a.meet_height)?;
        range("aim.ahead", a.ahead)?;
        range("aim.miss_clearance", a.miss_clearance)?;
        range("aim.body_meet_height", a.body_meet_height)?;
        range("aim.body_ahead", a.body_ahead)?;
        for (family, r) in &a.meet_height_by_family {
            range(&format!("aim.meet_height_by_family.{family}"), *r)?;
        }
        if let Some(family) = a
            .attempts_by_family
            .keys()
            .find(|f| crate::families::get(f).is_none())
        {
            return Err(fail(
                &format!("aim.attempts_by_family.{family}"),
                "is not an event family".to_string(),
            ));
        }
        for (field, v) in [
            ("aim.reaction_margin_s", a.reaction_margin_s),
            ("aim.lateral", a.lateral),
            ("aim.body_lateral", a.body_lateral),
            ("aim.wall_margin", a.wall_margin),
            ("aim.touch_slack", a.touch_slack),
            ("aim.clear_before", a.clear_before),
            ("aim.hands_half_length_max", a.hands_half_length_max),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(fail(
                    field,
                    format!("must be a non-negative number (got {v})"),
                ));
            }
        }
        Ok(())
    }

    fn validate_labels(&self, name: &str) -> Result<(), ConfigError> {
        let fail = |field: &str, message: String| field_error(name, field, message);
        let positive = |field: &str, v: f64| positive_field(name, field, v);
        let l = &self.labels;
        for (field, v) in [
            (
                "labels.envelope_shoulder_offset",
                l.envelope_shoulder_offset,
            ),
            ("labels.envelope_step", l.envelope_step),
            ("labels.envelope_arm_reach", l.envelope_arm_reach),
            ("labels.envelope_crouch", l.envelope_crouch),
            ("labels.envelope_min_height", l.envelope_min_height),
            ("labels.catch_walk_speed", l.catch_walk_speed),
            ("labels.catch_walk_accel", l.catch_walk_accel),
            ("labels.catch_prepare_s", l.catch_prepare_s),
            ("labels.catch_radius_max", l.catch_radius_max),
            ("labels.escape_speed", l.escape_speed),
            ("labels.escape_distance", l.escape_distance),
            ("labels.escape_directions", l.escape_directions as f64),
            ("labels.escape_check_within_s", l.escape_check_within_s),
            ("labels.interception_tolerance", l.interception_tolerance),
            ("labels.reaction_time_min", l.reaction_time_min),
            ("labels.floor_contact_eps", l.floor_contact_eps),
            ("labels.strike_window_s", l.strike_window_s),
            ("labels.harm_transient_factor", l.harm_transient_factor),
        ] {
            positive(field, v)?;
        }
        for region in rh_physics::strike::Region::ALL {
            let field = format!("labels.harm.{}", region.name());
            let Some(h) = l.harm.get(region.name()) else {
                return Err(fail(
                    &field,
                    "is missing (one table per body region)".into(),
                ));
            };
            positive(&format!("{field}.force_n"), h.force_n)?;
            positive(&format!("{field}.spring_n_per_mm"), h.spring_n_per_mm)?;
            positive(&format!("{field}.body_mass_kg"), h.body_mass_kg)?;
        }
        if let Some(extra) = l.harm.keys().find(|k| {
            rh_physics::strike::Region::ALL
                .iter()
                .all(|r| r.name() != *k)
        }) {
            return Err(fail(
                &format!("labels.harm.{extra}"),
                "is not a body region of the humanoid".into(),
            ));
        }
        positive("labels.reach_radius", self.labels.reach_radius)?;
        positive(
            "labels.closest_approach_max",
            self.labels.closest_approach_max,
        )?;
        positive("labels.heavy_mass_kg", self.labels.heavy_mass_kg)?;
        positive("labels.heavy_momentum", self.labels.heavy_momentum)?;
        positive("labels.catch_speed_max", self.labels.catch_speed_max)?;
        positive("labels.catch_energy_max", self.labels.catch_energy_max)?;
        positive("observer.torso_radius", self.observer.torso_radius)?;
        Ok(())
    }

    /// The family's speed parameter in the four bands (slow, normal, fast, very fast).
    pub fn speed_bands(&self, family: &str) -> Option<&[f64; 4]> {
        self.speed_bands.get(family)
    }
}

/// What the randomize stage reads of the build configuration: the sections a spec is
/// laid out from (the driver hands it out, [`Config::randomize`]; `From<&Config>` for
/// callers holding a whole configuration).
#[derive(Debug, Clone)]
pub struct RandomizeConfig<'a> {
    /// `[build] far_observer_share`: the share of groups drawn as a near miss.
    pub far_observer_share: f64,
    pub physics: &'a PhysicsConfig,
    pub observation: &'a ObservationConfig,
    pub observer: &'a ObserverConfig,
    /// `[render]`'s model-input image size and frame rate (the spec's `video`).
    pub video: rh_physics::spec::VideoSpec,
    pub speed_bands: &'a BTreeMap<String, [f64; 4]>,
    pub labels: &'a LabelConfig,
    /// `[aim] hands_half_length_max` (the intent of an object).
    pub hands_half_length_max: f64,
}

impl Config {
    /// The randomize stage's sections.
    pub fn randomize(&self) -> RandomizeConfig<'_> {
        RandomizeConfig {
            far_observer_share: self.build.far_observer_share,
            physics: &self.physics,
            observation: &self.observation,
            observer: &self.observer,
            video: rh_physics::spec::VideoSpec {
                width: self.render.width,
                height: self.render.height,
                fps: self.render.fps,
            },
            speed_bands: &self.speed_bands,
            labels: &self.labels,
            hands_half_length_max: self.aim.hands_half_length_max,
        }
    }
}

impl<'a> From<&'a Config> for RandomizeConfig<'a> {
    fn from(config: &'a Config) -> RandomizeConfig<'a> {
        config.randomize()
    }
}

/// A configuration error naming the file and the field.
fn field_error(name: &str, field: &str, message: String) -> ConfigError {
    ConfigError {
        location: format!("{name}: field '{field}'"),
        message,
    }
}

/// `v` must be a finite positive number.
fn positive_field(name: &str, field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(field_error(
            name,
            field,
            format!("must be a positive number (got {v})"),
        ))
    }
}

fn read(path: &Path) -> Result<String, ConfigError> {
    std::fs::read_to_string(path).map_err(|e| ConfigError {
        location: path.display().to_string(),
        message: format!("cannot read: {e}"),
    })
}

fn parse<T: serde::de::DeserializeOwned>(name: &str, text: &str) -> Result<T, ConfigError> {
    toml::from_str(text).map_err(|e| {
        let location = match e.span() {
            Some(span) => {
                // 1-based: the newlines before the span's start, plus one.
                let line = text.as_bytes()[..span.start.min(text.len())]
                    .iter()
                    .filter(|&&b| b == b'\n')
                    .count()
                    + 1;
                format!("{name}:{line}")
            }
            None => name.to_string(),
        };
        ConfigError {
            location,
            message: e.message().to_string(),
        }
    })
}

/// `[probes]` of `configs/default.toml` (absent: no twins, builds before label rule v5).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeConfig {
    #[serde(default)]
    pub pairs: Vec<ProbePair>,
    /// Label rule v6: a pair is a probe only where its hazards' centres of mass come this
    /// far apart (m) at some physics step of the observation window [`divergence`];
    /// otherwise both scenes stay, unpaired. 0: every pair is kept (rule v5).
    #[serde(default)]
    pub divergence_min: f64,
}

/// One probe pair: the disguised object and the family that shows it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbePair {
    pub adversarial: String,
    pub family: String,
    /// `false`: the object only needs to appear (one probe group, no twin) — for objects
    /// whose look-alike the physics cannot tell apart in any family that shows them.
    #[serde(default = "yes")]
    pub twin: bool,
}

fn yes() -> bool {
    true
}

/// `[decor]` of `configs/default.toml` (how rooms are furnished, `decor::furnish`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DecorConfig {
    /// Whether rooms are furnished at all.
    pub enabled: bool,
    /// Gap kept between a piece and the space the event's bodies take (m).
    pub clearance_m: f64,
    /// Kept clear around the observer beyond the escape walks' length (m).
    pub observer_clearance_m: f64,
    /// Positions drawn for a piece before it is left out.
    pub tries: u32,
    /// Pieces of furniture (not windows or doors) a room should hold: while fewer are
    /// placed, the pieces left out are tried again, `fill_tries` positions each.
    #[serde(default)]
    pub min_furniture: usize,
    #[serde(default)]
    pub fill_tries: u32,
}

impl Default for DecorConfig {
    /// Absent in the manifests of older builds: no decor.
    fn default() -> Self {
        DecorConfig {
            enabled: false,
            clearance_m: 0.25,
            observer_clearance_m: 0.45,
            tries: 8,
            min_furniture: 0,
            fill_tries: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_config_is_valid() {
        let c = Config::embedded().unwrap();
        assert!((c.physics.dt - 1.0 / 240.0).abs() < 1e-15);
        assert_eq!(c.labels.rule_version, "v6");
        for f in &c.build.families {
            assert!(
                c.speed_bands(f).is_some(),
                "default family {f} has no speed bands"
            );
        }
    }

    #[test]
    fn malformed_config_names_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, DEFAULT_TOML.replace("seed = 0", "seed = \"zero\"")).unwrap();
        std::fs::write(dir.path().join("labels.toml"), LABELS_TOML).unwrap();
        let err = Config::load(&path).unwrap_err().to_string();
        assert!(err.contains("bad.toml:"), "{err}");
        assert!(err.contains("\"zero\""), "{err}");
        // The exact line: a value at the start of a line and one after a blank line.
        for (text, line) in [
            ("labels = \"l.toml\"\n[build]\nseed = \"zero\"\n", 3),
            (
                "labels = \"l.toml\"\n\n[build]\nseed = 0\nfamilies = 7\n",
                5,
            ),
            ("labels = 3\n", 1),
        ] {
            let err = parse::<RawConfig>("x.toml", text).unwrap_err().to_string();
            assert!(
                err.starts_with(&format!("x.toml:{line}:")),
                "{text:?}: {err}"
            );
        }
    }

    #[test]
    fn semantic_errors_name_the_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.toml");
        std::fs::write(
            &path,
            DEFAULT_TOML.replace("horizon_s = 4.0", "horizon_s = -1.0"),
        )
        .unwrap();
        std::fs::write(dir.path().join("labels.toml"), LABELS_TOML).unwrap();
        let err = Config::load(&path).unwrap_err().to_string();
        assert!(err.contains("physics.horizon_s"), "{err}");
        // A body region without its limits.
        std::fs::write(&path, DEFAULT_TOML).unwrap();
        let labels = LABELS_TOML.replace("[harm.face]", "[harm.cheek]");
        std::fs::write(dir.path().join("labels.toml"), labels).unwrap();
        let err = Config::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("labels.harm.face") && err.contains("missing"),
            "{err}"
        );
        // A per-family number for a family that does not exist.
        std::fs::write(dir.path().join("labels.toml"), LABELS_TOML).unwrap();
        let bad = DEFAULT_TOML.replace("shelf_slide = 1", "shelf_slid = 1");
        assert_ne!(bad, DEFAULT_TOML);
        std::fs::write(&path, bad).unwrap();
        let err = Config::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("aim.attempts_by_family.shelf_slid")
                && err.contains("not an event family"),
            "{err}"
        );
    }

    #[test]
    fn aim_attempts_per_family_fall_back_to_attempts() {
        let mut aim = Config::embedded().unwrap().aim;
        aim.attempts = 4;
        aim.attempts_by_family = [("shelf_slide".to_string(), 1), ("door_swing".into(), 0)].into();
        assert_eq!(aim.attempts_for("shelf_slide"), 1);
        assert_eq!(aim.attempts_for("object_drop"), 4);
        // At least one layout is always drawn.
        assert_eq!(aim.attempts_for("door_swing"), 1);
    }
}
