//! Validators (specification §6): checks that run before rendering; each verdict is a dataset
//! column, and a scene failing any of them is resampled with the next attempt's seed.

use crate::cameras;
use crate::config::ValidatorConfig;
use crate::families::Family;
use crate::label::Labels;
use crate::visibility;
use rh_physics::simulate::Simulation;
use rh_physics::spec::SceneSpec;
use serde::{Deserialize, Serialize};

/// The verdict columns, in `Verdicts::as_array` order (the data contract's list).
pub use rh_contract::VALIDATOR_COLUMNS;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Verdicts {
    /// No two bodies overlap at t0 beyond tolerance.
    pub no_interpenetration: bool,
    /// Total mechanical energy never rises above its start beyond tolerance.
    pub energy: bool,
    /// The hazard never sinks through the floor.
    pub no_tunnelling: bool,
    /// The hazard stays in all three cameras' frames through the observation window.
    pub in_frame: bool,
    /// Every camera sees enough of the hazard, large enough (`visibility`): no fixed body
    /// and not the observer's body in the way; and every model-input ego frame before it
    /// reaches the observer shows it with enough pixels (`ego::ego_pixels_pass`).
    pub visible: bool,
    /// The family's intended event happened.
    pub intended_event: bool,
    /// The hazard reaches the observer no earlier than Δ + `labels.reaction_time_min`
    /// (label rule v2): a decision made at Δ can still matter.
    pub reaction_time: bool,
    /// Label rule v4: a DODGE scene whose hazard would strike the standing body has an
    /// escape (`execute::escape`): some walk under the robot's limits is not struck.
    pub escapable: bool,
    /// The event is under way in the window: the hazard (or a moving prop) moves at least
    /// `validators.motion_px_min` in the ego image between t = 0 and Δ (`ego::motion_px`).
    pub motion: bool,
}

impl Verdicts {
    pub fn all(&self) -> bool {
        self.as_array().iter().all(|&v| v)
    }

    pub fn as_array(&self) -> [bool; VALIDATOR_COLUMNS.len()] {
        [
            self.no_interpenetration,
            self.energy,
            self.no_tunnelling,
            self.in_frame,
            self.visible,
            self.intended_event,
            self.reaction_time,
            self.escapable,
            self.motion,
        ]
    }

    /// Names of the failed validators, for progress messages.
    pub fn failures(&self) -> Vec<&'static str> {
        VALIDATOR_COLUMNS
            .iter()
            .zip(self.as_array())
            .filter(|(_, ok)| !ok)
            .map(|(n, _)| *n)
            .collect()
    }
}

/// Runs every validator on a spec with its cameras (see `cameras::frame_group`);
/// `labels` are the scene's labels (the reaction-time rule reads their times).
pub fn validate(
    spec: &SceneSpec,
    sim: &Simulation,
    family: &dyn Family,
    cfg: &ValidatorConfig,
    labels: &Labels,
) -> Verdicts {
    Verdicts {
        reaction_time: reaction_time_ok(spec, labels),
        escapable: escapable(spec, labels),
        ..unlabelled(spec, sim, family, cfg)
    }
}

/// The validators that need no labels (nor the counterfactual run behind them), with
/// `reaction_time` and `escapable` left `true`: [`validate`] sets those
/// ([`reaction_time_ok`], [`escapable`]). A driver that only needs to know whether a
/// scene passes everything checks these first, then the cheaper label rule, then the
/// escape walks.
pub fn unlabelled(
    spec: &SceneSpec,
    sim: &Simulation,
    family: &dyn Family,
    cfg: &ValidatorConfig,
) -> Verdicts {
    let framing = cfg.framing();
    let e0 = sim.energy[0];
    let energy_limit = e0 + (cfg.energy_gain_relative * e0.abs()).max(cfg.energy_gain_absolute);
    Verdicts {
        no_interpenetration: sim.initial_penetration <= cfg.penetration_tolerance,
        energy: sim.energy.iter().all(|&e| e <= energy_limit),
        no_tunnelling: sim
            .hazard_lowest_z
            .iter()
            .all(|&z| z >= -cfg.tunnel_tolerance),
        in_frame: cameras::hazard_in_frame(spec, sim, &spec.cameras, &framing),
        visible: visibility::assess(spec, sim, &framing).passes(&framing)
            && crate::ego::ego_pixels_pass(spec, sim, &spec.cameras, &framing),
        intended_event: family.event_happened(spec, sim),
        reaction_time: true,
        escapable: true,
        motion: cfg.motion_px_min <= 0.0
            || crate::ego::ego_motion_px(spec, sim).is_some_and(|m| m >= cfg.motion_px_min),
    }
}

/// Label rule v4: a DODGE scene whose hazard would strike the standing body and reaches
/// the observer (`time_to_reach`) within `escape_check_within_s` of Δ needs an escape
/// walk that is not struck (`execute::escape`); every other scene passes without a
/// physics run (a later arrival leaves a walk from rest time to clear the body).
pub fn escapable(spec: &SceneSpec, labels: &Labels) -> bool {
    let soon = labels
        .time_to_reach
        .is_some_and(|t| t <= spec.observation_window_s + spec.labels.escape_check_within_s + 1e-9);
    !(labels.danger_present && labels.gt_action == crate::label::Action::Dodge && soon)
        || rh_physics::execute::escape::escapable(spec)
}

/// Label rule v2's reaction-time rule: neither the moment the hazard first reaches the
/// observer (`time_to_reach`) nor the impact point's time comes before Δ +
/// `labels.reaction_time_min`, so a plan committed at Δ can still matter.
pub fn reaction_time_ok(spec: &SceneSpec, labels: &Labels) -> bool {
    // Times are multiples of the physics step; allow for rounding.
    let earliest = spec.observation_window_s + spec.labels.reaction_time_min - 1e-9;
    labels.time_to_reach.is_none_or(|t| t >= earliest)
        && labels.time_to_impact.is_none_or(|t| t >= earliest)
}
