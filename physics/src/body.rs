//! The articulated observer (specification §2 proportions): thirteen links — pelvis, torso, head,
//! two two-link arms with hands, two two-link legs — posed from a base pose, a pelvis
//! drop and two hand targets. Pure geometry, no physics: `execute` turns the poses into
//! kinematic rapier bodies.
//!
//! Body frame: origin at the pelvis, x forward, y left, z up. Proportions beyond the
//! spec's heights (pelvis, shoulder, top of head) are the G1's, rounded:
//! shoulders 0.17 m either side of the axis and 0.01 m below `shoulder_z`, upper arm
//! 0.27 m, forearm to the palm centre 0.28 m (reach 0.55 m), hips 0.09 m either side,
//! thigh and shank 0.37 m each, ankle 0.05 m above the floor.

use crate::spec::{quat, vec3, ObserverSpec, Quat, Vec3, IDENTITY};

pub const UPPER_ARM: f64 = 0.27;
pub const FOREARM: f64 = 0.28;
pub const SHOULDER_Y: f64 = 0.17;
pub const HIP_Y: f64 = 0.09;
pub const THIGH: f64 = 0.37;
pub const SHANK: f64 = 0.37;
pub const ANKLE_Z: f64 = 0.05;
/// Hands never come closer than this (centre to centre, m): two palms side by side.
pub const HAND_GAP: f64 = 0.10;
/// The hands' rest targets in the body frame (m): beside the hips, palms in.
pub const REST_LEFT: Vec3 = [0.10, 0.15, 0.0];
pub const REST_RIGHT: Vec3 = [0.10, -0.15, 0.0];
/// Surface of the body's links where nothing else sets it: the standing body of the
/// counterfactual label run (`simulate` with `observer_collider`). The executor's links
/// use `link_friction` / `link_restitution` of `[execution]`, equal to these (a unit
/// test in `execute` holds them equal).
pub const BODY_FRICTION: f64 = 1.0;
pub const BODY_RESTITUTION: f64 = 0.0;

/// The links, in the order of [`Part::ALL`] (also the order of their rapier bodies).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Part {
    Pelvis,
    Torso,
    Head,
    LeftUpperArm,
    LeftForearm,
    LeftHand,
    RightUpperArm,
    RightForearm,
    RightHand,
    LeftThigh,
    LeftShank,
    RightThigh,
    RightShank,
}

impl Part {
    pub const ALL: [Part; 13] = [
        Part::Pelvis,
        Part::Torso,
        Part::Head,
        Part::LeftUpperArm,
        Part::LeftForearm,
        Part::LeftHand,
        Part::RightUpperArm,
        Part::RightForearm,
        Part::RightHand,
        Part::LeftThigh,
        Part::LeftShank,
        Part::RightThigh,
        Part::RightShank,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Part::Pelvis => "pelvis",
            Part::Torso => "torso",
            Part::Head => "head",
            Part::LeftUpperArm => "left_upper_arm",
            Part::LeftForearm => "left_forearm",
            Part::LeftHand => "left_hand",
            Part::RightUpperArm => "right_upper_arm",
            Part::RightForearm => "right_forearm",
            Part::RightHand => "right_hand",
            Part::LeftThigh => "left_thigh",
            Part::LeftShank => "left_shank",
            Part::RightThigh => "right_thigh",
            Part::RightShank => "right_shank",
        }
    }

    /// Hands and forearms: the parts that may hold the hazard (while the plan is reaching,
    /// a touch there is no strike; see `outcome`).
    pub fn is_catching(self) -> bool {
        matches!(
            self,
            Part::LeftHand | Part::RightHand | Part::LeftForearm | Part::RightForearm
        )
    }
}

/// A link's collision shape (capsules along their local z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LinkShape {
    Box(Vec3),
    Capsule { half_height: f64, radius: f64 },
    Sphere(f64),
}

impl LinkShape {
    /// Radius of a sphere about the link's centre that holds it (m).
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            LinkShape::Box(h) => vec3::norm(h),
            LinkShape::Capsule {
                half_height,
                radius,
            } => half_height + radius,
            LinkShape::Sphere(r) => r,
        }
    }
}

