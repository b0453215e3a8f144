//! shelf_slide: an object slides off a high shelf (SPEC §4).

use super::object_drop::com_behind_edge;
use super::*;

pub struct ShelfSlide;

impl Family for ShelfSlide {
    fn name(&self) -> &'static str {
        "shelf_slide"
    }
    fn speed_parameter(&self) -> &'static str {
        "push_speed_mps"
    }
    fn speed_sweep(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let height = uniform(rng, input.room.shelf_height[0], input.room.shelf_height[1]);
        let depth_half = uniform(rng, 0.14, 0.2);
        let width_half = uniform(rng, 0.4, 0.6);
        let surface_friction = uniform(rng, 0.25, 0.45);
        let lateral = uniform(rng, -0.2, 0.2);
        let relative_yaw = uniform(rng, -0.15, 0.15);
        let com_to_edge = com_behind_edge(rng, input, surface_friction, (0.8, 1.2));
        let origin = event_origin(rng, input.room, dir, 0.7);
        let launch = EdgeLaunch {
            surface_name: "shelf",
            surface_height: height,
            surface_half: [depth_half, width_half],
            surface_friction,
            heading_angle,
            com_to_edge,
            lateral,
            relative_yaw,
            origin,
            board_thickness: Some(0.03),
            rolling: false,
        };
        let (bodies, edge, start) = launch.build(input.object, input.speed);
        let landing = [edge[0] + dir[0] * 0.25, edge[1] + dir[1] * 0.25];
        let observer = observer_beyond(
            rng,
            landing,
            dir,
            (0.3, 0.9),
            (2.2, 2.8),
            0.35,
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
                ("shelf_height_m".into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("drop_height_m".into(), height),
                ("shelf_friction".into(), surface_friction),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        reached_floor(spec, sim)
    }
}
