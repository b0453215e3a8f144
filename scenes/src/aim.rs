//! Aimed events (label rule v5, specification §6): the observer stands where the hazard's own
//! path passes, after Δ plus the reaction time, at a sampled meeting height.
//!
//! The plain simulation never contains the observer's body (only the counterfactual run
//! does), so a scene's hazard path is known before the observer is placed. [`aim_group`]
//! takes a group's simulated bands (one observer pose for all four, specification §4: the bands
//! share everything but the speed), draws candidate meeting points on their paths from
//! the group's "aim" stream and keeps the first pose that every band's path meets after
//! Δ + `reaction_time_min` + `reaction_margin_s` and none reaches earlier — else the
//! candidate that most bands meet. A group drawn as a near miss (`build.far_observer_share`)
//! stands beside the path instead, beyond the reach envelope. Everything else of the
//! family's layout is unchanged; the pose depends only on the paths and the draws.

use crate::intent::Intent;
use crate::label::{approach, interception, ImpactKind};
use rand::RngExt;
use rh_physics::obstacles::Obstacles;
use rh_physics::simulate::Simulation;
use rh_physics::spec::{BodyKind, SceneSpec, Vec3};
use serde::{Deserialize, Serialize};

/// `[aim]` of `configs/default.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct AimConfig {
    /// Candidate meeting points drawn per group (0: events are not aimed; the family's
    /// own observer pose stands).
    pub candidates: u32,
    /// How many of the candidates that every band meets the driver tries, in turn, when
    /// the validators reject a pose (a camera that cannot see the hazard from there).
    #[serde(default)]
    pub tries: u32,
    /// A group whose event could not be aimed (the family's own pose stood) is planned
    /// afresh — another object and room of its family — up to this many times (at most
    /// `validators.replans`); the last plan stands.
    #[serde(default)]
    pub replans: u32,
    /// ... after this many attempts (new layouts of the same plan) none of which could
    /// be aimed.
    #[serde(default)]
    pub attempts: u32,
    /// `attempts` for these families instead (their layouts rarely give all four speed
    /// bands one meeting point).
    #[serde(default)]
    pub attempts_by_family: std::collections::BTreeMap<String, u32>,
    /// Extra time beyond Δ + `reaction_time_min` before the path may meet the observer (s).
    pub reaction_margin_s: f64,
    /// The meeting height band (hazard centre height, m) for every family but those in
    /// `meet_height_by_family`.
    pub meet_height: [f64; 2],
    #[serde(default)]
    pub meet_height_by_family: std::collections::BTreeMap<String, [f64; 2]>,
    /// The torso axis stands this far (m) ahead of the meeting point along the hazard's
    /// horizontal motion, and up to `lateral` (m) to either side.
    pub ahead: [f64; 2],
    pub lateral: f64,
    /// A hazard aimed at the body (a dangerous one, or one too large for the arms): the
    /// meeting height band (m), and the torso axis `body_ahead` (m) beyond the meeting
    /// point, up to `body_lateral` (m) to either side.
    #[serde(default)]
    pub body_meet_height: [f64; 2],
    #[serde(default)]
    pub body_ahead: [f64; 2],
    #[serde(default)]
    pub body_lateral: f64,
    /// Aimed at the body, the meeting point is one where the hazard moves at least this
    /// share of its top speed after the earliest step.
    #[serde(default)]
    pub body_speed_share: f64,
    /// A benign object whose largest half extent exceeds this (m) is aimed at the body,
    /// not the hands (`intent::Intent::for_object`; 0: no limit).
    #[serde(default)]
    pub hands_half_length_max: f64,
    /// A near miss stands this far (m) beyond `reach_radius` + the hazard's bounding
    /// radius, beside the path.
    pub miss_clearance: [f64; 2],
    /// The observer's axis keeps this distance (m) from the room's walls.
    pub wall_margin: f64,
    /// The hazard counts as meeting the body when its centre comes within the torso
    /// radius + its bounding radius + this (m) of the torso axis.
    pub touch_slack: f64,
    /// Before the earliest meeting step the hazard's centre stays farther than this (m)
    /// from the torso axis (the in-frame check's `frame_check_until_within`).
    #[serde(default)]
    pub clear_before: f64,
}

