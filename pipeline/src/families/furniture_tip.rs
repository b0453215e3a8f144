//! furniture_tip: tall furniture tips over like an inverted pendulum (SPEC §4).
//!
//! The piece stands on the floor, already rocked forward onto its front bottom edge just
//! past its balance angle (the angle at which its centre of mass is over that edge), so
//! it falls forward whatever the band. The band's value is the speed of its top at t0
//! (the push that rocked it), as a rotation about the front edge, which rests on the
//! floor. Gravity sets the pace of the fall (`speed_sweep = false`).
//!
//! Labels: nearly always DODGE. Every catalog piece but the styrofoam TV is heavy
//! (bookcases, wardrobes, fridges, mirrors: 5–80 kg), and a toppling one must be dodged;
//! only the styrofoam TV gives CATCH.

use super::*;

pub struct FurnitureTip;

/// Where the object tips about: the front bottom edge (local +y) of the parts that reach
/// its bottom, and the balance angle there (rad from upright).
pub fn front_edge(object: &Object) -> (Vec3, f64) {
    let bottom = bottom_offset(object);
    let front = object
        .parts
        .iter()
        .filter(|p| (p.offset[2] - p.half_extents()[2] + bottom).abs() < 1e-3)
        .map(|p| p.offset[1] + p.half_extents()[1])
        .fold(0.0, f64::max);
    let com = com_offset(object);
    let balance = (front - com[1]).atan2(com[2] + bottom);
    ([0.0, front, -bottom], balance)
}

impl Family for FurnitureTip {
    fn name(&self) -> &'static str {
        "furniture_tip"
    }
    fn speed_parameter(&self) -> &'static str {
        "push_speed_mps"
    }
    /// Gravity sets the pace of a toppling piece of furniture.
    fn speed_sweep(&self) -> bool {
        false
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let past_balance = uniform(rng, 0.03, 0.08);
        let origin = event_origin(rng, input.room, dir, 0.9 + far_shift(input));

        let (edge, balance) = front_edge(object);
        let tilt = balance + past_balance;
        // Local +y faces the fall; tilting about local x by −tilt brings the top forward.
        let rotation = quat::mul(
            yaw_quat(heading_angle - std::f64::consts::FRAC_PI_2),
            quat::from_axis_angle([1.0, 0.0, 0.0], -tilt),
        );
        let pivot = [origin[0], origin[1], 0.0005];
        let e = quat::rotate(rotation, edge);
        let position = [pivot[0] - e[0], pivot[1] - e[1], pivot[2] - e[2]];
        let height = top_offset(object) + bottom_offset(object);
        // Spin about the edge axis (ẑ × dir) so that the top moves forward at `speed`.
        let axis = left_of(dir);
        let omega = [axis[0], axis[1], 0.0].map(|c| c * input.speed / height);
        let com = quat::rotate(rotation, com_offset(object));
        let com_world = [
            position[0] + com[0],
            position[1] + com[1],
            position[2] + com[2],
        ];
        let linvel = velocity_about(omega, pivot, com_world);
        let hazard = hazard_body(object, position, rotation, linvel, omega);
        let observer = observer_beyond(
            rng,
            [pivot[0], pivot[1]],
            dir,
            (0.6, 1.3),
            (2.5, 2.9),
            0.35,
            input.far_observer,
            [com_world[0], com_world[1]],
        );
        Layout {
            bodies: vec![hazard],
            joints: vec![],
            hazard: 0,
            source_support: None,
            observer,
            params: BTreeMap::from([
                ("balance_angle_rad".into(), balance),
                ("initial_tilt_rad".into(), tilt),
                ("height_m".into(), height),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // It toppled: its up axis turned more than 45° from vertical (past its balance
        // angle) and its top came down to the floor.
        (0..=sim.steps())
            .any(|k| up_z(sim.hazard_state(k).rotation) < std::f64::consts::FRAC_1_SQRT_2)
            && crate::label::time_to_floor(spec, sim).is_some()
    }
}
