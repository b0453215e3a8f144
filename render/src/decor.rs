//! What furnishes a room and what holds the event's scenery up, drawn: decor pieces
//! (role `decor`, their catalog parts in their colours and finishes), and render-only
//! details that make a scene physically legible — brackets and wall rails under a
//! shelf, a hook and wire above whatever hangs on a wall, the grid a ceiling panel sits
//! in, and a lit (glowing) burner under a hot object standing on a surface. None of it
//! is in physics; decor bodies are (`rh_scenes::decor`).

use crate::mesh::{hex, mat, solid, Mesh, Xf, MAT_EMISSIVE, MAT_GLOSSY, MAT_PLAIN};
use rh_catalog::decor::Finish;
use rh_catalog::{Catalog, ShapeKind};
use rh_physics::spec::{quat, BodyRole, BodySpec, SceneSpec, ShapeSpec};

/// A decor body's look: every part of its catalog piece (drawn-only ones too) in the
/// piece's frame; `None` for a body that is not decor or names no piece.
pub(super) fn decor_mesh(catalog: &Catalog, body: &BodySpec) -> Option<Mesh> {
    if body.role != BodyRole::Decor {
        return None;
    }
    let piece = catalog.decor.piece(body.catalog_id.as_deref()?)?;
    let mut m = Mesh::new();
    for p in &piece.parts {
        let code = match p.finish {
            Finish::Matte => MAT_PLAIN,
            Finish::Glossy => MAT_GLOSSY,
            Finish::Glow => MAT_EMISSIVE,
        };
        let paint = solid(mat(hex(&p.color), code));
        let xf = Xf::at(p.offset.map(|v| v as f32));
        let s = |i: usize| p.size[i] as f32;
        match p.shape {
            ShapeKind::Box => m.boxy(&xf, [s(0) / 2.0, s(1) / 2.0, s(2) / 2.0], 1, &paint),
            ShapeKind::Sphere => m.sphere(&xf, s(0) / 2.0, 16, &paint),
            ShapeKind::Cylinder => m.cylinder(&xf, s(0) / 2.0, s(1) / 2.0, 20, &paint),
            ShapeKind::Capsule => {
                m.capsule(&xf, s(0) / 2.0, (s(1) - s(0)).max(0.0) / 2.0, 12, &paint)
            }
        }
    }
    Some(m)
}

/// The half extents of a body's first part if it is a box.
fn box_half(body: &BodySpec) -> Option<[f64; 3]> {
    match body.parts.first()?.shape {
        ShapeSpec::Box { half_extents } => Some(half_extents),
        _ => None,
    }
}

/// Render-only scenery of a spec, in world coordinates.
pub(super) fn scenery(spec: &SceneSpec) -> Mesh {
    let mut m = Mesh::new();
    for body in spec.bodies.iter().filter(|b| b.role == BodyRole::Support) {
        if body.name == "shelf" {
            shelf_brackets(&mut m, spec, body);
        } else if body.name.starts_with("mount_") && !body.name.contains("rod") {
            ceiling_grid(&mut m, spec);
        }
    }
    if spec.family == "hanging_fall" {
        wall_hook(&mut m, spec);
    }
    if spec.hazard_flags.iter().any(|f| f == "hot") {
        hot_plate(&mut m, spec);
    }
    m
}

/// Two wall rails from the floor past a free-standing shelf's back edge (the edge away
/// from the observer) and a bracket under the shelf on each: the shelf is held up.
fn shelf_brackets(m: &mut Mesh, spec: &SceneSpec, body: &BodySpec) {
    let Some(h) = box_half(body) else {
        return;
    };
    let c = body.position;
    let o = &spec.observer;
    // The shelf's local x and y in the world; its back is the side facing away from the
    // observer.
    let ax = quat::rotate(body.rotation, [1.0, 0.0, 0.0]);
    let ay = quat::rotate(body.rotation, [0.0, 1.0, 0.0]);
    let to_obs = [o.x - c[0], o.y - c[1]];
    let dot = |a: [f64; 3]| a[0] * to_obs[0] + a[1] * to_obs[1];
    let (along, across, half_along, half_across) = if dot(ax).abs() > dot(ay).abs() {
        (ay, ax, h[1], h[0])
    } else {
        (ax, ay, h[0], h[1])
    };
    let back = if dot(across) > 0.0 { -1.0 } else { 1.0 };
    let steel = solid(mat(hex("#5f646b"), MAT_GLOSSY));
    let top = c[2] - h[2];
    for side in [-0.7, 0.7] {
        let p = |d_across: f64, z: f64| {
            [
                (c[0] + along[0] * side * half_along + across[0] * back * d_across) as f32,
                (c[1] + along[1] * side * half_along + across[1] * back * d_across) as f32,
                z as f32,
            ]
        };
        let rail = half_across + 0.015;
        m.rod(&Xf::ID, p(rail, 0.0), p(rail, top + 0.35), 0.014, 8, &steel);
        m.rod(
            &Xf::ID,
            p(rail, top - 0.22),
            p(-half_across * 0.6, top - 0.01),
            0.01,
            6,
            &steel,
        );
        m.rod(
            &Xf::ID,
            p(rail, top - 0.01),
            p(-half_across * 0.9, top - 0.01),
            0.01,
            6,
            &steel,
        );
    }
}

