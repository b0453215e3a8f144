//! Stage 5 — label: ground truth from simulator state, never from appearance (specification §6).
//!
//! `label(&spec, &sim, &counterfactual)` reads the hazard's trajectory from the plain
//! simulation and the strike from the counterfactual one (the observer standing still:
//! the humanoid's rest-pose links as fixed colliders, `simulate::observer_links`), and
//! applies the thresholds stored in the spec (the harm test is `rh_physics::strike`'s, the
//! executor's too).

use rh_physics::simulate::{Simulation, Strike};
use rh_physics::spec::{SceneSpec, Vec3};
use serde::{Deserialize, Serialize};

/// The action primitives (the data contract's).
pub use rh_contract::Action;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImpactKind {
    /// Where the hazard's centre of mass, at or after Δ, is inside the reach envelope
    /// and (within `interception_tolerance`) as close to the torso axis as it gets there.
    Envelope,
    /// Rule v4: it is in the envelope after Δ only where the hands cannot hold it (below
    /// `envelope_min_height`) or cannot be in time ([`time_to_hands`]); the interception
    /// is chosen as in rule v3, among all its envelope points. Never a CATCH.
    EnvelopeLate,
    /// It never enters the envelope after Δ; its closest approach to the torso axis is used.
    ClosestApproach,
}

impl ImpactKind {
    pub fn name(self) -> &'static str {
        match self {
            ImpactKind::Envelope => "envelope",
            ImpactKind::EnvelopeLate => "envelope_late",
            ImpactKind::ClosestApproach => "closest_approach",
        }
    }
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
    /// Closest distance of the hazard's centre of mass to the observer's torso axis at
    /// or after the decision moment Δ (m).
    pub closest_approach: f64,
    /// The hazard comes within the observer's reach radius after Δ (or strikes them).
    pub reachable: bool,
    /// Speed of the hazard's contact point relative to the standing observer in the
    /// counterfactual run (m/s); `None` when it never touches them.
    pub strike_speed: Option<f64>,
    /// Impulse the standing observer receives in the counterfactual run (N·s).
    pub strike_impulse: Option<f64>,
    /// Rule v5's harm test on the same window (`rh_physics::strike`): the worst body region,
    /// its largest transient energy (J) and sustained force (N), and their larger ratio
    /// to that region's limits (≥ 1: harm); `None` when the hazard never touches the body.
    pub harm_region: Option<String>,
    pub harm_energy: Option<f64>,
    pub harm_force: Option<f64>,
    pub harm_ratio: Option<f64>,
    /// When the hazard first reaches the observer over the whole run (interception,
    /// closest approach within `reach_radius`, or a strike), from t = 0 (s).
    pub time_to_reach: Option<f64>,
}

