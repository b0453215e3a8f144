//! Kitchen and household vessels: cans, pans, plates, bowls, cups, jars, bottles, appliances.

use super::*;
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["can"],
        mesh: can,
    },
    Recipe {
        names: &["pan"],
        mesh: pan,
    },
    Recipe {
        names: &["plate"],
        mesh: plate,
    },
    Recipe {
        names: &["bowl"],
        mesh: bowl,
    },
    Recipe {
        names: &["dish"],
        mesh: dish,
    },
    Recipe {
        names: &["mug", "cup"],
        mesh: mug,
    },
    Recipe {
        names: &["disc"],
        mesh: disc,
    },
    Recipe {
        names: &["plant_pot"],
        mesh: plant_pot,
    },
    Recipe {
        names: &["pot"],
        mesh: pot,
    },
    Recipe {
        names: &["jar"],
        mesh: jar,
    },
    Recipe {
        names: &["bottle"],
        mesh: bottle,
    },
    Recipe {
        names: &["vase"],
        mesh: vase,
    },
    Recipe {
        names: &["glass"],
        mesh: glass,
    },
    Recipe {
        names: &["kettle"],
        mesh: kettle,
    },
    Recipe {
        names: &["iron"],
        mesh: iron,
    },
    Recipe {
        names: &["extinguisher"],
        mesh: extinguisher,
    },
];

fn can(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn pan(m: &mut Mesh, k: &Kit) {
    let Kit {
        c, s, h, id, desc, ..
    } = *k;
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

fn plate(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn bowl(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn dish(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn mug(m: &mut Mesh, k: &Kit) {
    let Kit {
        look, c, s, h, id, ..
    } = *k;
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

fn disc(m: &mut Mesh, k: &Kit) {
    let Kit { c, h, id, .. } = *k;
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

fn plant_pot(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn pot(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn jar(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn bottle(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, desc, .. } = *k;
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

fn vase(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn glass(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn kettle(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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
    // A dark lid on the steel body, its knob, and a lit switch on the base (switched
    // on): a kettle, not a can.
    m.cylinder(
        &Xf::at([0.0, 0.0, hh * 0.71]),
        rk * 0.62,
        hh * 0.03,
        24,
        &solid(s),
    );
    m.sphere(&Xf::at([0.0, 0.0, hh * 0.75]), rk * 0.15, 10, &solid(s));
    m.sphere(
        &Xf::at([-rk * 1.0, 0.0, -hh * 0.9]),
        rk * 0.09,
        8,
        &solid(mat([1.0, 0.45, 0.1, 0.0], MAT_EMISSIVE)),
    );
    // A big dark handle arching from the lid to the base and a thick spout rising from
    // the body's front, with steam above it: what makes a kettle read as a kettle.
    m.torus(
        &Xf::rot(0, FRAC_PI_2, [-rk * 0.8, 0.0, 0.0]),
        hh * 0.62,
        rk * 0.17,
        FRAC_PI_2,
        PI * 1.5,
        14,
        &solid(s),
    );
    m.rod(
        &id,
        [rk * 0.6, 0.0, -hh * 0.35],
        [rk * 1.25, 0.0, hh * 0.2],
        rk * 0.24,
        12,
        &solid(mat(c, MAT_GLOSSY)),
    );
    m.rod(
        &id,
        [rk * 1.2, 0.0, hh * 0.15],
        [rk * 1.5, 0.0, hh * 0.5],
        rk * 0.15,
        10,
        &solid(mat(c, MAT_GLOSSY)),
    );
    let steam = solid(mat([0.93, 0.95, 0.97, 0.0], MAT_EMISSIVE));
    for (i, r) in [0.13f32, 0.17, 0.21].iter().enumerate() {
        let up = hh * (0.72 + 0.3 * i as f32);
        m.sphere(
            &Xf::at([rk * (1.55 + 0.12 * i as f32), 0.0, up]),
            rk * r,
            10,
            &steam,
        );
    }
}

fn iron(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn extinguisher(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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