/// A link's world pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkPose {
    pub position: Vec3,
    pub rotation: Quat,
}

/// The body's dimensions for one observer.
#[derive(Debug, Clone, Copy)]
pub struct Geometry {
    pub pelvis_z: f64,
    pub shoulder_z: f64,
    pub height: f64,
}

/// Where the body is at one instant: base on the floor, pelvis drop (knee bend) and both
/// hand centres in the body frame (already reachable: see [`Geometry::reachable`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPose {
    /// `(x, y, yaw)` of the pelvis on the floor.
    pub base: Vec3,
    pub drop: f64,
    pub left: Vec3,
    pub right: Vec3,
}

impl Geometry {
    pub fn of(o: &ObserverSpec) -> Geometry {
        Geometry {
            pelvis_z: o.pelvis_z,
            shoulder_z: o.shoulder_z,
            height: o.height,
        }
    }

    /// The body standing still at `base` (`(x, y, yaw)`): no knee bend, both palms at
    /// their rest position (specification §2's `(0.10, ±0.15, 0.00)`, kept clear of the torso by
    /// [`Geometry::reachable`]). The one standing body: the executor starts every plan
    /// from it (the `freeze` plan keeps it), and the counterfactual label run
    /// (`simulate` with `observer_collider`) places these links as fixed colliders.
    pub fn rest_pose(&self, base: Vec3) -> BodyPose {
        BodyPose {
            base,
            drop: 0.0,
            left: self.reachable(1.0, REST_LEFT),
            right: self.reachable(-1.0, REST_RIGHT),
        }
    }

    /// How far the standing body reaches horizontally from its vertical axis (m): the
    /// largest horizontal distance of a rest-pose link's centre plus its bounding radius.
    pub fn rest_extent(&self) -> f64 {
        let links = self.link_poses(&self.rest_pose([0.0; 3]));
        links
            .iter()
            .zip(self.shapes())
            .map(|(l, s)| l.position[0].hypot(l.position[1]) + s.bounding_radius())
            .fold(0.0, f64::max)
    }

    /// Shoulder centre in the body frame (`side` +1 left, −1 right).
    pub fn shoulder(&self, side: f64) -> Vec3 {
        [
            0.0,
            side * SHOULDER_Y,
            self.shoulder_z - self.pelvis_z - 0.01,
        ]
    }

    /// The shapes of [`Part::ALL`], in order.
    pub fn shapes(&self) -> [LinkShape; 13] {
        let torso_top = self.shoulder_z - self.pelvis_z + 0.03;
        let cap = |length: f64, radius: f64| LinkShape::Capsule {
            half_height: (length / 2.0).max(0.0),
            radius,
        };
        [
            LinkShape::Box([0.08, 0.13, 0.07]),
            LinkShape::Box([0.09, 0.14, (torso_top - 0.05) / 2.0]),
            LinkShape::Sphere(0.10),
            cap(UPPER_ARM, 0.04),
            cap(FOREARM - 0.06, 0.035),
            LinkShape::Box([0.06, 0.05, 0.015]),
            cap(UPPER_ARM, 0.04),
            cap(FOREARM - 0.06, 0.035),
            LinkShape::Box([0.06, 0.05, 0.015]),
            cap(THIGH, 0.065),
            cap(SHANK, 0.055),
            cap(THIGH, 0.065),
            cap(SHANK, 0.055),
        ]
    }

    /// Clamps a hand target (body frame) to what the arm can do: inside the shoulder's
    /// reach sphere (a little short of straight), at least 0.12 m from the shoulder, not
    /// more than 0.15 m behind the body, and in front of the torso when in its width.
    pub fn reachable(&self, side: f64, target: Vec3) -> Vec3 {
        let mut p = target;
        p[0] = p[0].max(-0.15);
        if p[1].abs() < SHOULDER_Y + 0.03 && p[2] > -0.05 && p[2] < self.torso_top() {
            p[0] = p[0].max(0.15);
        }
        let s = self.shoulder(side);
        let d = vec3::sub(p, s);
        let n = vec3::norm(d);
        let (lo, hi) = (0.12, (UPPER_ARM + FOREARM) * 0.999);
        if n < 1e-9 {
            return vec3::add(s, [lo, 0.0, 0.0]);
        }
        let r = n.clamp(lo, hi);
        vec3::add(s, vec3::scale(d, r / n))
    }

