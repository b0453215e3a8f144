//! Object recipes: how each catalog `appearance.recipe` is drawn, in the body frame, from
//! the object's collision parts (for its size) and its colours. Unknown recipes fall back
//! to the collision parts in the object's colours, so no object ever fails to draw.

use super::mesh::*;
use crate::spec::{PartSpec, ShapeSpec};
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// What a recipe gets: the colours and the collision parts (body frame).
pub struct Look<'a> {
    pub recipe: &'a str,
    pub color: Rgba,
    pub secondary: Option<Rgba>,
    pub description: &'a str,
    pub parts: &'a [PartSpec],
}

/// Recipes drawn by dedicated code (the rest use the generic part fallback).
pub const SPECIFIC: &[&str] = &[
    "apple",
    "sphere_fruit",
    "ball",
    "glass_sphere",
    "wrecking_ball",
    "kettlebell",
    "book",
    "box",
    "laptop",
    "phone",
    "remote",
    "board",
    "block",
    "brick",
    "toolbox",
    "can",
    "pan",
    "plate",
    "bowl",
    "dish",
    "mug",
    "cup",
    "disc",
    "plant_pot",
    "pot",
    "sponge",
    "jar",
    "bottle",
    "vase",
    "glass",
    "kettle",
    "iron",
    "extinguisher",
    "knife",
    "scissors",
    "saw",
    "glass_shard",
    "axe",
    "hammer",
    "dumbbell",
    "anvil",
    "plush",
    "pillow",
    "sack",
    "frame",
    "mirror",
    "whiteboard",
    "clock",
    "shelf",
    "rack",
    "fan",
    "lamp",
    "panel",
    "light_fixture",
    "smoke_detector",
    "vent",
    "chandelier",
    "punching_bag",
    "tyre",
    "bookcase",
    "wardrobe",
    "cabinet",
    "dresser",
    "fridge",
    "tv",
    "door",
    "ladder",
    "floor_lamp",
    "coat_stand",
];

fn part_half(p: &PartSpec) -> V3 {
    match p.shape {
        ShapeSpec::Box { half_extents: h } => h.map(|v| v as f32),
        ShapeSpec::Sphere { radius } => [radius as f32; 3],
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => [radius as f32, radius as f32, half_height as f32],
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => [radius as f32, radius as f32, (half_height + radius) as f32],
    }
}

/// Half extents of the parts' bounding box around the body origin.
fn bounds(parts: &[PartSpec]) -> V3 {
    let mut h = [0.0f32; 3];
    for p in parts {
        let e = part_half(p);
        for k in 0..3 {
            h[k] = h[k].max(p.offset[k].abs() as f32 + e[k]);
        }
    }
    if h.iter().all(|&v| v == 0.0) {
        [0.05; 3]
    } else {
        h
    }
}

fn part_xf(p: &PartSpec) -> Xf {
    Xf::from_quat(p.rotation, p.offset)
}

/// The collision parts themselves, first part in `c0`, the rest in `c1`.
pub fn parts_mesh(m: &mut Mesh, parts: &[PartSpec], c0: Rgba, c1: Rgba) {
    for (i, p) in parts.iter().enumerate() {
        let c = if i == 0 { c0 } else { c1 };
        let xf = part_xf(p);
        let paint = solid(c);
        match p.shape {
            ShapeSpec::Box { half_extents } => {
                m.boxy(&xf, half_extents.map(|v| v as f32), 1, &paint)
            }
            ShapeSpec::Sphere { radius } => m.sphere(&xf, radius as f32, 20, &paint),
            ShapeSpec::Cylinder {
                half_height,
                radius,
            } => m.cylinder(&xf, radius as f32, half_height as f32, 24, &paint),
            ShapeSpec::Capsule {
                half_height,
                radius,
            } => m.capsule(&xf, radius as f32, half_height as f32, 16, &paint),
        }
    }
}

const DARK: Rgba = [0.02, 0.02, 0.02, MAT_PLAIN];
const STEEL: Rgba = [0.55, 0.57, 0.6, MAT_GLOSSY];
const WHITE: Rgba = [0.85, 0.85, 0.85, MAT_PLAIN];

