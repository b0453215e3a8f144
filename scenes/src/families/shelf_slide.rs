//! shelf_slide: an object slides off a high shelf (SPEC §4).
//!
//! Timing (label rule v2): the shelf sags forward, sloping toward its front edge just
//! steeper than the friction angle (a ball: a few degrees). Nudged down the slope at the
//! band's speed, the object creeps 0.2–0.28 m, accelerating at 0.4–0.65 m/s², before it
//! tips over the edge (about 0.45 s even for the fastest nudge), and then falls from
//! shelf height, so it reaches the observer in front of the shelf after Δ + 0.2 s = 0.8 s.

use super::launch::*;
use super::*;

pub struct ShelfSlide;

impl Family for ShelfSlide {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "shelf_slide",
            speed_parameter: "push_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let height = uniform(rng, input.room.shelf_height[0], input.room.shelf_height[1]);
        let width_half = uniform(rng, 0.4, 0.6);
        let surface_friction = uniform(rng, 0.1, 0.3);
        let lateral = uniform(rng, -0.15, 0.15);
        let relative_yaw = uniform(rng, -0.15, 0.15);
        let accel = uniform(rng, 0.4, 0.65);
        let com_to_edge = uniform(rng, 0.2, 0.28);
        let origin = event_origin(rng, input.room, dir, 0.7);

        let mu = combined_friction(object.friction, surface_friction);
        let tilt = creep_tilt(object, mu, accel);
        let lying = lies_on_slope(object, tilt);
        let (_, half_len) = slope_pose_extents(object, lying, relative_yaw);
        let depth_half = (com_to_edge + half_len + 0.05) / 2.0;
        let launch = TiltedLaunch {
            surface_name: "shelf",
            edge: [origin[0], origin[1], height],
            heading_angle,
            tilt,
            board_half: [depth_half, width_half],
            thickness: 0.03,
            friction: surface_friction,
            com_to_edge,
            lateral,
            relative_yaw,
            lying,
        };
        let (shelf, hazard) = launch.build(object, input.speed);
        let start = hazard.position;
        let landing = ahead(origin, dir, 0.25);
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
            bodies: vec![shelf, hazard],
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("shelf_height_m".into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("drop_height_m".into(), height),
                ("shelf_friction".into(), surface_friction),
                ("shelf_tilt_rad".into(), tilt),
                ("creep_accel_mps2".into(), accel),
                ("lying".into(), if lying { 1.0 } else { 0.0 }),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        reached_floor(spec, sim)
    }
}
