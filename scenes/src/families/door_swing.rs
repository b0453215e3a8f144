//! door_swing: a door swings violently on its hinge (specification §4).
//!
//! The door (a box: width along local x, thickness y, height z) hangs on a real revolute
//! joint anchored to the world along its hinge edge (vertical axis), 1 cm above the floor,
//! next to a fixed jamb post. It is flung open from the angle its timing sets: the band's
//! value is the speed of its free edge at t0. That is what a push impulse `J` at the free
//! edge does: `J·w = I_hinge·ω`, `ω = v/w`, with `I_hinge = m(w² + t²)/12 + m(w/2)²`; the
//! spec records `I_hinge` and the impulse. The observer stands inside the swing.
//!
//! Timing (label rule v5, self-aimed): the observer stands within the door's width (its
//! torso axis 0.75–0.92 w + 0.1 m from the hinge, so the fast outer part of the face
//! strikes), at a bearing the fastest band's door face reaches at a drawn time after
//! Δ + the reaction minimum (`MEET_S`), slower bands later: the door starts `ω·t` before
//! that bearing — through the doorway on the jamb's side when it must (a swing door, up
//! to `MAX_BACK_SWING`). The aim's meeting point of
//! the door's centre would stand the observer at half the width, where the face moves at
//! half the edge speed and touches the hand below the harm limits. A door too narrow to
//! reach the torso (a cabinet door) or too fast to time has its observer out of reach.
//!
//! Labels (rule v5): DODGE when the face's strike harms the standing body (the hand it
//! meets first, mostly: ≥ ~1.8 m/s at the edge for a 4 kg screen door, less for heavy
//! doors), else NO_ACTION; never CATCH (no door fits in the arms).

use super::*;

pub struct DoorSwing;

/// Moment of inertia of a uniform door about its hinge edge (kg·m²).
pub fn hinge_inertia(mass: f64, width: f64, thickness: f64) -> f64 {
    mass * (width * width + thickness * thickness) / 12.0 + mass * (width / 2.0).powi(2)
}

const CLEARANCE: f64 = 0.01;
/// Largest bearing of the observer from the closed position (rad): short of the wall line.
pub const MAX_BEARING: f64 = 2.75;
/// The door may start at most this far (rad) through the doorway on the other side of
/// its closed position (a double-acting door), clear of the jamb post.
pub const MAX_BACK_SWING: f64 = 1.5;
/// When the fastest band's door face meets the torso (s after t0): after Δ + the
/// reaction minimum (0.8 s) with a margin; slower bands meet later.
pub const MEET_S: [f64; 2] = [1.0, 1.15];
/// A door too fast to meet the observer this late (s) is not timed.
pub const EARLIEST_MEET_S: f64 = 0.95;
/// The observer's torso radius (m).
const TORSO_RADIUS: f64 = 0.18;

/// Where a group's door meets its observer (label rule v5): the observer's bearing from
/// the closed position and the time the fastest band's door face reaches the torso; the
/// door starts `ω·t` before that bearing (`ω = v/w` of the fastest band, the same start in
/// every band, so slower bands meet later) — on the far side of the doorway when it has
/// to (a swing door).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoorTiming {
    /// The torso's angular half-width seen from the hinge (rad).
    pub half_width: f64,
    pub bearing: f64,
    pub meet_time: f64,
    /// The fastest band's angular speed (rad/s).
    pub fastest: f64,
    /// Whether the fastest band can be timed (else the observer stands out of reach).
    pub in_reach: bool,
}

impl DoorTiming {
    /// From the door's width and thickness, the observer's distance from the hinge, the
    /// bands' edge speeds and two draws in [0, 1) and `MEET_S`. Speed-independent.
    pub fn new(
        width: f64,
        thickness: f64,
        radius: f64,
        band_speeds: &[f64; 4],
        bearing_share: f64,
        meet_time: f64,
    ) -> DoorTiming {
        let half_width = ((TORSO_RADIUS + thickness / 2.0 + 0.01) / radius)
            .min(1.0)
            .asin();
        let fastest = band_speeds.iter().fold(0.0, |a: f64, &b| a.max(b)) / width;
        let slowest = band_speeds
            .iter()
            .fold(f64::INFINITY, |a: f64, &b| a.min(b))
            / width;
        // The door must start no farther back than MAX_BACK_SWING (the fastest band
        // meeting sooner, when the drawn time is too long for that); the bearing is at
        // least what keeps the start on the opening side when the slowest band's sweep
        // allows (fewer starts through the doorway).
        let meet_time = meet_time
            .min((MAX_BEARING + MAX_BACK_SWING - half_width) / fastest)
            .max(EARLIEST_MEET_S);
        let least = (half_width + fastest * meet_time - MAX_BACK_SWING).max(0.0);
        let most = MAX_BEARING;
        let lowest = half_width + slowest * meet_time + 0.1;
        let lo = least.max(lowest.min(most));
        let bearing = lo + bearing_share * (most - lo).max(0.0) * 0.5;
        DoorTiming {
            half_width,
            bearing,
            meet_time,
            fastest,
            in_reach: radius < width + TORSO_RADIUS && least <= most && half_width < 1.2,
        }
    }

