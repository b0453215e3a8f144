//! thrown_object: an object is thrown at the observer (specification §4).
//!
//! Aimed (label rule v5): the throw is aimed at a target point beside the observer
//! chosen by the group's intent (`crate::intent`) — in front of the chest at a height the
//! hands hold (a benign object), into the chest or head (a dangerous one), or 1.8–2.2 m
//! to the side (a near miss) — and arrives there a drawn flight time after the release,
//! long enough for Δ plus the reaction time. Every band flies for that time (less only
//! where its speed or the ceiling cannot keep it up so long), so a faster band is
//! released from farther away: the release point follows from the speed, like the
//! elevation. No air drag: the centre of mass flies a parabola through the target
//! until it touches something (closed-form test).

use super::launch::*;
use super::*;
use crate::intent::Intent;

pub struct ThrownObject;

/// Clearance kept between the throw's apex (plus the object's size) and the ceiling (m).
const CEILING_CLEARANCE: f64 = 0.1;
/// Distance kept between the thrower's hand or the observer and the walls (m).
const WALL_MARGIN: f64 = 0.3;

/// The flight time (s) to draw from: release at t0, arrival after Δ (0.6 s) plus the
/// reaction time (0.2 s) and a margin.
pub const FLIGHT_S: [f64; 2] = [1.0, 1.15];

/// The flight time a throw at `speed` from height `h0` to height `h` can last at most:
/// its vertical launch speed at most `vz_max` (m/s) — 97% of the speed (a throw has some
/// horizontal speed) or what keeps the apex under the ceiling.
pub fn longest_flight(speed: f64, vz_max: f64, h0: f64, h: f64) -> f64 {
    let vz = vz_max.min(0.97 * speed).max(0.0);
    (vz + (vz * vz - 2.0 * GRAVITY * (h - h0)).max(0.0).sqrt()) / GRAVITY
}

/// The launch velocity (horizontal along the throw, vertical) of a throw at `speed` from
/// height `h0` that is at height `h` after `flight` seconds.
pub fn launch_velocity(speed: f64, flight: f64, h0: f64, h: f64) -> (f64, f64) {
    let vz = (h - h0 + 0.5 * GRAVITY * flight * flight) / flight;
    ((speed * speed - vz * vz).max(0.0).sqrt(), vz)
}

/// The shortest flight (s) of a throw's fastest band: it reaches the observer's reach at
/// least Δ + the reaction time (0.8 s) after the release.
pub const MIN_FLIGHT_S: f64 = 0.85;
/// How many throws a layout draws at most to find one the room holds for [`MIN_FLIGHT_S`].
const THROW_DRAWS: u32 = 16;

/// One drawn throw: its heading, release height, drawn flight time, target and spin.
#[derive(Clone, Copy)]
struct Throw {
    heading_angle: f64,
    dir: [f64; 2],
    side: [f64; 2],
    launch_height: f64,
    flight: f64,
    ahead_d: f64,
    across: f64,
    height: f64,
    spin: [f64; 3],
    yaw: f64,
    vz_ceiling: f64,
    span: f64,
}

