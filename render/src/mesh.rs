//! Triangle soup built from primitives (box, sphere, cylinder, frustum, capsule, torus),
//! each painted by a per-face colour function of the local point: the "procedural
//! textures" of the recipes (seams, stripes, labels) are just such painters.

use bytemuck::{Pod, Zeroable};

pub type V3 = [f32; 3];
/// RGB plus a material code in `a` (see `MAT_*`).
pub type Rgba = [f32; 4];

pub const MAT_PLAIN: f32 = 0.0;
/// Floor: a tile/plank pattern from the world position.
pub const MAT_FLOOR: f32 = 1.0;
/// Glossy (strong specular highlight): glass, metal, plastic.
pub const MAT_GLOSSY: f32 = 2.0;
/// Emissive (light tubes, bulbs): ignores shading.
pub const MAT_EMISSIVE: f32 = 3.0;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Vertex {
    pub pos: V3,
    pub normal: V3,
    pub color: Rgba,
}

/// Parses `#rrggbb` (falls back to mid grey).
pub fn hex(s: &str) -> Rgba {
    let s = s.trim().trim_start_matches('#');
    let p = |i: usize| {
        s.get(i..i + 2)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .map(|v| srgb_to_linear(v as f32 / 255.0))
            .unwrap_or(0.22)
    };
    if s.len() != 6 {
        return [0.22, 0.22, 0.22, MAT_PLAIN];
    }
    [p(0), p(2), p(4), MAT_PLAIN]
}

pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub fn mat(c: Rgba, m: f32) -> Rgba {
    [c[0], c[1], c[2], m]
}

pub fn shade(c: Rgba, k: f32) -> Rgba {
    [
        (c[0] * k).min(1.0),
        (c[1] * k).min(1.0),
        (c[2] * k).min(1.0),
        c[3],
    ]
}

pub fn mix(a: Rgba, b: Rgba, t: f32) -> Rgba {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
        a[3],
    ]
}

/// A rigid transform: rotation (columns are the local axes) and translation.
#[derive(Clone, Copy, Debug)]
pub struct Xf {
    pub r: [V3; 3],
    pub t: V3,
}

impl Xf {
    pub const ID: Xf = Xf {
        r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    pub fn at(t: V3) -> Xf {
        Xf { t, ..Xf::ID }
    }

    /// From a unit quaternion `[x, y, z, w]` and a translation.
    pub fn from_quat(q: [f64; 4], t: [f64; 3]) -> Xf {
        let [x, y, z, w] = q;
        let c0 = [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + w * z),
            2.0 * (x * z - w * y),
        ];
        let c1 = [
            2.0 * (x * y - w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + w * x),
        ];
        let c2 = [
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        ];
        let f = |v: [f64; 3]| v.map(|a| a as f32);
        Xf {
            r: [f(c0), f(c1), f(c2)],
            t: f(t),
        }
    }

