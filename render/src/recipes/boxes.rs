//! Boxy things: books, boxes, devices, blocks.

use super::*;
use std::f32::consts::{FRAC_PI_2, PI};

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["book"],
        mesh: book,
    },
    Recipe {
        names: &["box"],
        mesh: box_look,
    },
    Recipe {
        names: &["laptop"],
        mesh: laptop,
    },
    Recipe {
        names: &["phone"],
        mesh: phone,
    },
    Recipe {
        names: &["remote"],
        mesh: remote,
    },
    Recipe {
        names: &["board"],
        mesh: board,
    },
    Recipe {
        names: &["block"],
        mesh: block,
    },
    Recipe {
        names: &["brick"],
        mesh: brick,
    },
    Recipe {
        names: &["toolbox"],
        mesh: toolbox,
    },
    Recipe {
        names: &["sponge"],
        mesh: sponge,
    },
];

fn book(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn box_look(m: &mut Mesh, k: &Kit) {
    let Kit {
        c, s, h, id, desc, ..
    } = *k;
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
        return;
    } else {
        s
    };
    let paint = move |p: V3| {
        // Tape along the top centre and down the ends; a label on the sides.
        if p[2] > h[2] * 0.99 && p[1].abs() < h[1] * 0.15 {
            shade(c, 1.25)
        } else if p[1].abs() > h[1] * 0.99 && p[0].abs() < h[0] * 0.45 && p[2].abs() < h[2] * 0.3 {
            sh
        } else {
            c
        }
    };
    m.boxy(&id, h, 8, &paint);
}

fn laptop(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn phone(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
    m.boxy(&id, h, 1, &solid(c));
    m.boxy(
        &Xf::at([0.0, 0.0, h[2]]),
        [h[0] * 0.92, h[1] * 0.88, 0.0008],
        1,
        &solid(mat([0.03, 0.05, 0.09, 0.0], MAT_GLOSSY)),
    );
    m.sphere(&Xf::at([h[0] * 0.8, 0.0, -h[2]]), h[1] * 0.12, 8, &solid(s));
}

fn remote(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn board(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn block(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn brick(m: &mut Mesh, k: &Kit) {
    let Kit { c, h, id, desc, .. } = *k;
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

fn toolbox(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn sponge(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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
