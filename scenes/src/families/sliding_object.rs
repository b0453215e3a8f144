//! sliding_object: an object slides down a ramp steeper than its friction cone (specification §4).
//!
//! Timing (label rule v2): the observer stands 0.9–1.6 m beyond the ramp's lower end, so
//! the lower ramp lies outside their reach envelope and the object, accelerating from the
//! band's initial speed down a 1.2–2 m slope, meets them after Δ + 0.2 s.

use super::*;

pub struct SlidingObject;

/// Margin above the friction cone, so sliding is guaranteed rather than marginal.
const CONE_MARGIN_RAD: f64 = 0.07;
const MAX_ANGLE_RAD: f64 = 0.80;

/// Aimed at the hands: when every band leaves the ramp (s after t0), the height of its
/// lower end (m), and the longest ramp (m).
pub const HANDS_OFF_S: [f64; 2] = [0.8, 0.95];
pub const HANDS_END_M: [f64; 2] = [0.75, 0.9];
pub const HANDS_MAX_LENGTH_M: f64 = 2.6;

fn lerp(range: [f64; 2], u: f64) -> f64 {
    range[0] + (range[1] - range[0]) * u
}

impl Family for SlidingObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "sliding_object",
            speed_parameter: "initial_speed_mps",
            speed_sweep: true,
        }
    }

    fn timed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let ramp_friction = uniform(rng, 0.15, 0.35);
        let mu = combined_friction(object.friction, ramp_friction);
        // Floor the angle above the friction cone (tan θ > μ): sliding is guaranteed.
        let cone = mu.atan();
        let angle = (cone + CONE_MARGIN_RAD + uniform(rng, 0.0, 0.15))
            .min(MAX_ANGLE_RAD.max(cone + CONE_MARGIN_RAD));
        let u_length = uniform(rng, 0.0, 1.0);
        let half_width = uniform(rng, 0.25, 0.35);
        let start_gap = uniform(rng, 0.05, 0.2);
        // The lower end stands on a low support, so the object slides off the end and
        // drops rather than jamming its front edge into the floor at the kink.
        let u_end = uniform(rng, 0.0, 1.0);
        // Aimed at the hands (label rule v5), a chute whose lower end is at hip height and
        // every band slides off it after the same drawn time: a faster band starts lower
        // on the ramp, which is as long as the fastest band needs (at most
        // `HANDS_MAX_LENGTH_M`). Else label rule v4's drawn ramp, ending near the floor.
        let hands = input.intent == crate::intent::Intent::Hands;
        let accel = GRAVITY * (angle.sin() - mu * angle.cos());
        let t_off = lerp(HANDS_OFF_S, u_length);
        let slide = |v: f64| v * t_off + 0.5 * accel * t_off * t_off;
        let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
        let (length, end_height) = if hands {
            (
                (slide(fastest) + 0.2 + 2.0 * footprint_half_length(object, 0.0))
                    .min(HANDS_MAX_LENGTH_M)
                    .min((input.room.ceiling_height - 0.3 - HANDS_END_M[1]) / angle.sin()),
                lerp(HANDS_END_M, u_end),
            )
        } else {
            (lerp([1.2, 2.0], u_length), lerp([0.15, 0.35], u_end))
        };
        let origin = event_origin(rng, input.room, dir, 0.8);
        let thickness = 0.04;

        // Ramp frame: yaw to the heading, then pitch so local +x points downhill.
        let rotation = quat::mul(
            yaw_quat(heading_angle),
            quat::from_axis_angle([0.0, 1.0, 0.0], angle),
        );
        let downhill = quat::rotate(rotation, [1.0, 0.0, 0.0]);
        let normal = quat::rotate(rotation, [0.0, 0.0, 1.0]);
        let bottom = [origin[0], origin[1], end_height];
        let along = |s: f64, n: f64| -> Vec3 {
            [0, 1, 2].map(|k| bottom[k] - downhill[k] * s + normal[k] * n)
        };
        let ramp = fixed_box(
            "ramp",
            [length / 2.0, half_width, thickness / 2.0],
            along(length / 2.0, -thickness / 2.0),
            rotation,
            ramp_friction,
            0.1,
        );
        let half_len = footprint_half_length(object, 0.0);
        // Distance (along the slope) from the object's centre to the ramp's lower end.
        let slide_distance = if hands {
            slide(input.speed).min(length - start_gap - half_len)
        } else {
            length - start_gap - half_len
        };
        let position = along(slide_distance, bottom_offset(object));
        let linvel = downhill.map(|c| c * input.speed);
        let hazard = hazard_body(object, position, rotation, linvel, [0.0; 3]);
        let observer = observer_beyond(
            rng,
            [bottom[0], bottom[1]],
            dir,
            (0.9, 1.6),
            (2.4, 3.0),
            0.3,
            input.far_observer,
            // Facing the ramp's top start (where every band would start untimed).
            {
                let top = along(length - start_gap - half_len, 0.0);
                [top[0], top[1]]
            },
        );
        Layout {
            bodies: vec![ramp, hazard],
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("ramp_angle_rad".into(), angle),
                ("friction_cone_rad".into(), cone),
                ("mu_effective".into(), mu),
                ("ramp_length_m".into(), length),
                ("ramp_height_m".into(), end_height + length * angle.sin()),
                ("ramp_end_height_m".into(), end_height),
                ("slide_distance_m".into(), slide_distance),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The object slid all the way down and off the ramp's lower end.
        let ramp = &spec.bodies[spec.source_support.unwrap_or(0)];
        let downhill = quat::rotate(ramp.rotation, [1.0, 0.0, 0.0]);
        let floor_dir = {
            let n = (downhill[0].powi(2) + downhill[1].powi(2)).sqrt();
            [downhill[0] / n, downhill[1] / n]
        };
        let half_len = spec
            .family_params
            .get("ramp_length_m")
            .copied()
            .unwrap_or(0.0)
            / 2.0;
        let angle = spec
            .family_params
            .get("ramp_angle_rad")
            .copied()
            .unwrap_or(0.0);
        // The lower end lies half a ramp length (projected) beyond the ramp's centre.
        let end = [
            ramp.position[0] + floor_dir[0] * half_len * angle.cos(),
            ramp.position[1] + floor_dir[1] * half_len * angle.cos(),
        ];
        (0..=sim.steps()).any(|k| {
            let p = sim.hazard_position(k);
            (p[0] - end[0]) * floor_dir[0] + (p[1] - end[1]) * floor_dir[1] > 0.0
        })
    }
}
