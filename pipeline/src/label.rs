//! Stage 5 — label: ground truth from simulator state, never from appearance (SPEC §6).
//!
//! `label(&spec, &sim, &counterfactual)` reads the hazard's trajectory from the plain
//! simulation and the strike from the counterfactual one (the observer standing still as
//! a static collider), and applies the thresholds stored in the spec.

use crate::simulate::{Simulation, Strike};
use crate::spec::{SceneSpec, Vec3};
use serde::{Deserialize, Serialize};

/// The action primitives (the data contract's).
pub use rh_contract::Action;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::randomize::{randomize, SceneKey};
    use crate::simulate::{BodyState, TOUCH_FLOOR};
    use crate::spec::Selection;
    use rh_catalog::Catalog;

    /// A real spec (thrown apple) whose observer stands at the origin facing +x.
    fn spec(object: &str) -> SceneSpec {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let selection = Selection {
            family: "thrown_object".into(),
            object_id: object.into(),
            room_id: "kitchen".into(),
            description: None,
            planner: None,
        };
        let mut spec = randomize(&selection, &SceneKey::new(0, 1, 0), &catalog, &config).unwrap();
        spec.observer.x = 0.0;
        spec.observer.y = 0.0;
        spec
    }

    /// A one-body simulation following `path(t)` (velocity by finite differences).
    fn synthetic(spec: &SceneSpec, steps: u32, path: impl Fn(f64) -> [f64; 3]) -> Simulation {
        let dt = spec.physics.dt;
        let mut sim = Simulation {
            dt,
            dynamic_bodies: vec![spec.hazard],
            states: vec![],
            hazard_slot: 0,
            hazard_lowest_z: vec![],
            hazard_contacts: vec![],
            energy: vec![],
            initial_penetration: 0.0,
            strike: None,
            state_hash: String::new(),
        };
        let r = 0.04;
        for k in 0..=steps {
            let t = k as f64 * dt;
            let p = path(t);
            let q = path(t + dt);
            let v = [(q[0] - p[0]) / dt, (q[1] - p[1]) / dt, (q[2] - p[2]) / dt];
            sim.states.push(BodyState {
                position: p.map(|c| c as f32),
                rotation: [0.0, 0.0, 0.0, 1.0],
                linvel: v.map(|c| c as f32),
                angvel: [0.0; 3],
            });
            sim.hazard_lowest_z.push(p[2] - r);
            sim.hazard_contacts
                .push(if p[2] - r <= 0.005 { TOUCH_FLOOR } else { 0 });
            sim.energy.push(0.0);
        }
        sim
    }

    fn falling_at(x: f64) -> impl Fn(f64) -> [f64; 3] {
        move |t| [x, 0.0, (2.0 - 0.5 * 9.81 * t * t).max(0.04)]
    }

    #[test]
    fn reach_plane_crossing_is_interpolated() {
        let s = spec("apple");
        let sim = synthetic(&s, 240, falling_at(0.5));
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::ReachPlane));
        let p = l.impact_point.unwrap();
        assert!((p[2] - s.labels.reach_plane_z).abs() < 1e-9);
        // Free fall from 2 m to 0.9 m: t = sqrt(2·1.1/g).
        let t = (2.0 * 1.1 / 9.81f64).sqrt();
        assert!((l.time_to_impact.unwrap() - t).abs() < 2.0 * s.physics.dt);
        assert!((l.impact_speed.unwrap() - 9.81 * t).abs() < 0.1);
    }

    #[test]
    fn benign_reachable_object_is_caught_and_far_one_is_no_action() {
        let s = spec("apple");
        let near = label(&s, &synthetic(&s, 240, falling_at(0.5)), None);
        assert!(near.reachable && !near.dangerous && !near.danger_present);
        assert_eq!(near.gt_action, Action::Catch);
        let far = label(&s, &synthetic(&s, 240, falling_at(3.0)), None);
        assert!(!far.reachable);
        assert_eq!(far.gt_action, Action::NoAction);
    }

    #[test]
    fn dangerous_or_fast_objects_are_dodged() {
        // Sharp.
        let knife = spec("chef_knife");
        let l = label(&knife, &synthetic(&knife, 240, falling_at(0.5)), None);
        assert!(l.dangerous && l.danger_reasons.contains(&"sharp".to_string()));
        assert_eq!(l.gt_action, Action::Dodge);
        // Heavy by mass (a steel apple looks like an apple).
        let steel = spec("steel_apple");
        let l = label(&steel, &synthetic(&steel, 240, falling_at(0.5)), None);
        assert!(l.danger_reasons.contains(&"heavy_mass".to_string()));
        assert_eq!(l.gt_action, Action::Dodge);
        // Too fast to catch: a benign apple arriving at 12 m/s.
        let apple = spec("apple");
        let l = label(
            &apple,
            &synthetic(&apple, 120, |t| [0.5, 3.0 - 12.0 * t, 1.0]),
            None,
        );
        assert!(!l.dangerous);
        assert!(l.impact_speed.unwrap() > apple.labels.catch_speed_max);
        assert_eq!(l.gt_action, Action::Dodge);
    }

    #[test]
    fn closest_approach_is_used_when_the_reach_plane_is_never_crossed() {
        let s = spec("apple");
        // Rolling along the floor, passing 0.4 m from the observer.
        let sim = synthetic(&s, 480, |t| [2.0 - 1.0 * t, 0.4, 0.04]);
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::ClosestApproach));
        let p = l.impact_point.unwrap();
        assert!(p[0].abs() < 0.01 && (p[1] - 0.4).abs() < 1e-6);
        assert!((l.closest_approach - 0.4).abs() < 1e-3);
        // Never within 1.5 m: no impact point at all.
        let sim = synthetic(&s, 480, |t| [2.0 - 1.0 * t, 2.0, 0.04]);
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_point, None);
        assert_eq!(l.gt_action, Action::NoAction);
    }

    #[test]
    fn strike_in_the_counterfactual_sets_danger_present() {
        let s = spec("apple");
        let sim = synthetic(&s, 240, falling_at(3.0));
        let fast = label(
            &s,
            &sim,
            Some(Strike {
                step: 10,
                speed: 3.0,
            }),
        );
        assert!(fast.danger_present && fast.reachable);
        assert_ne!(fast.gt_action, Action::NoAction);
        let gentle = label(
            &s,
            &sim,
            Some(Strike {
                step: 10,
                speed: 0.1,
            }),
        );
        assert!(!gentle.danger_present);
    }

    #[test]
    fn time_to_floor_is_refined_within_the_step() {
        let s = spec("apple");
        let sim = synthetic(&s, 240, falling_at(0.5));
        // The lowest point (centre − 4 cm) falls 1.96 m.
        let expected = (2.0 * 1.96 / 9.81f64).sqrt();
        let measured = time_to_floor(&sim, 9.81).unwrap();
        assert!(
            (measured - expected).abs() / expected < 0.005,
            "{measured} vs {expected}"
        );
    }
}