/// What the aim decided, recorded in the spec's `family_params` (`aim_*`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aim {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
    /// Which candidate won, and the meeting point's height on the band it was drawn on.
    pub candidate: u32,
    pub meet_height: f64,
    /// How many bands' paths meet the pose as intended.
    pub bands_met: u32,
    pub near_miss: bool,
    pub intent: Intent,
}

/// The hazard speed below which a path point is not a meeting candidate (m/s).
const MOVING: f64 = 0.1;

/// Places the observer of every band of `runs` (same pose) on the bands' hazard paths:
/// the first of [`aims`], applied. Returns it, or `None` (poses unchanged).
pub fn aim_group(runs: &mut [(SceneSpec, Simulation)], cfg: &AimConfig) -> Option<Aim> {
    let aim = aims(runs, cfg).into_iter().next()?;
    apply(runs, &aim);
    Some(aim)
}

/// The poses, in the order of the group's drawn candidates, that every band's path meets
/// as the group's intent asks (at most `cfg.tries`; at least one when `tries` is 0). Empty
/// when none does (the family's own pose then stands), when the family aims its own event,
/// or when the spec records no intent. The driver labels them in turn and keeps the first
/// whose bands all pass the validators (an aimed pose can hide the hazard from a camera).
pub fn aims(runs: &[(SceneSpec, Simulation)], cfg: &AimConfig) -> Vec<Aim> {
    let Some(first) = runs.first().map(|(s, _)| s) else {
        return vec![];
    };
    let Some(intent) = driver_aimed(first, cfg) else {
        return vec![];
    };
    let near_miss = intent == Intent::Miss;
    let mut rng = rh_physics::seeds::stream(first.seed, first.attempt, "aim");
    // Always the same draws, whatever the paths.
    let (ahead, lateral) = match intent {
        Intent::Body => (cfg.body_ahead, cfg.body_lateral),
        _ => (cfg.ahead, cfg.lateral),
    };
    let draws: Vec<[f64; 4]> = (0..cfg.candidates)
        .map(|_| {
            [
                rng.random_range(0.0..1.0),
                rng.random_range(ahead[0]..=ahead[1]),
                rng.random_range(-lateral..=lateral),
                rng.random_range(cfg.miss_clearance[0]..=cfg.miss_clearance[1]),
            ]
        })
        .collect();
    let band = match intent {
        Intent::Body => cfg.body_meet_height,
        _ => cfg
            .meet_height_by_family
            .get(&first.family)
            .copied()
            .unwrap_or(cfg.meet_height),
    };
    let wanted = cfg.tries.max(1) as usize;
    let mut found = Vec::new();
    let mut best_met = None;
    let at_rest: Vec<Obstacles> = runs.iter().map(|(s, _)| bodies_at_rest(s)).collect();
    let points: Vec<Vec<u32>> = runs
        .iter()
        .map(|(s, m)| meeting_points(s, m, cfg, band, intent))
        .collect();
    for (c, d) in draws.iter().enumerate() {
        let (spec, sim) = &runs[c % runs.len()];
        let bodies = &at_rest[c % runs.len()];
        let points = &points[c % runs.len()];
        let Some((x, y, yaw, meet_height)) =
            clear_candidate(spec, sim, bodies, points, cfg, intent, d)
        else {
            continue;
        };
        let met = runs
            .iter()
            .filter(|(s, m)| meets(&posed(s, x, y, yaw), m, cfg, intent))
            .count() as u32;
        if best_met.is_none_or(|(m, _, _)| met > m) {
            best_met = Some((met, c, meet_height));
        }
        if met as usize == runs.len() {
            found.push(Aim {
                x,
                y,
                yaw,
                candidate: c as u32,
                meet_height,
                bands_met: met,
                near_miss,
                intent,
            });
            if found.len() == wanted {
                break;
            }
        }
    }
    if std::env::var_os("RH_AIM_DEBUG").is_some() {
        let clear = (0..draws.len())
            .filter(|&c| {
                let (spec, sim) = &runs[c % runs.len()];
                let bodies = &at_rest[c % runs.len()];
                let points = &points[c % runs.len()];
                clear_candidate(spec, sim, bodies, points, cfg, intent, &draws[c]).is_some()
            })
            .count();
        eprintln!(
            "aim {} {} attempt {}: {clear}/{} clear, best (met, candidate, height) {best_met:?}, {} aims",
            first.family,
            first.selection.object_id,
            first.attempt,
            draws.len(),
            found.len()
        );
    }
    found
}

