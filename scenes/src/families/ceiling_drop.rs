//! ceiling_drop: a fixture comes loose and falls from the ceiling (specification §4).
//!
//! Timing (label rule v2): the fixture's mount (two rails) has bent, so it hangs under the
//! ceiling sloping down just steeper than the friction angle. The fixture creeps
//! 0.18–0.28 m down the rails, accelerating at 0.45–0.8 m/s² from the band's release
//! speed, before it tips off the rails' lower ends (about 0.5 s even for the fastest
//! release), and then falls: it reaches the observer, or strikes one standing under it,
//! after Δ + 0.2 s = 0.8 s. The observer stands near the fall line (under it, within
//! reach, or beyond reach), and in some groups behind the mount, which the fixture
//! slides away from.

use super::launch::*;
use super::*;

pub struct CeilingDrop;

impl Family for CeilingDrop {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "ceiling_drop",
            speed_parameter: "release_speed_mps",
            // Gravity sets the pace of a fall from the ceiling.
            speed_sweep: false,
        }
    }

    /// A push (label rule v6): a faster band's object starts farther up the same board.
    fn timed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let ceiling = input.room.ceiling_height;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let yaw = uniform(rng, -0.3, 0.3);
        let plate_friction = uniform(rng, 0.25, 0.4);
        let accel = uniform(rng, 0.45, 0.8);
        let base_to_edge = uniform(rng, 0.18, 0.28);
        let (lead, lead_max) = push_leads(input);
        let com_to_edge = base_to_edge + lead;
        let com_max = base_to_edge + lead_max;
        let behind = uniform(rng, 0.0, 1.0) < 0.2;
        let origin = event_origin(rng, input.room, dir, 0.5);

        let mu = combined_friction(object.friction, plate_friction);
        let tilt = creep_tilt(object, mu, accel);
        let lying = lies_on_slope(object, tilt);
        let (sin_t, cos_t) = tilt.sin_cos();
        let (_, half_len) = slope_pose_extents(object, lying, yaw);
        let half_wide = footprint_half_length(object, yaw + std::f64::consts::FRAC_PI_2);
        let plate_half_len = (com_max + half_len + 0.05) / 2.0;
        // The plate's lower edge as high as the plate's upper end and the fixture's
        // highest corner allow (a few centimetres under the ceiling).
        let height = top_offset(object) + bottom_offset(object);
        let edge_z = (ceiling - 0.03 - 2.0 * plate_half_len * sin_t)
            .min(ceiling - 0.04 - com_max * sin_t - height * cos_t - half_len * sin_t);
        let launch = TiltedLaunch {
            surface_name: "mount",
            edge: [origin[0], origin[1], edge_z],
            heading_angle,
            tilt,
            board_half: [plate_half_len, 0.012],
            thickness: 0.015,
            friction: plate_friction,
            com_to_edge,
            lateral: 0.0,
            relative_yaw: yaw,
            lying,
        };
        let (rail, hazard) = launch.build(object, input.speed);
        // The mount is two rails under the fixture's sides (the cameras see its middle
        // between them), each held to the ceiling by a rod at its upper end.
        let side = left_of(dir);
        let offset = (0.55 * half_wide).max(0.04);
        let back = ahead(origin, dir, -2.0 * plate_half_len * cos_t - 0.01);
        let rod_bottom = launch.top_height() - 0.02;
        let mut bodies = Vec::new();
        for (k, rail) in launch.rails(&rail, offset).into_iter().enumerate() {
            bodies.push(rail);
            let sign = if k == 0 { -1.0 } else { 1.0 };
            let foot = ahead(back, side, sign * offset);
            bodies.push(fixed_box(
                &format!("mount_rod_{k}"),
                [0.01, 0.012, (ceiling - rod_bottom) / 2.0],
                [foot[0], foot[1], (ceiling + rod_bottom) / 2.0],
                yaw_quat(heading_angle),
                0.5,
                0.1,
            ));
        }
        bodies.push(hazard);
        // Where it meets head height: the edge plus its drift while falling.
        let landing = ahead(origin, dir, 0.3);
        let observer = if behind {
            // Behind the mount: the fixture slides and falls away from the observer.
            observer_beyond(
                rng,
                ahead(origin, dir, -com_max),
                [-dir[0], -dir[1]],
                (1.3, 1.7),
                (2.2, 2.8),
                0.3,
                input.far_observer,
                [origin[0], origin[1]],
            )
        } else {
            observer_beyond(
                rng,
                landing,
                dir,
                (-0.35, 1.35),
                (2.2, 2.8),
                0.3,
                input.far_observer,
                [origin[0], origin[1]],
            )
        };
        Layout {
            hazard: bodies.len() - 1,
            bodies,
            joints: vec![],
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("drop_height_m".into(), edge_z),
                ("ceiling_height_m".into(), ceiling),
                ("mount_tilt_rad".into(), tilt),
                ("creep_accel_mps2".into(), accel),
                ("lying".into(), if lying { 1.0 } else { 0.0 }),
                ("com_behind_edge_m".into(), com_to_edge),
                ("observer_behind".into(), if behind { 1.0 } else { 0.0 }),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        reached_floor(spec, sim)
    }
}
