//! object_drop: an object on a table is nudged past the edge and tips off (SPEC §4).

use super::*;

pub struct ObjectDrop;

/// Where the centre of mass starts relative to a surface edge (positive: behind it).
///
/// Sized so that even the slowest band would slide on until its centre is `overshoot`
/// half-lengths past the edge (`stop − c`, with the sliding distance `v²/(2μg)`): an
/// object that comes to rest just past an edge can stay balanced there in the solver,
/// and one that overshoots by a good fraction of its length reliably tips off. The
/// start overhang is capped at 40% of the half-length, so the object always begins
/// mostly on the surface. The draw does not depend on the band's speed.
pub(super) fn com_behind_edge(
    rng: &mut ChaCha8Rng,
    input: &FamilyInput,
    surface_friction: f64,
    overshoot: (f64, f64),
) -> f64 {
    let mu = combined_friction(input.object.friction, surface_friction);
    let slowest = input
        .band_speeds
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let stop_distance = slowest * slowest / (2.0 * mu * GRAVITY);
    let half_len = footprint_half_length(input.object, 0.0);
    let c = stop_distance - uniform(rng, overshoot.0, overshoot.1) * half_len;
    c.clamp(-0.4 * half_len, 0.25)
}

impl Family for ObjectDrop {
    fn name(&self) -> &'static str {
        "object_drop"
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
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let surface_half = [uniform(rng, 0.3, 0.45), uniform(rng, 0.35, 0.7)];
        let surface_friction = uniform(rng, 0.35, 0.6);
        let lateral = uniform(rng, -0.15, 0.15);
        let relative_yaw = uniform(rng, -0.25, 0.25);
        let com_to_edge = com_behind_edge(rng, input, surface_friction, (0.8, 1.2));
        let origin = event_origin(rng, input.room, dir, 0.6);
        let launch = EdgeLaunch {
            surface_name: "table",
            surface_height: height,
            surface_half,
            surface_friction,
            heading_angle,
            com_to_edge,
            lateral,
            relative_yaw,
            origin,
            board_thickness: None,
            rolling: false,
        };
        let (bodies, edge, start) = launch.build(input.object, input.speed);
        let landing = [edge[0] + dir[0] * 0.15, edge[1] + dir[1] * 0.15];
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
            bodies,
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("drop_height_m".into(), height),
                ("table_friction".into(), surface_friction),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The object left the table and reached the floor.
        reached_floor(spec, sim)
    }
}