impl AimConfig {
    /// How many unaimed layouts of one plan of `family` are drawn before it is planned
    /// afresh (`attempts_by_family`, else `attempts`; at least 1).
    pub fn attempts_for(&self, family: &str) -> u32 {
        self.attempts_by_family
            .get(family)
            .copied()
            .unwrap_or(self.attempts)
            .max(1)
    }
}

/// The intent of a spec whose observer [`aims`] places: events are aimed
/// (`candidates` > 0), the family does not aim its own event (a throw keeps its pose),
/// and the spec records an intent. `None` otherwise.
pub fn driver_aimed(spec: &SceneSpec, cfg: &AimConfig) -> Option<Intent> {
    let self_aimed = crate::families::get(&spec.family).is_some_and(|f| f.self_aimed());
    (cfg.candidates > 0 && !self_aimed)
        .then(|| Intent::of(spec))
        .flatten()
}

/// Whether [`apply`] stood the spec's observer at an aimed pose.
pub fn posed_by_aim(spec: &SceneSpec) -> bool {
    spec.family_params.contains_key(CANDIDATE_PARAM)
}

/// The `family_params` key [`apply`] records the winning candidate under.
const CANDIDATE_PARAM: &str = "aim_candidate";

/// Stands the observer of every band of `runs` at `aim` and records it in the specs'
/// `family_params` (`aim_candidate`, `aim_meet_height`, `aim_bands_met`).
pub fn apply(runs: &mut [(SceneSpec, Simulation)], aim: &Aim) {
    for (spec, _) in runs.iter_mut() {
        *spec = posed(spec, aim.x, aim.y, aim.yaw);
        let p = &mut spec.family_params;
        p.insert(CANDIDATE_PARAM.into(), aim.candidate as f64);
        p.insert("aim_meet_height".into(), aim.meet_height);
        p.insert("aim_bands_met".into(), aim.bands_met as f64);
    }
}

/// The spec with its observer standing at (x, y) facing `yaw`.
pub fn posed(spec: &SceneSpec, x: f64, y: f64, yaw: f64) -> SceneSpec {
    let mut s = spec.clone();
    s.observer.x = x;
    s.observer.y = y;
    s.observer.yaw = yaw;
    s
}

/// The first step from which the path may meet the observer.
fn earliest_step(spec: &SceneSpec, cfg: &AimConfig) -> u32 {
    let t = spec.observation_window_s + spec.labels.reaction_time_min + cfg.reaction_margin_s;
    (t / spec.physics.dt).ceil() as u32
}

/// The first of draw `d`'s candidate poses (the offset along the hazard's motion, then
/// turned to its left, its right and back) that stands clear ([`stands_clear`]): a fall
/// beside a wall or a cabinet is met from the open side.
/// `bodies` is [`bodies_at_rest`] of `spec`.
fn clear_candidate(
    spec: &SceneSpec,
    sim: &Simulation,
    bodies: &Obstacles,
    points: &[u32],
    cfg: &AimConfig,
    intent: Intent,
    d: &[f64; 4],
) -> Option<(f64, f64, f64, f64)> {
    (0..4)
        .filter_map(|turn| candidate(spec, sim, points, intent, d, turn))
        .find(|&(x, y, _, _)| stands_clear(spec, bodies, cfg, x, y))
}