    /// The door's starting angle from the closed position, the same in every band (rad;
    /// negative: through the doorway on the other side): the fastest band's face reaches
    /// the torso at `meet_time`, slower ones later.
    pub fn start_angle(&self) -> f64 {
        if self.in_reach {
            self.bearing - self.half_width - self.fastest * self.meet_time
        } else {
            0.2
        }
    }
}

impl Family for DoorSwing {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "door_swing",
            speed_parameter: "edge_speed_mps",
            speed_sweep: true,
        }
    }

    fn self_aimed(&self) -> bool {
        true
    }

    /// The door starts at the same angle in every band (only its speed differs).
    fn timed(&self) -> bool {
        false
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let closed_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let opens_left = uniform(rng, 0.0, 1.0) < 0.5;
        let bearing_share = uniform(rng, 0.0, 1.0);
        let meet_time = uniform(rng, MEET_S[0], MEET_S[1]);
        let he = object.half_extents();
        let (width, thickness, height) = (2.0 * he[0], 2.0 * he[1], 2.0 * he[2]);
        let obs_near = uniform(rng, 0.75, 0.92) * width + 0.1;
        let obs_far = width + uniform(rng, 1.6, 2.0);
        let sign = if opens_left { 1.0 } else { -1.0 };
        let timing = DoorTiming::new(
            width,
            thickness,
            obs_near,
            &input.band_speeds,
            bearing_share,
            meet_time,
        );
        // Too narrow to meet the torso (a cabinet door), or too fast to be timed: the
        // observer stands beyond its reach (its centre of mass passes more than the
        // reach radius away).
        let obs_near = if timing.in_reach {
            obs_near
        } else {
            width / 2.0 + 1.35
        };
        let obs_angle = timing.bearing;
        let open0 = timing.start_angle();
        let obs_dir = heading(closed_angle + sign * obs_angle);
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
        // side the door mostly opens away from), clear of the door's hinge-side corners:
        // the door opens up to 180°, flat against the wall, as a door hinged on a wall's
        // face, and swings up to MAX_BACK_SWING through the doorway to the post's side.
        let closed = heading(closed_angle);
        let post_half = 0.05;
        let back = [-sign * left_of(closed)[0], -sign * left_of(closed)[1]];
        let post_xy = ahead(
            ahead(hinge, closed, -(post_half + 0.135)),
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
        // Facing where the door comes from (the same pose in every band): its centre a
        // radian before the observer's bearing.
        let from = ahead(
            hinge,
            heading(closed_angle + sign * (obs_angle - 1.0)),
            he[0],
        );
        let yaw = (from[1] - obs_xy[1]).atan2(from[0] - obs_xy[0]);
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
                ("start_open_rad".into(), open0),
                ("meet_time_s".into(), timing.meet_time),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A 0.9 m door, observer 0.8 m from the hinge: every band's face reaches the torso
    /// after Δ (0.6 s) + the reaction minimum (0.2 s), the fastest at the drawn time,
    /// still swinging at its band's speed (no damping on the hinge) — at least 1 m/s where
    /// it meets the body's near side even in the slowest band; the door starts no farther
    /// back than the swing door allows.
    #[test]
    fn every_band_meets_the_observer_after_the_reaction_time() {
        let bands = [1.5, 1.7, 1.85, 2.0];
        let (w, radius) = (0.9, 0.8);
        for (share, meet) in [(0.0, 1.0), (0.5, 1.1), (0.99, 1.15)] {
            let t = DoorTiming::new(w, 0.05, radius, &bands, share, meet);
            assert!(t.in_reach, "{t:?}");
            assert!(t.meet_time >= 0.95 && t.meet_time > 0.6 + 0.2);
            assert!(t.bearing <= MAX_BEARING);
            let start = t.start_angle();
            assert!(start >= -MAX_BACK_SWING - 1e-9, "{start}");
            for v in bands {
                let omega = v / w;
                // When the face reaches the torso's angular edge.
                let meets = (t.bearing - t.half_width - start) / omega;
                assert!(
                    meets >= t.meet_time - 1e-9 && meets > 0.6 + 0.2,
                    "{v}: {meets}"
                );
                assert!(omega * (radius - TORSO_RADIUS) >= 1.0);
            }
            let fastest = (t.bearing - t.half_width - start) / (2.0 / w);
            assert!((fastest - t.meet_time).abs() < 1e-9);
        }
        // A cabinet door at these speeds would have to start beyond the doorway: its
        // observer stands out of reach.
        let t = DoorTiming::new(0.4, 0.018, 0.45, &bands, 0.5, 1.1);
        assert!(!t.in_reach);
    }
}
