//! thrown_object: an object is thrown at the observer (SPEC §4).

use super::*;

pub struct ThrownObject;

/// Elevation that carries a projectile launched at `speed` through a point `dx` away
/// horizontally and `dy` higher: the flatter of the two solutions, or 45° (the longest
/// throw) when the speed cannot reach it.
pub fn aim_elevation(speed: f64, dx: f64, dy: f64) -> f64 {
    let v2 = speed * speed;
    let disc = v2 * v2 - GRAVITY * (GRAVITY * dx * dx + 2.0 * dy * v2);
    if disc < 0.0 || dx <= 0.0 {
        std::f64::consts::FRAC_PI_4
    } else {
        ((v2 - disc.sqrt()) / (GRAVITY * dx)).atan()
    }
}

impl Family for ThrownObject {
    fn name(&self) -> &'static str {
        "thrown_object"
    }
    fn speed_parameter(&self) -> &'static str {
        "launch_speed_mps"
    }
    fn speed_sweep(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let perp = [-dir[1], dir[0]];
        let distance = uniform(rng, 2.5, 4.0);
        let launch_height = uniform(rng, 1.1, 1.6);
        let aim_height = uniform(rng, 0.85, 1.25);
        let aim_lateral = uniform(rng, -0.25, 0.25);
        // A far-observer group is a throw that goes wide of the observer.
        let miss_side = if uniform(rng, 0.0, 1.0) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let miss_offset = uniform(rng, 2.2, 2.8) * miss_side;
        let spin = [
            uniform(rng, -6.0, 6.0),
            uniform(rng, -6.0, 6.0),
            uniform(rng, -6.0, 6.0),
        ];
        let yaw = uniform(rng, 0.0, std::f64::consts::TAU);
        let origin = event_origin(rng, input.room, dir, distance / 2.0);

        let start = [origin[0], origin[1], launch_height];
        let observer_xy = [origin[0] + dir[0] * distance, origin[1] + dir[1] * distance];
        let lateral = if input.far_observer {
            miss_offset
        } else {
            aim_lateral
        };
        let target = [
            observer_xy[0] + perp[0] * lateral,
            observer_xy[1] + perp[1] * lateral,
            aim_height,
        ];
        let dx = ((target[0] - start[0]).powi(2) + (target[1] - start[1]).powi(2)).sqrt();
        let elevation = aim_elevation(input.speed, dx, target[2] - start[2]);
        let aim = [(target[0] - start[0]) / dx, (target[1] - start[1]) / dx];
        let linvel = [
            aim[0] * input.speed * elevation.cos(),
            aim[1] * input.speed * elevation.cos(),
            input.speed * elevation.sin(),
        ];
        let hazard = hazard_body(input.object, start, yaw_quat(yaw), linvel, spin);
        let observer = ObserverPose {
            x: observer_xy[0],
            y: observer_xy[1],
            yaw: heading_angle + std::f64::consts::PI,
        };
        Layout {
            bodies: vec![hazard],
            joints: vec![],
            hazard: 0,
            source_support: None,
            observer,
            params: BTreeMap::from([
                ("launch_height_m".into(), launch_height),
                ("throw_distance_m".into(), dx),
                ("aim_height_m".into(), aim_height),
                ("elevation_rad".into(), elevation),
            ]),
        }
    }

    fn event_happened(&self, _spec: &SceneSpec, sim: &Simulation) -> bool {
        // A real throw: at least a metre of flight before anything is touched.
        let Some(k) = sim.first_contact_step() else {
            return false;
        };
        let a = sim.hazard_position(0);
        let b = sim.hazard_position(k);
        ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt() >= 1.0
    }
}