    /// Rotation about a local axis (0 = x, 1 = y, 2 = z) by `angle`, then translation.
    pub fn rot(axis: usize, angle: f32, t: V3) -> Xf {
        let (s, c) = angle.sin_cos();
        let r = match axis {
            0 => [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]],
            1 => [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]],
            _ => [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]],
        };
        Xf { r, t }
    }

    pub fn apply(&self, p: V3) -> V3 {
        let v = self.rotate(p);
        [v[0] + self.t[0], v[1] + self.t[1], v[2] + self.t[2]]
    }

    pub fn rotate(&self, p: V3) -> V3 {
        let r = &self.r;
        [
            r[0][0] * p[0] + r[1][0] * p[1] + r[2][0] * p[2],
            r[0][1] * p[0] + r[1][1] * p[1] + r[2][1] * p[2],
            r[0][2] * p[0] + r[1][2] * p[1] + r[2][2] * p[2],
        ]
    }

    /// `self ∘ inner`: first `inner`, then `self`.
    pub fn then(&self, inner: &Xf) -> Xf {
        Xf {
            r: [
                self.rotate(inner.r[0]),
                self.rotate(inner.r[1]),
                self.rotate(inner.r[2]),
            ],
            t: self.apply(inner.t),
        }
    }
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn normalize(a: V3) -> V3 {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt().max(1e-12);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The mean of a quad's corners (where its painter is asked for the colour).
fn centroid(p: &[V3; 4]) -> V3 {
    [
        (p[0][0] + p[1][0] + p[2][0] + p[3][0]) / 4.0,
        (p[0][1] + p[1][1] + p[2][1] + p[3][1]) / 4.0,
        (p[0][2] + p[1][2] + p[2][2] + p[3][2]) / 4.0,
    ]
}

/// The grid lines (`0..=cells[e]`) along box edge direction `e` that some face's colour
/// changes across: a face (axis, sign, colours over `cells[u]` × `cells[v]`, u and v the
/// axes after `axis`) lying along `e` has line k when two of its cells on either side
/// of k differ. The outer lines are always kept.
fn kept_lines(faces: &[(usize, f32, Vec<Rgba>)], cells: [usize; 3], e: usize) -> Vec<usize> {
    let same = |a: &Rgba, b: &Rgba| a.map(f32::to_bits) == b.map(f32::to_bits);
    let changes_across = |k: usize| {
        faces.iter().any(|(axis, _, colours)| {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let (nu, nv) = (cells[u], cells[v]);
            if e == u {
                (0..nv).any(|j| !same(&colours[(k - 1) * nv + j], &colours[k * nv + j]))
            } else if e == v {
                (0..nu).any(|i| !same(&colours[i * nv + k - 1], &colours[i * nv + k]))
            } else {
                false
            }
        })
    };
    (0..=cells[e])
        .filter(|&k| k == 0 || k == cells[e] || changes_across(k))
        .collect()
}

/// A painter: colour of the face around a local point (the face's centroid).
pub type Paint<'a> = &'a dyn Fn(V3) -> Rgba;

/// A mesh under construction; primitives are added in a local frame `xf`.
#[derive(Default, Clone, Debug)]
pub struct Mesh {
    pub verts: Vec<Vertex>,
}

impl Mesh {
    pub fn new() -> Mesh {
        Mesh::default()
    }

    pub fn append(&mut self, other: &Mesh) {
        self.verts.extend_from_slice(&other.verts);
    }

    /// Copies the mesh through a transform into `out`.
    pub fn transformed_into(&self, xf: &Xf, out: &mut Vec<Vertex>) {
        out.extend(self.verts.iter().map(|v| Vertex {
            pos: xf.apply(v.pos),
            normal: xf.rotate(v.normal),
            color: v.color,
        }));
    }

    /// One triangle in local coordinates with per-vertex smooth normals (`None`: flat).
    fn tri(&mut self, xf: &Xf, p: [V3; 3], n: Option<[V3; 3]>, paint: Paint) {
        let c = [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
            (p[0][2] + p[1][2] + p[2][2]) / 3.0,
        ];
        let color = paint(c);
        let flat = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        let n = n.unwrap_or([flat; 3]);
        for k in 0..3 {
            self.verts.push(Vertex {
                pos: xf.apply(p[k]),
                normal: normalize(xf.rotate(n[k])),
                color,
            });
        }
    }

    fn quad(&mut self, xf: &Xf, p: [V3; 4], n: Option<[V3; 4]>, paint: Paint) {
        let one = |_: V3| paint(centroid(&p));
        self.tri(xf, [p[0], p[1], p[2]], n.map(|n| [n[0], n[1], n[2]]), &one);
        self.tri(xf, [p[0], p[2], p[3]], n.map(|n| [n[0], n[2], n[3]]), &one);
    }

    /// Axis-aligned box of half extents `h` centred at the local origin; faces are split
    /// into a grid of `div` cells per side so painters can draw patterns. A cell takes
    /// the painter's colour at its centre. Grid lines across which no face's colour
    /// changes are left out ([`kept_lines`]): a plain box is 12 triangles, and every
    /// face still meets its neighbours vertex to vertex (no T-junction, so no pixel
    /// cracks along edges).
    pub fn boxy(&mut self, xf: &Xf, h: V3, div: usize, paint: Paint) {
        // `div` cells along the longest edge, proportionally fewer along shorter ones
        // (a thin panel's rim needs no grid: it only carries the paint's resolution).
        let longest = h[0].max(h[1]).max(h[2]).max(1e-9);
        let cells = h.map(|e| ((div.max(1) as f32 * e / longest).ceil() as usize).max(1));
        let at = |axis: usize, k: usize| -1.0 + 2.0 * k as f32 / cells[axis] as f32;
        // Face (axis, sign)'s quad over grid lines i0..i1 along u and j0..j1 along v.
        let face_quad = |axis: usize, sign: f32, [i0, i1, j0, j1]: [usize; 4]| {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let pt = |a: f32, b: f32| {
                let mut p = [0.0; 3];
                p[axis] = sign * h[axis];
                p[u] = a * h[u];
                p[v] = b * h[v];
                p
            };
            let (a0, a1, b0, b1) = (at(u, i0), at(u, i1), at(v, j0), at(v, j1));
            let mut q = [pt(a0, b0), pt(a1, b0), pt(a1, b1), pt(a0, b1)];
            if sign < 0.0 {
                q.reverse();
            }
            q
        };
        // Each face's cell colours, `i * nv + j`.
        let faces: Vec<(usize, f32, Vec<Rgba>)> = (0..3)
            .flat_map(|axis| [-1.0f32, 1.0].map(|sign| (axis, sign)))
            .map(|(axis, sign)| {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let colours = (0..cells[u])
                    .flat_map(|i| (0..cells[v]).map(move |j| [i, i + 1, j, j + 1]))
                    .map(|r| paint(centroid(&face_quad(axis, sign, r))))
                    .collect();
                (axis, sign, colours)
            })
            .collect();
        let lines: Vec<Vec<usize>> = (0..3).map(|e| kept_lines(&faces, cells, e)).collect();
        for (axis, sign, colours) in &faces {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for iw in lines[u].windows(2) {
                for jw in lines[v].windows(2) {
                    let colour = colours[iw[0] * cells[v] + jw[0]];
                    let q = face_quad(*axis, *sign, [iw[0], iw[1], jw[0], jw[1]]);
                    self.quad(xf, q, None, &|_| colour);
                }
            }
        }
    }

    /// Ellipsoid with semi-axes `r` (a sphere when equal), `seg` segments around z.
    pub fn ellipsoid(&mut self, xf: &Xf, r: V3, seg: usize, paint: Paint) {
        let rings = (seg / 2).max(3);
        let pt = |i: usize, j: usize| {
            let th = std::f32::consts::PI * i as f32 / rings as f32;
            let ph = std::f32::consts::TAU * j as f32 / seg as f32;
            let d = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            (
                [d[0] * r[0], d[1] * r[1], d[2] * r[2]],
                normalize([d[0] / r[0], d[1] / r[1], d[2] / r[2]]),
            )
        };
        for i in 0..rings {
            for j in 0..seg {
                let (a, na) = pt(i, j);
                let (b, nb) = pt(i + 1, j);
                let (c, nc) = pt(i + 1, j + 1);
                let (d, nd) = pt(i, j + 1);
                if i != 0 {
                    self.tri(xf, [a, b, d], Some([na, nb, nd]), paint);
                }
                if i != rings - 1 {
                    self.tri(xf, [d, b, c], Some([nd, nb, nc]), paint);
                }
            }
        }
    }

    pub fn sphere(&mut self, xf: &Xf, r: f32, seg: usize, paint: Paint) {
        self.ellipsoid(xf, [r, r, r], seg, paint);
    }

    /// Frustum along local z from `-hh` (radius `r0`) to `+hh` (radius `r1`), capped
    /// where `caps` says (bottom, top).
    pub fn frustum(
        &mut self,
        xf: &Xf,
        r0: f32,
        r1: f32,
        hh: f32,
        seg: usize,
        caps: (bool, bool),
        paint: Paint,
    ) {
        let slope = (r0 - r1) / (2.0 * hh);
        for j in 0..seg {
            let a0 = std::f32::consts::TAU * j as f32 / seg as f32;
            let a1 = std::f32::consts::TAU * (j + 1) as f32 / seg as f32;
            let (s0, c0) = a0.sin_cos();
            let (s1, c1) = a1.sin_cos();
            let n0 = normalize([c0, s0, slope]);
            let n1 = normalize([c1, s1, slope]);
            let q = [
                [r0 * c0, r0 * s0, -hh],
                [r0 * c1, r0 * s1, -hh],
                [r1 * c1, r1 * s1, hh],
                [r1 * c0, r1 * s0, hh],
            ];
            self.quad(xf, q, Some([n0, n1, n1, n0]), paint);
            if caps.0 && r0 > 0.0 {
                self.tri(
                    xf,
                    [
                        [0.0, 0.0, -hh],
                        [r0 * c1, r0 * s1, -hh],
                        [r0 * c0, r0 * s0, -hh],
                    ],
                    None,
                    paint,
                );
            }
            if caps.1 && r1 > 0.0 {
                self.tri(
                    xf,
                    [
                        [0.0, 0.0, hh],
                        [r1 * c0, r1 * s0, hh],
                        [r1 * c1, r1 * s1, hh],
                    ],
                    None,
                    paint,
                );
            }
        }
    }

    pub fn cylinder(&mut self, xf: &Xf, r: f32, hh: f32, seg: usize, paint: Paint) {
        self.frustum(xf, r, r, hh, seg, (true, true), paint);
    }

    /// Annulus in the plane z = `z` between radii `ri` and `ro`, facing +z (or -z).
    pub fn ring(&mut self, xf: &Xf, ri: f32, ro: f32, z: f32, up: bool, seg: usize, paint: Paint) {
        for j in 0..seg {
            let a0 = std::f32::consts::TAU * j as f32 / seg as f32;
            let a1 = std::f32::consts::TAU * (j + 1) as f32 / seg as f32;
            let (s0, c0) = a0.sin_cos();
            let (s1, c1) = a1.sin_cos();
            let mut q = [
                [ri * c0, ri * s0, z],
                [ro * c0, ro * s0, z],
                [ro * c1, ro * s1, z],
                [ri * c1, ri * s1, z],
            ];
            if !up {
                q.reverse();
            }
            self.quad(xf, q, None, paint);
        }
    }

    /// Open vessel along z: outer wall (`r0` bottom → `r1` top), inner wall `wall` thinner,
    /// closed bottom of thickness `base`, rim at the top.
    #[allow(clippy::too_many_arguments)]
    pub fn vessel(
        &mut self,
        xf: &Xf,
        r0: f32,
        r1: f32,
        hh: f32,
        wall: f32,
        base: f32,
        seg: usize,
        outside: Paint,
        inside: Paint,
    ) {
        self.frustum(xf, r0, r1, hh, seg, (true, false), outside);
        let ihh = hh - base / 2.0;
        let inner = Xf::at([0.0, 0.0, base / 2.0]);
        let ixf = xf.then(&inner);
        let (ri0, ri1) = ((r0 - wall).max(0.001), (r1 - wall).max(0.001));
        // Inner wall faces inwards: draw it with reversed orientation by flipping radii
        // normals through a mirrored frustum (shading uses two-sided normals anyway).
        self.frustum(&ixf, ri0, ri1, ihh, seg, (true, false), inside);
        self.ring(xf, ri1, r1, hh, true, seg, outside);
    }

    /// Capsule along z: cylinder half height `hh` plus hemispherical caps of radius `r`.
    pub fn capsule(&mut self, xf: &Xf, r: f32, hh: f32, seg: usize, paint: Paint) {
        self.frustum(xf, r, r, hh, seg, (false, false), paint);
        self.sphere(&xf.then(&Xf::at([0.0, 0.0, hh])), r, seg, paint);
        self.sphere(&xf.then(&Xf::at([0.0, 0.0, -hh])), r, seg, paint);
    }

    /// Torus in the local xy plane (major radius `big`, tube radius `small`), covering the
    /// angle range `a0..a1` (radians, from +x toward +y).
    #[allow(clippy::too_many_arguments)]
    pub fn torus(
        &mut self,
        xf: &Xf,
        big: f32,
        small: f32,
        a0: f32,
        a1: f32,
        seg: usize,
        paint: Paint,
    ) {
        let tube = 8;
        let pt = |i: usize, j: usize| {
            let u = a0 + (a1 - a0) * i as f32 / seg as f32;
            let v = std::f32::consts::TAU * j as f32 / tube as f32;
            let (su, cu) = u.sin_cos();
            let (sv, cv) = v.sin_cos();
            let n = [cv * cu, cv * su, sv];
            (
                [(big + small * cv) * cu, (big + small * cv) * su, small * sv],
                n,
            )
        };
        for i in 0..seg {
            for j in 0..tube {
                let (a, na) = pt(i, j);
                let (b, nb) = pt(i + 1, j);
                let (c, nc) = pt(i + 1, j + 1);
                let (d, nd) = pt(i, j + 1);
                self.tri(xf, [a, b, c], Some([na, nb, nc]), paint);
                self.tri(xf, [a, c, d], Some([na, nc, nd]), paint);
            }
        }
    }

    /// A thin cylinder from `a` to `b` (local points), radius `r`.
    pub fn rod(&mut self, xf: &Xf, a: V3, b: V3, r: f32, seg: usize, paint: Paint) {
        let d = sub(b, a);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if len < 1e-5 {
            return;
        }
        let z = [d[0] / len, d[1] / len, d[2] / len];
        let helper = if z[2].abs() < 0.9 {
            [0.0, 0.0, 1.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        let x = normalize(cross(helper, z));
        let y = cross(z, x);
        let mid = [
            (a[0] + b[0]) / 2.0,
            (a[1] + b[1]) / 2.0,
            (a[2] + b[2]) / 2.0,
        ];
        let local = Xf {
            r: [x, y, z],
            t: mid,
        };
        self.cylinder(&xf.then(&local), r, len / 2.0, seg, paint);
    }

    /// A flat polygon (fan) in the local xy plane at z, with thickness `2 * hz`.
    pub fn slab(&mut self, xf: &Xf, outline: &[[f32; 2]], hz: f32, paint: Paint) {
        let n = outline.len();
        for i in 1..n.saturating_sub(1) {
            let (a, b, c) = (outline[0], outline[i], outline[i + 1]);
            self.tri(
                xf,
                [[a[0], a[1], hz], [b[0], b[1], hz], [c[0], c[1], hz]],
                None,
                paint,
            );
            self.tri(
                xf,
                [[a[0], a[1], -hz], [c[0], c[1], -hz], [b[0], b[1], -hz]],
                None,
                paint,
            );
        }
        for i in 0..n {
            let (a, b) = (outline[i], outline[(i + 1) % n]);
            self.quad(
                xf,
                [
                    [a[0], a[1], -hz],
                    [b[0], b[1], -hz],
                    [b[0], b[1], hz],
                    [a[0], a[1], hz],
                ],
                None,
                paint,
            );
        }
    }
}

/// A constant painter.
pub fn solid(c: Rgba) -> impl Fn(V3) -> Rgba {
    move |_| c
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    const H: V3 = [0.3, 0.1, 0.45];
    const RED: Rgba = [0.8, 0.1, 0.1, MAT_PLAIN];
    const GREY: Rgba = [0.5, 0.5, 0.5, MAT_PLAIN];

    /// Red where x > 0 and y < 0.02: on a 12-cell grid (8 × 3 × 12 cells) the colour
    /// changes across x line 4 and y line 2 only.
    fn half_red(p: V3) -> Rgba {
        if p[0] > 0.0 && p[1] < 0.02 {
            RED
        } else {
            GREY
        }
    }

    /// The face (axis, sign) a box triangle lies in.
    fn face_of(t: &[Vertex]) -> (usize, bool) {
        (0..3)
            .find_map(|a| {
                let c = t[0].pos[a];
                (c.abs() == H[a] && t.iter().all(|v| v.pos[a] == c)).then_some((a, c > 0.0))
            })
            .expect("a box triangle lies in a face")
    }

    #[test]
    fn a_plain_box_is_twelve_triangles_whatever_its_grid() {
        let mut m = Mesh::new();
        m.boxy(&Xf::ID, H, 24, &solid(GREY));
        assert_eq!(m.verts.len(), 36);
    }

    #[test]
    fn a_painted_box_keeps_every_cell_colour_with_only_the_lines_it_needs() {
        let mut m = Mesh::new();
        m.boxy(&Xf::ID, H, 12, &half_red);
        // Faces ±x: 2 × 1 quads, ±y: 1 × 2, ±z: 2 × 2 — 16 quads, 32 triangles.
        assert_eq!(m.verts.len(), 96);
        let cells = [8usize, 3, 12];
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for sign in [-1.0f32, 1.0] {
                for i in 0..cells[u] {
                    for j in 0..cells[v] {
                        // The centre of fine cell (i, j) and the triangle drawn over it.
                        let centre = |k: usize, a: usize| {
                            H[a] * (-1.0 + (2 * k + 1) as f32 / cells[a] as f32)
                        };
                        let mut p = [0.0; 3];
                        p[axis] = sign * H[axis];
                        p[u] = centre(i, u);
                        p[v] = centre(j, v);
                        let inside = |t: &[Vertex]| {
                            let lo = |a: usize| t.iter().map(|q| q.pos[a]).fold(f32::MAX, f32::min);
                            let hi = |a: usize| t.iter().map(|q| q.pos[a]).fold(f32::MIN, f32::max);
                            face_of(t) == (axis, sign > 0.0)
                                && [u, v].iter().all(|&a| lo(a) <= p[a] && p[a] <= hi(a))
                        };
                        let t = m.verts.chunks(3).find(|t| inside(t)).expect("covered");
                        assert_eq!(t[0].color, half_red(p), "face {axis}{sign} cell {i},{j}");
                    }
                }
            }
        }
    }

    #[test]
    fn neighbouring_faces_share_every_vertex_along_their_edge() {
        let mut m = Mesh::new();
        m.boxy(&Xf::ID, H, 12, &half_red);
        // Box edge (the two coordinates at ±h) → face → the vertices on that edge.
        type Face = (usize, bool);
        let mut edges: BTreeMap<Vec<Face>, BTreeMap<Face, Vec<u32>>> = BTreeMap::new();
        for t in m.verts.chunks(3) {
            let face = face_of(t);
            for q in t {
                let at_h: Vec<(usize, bool)> = (0..3)
                    .filter(|&a| q.pos[a].abs() == H[a])
                    .map(|a| (a, q.pos[a] > 0.0))
                    .collect();
                // On every edge whose two coordinates it has at ±h (a corner: three).
                for x in 0..at_h.len() {
                    for y in x + 1..at_h.len() {
                        let edge = vec![at_h[x], at_h[y]];
                        if !edge.contains(&face) {
                            continue; // a face meeting the edge only at its end
                        }
                        let free = 3 - at_h[x].0 - at_h[y].0;
                        let on = edges.entry(edge).or_default().entry(face).or_default();
                        on.push(q.pos[free].to_bits());
                    }
                }
            }
        }
        assert_eq!(edges.len(), 12);
        for (edge, faces) in edges {
            let mut sets: Vec<Vec<u32>> = faces.into_values().collect();
            for s in &mut sets {
                s.sort();
                s.dedup();
            }
            assert_eq!(sets.len(), 2, "edge {edge:?}");
            assert_eq!(sets[0], sets[1], "T-junction along edge {edge:?}");
        }
    }
}
