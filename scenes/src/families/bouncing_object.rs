//! bouncing_object: an object is thrown down at the floor and bounces toward the observer
//! (specification §4).
//!
//! The band's value is the launch's speed along the floor (`forward_speed_mps`); the
//! throw's downward part is drawn (pitched down by a drawn angle) or, for a slam, set by
//! its timing.
//!
//! Pitched throws: launched from hand height, pitched down, along the line to the
//! observer. Timing (label rule v2): the launch point and the observer lie along the
//! room's diagonal, as far apart as the fastest band needs to cover in
//! `FASTEST_ARRIVAL_S` (bounces only slow it), so every band reaches the observer bouncing
//! (then rolling) after Δ + 0.2 s; slow bands arrive seconds later or, if the run ends
//! first, not at all. In far-observer groups the observer stands well off to the side of
//! that line instead. Dangerous balls (aimed at the body) are always pitched throws.
//!
//! Slams (label rule v5, timed): a benign ball aimed at the hands whose bounce can carry
//! it (`slam`: the ball's and the floor's restitution, averaged as the simulator does) is
//! slammed at the floor so hard that its one bounce rises above the hands and comes back
//! down through the hands' heights after Δ + the reaction minimum: its centre passes
//! `SLAM_LOW_M` on the way down at a drawn time `SLAM_LOW_S`. The downward speed follows
//! from that time alone, so every band bounces alike; a band's ball starts as far back
//! as its forward speed carries it by then (a ball rolls off its bounce at 5/7 of its
//! forward speed), so every band comes down at the same point. `aim` stands the observer
//! where it comes down.

use super::launch::*;
use super::*;

pub struct BouncingObject;

/// The fastest band's horizontal launch speed covers the distance to the observer in
/// this time (s).
pub const FASTEST_ARRIVAL_S: f64 = 0.95;

/// Slams: when the ball's centre, coming down from its bounce, passes `SLAM_LOW_M` (s).
pub const SLAM_LOW_S: [f64; 2] = [1.1, 1.2];
/// Slams: the hands' lowest meeting height (`[aim] meet_height`'s lower end, m).
pub const SLAM_LOW_M: f64 = 0.6;
/// Slams: the hardest downward launch (m/s); a ball that needs more is thrown pitched.
pub const SLAM_MAX_MPS: f64 = 12.0;
/// Slams: the bounce's apex stays this far below the ceiling (m).
pub const CEILING_GAP_M: f64 = 0.15;
/// A solid ball leaves a bounce with enough friction rolling, at 5/7 of its forward speed.
pub const ROLLING_SHARE: f64 = 5.0 / 7.0;

/// Horizontal distance to the first floor contact of a centre launched at height `h`
/// (above its resting height) with speed `v`, pitched `pitch` below horizontal.
pub fn first_bounce_distance(v: f64, pitch: f64, h: f64) -> f64 {
    let vz = v * pitch.sin();
    let t = (-vz + (vz * vz + 2.0 * GRAVITY * h).sqrt()) / GRAVITY;
    v * pitch.cos() * t
}

/// A slam's vertical motion (speed-independent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slam {
    /// Downward launch speed (m/s).
    pub down: f64,
    /// When it first touches the floor (s).
    pub bounce_s: f64,
    /// Its centre's apex after the bounce (m).
    pub apex: f64,
    /// When its centre comes back down to `SLAM_LOW_M` (s).
    pub low_s: f64,
}

impl Slam {
    /// How far a band's ball travels along the floor by `low_s` (m).
    pub fn distance(&self, forward: f64) -> f64 {
        forward * self.bounce_s + ROLLING_SHARE * forward * (self.low_s - self.bounce_s)
    }
}

/// The gentlest slam (downward speed in 0.01 m/s steps) of a ball of radius `r` launched
/// with its centre at `launch_height`, bouncing with restitution `e`, whose centre comes
/// back down to `SLAM_LOW_M` no earlier than `low_s` — `None` when that needs more than
/// `SLAM_MAX_MPS` or an apex above `ceiling - CEILING_GAP_M`.
pub fn slam(e: f64, r: f64, launch_height: f64, low_s: f64, ceiling: f64) -> Option<Slam> {
    let h = (launch_height - r).max(0.0);
    (0..=(SLAM_MAX_MPS * 100.0) as u32).find_map(|i| {
        let down = i as f64 / 100.0;
        let u = (down * down + 2.0 * GRAVITY * h).sqrt();
        let bounce_s = (u - down) / GRAVITY;
        let w = e * u;
        let apex = r + w * w / (2.0 * GRAVITY);
        if apex + r > ceiling - CEILING_GAP_M || apex < SLAM_LOW_M {
            return None;
        }
        let low = bounce_s + w / GRAVITY + (2.0 * (apex - SLAM_LOW_M) / GRAVITY).sqrt();
        (low >= low_s).then_some(Slam {
            down,
            bounce_s,
            apex,
            low_s: low,
        })
    })
}

