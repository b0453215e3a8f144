//! Quadratic air drag (label rule v6, [`DragSpec`]): `F = -½ ρ C_d A(v̂) |v| v` through
//! the centre of mass of every large light body, set before every physics step. `A(v̂)`
//! is the body's area projected along its velocity, summed over its parts (exact for one
//! convex part; overlapping parts count twice). Deterministic: a pure function of the
//! body's state, in spec order.

use crate::shapes::rot;
use crate::spec::{BodyKind, BodySpec, DragSpec, PartSpec, ShapeSpec};
use rapier3d::prelude::*;

/// Area of one part projected along the unit direction `d` given in the part's frame.
fn part_area(shape: &ShapeSpec, d: [f64; 3]) -> f64 {
    let lateral = (1.0 - d[2] * d[2]).max(0.0).sqrt();
    match *shape {
        ShapeSpec::Box { half_extents: h } => {
            4.0 * (h[1] * h[2] * d[0].abs() + h[0] * h[2] * d[1].abs() + h[0] * h[1] * d[2].abs())
        }
        ShapeSpec::Sphere { radius } => std::f64::consts::PI * radius * radius,
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => {
            std::f64::consts::PI * radius * radius * d[2].abs()
                + 4.0 * radius * half_height * lateral
        }
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => std::f64::consts::PI * radius * radius + 4.0 * radius * half_height * lateral,
    }
}

fn coefficient(shape: &ShapeSpec, drag: &DragSpec) -> f64 {
    match shape {
        ShapeSpec::Sphere { .. } | ShapeSpec::Capsule { .. } => drag.sphere_coefficient,
        ShapeSpec::Box { .. } | ShapeSpec::Cylinder { .. } => drag.flat_coefficient,
    }
}

/// `C_d A` of a body's parts along the unit direction `d` in the body's frame (m²).
pub fn drag_area(parts: &[PartSpec], d: [f64; 3], drag: &DragSpec) -> f64 {
    parts
        .iter()
        .map(|p| {
            let local =
                rot(p.rotation).inverse() * Vector::new(d[0] as Real, d[1] as Real, d[2] as Real);
            let local = [local.x as f64, local.y as f64, local.z as f64];
            coefficient(&p.shape, drag) * part_area(&p.shape, local)
        })
        .sum()
}

/// The largest `C_d A` of a body along its frame's axes and diagonals (m²).
fn drag_area_max(parts: &[PartSpec], drag: &DragSpec) -> f64 {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let r = 1.0 / 3f64.sqrt();
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [s, s, 0.0],
        [s, 0.0, s],
        [0.0, s, s],
        [r, r, r],
    ]
    .into_iter()
    .map(|d| drag_area(parts, d, drag))
    .fold(0.0, f64::max)
}

/// Whether the drag acts on `body`: dynamic, and its terminal speed with its largest
/// projected area is below `terminal_speed_max`.
pub fn feels_drag(body: &BodySpec, drag: &DragSpec, gravity: f64) -> bool {
    if body.kind != BodyKind::Dynamic || body.mass <= 0.0 || drag.air_density <= 0.0 {
        return false;
    }
    let k = 0.5 * drag.air_density * drag_area_max(&body.parts, drag);
    k > 0.0 && (body.mass * gravity / k).sqrt() < drag.terminal_speed_max
}

/// Sets the drag force on the rigid body `rb` shaped as `parts` for the coming step
/// (replacing the last step's).
pub fn apply(rb: &mut RigidBody, parts: &[PartSpec], drag: &DragSpec) {
    rb.reset_forces(false);
    let v = rb.linvel();
    let speed = v.length();
    if speed <= 0.0 {
        return;
    }
    let local = rb.rotation().inverse() * (v / speed);
    let ca = drag_area(
        parts,
        [local.x as f64, local.y as f64, local.z as f64],
        drag,
    );
    let magnitude = 0.5 * drag.air_density * ca * (speed as f64) * (speed as f64);
    rb.add_force(-v / speed * magnitude as Real, false);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::IDENTITY;

    fn part(shape: ShapeSpec) -> PartSpec {
        PartSpec {
            shape,
            offset: [0.0; 3],
            rotation: IDENTITY,
        }
    }

    #[test]
    fn projected_areas_are_the_shapes_shadows() {
        let panel = ShapeSpec::Box {
            half_extents: [0.3, 0.3, 0.01],
        };
        assert!((part_area(&panel, [0.0, 0.0, 1.0]) - 0.36).abs() < 1e-12);
        assert!((part_area(&panel, [1.0, 0.0, 0.0]) - 0.012).abs() < 1e-12);
        let ball = ShapeSpec::Sphere { radius: 0.1 };
        assert!((part_area(&ball, [0.6, 0.0, 0.8]) - 0.01 * std::f64::consts::PI).abs() < 1e-12);
        let can = ShapeSpec::Cylinder {
            half_height: 0.1,
            radius: 0.05,
        };
        assert!((part_area(&can, [1.0, 0.0, 0.0]) - 0.02).abs() < 1e-12);
    }

    #[test]
    fn only_large_light_bodies_feel_drag() {
        let drag = DragSpec {
            air_density: 1.2,
            sphere_coefficient: 0.47,
            flat_coefficient: 1.1,
            terminal_speed_max: 15.0,
        };
        let body = |mass: f64, shape: ShapeSpec| BodySpec {
            name: "b".into(),
            role: crate::spec::BodyRole::Hazard,
            kind: BodyKind::Dynamic,
            catalog_id: None,
            parts: vec![part(shape)],
            position: [0.0; 3],
            rotation: IDENTITY,
            mass,
            friction: 0.5,
            restitution: 0.1,
            linvel: [0.0; 3],
            angvel: [0.0; 3],
            ccd: false,
            push_mass: None,
        };
        let panel = ShapeSpec::Box {
            half_extents: [0.3, 0.3, 0.01],
        };
        // A 0.2 kg foam panel (terminal speed ~2.8 m/s) does; a 4 kg gypsum one (~12.6 m/s)
        // too; an apple (0.21 kg, 8 cm: ~37 m/s) does not.
        assert!(feels_drag(&body(0.2, panel), &drag, 9.81));
        assert!(!feels_drag(&body(60.0, panel), &drag, 9.81));
        assert!(!feels_drag(
            &body(0.21, ShapeSpec::Sphere { radius: 0.04 }),
            &drag,
            9.81
        ));
    }
}
