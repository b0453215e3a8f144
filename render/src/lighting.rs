//! Lighting: the spec's sun and ambient in display range, and the sun's orthographic
//! shadow-map projection covering the room.

use super::camera::to_cols;
use super::gpu;
use rh_physics::spec::vec3::{cross, dot, norm, scale, sub};
use rh_physics::spec::{SceneSpec, Vec3};

/// A scene's light as the shader gets it.
pub(super) struct Lighting {
    /// The sun's shadow-map view-projection.
    pub light_vp: [[f32; 4]; 4],
    pub sun_dir: [f32; 4],
    pub sun_color: [f32; 4],
    pub ambient: [f32; 4],
    /// Distance (m) from a shadow volume within which shading may depend on it.
    pub shadow_reach: f64,
    /// The same in the sun's clip space (x and y alike): how far from a caster's
    /// footprint in the shadow map a point's shading may depend on it: the lookup point's
    /// largest normal offset (`SHADOW_NORMAL_OFFSET` + `SHADOW_SLOPE_OFFSET` texels, at
    /// most that far along either clip axis), and the 3×3 bilinear taps, which read
    /// texels whose centres lie within 2 texels of it on each axis; half a texel spare
    /// for rounding (`tiles::SurfaceTiles`).
    pub shadow_reach_light: f64,
}

impl Lighting {
    /// The spec's sun (scaled into display range) and ambient.
    pub(super) fn of(spec: &SceneSpec) -> Lighting {
        let room = &spec.room;
        let l = &spec.lighting;
        let mut dir = l.sun_direction;
        let n = norm(dir);
        dir = if n > 1e-9 {
            scale(dir, 1.0 / n)
        } else {
            [0.3, 0.2, -0.93]
        };
        let tint = color_temperature(l.color_temperature_k);
        let sun = (l.sun_intensity * 0.25) as f32;
        let amb = (l.ambient * 1.3) as f32;
        let (light_vp, light_radius) = light_matrix(dir, room.size, room.ceiling_height);
        // How far from a moving body's shadow volume a static pixel's shading can still
        // see it: the shader's normal offset (constant plus slope-scaled), the filter's
        // footprint (with a texel to spare), and a centimetre of slack.
        let texel = 2.0 * light_radius / gpu::SHADOW_SIZE as f64;
        let shadow_reach =
            SHADOW_NORMAL_OFFSET + (SHADOW_SLOPE_OFFSET + SHADOW_PCF_TEXELS + 1.0) * texel + 0.01;
        // The light matrix scales x and y by 1 / light_radius: a texel is 2 / SHADOW_SIZE.
        let texel_clip = 2.0 / gpu::SHADOW_SIZE as f64;
        let shadow_reach_light =
            (SHADOW_NORMAL_OFFSET + SHADOW_SLOPE_OFFSET * texel) / light_radius + 2.5 * texel_clip;
        Lighting {
            light_vp,
            sun_dir: [dir[0] as f32, dir[1] as f32, dir[2] as f32, 0.0],
            sun_color: [tint[0] * sun, tint[1] * sun, tint[2] * sun, 0.0],
            ambient: [
                amb * (0.9 + 0.1 * tint[0]),
                amb * (0.9 + 0.1 * tint[1]),
                amb * (0.9 + 0.1 * tint[2]),
                0.0,
            ],
            shadow_reach,
            shadow_reach_light,
        }
    }
}

fn color_temperature(k: f64) -> [f32; 3] {
    let t = ((k - 3000.0) / 4000.0).clamp(0.0, 1.0) as f32;
    let warm = [1.0, 0.82, 0.62];
    let cool = [0.92, 0.96, 1.0];
    [0, 1, 2].map(|i| warm[i] + (cool[i] - warm[i]) * t)
}

/// The sun's orthographic view-projection covering the room (and a margin) along its
/// direction, and its half-width (m).
fn light_matrix(dir: Vec3, size: [f64; 2], ceiling: f64) -> ([[f32; 4]; 4], f64) {
    let center = [0.0, 0.0, ceiling / 2.0];
    let radius = 0.5 * (size[0].hypot(size[1])).hypot(ceiling) + 0.5;
    let eye = sub(center, scale(dir, radius + 2.0));
    let hint = if dir[2].abs() > 0.95 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let r = cross(dir, hint);
    let r = scale(r, 1.0 / norm(r));
    let u = cross(r, dir);
    let depth = 2.0 * radius + 4.0;
    let rows = [
        [
            r[0] / radius,
            r[1] / radius,
            r[2] / radius,
            -dot(r, eye) / radius,
        ],
        [
            u[0] / radius,
            u[1] / radius,
            u[2] / radius,
            -dot(u, eye) / radius,
        ],
        [
            dir[0] / depth,
            dir[1] / depth,
            dir[2] / depth,
            -dot(dir, eye) / depth,
        ],
        [0.0, 0.0, 0.0, 1.0],
    ];
    (to_cols(rows), radius)
}

/// The shader's shadow lookup offset along the surface normal (m; `shadow_factor`).
const SHADOW_NORMAL_OFFSET: f64 = 0.005;
/// The shader's largest slope-scaled extra normal offset, in shadow-map texels (on
/// surfaces the light grazes).
const SHADOW_SLOPE_OFFSET: f64 = 1.0;
/// How far (texels) the shader's filter reads from the lookup point: a 3×3 grid of
/// bilinear taps one texel apart, each reading one more texel: 2 texels per axis,
/// 2·√2 along the diagonal, which 3 bounds.
const SHADOW_PCF_TEXELS: f64 = 3.0;
