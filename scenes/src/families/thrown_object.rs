//! thrown_object: an object is thrown at the observer (SPEC §4).
//!
//! Timing (label rule v2): indoors a throw that reaches the observer only after
//! Δ + 0.2 s must be a long lob under the ceiling, so the thrower stands along the room's
//! diagonal as far away as the fastest band needs to arrive `FASTEST_FLIGHT_S` after the
//! release (its apex under the ceiling); each band aims at the observer with the longest
//! flight whose apex clears the ceiling, and a throw too weak to carry that far is thrown
//! at its longest range and falls short, arriving (if at all) bouncing, rolling or sliding.

use super::launch::*;
use super::*;

pub struct ThrownObject;

/// Flight time of the fastest band's throw to the aim point (s).
pub const FASTEST_FLIGHT_S: f64 = 0.9;
/// Clearance kept between the throw's apex (plus the object's size) and the ceiling (m).
const CEILING_CLEARANCE: f64 = 0.1;
/// Distance kept between the thrower's hand or the observer and the walls (m).
const WALL_MARGIN: f64 = 0.3;

/// Elevation of a throw at `speed` toward a point `dx` away and `dy` higher whose apex
/// may rise at most `rise` above the release: of the two aiming solutions, the one with
/// the longer flight whose apex fits (the flatter one when neither does); when the speed
/// cannot carry that far, the longest throw that fits (45°, or flatter under the ceiling).
pub fn indoor_elevation(speed: f64, dx: f64, dy: f64, rise: f64) -> f64 {
    let v2 = speed * speed;
    let fits = |e: f64| (speed * e.sin()).max(0.0).powi(2) / (2.0 * GRAVITY) <= rise;
    let disc = v2 * v2 - GRAVITY * (GRAVITY * dx * dx + 2.0 * dy * v2);
    if disc < 0.0 || dx <= 0.0 {
        let ceiling = ((2.0 * GRAVITY * rise.max(0.0)).sqrt() / speed)
            .min(1.0)
            .asin();
        return ceiling.min(std::f64::consts::FRAC_PI_4);
    }
    let high = ((v2 + disc.sqrt()) / (GRAVITY * dx)).atan();
    let low = ((v2 - disc.sqrt()) / (GRAVITY * dx)).atan();
    if fits(high) {
        high
    } else {
        low
    }
}

/// Horizontal distance at which a throw at `speed`, released at height `h0`, passes
/// height `ha` after `flight` seconds (0 when the speed cannot stay up that long).
pub fn throw_distance(speed: f64, flight: f64, h0: f64, ha: f64) -> f64 {
    let vz = (ha - h0 + 0.5 * GRAVITY * flight * flight) / flight;
    (speed * speed - vz * vz).max(0.0).sqrt() * flight
}

impl Family for ThrownObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "thrown_object",
            speed_parameter: "launch_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let room = input.room;
        let heading_angle = diagonal_heading(rng, room, 0.05);
        let dir = heading(heading_angle);
        let perp = [-dir[1], dir[0]];
        let launch_height = uniform(rng, 1.0, 1.3);
        let aim_height = uniform(rng, 0.6, 0.95);
        let aim_lateral = uniform(rng, -0.25, 0.25);
        // A far-observer group is a throw that goes wide of the observer.
        let miss_side = if uniform(rng, 0.0, 1.0) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let miss_offset = uniform(rng, 1.8, 2.2) * miss_side;
        let spin = [
            uniform(rng, -6.0, 6.0),
            uniform(rng, -6.0, 6.0),
            uniform(rng, -6.0, 6.0),
        ];
        let yaw = uniform(rng, 0.0, std::f64::consts::TAU);
        // The fastest band reaches the aim point `FASTEST_FLIGHT_S` after release; the
        // room may cut that distance short.
        let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
        let wanted = throw_distance(fastest, FASTEST_FLIGHT_S, launch_height, aim_height);
        let distance = wanted.min(room_span(room, dir, WALL_MARGIN));
        let origin = span_start(rng, room, dir, distance, WALL_MARGIN);
        let radius = input.object.half_extents().into_iter().fold(0.0, f64::max);
        let rise = room.ceiling_height - CEILING_CLEARANCE - radius - launch_height;

        let start = [origin[0], origin[1], launch_height];
        let observer_xy = [origin[0] + dir[0] * distance, origin[1] + dir[1] * distance];
        let lateral = if input.far_observer {
            miss_offset
        } else {
            aim_lateral
        };
        let target = [
            observer_xy[0] + perp[0] * lateral,
            observer_xy[1] + perp[1] * lateral,
            aim_height,
        ];
        let dx = ((target[0] - start[0]).powi(2) + (target[1] - start[1]).powi(2)).sqrt();
        let elevation = indoor_elevation(input.speed, dx, target[2] - start[2], rise);
        let aim = [(target[0] - start[0]) / dx, (target[1] - start[1]) / dx];
        let linvel = [
            aim[0] * input.speed * elevation.cos(),
            aim[1] * input.speed * elevation.cos(),
            input.speed * elevation.sin(),
        ];
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
                ("throw_distance_m".into(), dx),
                ("aim_height_m".into(), aim_height),
                ("elevation_rad".into(), elevation),
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
