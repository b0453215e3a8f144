//! rolling_ball: a ball rolls off a table and on across the floor (specification §4).
//!
//! Timing (label rule v2): the observer stands along the room's diagonal, beyond where
//! the fastest band's ball lands by `OBSERVER_GAP_M` or more, so no band's fall passes
//! through their reach envelope and every ball meets them only after rolling that gap on
//! the floor, after Δ + 0.2 s.

use super::launch::*;
use super::*;

pub struct RollingBall;

/// Least floor distance between the fastest band's landing point and the observer (m).
pub const OBSERVER_GAP_M: f64 = 1.3;

/// When every band's ball leaves the table edge (s after t0): after Δ (0.6 s) plus the
/// reaction time (0.2 s), a little before the label's earliest meeting.
pub const EDGE_S: [f64; 2] = [0.8, 0.95];

/// The least counter height (m): from there the ball falls through the hands' heights.
pub const COUNTER_MIN_M: f64 = 0.8;

impl Family for RollingBall {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "rolling_ball",
            speed_parameter: "roll_speed_mps",
            speed_sweep: true,
        }
    }

    fn timed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let room = input.room;
        let heading_angle = diagonal_heading(rng, room, 0.2);
        let dir = heading(heading_angle);
        // A counter at least at hip height: the ball leaves it where the hands can hold it.
        let height = uniform(rng, room.table_height[0], room.table_height[1]).max(COUNTER_MIN_M);
        let surface_half = [uniform(rng, 0.35, 0.5), uniform(rng, 0.35, 0.7)];
        let surface_friction = uniform(rng, 0.4, 0.7);
        let lateral = uniform(rng, -0.2, 0.2);
        // A rolling ball keeps its speed: it starts `speed · t_edge` behind the edge, so
        // every band leaves the edge after the same drawn time (label rule v5: after Δ
        // plus the reaction time, then it falls through the hands' heights).
        let t_edge = uniform(rng, EDGE_S[0], EDGE_S[1]);
        let com_to_edge = input.speed * t_edge;
        let gap_near = uniform(rng, OBSERVER_GAP_M, OBSERVER_GAP_M + 0.6);
        let gap_far = uniform(rng, OBSERVER_GAP_M + 1.5, OBSERVER_GAP_M + 2.0);
        let side = uniform(rng, -0.3, 0.3);
        // Where the fastest band's ball lands, beyond the table edge.
        let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
        let r = bottom_offset(input.object);
        let landing = fastest * (2.0 * height / GRAVITY).sqrt() + r;
        let beyond = landing
            + if input.far_observer {
                gap_far
            } else {
                gap_near
            };
        let longest_run = fastest * t_edge + 0.1;
        let surface_half = [surface_half[0].max(longest_run / 2.0), surface_half[1]];
        let length = (surface_half[0] * 2.0 + beyond).min(room_span(room, dir, 0.55));
        let back = span_start(rng, room, dir, length, 0.55);
        let origin = ahead(back, dir, surface_half[0]);
        let launch = EdgeLaunch {
            surface_name: "table",
            surface_height: height,
            surface_half,
            surface_friction,
            heading_angle,
            com_to_edge,
            lateral,
            relative_yaw: 0.0,
            origin,
            board_thickness: None,
            rolling: true,
        };
        let (bodies, edge, _start) = launch.build(input.object, input.speed);
        let d = length - surface_half[0] * 2.0;
        let obs = ahead(ahead(edge, dir, d), left_of(dir), side);
        let observer = ObserverPose {
            x: obs[0],
            y: obs[1],
            // Facing the table's centre (the ball's start follows from the band's speed).
            yaw: (origin[1] - obs[1]).atan2(origin[0] - obs[0]),
        };
        Layout {
            bodies,
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("edge_time_s".into(), t_edge),
                ("drop_height_m".into(), height),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // It left the table, reached the floor, and rolled on for at least 0.3 m.
        let Some(k) = sim.time_to_floor_step(spec.labels.floor_contact_eps) else {
            return false;
        };
        let at_floor = sim.hazard_position(k);
        let last = sim.hazard_position(sim.steps());
        let _ = spec;
        let travelled = ((last[0] - at_floor[0]).powi(2) + (last[1] - at_floor[1]).powi(2)).sqrt();
        travelled >= 0.3
    }
}
