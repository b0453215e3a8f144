//! The spec's shapes and the humanoid's links as rapier shapes: the one conversion from
//! plain spec numbers (f64, z up) to the solver's types, for the simulated world, the
//! executor's body and the line-of-sight obstacles.

use crate::body::LinkShape;
use crate::spec::{PartSpec, ShapeSpec};
use rapier3d::prelude::*;

pub(crate) fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0] as Real, a[1] as Real, a[2] as Real)
}

pub(crate) fn rot(q: [f64; 4]) -> Rotation {
    Rotation::from_xyzw(q[0] as Real, q[1] as Real, q[2] as Real, q[3] as Real).normalize()
}

fn shared_shape(shape: &ShapeSpec) -> SharedShape {
    match *shape {
        ShapeSpec::Box { half_extents: h } => {
            SharedShape::cuboid(h[0] as Real, h[1] as Real, h[2] as Real)
        }
        ShapeSpec::Sphere { radius } => SharedShape::ball(radius as Real),
        // rapier's cylinders and capsules are along local y; the spec's are along z.
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => SharedShape::cylinder(half_height as Real, radius as Real),
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => SharedShape::capsule_y(half_height as Real, radius as Real),
    }
}

/// Extra rotation taking a y-axis primitive to the spec's z axis.
fn axis_fix(shape: &ShapeSpec) -> Rotation {
    match shape {
        ShapeSpec::Cylinder { .. } | ShapeSpec::Capsule { .. } => {
            Rotation::from_axis_angle(Vector::X, std::f32::consts::FRAC_PI_2 as Real)
        }
        _ => Rotation::IDENTITY,
    }
}

/// A body's parts as (pose in the body frame, shape) pairs.
pub(crate) fn posed_parts(parts: &[PartSpec]) -> Vec<(Pose, SharedShape)> {
    parts
        .iter()
        .map(|p| {
            let pose = Pose::from_parts(v3(p.offset), rot(p.rotation) * axis_fix(&p.shape));
            (pose, shared_shape(&p.shape))
        })
        .collect()
}

pub(crate) fn collider_for(parts: &[PartSpec]) -> ColliderBuilder {
    let posed = posed_parts(parts);
    if posed.len() == 1 {
        let (pose, shape) = posed.into_iter().next().expect("one part");
        ColliderBuilder::new(shape).position(pose)
    } else {
        ColliderBuilder::compound(posed)
    }
}

/// The collision shape of one of the humanoid's links (the label's standing body and the
/// executor's moving one alike).
pub fn link_shape(shape: LinkShape) -> SharedShape {
    match shape {
        LinkShape::Box(h) => SharedShape::cuboid(h[0] as Real, h[1] as Real, h[2] as Real),
        LinkShape::Capsule {
            half_height,
            radius,
        } => SharedShape::capsule_z(half_height as Real, radius as Real),
        LinkShape::Sphere(r) => SharedShape::ball(r as Real),
    }
}
