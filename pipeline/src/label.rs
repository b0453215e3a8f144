//! Stage 5 — label: ground truth from simulator state, never from appearance (SPEC §6).
//!
//! `label(&spec, &sim, &counterfactual)` reads the hazard's trajectory from the plain
//! simulation and the strike from the counterfactual one (the observer standing still as
//! a static collider), and applies the thresholds stored in the spec.

use crate::simulate::{Simulation, Strike};
use crate::spec::{SceneSpec, Vec3};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Action {
    #[serde(rename = "CATCH")]
    Catch,
    #[serde(rename = "DODGE")]
    Dodge,
    #[serde(rename = "NO_ACTION")]
    NoAction,
}

impl Action {
    pub fn name(self) -> &'static str {
        match self {
            Action::Catch => "CATCH",
            Action::Dodge => "DODGE",
            Action::NoAction => "NO_ACTION",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImpactKind {
    /// The hazard's centre descended through the reach plane.
    ReachPlane,
    /// The hazard never did; its closest approach to the torso axis is used.
    ClosestApproach,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Labels {
    pub gt_action: Action,
    pub dangerous: bool,
    pub danger_present: bool,
    /// Why `dangerous` holds (e.g. "sharp", "heavy_mass", "momentum"), empty if not.
    pub danger_reasons: Vec<String>,
    pub impact_point: Option<Vec3>,
    pub impact_kind: Option<ImpactKind>,
    pub time_to_impact: Option<f64>,
    pub time_to_floor: Option<f64>,
    pub impact_speed: Option<f64>,
    /// Closest distance of the hazard's centre to the observer's torso axis (m).
    pub closest_approach: f64,
    /// The hazard comes within the observer's reach radius (or strikes them).
    pub reachable: bool,
    /// Hazard speed when it struck the standing observer in the counterfactual (m/s).
    pub strike_speed: Option<f64>,
}

fn lerp3(a: Vec3, b: Vec3, f: f64) -> Vec3 {
    [
        a[0] + (b[0] - a[0]) * f,
        a[1] + (b[1] - a[1]) * f,
        a[2] + (b[2] - a[2]) * f,
    ]
}

fn length(v: Vec3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Time of first floor contact, refined within the contact step by the ballistic motion
/// of the hazard's lowest point from the previous step (a step is 4.2 ms; the refinement
/// keeps `time_to_floor` well inside 1% of a closed-form fall).
pub fn time_to_floor(sim: &Simulation, gravity: f64) -> Option<f64> {
    let k = sim.time_to_floor_step()?;
    let h = sim.hazard_lowest_z[(k - 1) as usize].max(0.0);
    let vz = sim.hazard_velocity(k - 1)[2];
    // h + vz τ − ½ g τ² = 0, the positive root.
    let tau = (vz + (vz * vz + 2.0 * gravity * h).sqrt()) / gravity;
    Some((k - 1) as f64 * sim.dt + tau.clamp(0.0, sim.dt))
}

pub fn label(spec: &SceneSpec, sim: &Simulation, strike: Option<Strike>) -> Labels {
    let cfg = &spec.labels;
    let g = -spec.physics.gravity[2];
    let steps = sim.steps();

    // Impact point: first descent of the centre through the reach plane after t0 …
    let mut impact: Option<(Vec3, f64, f64, ImpactKind)> = None;
    for k in 1..=steps {
        let a = sim.hazard_position(k - 1);
        let b = sim.hazard_position(k);
        if a[2] > cfg.reach_plane_z && b[2] <= cfg.reach_plane_z {
            let f = (a[2] - cfg.reach_plane_z) / (a[2] - b[2]);
            let point = lerp3(a, b, f);
            let speed = length(lerp3(sim.hazard_velocity(k - 1), sim.hazard_velocity(k), f));
            impact = Some((
                point,
                (k - 1) as f64 * sim.dt + f * sim.dt,
                speed,
                ImpactKind::ReachPlane,
            ));
            break;
        }
    }
    // … else its closest approach to the torso axis, if near enough.
    let (closest_step, closest_approach) = (0..=steps)
        .map(|k| (k, spec.observer.torso_axis_distance(sim.hazard_position(k))))
        .fold(
            (0, f64::INFINITY),
            |best, cur| if cur.1 < best.1 { cur } else { best },
        );
    if impact.is_none() && closest_approach <= cfg.closest_approach_max {
        impact = Some((
            sim.hazard_position(closest_step),
            closest_step as f64 * sim.dt,
            length(sim.hazard_velocity(closest_step)),
            ImpactKind::ClosestApproach,
        ));
    }

    let mass = spec.hazard_body().mass;
    let flags = &spec.hazard_flags;
    let has = |f: &str| flags.iter().any(|x| x == f);
    let max_speed = (0..=steps)
        .map(|k| length(sim.hazard_velocity(k)))
        .fold(0.0, f64::max);
    let impact_speed = impact.map(|i| i.2);
    let momentum = mass * impact_speed.unwrap_or(max_speed);
    let mut danger_reasons = Vec::new();
    for flag in ["sharp", "hot"] {
        if has(flag) {
            danger_reasons.push(flag.to_string());
        }
    }
    if has("fragile") && has("large") {
        danger_reasons.push("large_fragile".into());
    }
    if mass >= cfg.heavy_mass_kg {
        danger_reasons.push("heavy_mass".into());
    }
    if momentum >= cfg.heavy_momentum {
        danger_reasons.push("momentum".into());
    }
    let dangerous = !danger_reasons.is_empty();

    let strike_speed = strike.map(|s| s.speed);
    let danger_present = strike_speed.is_some_and(|s| s >= cfg.strike_speed_min);
    let reachable = closest_approach <= cfg.reach_radius || danger_present;

    let speed = impact_speed.unwrap_or(max_speed);
    let too_fast = speed > cfg.catch_speed_max || 0.5 * mass * speed * speed > cfg.catch_energy_max;
    let gt_action = if !reachable {
        Action::NoAction
    } else if dangerous || too_fast {
        Action::Dodge
    } else {
        Action::Catch
    };

    Labels {
        gt_action,
        dangerous,
        danger_present,
        danger_reasons,
        impact_point: impact.map(|i| i.0),
        impact_kind: impact.map(|i| i.3),
        time_to_impact: impact.map(|i| i.1),
        time_to_floor: time_to_floor(sim, g),
        impact_speed,
        closest_approach,
        reachable,
        strike_speed,
    }
}
