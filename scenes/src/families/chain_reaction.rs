//! chain_reaction: a strike launches a second, initially resting object (specification §4).
//!
//! The target (the hazard) rests on a table near its edge — placed exactly on the table,
//! centre of mass well behind the edge, at rest (capsules lie on their side) — and a
//! heavier block (the trigger, twice the target's mass, at least 0.5 kg) slides into it
//! from behind at the band's speed. No force acts after t0: the impact alone launches
//! the target toward the edge and off it.
//!
//! Timing (label rule v2): the trigger starts well back on a longer, polished table (a
//! 1.1–1.5 m run-up on felt pads: little friction, so even the slowest band arrives),
//! the target rests with its centre of mass just behind the edge (any strike tips it
//! off), and the observer stands 1.2–1.6 m beyond the edge: clear of the table and of
//! the target's fall, so the target reaches them only on the floor, after the run-up,
//! the strike and the fall.

use super::*;

pub struct ChainReaction;

/// The trigger block slides on felt pads.
const TRIGGER_FRICTION: f64 = 0.02;

/// When every band's trigger strikes the target (s after t0): the target then leaves the
/// edge after Δ (0.6 s) plus the reaction time (0.2 s).
pub const STRIKE_S: [f64; 2] = [0.75, 0.9];

/// The trigger's run-up (m) when not aimed at the hands (label rule v4's range).
pub const FLOOR_GAP_M: [f64; 2] = [1.1, 1.5];

fn lerp(range: [f64; 2], u: f64) -> f64 {
    range[0] + (range[1] - range[0]) * u
}

/// The least table height (m): from there the target falls through the hands' heights.
pub const TABLE_MIN_M: f64 = 0.8;

/// The run-up (m) a trigger sliding at `speed` on its felt pads covers in `t` seconds.
pub fn gap_for(speed: f64, t: f64) -> f64 {
    let decel = TRIGGER_FRICTION * GRAVITY;
    let stop = speed / decel;
    let t = t.min(stop);
    speed * t - 0.5 * decel * t * t
}

impl Family for ChainReaction {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "chain_reaction",
            speed_parameter: "trigger_speed_mps",
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
        // At least hip height: the target leaves it where the hands can hold it.
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let half_width = uniform(rng, 0.35, 0.6);
        let friction = uniform(rng, 0.08, 0.15);
        let behind = uniform(rng, 0.15, 0.45);
        // Every band's trigger strikes after the same drawn time (label rule v5: the target
        // leaves the edge after Δ plus the reaction time): a faster trigger starts farther
        // back, `gap_for` its speed; the table is as long as the fastest band needs.
        let u = uniform(rng, 0.0, 1.0);
        // Aimed at the hands, every band's trigger strikes after the same drawn time (the
        // target leaves the edge after Δ plus the reaction time; a faster trigger starts
        // farther back, `gap_for` its speed). Else (aimed at the body, or a near miss) the
        // drawn run-up of label rule v4: the target reaches the observer along the floor.
        let hands = input.intent == crate::intent::Intent::Hands;
        let t_strike = lerp(STRIKE_S, u);
        let gap_of = |v: f64| {
            if hands {
                gap_for(v, t_strike)
            } else {
                lerp(FLOOR_GAP_M, u)
            }
        };
        let gap = gap_of(input.speed);
        let longest_gap = input
            .band_speeds
            .iter()
            .map(|&v| gap_of(v))
            .fold(0.0, f64::max);
        let lateral = uniform(rng, -0.12, 0.12);
        let origin = event_origin(rng, input.room, dir, 0.4 + far_shift(input));

        let (pose, bottom, target_h) = resting_pose(object);
        let rotation = quat::mul(yaw_quat(heading_angle), pose);
        let he = object.half_extents();
        let (half_len, half_w) = if pose == IDENTITY {
            (he[0], he[1])
        } else {
            (he[0], he[2])
        };
        let trigger_half = [
            0.06,
            half_w.clamp(0.04, 0.2),
            (target_h / 2.0).clamp(0.01, 0.15),
        ];
        // The table reaches from behind the trigger to the edge.
        // Aimed at the hands, a table at least at hip height.
        let height = if hands {
            height.max(TABLE_MIN_M)
        } else {
            height
        };
        let needed = 2.0 * trigger_half[0] + longest_gap + half_len * (1.0 + behind) + 0.15;
        let half_depth = (needed / 2.0).max(0.3);
        let table = table_block(
            "table",
            origin,
            [half_depth, half_width],
            height,
            heading_angle,
            friction,
        );
        let edge = ahead(origin, dir, half_depth);
        let target_xy = ahead(ahead(edge, dir, -behind * half_len), side, lateral);
        let target = hazard_body(
            object,
            [target_xy[0], target_xy[1], height + bottom],
            rotation,
            [0.0; 3],
            [0.0; 3],
        );
        let trigger_xy = ahead(target_xy, dir, -(half_len + gap + trigger_half[0]));
        let trigger = prop_box(
            "trigger_block",
            trigger_half,
            [
                trigger_xy[0],
                trigger_xy[1],
                height + trigger_half[2] + 1e-4,
            ],
            yaw_quat(heading_angle),
            (2.0 * object.mass).max(0.5),
            TRIGGER_FRICTION,
            0.1,
            [dir[0] * input.speed, dir[1] * input.speed, 0.0],
        );
        let observer = observer_beyond(
            rng,
            edge,
            dir,
            (1.2, 1.6),
            (2.8, 3.2),
            0.35,
            input.far_observer,
            target_xy,
        );
        let mut params = BTreeMap::from([
            ("table_height_m".into(), height),
            ("com_behind_edge_m".into(), behind * half_len),
            ("trigger_gap_m".into(), gap),
            ("drop_height_m".into(), height),
        ]);
        if hands {
            params.insert("strike_time_s".into(), t_strike);
        }
        Layout {
            bodies: vec![table, trigger, target],
            joints: vec![],
            hazard: 2,
            source_support: Some(0),
            observer,
            params,
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The target was launched off its table: it started on it and reached the floor
        // (a target nudged a few centimetres that stays on the table is no event), and it
        // rested until the trigger struck it (a head-heavy target that creeps off on its
        // own, as a hatchet on the felt-smooth table can, is not this family's event).
        reached_floor(spec, sim)
            && first_strike_step(sim).is_some_and(|strike| {
                let p0 = sim.hazard_position(0);
                (0..strike).all(|k| {
                    let p = sim.hazard_position(k);
                    let d2: f64 = (0..3).map(|i| (p[i] - p0[i]).powi(2)).sum();
                    d2 < REST_CREEP_M * REST_CREEP_M
                })
            })
    }
}

/// How far (m) the target may settle on its table before the trigger strikes it: rapier's
/// soft contacts let a body set exactly on a surface creep at about 1 mm/s.
pub const REST_CREEP_M: f64 = 0.002;

/// First step at which the hazard touches a body other than its table or the floor
/// (the trigger, in this family).
pub fn first_strike_step(sim: &Simulation) -> Option<u32> {
    (0..=sim.steps())
        .find(|&k| sim.hazard_contacts[k as usize] & rh_physics::simulate::TOUCH_OTHER != 0)
}