/// The path points of one band a meeting point is drawn from: the steps after the
/// earliest step where the hazard moves (aimed at the body: at least `body_speed_share`
/// of its top speed there) and its centre height is in `band` — all the moving ones if
/// none is in `band`, or for a near miss.
fn meeting_points(
    spec: &SceneSpec,
    sim: &Simulation,
    cfg: &AimConfig,
    band: [f64; 2],
    intent: Intent,
) -> Vec<u32> {
    let from = earliest_step(spec, cfg);
    let fastest = (from..=sim.steps())
        .map(|k| norm(sim.hazard_velocity(k)))
        .fold(0.0, f64::max);
    // Aimed at the body, the meeting point is where the hazard still moves at least
    // `body_speed_share` of its top speed (not the slow end of its path).
    let slowest = if intent == Intent::Body {
        MOVING.max(cfg.body_speed_share * fastest)
    } else {
        MOVING
    };
    let moving: Vec<u32> = (from..=sim.steps())
        .filter(|&k| norm(sim.hazard_velocity(k)) > slowest)
        .collect();
    let in_band: Vec<u32> = moving
        .iter()
        .copied()
        .filter(|&k| (band[0]..=band[1]).contains(&sim.hazard_com(k)[2]))
        .collect();
    // A path that never passes at a height of the band meets the body where it can.
    if intent == Intent::Miss || in_band.is_empty() {
        moving
    } else {
        in_band
    }
}

/// A candidate pose from draw `d` = [time fraction, ahead, lateral, miss clearance] on
/// one band's path: the meeting point is the `d[0]` fraction of the moving path points
/// after the earliest step whose centre height is in `band`; the offset runs along the
/// hazard's horizontal motion there, turned by `turn` quarter turns (0, left, right, back).
fn candidate(
    spec: &SceneSpec,
    sim: &Simulation,
    points: &[u32],
    intent: Intent,
    d: &[f64; 4],
    turn: usize,
) -> Option<(f64, f64, f64, f64)> {
    if points.is_empty() {
        return None;
    }
    let near_miss = intent == Intent::Miss;
    let k = points[((d[0] * points.len() as f64) as usize).min(points.len() - 1)];
    let p = sim.hazard_com(k);
    let v = sim.hazard_velocity(k);
    let start = sim.hazard_com(0);
    // Along the horizontal motion there; for a (nearly) vertical fall, away from where
    // it started, else toward where the family stood its observer.
    let o = &spec.observer;
    let u = unit2([v[0], v[1]])
        .or_else(|| unit2([p[0] - start[0], p[1] - start[1]]))
        .or_else(|| unit2([o.x - p[0], o.y - p[1]]))
        .unwrap_or([1.0, 0.0]);
    let u = match turn {
        0 => u,
        1 => [-u[1], u[0]],
        2 => [u[1], -u[0]],
        _ => [-u[0], -u[1]],
    };
    let side = [-u[1], u[0]];
    let (along, across) = if near_miss {
        let r = spec.hazard_body().bounding_radius();
        let off = spec.labels.reach_radius + r + d[3];
        (0.0, if d[2] < 0.0 { -off } else { off })
    } else {
        (d[1], d[2])
    };
    let x = p[0] + u[0] * along + side[0] * across;
    let y = p[1] + u[1] * along + side[1] * across;
    // Face the hazard as the decision moment shows it; straight at the oncoming path
    // when it is (nearly) overhead then.
    let seen = sim.hazard_com(spec.decision_step().min(sim.steps()));
    let yaw = match unit2([seen[0] - x, seen[1] - y]) {
        Some(f) if ((seen[0] - x).powi(2) + (seen[1] - y).powi(2)).sqrt() > 0.3 => f[1].atan2(f[0]),
        _ => (-u[1]).atan2(-u[0]),
    };
    Some((x, y, yaw, p[2]))
}

