//! object_drop: an object on a table creeps off the edge and falls (SPEC §4).
//!
//! Timing (label rule v2): the object rests on a smooth board propped on the table (a tray,
//! a drawing board) that slopes gently toward the table's front edge, just steeper than
//! the friction angle (a rolling ball: a few degrees). Nudged down the slope at the band's
//! speed it creeps 0.24–0.32 m, accelerating at 0.35–0.6 m/s², before it tips over the
//! edge: even the fastest nudge takes about 0.55 s to get there, so the fall reaches the
//! observer standing beyond the edge after Δ + 0.2 s = 0.8 s.

use super::launch::*;
use super::*;

pub struct ObjectDrop;

impl Family for ObjectDrop {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "object_drop",
            speed_parameter: "push_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let table_half = [uniform(rng, 0.3, 0.45), uniform(rng, 0.35, 0.7)];
        let board_friction = uniform(rng, 0.1, 0.3);
        let lateral = uniform(rng, -0.12, 0.12);
        let relative_yaw = uniform(rng, -0.25, 0.25);
        let accel = uniform(rng, 0.35, 0.6);
        let com_to_edge = uniform(rng, 0.24, 0.32);
        let origin = event_origin(rng, input.room, dir, 0.6);

        let mu = combined_friction(object.friction, board_friction);
        let tilt = creep_tilt(object, mu, accel);
        let lying = lies_on_slope(object, tilt);
        let (_, half_len) = slope_pose_extents(object, lying, relative_yaw);
        let board_half_len = (com_to_edge + half_len + 0.05) / 2.0;
        // The table's front edge, and the board's lower edge on it.
        let edge_xy = ahead(origin, dir, table_half[0]);
        let launch = TiltedLaunch {
            surface_name: "board",
            edge: [edge_xy[0], edge_xy[1], height],
            heading_angle,
            tilt,
            board_half: [board_half_len, table_half[1].min(0.35)],
            thickness: 0.02,
            friction: board_friction,
            com_to_edge,
            lateral,
            relative_yaw,
            lying,
        };
        let (board, hazard) = launch.build(object, input.speed);
        // The table block under the board (its top just below the board's lower edge).
        let table_top = height - 0.025;
        let table = table_block("table", origin, table_half, table_top, heading_angle, 0.5);
        let start = hazard.position;
        let landing = ahead(edge_xy, dir, 0.15);
        let observer = observer_beyond(
            rng,
            landing,
            dir,
            (0.35, 0.85),
            (2.2, 2.8),
            0.35,
            input.far_observer,
            [start[0], start[1]],
        );
        Layout {
            bodies: vec![board, hazard, table],
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("drop_height_m".into(), height),
                ("board_friction".into(), board_friction),
                ("board_tilt_rad".into(), tilt),
                ("creep_accel_mps2".into(), accel),
                ("lying".into(), if lying { 1.0 } else { 0.0 }),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The object left the table and reached the floor.
        reached_floor(spec, sim)
    }
}
