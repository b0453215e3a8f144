//! Validators (SPEC §6): checks that run before rendering; each verdict is a dataset
//! column, and a scene failing any of them is resampled with the next attempt's seed.

use crate::cameras;
use crate::config::ValidatorConfig;
use crate::families::Family;
use crate::simulate::Simulation;
use crate::spec::SceneSpec;
use serde::{Deserialize, Serialize};

pub const VALIDATOR_COLUMNS: [&str; 5] = [
    "valid_no_interpenetration",
    "valid_energy",
    "valid_no_tunnelling",
    "valid_in_frame",
    "valid_intended_event",
];

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
    /// The family's intended event happened.
    pub intended_event: bool,
}

impl Verdicts {
    pub fn all(&self) -> bool {
        self.as_array().iter().all(|&v| v)
    }

    pub fn as_array(&self) -> [bool; 5] {
        [
            self.no_interpenetration,
            self.energy,
            self.no_tunnelling,
            self.in_frame,
            self.intended_event,
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

/// Runs every validator. `cameras_in_frame` is the framing outcome (see `cameras::frame`).
pub fn validate(
    spec: &SceneSpec,
    sim: &Simulation,
    family: &dyn Family,
    cfg: &ValidatorConfig,
    cameras_in_frame: bool,
) -> Verdicts {
    let e0 = sim.energy[0];
    let energy_limit = e0 + (cfg.energy_gain_relative * e0.abs()).max(cfg.energy_gain_absolute);
    Verdicts {
        no_interpenetration: sim.initial_penetration <= cfg.penetration_tolerance,
        energy: sim.energy.iter().all(|&e| e <= energy_limit),
        no_tunnelling: sim
            .hazard_lowest_z
            .iter()
            .all(|&z| z >= -cfg.tunnel_tolerance),
        in_frame: cameras_in_frame
            && cameras::hazard_in_frame(spec, sim, &spec.cameras, &cfg.framing()),
        intended_event: family.event_happened(spec, sim),
    }
}
