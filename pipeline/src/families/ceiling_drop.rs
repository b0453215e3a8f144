//! ceiling_drop: a fixture comes loose and falls from the ceiling (SPEC §4).

use super::*;

pub struct CeilingDrop;

impl Family for CeilingDrop {
    fn name(&self) -> &'static str {
        "ceiling_drop"
    }
    fn speed_parameter(&self) -> &'static str {
        "release_speed_mps"
    }
    /// Gravity sets the pace of a fall from the ceiling.
    fn speed_sweep(&self) -> bool {
        false
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let mount_gap = uniform(rng, 0.02, 0.06);
        let yaw = uniform(rng, 0.0, std::f64::consts::TAU);
        let origin = event_origin(rng, input.room, dir, 0.5);
        let object = input.object;
        let top_offset = object
            .parts
            .iter()
            .map(|p| p.half_extents()[2] + p.offset[2])
            .fold(0.0, f64::max);
        let z = input.room.ceiling_height - mount_gap - top_offset;
        let hazard = hazard_body(
            object,
            [origin[0], origin[1], z],
            yaw_quat(yaw),
            [0.0, 0.0, -input.speed],
            [0.0; 3],
        );
        let observer = observer_beyond(
            rng,
            origin,
            dir,
            (0.8, 1.15),
            (2.2, 2.8),
            0.0,
            input.far_observer,
            origin,
        );
        Layout {
            bodies: vec![hazard],
            joints: vec![],
            hazard: 0,
            source_support: None,
            observer,
            params: BTreeMap::from([
                ("drop_height_m".into(), z - bottom_offset(object)),
                ("ceiling_height_m".into(), input.room.ceiling_height),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        reached_floor(spec, sim)
    }
}
