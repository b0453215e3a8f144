//! door_swing: a door swings violently on its hinge (SPEC §4).
//!
//! The door (a box: width along local x, thickness y, height z) hangs on a real revolute
//! joint anchored to the world along its hinge edge (vertical axis), 1 cm above the floor,
//! next to a fixed jamb post. It starts a little open and is flung further open: the band's
//! value is the speed of its free edge at t0. That is what a push impulse `J` at the free
//! edge does: `J·w = I_hinge·ω`, `ω = v/w`, with `I_hinge = m(w² + t²)/12 + m(w/2)²`; the
//! spec records `I_hinge` and the impulse. The observer stands inside the swing.
//!
//! Timing (label rule v2): the observer stands near the end of a long sweep (up to
//! ~155° from the closed position), at the bearing the fastest band's door reaches
//! 0.95–1.25 s after t0, so every band's door reaches them after Δ + 0.2 s; they stand
//! within the door's width, so its face strikes them at `v·r/w` ≥ 0.7 v. A door too narrow
//! to sweep that long at the fastest band (a cabinet door) has its observer out of its
//! reach instead.
//!
//! Labels: nearly always DODGE. Every catalog door but the hollow prop door weighs over
//! 2 kg (`heavy`), so a door that reaches the observer must be dodged; the prop door is
//! CATCH at the slower bands and DODGE once its momentum passes the threshold.

use super::*;

pub struct DoorSwing;

/// Moment of inertia of a uniform door about its hinge edge (kg·m²).
pub fn hinge_inertia(mass: f64, width: f64, thickness: f64) -> f64 {
    mass * (width * width + thickness * thickness) / 12.0 + mass * (width / 2.0).powi(2)
}

const CLEARANCE: f64 = 0.01;
/// Largest bearing of the observer from the closed position (rad): short of the wall line.
const MAX_BEARING: f64 = 2.75;
/// The fastest band's door reaches the observer no earlier than this (s).
const EARLIEST_REACH_S: f64 = 0.95;
/// The observer's torso radius (m).
const TORSO_RADIUS: f64 = 0.18;

impl Family for DoorSwing {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "door_swing",
            speed_parameter: "edge_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let closed_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let opens_left = uniform(rng, 0.0, 1.0) < 0.5;
        let open0 = uniform(rng, 0.1, 0.3);
        let reach_time = uniform(rng, EARLIEST_REACH_S, 1.25);
        let he = object.half_extents();
        let (width, thickness, height) = (2.0 * he[0], 2.0 * he[1], 2.0 * he[2]);
        let obs_near = uniform(rng, 0.7, 0.95) * width + 0.1;
        let obs_far = width + uniform(rng, 1.6, 2.0);
        let sign = if opens_left { 1.0 } else { -1.0 };
        // Observer bearing from the door at t0: the door's face meets the torso once it has
        // turned to within the torso's angular half-width of the observer's bearing.
        let half_width = ((TORSO_RADIUS + thickness / 2.0 + 0.01) / obs_near)
            .min(1.0)
            .asin();
        let fastest = input.band_speeds.iter().fold(0.0, |a: f64, &b| a.max(b)) / width;
        let obs_angle = (half_width + reach_time * fastest).min(MAX_BEARING - open0);
        let in_reach = (obs_angle - half_width) / fastest >= EARLIEST_REACH_S;
        // Too narrow to reach the observer late enough: they stand beyond its reach
        // (its centre of mass passes more than the reach radius away).
        let obs_near = if in_reach {
            obs_near
        } else {
            width / 2.0 + 1.35
        };
        let obs_dir = heading(closed_angle + sign * (open0 + obs_angle));
        let hinge = event_origin(rng, input.room, obs_dir, 0.6 + far_shift(input));

        let door_angle = closed_angle + sign * open0;
        let d0 = heading(door_angle);
        let z = CLEARANCE + bottom_offset(object);
        let centre = ahead(hinge, d0, he[0]);
        let position = [centre[0], centre[1], z];
        let omega = [0.0, 0.0, sign * input.speed / width];
        let hinge3 = [hinge[0], hinge[1], z];
        let linvel = velocity_about(omega, hinge3, position);
        let door = hazard_body(object, position, yaw_quat(door_angle), linvel, omega);

        // Jamb post behind the hinge and behind the door's plane (the wall's face, on the
        // side the door does not open to), clear of the door's hinge-side corners: the
        // door opens up to 180°, flat against the wall, as a door hinged on a wall's face.
        let closed = heading(closed_angle);
        let post_half = 0.05;
        let back = [-sign * left_of(closed)[0], -sign * left_of(closed)[1]];
        let post_xy = ahead(
            ahead(hinge, closed, -(post_half + 0.015)),
            back,
            post_half + thickness / 2.0 + 0.015,
        );
        let post = fixed_box(
            "jamb",
            [post_half, post_half, (height + CLEARANCE) / 2.0 + 0.05],
            [post_xy[0], post_xy[1], (height + CLEARANCE) / 2.0 + 0.05],
            yaw_quat(closed_angle),
            0.5,
            0.1,
        );
        let distance = if input.far_observer {
            obs_far
        } else {
            obs_near
        };
        let obs_xy = ahead(hinge, obs_dir, distance);
        let yaw = (centre[1] - obs_xy[1]).atan2(centre[0] - obs_xy[0]);
        let inertia = hinge_inertia(object.mass, width, thickness);
        Layout {
            bodies: vec![post, door],
            joints: vec![JointSpec {
                kind: JointKind::Revolute {
                    axis: [0.0, 0.0, 1.0],
                },
                body_a: None,
                body_b: 1,
                anchor_a: hinge3,
                anchor_b: [-he[0], 0.0, 0.0],
            }],
            hazard: 1,
            source_support: None,
            observer: ObserverPose {
                x: obs_xy[0],
                y: obs_xy[1],
                yaw,
            },
            params: BTreeMap::from([
                ("initial_open_rad".into(), open0),
                ("observer_bearing_rad".into(), obs_angle),
                ("door_width_m".into(), width),
                ("hinge_inertia_kgm2".into(), inertia),
                (
                    "push_impulse_ns".into(),
                    inertia * input.speed / width / width,
                ),
            ]),
        }
    }

    fn event_happened(&self, _spec: &SceneSpec, sim: &Simulation) -> bool {
        // The door swung at least 45° from where it started.
        let x0 = quat::rotate(sim.hazard_state(0).rotation.map(f64::from), [1.0, 0.0, 0.0]);
        (0..=sim.steps()).any(|k| {
            let x = quat::rotate(sim.hazard_state(k).rotation.map(f64::from), [1.0, 0.0, 0.0]);
            x[0] * x0[0] + x[1] * x0[1] + x[2] * x0[2] < std::f64::consts::FRAC_1_SQRT_2
        })
    }
}