impl Family for BouncingObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "bouncing_object",
            speed_parameter: "forward_speed_mps",
            speed_sweep: true,
        }
    }

    fn timed(&self) -> bool {
        true
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
        let low_s = uniform(rng, SLAM_LOW_S[0], SLAM_LOW_S[1]);
        let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
        let r = bottom_offset(object);
        let restitution = 0.5 * (object.restitution + input.room.floor_restitution);
        let slammed = (input.intent == crate::intent::Intent::Hands && !input.far_observer)
            .then(|| {
                slam(
                    restitution,
                    r,
                    launch_height,
                    low_s,
                    input.room.ceiling_height,
                )
            })
            .flatten()
            .filter(|s| s.distance(fastest) + 0.6 <= room_span(input.room, dir, 0.35));
        let distance = match slammed {
            Some(s) => s.distance(fastest) + 0.3,
            None => (first_bounce_distance(fastest / pitch.cos(), pitch, launch_height - r)
                + beyond)
                .max(fastest * FASTEST_ARRIVAL_S)
                .min(room_span(input.room, dir, 0.35)),
        };
        let origin = span_start(rng, input.room, dir, distance, 0.35);

        let v = input.speed;
        let (start, down) = match slammed {
            // The fastest band starts at `origin`, slower ones as much nearer as they
            // travel less by `low_s`.
            Some(s) => (
                ahead(origin, dir, s.distance(fastest) - s.distance(v)),
                s.down,
            ),
            None => (origin, v * pitch.tan()),
        };
        let linvel = [dir[0] * v, dir[1] * v, -down];
        let hazard = hazard_body(
            object,
            [start[0], start[1], launch_height],
            yaw_quat(heading_angle),
            linvel,
            [0.0; 3],
        );
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
        let mut params = BTreeMap::from([
            ("launch_height_m".into(), launch_height),
            ("observer_distance_m".into(), distance),
        ]);
        match slammed {
            Some(s) => {
                params.insert("slam_down_mps".into(), s.down);
                params.insert("slam_apex_m".into(), s.apex);
                params.insert("slam_low_time_s".into(), s.low_s);
            }
            None => {
                params.insert("pitch_down_rad".into(), pitch);
            }
        }
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
            params,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A tennis ball (restitution 0.75) on a 0.25 floor, launched at 1.2 m: its slam's one
    /// bounce comes back down through the hands' heights after Δ (0.6 s) + the reaction
    /// minimum (0.2 s) + the aim's margin (0.1 s), at the drawn time, below the ceiling.
    #[test]
    fn a_slam_comes_down_through_the_hands_after_the_reaction_time() {
        let (e, r, h0, ceiling) = (0.5, 0.0335, 1.2, 2.6);
        let s = slam(e, r, h0, 1.15, ceiling).expect("a tennis ball can be slammed");
        assert!(s.down > 0.0 && s.down <= SLAM_MAX_MPS);
        assert!(s.low_s >= 1.15 && s.low_s < 1.16, "{s:?}");
        assert!(
            s.apex > 1.25 && s.apex + r <= ceiling - CEILING_GAP_M,
            "{s:?}"
        );
        // Closed form: the centre's height after the bounce, at the stated time.
        let u = (s.down * s.down + 2.0 * GRAVITY * (h0 - r)).sqrt();
        assert!(((u - s.down) / GRAVITY - s.bounce_s).abs() < 1e-9);
        let z = |t: f64| {
            let tb = t - s.bounce_s;
            r + e * u * tb - 0.5 * GRAVITY * tb * tb
        };
        assert!((z(s.low_s) - SLAM_LOW_M).abs() < 1e-6);
        // At hand height (0.6-1.25 m) and coming down at some time after 0.9 s.
        let in_band: Vec<f64> = (90..=120)
            .map(|k| k as f64 / 100.0)
            .filter(|&t| (0.6..=1.25).contains(&z(t)))
            .collect();
        assert!(in_band.len() >= 10, "{in_band:?}");
        // Every band comes down at the same point: a band's start is set back by its
        // own travel, so start + travel is the fastest band's travel.
        let fastest = s.distance(4.6);
        for v in [1.5, 2.4, 3.4, 4.6] {
            let start = fastest - s.distance(v);
            assert!((start + s.distance(v) - fastest).abs() < 1e-12);
            assert!(s.distance(v) < s.distance(4.6) + 1e-12);
        }
    }

    /// A ball that bounces too little (an apple, 0.3, on a 0.2 floor) cannot reach the
    /// hands from a slam under the ceiling: it is thrown pitched instead.
    #[test]
    fn a_dead_ball_is_not_slammed() {
        assert_eq!(slam(0.25, 0.04, 1.2, 1.1, 2.6), None);
    }
}
