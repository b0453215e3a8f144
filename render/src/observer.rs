//! The observer's mesh: a humanoid with Unitree-G1 proportions.

use super::mesh::*;
use rh_physics::body::{LinkShape, Part};

/// The observer: a humanoid with Unitree-G1 proportions (height 1.32 m, pelvis 0.79 m,
/// shoulders 1.10 m), in its body frame (x forward, y left, z up, origin on the floor).
/// Returns (body, head).
pub(super) fn observer_mesh(height: f64, pelvis: f64, shoulder: f64) -> (Mesh, Mesh) {
    let (h, pz, sz) = (height as f32, pelvis as f32, shoulder as f32);
    let shell = hex("#c9cdd2");
    let dark = hex("#2b2f33");
    let accent = hex("#ff6f00");
    let mut m = Mesh::new();
    let id = Xf::ID;
    for sy in [-1.0f32, 1.0] {
        let y = sy * 0.1;
        m.boxy(
            &Xf::at([0.03, y, 0.03]),
            [0.1, 0.045, 0.03],
            1,
            &solid(dark),
        );
        m.rod(
            &id,
            [0.0, y, 0.08],
            [0.0, y, pz * 0.52],
            0.05,
            12,
            &solid(shell),
        );
        m.sphere(&Xf::at([0.0, y, pz * 0.54]), 0.055, 12, &solid(dark));
        m.rod(
            &id,
            [0.0, y, pz * 0.57],
            [0.0, y * 0.95, pz - 0.05],
            0.062,
            12,
            &solid(shell),
        );
        // Arms: shoulder → elbow → hand at rest (≈ pelvis height, 0.1 m forward).
        let shoulder_p = [0.0, sy * 0.2, sz - 0.02];
        let elbow = [-0.02, sy * 0.21, sz - 0.24];
        let hand = [0.11, sy * 0.17, pz + 0.02];
        m.sphere(&Xf::at(shoulder_p), 0.055, 12, &solid(dark));
        m.rod(&id, shoulder_p, elbow, 0.04, 10, &solid(shell));
        m.sphere(&Xf::at(elbow), 0.042, 10, &solid(dark));
        m.rod(&id, elbow, hand, 0.035, 10, &solid(shell));
        m.boxy(
            &Xf::at([hand[0] + 0.03, hand[1], hand[2] - 0.02]),
            [0.035, 0.02, 0.045],
            1,
            &solid(dark),
        );
    }
    m.boxy(&Xf::at([0.0, 0.0, pz]), [0.08, 0.14, 0.07], 1, &solid(dark));
    m.cylinder(
        &Xf::at([0.0, 0.0, pz + 0.09]),
        0.085,
        0.035,
        16,
        &solid(dark),
    );
    let torso_mid = (pz + 0.12 + sz + 0.02) / 2.0;
    let torso_half = (sz + 0.02 - pz - 0.12) / 2.0;
    let chest = move |p: V3| {
        if p[0] > 0.09 && (p[2] - torso_half * 0.3).abs() < 0.015 {
            accent
        } else {
            shell
        }
    };
    m.boxy(
        &Xf::at([0.0, 0.0, torso_mid]),
        [0.1, 0.15, torso_half],
        4,
        &chest,
    );
    m.cylinder(
        &Xf::at([0.0, 0.0, sz + 0.05]),
        0.035,
        0.04,
        10,
        &solid(dark),
    );
    let mut head = Mesh::new();
    let head_z = h - 0.075;
    head.ellipsoid(
        &Xf::at([0.0, 0.0, head_z]),
        [0.075, 0.07, 0.075],
        20,
        &solid(shell),
    );
    head.ellipsoid(
        &Xf::at([0.035, 0.0, head_z + 0.005]),
        [0.05, 0.06, 0.035],
        16,
        &solid(mat(hex("#101418"), MAT_GLOSSY)),
    );
    (m, head)
}

/// The executing humanoid (`execute::humanoid`): one mesh per link, in
/// `humanoid::Part::ALL` order, each in its link's frame (capsules along z) with the
/// shape the physics uses; coloured like the observer, the palms in its accent colour.
pub(super) fn link_meshes(shapes: &[LinkShape; 13]) -> Vec<Mesh> {
    let shell = hex("#c9cdd2");
    let dark = hex("#2b2f33");
    let accent = hex("#ff6f00");
    shapes
        .iter()
        .zip(Part::ALL)
        .map(|(shape, part)| {
            let c = match part {
                Part::Pelvis | Part::LeftShank | Part::RightShank => dark,
                Part::LeftHand | Part::RightHand => accent,
                _ => shell,
            };
            let mut m = Mesh::new();
            match *shape {
                LinkShape::Box(h) => m.boxy(&Xf::ID, h.map(|v| v as f32), 1, &solid(c)),
                LinkShape::Capsule {
                    half_height,
                    radius,
                } => m.capsule(&Xf::ID, radius as f32, half_height as f32, 12, &solid(c)),
                LinkShape::Sphere(r) => m.sphere(&Xf::ID, r as f32, 16, &solid(c)),
            }
            m
        })
        .collect()
}