fn length(v: Vec3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// How far `p` lies outside the observer's reach envelope (≤ 0 inside): its distance to
/// the shoulder region minus the arm's reach (see `configs/labels.toml`). Where the hazard
/// reaches the observer; [`catch_excess`] is where the hands can hold it.
pub fn envelope_excess(spec: &SceneSpec, p: Vec3) -> f64 {
    let cfg = &spec.labels;
    let (rho, d_z) = shoulder_band_offsets(spec, p);
    let d_rho = (rho - (cfg.envelope_shoulder_offset + cfg.envelope_step)).max(0.0);
    (d_rho * d_rho + d_z * d_z).sqrt() - cfg.envelope_arm_reach
}

/// Rule v4: how far `p` lies outside the part of the envelope where the hands can hold
/// the hazard (≤ 0 inside): the envelope above `envelope_min_height` (lower, the crouched
/// knees are in front of the hands).
pub fn catch_excess(spec: &SceneSpec, p: Vec3) -> f64 {
    envelope_excess(spec, p).max(spec.labels.envelope_min_height - p[2])
}

/// `p`'s horizontal distance from the torso axis and its height outside the shoulder band
/// (shoulder height − `envelope_crouch` … shoulder height; 0 within it).
fn shoulder_band_offsets(spec: &SceneSpec, p: Vec3) -> (f64, f64) {
    let o = &spec.observer;
    let rho = ((p[0] - o.x).powi(2) + (p[1] - o.y).powi(2)).sqrt();
    let top = o.shoulder_z;
    let bottom = o.shoulder_z - spec.labels.envelope_crouch;
    let d_z = if p[2] > top {
        p[2] - top
    } else if p[2] < bottom {
        bottom - p[2]
    } else {
        0.0
    };
    (rho, d_z)
}

/// Rule v4: the time the observer, standing still at Δ, needs to have its hands at `p`
/// (an envelope point): walk the horizontal distance by which `p` lies beyond the arms'
/// reach at its height (the envelope without its step: `envelope_shoulder_offset` +
/// √(arm² − Δz²)), from rest, at most `catch_walk_accel` and `catch_walk_speed` (the
/// robot's base limits), plus `catch_prepare_s` for the hands to get there. Specs of
/// rules ≤ v3 (no walking limits stored) need no time.
pub fn time_to_hands(spec: &SceneSpec, p: Vec3) -> f64 {
    let cfg = &spec.labels;
    if cfg.catch_walk_accel <= 0.0 || cfg.catch_walk_speed <= 0.0 {
        return 0.0;
    }
    let (rho, d_z) = shoulder_band_offsets(spec, p);
    let arm = cfg.envelope_arm_reach;
    if d_z >= arm {
        return f64::INFINITY;
    }
    let reach = cfg.envelope_shoulder_offset + (arm * arm - d_z * d_z).sqrt();
    walk_time(
        (rho - reach).max(0.0),
        cfg.catch_walk_speed,
        cfg.catch_walk_accel,
    ) + cfg.catch_prepare_s
}

/// Time to cover `s` m from rest at acceleration ≤ `a` and speed ≤ `v` (closed form).
fn walk_time(s: f64, v: f64, a: f64) -> f64 {
    if s <= v * v / a {
        (2.0 * s / a).sqrt()
    } else {
        s / v + v / (2.0 * a)
    }
}

/// Where, from step `from` on, the hazard meets the observer: the interception in the
/// reach envelope, else the closest approach if within `max_distance`.
pub fn approach(
    spec: &SceneSpec,
    sim: &Simulation,
    from: u32,
    max_distance: f64,
) -> Option<(u32, ImpactKind)> {
    let steps = sim.steps();
    if from > steps {
        return None;
    }
    let inside = |k: u32| envelope_excess(spec, sim.hazard_com(k)) <= 0.0;
    if let Some(k) = first_near_closest(spec, sim, from, inside) {
        return Some((k, ImpactKind::Envelope));
    }
    let (k, dist) = closest_after(spec, sim, from);
    (dist <= max_distance).then_some((k, ImpactKind::ClosestApproach))
}

/// Rule v4's impact point from the decision step `from` on: the interception among the
/// points where the hands can hold the hazard ([`catch_excess`] ≤ 0), get in time
/// ([`time_to_hands`] ≤ the time since `from`) and before the hazard would first touch
/// the standing body (step `touch`, from the counterfactual run), `Envelope`; else
/// [`approach`]'s, an envelope point then being `EnvelopeLate` (too low, too soon or
/// too late to hold).
pub fn interception(
    spec: &SceneSpec,
    sim: &Simulation,
    from: u32,
    max_distance: f64,
    touch: Option<u32>,
) -> Option<(u32, ImpactKind)> {
    if from > sim.steps() {
        return None;
    }
    let holdable_in_time = |k: u32| {
        let p = sim.hazard_com(k);
        touch.is_none_or(|t| k < t)
            && catch_excess(spec, p) <= 0.0
            && time_to_hands(spec, p) <= (k - from) as f64 * sim.dt + 1e-12
    };
    if let Some(k) = first_near_closest(spec, sim, from, holdable_in_time) {
        return Some((k, ImpactKind::Envelope));
    }
    approach(spec, sim, from, max_distance).map(|(k, kind)| match kind {
        ImpactKind::Envelope => (k, ImpactKind::EnvelopeLate),
        other => (k, other),
    })
}

/// The first step (≥ `from`) that is `eligible` and within `interception_tolerance` of the
/// closest the hazard's centre of mass comes to the torso axis at eligible steps.
fn first_near_closest(
    spec: &SceneSpec,
    sim: &Simulation,
    from: u32,
    ok: impl Fn(u32) -> bool,
) -> Option<u32> {
    let steps = sim.steps();
    let d = |k: u32| spec.observer.torso_axis_distance(sim.hazard_com(k));
    let closest = (from..=steps)
        .filter(|&k| ok(k))
        .map(d)
        .fold(f64::INFINITY, f64::min);
    let tolerance = spec.labels.interception_tolerance;
    (from..=steps).find(|&k| closest.is_finite() && ok(k) && d(k) <= closest + tolerance)
}

/// First step (≥ `from`) of the hazard's closest approach to the torso axis, and that distance.
fn closest_after(spec: &SceneSpec, sim: &Simulation, from: u32) -> (u32, f64) {
    (from..=sim.steps())
        .map(|k| (k, spec.observer.torso_axis_distance(sim.hazard_com(k))))
        .fold((from, f64::INFINITY), |best, cur| {
            if cur.1 < best.1 {
                cur
            } else {
                best
            }
        })
}

/// Time of first floor contact (specification §6). A hazard that starts above the floor: the first
/// floor contact with its lowest point within `floor_contact_eps`, refined by the
/// ballistic motion of the lowest point from the last step it was above the floor. A
/// hazard that starts on the floor (a toppling wardrobe, a slipping ladder): the moment
/// its top — the top corners of its parts' bounding box in its own frame — first comes
/// within `floor_contact_eps` of the floor, interpolated within the step.
pub fn time_to_floor(spec: &SceneSpec, sim: &Simulation) -> Option<f64> {
    let eps = spec.labels.floor_contact_eps;
    let gravity = -spec.physics.gravity[2];
    if sim.hazard_lowest_z[0] <= eps {
        return top_touches_floor(spec, sim, eps);
    }
    let k = sim.time_to_floor_step(eps)?;
    // The last step with the lowest point above the floor, and the ballistic fall of
    // the lowest point from there to z = 0 (at most to the contact step and one more:
    // the solver may hold a fast body a few millimetres up at its contact step).
    let mut j = k - 1;
    while j > 0 && sim.hazard_lowest_z[j as usize] <= 0.0 {
        j -= 1;
    }
    let h = sim.hazard_lowest_z[j as usize].max(0.0);
    let vz = sim.hazard_velocity(j)[2];
    let tau = (vz + (vz * vz + 2.0 * gravity * h).sqrt()) / gravity;
    let span = (k - j + 1) as f64 * sim.dt;
    if tau > 0.0 && tau < span {
        return Some(j as f64 * sim.dt + tau);
    }
    // A spinning or grazing body whose lowest point does not follow its centre's fall:
    // interpolate the lowest point's own crossing of the contact height in the step
    // (the middle of the step when it was already that low before).
    let (a, b) = (
        sim.hazard_lowest_z[(k - 1) as usize],
        sim.hazard_lowest_z[k as usize],
    );
    let f = if a > b {
        ((a - eps) / (a - b)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    Some((k - 1) as f64 * sim.dt + f * sim.dt)
}

/// Top corners of the hazard's parts' bounding box, in its body frame.
fn top_corners(spec: &SceneSpec) -> [Vec3; 4] {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for part in &spec.hazard_body().parts {
        let r = part.shape.bounding_radius();
        let half = match part.shape {
            rh_physics::spec::ShapeSpec::Box { half_extents } => half_extents,
            rh_physics::spec::ShapeSpec::Sphere { radius } => [radius; 3],
            rh_physics::spec::ShapeSpec::Cylinder {
                half_height,
                radius,
            } => [radius, radius, half_height],
            rh_physics::spec::ShapeSpec::Capsule {
                half_height,
                radius,
            } => [radius, radius, half_height + radius],
        };
        // A part rotated within the body: its bounding sphere bounds it.
        let half = if part.rotation == rh_physics::spec::IDENTITY {
            half
        } else {
            [r; 3]
        };
        for a in 0..3 {
            lo[a] = lo[a].min(part.offset[a] - half[a]);
            hi[a] = hi[a].max(part.offset[a] + half[a]);
        }
    }
    [
        [lo[0], lo[1], hi[2]],
        [hi[0], lo[1], hi[2]],
        [lo[0], hi[1], hi[2]],
        [hi[0], hi[1], hi[2]],
    ]
}

fn top_touches_floor(spec: &SceneSpec, sim: &Simulation, eps: f64) -> Option<f64> {
    let corners = top_corners(spec);
    let top_z = |k: u32| {
        let s = sim.hazard_state(k);
        let q = s.rotation.map(f64::from);
        corners
            .iter()
            .map(|&c| rh_physics::spec::quat::rotate(q, c)[2] + s.position[2] as f64)
            .fold(f64::INFINITY, f64::min)
    };
    if top_z(0) <= eps {
        return None;
    }
    let k = (1..=sim.steps()).find(|&k| top_z(k) <= eps)?;
    let (a, b) = (top_z(k - 1), top_z(k));
    let f = ((a - eps) / (a - b)).clamp(0.0, 1.0);
    Some((k - 1) as f64 * sim.dt + f * sim.dt)
}

/// Rule v4: the hazard is small enough for the arms to close around — within
/// `catch_radius_max` of its centre (half the arm span). Longer things (a 2.2 m prop
/// ladder, a hinged 2.1 m prop door) are fended off, not caught: hands at their centre
/// leave their ends free to hit the body. Specs without the limit (rules ≤ v3): any size.
pub fn fits_in_arms(spec: &SceneSpec) -> bool {
    let max = spec.labels.catch_radius_max;
    max <= 0.0 || spec.hazard_body().bounding_radius() <= max
}

/// `gt_action` (rule v5), in this order: CATCH when the hazard is benign (`catchable`: not
/// dangerous, not too fast or energetic to catch), reaches the observer, comes where the
/// hands can hold it in time (`impact_kind = envelope`) and fits in the arms
/// ([`fits_in_arms`]) — rule v4's CATCH; else DODGE when the standing body would be
/// harmed (`danger_present`, the harm test of `rh_physics::strike`); else NO_ACTION — nothing
/// reaches the observer, or only harmlessly, a dangerous object that never harms the
/// standing body included.
fn action(reachable: bool, catchable: bool, in_hands_reach: bool, danger_present: bool) -> Action {
    if reachable && catchable && in_hands_reach {
        Action::Catch
    } else if danger_present {
        Action::Dodge
    } else {
        Action::NoAction
    }
}

pub fn label(spec: &SceneSpec, sim: &Simulation, strike: Option<Strike>) -> Labels {
    let cfg = &spec.labels;
    let steps = sim.steps();
    let decision = spec.decision_step().min(steps);
    let at = |k: u32| k as f64 * sim.dt;

    let touch = strike.map(|s| s.first_touch);
    let impact = interception(spec, sim, decision, cfg.closest_approach_max, touch);
    let closest_approach = closest_after(spec, sim, decision).1;
    let impact_speed = impact.map(|(k, _)| length(sim.hazard_velocity(k)));

    let reach = approach(spec, sim, 0, cfg.reach_radius).map(|(k, _)| at(k));
    let strike_time = strike.map(|s| at(s.first_touch));
    let time_to_reach = match (reach, strike_time) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };

    let mass = spec.hazard_body().mass;
    let flags = &spec.hazard_flags;
    let has = |f: &str| flags.iter().any(|x| x == f);
    let max_speed = (0..=steps)
        .map(|k| length(sim.hazard_velocity(k)))
        .fold(0.0, f64::max);
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

    // The one harm test (`rh_physics::strike`), the executor's too: judged in the run.
    let danger_present = strike.is_some_and(|s| s.harm);
    let reachable = closest_approach <= cfg.reach_radius || danger_present;

    let speed = impact_speed.unwrap_or(max_speed);
    let too_fast = speed > cfg.catch_speed_max || 0.5 * mass * speed * speed > cfg.catch_energy_max;
    let in_hands_reach =
        impact.is_some_and(|(_, kind)| kind == ImpactKind::Envelope) && fits_in_arms(spec);
    let gt_action = action(
        reachable,
        !(dangerous || too_fast),
        in_hands_reach,
        danger_present,
    );

    Labels {
        gt_action,
        dangerous,
        danger_present,
        danger_reasons,
        impact_point: impact.map(|(k, _)| sim.hazard_com(k)),
        impact_kind: impact.map(|(_, kind)| kind),
        time_to_impact: impact.map(|(k, _)| at(k)),
        time_to_floor: time_to_floor(spec, sim),
        impact_speed,
        closest_approach,
        reachable,
        strike_speed: strike.map(|s| s.speed),
        strike_impulse: strike.map(|s| s.impulse),
        harm_region: strike.map(|s| s.region.name().to_string()),
        harm_energy: strike.map(|s| s.energy),
        harm_force: strike.map(|s| s.force),
        harm_ratio: strike.map(|s| s.ratio),
        time_to_reach,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::randomize::{randomize, SceneKey};
    use rh_catalog::Catalog;
    use rh_physics::body::Part;
    use rh_physics::simulate::{BodyState, TOUCH_FLOOR};
    use rh_physics::spec::Selection;
    use rh_physics::strike::Region;

    const G: f64 = 9.81;

    /// A real spec (thrown apple) whose observer stands at the origin facing +x.
    fn spec(object: &str) -> SceneSpec {
        // A constructed throw may carry an object the catalog does not list for
        // thrown_object (too small to be seen thrown from 5–8 m): the test places it.
        let mut catalog = Catalog::embedded().unwrap();
        for o in catalog.objects.iter_mut().filter(|o| o.id == object) {
            if !o.families.iter().any(|f| f == "thrown_object") {
                o.families.push("thrown_object".into());
            }
        }
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

    /// A one-body simulation whose centre of mass follows `path(t)` (velocity by finite
    /// differences).
    fn synthetic(spec: &SceneSpec, steps: u32, path: impl Fn(f64) -> [f64; 3]) -> Simulation {
        let dt = spec.physics.dt;
        let mut sim = Simulation {
            dt,
            dynamic_bodies: vec![spec.hazard],
            states: vec![],
            hazard_slot: 0,
            hazard_lowest_z: vec![],
            hazard_com: vec![],
            hazard_contacts: vec![],
            energy: vec![],
            initial_penetration: 0.0,
            strike: None,
            state_hash: String::new(),
            snapshots: Default::default(),
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
            sim.hazard_com.push(p);
            sim.hazard_lowest_z.push(p[2] - r);
            sim.hazard_contacts
                .push(if p[2] - r <= 0.005 { TOUCH_FLOOR } else { 0 });
            sim.energy.push(0.0);
        }
        sim
    }

    /// Held at 2 m until `release`, then in free fall, `x` in front of the observer.
    fn dropped_at(x: f64, release: f64) -> impl Fn(f64) -> [f64; 3] {
        move |t| {
            let s = (t - release).max(0.0);
            [x, 0.0, (2.0 - 0.5 * G * s * s).max(0.04)]
        }
    }

    /// The counterfactual's record of a touch at `step` (first touch too) of `part` in
    /// `region`, `ratio` times the region's limits (harm when ≥ 1).
    fn touched(step: u32, speed: f64, part: Part, region: Region, ratio: f64) -> Strike {
        Strike {
            step,
            first_touch: step,
            speed,
            impulse: 0.2,
            part,
            region,
            energy: ratio,
            force: 1.0,
            ratio,
            harm: ratio >= 1.0,
        }
    }

    #[test]
    fn the_interception_is_where_a_falling_object_comes_within_reach_after_the_decision() {
        let s = spec("apple");
        let sim = synthetic(&s, 480, dropped_at(0.5, 0.9));
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::Envelope));
        // 0.5 m from the torso axis, inside the envelope's top (1.65 m) from z = 1.65 on;
        // the closest it comes there is 0.5 m (at and below head height, 1.32 m), so the
        // interception is where √(0.5² + (z − 1.32)²) = 0.5 + tolerance.
        let tol = s.labels.interception_tolerance;
        let z = 1.32 + ((0.5 + tol).powi(2) - 0.25).sqrt();
        let t = 0.9 + (2.0 * (2.0 - z) / G).sqrt();
        assert!(
            (l.time_to_impact.unwrap() - t).abs() <= 1.5 * s.physics.dt,
            "{l:?}"
        );
        let p = l.impact_point.unwrap();
        assert!(
            (p[2] - z).abs() < 0.02 && (p[0] - 0.5).abs() < 1e-9,
            "{p:?}"
        );
        assert!((l.impact_speed.unwrap() - G * (t - 0.9)).abs() < 0.05);
        // It reaches the observer at that same moment: well after Δ + the reaction minimum.
        assert_eq!(l.time_to_reach, l.time_to_impact);
    }

    #[test]
    fn a_ball_launched_above_the_old_reach_plane_is_intercepted_at_the_observer() {
        // v1 took the first descent through z = 0.9 m, i.e. where it starts; v2 takes the
        // envelope: the ball flies level at 1.2 m through the observer's position.
        let s = spec("apple");
        let sim = synthetic(&s, 480, |t| [3.0 - 2.5 * t, 0.0, 1.2]);
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::Envelope));
        let p = l.impact_point.unwrap();
        let tol = s.labels.interception_tolerance;
        assert!(p[0] <= tol + 1e-9 && p[0] > 0.0, "{p:?}");
        let t = (3.0 - tol) / 2.5;
        assert!((l.time_to_impact.unwrap() - t).abs() <= 1.5 * s.physics.dt);
        assert!(l.closest_approach < 0.02);
    }

    #[test]
    fn a_hazard_that_arrives_before_the_decision_reaches_too_early() {
        let s = spec("apple");
        // Through the observer at t = 0.5 s.
        let sim = synthetic(&s, 480, |t| [1.0 - 2.0 * t, 0.0, 1.0]);
        let l = label(&s, &sim, None);
        let reach = l.time_to_reach.unwrap();
        assert!(reach < s.observation_window_s + s.labels.reaction_time_min);
        assert!(
            (reach - (1.0 - s.labels.interception_tolerance) / 2.0).abs() <= 1.5 * s.physics.dt,
            "{l:?}"
        );
    }

    #[test]
    fn benign_reachable_object_is_caught_and_far_one_is_no_action() {
        let s = spec("apple");
        let near = label(&s, &synthetic(&s, 480, dropped_at(0.5, 0.9)), None);
        assert!(near.reachable && !near.dangerous && !near.danger_present);
        assert_eq!(near.gt_action, Action::Catch);
        let far = label(&s, &synthetic(&s, 480, dropped_at(3.0, 0.9)), None);
        assert!(!far.reachable);
        assert_eq!(far.impact_point, None);
        assert_eq!(far.gt_action, Action::NoAction);
    }

    #[test]
    fn dangerous_or_fast_objects_are_never_caught_and_dodged_when_they_harm() {
        // Each passes through the hands' reach; the standing body, say, takes a blow to
        // the chest over its limits — DODGE — or no touch at all — NO_ACTION (rule v5).
        let blow = Some(touched(330, 4.0, Part::Torso, Region::Chest, 3.0));
        // Sharp.
        let knife = spec("chef_knife");
        let fall = synthetic(&knife, 480, dropped_at(0.5, 0.9));
        let l = label(&knife, &fall, None);
        assert!(l.dangerous && l.danger_reasons.contains(&"sharp".to_string()));
        assert_eq!(l.impact_kind, Some(ImpactKind::Envelope));
        assert_eq!(l.gt_action, Action::NoAction);
        assert_eq!(label(&knife, &fall, blow).gt_action, Action::Dodge);
        // Heavy by mass (a steel apple looks like an apple).
        let steel = spec("steel_apple");
        let fall = synthetic(&steel, 480, dropped_at(0.5, 0.9));
        let l = label(&steel, &fall, None);
        assert!(l.danger_reasons.contains(&"heavy_mass".to_string()));
        assert_eq!(l.gt_action, Action::NoAction);
        assert_eq!(label(&steel, &fall, blow).gt_action, Action::Dodge);
        // Too fast to catch: a benign apple arriving at 12 m/s.
        let apple = spec("apple");
        let fast = synthetic(&apple, 240, |t| [0.5, 12.0 - 12.0 * t, 1.0]);
        let l = label(&apple, &fast, None);
        assert!(!l.dangerous);
        assert!(l.impact_speed.unwrap() > apple.labels.catch_speed_max);
        assert_eq!(l.gt_action, Action::NoAction);
        assert_eq!(label(&apple, &fast, blow).gt_action, Action::Dodge);
    }

    #[test]
    fn closest_approach_is_used_when_the_envelope_is_never_entered_and_is_no_catch() {
        let s = spec("apple");
        // Rolling along the floor (below the envelope), passing 0.4 m from the observer.
        let sim = synthetic(&s, 720, |t| [2.0 - 1.0 * t, 0.4, 0.04]);
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::ClosestApproach));
        let p = l.impact_point.unwrap();
        assert!(p[0].abs() < 0.01 && (p[1] - 0.4).abs() < 1e-6);
        assert!((l.closest_approach - 0.4).abs() < 1e-3);
        assert!((l.time_to_impact.unwrap() - 2.0).abs() <= s.physics.dt);
        // Rule v4: 0.46 m below the lowest height a hand holds anything (0.50 m), so a
        // benign roller is no CATCH: NO_ACTION when it would not strike the standing
        // body …
        assert!((catch_excess(&s, p) - 0.46).abs() < 1e-9);
        assert!(l.reachable && !l.dangerous && !l.danger_present);
        assert_eq!(l.gt_action, Action::NoAction);
        // … and DODGE when it would harm it (the same roller striking a shank at 1 m/s
        // over its limit, say).
        let shin = touched(480, 1.0, Part::LeftShank, Region::LowerLeg, 1.5);
        let struck = label(&s, &sim, Some(shin));
        assert!(struck.danger_present && !struck.dangerous);
        assert_eq!(struck.gt_action, Action::Dodge);
        // The same apple carried 0.9 m above the floor on the same line enters the
        // envelope and is a CATCH whether or not it would strike.
        let high = synthetic(&s, 720, |t| [2.0 - 1.0 * t, 0.4, 0.9]);
        assert_eq!(
            label(&s, &high, None).impact_kind,
            Some(ImpactKind::Envelope)
        );
        assert_eq!(label(&s, &high, None).gt_action, Action::Catch);
        assert_eq!(label(&s, &high, Some(shin)).gt_action, Action::Catch);
        // Carried at 0.45 m it is within an arm's reach of the crouched shoulder (whose
        // sphere goes down to 0.30 m), so it reaches the observer there, but under the
        // 0.50 m a hand holds anything: no CATCH.
        let knee_high = synthetic(&s, 720, |t| [2.0 - 1.0 * t, 0.4, 0.45]);
        let l = label(&s, &knee_high, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::EnvelopeLate));
        assert!(envelope_excess(&s, l.impact_point.unwrap()) <= 0.0);
        assert_eq!(l.gt_action, Action::NoAction);
        // Never within reach: no impact point at all.
        let sim = synthetic(&s, 720, |t| [2.0 - 1.0 * t, 2.0, 0.04]);
        let l = label(&s, &sim, None);
        assert_eq!(l.impact_point, None);
        assert_eq!(l.gt_action, Action::NoAction);
    }

    #[test]
    fn the_hands_meet_it_before_it_touches_the_body_and_only_if_it_fits_in_the_arms() {
        let s = spec("apple");
        let dt = s.physics.dt;
        let delta = s.observation_window_s;
        // Falling straight down 0.15 m in front of the torso axis at 2 m/s from 2.0 m at
        // Δ: in the envelope from z 1.65 m (τ = 0.175 s) on; the torso axis (floor to the
        // top of the head, 1.32 m) is 0.15 m away below the head, so the interception is
        // where it first comes within 0.15 + 0.05 m: z = 1.32 + √(0.20² − 0.15²) ≈ 1.452.
        let fall = synthetic(&s, 960, move |t| {
            [0.15, 0.0, 2.0 - 2.0 * (t - delta).max(0.0)]
        });
        let free = label(&s, &fall, None);
        assert_eq!(free.impact_kind, Some(ImpactKind::Envelope));
        let z_free = free.impact_point.unwrap()[2];
        let expected = s.observer.height + (0.2f64.powi(2) - 0.15f64.powi(2)).sqrt();
        assert!(
            z_free <= expected && z_free > expected - 2.0 * dt - 1e-9,
            "{z_free}"
        );
        assert_eq!(free.gt_action, Action::Catch);
        // Say it would first touch the standing body at τ = 0.10 s (z 1.80 m): before it
        // enters the envelope, so no point is left for the hands: not a CATCH but, with
        // the touch a strike, a DODGE (an `envelope_late` point, rule v3's).
        let touch_at = |tau: f64| {
            let step = ((delta + tau) / dt).round() as u32;
            touched(step, 2.0, Part::Head, Region::SkullForehead, 3.0)
        };
        let early = label(&s, &fall, Some(touch_at(0.10)));
        assert_eq!(early.impact_kind, Some(ImpactKind::EnvelopeLate));
        assert_eq!(early.gt_action, Action::Dodge);
        // A touch at τ = 0.30 s (z 1.40 m) leaves the steps from 1.65 m down to 1.40 m,
        // whose closest to the axis is √(0.15² + 0.08²) m: the interception is where it
        // first comes within 0.05 m of that, a little higher than without the touch.
        let later = label(&s, &fall, Some(touch_at(0.30)));
        assert_eq!(later.impact_kind, Some(ImpactKind::Envelope));
        let d_last = 0.15f64.hypot(1.40 - s.observer.height);
        let z_later = s.observer.height + ((d_last + 0.05).powi(2) - 0.15f64.powi(2)).sqrt();
        let z = later.impact_point.unwrap()[2];
        assert!((z - z_later).abs() < 0.02 && z > z_free, "{z} vs {z_later}");
        assert_eq!(later.gt_action, Action::Catch);
        // A 2.2 m prop-ladder-shaped apple (bounding radius 1.12 m > 0.72 m, half the arm
        // span) on the same path is no CATCH, though its centre is where hands could be.
        let mut long = s.clone();
        long.labels.catch_radius_max = 0.72;
        let hazard = long.hazard;
        long.bodies[hazard].parts = vec![rh_physics::spec::PartSpec {
            shape: rh_physics::spec::ShapeSpec::Box {
                half_extents: [0.225, 0.03, 1.1],
            },
            offset: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
        }];
        assert!(!fits_in_arms(&long) && fits_in_arms(&s));
        let l = label(&long, &fall, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::Envelope));
        assert_eq!(l.gt_action, Action::NoAction);
        assert_eq!(
            label(&long, &fall, Some(touch_at(0.30))).gt_action,
            Action::Dodge
        );
    }

    #[test]
    fn the_hands_must_get_there_in_time() {
        // Rule v4 on constructed paths at shoulder-band height (z 1.0: the arms reach
        // 0.15 + 0.55 = 0.70 m from the torso axis without a step).
        let s = spec("apple");
        let delta = s.observation_window_s;
        let dt = s.physics.dt;
        assert_eq!(
            (s.labels.catch_walk_speed, s.labels.catch_walk_accel),
            (1.5, 4.0)
        );
        // Hovering 1.0 m away: 0.30 m to walk, under v²/a = 0.5625 m, so √(2·0.30/4) s,
        // plus 0.1 s for the hands; the interception is the first step after Δ that late.
        let need = (2.0f64 * 0.30 / 4.0).sqrt() + 0.1;
        assert!((time_to_hands(&s, [1.0, 0.0, 1.0]) - need).abs() < 1e-12);
        let hover = synthetic(&s, 720, |_| [1.0, 0.0, 1.0]);
        let l = label(&s, &hover, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::Envelope));
        assert_eq!(l.gt_action, Action::Catch);
        let t = l.time_to_impact.unwrap() - delta;
        assert!(t >= need - 1e-9 && t < need + dt + 1e-9, "{t} vs {need}");
        // Within arm's reach no walk: only the hands' 0.1 s.
        assert!((time_to_hands(&s, [0.6, 0.0, 1.0]) - 0.1).abs() < 1e-12);
        // Beyond 1.5²/(2·4) m the walk cruises: s/1.5 + 1.5/8.
        let far = 0.70 + 0.9;
        let cruise = 0.9 / 1.5 + 1.5 / 8.0 + 0.1;
        assert!((time_to_hands(&s, [far, 0.0, 1.0]) - cruise).abs() < 1e-12);
        // Crossing the envelope's rim 1.1 m out at 3 m/s: inside for 0.32 s only, and the
        // hands need ≥ √(2·0.40/4) + 0.1 = 0.547 s to get 1.1 m out: too late. A benign
        // apple that would not strike is then NO_ACTION, not CATCH.
        let cross = synthetic(&s, 720, move |t| [1.1, -0.6 + 3.0 * (t - delta), 1.0]);
        let l = label(&s, &cross, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::EnvelopeLate));
        assert!(envelope_excess(&s, l.impact_point.unwrap()) <= 0.0);
        assert_eq!(l.gt_action, Action::NoAction);
        // The same crossing at 0.5 m/s is slow enough: CATCH, at the first envelope step
        // the hands make in time (near the closest in-time approach to the axis).
        let slow = synthetic(&s, 960, move |t| [1.1, -0.6 + 0.5 * (t - delta), 1.0]);
        let l = label(&s, &slow, None);
        assert_eq!(l.impact_kind, Some(ImpactKind::Envelope));
        assert_eq!(l.gt_action, Action::Catch);
        let k = ((l.time_to_impact.unwrap()) / dt).round() as u32;
        let late = |k: u32| time_to_hands(&s, slow.hazard_com(k)) - (k as f64 * dt - delta);
        assert!(
            late(k) <= 1e-9 && late(k - 1) > 0.0,
            "{} {}",
            late(k),
            late(k - 1)
        );
    }

    #[test]
    fn the_envelope_follows_the_configured_body() {
        let s = spec("apple");
        let out = s.labels.envelope_shoulder_offset + s.labels.envelope_step;
        let reach = s.labels.envelope_arm_reach;
        let sz = s.observer.shoulder_z;
        // Shoulder height: out to offset + step + arm reach.
        assert!(envelope_excess(&s, [out + reach - 1e-6, 0.0, sz]) <= 0.0);
        assert!(envelope_excess(&s, [out + reach + 1e-3, 0.0, sz]) > 0.0);
        // Straight up from the shoulder, and down from the crouched shoulder.
        assert!(envelope_excess(&s, [0.0, 0.0, sz + reach - 1e-6]) <= 0.0);
        assert!(envelope_excess(&s, [0.0, 0.0, sz + reach + 1e-3]) > 0.0);
        // Down to the crouched shoulder's arm reach (0.30 m); the hands hold things only
        // down to `envelope_min_height` (rule v4).
        let low = sz - s.labels.envelope_crouch - reach;
        let floor = s.labels.envelope_min_height;
        assert!((low - 0.30).abs() < 1e-9 && floor == 0.50);
        assert!(envelope_excess(&s, [0.0, 0.3, low + 1e-6]) <= 0.0);
        assert!(envelope_excess(&s, [0.0, 0.3, low - 1e-3]) > 0.0);
        assert!(catch_excess(&s, [0.0, 0.3, floor + 1e-6]) <= 0.0);
        assert!((catch_excess(&s, [0.0, 0.3, floor - 0.1]) - 0.1).abs() < 1e-9);
        // Older specs (no `envelope_min_height`: 0) hold wherever the envelope reaches.
        let mut old = s.clone();
        old.labels.envelope_min_height = 0.0;
        assert!(catch_excess(&old, [0.0, 0.3, low + 1e-6]) <= 0.0);
    }

    #[test]
    fn danger_present_is_the_harm_verdict_and_dodge_needs_it() {
        let s = spec("apple");
        // Out of reach of the hands (3 m away): never CATCH.
        let sim = synthetic(&s, 480, dropped_at(3.0, 0.9));
        let at = |ratio| Some(touched(300, 3.0, Part::Torso, Region::Chest, ratio));
        let hard = label(&s, &sim, at(2.5));
        assert!(hard.danger_present && hard.reachable);
        assert_eq!(hard.gt_action, Action::Dodge);
        assert_eq!(hard.harm_region.as_deref(), Some("chest"));
        assert_eq!(hard.harm_ratio, Some(2.5));
        // A touch under the chest's limits is no danger: NO_ACTION.
        let soft = label(&s, &sim, at(0.4));
        assert!(!soft.danger_present && soft.harm_energy.is_some());
        assert_eq!(soft.gt_action, Action::NoAction);
        // A touch is the observer being reached.
        assert_eq!(soft.time_to_reach, Some(300.0 * s.physics.dt));
        // Rule v5: a dangerous object (a knife) is DODGE only when it would harm the
        // standing body; falling beside it without a touch it is NO_ACTION.
        let knife = spec("chef_knife");
        let near = synthetic(&knife, 480, dropped_at(0.5, 0.9));
        let l = label(&knife, &near, None);
        assert!(l.dangerous && !l.danger_present && l.harm_region.is_none());
        assert_eq!(l.gt_action, Action::NoAction);
        let mut cut = touched(300, 0.3, Part::LeftForearm, Region::Forearm, 0.01);
        cut.harm = true; // a sharp hazard's touch harms at any energy
        let l = label(&knife, &near, Some(cut));
        assert!(l.danger_present && l.harm_ratio.unwrap() < 1.0);
        assert_eq!(l.gt_action, Action::Dodge);
    }

    #[test]
    fn time_to_floor_is_refined_within_the_step() {
        let s = spec("apple");
        let sim = synthetic(&s, 480, dropped_at(0.5, 0.0));
        // The lowest point (centre − 4 cm) falls 1.96 m.
        let expected = (2.0 * 1.96 / G).sqrt();
        let measured = time_to_floor(&s, &sim).unwrap();
        assert!(
            (measured - expected).abs() / expected < 0.002,
            "{measured} vs {expected}"
        );
        // Not a multiple of the step: it is interpolated.
        let steps = measured / s.physics.dt;
        assert!((steps - steps.round()).abs() > 1e-6);
    }
}