/// The T-bar grid a ceiling panel sits in: a dark frame just below the ceiling around
/// the hazard's footprint at t0, so the panel reads apart from the ceiling.
fn ceiling_grid(m: &mut Mesh, spec: &SceneSpec) {
    let hazard = &spec.bodies[spec.hazard];
    let Some(h) = box_half(hazard) else {
        return;
    };
    let z = (spec.room.ceiling_height - 0.006) as f32;
    let frame = solid(mat(hex("#6d6a64"), MAT_PLAIN));
    let (hx, hy) = (h[0] as f32 + 0.02, h[1] as f32 + 0.02);
    let c = hazard.position.map(|v| v as f32);
    let (yaw_s, yaw_c) = {
        let v = quat::rotate(hazard.rotation, [1.0, 0.0, 0.0]);
        let n = v[0].hypot(v[1]).max(1e-9);
        ((v[1] / n) as f32, (v[0] / n) as f32)
    };
    let xf = Xf::rot(2, yaw_s.atan2(yaw_c), [c[0], c[1], z]);
    for (dx, dy, lx, ly) in [
        (hx, 0.0, 0.02, hy + 0.02),
        (-hx, 0.0, 0.02, hy + 0.02),
        (0.0, hy, hx + 0.02, 0.02),
        (0.0, -hy, hx + 0.02, 0.02),
    ] {
        m.boxy(&xf.then(&Xf::at([dx, dy, 0.0])), [lx, ly, 0.006], 1, &frame);
    }
}

/// A hook in the wall above what hangs there, and the wire from it to the object's top
/// corners at t0.
fn wall_hook(m: &mut Mesh, spec: &SceneSpec) {
    let hazard = &spec.bodies[spec.hazard];
    let Some(wall) = spec.bodies.iter().find(|b| b.name == "wall") else {
        return;
    };
    let h = hazard.bounding_radius();
    let top_local = box_half(hazard).map_or(h, |e| e[2]);
    let top = quat::rotate(hazard.rotation, [0.0, 0.0, top_local]);
    let p = hazard.position;
    let t = [p[0] + top[0], p[1] + top[1], p[2] + top[2]];
    // The hook sits on the wall's face nearest the hazard, 12 cm above its top.
    let w = wall.position;
    let (dx, dy) = (t[0] - w[0], t[1] - w[1]);
    let wh = box_half(wall).unwrap_or([0.05; 3]);
    let toward = quat::rotate(wall.rotation, [1.0, 0.0, 0.0]);
    let thin_x = wh[0] <= wh[1];
    let n = if thin_x {
        toward
    } else {
        quat::rotate(wall.rotation, [0.0, 1.0, 0.0])
    };
    let face = if thin_x { wh[0] } else { wh[1] };
    let side = if dx * n[0] + dy * n[1] >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let along = dx * n[0] + dy * n[1];
    let hook = [
        t[0] - n[0] * side * (along.abs() - face),
        t[1] - n[1] * side * (along.abs() - face),
        t[2] + 0.12,
    ];
    let f = |v: [f64; 3]| v.map(|a| a as f32);
    let brass = solid(mat(hex("#b08d3c"), MAT_GLOSSY));
    let wire = solid(mat(hex("#3a3a3a"), MAT_PLAIN));
    let out = [
        hook[0] + n[0] * side * 0.03,
        hook[1] + n[1] * side * 0.03,
        hook[2],
    ];
    m.rod(&Xf::ID, f(hook), f(out), 0.006, 6, &brass);
    m.rod(&Xf::ID, f(out), f(t), 0.0025, 5, &wire);
}

/// A hot plate under a hot object standing on a surface: a dark cooktop with a red
/// glowing burner ring, just on the surface under the object at t0.
fn hot_plate(m: &mut Mesh, spec: &SceneSpec) {
    let Some(support) = spec.source_support.map(|i| &spec.bodies[i]) else {
        return;
    };
    let Some(h) = box_half(support) else {
        return;
    };
    let hazard = &spec.bodies[spec.hazard];
    let r = hazard
        .parts
        .iter()
        .map(|p| p.shape.bounding_radius())
        .fold(0.05, f64::max)
        .min(0.16) as f32;
    // The support's top face (its first part, a box; supports stand upright).
    let off = support.parts[0].offset;
    let z = (support.position[2] + off[2] + h[2]) as f32;
    let (x, y) = (hazard.position[0] as f32, hazard.position[1] as f32);
    let top = solid(mat(hex("#1c1c1c"), MAT_GLOSSY));
    let glow = solid(mat(hex("#ff4a12"), MAT_EMISSIVE));
    m.boxy(
        &Xf::at([x, y, z + 0.002]),
        [r + 0.07, r + 0.07, 0.002],
        1,
        &top,
    );
    m.ring(
        &Xf::at([x, y, z]),
        r * 0.55,
        r * 0.85,
        0.0045,
        true,
        28,
        &glow,
    );
    m.ring(
        &Xf::at([x, y, z]),
        r * 0.2,
        r * 0.35,
        0.0045,
        true,
        20,
        &glow,
    );
}
