//! The world a spec builds for stepping (`build_world`): the floor, every body and joint
//! in spec order — the one place the physics setup lives (`simulate` and `execute` both
//! start from it, so a replay cannot drift from the build) — and its forks
//! (`fork_world`), the copies that later runs step on.

use crate::shapes::{collider_for, rot, v3};
use crate::spec::{BodyKind, DragSpec, JointKind, PartSpec, SceneSpec};
use rapier3d::prelude::*;

const FLOOR_HALF_EXTENT: Real = 50.0;
const FLOOR_HALF_THICKNESS: Real = 0.5;

/// A spec's world as built for stepping: the floor, every body and joint, in spec
/// order — the one place the physics setup lives (`simulate` and `execute` both start
/// from it, so a replay cannot drift from the build).
pub struct SceneWorld {
    pub world: PhysicsWorld,
    pub floor: ColliderHandle,
    /// Per spec body.
    pub body_handles: Vec<RigidBodyHandle>,
    /// Per spec body.
    pub collider_handles: Vec<ColliderHandle>,
    /// Spec indices of the dynamic bodies, in spec order (the hashed state's order).
    pub dynamic_bodies: Vec<usize>,
    /// The bodies air drag acts on, in spec order, with their parts (`drag`).
    pub drag_bodies: Vec<(RigidBodyHandle, Vec<PartSpec>)>,
    pub drag: Option<DragSpec>,
}

impl SceneWorld {
    /// One physics step: the drag forces of this step set, then the solver.
    pub fn step(&mut self) {
        if let Some(drag) = &self.drag {
            for (h, parts) in &self.drag_bodies {
                crate::drag::apply(&mut self.world.bodies[*h], parts, drag);
            }
        }
        self.world.step();
    }
}

/// Builds the spec's world at t0 (no observer). Pure in `spec`.
pub fn build_world(spec: &SceneSpec) -> SceneWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = v3(spec.physics.gravity);
    world.integration_parameters.dt = spec.physics.dt as Real;
    world.integration_parameters.num_solver_iterations = spec.physics.solver_iterations.max(1);

    let floor = world
        .insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, 0.0, -FLOOR_HALF_THICKNESS)),
            ColliderBuilder::cuboid(FLOOR_HALF_EXTENT, FLOOR_HALF_EXTENT, FLOOR_HALF_THICKNESS)
                .friction(spec.room.floor_friction as Real)
                .restitution(spec.room.floor_restitution as Real)
                .friction_combine_rule(CoefficientCombineRule::Average)
                .restitution_combine_rule(CoefficientCombineRule::Average),
        )
        .1;

    let (body_handles, collider_handles) = insert_bodies(&mut world, spec);

    insert_joints(&mut world, spec, &body_handles);
    let dynamic_bodies: Vec<usize> = (0..spec.bodies.len())
        .filter(|&i| spec.bodies[i].kind == BodyKind::Dynamic)
        .collect();
    let drag = spec.physics.drag;
    let gravity = spec.physics.gravity[2].abs();
    let drag_bodies = drag.map_or_else(Vec::new, |d| {
        (0..spec.bodies.len())
            .filter(|&i| crate::drag::feels_drag(&spec.bodies[i], &d, gravity))
            .map(|i| (body_handles[i], spec.bodies[i].parts.clone()))
            .collect()
    });
    SceneWorld {
        world,
        floor,
        body_handles,
        collider_handles,
        dynamic_bodies,
        drag_bodies,
        drag,
    }
}

/// A world ready to step from: `sw`'s state (bodies, colliders, joints, broad and
/// narrow phase, islands, CCD) cloned into a fresh solver workspace, as `execute` forks
/// the world at Δ for every plan.
pub fn fork_world(sw: &SceneWorld) -> SceneWorld {
    SceneWorld {
        world: fork_physics(&sw.world),
        floor: sw.floor,
        body_handles: sw.body_handles.clone(),
        collider_handles: sw.collider_handles.clone(),
        dynamic_bodies: sw.dynamic_bodies.clone(),
        drag_bodies: sw.drag_bodies.clone(),
        drag: sw.drag,
    }
}

