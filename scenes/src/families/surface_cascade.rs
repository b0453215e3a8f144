//! surface_cascade: an object hops from a table onto a stool and on to the floor (specification §4).
//!
//! A stool stands flush against the table's front, its seat a drawn step lower. The
//! object is shoved toward the table edge at the band's speed (a ball rolls): it leaves
//! the edge, hops down onto the seat, and crosses it to drop to the floor. The seat is
//! sized from the bands' speeds (not the current one): deep enough that even the fastest
//! band's object lands with its rear part on it, and no deeper, so that the slowest band,
//! after the landing's friction impulse, still slides across it. The object starts with
//! its centre of mass 30–60% of its half-length behind the table edge (resting there,
//! were it not moving), so it leaves the table at nearly the band's speed.
//!
//! Timing (label rule v2): the observer stands along the room's diagonal, at least
//! `OBSERVER_GAP_M` beyond where the fastest band's object would land off the stool, so
//! no band's drop passes through their reach envelope; what reaches them slides or rolls
//! that gap across the floor after Δ + 0.2 s, and what the floor's friction stops first
//! never reaches them at all.
//!
//! Timed (label rule v5): a group aimed at the hands or the body whose object keeps most
//! of its shove over a long run (a ball rolls, a slippery object slides) starts
//! `v·t − ½·a·t²` behind a counter-height table's edge, so every band leaves the edge after
//! the same drawn time `t` (`EDGE_S`), hops onto the seat a step lower (hip height) and
//! drops off it after Δ plus the reaction time, through the hands' heights. `aim` then
//! stands the observer where it falls.

use super::launch::*;
use super::*;

pub struct SurfaceCascade;

/// Least floor distance between the fastest band's landing off the stool and the
/// observer (m).
pub const OBSERVER_GAP_M: f64 = 1.3;

/// Timed groups: when every band's object leaves the table edge (s after t0); it leaves
/// the seat about 0.2–0.3 s later.
pub const EDGE_S: [f64; 2] = [0.55, 0.7];

/// Timed groups: the least share of its shove the object keeps over the run-up (a slider
/// that loses more would stop on the seat).
pub const KEPT_SPEED: f64 = 0.6;

/// Timed groups: the least table height (m); the seat, a step lower, is at hip height.
pub const TABLE_MIN_M: f64 = 1.0;

impl Family for SurfaceCascade {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "surface_cascade",
            speed_parameter: "push_speed_mps",
            speed_sweep: true,
        }
    }

    fn timed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let room = input.room;
        let heading_angle = diagonal_heading(rng, room, 0.2);
        let dir = heading(heading_angle);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let step = uniform(rng, 0.08, 0.14);
        let surface_friction = uniform(rng, 0.05, 0.2);
        let com_back = uniform(rng, 0.3, 0.6);
        let lateral = uniform(rng, -0.1, 0.1);
        let stool_half_width = uniform(rng, 0.17, 0.22);
        let gap_near = uniform(rng, OBSERVER_GAP_M, OBSERVER_GAP_M + 0.5);
        let gap_far = uniform(rng, OBSERVER_GAP_M + 1.5, OBSERVER_GAP_M + 2.0);
        let side = uniform(rng, -0.35, 0.35);
        let rolling = is_single_sphere(object);
        let t_edge = uniform(rng, EDGE_S[0], EDGE_S[1]);

        // Timed (see the module doc) when aimed and the run-up keeps most of the shove.
        let decel = if rolling {
            0.0
        } else {
            0.5 * (object.friction + surface_friction) * GRAVITY
        };
        let slowest = input
            .band_speeds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let timed = input.intent != crate::intent::Intent::Miss
            && !input.far_observer
            && decel * t_edge <= (1.0 - KEPT_SPEED) * slowest;
        let height = if timed {
            height.max(TABLE_MIN_M)
        } else {
            height
        };
        // What a band's object has left at the edge, and how far back it starts.
        let edge_speed = |v: f64| if timed { v - decel * t_edge } else { v };
        let half_len = footprint_half_length(object, 0.0);
        let run_up = |v: f64| {
            if timed {
                v * t_edge - 0.5 * decel * t_edge * t_edge
            } else {
                half_len * com_back
            }
        };
        let fastest = input
            .band_speeds
            .iter()
            .map(|&v| edge_speed(v))
            .fold(0.0, f64::max);
        let longest_run_up = input
            .band_speeds
            .iter()
            .map(|&v| run_up(v))
            .fold(0.0, f64::max);
        let flight = fastest * (2.0 * step / GRAVITY).sqrt();
        // The fastest band's object still lands with its rear part on the seat.
        let seat_depth = (flight - 0.6 * half_len + 0.06).max(0.25);
        let seat_height = height - step;
        // The fastest band's object, leaving the seat's far edge at the band's speed,
        // lands this far beyond it.
        let landing = fastest * (2.0 * seat_height / GRAVITY).sqrt() + half_len;
        let table_half = [(0.5 * (longest_run_up + half_len + 0.05)).max(0.35), 0.45];
        let beyond = landing
            + if input.far_observer {
                gap_far
            } else {
                gap_near
            };
        let length = (2.0 * table_half[0] + seat_depth + beyond).min(room_span(room, dir, 0.6));
        let origin = ahead(span_start(rng, room, dir, length, 0.6), dir, table_half[0]);
        let launch = EdgeLaunch {
            surface_name: "table",
            surface_height: height,
            surface_half: table_half,
            surface_friction,
            heading_angle,
            com_to_edge: run_up(input.speed),
            lateral,
            relative_yaw: 0.0,
            origin,
            board_thickness: None,
            rolling,
        };
        let (mut bodies, edge, _start) = launch.build(object, input.speed);
        let seat_centre = ahead(edge, dir, seat_depth / 2.0);
        bodies.insert(
            1,
            fixed_box(
                "stool",
                [
                    seat_depth / 2.0,
                    stool_half_width.max(half_len),
                    seat_height / 2.0,
                ],
                [seat_centre[0], seat_centre[1], seat_height / 2.0],
                yaw_quat(heading_angle),
                surface_friction,
                0.2,
            ),
        );
        let far_edge = ahead(edge, dir, seat_depth);
        let d = (length - 2.0 * table_half[0] - seat_depth).max(landing + 0.3);
        let obs = ahead(ahead(far_edge, dir, d), left_of(dir), side);
        let observer = ObserverPose {
            x: obs[0],
            y: obs[1],
            // Facing the table's centre (a timed object's start follows from the speed).
            yaw: (origin[1] - obs[1]).atan2(origin[0] - obs[0]),
        };
        Layout {
            bodies,
            joints: vec![],
            hazard: 2,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("stool_height_m".into(), seat_height),
                ("stool_depth_m".into(), seat_depth),
                ("drop_height_m".into(), height),
                ("com_behind_edge_m".into(), run_up(input.speed)),
                ("edge_time_s".into(), if timed { t_edge } else { 0.0 }),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        touched_stool_before_floor(spec, sim)
    }
}

/// The hazard touched the stool (not its table, not the floor) before it first reached
/// the floor, and it did reach the floor.
pub fn touched_stool_before_floor(spec: &SceneSpec, sim: &Simulation) -> bool {
    let Some(floor) = sim.time_to_floor_step(spec.labels.floor_contact_eps) else {
        return false;
    };
    (0..floor).any(|k| sim.hazard_contacts[k as usize] & rh_physics::simulate::TOUCH_OTHER != 0)
}
