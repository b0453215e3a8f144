//! multi_object: momentum runs down a row of objects (SPEC §4).
//!
//! Three or four copies of the object stand in a row on a table, a few millimetres apart,
//! the last one (the hazard) near the edge — all placed exactly on the table, at rest.
//! The first is shoved toward the others at the band's speed; each collision passes the
//! momentum on, and the last object is pushed toward (and usually off) the edge.
//!
//! Timing (label rule v2): the first object starts 0.3–0.5 m back from the rest of the
//! row on a long, polished table (a run-up), the last one rests with its centre of mass
//! just behind the edge, and the observer stands 1.5–1.9 m beyond the edge, clear of the
//! table and of the fall: the hazard reaches them only on the floor, after the run-up,
//! the collisions down the row and the fall.

use super::launch::rests_on_a_ball;
use super::*;

pub struct MultiObject;

/// When every band's shoved object reaches the row (s after t0).
pub const HIT_S: [f64; 2] = [0.7, 0.85];

/// The least share of its shove the first object keeps over a timed run-up.
pub const KEPT_SPEED: f64 = 0.3;

/// The run-up (m) when not aimed at the hands (label rule v4's range).
pub const FLOOR_RUN_UP_M: [f64; 2] = [0.3, 0.5];

/// Aimed at the hands, the least table height (m): from there the last object falls
/// through the hands' heights.
pub const TABLE_MIN_M: f64 = 0.8;

impl Family for MultiObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "multi_object",
            speed_parameter: "shove_speed_mps",
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
        let side = left_of(dir);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let half_width = uniform(rng, 0.35, 0.6);
        let friction = uniform(rng, 0.03, 0.1);
        let count = if uniform(rng, 0.0, 1.0) < 0.5 { 3 } else { 4 };
        let mut gaps = [0, 1, 2].map(|_| uniform(rng, 0.005, 0.03));
        // The run-up: the shoved object starts back from the rest of the row, by what it
        // slides in a drawn time (label rule v5: every band's row is struck then, so the
        // last object leaves the edge after Δ plus the reaction time; a faster shove starts
        // farther back). The table is as long as the fastest band needs.
        // Aimed at the hands only; else (at the body, a near miss) label rule v4's drawn
        // run-up: the hazard reaches the observer along the floor.
        let u = uniform(rng, 0.0, 1.0);
        let t_hit = HIT_S[0] + (HIT_S[1] - HIT_S[0]) * u;
        let decel = if rests_on_a_ball(object) {
            0.0
        } else {
            0.5 * (object.friction + friction) * GRAVITY
        };
        // Timed only while the long run-up keeps most of the shove (a rolling or slippery
        // object): a slider that loses more than `KEPT_SPEED` of the slowest shove no
        // longer pushes the row off the edge.
        let slowest = input
            .band_speeds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hands = input.intent == crate::intent::Intent::Hands
            && decel * t_hit <= (1.0 - KEPT_SPEED) * slowest;
        let run_up = |v: f64| {
            if !hands {
                return FLOOR_RUN_UP_M[0] + (FLOOR_RUN_UP_M[1] - FLOOR_RUN_UP_M[0]) * u;
            }
            let t = t_hit.min(if decel > 0.0 {
                v / decel
            } else {
                f64::INFINITY
            });
            v * t - 0.5 * decel * t * t
        };
        let longest_run_up = input
            .band_speeds
            .iter()
            .map(|&v| run_up(v))
            .fold(0.0, f64::max);
        gaps[0] += run_up(input.speed);
        let height = if hands {
            height.max(TABLE_MIN_M)
        } else {
            height
        };
        let behind = uniform(rng, 0.15, 0.4);
        let lateral = uniform(rng, -0.12, 0.12);
        let origin = event_origin(rng, input.room, dir, 0.5 + far_shift(input));

        let (pose, bottom, _) = resting_pose(object);
        let rotation = quat::mul(yaw_quat(heading_angle), pose);
        let half_len = object.half_extents()[0];
        let row: f64 = 2.0 * half_len * count as f64 + gaps[..count - 1].iter().sum::<f64>();
        let longest_row = row - run_up(input.speed) + longest_run_up;
        let half_depth = ((longest_row + 0.2) / 2.0).max(0.3);
        let table = table_block(
            "table",
            origin,
            [half_depth, half_width],
            height,
            heading_angle,
            friction,
        );
        let edge = ahead(origin, dir, half_depth);
        let last = ahead(ahead(edge, dir, -behind * half_len), side, lateral);
        let mut bodies = vec![table];
        // Items from the first (the shoved one) to the last (the hazard).
        let mut offsets = vec![0.0; count];
        for i in (0..count - 1).rev() {
            offsets[i] = offsets[i + 1] + 2.0 * half_len + gaps[i];
        }
        for (i, off) in offsets.iter().enumerate() {
            let xy = ahead(last, dir, -off);
            let position = [xy[0], xy[1], height + bottom];
            let v = if i == 0 { input.speed } else { 0.0 };
            let linvel = [dir[0] * v, dir[1] * v, 0.0];
            if i + 1 == count {
                bodies.push(hazard_body(object, position, rotation, linvel, [0.0; 3]));
            } else {
                bodies.push(prop_copy(
                    object,
                    &format!("{}_{i}", object.id),
                    position,
                    rotation,
                    linvel,
                ));
            }
        }
        let observer = observer_beyond(
            rng,
            edge,
            dir,
            (1.5, 1.9),
            (2.8, 3.2),
            0.35,
            input.far_observer,
            last,
        );
        Layout {
            hazard: bodies.len() - 1,
            bodies,
            joints: vec![],
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("row_count".into(), count as f64),
                ("run_up_m".into(), run_up(input.speed)),
                ("com_behind_edge_m".into(), behind * half_len),
                ("drop_height_m".into(), height),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // Momentum ran down the row and pushed the last object off the table: it started
        // on the table and reached the floor.
        reached_floor(spec, sim)
    }
}
