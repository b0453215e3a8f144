//! rolling_ball: a ball rolls off a table and on across the floor (SPEC §4).

use super::*;

pub struct RollingBall;

impl Family for RollingBall {
    fn name(&self) -> &'static str {
        "rolling_ball"
    }
    fn speed_parameter(&self) -> &'static str {
        "roll_speed_mps"
    }
    fn speed_sweep(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let surface_half = [uniform(rng, 0.35, 0.5), uniform(rng, 0.35, 0.7)];
        let surface_friction = uniform(rng, 0.4, 0.7);
        let lateral = uniform(rng, -0.2, 0.2);
        // A rolling ball keeps its speed, so it may start well behind the edge.
        let com_to_edge = uniform(rng, 0.08, 0.3);
        let origin = event_origin(rng, input.room, dir, 1.0);
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
        let (bodies, edge, start) = launch.build(input.object, input.speed);
        let observer = observer_beyond(
            rng,
            edge,
            dir,
            (0.9, 2.0),
            (3.0, 3.6),
            0.3,
            input.far_observer,
            [start[0], start[1]],
        );
        Layout {
            bodies,
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
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