    fn torso_top(&self) -> f64 {
        self.shoulder_z - self.pelvis_z + 0.03
    }

    /// World poses of every link, in [`Part::ALL`] order.
    pub fn link_poses(&self, pose: &BodyPose) -> [LinkPose; 13] {
        let [bx, by, yaw] = pose.base;
        let yaw_q = quat::from_axis_angle([0.0, 0.0, 1.0], yaw);
        let pelvis_world = [bx, by, self.pelvis_z - pose.drop];
        let world = |p: Vec3| vec3::add(pelvis_world, quat::rotate(yaw_q, p));
        let fixed = |p: Vec3| LinkPose {
            position: world(p),
            rotation: yaw_q,
        };
        let segment = |a: Vec3, b: Vec3| LinkPose {
            position: world(vec3::scale(vec3::add(a, b), 0.5)),
            rotation: quat::mul(yaw_q, z_to(vec3::sub(b, a))),
        };
        let torso_half = (self.torso_top() - 0.05) / 2.0;
        let head_z = self.height - self.pelvis_z - 0.10;
        let mut out = [LinkPose {
            position: [0.0; 3],
            rotation: IDENTITY,
        }; 13];
        out[0] = fixed([0.0; 3]);
        out[1] = fixed([0.0, 0.0, 0.05 + torso_half]);
        out[2] = fixed([0.0, 0.0, head_z]);
        for (side, hand, base) in [(1.0, pose.left, 3), (-1.0, pose.right, 6)] {
            let s = self.shoulder(side);
            let e = elbow(s, hand, side);
            // The forearm capsule stops short of the palm centre (the palm box is there).
            let dir = unit(vec3::sub(hand, e));
            let wrist = vec3::sub(hand, vec3::scale(dir, 0.06));
            out[base] = segment(s, e);
            out[base + 1] = segment(e, wrist);
            out[base + 2] = fixed(hand);
        }
        let hip_z = -0.06;
        let ankle_z = ANKLE_Z - (self.pelvis_z - pose.drop);
        for (side, base) in [(1.0, 9), (-1.0, 11)] {
            let hip = [0.0, side * HIP_Y, hip_z];
            let ankle = [0.0, side * HIP_Y, ankle_z];
            let knee = knee(hip, ankle);
            out[base] = segment(hip, knee);
            out[base + 1] = segment(knee, ankle);
        }
        out
    }
}

fn unit(v: Vec3) -> Vec3 {
    let n = vec3::norm(v);
    if n < 1e-12 {
        [0.0, 0.0, 1.0]
    } else {
        vec3::scale(v, 1.0 / n)
    }
}

/// Rotation taking +z to the direction of `d` (shortest arc).
fn z_to(d: Vec3) -> Quat {
    let u = unit(d);
    let c = u[2];
    if c < -1.0 + 1e-12 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    // Half-way quaternion: axis z × u, angle acos(c).
    let axis = vec3::cross([0.0, 0.0, 1.0], u);
    let w = 1.0 + c;
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2] + w * w).sqrt();
    [axis[0] / n, axis[1] / n, axis[2] / n, w / n]
}

/// Elbow of a two-link arm from shoulder `s` to hand `h` (analytic IK); the elbow points
/// down and outwards (`side` +1 left, −1 right).
pub fn elbow(s: Vec3, h: Vec3, side: f64) -> Vec3 {
    two_link(s, h, UPPER_ARM, FOREARM, [0.0, 0.4 * side, -1.0])
}

/// Knee of a leg from hip to ankle; the knee points forward.
fn knee(hip: Vec3, ankle: Vec3) -> Vec3 {
    two_link(hip, ankle, THIGH, SHANK, [1.0, 0.0, 0.0])
}

