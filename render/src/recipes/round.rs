//! Round things: fruit, balls, weights with a round body.

use super::*;
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["apple"],
        mesh: apple,
    },
    Recipe {
        names: &["sphere_fruit"],
        mesh: sphere_fruit,
    },
    Recipe {
        names: &["ball"],
        mesh: ball,
    },
    Recipe {
        names: &["iron_ball"],
        mesh: iron_ball,
    },
    Recipe {
        names: &["glass_sphere"],
        mesh: glass_sphere,
    },
    Recipe {
        names: &["wrecking_ball"],
        mesh: wrecking_ball,
    },
    Recipe {
        names: &["kettlebell"],
        mesh: kettlebell,
    },
];

fn apple(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, id, r, .. } = *k;
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

fn sphere_fruit(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, id, r, .. } = *k;
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
            let n = ((p[0] * 997.0).sin() * (p[1] * 761.0).sin() * (p[2] * 883.0).sin()).abs();
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

fn ball(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, id, r, .. } = *k;
    if r >= 0.15 {
        // Beach ball: six coloured gores and white caps. Triangles take the colour at
        // their centroid, so every colour boundary lies on mesh edges (no sawtooth):
        // 48 segments around (8 per 60° gore, boundaries at multiples of 60°) and 24
        // rings of 7.5°, the caps being the first two (cos 15° ≈ 0.966; every cap
        // triangle's centroid is above 0.96 r, every other one below).
        let paint = move |p: V3| {
            let a = p[1].atan2(p[0]);
            let k = ((a + PI) / TAU * 6.0) as i32;
            if p[2].abs() > r * 0.96 {
                WHITE
            } else if k % 2 == 0 {
                mat(c, MAT_GLOSSY)
            } else {
                mat(s, MAT_GLOSSY)
            }
        };
        m.sphere(&id, r, 48, &paint);
        return;
    }
    let seam = r * 0.09;
    let paint = move |p: V3| {
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

/// A cast-iron ball (a shot put): matte, no seams, its grey faintly mottled as cast
/// metal is (a fixed pattern of the surface point, the same in every frame).
fn iron_ball(m: &mut Mesh, k: &Kit) {
    let Kit { c, id, r, .. } = *k;
    let paint = move |p: V3| {
        let q = [p[0] / r, p[1] / r, p[2] / r];
        let n = (q[0] * 11.0).sin() * (q[1] * 13.0).sin() * (q[2] * 7.0).cos();
        mat(shade(c, 1.0 + 0.12 * n), MAT_PLAIN)
    };
    m.sphere(&id, r, 32, &paint);
}

fn glass_sphere(m: &mut Mesh, k: &Kit) {
    let Kit { c, id, r, .. } = *k;
    let paint = move |p: V3| mat(mix(c, WHITE, (p[2] / r).max(0.0) * 0.5), MAT_GLOSSY);
    m.sphere(&id, r, 32, &paint);
}

fn wrecking_ball(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, id, r, .. } = *k;
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

fn kettlebell(m: &mut Mesh, k: &Kit) {
    let Kit { look, c, .. } = *k;
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
