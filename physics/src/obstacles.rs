//! Line-of-sight queries against a scene's fixed bodies (and the observer's sight
//! envelope), for camera framing and the visibility validator.

use crate::shapes::{posed_parts, rot, v3};
use crate::spec::{BodyKind, ObserverSpec, PartSpec, Quat, SceneSpec, Vec3};
use rapier3d::prelude::*;

/// The spec's fixed bodies (furniture, walls, stairs) as world-posed shapes, for line-of-
/// sight queries: `Obstacles::blocks` says whether a segment passes through any of them.
#[derive(Clone)]
pub struct Obstacles {
    parts: Vec<(Pose, SharedShape)>,
}

impl Obstacles {
    /// The spec's fixed bodies but its decor: decor is placed clear of every camera's
    /// sight line to the hazard (`rh_scenes::decor`), so it never blocks these queries.
    pub fn of(spec: &SceneSpec) -> Obstacles {
        let parts = spec
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Fixed && b.role != crate::spec::BodyRole::Decor)
            .flat_map(|b| {
                let body_pose = Pose::from_parts(v3(b.position), rot(b.rotation));
                posed_parts(&b.parts)
                    .into_iter()
                    .map(move |(pose, shape)| (body_pose * pose, shape))
            })
            .collect();
        Obstacles { parts }
    }

    /// Adds the observer's collision capsule (see `observer_capsule`), its radius widened
    /// by `inflate` (m), as one more obstacle.
    pub fn with_observer(mut self, observer: &ObserverSpec, inflate: f64) -> Obstacles {
        let (centre, half, radius) = observer_capsule(observer, inflate);
        self.parts.push((
            Pose::from_parts(centre, Rotation::IDENTITY),
            SharedShape::capsule_z(half, radius),
        ));
        self
    }

    /// No shapes (add bodies with [`Obstacles::with_body`]).
    pub fn none() -> Obstacles {
        Obstacles { parts: Vec::new() }
    }

    /// These obstacles and a body's `parts` posed at `position`, `rotation` (a moving body
    /// at one step: a hazard to cast rays at, or a prop in the way).
    pub fn with_body(mut self, parts: &[PartSpec], position: Vec3, rotation: Quat) -> Obstacles {
        let body_pose = Pose::from_parts(v3(position), rot(rotation));
        self.parts.extend(
            posed_parts(parts)
                .into_iter()
                .map(|(pose, shape)| (body_pose * pose, shape)),
        );
        self
    }

    /// The distance along the ray from `origin` in the unit direction `dir` to the first
    /// shape it meets within `max`, if any.
    pub fn first_hit(&self, origin: Vec3, dir: Vec3, max: f64) -> Option<f64> {
        let ray = rapier3d::parry::query::Ray::new(v3(origin), v3(dir));
        self.parts
            .iter()
            .filter_map(|(pose, shape)| shape.cast_ray(pose, &ray, max as Real, true))
            .reduce(Real::min)
            .map(f64::from)
    }

    /// Whether `p` lies inside one of the obstacles.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.parts
            .iter()
            .any(|(pose, shape)| shape.contains_point(pose, v3(p)))
    }

    /// Whether the straight segment from `a` to `b` passes through a fixed body.
    pub fn blocks(&self, a: [f64; 3], b: [f64; 3]) -> bool {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if length < 1e-9 {
            return false;
        }
        let ray = rapier3d::parry::query::Ray::new(v3(a), v3(d.map(|c| c / length)));
        self.parts
            .iter()
            .any(|(pose, shape)| shape.cast_ray(pose, &ray, length as Real, true).is_some())
    }
}

/// The observer's *sight envelope* for line-of-sight queries (the visibility validator):
/// a vertical capsule of the torso radius from the floor to the top of the head, as
/// (centre, half height of the segment, radius), `inflate` widening the radius to cover
/// the drawn mesh's limbs. It answers "could the drawn observer hide the hazard from a
/// camera", not "does the hazard hit the body": the body that is struck is
/// [`crate::simulate::observer_links`] (the humanoid of `execute::humanoid`).
fn observer_capsule(o: &ObserverSpec, inflate: f64) -> (Vector, Real, Real) {
    let radius = o.torso_radius as Real;
    let half = ((o.height as Real) / 2.0 - radius).max(0.0);
    let centre = Vector::new(o.x as Real, o.y as Real, (o.height / 2.0) as Real);
    (centre, half, radius + inflate as Real)
}
