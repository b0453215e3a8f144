//! Wall and ceiling fixtures: frames, clocks, shelves, fans, lamps, panels, chandeliers.

use super::*;
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["frame", "mirror", "whiteboard"],
        mesh: frame,
    },
    Recipe {
        names: &["clock"],
        mesh: clock,
    },
    Recipe {
        names: &["shelf", "rack"],
        mesh: shelf,
    },
    Recipe {
        names: &["fan"],
        mesh: fan,
    },
    Recipe {
        names: &["lamp"],
        mesh: lamp,
    },
    Recipe {
        names: &["panel", "vent"],
        mesh: panel,
    },
    Recipe {
        names: &["light_fixture"],
        mesh: light_fixture,
    },
    Recipe {
        names: &["smoke_detector"],
        mesh: smoke_detector,
    },
    Recipe {
        names: &["chandelier"],
        mesh: chandelier,
    },
];

fn frame(m: &mut Mesh, k: &Kit) {
    let Kit {
        look,
        c,
        s,
        h,
        id,
        desc,
        ..
    } = *k;
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
    // A mirror's sheen is a smooth gradient that changes in every cell (so no grid line
    // can go): 12 cells per side instead of 24 change its frames by at most 3 levels and
    // its hanging_fall scenes render 14% faster (docs/rendering.md, "Seventh round").
    let div = if recipe == "mirror" { 12 } else { 24 };
    for sy in [-1.0f32, 1.0] {
        m.boxy(
            &Xf::at([0.0, sy * h[1] * 0.65, 0.0]),
            [h[0] - b, h[1] * 0.05, h[2] - b],
            div,
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

fn clock(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn shelf(m: &mut Mesh, k: &Kit) {
    let Kit {
        look,
        c,
        s,
        h,
        id,
        desc,
        ..
    } = *k;
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

fn fan(m: &mut Mesh, k: &Kit) {
    let Kit {
        look, c, s, h, id, ..
    } = *k;
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

fn lamp(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn panel(m: &mut Mesh, k: &Kit) {
    let Kit {
        look, c, s, h, id, ..
    } = *k;
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

fn light_fixture(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn smoke_detector(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn chandelier(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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