fn fork_physics(w: &PhysicsWorld) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = w.gravity;
    world.integration_parameters = w.integration_parameters;
    world.islands = w.islands.clone();
    world.broad_phase = w.broad_phase.clone();
    world.narrow_phase = w.narrow_phase.clone();
    world.bodies = w.bodies.clone();
    world.colliders = w.colliders.clone();
    world.impulse_joints = w.impulse_joints.clone();
    world.multibody_joints = w.multibody_joints.clone();
    world.soft_bodies = w.soft_bodies.clone();
    world.ccd_solver = w.ccd_solver.clone();
    world
}

/// Inserts every body of the spec with its collider, in spec order.
fn insert_bodies(
    world: &mut PhysicsWorld,
    spec: &SceneSpec,
) -> (Vec<RigidBodyHandle>, Vec<ColliderHandle>) {
    let mut body_handles = Vec::with_capacity(spec.bodies.len());
    let mut collider_handles = Vec::with_capacity(spec.bodies.len());
    for b in &spec.bodies {
        // A push gives a body of another mass these velocities (`BodySpec::push_mass`).
        let scale = b.push_scale();
        let scaled = |v: [f64; 3]| {
            if scale == 1.0 {
                v
            } else {
                v.map(|c| c * scale)
            }
        };
        let builder = match b.kind {
            BodyKind::Fixed => RigidBodyBuilder::fixed(),
            BodyKind::Dynamic => RigidBodyBuilder::dynamic()
                .linvel(v3(scaled(b.linvel)))
                .angvel(v3(scaled(b.angvel)))
                .ccd_enabled(b.ccd)
                // Never frozen by the sleep heuristic (an object balanced on an edge must
                // tip); `simulate` stops by its own settle rule instead.
                .can_sleep(false),
        }
        .pose(Pose::from_parts(v3(b.position), rot(b.rotation)));
        if b.parts.is_empty() {
            // Drawn only (a window, a door in the wall plane: decor without a collider).
            body_handles.push(world.bodies.insert(builder));
            collider_handles.push(ColliderHandle::invalid());
            continue;
        }
        let mut collider = collider_for(&b.parts)
            .friction(b.friction as Real)
            .restitution(b.restitution as Real)
            .friction_combine_rule(CoefficientCombineRule::Average)
            .restitution_combine_rule(CoefficientCombineRule::Average);
        if b.kind == BodyKind::Dynamic {
            collider = collider.mass(b.mass as Real);
        }
        let (bh, ch) = world.insert(builder, collider);
        body_handles.push(bh);
        collider_handles.push(ch);
    }
    (body_handles, collider_handles)
}

/// Inserts the spec's joints, in spec order; a world anchor is a fixed body at the origin.
fn insert_joints(world: &mut PhysicsWorld, spec: &SceneSpec, body_handles: &[RigidBodyHandle]) {
    let mut world_anchor = None;
    for j in &spec.joints {
        let a = match j.body_a {
            Some(i) => body_handles[i],
            None => {
                *world_anchor.get_or_insert_with(|| world.bodies.insert(RigidBodyBuilder::fixed()))
            }
        };
        let b = body_handles[j.body_b];
        let joint: GenericJoint = match &j.kind {
            JointKind::Revolute { axis } => RevoluteJointBuilder::new(v3(*axis).normalize())
                .local_anchor1(v3(j.anchor_a))
                .local_anchor2(v3(j.anchor_b))
                .into(),
            JointKind::Spherical => SphericalJointBuilder::new()
                .local_anchor1(v3(j.anchor_a))
                .local_anchor2(v3(j.anchor_b))
                .into(),
            JointKind::Rope { max_length } => RopeJointBuilder::new(*max_length as Real)
                .local_anchor1(v3(j.anchor_a))
                .local_anchor2(v3(j.anchor_b))
                .into(),
        };
        world.impulse_joints.insert(a, b, joint, true);
    }
}