/// Middle joint of a two-link chain from `a` to `b` with lengths `l1`, `l2`, bent towards
/// `pole`. The distance is clamped to what the chain can span.
pub fn two_link(a: Vec3, b: Vec3, l1: f64, l2: f64, pole: Vec3) -> Vec3 {
    let d = vec3::sub(b, a);
    let n = vec3::norm(d).clamp((l1 - l2).abs() + 1e-6, l1 + l2 - 1e-6);
    let u = unit(d);
    let x = (n * n + l1 * l1 - l2 * l2) / (2.0 * n);
    let h = (l1 * l1 - x * x).max(0.0).sqrt();
    let mut v = vec3::sub(pole, vec3::scale(u, vec3::dot(pole, u)));
    if vec3::norm(v) < 1e-9 {
        v = vec3::sub([1.0, 0.0, 0.0], vec3::scale(u, u[0]));
    }
    let v = unit(v);
    vec3::add(a, vec3::add(vec3::scale(u, x), vec3::scale(v, h)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> Geometry {
        Geometry {
            pelvis_z: 0.79,
            shoulder_z: 1.10,
            height: 1.32,
        }
    }

    #[test]
    fn ik_keeps_link_lengths_and_reaches_reachable_targets() {
        let g = geometry();
        // The rest pose's hand (x = 0.10) is inside the torso's depth: kept in front of it.
        assert_eq!(g.reachable(1.0, [0.1, 0.15, 0.0]), [0.15, 0.15, 0.0]);
        for target in [
            [0.15, 0.15, 0.0],
            [0.45, 0.1, 0.1],
            [0.3, 0.4, 0.5],
            [2.0, 0.0, 0.3],
        ] {
            let h = g.reachable(1.0, target);
            let s = g.shoulder(1.0);
            let e = elbow(s, h, 1.0);
            assert!((vec3::norm(vec3::sub(e, s)) - UPPER_ARM).abs() < 1e-9);
            assert!((vec3::norm(vec3::sub(h, e)) - FOREARM).abs() < 1e-6);
            if vec3::norm(vec3::sub(target, s)) < UPPER_ARM + FOREARM - 0.01 {
                assert!(
                    vec3::norm(vec3::sub(h, target)) < 1e-9,
                    "{target:?} -> {h:?}"
                );
            }
        }
        // Out of reach: on the reach sphere, in the target's direction.
        let h = g.reachable(1.0, [2.0, 0.17, 0.30]);
        assert!((h[0] - 0.55 * 0.999).abs() < 1e-9, "{h:?}");
    }

    #[test]
    fn rest_pose_stands_on_the_floor_and_reaches_head_height() {
        let g = geometry();
        let pose = BodyPose {
            base: [1.0, 2.0, 0.3],
            drop: 0.0,
            left: [0.1, 0.15, 0.0],
            right: [0.1, -0.15, 0.0],
        };
        let links = g.link_poses(&pose);
        assert!((links[0].position[2] - 0.79).abs() < 1e-12);
        assert!((links[2].position[2] + 0.10 - 1.32).abs() < 1e-12);
        // Hands where asked (world), shank ends at the ankle.
        let yaw_q = quat::from_axis_angle([0.0, 0.0, 1.0], 0.3);
        let want = vec3::add([1.0, 2.0, 0.79], quat::rotate(yaw_q, [0.1, 0.15, 0.0]));
        assert!(vec3::norm(vec3::sub(links[5].position, want)) < 1e-12);
        // Crouching lowers the pelvis and keeps the shanks' lower ends at the ankle.
        let low = g.link_poses(&BodyPose { drop: 0.2, ..pose });
        assert!((low[0].position[2] - 0.59).abs() < 1e-12);
        let shank = low[10];
        let tip = vec3::add(
            shank.position,
            quat::rotate(shank.rotation, [0.0, 0.0, SHANK / 2.0]),
        );
        assert!((tip[2] - ANKLE_Z).abs() < 1e-6, "{tip:?}");
    }
}
