//! hanging_fall: a wall fixture (picture frame, clock, mirror, shelf) comes off its mount
//! and falls (SPEC §4).
//!
//! The fixture hangs flat against a room wall (a fixed slab), a centimetre or two off it,
//! just below its mount (a small fixed hook). At t0 the mount has let go: the fixture is
//! free, and the band's value is how hard it pops off the wall: it peels off about its
//! bottom back edge (which starts at rest) with the top edge leaving the wall at that
//! speed (for fixtures under 30 cm tall, a point 30 cm up). Gravity sets the pace of the
//! fall (`speed_sweep = false`).

use super::*;

pub struct HangingFall;

impl Family for HangingFall {
    fn name(&self) -> &'static str {
        "hanging_fall"
    }
    fn speed_parameter(&self) -> &'static str {
        "detach_speed_mps"
    }
    /// Gravity sets the pace of a fall from the wall.
    fn speed_sweep(&self) -> bool {
        false
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let room = input.room;
        let site = wall_site(rng, room, 1.0);
        let bottom_height = uniform(rng, 1.15, 1.6);
        let gap = uniform(rng, 0.01, 0.02);
        let n = heading(site.normal_angle);
        let side = left_of(n);

        // Object frame: face in x–z, thickness along y; local +y points into the room.
        let rotation = yaw_quat(site.normal_angle - std::f64::consts::FRAC_PI_2);
        let back = object
            .parts
            .iter()
            .map(|p| p.half_extents()[1] - p.offset[1])
            .fold(0.0, f64::max);
        let bottom = bottom_offset(object);
        let top = top_offset(object);
        let z = (bottom_height + bottom).min(room.ceiling_height - 0.2 - top);
        let centre = ahead(site.base, n, gap + back);
        let position = [centre[0], centre[1], z];

        // Peel about the bottom back edge (the one against the wall), at the rate that
        // moves a point 30 cm up (or the top of a taller fixture) off the wall at `speed`:
        // every other point moves away from the wall, none into it.
        let height = top + bottom;
        let omega = [side[0], side[1], 0.0].map(|c| c * input.speed / height.max(0.3));
        let com = com_offset(object);
        let pivot = {
            let e = quat::rotate(rotation, [0.0, -back, -bottom]);
            [position[0] + e[0], position[1] + e[1], position[2] + e[2]]
        };
        let com_world = {
            let c = quat::rotate(rotation, com);
            [position[0] + c[0], position[1] + c[1], position[2] + c[2]]
        };
        let linvel = velocity_about(omega, pivot, com_world);
        let hazard = hazard_body(object, position, rotation, linvel, omega);

        let wall = wall_body(&site, 1.2, room.ceiling_height, 0.5);
        let hook_xy = ahead(site.base, n, 0.012);
        let hook = fixed_box(
            "mount",
            [0.012, 0.015, 0.006],
            [hook_xy[0], hook_xy[1], z + top + 0.05],
            yaw_quat(site.normal_angle),
            0.5,
            0.1,
        );
        let observer = observer_beyond(
            rng,
            site.base,
            n,
            (0.85, 1.15),
            (2.35, 2.7),
            0.3,
            input.far_observer,
            centre,
        );
        Layout {
            bodies: vec![wall, hook, hazard],
            joints: vec![],
            hazard: 2,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("drop_height_m".into(), z - bottom),
                ("mount_height_m".into(), z + top + 0.05),
                ("wall_gap_m".into(), gap),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // Detached and fell: it reached the floor from at least half a metre up.
        let drop = spec
            .family_params
            .get("drop_height_m")
            .copied()
            .unwrap_or(0.0);
        drop >= 0.5 && reached_floor(spec, sim)
    }
}
