//! Tools, blades and metal weights.

use super::*;
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["knife"],
        mesh: knife,
    },
    Recipe {
        names: &["scissors"],
        mesh: scissors,
    },
    Recipe {
        names: &["saw"],
        mesh: saw,
    },
    Recipe {
        names: &["glass_shard"],
        mesh: glass_shard,
    },
    Recipe {
        names: &["axe", "hammer"],
        mesh: axe,
    },
    Recipe {
        names: &["dumbbell"],
        mesh: dumbbell,
    },
    Recipe {
        names: &["anvil"],
        mesh: anvil,
    },
];

fn knife(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn scissors(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn saw(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn glass_shard(m: &mut Mesh, k: &Kit) {
    let Kit { c, h, id, .. } = *k;
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

fn axe(m: &mut Mesh, k: &Kit) {
    let Kit { look, c, s, .. } = *k;
    // Handle (first part) in the primary colour, head (second) in the secondary.
    parts_mesh(m, &look.parts[..1], c, s);
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

fn dumbbell(m: &mut Mesh, k: &Kit) {
    let Kit { look, c, s, id, .. } = *k;
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

fn anvil(m: &mut Mesh, k: &Kit) {
    let Kit { look, c, s, .. } = *k;
    parts_mesh(m, look.parts, s, mat(c, MAT_GLOSSY));
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
