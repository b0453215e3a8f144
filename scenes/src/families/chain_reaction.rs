//! chain_reaction: a strike launches a second, initially resting object (SPEC §4).
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

impl Family for ChainReaction {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "chain_reaction",
            speed_parameter: "trigger_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let side = left_of(dir);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let half_width = uniform(rng, 0.35, 0.6);
        let friction = uniform(rng, 0.08, 0.15);
        let behind = uniform(rng, 0.15, 0.45);
        let gap = uniform(rng, 1.1, 1.5);
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
        let needed = 2.0 * trigger_half[0] + gap + half_len * (1.0 + behind) + 0.15;
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
        Layout {
            bodies: vec![table, trigger, target],
            joints: vec![],
            hazard: 2,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("com_behind_edge_m".into(), behind * half_len),
                ("trigger_gap_m".into(), gap),
                ("drop_height_m".into(), height),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The target was launched off its table: it started on it and reached the floor
        // (a target nudged a few centimetres that stays on the table is no event).
        reached_floor(spec, sim)
    }
}

/// First step at which the hazard touches a body other than its table or the floor
/// (the trigger, in this family).
pub fn first_strike_step(sim: &Simulation) -> Option<u32> {
    (0..=sim.steps())
        .find(|&k| sim.hazard_contacts[k as usize] & rh_physics::simulate::TOUCH_OTHER != 0)
}
