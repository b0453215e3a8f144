//! Soft and stuffed things: plush toys, pillows, sacks, punching bags, tyres.

use super::*;
use std::f32::consts::TAU;

/// The recipes of this file: names (the catalog's `appearance.recipe`) and their mesher.
pub(super) const RECIPES: &[Recipe] = &[
    Recipe {
        names: &["plush"],
        mesh: plush,
    },
    Recipe {
        names: &["pillow", "sack"],
        mesh: pillow,
    },
    Recipe {
        names: &["punching_bag"],
        mesh: punching_bag,
    },
    Recipe {
        names: &["tyre"],
        mesh: tyre,
    },
];

fn plush(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, .. } = *k;
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

fn pillow(m: &mut Mesh, k: &Kit) {
    let Kit {
        look, c, s, h, id, ..
    } = *k;
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

fn punching_bag(m: &mut Mesh, k: &Kit) {
    let Kit { c, s, h, id, .. } = *k;
    let (rp, hz) = (h[0], h[2]);
    let hh = (hz - rp).max(0.0);
    let leather = mat(c, MAT_GLOSSY);
    // Red leather body with a dark band, and a dark end cap on each hemisphere.
    // Triangles take the colour at their centroid, so boundaries lie on mesh edges:
    // the body is one band of quads (the band is a ring of its own), and the caps are
    // the hemispheres' first two rings of 15° (24 segments: centroids above 0.85 r).
    m.frustum(&id, rp, rp, hh, 24, (false, false), &solid(leather));
    let band = hz * 0.35;
    if band + rp * 0.15 < hh {
        m.frustum(
            &id.then(&Xf::at([0.0, 0.0, band])),
            rp * 1.01,
            rp * 1.01,
            hz * 0.03,
            24,
            (false, false),
            &solid(s),
        );
    }
    for sz in [-1.0f32, 1.0] {
        let cap = move |p: V3| if p[2] * sz > rp * 0.85 { s } else { leather };
        m.sphere(&id.then(&Xf::at([0.0, 0.0, sz * hh])), rp, 24, &cap);
    }
}

fn tyre(m: &mut Mesh, k: &Kit) {
    let Kit { c, h, id, .. } = *k;
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
