//! bouncing_object: an object is thrown down at the floor and bounces toward the observer
//! (SPEC §4).
//!
//! Launched from hand height, pitched down by a drawn angle, at the band's speed, along the
//! line to the observer. Timing (label rule v2): the launch point and the observer lie
//! along the room's diagonal, as far apart as the fastest band needs to cover in
//! `FASTEST_ARRIVAL_S` at its launch's horizontal speed (bounces only slow it), so every
//! band reaches the observer bouncing (then rolling) after Δ + 0.2 s; slow bands arrive
//! seconds later or, if the run ends first, not at all. In far-observer groups the
//! observer stands well off to the side of that line instead.

use super::launch::*;
use super::*;

pub struct BouncingObject;

/// The fastest band's horizontal launch speed covers the distance to the observer in
/// this time (s).
pub const FASTEST_ARRIVAL_S: f64 = 0.95;

/// Horizontal distance to the first floor contact of a centre launched at height `h`
/// (above its resting height) with speed `v`, pitched `pitch` below horizontal.
pub fn first_bounce_distance(v: f64, pitch: f64, h: f64) -> f64 {
    let vz = v * pitch.sin();
    let t = (-vz + (vz * vz + 2.0 * GRAVITY * h).sqrt()) / GRAVITY;
    v * pitch.cos() * t
}

impl Family for BouncingObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "bouncing_object",
            speed_parameter: "launch_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = diagonal_heading(rng, input.room, 0.15);
        let dir = heading(heading_angle);
        let side = left_of(dir);
        let launch_height = uniform(rng, 0.9, 1.4);
        let pitch = uniform(rng, 0.3, 0.6);
        let beyond = uniform(rng, 0.4, 0.9);
        let near_lateral = uniform(rng, -0.25, 0.25);
        let far_lateral = uniform(rng, 2.0, 2.4)
            * if uniform(rng, 0.0, 1.0) < 0.5 {
                -1.0
            } else {
                1.0
            };
        let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
        let r = bottom_offset(object);
        let distance = (first_bounce_distance(fastest, pitch, launch_height - r) + beyond)
            .max(fastest * pitch.cos() * FASTEST_ARRIVAL_S)
            .min(room_span(input.room, dir, 0.35));
        let origin = span_start(rng, input.room, dir, distance, 0.35);

        let start = [origin[0], origin[1], launch_height];
        let v = input.speed;
        let linvel = [
            dir[0] * v * pitch.cos(),
            dir[1] * v * pitch.cos(),
            -v * pitch.sin(),
        ];
        let hazard = hazard_body(object, start, yaw_quat(heading_angle), linvel, [0.0; 3]);
        // A far observer steps off the line toward the room's centre (the line ends near a
        // corner), so they stay inside the room.
        let end = ahead(origin, dir, distance);
        let inward = if side[0] * end[0] + side[1] * end[1] <= 0.0 {
            1.0
        } else {
            -1.0
        };
        let lateral = if input.far_observer {
            far_lateral.abs() * inward
        } else {
            near_lateral
        };
        let obs = ahead(ahead(origin, dir, distance), side, lateral);
        // (Kept inside the room, clear of the walls.)
        let limit = [0, 1].map(|k| (input.room.size[k] / 2.0 - 0.4).max(0.0));
        let obs = [0, 1].map(|k| obs[k].clamp(-limit[k], limit[k]));
        Layout {
            bodies: vec![hazard],
            joints: vec![],
            hazard: 0,
            source_support: None,
            observer: ObserverPose {
                x: obs[0],
                y: obs[1],
                yaw: (origin[1] - obs[1]).atan2(origin[0] - obs[0]),
            },
            params: BTreeMap::from([
                ("launch_height_m".into(), launch_height),
                ("pitch_down_rad".into(), pitch),
                ("observer_distance_m".into(), distance),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // It bounced: after its first floor contact it moved up again.
        let Some(k) = sim.time_to_floor_step(spec.labels.floor_contact_eps) else {
            return false;
        };
        (k..=sim.steps()).any(|j| sim.hazard_velocity(j)[2] > 0.1)
    }
}
