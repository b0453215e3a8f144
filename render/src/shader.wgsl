struct U {
    view_proj: mat4x4<f32>,
    light_vp: mat4x4<f32>,
    cam_pos: vec4<f32>,
    // Direction the sun light travels (unit), w unused.
    sun_dir: vec4<f32>,
    sun_color: vec4<f32>,
    // rgb ambient; w > 0.5: unlit diagnostic colours.
    ambient: vec4<f32>,
    // rgb: clear colour, drawn by the fill pass.
    background: vec4<f32>,
    // The fill pass's rectangles in normalised device coordinates (x0, y0, x1, y1),
    // one per instance.
    fill_rects: array<vec4<f32>, 32>,
};

@group(0) @binding(0) var<uniform> u: U;
@group(0) @binding(1) var shadow_tex: texture_depth_2d;
@group(0) @binding(2) var shadow_smp: sampler_comparison;
// Model textures (render/src/models): one image per layer.
@group(0) @binding(3) var model_tex: texture_2d_array<f32>;
@group(0) @binding(4) var model_smp: sampler;

struct VIn {
    @location(0) pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
};

// Centroid interpolation: a multisampled edge pixel is shaded at a point on its
// triangle, never extrapolated past it (which would look up shadows elsewhere).
// Invariant: the depth pre-pass and the shading pass must compute identical depths.
struct VOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) world: vec3<f32>,
    @location(1) @interpolate(perspective, centroid) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
};

@vertex
fn vs_main(v: VIn) -> VOut {
    var o: VOut;
    o.clip = u.view_proj * vec4<f32>(v.pos, 1.0);
    o.world = v.pos;
    o.normal = v.normal;
    o.color = v.color;
    return o;
}

// A rectangle (two triangles) at the far plane (depth 1): clears what it covers to the
// background. Its own edges bound it, not only the scissor: a CPU rasterizer's
// multisampled scissor test may let samples just outside the rectangle through.
@vertex
fn vs_fill(
    @builtin(vertex_index) i: u32,
    @builtin(instance_index) rect: u32,
) -> @builtin(position) vec4<f32> {
    let r = u.fill_rects[rect];
    let corner = array<vec2<u32>, 6>(
        vec2<u32>(0u, 0u), vec2<u32>(1u, 0u), vec2<u32>(0u, 1u),
        vec2<u32>(0u, 1u), vec2<u32>(1u, 0u), vec2<u32>(1u, 1u),
    )[i];
    let x = select(r.x, r.z, corner.x == 1u);
    let y = select(r.y, r.w, corner.y == 1u);
    return vec4<f32>(x, y, 1.0, 1.0);
}

@fragment
fn fs_fill() -> @location(0) vec4<f32> {
    return vec4<f32>(u.background.rgb, 1.0);
}

@vertex
fn vs_shadow(v: VIn) -> @builtin(position) vec4<f32> {
    return u.light_vp * vec4<f32>(v.pos, 1.0);
}

