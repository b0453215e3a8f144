//! multi_object: momentum runs down a row of objects (specification §4).
//!
//! Three or four copies of the object stand in a row on a long counter, a few millimetres
//! apart, the last one (the hazard) near the edge — all placed exactly on it, at rest.
//! The first is shoved from far back toward the others; each collision passes the
//! momentum on, and the last object is pushed toward (and usually off) the edge.
//!
//! Timing (label rule v5): the band's speed is the first object's as it strikes the rest
//! of the row, after the same drawn time `t` (`HIT_S`) in every band. It is shoved from
//! `u·t + ½·a·t²` back at `u + a·t` (`a` = μ·g, the deceleration of its slide on the
//! polished table at the pair's combined friction μ; 0 for an object that rolls), so it
//! slides into the row at the band's speed `u` whatever its friction: a faster band or a
//! rougher object starts farther back and is shoved harder. The row's last object then
//! goes over the edge of a counter (at least `TABLE_MIN_M` high) and falls, and `aim`
//! stands the observer where it passes after Δ plus the reaction time and margin: at the
//! hands (a benign object), or where it lands on the feet (a dangerous one). The counter runs along one of the room's
//! diagonals; where even that is too short for the fastest band's run-up, every band
//! strikes sooner (`fit_time`). (Until label rule v5 the band's speed was the shove, and
//! only objects that kept 30% of it over the run-up were timed: 4 of 40 scenes a real
//! decision.)
//! The family's own pose (a group that cannot be aimed) stands 1.5–1.9 m beyond the edge,
//! clear of the table and of the fall: the hazard reaches it only on the floor.

use super::launch::{diagonal_heading, rests_on_a_ball, room_span, span_start};
use super::*;

pub struct MultiObject;

/// When every band's shoved object strikes the row (s after t0): the last object goes
/// over the edge soon after and falls through the hands' heights, or onto the feet, after
/// Δ plus the reaction time and `[aim] reaction_margin_s` (`aim` checks every band).
pub const HIT_S: [f64; 2] = [0.75, 0.9];

/// The room keeps this margin (m) from the walls to the table's back and to `BEYOND_M`
/// beyond its edge, where the last object falls and the observer stands.
pub const ROOM_MARGIN_M: f64 = 0.6;
pub const BEYOND_M: f64 = 0.8;

/// The table's length beyond the longest run-up and the row (m).
pub const TABLE_MARGIN_M: f64 = 0.2;

/// The time (s) in which an object decelerating at `decel` and striking at `strike`
/// covers `run_up` m (the inverse of [`run_up`]); 0 when there is no room.
pub fn fit_time(strike: f64, decel: f64, run_up: f64) -> f64 {
    if run_up <= 0.0 {
        0.0
    } else if decel > 0.0 {
        ((strike * strike + 2.0 * decel * run_up).sqrt() - strike) / decel
    } else {
        run_up / strike.max(1e-9)
    }
}

/// The least table height (m), a counter's: the last object falls through the hands'
/// heights, and far enough beyond the edge to land on the feet of a body standing clear
/// of the counter (`balance` pools of seeds 0, 1, 2: 6, 2, 8 DODGE of 40 scenes with
/// 0.8 m; 10, 5, 7 with 1.0 m).
pub const TABLE_MIN_M: f64 = 1.0;

/// The run-up (m) over which an object decelerating at `decel` (m/s²) reaches the row at
/// `strike` (m/s) after `t` s, and the shove (m/s) it starts with: `u·t + ½·a·t²`, `u + a·t`.
pub fn run_up(strike: f64, decel: f64, t: f64) -> (f64, f64) {
    (strike * t + 0.5 * decel * t * t, strike + decel * t)
}

/// The deceleration (m/s²) of a copy of `object` sliding on a surface of `friction`: the
/// pair's combined (averaged) friction times g; 0 for an object that rolls on a ball.
pub fn slide_decel(object: &Object, friction: f64) -> f64 {
    if rests_on_a_ball(object) {
        0.0
    } else {
        0.5 * (object.friction + friction) * GRAVITY
    }
}

impl Family for MultiObject {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "multi_object",
            speed_parameter: "strike_speed_mps",
            speed_sweep: true,
        }
    }

    fn timed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        // Along one of the room's diagonals: the longest straight run it offers.
        let heading_angle = diagonal_heading(rng, input.room, 0.2);
        let dir = heading(heading_angle);
        let side = left_of(dir);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let half_width = uniform(rng, 0.35, 0.6);
        let friction = uniform(rng, 0.03, 0.1);
        let count = if uniform(rng, 0.0, 1.0) < 0.5 { 3 } else { 4 };
        let mut gaps = [0, 1, 2].map(|_| uniform(rng, 0.005, 0.03));
        // Every band's first object strikes the row after the same drawn time, at the
        // band's speed (see the module doc); the table is as long as the fastest band needs.
        let t_drawn = uniform(rng, HIT_S[0], HIT_S[1]);
        let decel = slide_decel(object, friction);
        let (pose, bottom, _) = resting_pose(object);
        let half_len = object.half_extents()[0];
        let row: f64 = 2.0 * half_len * count as f64 + gaps[..count - 1].iter().sum::<f64>();
        // The table (run-up, row and a margin) and `BEYOND_M` for the fall and the
        // observer fit along the room's diagonal: where the fastest band's run-up would
        // not, every band strikes sooner (`fit_time`; such a group may not be aimable).
        let span = room_span(input.room, dir, ROOM_MARGIN_M);
        let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
        let room_for_run_up = span - BEYOND_M - row - TABLE_MARGIN_M;
        let t_hit = t_drawn.min(fit_time(fastest, decel, room_for_run_up));
        let (run, shove) = run_up(input.speed, decel, t_hit);
        let longest_run_up = run_up(fastest, decel, t_hit).0;
        gaps[0] += run;
        let height = height.max(TABLE_MIN_M);
        let behind = uniform(rng, 0.15, 0.4);
        let lateral = uniform(rng, -0.12, 0.12);
        let rotation = quat::mul(yaw_quat(heading_angle), pose);
        let longest_row = row + longest_run_up;
        let half_depth = ((longest_row + TABLE_MARGIN_M) / 2.0).max(0.3);
        let start = span_start(
            rng,
            input.room,
            dir,
            2.0 * half_depth + BEYOND_M,
            ROOM_MARGIN_M,
        );
        let origin = ahead(start, dir, half_depth);
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
            let v = if i == 0 { shove } else { 0.0 };
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
                ("run_up_m".into(), run),
                ("hit_time_s".into(), t_hit),
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
