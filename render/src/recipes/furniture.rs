//! Furniture and large fixed pieces: bookcases, cabinets, TVs, doors, ladders, standing lamps.

use super::*;
use std::f32::consts::FRAC_PI_2;

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["bookcase"],
        mesh: bookcase,
    },
    Recipe {
        names: &["wardrobe", "cabinet", "dresser", "fridge"],
        mesh: wardrobe,
    },
    Recipe {
        names: &["tv"],
        mesh: tv,
    },
    Recipe {
        names: &["door"],
        mesh: door,
    },
    Recipe {
        names: &["ladder"],
        mesh: ladder,
    },
    Recipe {
        names: &["floor_lamp", "coat_stand"],
        mesh: floor_lamp,
    },
];

fn bookcase(m: &mut Mesh, k: &Kit) {
    let Kit { c, h, .. } = *k;
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

fn wardrobe(m: &mut Mesh, k: &Kit) {
    let Kit {
        look, c, s, h, id, ..
    } = *k;
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

fn tv(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
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

fn door(m: &mut Mesh, k: &Kit) {
    let Kit {
        c, s, h, id, desc, ..
    } = *k;
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

fn ladder(m: &mut Mesh, k: &Kit) {
    let Kit {
        c, s, h, id, desc, ..
    } = *k;
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

fn floor_lamp(m: &mut Mesh, k: &Kit) {
    let Kit {
        look, c, s, h, id, ..
    } = *k;
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