/// Builds the mesh of a catalog object in its body frame.
pub fn object_mesh(look: &Look) -> Mesh {
    let mut m = Mesh::new();
    let c = look.color;
    let s = look.secondary.unwrap_or_else(|| shade(c, 0.6));
    let h = bounds(look.parts);
    let id = Xf::ID;
    let r = h[0].min(h[1]);
    let desc = look.description;
    match look.recipe {
        "apple" => {
            let body = move |p: V3| {
                // Darker toward the top and a lighter cheek.
                let k = 1.0 - 0.25 * (p[2] / r).max(0.0) + 0.2 * (p[0] / r).max(0.0);
                mat(shade(c, k), MAT_GLOSSY)
            };
            m.ellipsoid(&id, [r, r, r * 0.92], 24, &body);
            m.rod(
                &id,
                [0.0, 0.0, r * 0.8],
                [0.01, 0.0, r * 1.25],
                r * 0.07,
                6,
                &solid(s),
            );
            m.ellipsoid(
                &Xf::rot(1, 0.6, [r * 0.22, 0.0, r * 1.08]),
                [r * 0.25, r * 0.1, r * 0.04],
                8,
                &solid([0.1, 0.4, 0.05, MAT_PLAIN]),
            );
        }
        "sphere_fruit" => {
            if r > 0.08 {
                // Watermelon: longitudinal stripes.
                let paint = move |p: V3| {
                    let a = p[1].atan2(p[0]);
                    if ((a / TAU * 14.0).rem_euclid(1.0)) < 0.45 {
                        s
                    } else {
                        c
                    }
                };
                m.ellipsoid(&id, [r * 1.05, r, r * 0.97], 36, &paint);
            } else {
                let paint = move |p: V3| {
                    let n =
                        ((p[0] * 997.0).sin() * (p[1] * 761.0).sin() * (p[2] * 883.0).sin()).abs();
                    shade(c, 0.92 + 0.12 * n)
                };
                m.sphere(&id, r, 28, &paint);
                m.cylinder(
                    &Xf::at([0.0, 0.0, r * 0.98]),
                    r * 0.12,
                    r * 0.06,
                    8,
                    &solid(s),
                );
            }
        }
        "ball" => {
            let big = r >= 0.15;
            let seam = r * 0.09;
            let paint = move |p: V3| {
                if big {
                    // Beach ball: six coloured gores.
                    let a = p[1].atan2(p[0]);
                    let k = ((a + PI) / TAU * 6.0) as i32;
                    return if p[2].abs() > r * 0.93 {
                        WHITE
                    } else if k % 2 == 0 {
                        mat(c, MAT_GLOSSY)
                    } else {
                        mat(s, MAT_GLOSSY)
                    };
                }
                // Two crossing seams (tennis/basketball/baseball-like), plus an equator
                // on larger balls.
                let curve = p[2] - 0.35 * r * (2.0 * p[1].atan2(p[0])).sin();
                if curve.abs() < seam || (r > 0.08 && p[0].abs() < seam * 0.7) {
                    mat(s, MAT_PLAIN)
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.sphere(&id, r, 40, &paint);
        }
        "glass_sphere" => {
            let paint = move |p: V3| mat(mix(c, WHITE, (p[2] / r).max(0.0) * 0.5), MAT_GLOSSY);
            m.sphere(&id, r, 32, &paint);
        }
        "wrecking_ball" => {
            m.sphere(&id, r, 28, &solid(mat(c, MAT_GLOSSY)));
            m.torus(
                &Xf::rot(0, FRAC_PI_2, [0.0, 0.0, r * 1.1]),
                r * 0.25,
                r * 0.06,
                0.0,
                TAU,
                12,
                &solid(s),
            );
        }
        "kettlebell" => {
            let p0 = &look.parts[0];
            let (rb, off) = (part_half(p0)[0], p0.offset.map(|v| v as f32));
            m.sphere(&Xf::at(off), rb, 28, &solid(mat(c, MAT_PLAIN)));
            m.torus(
                &Xf::rot(0, FRAC_PI_2, [0.0, 0.0, off[2] + rb * 0.6]),
                rb * 0.55,
                rb * 0.14,
                0.0,
                PI,
                14,
                &solid(shade(c, 1.3)),
            );
        }
        "book" => {
            let cover = h[2] * 0.12;
            // Covers (top/bottom) and spine at -x, pages inset in the secondary colour.
            for z in [-1.0f32, 1.0] {
                m.boxy(
                    &Xf::at([0.0, 0.0, z * (h[2] - cover)]),
                    [h[0], h[1], cover],
                    1,
                    &solid(c),
                );
            }
            m.boxy(
                &Xf::at([-h[0] + cover, 0.0, 0.0]),
                [cover, h[1], h[2]],
                1,
                &solid(c),
            );
            let pages = move |p: V3| {
                let lines = ((p[2] * 900.0).sin() * 0.5 + 0.5) * 0.1;
                shade(s, 0.95 - lines)
            };
            m.boxy(
                &Xf::at([cover * 0.5, 0.0, 0.0]),
                [h[0] - cover * 1.2, h[1] * 0.96, h[2] - cover * 1.8],
                4,
                &pages,
            );
            // A title band on the cover.
            m.boxy(
                &Xf::at([0.0, 0.0, h[2] + 0.0005]),
                [h[0] * 0.5, h[1] * 0.12, 0.001],
                1,
                &solid(shade(s, 0.9)),
            );
        }
        "box" => {
            let sh = if desc.contains("microwave") {
                m.boxy(&id, h, 1, &solid(c));
                m.boxy(
                    &Xf::at([-h[0] * 0.15, -h[1] - 0.002, 0.0]),
                    [h[0] * 0.7, 0.003, h[2] * 0.75],
                    1,
                    &solid(mat(s, MAT_GLOSSY)),
                );
                m.boxy(
                    &Xf::at([h[0] * 0.75, -h[1] - 0.002, 0.0]),
                    [h[0] * 0.18, 0.003, h[2] * 0.75],
                    1,
                    &solid(shade(c, 0.7)),
                );
                return m;
            } else {
                s
            };
            let paint = move |p: V3| {
                // Tape along the top centre and down the ends; a label on the sides.
                if p[2] > h[2] * 0.99 && p[1].abs() < h[1] * 0.15 {
                    shade(c, 1.25)
                } else if p[1].abs() > h[1] * 0.99
                    && p[0].abs() < h[0] * 0.45
                    && p[2].abs() < h[2] * 0.3
                {
                    sh
                } else {
                    c
                }
            };
            m.boxy(&id, h, 8, &paint);
        }
        "laptop" => {
            let paint = move |p: V3| {
                if p[2].abs() < h[2] * 0.15 {
                    s
                } else if p[2] > h[2] * 0.99 && p[0].hypot(p[1]) < h[1] * 0.12 {
                    WHITE
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.boxy(&id, h, 10, &paint);
        }
        "phone" => {
            m.boxy(&id, h, 1, &solid(c));
            m.boxy(
                &Xf::at([0.0, 0.0, h[2]]),
                [h[0] * 0.92, h[1] * 0.88, 0.0008],
                1,
                &solid(mat([0.03, 0.05, 0.09, 0.0], MAT_GLOSSY)),
            );
            m.sphere(&Xf::at([h[0] * 0.8, 0.0, -h[2]]), h[1] * 0.12, 8, &solid(s));
        }
        "remote" => {
            m.boxy(&id, h, 1, &solid(c));
            for i in 0..4 {
                for j in 0..3 {
                    let x = -h[0] * 0.6 + i as f32 * h[0] * 0.35;
                    let y = (j as f32 - 1.0) * h[1] * 0.5;
                    m.boxy(
                        &Xf::at([x, y, h[2]]),
                        [h[0] * 0.06, h[1] * 0.14, 0.003],
                        1,
                        &solid(s),
                    );
                }
            }
            m.boxy(
                &Xf::at([h[0] * 0.8, 0.0, h[2]]),
                [h[0] * 0.07, h[1] * 0.2, 0.003],
                1,
                &solid(hex("#d32f2f")),
            );
        }
        "board" => {
            m.boxy(&id, h, 1, &solid(c));
            let rim = h[0].min(h[1]) * 0.08;
            for (x, y, hx, hy) in [
                (0.0, h[1] - rim, h[0], rim),
                (0.0, -h[1] + rim, h[0], rim),
                (h[0] - rim, 0.0, rim, h[1]),
                (-h[0] + rim, 0.0, rim, h[1]),
            ] {
                m.boxy(&Xf::at([x, y, h[2]]), [hx, hy, h[2] * 0.5], 1, &solid(s));
            }
        }
        "block" => {
            let paint = move |p: V3| {
                if p[0].abs() > h[0] * 0.99 {
                    s
                } else if p[1].abs() > h[1] * 0.99 {
                    hex("#2a9d8f")
                } else {
                    c
                }
            };
            m.boxy(&id, h, 1, &paint);
        }
        "brick" => {
            let hollow = desc.contains("hollow");
            let paint = move |p: V3| {
                let n = ((p[0] * 431.0).sin() * (p[1] * 577.0).sin() * (p[2] * 389.0).sin()).abs();
                shade(c, 0.85 + 0.25 * n)
            };
            m.boxy(&id, h, 6, &paint);
            if hollow {
                for x in [-0.5f32, 0.5] {
                    m.boxy(
                        &Xf::at([x * h[0], 0.0, h[2]]),
                        [h[0] * 0.32, h[1] * 0.6, 0.002],
                        1,
                        &solid(DARK),
                    );
                }
            }
        }
        "toolbox" => {
            let paint = move |p: V3| {
                if (p[2] - h[2] * 0.4).abs() < h[2] * 0.05 {
                    DARK
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.boxy(&id, h, 8, &paint);
            m.torus(
                &Xf::rot(0, FRAC_PI_2, [0.0, 0.0, h[2]]),
                h[0] * 0.35,
                h[2] * 0.07,
                0.0,
                PI,
                12,
                &solid(s),
            );
        }
        "can" => {
            let (rc, hh) = (h[0], h[2]);
            let paint = move |p: V3| {
                if p[2].abs() > hh * 0.86 {
                    mat(s, MAT_GLOSSY)
                } else if (p[2] - (p[1].atan2(p[0])).sin() * hh * 0.25).abs() < hh * 0.12 {
                    WHITE
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.frustum(&id, rc, rc, hh, 28, (true, true), &paint);
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.88]),
                rc * 0.97,
                hh * 0.12,
                28,
                &solid(s),
            );
        }
        "pan" => {
            let (rp, hh) = (h[0], h[2]);
            let inner = if desc.contains("smoking") {
                shade(s, 0.8)
            } else {
                s
            };
            m.vessel(
                &id,
                rp * 0.9,
                rp,
                hh,
                rp * 0.06,
                hh * 0.3,
                32,
                &solid(c),
                &solid(inner),
            );
            m.boxy(
                &Xf::at([rp * 1.5, 0.0, hh * 0.6]),
                [rp * 0.55, rp * 0.09, hh * 0.18],
                1,
                &solid(shade(c, 0.7)),
            );
        }
        "plate" => {
            let (rp, hh) = (h[0], h[2]);
            let paint = move |p: V3| {
                let d = p[0].hypot(p[1]);
                if p[2] > 0.0 && d > rp * 0.8 && d < rp * 0.9 {
                    s
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.frustum(&id, rp * 0.6, rp, hh, 40, (true, false), &paint);
            m.ring(&id, 0.0, rp, hh * 0.5, true, 40, &paint);
        }
        "bowl" => {
            let (rb, hh) = (h[0], h[2]);
            m.vessel(
                &id,
                rb * 0.55,
                rb,
                hh,
                rb * 0.07,
                hh * 0.2,
                32,
                &solid(mat(c, MAT_GLOSSY)),
                &solid(c),
            );
            m.ring(&id, rb * 0.9, rb, hh, true, 32, &solid(s));
        }
        "dish" => {
            let g = mat(c, MAT_GLOSSY);
            m.boxy(
                &Xf::at([0.0, 0.0, -h[2] * 0.85]),
                [h[0], h[1], h[2] * 0.15],
                1,
                &solid(g),
            );
            let t = h[1] * 0.06;
            for (x, y, hx, hy) in [
                (0.0, h[1] - t, h[0], t),
                (0.0, -h[1] + t, h[0], t),
                (h[0] - t, 0.0, t, h[1]),
                (-h[0] + t, 0.0, t, h[1]),
            ] {
                m.boxy(
                    &Xf::at([x, y, 0.0]),
                    [hx, hy, h[2]],
                    1,
                    &solid(mat(s, MAT_GLOSSY)),
                );
            }
        }
        "mug" | "cup" => {
            let (rm, hh) = (h[0], h[2]);
            let taper = if look.recipe == "cup" { 0.75 } else { 0.97 };
            m.vessel(
                &id,
                rm * taper,
                rm,
                hh,
                rm * 0.1,
                hh * 0.12,
                28,
                &solid(mat(c, MAT_GLOSSY)),
                &solid(if look.recipe == "cup" { c } else { WHITE }),
            );
            if look.recipe == "mug" {
                m.cylinder(
                    &Xf::at([0.0, 0.0, hh * 0.6]),
                    rm * 0.9,
                    0.001,
                    24,
                    &solid(s),
                );
                m.torus(
                    &Xf::rot(0, FRAC_PI_2, [rm, 0.0, 0.0]),
                    hh * 0.5,
                    rm * 0.13,
                    -FRAC_PI_2,
                    FRAC_PI_2,
                    12,
                    &solid(mat(c, MAT_GLOSSY)),
                );
            } else {
                m.ring(&id, rm * 0.9, rm * 1.01, hh, true, 28, &solid(s));
            }
        }
        "disc" => {
            let (rd, hh) = (h[0], h[2]);
            m.frustum(
                &id,
                rd * 0.85,
                rd * 0.95,
                hh * 0.6,
                36,
                (true, true),
                &solid(mat(c, MAT_GLOSSY)),
            );
            m.torus(
                &Xf::at([0.0, 0.0, 0.0]),
                rd * 0.93,
                hh * 0.9,
                0.0,
                TAU,
                36,
                &solid(shade(c, 0.85)),
            );
        }
        "plant_pot" => {
            let (rp, hh) = (h[0], h[2]);
            m.vessel(
                &id,
                rp * 0.75,
                rp,
                hh,
                rp * 0.08,
                hh * 0.2,
                24,
                &solid(c),
                &solid(shade(c, 0.6)),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.8]),
                rp * 0.9,
                0.003,
                20,
                &solid(hex("#3e2723")),
            );
            let leaf = move |p: V3| shade(s, 0.8 + 0.4 * ((p[0] * 90.0).sin() * 0.5 + 0.5));
            for k in 0..7 {
                let a = k as f32 * TAU / 7.0;
                let rr = if k == 0 { 0.0 } else { rp * 0.5 };
                m.ellipsoid(
                    &Xf::at([rr * a.cos(), rr * a.sin(), hh + rp * 0.35]),
                    [rp * 0.45, rp * 0.45, rp * 0.6],
                    12,
                    &leaf,
                );
            }
        }
        "pot" => {
            let (rp, hh) = (h[0], h[2]);
            m.vessel(
                &id,
                rp,
                rp,
                hh,
                rp * 0.05,
                hh * 0.1,
                32,
                &solid(mat(c, MAT_GLOSSY)),
                &solid(c),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.7]),
                rp * 0.95,
                0.002,
                28,
                &solid(mat(s, MAT_GLOSSY)),
            );
            for sx in [-1.0f32, 1.0] {
                m.boxy(
                    &Xf::at([sx * rp * 1.1, 0.0, hh * 0.75]),
                    [rp * 0.12, rp * 0.2, hh * 0.06],
                    1,
                    &solid(DARK),
                );
            }
        }
        "sponge" => {
            let paint = move |p: V3| {
                let n = ((p[0] * 1300.0).sin() * (p[1] * 1100.0).sin()).abs();
                shade(c, 0.9 + 0.15 * n)
            };
            m.boxy(
                &Xf::at([0.0, 0.0, h[2] * 0.3]),
                [h[0], h[1], h[2] * 0.7],
                6,
                &paint,
            );
            m.boxy(
                &Xf::at([0.0, 0.0, -h[2] * 0.7]),
                [h[0], h[1], h[2] * 0.3],
                1,
                &solid(s),
            );
        }
        "jar" => {
            let (rj, hh) = (h[0], h[2]);
            m.cylinder(
                &Xf::at([0.0, 0.0, -hh * 0.1]),
                rj * 0.92,
                hh * 0.8,
                24,
                &solid(s),
            );
            m.frustum(
                &Xf::at([0.0, 0.0, -hh * 0.1]),
                rj,
                rj,
                hh * 0.9,
                24,
                (true, false),
                &solid(mat(c, MAT_GLOSSY)),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.88]),
                rj * 0.9,
                hh * 0.12,
                24,
                &solid(STEEL),
            );
        }
        "bottle" => {
            let (rb, hh) = (h[0], h[2]);
            let body = mat(c, MAT_GLOSSY);
            m.cylinder(
                &Xf::at([0.0, 0.0, -hh * 0.35]),
                rb,
                hh * 0.65,
                24,
                &solid(body),
            );
            if desc.contains("label") {
                m.frustum(
                    &Xf::at([0.0, 0.0, -hh * 0.35]),
                    rb * 1.01,
                    rb * 1.01,
                    hh * 0.3,
                    24,
                    (false, false),
                    &solid(s),
                );
            }
            m.frustum(
                &Xf::at([0.0, 0.0, hh * 0.4]),
                rb,
                rb * 0.35,
                hh * 0.1,
                24,
                (false, false),
                &solid(body),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.7]),
                rb * 0.35,
                hh * 0.2,
                16,
                &solid(body),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.93]),
                rb * 0.4,
                hh * 0.07,
                16,
                &solid(if desc.contains("label") {
                    shade(c, 0.5)
                } else {
                    s
                }),
            );
        }
        "vase" => {
            let (rv, hh) = (h[0], h[2]);
            let g = solid(mat(c, MAT_GLOSSY));
            m.frustum(
                &Xf::at([0.0, 0.0, -hh * 0.5]),
                rv * 0.7,
                rv,
                hh * 0.5,
                24,
                (true, false),
                &g,
            );
            m.frustum(
                &Xf::at([0.0, 0.0, hh * 0.3]),
                rv,
                rv * 0.55,
                hh * 0.3,
                24,
                (false, false),
                &g,
            );
            m.frustum(
                &Xf::at([0.0, 0.0, hh * 0.8]),
                rv * 0.55,
                rv * 0.75,
                hh * 0.2,
                24,
                (false, false),
                &solid(mat(s, MAT_GLOSSY)),
            );
        }
        "glass" => {
            let (rg, hh) = (h[0], h[2]);
            let g = solid(mat(c, MAT_GLOSSY));
            m.cylinder(&Xf::at([0.0, 0.0, -hh * 0.97]), rg * 0.8, hh * 0.03, 20, &g);
            m.cylinder(&Xf::at([0.0, 0.0, -hh * 0.5]), rg * 0.08, hh * 0.45, 8, &g);
            m.vessel(
                &Xf::at([0.0, 0.0, hh * 0.45]),
                rg * 0.45,
                rg,
                hh * 0.55,
                rg * 0.05,
                hh * 0.05,
                24,
                &g,
                &solid(mat(s, MAT_GLOSSY)),
            );
        }
        "kettle" => {
            let (rk, hh) = (h[0], h[2]);
            m.frustum(
                &Xf::at([0.0, 0.0, -hh * 0.1]),
                rk,
                rk * 0.8,
                hh * 0.8,
                28,
                (false, true),
                &solid(mat(c, MAT_GLOSSY)),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, -hh * 0.95]),
                rk,
                hh * 0.08,
                28,
                &solid(s),
            );
            m.sphere(&Xf::at([0.0, 0.0, hh * 0.75]), rk * 0.15, 10, &solid(s));
            m.torus(
                &Xf::rot(0, FRAC_PI_2, [-rk * 0.75, 0.0, 0.0]),
                hh * 0.55,
                rk * 0.1,
                FRAC_PI_2,
                PI * 1.5,
                12,
                &solid(s),
            );
            m.rod(
                &id,
                [rk * 0.7, 0.0, -hh * 0.3],
                [rk * 1.3, 0.0, hh * 0.35],
                rk * 0.1,
                8,
                &solid(mat(c, MAT_GLOSSY)),
            );
        }
        "iron" => {
            let outline: Vec<[f32; 2]> = vec![
                [-h[0], -h[1]],
                [h[0] * 0.4, -h[1]],
                [h[0], 0.0],
                [h[0] * 0.4, h[1]],
                [-h[0], h[1]],
            ];
            m.slab(
                &Xf::at([0.0, 0.0, -h[2] * 0.85]),
                &outline,
                h[2] * 0.15,
                &solid(mat(s, MAT_GLOSSY)),
            );
            let body: Vec<[f32; 2]> = outline.iter().map(|p| [p[0] * 0.9, p[1] * 0.8]).collect();
            m.slab(
                &Xf::at([0.0, 0.0, -h[2] * 0.45]),
                &body,
                h[2] * 0.25,
                &solid(mat(c, MAT_GLOSSY)),
            );
            m.rod(
                &id,
                [-h[0] * 0.7, 0.0, -h[2] * 0.2],
                [-h[0] * 0.6, 0.0, h[2] * 0.9],
                h[1] * 0.15,
                8,
                &solid(c),
            );
            m.rod(
                &id,
                [-h[0] * 0.6, 0.0, h[2] * 0.85],
                [h[0] * 0.3, 0.0, h[2] * 0.85],
                h[1] * 0.15,
                8,
                &solid(c),
            );
            m.rod(
                &id,
                [h[0] * 0.3, 0.0, h[2] * 0.85],
                [h[0] * 0.5, 0.0, -h[2] * 0.2],
                h[1] * 0.15,
                8,
                &solid(c),
            );
        }
        "extinguisher" => {
            let (re, hh) = (h[0], h[2]);
            m.cylinder(
                &Xf::at([0.0, 0.0, -hh * 0.15]),
                re * 0.9,
                hh * 0.72,
                24,
                &solid(mat(c, MAT_GLOSSY)),
            );
            m.sphere(
                &Xf::at([0.0, 0.0, hh * 0.57]),
                re * 0.9,
                20,
                &solid(mat(c, MAT_GLOSSY)),
            );
            m.cylinder(
                &Xf::at([0.0, 0.0, hh * 0.85]),
                re * 0.3,
                hh * 0.12,
                12,
                &solid(s),
            );
            m.boxy(
                &Xf::rot(1, 0.3, [re * 0.4, 0.0, hh * 0.95]),
                [re * 0.6, re * 0.12, re * 0.05],
                1,
                &solid(s),
            );
            m.rod(
                &id,
                [-re * 0.2, 0.0, hh * 0.88],
                [-re * 1.0, 0.0, -hh * 0.4],
                re * 0.08,
                6,
                &solid(s),
            );
        }
        "knife" => {
            let blade_len = h[0] * 1.2;
            let x0 = -h[0] + h[0] * 0.8;
            let outline = [
                [x0, -h[1] * 0.95],
                [x0 + blade_len * 0.8, -h[1] * 0.7],
                [h[0], h[1] * 0.2],
                [x0 + blade_len * 0.6, h[1] * 0.9],
                [x0, h[1] * 0.95],
            ];
            // Blade lies in the x–y plane (flat), edge at -y.
            m.slab(&id, &outline, h[2] * 0.15, &solid(mat(c, MAT_GLOSSY)));
            m.boxy(
                &Xf::at([-h[0] + h[0] * 0.4, 0.0, 0.0]),
                [h[0] * 0.4, h[1] * 0.55, h[2] * 0.8],
                1,
                &solid(s),
            );
            for x in [0.25f32, 0.55] {
                m.cylinder(
                    &Xf::at([-h[0] + h[0] * x, 0.0, 0.0]),
                    h[1] * 0.12,
                    h[2] * 0.85,
                    8,
                    &solid(STEEL),
                );
            }
        }
        "scissors" => {
            for sgn in [-1.0f32, 1.0] {
                let xf = Xf::rot(2, sgn * 0.12, [0.0, 0.0, sgn * h[2] * 0.4]);
                m.slab(
                    &xf,
                    &[
                        [-h[0] * 0.1, -h[1] * 0.12],
                        [h[0], -h[1] * 0.02],
                        [h[0], h[1] * 0.06],
                        [-h[0] * 0.1, h[1] * 0.12],
                    ],
                    h[2] * 0.2,
                    &solid(mat(c, MAT_GLOSSY)),
                );
                m.torus(
                    &Xf::at([-h[0] * 0.55, sgn * h[1] * 0.45, sgn * h[2] * 0.4]),
                    h[1] * 0.4,
                    h[2] * 0.45,
                    0.0,
                    TAU,
                    16,
                    &solid(s),
                );
            }
        }
        "saw" => {
            // Blade in the x–z plane (thin along y), teeth along -z, handle at -x.
            let outline = [
                [-h[0] * 0.55, -h[2]],
                [h[0], -h[2]],
                [h[0], -h[2] * 0.3],
                [-h[0] * 0.55, h[2] * 0.6],
            ];
            let blade = move |p: V3| {
                if p[1] < -h[2] * 0.85 {
                    shade(c, 0.6)
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.slab(
                &Xf::rot(0, FRAC_PI_2, [0.0, 0.0, 0.0]),
                &outline,
                h[1] * 0.4,
                &blade,
            );
            m.boxy(
                &Xf::at([-h[0] * 0.78, 0.0, h[2] * 0.1]),
                [h[0] * 0.22, h[1] * 1.0, h[2] * 0.8],
                1,
                &solid(s),
            );
            m.boxy(
                &Xf::at([-h[0] * 0.78, 0.0, h[2] * 0.15]),
                [h[0] * 0.1, h[1] * 1.3, h[2] * 0.3],
                1,
                &solid(DARK),
            );
        }
        "glass_shard" => {
            let outline = [
                [-h[0], -h[1] * 0.8],
                [h[0] * 0.3, -h[1]],
                [h[0], -h[1] * 0.1],
                [h[0] * 0.2, h[1] * 0.4],
                [-h[0] * 0.4, h[1]],
                [-h[0] * 0.9, h[1] * 0.3],
            ];
            m.slab(&id, &outline, h[2], &solid(mat(c, MAT_GLOSSY)));
        }
        "axe" | "hammer" => {
            // Handle (first part) in the primary colour, head (second) in the secondary.
            parts_mesh(&mut m, &look.parts[..1], c, s);
            if let Some(head) = look.parts.get(1) {
                let xf = part_xf(head);
                let hh = part_half(head);
                m.boxy(&xf, hh, 1, &solid(mat(s, MAT_GLOSSY)));
                if look.recipe == "axe" {
                    m.boxy(
                        &xf.then(&Xf::at([0.0, hh[1] * 0.95, 0.0])),
                        [hh[0] * 1.6, hh[1] * 0.12, hh[2] * 0.6],
                        1,
                        &solid(mat(shade(s, 1.5), MAT_GLOSSY)),
                    );
                } else {
                    m.cylinder(
                        &xf.then(&Xf::rot(0, FRAC_PI_2, [0.0, -hh[1] * 1.1, 0.0])),
                        hh[0] * 1.1,
                        hh[1] * 0.3,
                        10,
                        &solid(mat(s, MAT_GLOSSY)),
                    );
                }
            }
        }
        "dumbbell" => {
            let handle = &look.parts[0];
            let hh = part_half(handle);
            m.rod(
                &id,
                [-hh[0] - 0.02, 0.0, 0.0],
                [hh[0] + 0.02, 0.0, 0.0],
                hh[1] * 0.8,
                10,
                &solid(mat(s, MAT_GLOSSY)),
            );
            for p in &look.parts[1..] {
                let e = part_half(p);
                let o = p.offset.map(|v| v as f32);
                // Hexagonal heads along x.
                m.frustum(
                    &Xf::rot(1, FRAC_PI_2, o).then(&Xf::rot(2, PI / 6.0, [0.0; 3])),
                    e[1].min(e[2]) * 1.05,
                    e[1].min(e[2]) * 1.05,
                    e[0],
                    6,
                    (true, true),
                    &solid(c),
                );
            }
        }
        "anvil" => {
            parts_mesh(&mut m, look.parts, s, mat(c, MAT_GLOSSY));
            if let Some(top) = look.parts.last() {
                let e = part_half(top);
                let o = top.offset.map(|v| v as f32);
                m.frustum(
                    &Xf::rot(
                        1,
                        FRAC_PI_2,
                        [o[0] + e[0] + e[0] * 0.2, o[1], o[2] + e[2] * 0.3],
                    ),
                    e[2] * 0.7,
                    0.002,
                    e[0] * 0.2,
                    10,
                    (true, false),
                    &solid(mat(c, MAT_GLOSSY)),
                );
            }
        }
        "plush" => {
            // A teddy bear sitting along the capsule's axis (z).
            let (rb, hz) = (h[0], h[2]);
            let fur = move |p: V3| {
                shade(
                    c,
                    0.9 + 0.15 * ((p[0] * 400.0).sin() * (p[2] * 350.0).sin()).abs(),
                )
            };
            m.ellipsoid(
                &Xf::at([0.0, 0.0, -hz * 0.3]),
                [rb * 0.85, rb * 0.8, hz * 0.45],
                20,
                &fur,
            );
            let head_z = hz * 0.45;
            m.sphere(&Xf::at([0.0, 0.0, head_z]), rb * 0.7, 20, &fur);
            for sy in [-1.0f32, 1.0] {
                m.sphere(
                    &Xf::at([0.0, sy * rb * 0.5, head_z + rb * 0.55]),
                    rb * 0.25,
                    10,
                    &fur,
                );
                m.sphere(
                    &Xf::at([rb * 0.55, sy * rb * 0.25, head_z + rb * 0.15]),
                    rb * 0.08,
                    8,
                    &solid(DARK),
                );
                m.ellipsoid(
                    &Xf::at([rb * 0.2, sy * rb * 0.8, -hz * 0.15]),
                    [rb * 0.25, rb * 0.25, rb * 0.4],
                    10,
                    &fur,
                );
                m.ellipsoid(
                    &Xf::at([rb * 0.3, sy * rb * 0.45, -hz * 0.75]),
                    [rb * 0.35, rb * 0.28, rb * 0.25],
                    10,
                    &fur,
                );
            }
            m.ellipsoid(
                &Xf::at([rb * 0.6, 0.0, head_z - rb * 0.1]),
                [rb * 0.22, rb * 0.25, rb * 0.18],
                10,
                &solid(s),
            );
            m.sphere(
                &Xf::at([rb * 0.8, 0.0, head_z - rb * 0.05]),
                rb * 0.07,
                8,
                &solid(DARK),
            );
        }
        "pillow" | "sack" => {
            let stripe = look.recipe == "pillow";
            let paint = move |p: V3| {
                if stripe && (p[1]).abs() < h[1] * 0.2 {
                    s
                } else if !stripe && p[0].abs() < h[0] * 0.05 {
                    s
                } else {
                    c
                }
            };
            m.ellipsoid(&id, [h[0] * 1.02, h[1] * 1.02, h[2] * 1.05], 28, &paint);
            if !stripe {
                m.sphere(
                    &Xf::at([h[0] * 0.9, 0.0, h[2] * 0.3]),
                    h[2] * 0.5,
                    8,
                    &solid(s),
                );
            }
        }
        "frame" | "mirror" | "whiteboard" => {
            // Face in the x–z plane, thickness along y; border in `border`, inner panel
            // on both faces.
            let (border, inner, inner_mat) = match look.recipe {
                "mirror" => (s, c, MAT_GLOSSY),
                "whiteboard" => (s, c, MAT_GLOSSY),
                _ => (c, s, MAT_PLAIN),
            };
            let b = h[0].min(h[2]) * if desc.contains("unframed") { 0.02 } else { 0.1 };
            m.boxy(&id, [h[0], h[1] * 0.6, h[2]], 1, &solid(border));
            for (x, z, hx, hz) in [
                (0.0, h[2] - b / 2.0, h[0], b / 2.0),
                (0.0, -h[2] + b / 2.0, h[0], b / 2.0),
                (h[0] - b / 2.0, 0.0, b / 2.0, h[2]),
                (-h[0] + b / 2.0, 0.0, b / 2.0, h[2]),
            ] {
                m.boxy(&Xf::at([x, 0.0, z]), [hx, h[1], hz], 1, &solid(border));
            }
            let recipe = look.recipe;
            let picture = move |p: V3| {
                match recipe {
                    "frame" => {
                        // A tiny landscape: sky, a hill, a sun.
                        let hill = -0.2 * h[2] + 0.25 * h[2] * (p[0] / h[0] * 3.0).sin();
                        if p[2] < hill {
                            mix(inner, hex("#4caf50"), 0.7)
                        } else if (p[0] - h[0] * 0.4).hypot(p[2] - h[2] * 0.4) < h[2] * 0.15 {
                            hex("#fff176")
                        } else {
                            inner
                        }
                    }
                    "mirror" => mat(
                        mix(
                            inner,
                            WHITE,
                            ((p[0] + p[2]) / (h[0] + h[2]) * 4.0).sin().abs() * 0.35,
                        ),
                        inner_mat,
                    ),
                    _ => {
                        if (p[2] - h[2] * 0.3 - 0.05 * (p[0] * 30.0).sin()).abs() < 0.006
                            && p[0].abs() < h[0] * 0.6
                        {
                            hex("#1e88e5")
                        } else if (p[2] + 0.1 * p[0]).abs() < 0.006 && p[0].abs() < h[0] * 0.4 {
                            hex("#e53935")
                        } else {
                            mat(inner, inner_mat)
                        }
                    }
                }
            };
            for sy in [-1.0f32, 1.0] {
                m.boxy(
                    &Xf::at([0.0, sy * h[1] * 0.65, 0.0]),
                    [h[0] - b, h[1] * 0.05, h[2] - b],
                    24,
                    &picture,
                );
            }
            if recipe == "whiteboard" {
                m.boxy(
                    &Xf::at([0.0, 0.0, -h[2] - 0.01]),
                    [h[0] * 0.8, h[1] * 2.5, 0.01],
                    1,
                    &solid(border),
                );
            }
        }
        "clock" => {
            let rc = h[0].min(h[2]);
            let face = Xf::rot(0, FRAC_PI_2, [0.0, 0.0, 0.0]);
            m.cylinder(&face, rc * 0.95, h[1] * 0.8, 36, &solid(c));
            m.torus(&face, rc * 0.95, h[1] * 0.5, 0.0, TAU, 36, &solid(s));
            for sy in [-1.0f32, 1.0] {
                let y = sy * h[1] * 0.85;
                m.boxy(
                    &Xf::rot(1, 0.5, [rc * 0.2, y, rc * 0.1]),
                    [rc * 0.45, 0.002, rc * 0.035],
                    1,
                    &solid(s),
                );
                m.boxy(
                    &Xf::rot(1, -1.2, [-rc * 0.1, y, rc * 0.25]),
                    [rc * 0.3, 0.002, rc * 0.045],
                    1,
                    &solid(s),
                );
                for k in 0..12 {
                    let a = k as f32 * TAU / 12.0;
                    m.boxy(
                        &Xf::at([a.cos() * rc * 0.8, y, a.sin() * rc * 0.8]),
                        [rc * 0.03, 0.002, rc * 0.03],
                        1,
                        &solid(s),
                    );
                }
            }
        }
        "shelf" | "rack" => {
            let glossy = if desc.contains("glass") {
                MAT_GLOSSY
            } else {
                MAT_PLAIN
            };
            m.boxy(&id, h, 1, &solid(mat(c, glossy)));
            if look.recipe == "shelf" {
                for sx in [-0.7f32, 0.7] {
                    m.boxy(
                        &Xf::at([sx * h[0], h[1] * 0.3, -h[2] - h[1] * 0.5]),
                        [h[0] * 0.03, h[1] * 0.6, h[1] * 0.5],
                        1,
                        &solid(s),
                    );
                }
            } else {
                for k in 0..4 {
                    let x = -h[0] * 0.75 + k as f32 * h[0] * 0.5;
                    m.rod(
                        &id,
                        [x, -h[1], 0.0],
                        [x, -h[1] * 3.0, h[2] * 0.6],
                        h[1] * 0.1,
                        8,
                        &solid(mat(s, MAT_GLOSSY)),
                    );
                }
            }
        }
        "fan" => {
            let motor = &look.parts[0];
            let e = part_half(motor);
            let o = motor.offset.map(|v| v as f32);
            m.cylinder(&Xf::at(o), e[0], e[2], 20, &solid(c));
            m.rod(
                &id,
                [0.0, 0.0, o[2]],
                [0.0, 0.0, o[2] + e[2] + 0.3],
                0.015,
                8,
                &solid(c),
            );
            let blade_z = look
                .parts
                .get(1)
                .map(|p| p.offset[2] as f32)
                .unwrap_or(-0.03);
            for k in 0..4 {
                let a = k as f32 * FRAC_PI_2 + 0.3;
                let xf = Xf::rot(2, a, [0.0, 0.0, blade_z]);
                m.boxy(
                    &xf.then(&Xf::at([h[0] * 0.55, 0.0, 0.0])),
                    [h[0] * 0.42, h[0] * 0.09, 0.005],
                    1,
                    &solid(s),
                );
            }
        }
        "lamp" => {
            let (rl, hh) = (h[0], h[2]);
            m.vessel(
                &Xf::rot(0, PI, [0.0, 0.0, 0.0]),
                rl * 0.25,
                rl,
                hh,
                rl * 0.03,
                hh * 0.1,
                28,
                &solid(mat(c, MAT_GLOSSY)),
                &solid(mat(c, MAT_EMISSIVE)),
            );
            m.sphere(
                &Xf::at([0.0, 0.0, -hh * 0.3]),
                rl * 0.2,
                12,
                &solid(mat([1.0, 0.95, 0.8, 0.0], MAT_EMISSIVE)),
            );
            m.rod(
                &id,
                [0.0, 0.0, hh],
                [0.0, 0.0, hh + 1.5],
                0.006,
                6,
                &solid(s),
            );
        }
        "panel" | "vent" => {
            let vent = look.recipe == "vent";
            let paint = move |p: V3| {
                if vent && p[2] < 0.0 && (p[0] / h[0] * 5.0).rem_euclid(1.0) < 0.35 {
                    shade(s, 0.5)
                } else if !vent && ((p[0] * 97.0).sin() * (p[1] * 89.0).sin()).abs() > 0.9 {
                    shade(c, 0.9)
                } else if p[0].abs() > h[0] * 0.92 || p[1].abs() > h[1] * 0.92 {
                    s
                } else {
                    c
                }
            };
            m.boxy(&id, h, 24, &paint);
        }
        "light_fixture" => {
            m.boxy(
                &Xf::at([0.0, 0.0, h[2] * 0.3]),
                [h[0], h[1], h[2] * 0.7],
                1,
                &solid(mat(c, MAT_GLOSSY)),
            );
            for y in [-0.45f32, 0.45] {
                m.rod(
                    &id,
                    [-h[0] * 0.95, y * h[1], -h[2] * 0.5],
                    [h[0] * 0.95, y * h[1], -h[2] * 0.5],
                    h[2] * 0.35,
                    10,
                    &solid(mat(s, MAT_EMISSIVE)),
                );
            }
        }
        "smoke_detector" => {
            let (rs, hh) = (h[0], h[2]);
            m.frustum(&id, rs * 0.85, rs, hh, 28, (true, true), &solid(c));
            m.ring(
                &id,
                rs * 0.4,
                rs * 0.5,
                -hh - 0.001,
                false,
                24,
                &solid(shade(c, 0.7)),
            );
            m.sphere(
                &Xf::at([rs * 0.6, 0.0, -hh]),
                rs * 0.06,
                8,
                &solid(mat(s, MAT_EMISSIVE)),
            );
        }
        "chandelier" => {
            let (rc, hh) = (h[0], h[2]);
            let brass = solid(mat(c, MAT_GLOSSY));
            m.torus(
                &Xf::at([0.0, 0.0, -hh * 0.2]),
                rc * 0.8,
                rc * 0.04,
                0.0,
                TAU,
                32,
                &brass,
            );
            m.rod(
                &id,
                [0.0, 0.0, -hh * 0.5],
                [0.0, 0.0, hh],
                rc * 0.06,
                10,
                &brass,
            );
            for k in 0..8 {
                let a = k as f32 * TAU / 8.0;
                let (x, y) = (a.cos() * rc * 0.8, a.sin() * rc * 0.8);
                m.rod(
                    &id,
                    [0.0, 0.0, -hh * 0.3],
                    [x, y, -hh * 0.2],
                    rc * 0.02,
                    6,
                    &brass,
                );
                m.cylinder(
                    &Xf::at([x, y, -hh * 0.05]),
                    rc * 0.04,
                    hh * 0.12,
                    8,
                    &solid(WHITE),
                );
                m.sphere(
                    &Xf::at([x, y, hh * 0.1]),
                    rc * 0.035,
                    6,
                    &solid(mat([1.0, 0.9, 0.6, 0.0], MAT_EMISSIVE)),
                );
                m.frustum(
                    &Xf::at([x * 0.9, y * 0.9, -hh * 0.55]),
                    0.001,
                    rc * 0.05,
                    hh * 0.15,
                    6,
                    (false, true),
                    &solid(mat(s, MAT_GLOSSY)),
                );
            }
        }
        "punching_bag" => {
            let (rp, hz) = (h[0], h[2]);
            let paint = move |p: V3| {
                if p[2].abs() > hz * 0.7 || (p[2] - hz * 0.35).abs() < hz * 0.03 {
                    s
                } else {
                    mat(c, MAT_GLOSSY)
                }
            };
            m.capsule(&id, rp, hz - rp, 24, &paint);
        }
        "tyre" => {
            let (rt, hh) = (h[0], h[2]);
            let tube = hh.min(rt * 0.35);
            let tread = move |p: V3| {
                let a = p[1].atan2(p[0]);
                if (a / TAU * 48.0).rem_euclid(1.0) < 0.3 {
                    shade(c, 0.6)
                } else {
                    c
                }
            };
            m.torus(&id, rt - tube, tube, 0.0, TAU, 48, &tread);
        }
        "bookcase" => {
            let t = 0.02;
            let wood = solid(c);
            for sx in [-1.0f32, 1.0] {
                m.boxy(
                    &Xf::at([sx * (h[0] - t), 0.0, 0.0]),
                    [t, h[1], h[2]],
                    1,
                    &wood,
                );
            }
            m.boxy(
                &Xf::at([0.0, -h[1] + 0.005, 0.0]),
                [h[0], 0.005, h[2]],
                1,
                &solid(shade(c, 0.7)),
            );
            let shelves = 5;
            let colors = [
                "#b71c1c", "#1565c0", "#2e7d32", "#f9a825", "#4e342e", "#6a1b9a", "#00838f",
            ];
            for i in 0..=shelves {
                let z = -h[2] + t + i as f32 * (2.0 * h[2] - 2.0 * t) / shelves as f32;
                m.boxy(&Xf::at([0.0, 0.0, z]), [h[0], h[1], t], 1, &wood);
                if i < shelves {
                    let gap = (2.0 * h[2] - 2.0 * t) / shelves as f32;
                    let mut x = -h[0] + 2.0 * t;
                    let mut k = i * 3;
                    while x < h[0] - 3.0 * t {
                        let w = 0.018 + 0.012 * ((k * 7 % 5) as f32 / 4.0);
                        let bh = gap * (0.6 + 0.25 * ((k * 5 % 7) as f32 / 6.0));
                        m.boxy(
                            &Xf::at([x + w, h[1] * 0.05, z + t + bh / 2.0]),
                            [w, h[1] * 0.85, bh / 2.0],
                            1,
                            &solid(hex(colors[k % colors.len()])),
                        );
                        x += 2.0 * w + 0.004;
                        k += 1;
                    }
                }
            }
        }
        "wardrobe" | "cabinet" | "dresser" | "fridge" => {
            let recipe = look.recipe;
            let paint = move |p: V3| {
                let face = p[1].abs() > h[1] * 0.99;
                let u = (p[2] + h[2]) / (2.0 * h[2]);
                let line = match recipe {
                    "wardrobe" => p[0].abs() < h[0] * 0.01,
                    "cabinet" => ((u * 4.0).rem_euclid(1.0)) < 0.02,
                    "dresser" => ((u * 5.0).rem_euclid(1.0)) < 0.03,
                    _ => (u - 0.68).abs() < 0.006,
                };
                if face && line {
                    shade(c, 0.45)
                } else if recipe == "fridge" || recipe == "cabinet" {
                    mat(c, MAT_GLOSSY)
                } else {
                    c
                }
            };
            m.boxy(&id, h, 40, &paint);
            for sy in [-1.0f32, 1.0] {
                let y = sy * (h[1] + 0.012);
                match recipe {
                    "wardrobe" => {
                        for sx in [-1.0f32, 1.0] {
                            m.boxy(
                                &Xf::at([sx * h[0] * 0.08, y, h[2] * 0.05]),
                                [0.01, 0.012, h[2] * 0.12],
                                1,
                                &solid(s),
                            );
                        }
                    }
                    "fridge" => {
                        m.boxy(
                            &Xf::at([h[0] * 0.8, y, h[2] * 0.1]),
                            [0.015, 0.015, h[2] * 0.25],
                            1,
                            &solid(s),
                        );
                        m.boxy(
                            &Xf::at([h[0] * 0.8, y, h[2] * 0.75]),
                            [0.015, 0.015, h[2] * 0.12],
                            1,
                            &solid(s),
                        );
                    }
                    _ => {
                        let n = if recipe == "cabinet" { 4 } else { 5 };
                        for i in 0..n {
                            let z = -h[2] + (i as f32 + 0.5) * 2.0 * h[2] / n as f32;
                            for sx in if recipe == "dresser" {
                                [-0.5f32, 0.5]
                            } else {
                                [0.0f32, 0.0]
                            } {
                                m.boxy(
                                    &Xf::at([sx * h[0], y, z + h[2] * 0.08]),
                                    [h[0] * 0.12, 0.012, 0.012],
                                    1,
                                    &solid(mat(s, MAT_GLOSSY)),
                                );
                            }
                        }
                    }
                }
            }
        }
        "tv" => {
            m.boxy(&id, h, 1, &solid(s));
            let b = h[2] * 0.05;
            let screen = move |p: V3| {
                let k = ((p[0] / h[0] + p[2] / h[2]) * 0.5 + 0.5) * 0.08;
                mat([0.01 + k, 0.015 + k, 0.03 + k, 0.0], MAT_GLOSSY)
            };
            for sy in [-1.0f32, 1.0] {
                m.boxy(
                    &Xf::at([0.0, sy * h[1], 0.0]),
                    [h[0] - b, 0.002, h[2] - b],
                    8,
                    &screen,
                );
            }
            let _ = c;
        }
        "door" => {
            let glass = desc.contains("glass");
            let mesh_door = desc.contains("mesh");
            let b = h[0] * 0.12;
            let panel = move |p: V3| {
                let u = p[0] / h[0];
                let v = p[2] / h[2];
                if glass {
                    mat(c, MAT_GLOSSY)
                } else if mesh_door {
                    // Fine mesh reads as a uniform grey-tinted screen at video scale.
                    mix(c, s, 0.45)
                } else {
                    // Four raised panels.
                    let inside = u.abs() < 0.75
                        && (u.abs() > 0.08)
                        && ((v > 0.08 && v < 0.85) || (v < -0.08 && v > -0.85));
                    if inside {
                        shade(c, 0.93)
                    } else {
                        c
                    }
                }
            };
            if glass || mesh_door {
                // Frame of four bars, pane in the middle.
                for (x, z, hx, hz) in [
                    (0.0, h[2] - b / 2.0, h[0], b / 2.0),
                    (0.0, -h[2] + b / 2.0, h[0], b / 2.0),
                    (h[0] - b / 2.0, 0.0, b / 2.0, h[2]),
                    (-h[0] + b / 2.0, 0.0, b / 2.0, h[2]),
                ] {
                    m.boxy(&Xf::at([x, 0.0, z]), [hx, h[1], hz], 1, &solid(s));
                }
                m.boxy(&id, [h[0] - b, h[1] * 0.3, h[2] - b], 24, &panel);
            } else {
                m.boxy(&id, h, 32, &panel);
            }
            // Handles on both faces near the free (+x) edge, at ~1 m above the bottom.
            let z = (-h[2] + 1.0).min(0.0);
            for sy in [-1.0f32, 1.0] {
                m.sphere(
                    &Xf::at([h[0] * 0.8, sy * (h[1] + 0.03), z]),
                    0.028,
                    10,
                    &solid(mat(s, MAT_GLOSSY)),
                );
                m.rod(
                    &id,
                    [h[0] * 0.8, sy * h[1], z],
                    [h[0] * 0.8, sy * (h[1] + 0.03), z],
                    0.01,
                    6,
                    &solid(mat(s, MAT_GLOSSY)),
                );
            }
        }
        "ladder" => {
            let rail = h[0] * 0.1;
            let round = desc.contains("round");
            for sx in [-1.0f32, 1.0] {
                let x = sx * (h[0] - rail);
                m.boxy(
                    &Xf::at([x, 0.0, 0.0]),
                    [rail, h[1], h[2]],
                    1,
                    &solid(mat(c, MAT_GLOSSY)),
                );
                m.boxy(
                    &Xf::at([x, 0.0, -h[2] + 0.03]),
                    [rail * 1.2, h[1] * 1.1, 0.03],
                    1,
                    &solid(s),
                );
            }
            let n = ((2.0 * h[2]) / 0.3).floor() as usize;
            for i in 1..n {
                let z = -h[2] + i as f32 * 2.0 * h[2] / n as f32;
                if round {
                    m.rod(
                        &id,
                        [-h[0] + rail, 0.0, z],
                        [h[0] - rail, 0.0, z],
                        h[1] * 0.35,
                        10,
                        &solid(c),
                    );
                } else {
                    m.boxy(
                        &Xf::at([0.0, 0.0, z]),
                        [h[0] - rail, h[1] * 0.8, 0.015],
                        1,
                        &solid(mat(c, MAT_GLOSSY)),
                    );
                }
            }
        }
        "floor_lamp" | "coat_stand" => {
            let n = look.parts.len();
            for (i, p) in look.parts.iter().enumerate() {
                let e = part_half(p);
                let o = p.offset.map(|v| v as f32);
                if look.recipe == "floor_lamp" && i == n - 1 && n > 2 {
                    m.vessel(
                        &Xf::at(o),
                        e[0],
                        e[0] * 0.75,
                        e[2],
                        0.004,
                        0.0,
                        28,
                        &solid(s),
                        &solid(mat(s, MAT_EMISSIVE)),
                    );
                    m.sphere(
                        &Xf::at([o[0], o[1], o[2] - e[2] * 0.3]),
                        e[0] * 0.25,
                        10,
                        &solid(mat([1.0, 0.95, 0.8, 0.0], MAT_EMISSIVE)),
                    );
                } else {
                    m.cylinder(&Xf::at(o), e[0], e[2], 24, &solid(mat(c, MAT_GLOSSY)));
                }
            }
            if look.recipe == "coat_stand" {
                let top = h[2];
                for k in 0..4 {
                    let a = k as f32 * FRAC_PI_2;
                    m.rod(
                        &id,
                        [0.0, 0.0, top - 0.12],
                        [a.cos() * 0.14, a.sin() * 0.14, top - 0.02],
                        0.012,
                        6,
                        &solid(c),
                    );
                    m.sphere(
                        &Xf::at([a.cos() * 0.14, a.sin() * 0.14, top - 0.02]),
                        0.02,
                        8,
                        &solid(c),
                    );
                }
            }
        }
        _ => parts_mesh(&mut m, look.parts, c, s),
    }
    m
}