impl Throw {
    /// The flight time of a band thrown at `v`: the drawn one, less where the ceiling
    /// caps the arc or the room the range (bisection on t).
    fn flight_of(&self, v: f64) -> f64 {
        let (h0, h) = (self.launch_height, self.height);
        let t = self.flight.min(longest_flight(v, self.vz_ceiling, h0, h));
        let (vh, _) = launch_velocity(v, t, h0, h);
        if vh * t <= self.span {
            return t;
        }
        let (mut lo, mut hi) = (0.05, t);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if launch_velocity(v, mid, h0, h).0 * mid > self.span {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }
}

/// Draws a throw: heading, release height, flight time, the target where the group's
/// intent puts it, spin and yaw.
fn draw_throw(input: &FamilyInput, rng: &mut ChaCha8Rng) -> Throw {
    let room = input.room;
    let heading_angle = diagonal_heading(rng, room, 0.05);
    let dir = heading(heading_angle);
    let side = left_of(dir);
    let launch_height = uniform(rng, 1.0, 1.3);
    let flight = uniform(rng, FLIGHT_S[0], FLIGHT_S[1]);
    // Where the target lies from the torso axis: `ahead` toward the thrower, `across`
    // to the side, at `height`.
    let (ahead_d, across, height) = match input.intent {
        Intent::Hands => (
            uniform(rng, 0.2, 0.4),
            uniform(rng, -0.15, 0.15),
            uniform(rng, 0.75, 1.15),
        ),
        Intent::Body => (
            uniform(rng, -0.05, 0.05),
            uniform(rng, -0.05, 0.05),
            uniform(rng, 1.0, 1.3),
        ),
        Intent::Miss => {
            let off = uniform(rng, 1.8, 2.2);
            let sign = if uniform(rng, 0.0, 1.0) < 0.5 {
                -1.0
            } else {
                1.0
            };
            (0.0, off * sign, uniform(rng, 0.6, 1.2))
        }
    };
    let spin = [
        uniform(rng, -6.0, 6.0),
        uniform(rng, -6.0, 6.0),
        uniform(rng, -6.0, 6.0),
    ];
    let yaw = uniform(rng, 0.0, std::f64::consts::TAU);
    let radius = input.object.half_extents().into_iter().fold(0.0, f64::max);
    let rise = room.ceiling_height - CEILING_CLEARANCE - radius - launch_height;
    // Each band's flight and range; the room must hold the longest range plus the
    // observer's offset.
    Throw {
        heading_angle,
        dir,
        side,
        launch_height,
        flight,
        ahead_d,
        across,
        height,
        spin,
        yaw,
        vz_ceiling: (2.0 * GRAVITY * rise.max(0.0)).sqrt(),
        span: room_span(room, dir, WALL_MARGIN) - ahead_d.max(0.0),
    }
}

impl Family for ThrownObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "thrown_object",
            speed_parameter: "launch_speed_mps",
            speed_sweep: true,
        }
    }

    fn self_aimed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        // A throw whose fastest band the room cannot hold for MIN_FLIGHT_S (its ceiling
        // caps the arc, its length the range) arrives too soon to react: the throw is
        // drawn again, up to THROW_DRAWS times (the last draw stands).
        let fastest = input.band_speeds.iter().fold(0.0, |a: f64, &b| a.max(b));
        let mut tries = 0;
        let throw = loop {
            let throw = draw_throw(input, rng);
            tries += 1;
            if throw.flight_of(fastest) >= MIN_FLIGHT_S || tries == THROW_DRAWS {
                break throw;
            }
        };
        let Throw {
            heading_angle,
            dir,
            side,
            launch_height,
            ahead_d,
            across,
            height,
            spin,
            yaw,
            ..
        } = throw;
        let room = input.room;
        let range_of = |v: f64| throw.flight_of(v);
        let range = |v: f64| {
            let t = range_of(v);
            launch_velocity(v, t, launch_height, height).0 * t
        };
        let longest = input
            .band_speeds
            .iter()
            .map(|&v| range(v))
            .fold(0.0, f64::max);
        let origin = span_start(rng, room, dir, longest + ahead_d.max(0.0), WALL_MARGIN);
        // The target's ground point, the torso axis `ahead_d` beyond it, and this band's
        // release point `range` before it.
        let target_xy = ahead(ahead(origin, dir, longest), side, across);
        let observer_xy = ahead(ahead(target_xy, dir, ahead_d), side, -across);
        let t = range_of(input.speed);
        let (vh, vz) = launch_velocity(input.speed, t, launch_height, height);
        let release = ahead(target_xy, dir, -vh * t);
        let start = [release[0], release[1], launch_height];
        let linvel = [dir[0] * vh, dir[1] * vh, vz];
        let hazard = hazard_body(input.object, start, yaw_quat(yaw), linvel, spin);
        let observer = ObserverPose {
            x: observer_xy[0],
            y: observer_xy[1],
            yaw: heading_angle + std::f64::consts::PI,
        };
        Layout {
            bodies: vec![hazard],
            joints: vec![],
            hazard: 0,
            source_support: None,
            observer,
            params: BTreeMap::from([
                ("launch_height_m".into(), launch_height),
                ("throw_distance_m".into(), vh * t),
                ("aim_height_m".into(), height),
                ("aim_target_x_m".into(), target_xy[0]),
                ("aim_target_y_m".into(), target_xy[1]),
                ("flight_s".into(), t),
                ("elevation_rad".into(), vz.atan2(vh)),
            ]),
        }
    }

    fn event_happened(&self, _spec: &SceneSpec, sim: &Simulation) -> bool {
        // A real throw: at least a metre of flight before anything is touched.
        let Some(k) = sim.first_contact_step() else {
            return false;
        };
        let a = sim.hazard_position(0);
        let b = sim.hazard_position(k);
        ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt() >= 1.0
    }
}
