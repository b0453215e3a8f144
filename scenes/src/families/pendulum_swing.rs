//! pendulum_swing: a suspended mass (chandelier, punching bag, lamp) swings in (specification §4).
//!
//! The object hangs from a ceiling anchor on a real spherical joint: a rigid, massless
//! suspension rod from the anchor to the top of the object (a physical pendulum). It
//! starts hanging straight down and moving: the band's value is the speed of its centre
//! of mass through the lowest point (amplitude follows from it: `v² = 2 g d (1 − cos θ)`),
//! with the matching spin about the anchor.
//!
//! Timing (label rule v2): it starts swinging *away* from the observer, who stands just
//! beyond its reach on the other side, so it comes back through the lowest point (with
//! the band's speed again, toward the observer) only after half a period — over a second
//! for any arm of 1 m or more — and the decision moment Δ falls near the far end of the
//! first swing, before the return that decides the outcome.

use super::*;

pub struct PendulumSwing;

impl Family for PendulumSwing {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "pendulum_swing",
            speed_parameter: "swing_speed_mps",
            speed_sweep: true,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let room = input.room;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let com_height = uniform(rng, 1.0, 1.45);
        let yaw = uniform(rng, 0.0, std::f64::consts::TAU);
        // Centred between the far end of the first swing (behind) and the observer.
        let origin = event_origin(rng, room, dir, 0.1 + far_shift(input));

        let com = com_offset(object);
        let top = top_offset(object);
        let ceiling = room.ceiling_height;
        // At least 25 cm of suspension between the ceiling and the object's top.
        let z = (com_height - com[2]).min(ceiling - 0.25 - top);
        let rod = ceiling - (z + top);
        let anchor = [origin[0], origin[1], ceiling];
        let com_world = [origin[0], origin[1], z + com[2]];
        let arm = ceiling - com_world[2];
        // Swing about the horizontal axis ŝ = ẑ × dir: ω = +(v/d) ŝ moves the mass along
        // −dir, away from the observer.
        let s = left_of(dir);
        let omega = [s[0], s[1], 0.0].map(|c| c * input.speed / arm);
        let linvel = velocity_about(omega, anchor, com_world);
        let hazard = hazard_body(
            object,
            [origin[0], origin[1], z],
            yaw_quat(yaw),
            linvel,
            omega,
        );
        // The observer stands clear of the hanging object's side (its horizontal radius
        // plus the torso's, plus a gap), so nothing touches them before it swings back.
        let he = object.half_extents();
        let radius = he[0].hypot(he[1]);
        let near = radius + 0.18;
        let observer = observer_beyond(
            rng,
            origin,
            dir,
            (near + 0.1, near + 0.6),
            (2.5, 2.9),
            0.25,
            input.far_observer,
            origin,
        );
        Layout {
            bodies: vec![hazard],
            joints: vec![JointSpec {
                kind: JointKind::Spherical,
                body_a: None,
                body_b: 0,
                anchor_a: anchor,
                anchor_b: [0.0, 0.0, top + rod],
            }],
            hazard: 0,
            source_support: None,
            observer,
            params: BTreeMap::from([
                ("pivot_to_com_m".into(), arm),
                ("rod_length_m".into(), rod),
                ("anchor_height_m".into(), ceiling),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // It swung: the arm turned at least 0.1 rad from vertical and the mass travelled
        // at least 0.2 m sideways.
        let Some(joint) = spec.joints.first() else {
            return false;
        };
        let a = joint.anchor_a;
        let start = sim.hazard_position(0);
        (0..=sim.steps()).any(|k| {
            let p = sim.hazard_position(k);
            let horizontal = ((p[0] - a[0]).powi(2) + (p[1] - a[1]).powi(2)).sqrt();
            horizontal.atan2(a[2] - p[2]) >= 0.1
        }) && (0..=sim.steps()).any(|k| {
            let p = sim.hazard_position(k);
            ((p[0] - start[0]).powi(2) + (p[1] - start[1]).powi(2)).sqrt() >= 0.2
        })
    }
}