// Shadow lookup. Must agree with lighting.rs, whose `shadow_reach` bounds how far from
// a caster's shadow volume a pixel's shading can depend on it: the normal offset (at
// most SHADOW_NORMAL_OFFSET + SHADOW_SLOPE_OFFSET texels) plus the filter's footprint
// (SHADOW_PCF_TEXELS).
fn shadow_factor(world: vec3<f32>, n: vec3<f32>, ndl: f32) -> f32 {
    let size = vec2<f32>(textureDimensions(shadow_tex));
    // The light matrix's rows: right / radius, up / radius, sun direction / depth range.
    let r0 = vec3<f32>(u.light_vp[0].x, u.light_vp[1].x, u.light_vp[2].x);
    let r1 = vec3<f32>(u.light_vp[0].y, u.light_vp[1].y, u.light_vp[2].y);
    let r2 = vec3<f32>(u.light_vp[0].z, u.light_vp[1].z, u.light_vp[2].z);
    // World size of a shadow-map texel: the orthographic light matrix scales x by
    // 1 / half-width.
    let sx = length(r0);
    let texel = 2.0 / (sx * size.x);
    // Normal offset: 5 mm plus up to one texel on surfaces the light grazes. Kept small
    // so that the lookup point is not lifted past a caster a few centimetres above the
    // receiver (a board resting on a table: larger offsets showed a comb of stripes
    // there); the receiver-plane depth below keeps lit surfaces free of acne.
    let sin_t = sqrt(max(1.0 - ndl * ndl, 0.0));
    let lp = u.light_vp * vec4<f32>(world + n * (0.005 + texel * sin_t), 1.0);
    let ndc = lp.xyz / lp.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0 || ndc.z > 1.0) {
        return 1.0;
    }
    // Receiver-plane depth: the surface's own light depth at each tap, from its normal
    // in the light's clip space. With the rows r0 = right / R, r1 = up / R, r2 = sun / D
    // the plane n·dp = 0 has dz/dx = -(n·r0) / (n·r2) · |r2|² / |r0|² (and dz/dy with
    // r1), so the wide filter compares each tap against the receiver's depth there, not
    // the centre's. n·sun is clamped to -0.1 where the light grazes.
    let k2 = dot(r2, r2) / dot(r0, r0);
    let nd = min(dot(n, r2) / length(r2), -0.1) * length(r2);
    let dzdx = -k2 * dot(n, r0) / nd;
    let dzdy = -k2 * dot(n, r1) / nd;
    // uv = (x / 2 + 1/2, 1/2 - y / 2): dz/du = 2 dz/dx, dz/dv = -2 dz/dy.
    let dzduv = vec2<f32>(2.0 * dzdx, -2.0 * dzdy);
    let o = 1.0 / size;
    // One texel of the receiver's slope (the bilinear taps read up to a texel away) and
    // a small constant.
    let base = ndc.z - abs(dzduv.x) * o.x - abs(dzduv.y) * o.y - 0.0002;
    // Percentage-closer filtering: a 3×3 grid of bilinear comparison taps one texel
    // apart, tent-weighted (1 2 1): together a smooth 4×4-texel footprint whose edge
    // ramps over two texels, so shadow edges close to a camera show neither the
    // staircase of the map's texels nor the comb of a narrower filter.
    var sum = 0.0;
    for (var j = -1; j <= 1; j = j + 1) {
        for (var k = -1; k <= 1; k = k + 1) {
            let w = f32((2 - abs(j)) * (2 - abs(k)));
            let off = vec2<f32>(f32(k) * o.x, f32(j) * o.y);
            let d = base + dot(dzduv, off);
            sum = sum + w * textureSampleCompareLevel(shadow_tex, shadow_smp, uv + off, d);
        }
    }
    return sum / 16.0;
}

@fragment
fn fs_main(i: VOut) -> @location(0) vec4<f32> {
    var base = i.color.rgb;
    var m = i.color.a;
    // Textured model surfaces (codes 4, 5: plain, glossy): `color` carries the texture
    // coordinates in rg and the array layer in b. Derivatives are taken for every
    // fragment (uniform control flow), the level picked from them.
    let duv_dx = dpdx(i.color.rg);
    let duv_dy = dpdy(i.color.rg);
    if (m > 3.5) {
        let layer = i32(round(i.color.b));
        base = textureSampleGrad(model_tex, model_smp, i.color.rg, layer, duv_dx, duv_dy).rgb;
        m = select(0.0, 2.0, m > 4.5);
    }
    if (u.ambient.w > 0.5 || m > 2.5) {
        return vec4<f32>(base, 1.0);
    }
    var n = normalize(i.normal);
    let v = normalize(u.cam_pos.xyz - i.world);
    if (dot(n, v) < 0.0) {
        n = -n;
    }
    if (m > 0.5 && m < 1.5) {
        // Floor: 0.5 m tiles with thin grout lines and a slight per-tile tint.
        let g = i.world.xy * 2.0;
        let cell = floor(g);
        let f = fract(g);
        let checker = (i32(cell.x) + i32(cell.y)) & 1;
        var k = select(0.96, 1.04, checker == 1);
        if (min(min(f.x, 1.0 - f.x), min(f.y, 1.0 - f.y)) < 0.012) {
            k = 0.75;
        }
        base = base * k;
    }
    let l = -u.sun_dir.xyz;
    let ndl = max(dot(n, l), 0.0);
    var sh = 1.0;
    if (ndl > 0.0) {
        sh = shadow_factor(i.world, n, ndl);
    }
    let hemi = 0.8 + 0.2 * n.z;
    var color = base * (u.ambient.rgb * hemi + u.sun_color.rgb * ndl * sh);
    if (m > 1.5) {
        let h = normalize(l + v);
        // x^48 = (x^16)^3 by squaring: a CPU rasterizer evaluates pow as exp2(log2).
        let x = max(dot(n, h), 0.0);
        let x2 = x * x;
        let x4 = x2 * x2;
        let x8 = x4 * x4;
        let x16 = x8 * x8;
        color = color + u.sun_color.rgb * (x16 * x16 * x16) * 0.6 * sh;
    }
    return vec4<f32>(min(color, vec3<f32>(1.0)), 1.0);
}
