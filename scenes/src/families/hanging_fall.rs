//! hanging_fall: a wall fixture (picture frame, clock, mirror, shelf) comes off its mount
//! and falls (specification §4).
//!
//! The fixture has slipped off its hook onto the picture ledge below it, which has come
//! loose at one end: the ledge (a narrow fixed board along the wall) slopes down along the
//! wall just steeper than the friction angle. The fixture stands on it flat against the
//! wall (a centimetre or two off it), its face parallel to the wall, and creeps down the
//! ledge from the band's speed (`detach_speed_mps`), accelerating at 0.45–0.8 m/s², until
//! it tips off the ledge's lower end and falls along the wall. Gravity sets the pace
//! (`speed_sweep = false`).
//!
//! Timing (label rule v2): the creep of 0.2–0.3 m takes about half a second even at the
//! fastest band, and the observer stands in front of the wall beyond the ledge's lower
//! end, so the fixture comes closest (falling past, or striking) after Δ + 0.2 s = 0.8 s.

use super::launch::*;
use super::*;

pub struct HangingFall;

impl Family for HangingFall {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "hanging_fall",
            speed_parameter: "detach_speed_mps",
            // Gravity sets the pace of a fall from the wall.
            speed_sweep: false,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let room = input.room;
        let site = wall_site(rng, room, 1.3);
        let bottom_height = uniform(rng, 1.15, 1.6);
        let gap = uniform(rng, 0.01, 0.02);
        let downhill_sign = if uniform(rng, 0.0, 1.0) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let ledge_friction = uniform(rng, 0.15, 0.3);
        let accel = uniform(rng, 0.45, 0.8);
        let com_to_end = uniform(rng, 0.2, 0.3);
        let n = heading(site.normal_angle);
        let along = left_of(n);
        let dir = [along[0] * downhill_sign, along[1] * downhill_sign];
        let heading_angle = dir[1].atan2(dir[0]);

        // Object frame: face in x–z, thickness along y; its x runs down the ledge.
        let back = object
            .parts
            .iter()
            .map(|p| p.half_extents()[1] - p.offset[1])
            .fold(0.0, f64::max);
        let front = object
            .parts
            .iter()
            .map(|p| p.half_extents()[1] + p.offset[1])
            .fold(0.0, f64::max);
        let mu = combined_friction(object.friction, ledge_friction);
        let tilt = creep_tilt(object, mu, accel);
        let (sin_t, cos_t) = tilt.sin_cos();
        let half_len = footprint_half_length(object, 0.0);
        let height = top_offset(object) + bottom_offset(object);
        let ledge_half_len = (com_to_end + half_len + 0.05) / 2.0;
        // The fixture's top stays 10 cm under the ceiling.
        let z_end = bottom_height.min(
            room.ceiling_height - 0.1 - com_to_end * sin_t - height * cos_t - half_len * sin_t,
        );
        // The ledge's lower end, its centre line under the fixture's centre.
        let end_xy = ahead(ahead(site.base, n, gap + back), dir, 0.3);
        // Local +y of the object must point into the room: with x along `dir`, y is
        // `left_of(dir)`, which is the wall normal when the ledge runs down to the left.
        let relative_yaw = if dot2(left_of(dir), n) > 0.0 {
            0.0
        } else {
            std::f64::consts::PI
        };
        let launch = TiltedLaunch {
            surface_name: "ledge",
            edge: [end_xy[0], end_xy[1], z_end],
            heading_angle,
            tilt,
            board_half: [ledge_half_len, (back + front) / 2.0 + 0.01],
            thickness: 0.02,
            friction: ledge_friction,
            com_to_edge: com_to_end,
            lateral: 0.0,
            relative_yaw,
            lying: false,
        };
        let (ledge, hazard) = launch.build(object, input.speed);
        let wall = wall_body(&site, 1.2, room.ceiling_height, 0.5);
        let centre = [hazard.position[0], hazard.position[1]];
        // In front of the wall, beyond the ledge's lower end.
        let observer = observer_beyond(
            rng,
            ahead(ahead(site.base, dir, 0.3 + 0.45), n, 0.0),
            n,
            (0.5, 0.9),
            (2.35, 2.7),
            0.25,
            input.far_observer,
            centre,
        );
        Layout {
            bodies: vec![wall, ledge, hazard],
            joints: vec![],
            hazard: 2,
            source_support: Some(1),
            observer,
            params: BTreeMap::from([
                ("drop_height_m".into(), z_end),
                ("wall_gap_m".into(), gap),
                ("ledge_tilt_rad".into(), tilt),
                ("creep_accel_mps2".into(), accel),
                ("com_to_ledge_end_m".into(), com_to_end),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // Came off the ledge and fell: it reached the floor from at least half a metre up.
        let drop = spec
            .family_params
            .get("drop_height_m")
            .copied()
            .unwrap_or(0.0);
        drop >= 0.5 && reached_floor(spec, sim)
    }
}

fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