/// Every body of `spec` as it stands at t0 (furniture, props and the hazard itself), as
/// obstacles.
fn bodies_at_rest(spec: &SceneSpec) -> Obstacles {
    let mut at_rest = spec.clone();
    for b in at_rest.bodies.iter_mut() {
        b.kind = BodyKind::Fixed;
    }
    Obstacles::of(&at_rest)
}

/// Whether an observer at (x, y) stands inside the room, clear of `bodies`
/// ([`bodies_at_rest`] of `spec`).
fn stands_clear(spec: &SceneSpec, bodies: &Obstacles, cfg: &AimConfig, x: f64, y: f64) -> bool {
    let [w, d] = [spec.room.size[0], spec.room.size[1]];
    if x.abs() > w / 2.0 - cfg.wall_margin || y.abs() > d / 2.0 - cfg.wall_margin {
        return false;
    }
    let o = &spec.observer;
    let r = o.torso_radius + 0.05;
    let ring = [[0.0, 0.0], [r, 0.0], [-r, 0.0], [0.0, r], [0.0, -r]];
    [0.05, 0.4, 0.8, 1.1, o.height].iter().all(|&z| {
        !ring
            .iter()
            .any(|[dx, dy]| bodies.contains([x + dx, y + dy, z]))
    })
}

/// Whether a posed band's path does what the aim intends. Always: nothing enters the
/// reach envelope before the earliest step. Then, for `Hands`, the label rule's
/// interception is a point the hands can hold in time (`label::interception`, with the
/// first touch of the body estimated from the path: the hazard's centre within the torso
/// radius + its bounding radius of the axis); for `Body`, the hazard's centre comes
/// within the torso radius + half its bounding radius + `touch_slack` of the torso axis;
/// for `Miss`, it never comes within `reach_radius`.
pub fn meets(spec: &SceneSpec, sim: &Simulation, cfg: &AimConfig, intent: Intent) -> bool {
    let from = earliest_step(spec, cfg).min(sim.steps() + 1);
    let o = &spec.observer;
    let radius = spec.hazard_body().bounding_radius();
    let distance = |k: u32| o.torso_axis_distance(sim.hazard_com(k));
    // The reaction-time validator's "reaches the observer" (label `time_to_reach`), and
    // no touch of the body, before the earliest step.
    let reached = approach(spec, sim, 0, spec.labels.reach_radius).map(|(k, _)| k);
    if reached.is_some_and(|k| k < from) {
        return false;
    }
    // Nor does its centre come within `clear_before` of the torso axis before then (a
    // pendulum hanging beside the head at t0 that swings away and back: it has reached
    // the observer before any decision).
    if (0..from).any(|k| distance(k) <= cfg.clear_before) {
        return false;
    }
    let closest = (from..=sim.steps())
        .map(distance)
        .fold(f64::INFINITY, f64::min);
    match intent {
        Intent::Miss => closest > spec.labels.reach_radius,
        Intent::Body => closest <= o.torso_radius + 0.5 * radius + cfg.touch_slack,
        Intent::Hands => {
            let decision = spec.decision_step().min(sim.steps());
            let touch = (decision..=sim.steps()).find(|&k| distance(k) <= o.torso_radius + radius);
            interception(spec, sim, decision, spec.labels.closest_approach_max, touch)
                .is_some_and(|(_, kind)| kind == ImpactKind::Envelope)
        }
    }
}

fn norm(v: Vec3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn unit2(v: [f64; 2]) -> Option<[f64; 2]> {
    let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
    (n > 0.2).then(|| [v[0] / n, v[1] / n])
}
