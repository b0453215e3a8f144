// FXAA-style post-process anti-aliasing (after Lottes' FXAA, the compact variant):
// full-screen passes over a resolved frame, in display (sRGB-encoded) values. Pixels
// whose four neighbours differ little in luma are copied unchanged (most pixels: five
// texel loads); on an edge, the blur direction is taken from the luma gradient (four
// diagonal loads) and the frame is sampled along it (four filtered taps). Two passes:
// `fs_fxaa_mark` copies and marks edges, `fs_fxaa_edge` blends only those.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var smp: sampler;

// One triangle covering the target.
@vertex
fn vs_post(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, y * 2.0 - 1.0, 0.0, 1.0);
}

fn luma(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.299, 0.587, 0.114));
}

// The texel at `p + o`, clamped to the frame (what a clamped sample at its centre reads).
fn near(p: vec2<i32>, dims: vec2<i32>, o: vec2<i32>) -> vec3<f32> {
    return textureLoad(src, clamp(p + o, vec2<i32>(0, 0), dims - vec2<i32>(1, 1)), 0).rgb;
}

fn tap(uv: vec2<f32>) -> vec3<f32> {
    return textureSampleLevel(src, smp, uv, 0.0).rgb;
}

// Edge detection: local contrast below max(EDGE_MIN, EDGE_REL · brightest) is left alone.
const EDGE_MIN: f32 = 0.0312;
const EDGE_REL: f32 = 0.125;
const REDUCE_MUL: f32 = 0.125;
const REDUCE_MIN: f32 = 0.0078125;
const SPAN_MAX: f32 = 8.0;

// The four neighbours' lumas and the frame's (lmin, lmax) around `p`.
struct Cross {
    m: vec3<f32>,
    lmin: f32,
    lmax: f32,
};

fn cross_at(p: vec2<i32>, dims: vec2<i32>) -> Cross {
    let m = textureLoad(src, p, 0).rgb;
    let lm = luma(m);
    let ln = luma(near(p, dims, vec2<i32>(0, -1)));
    let ls = luma(near(p, dims, vec2<i32>(0, 1)));
    let lw = luma(near(p, dims, vec2<i32>(-1, 0)));
    let le = luma(near(p, dims, vec2<i32>(1, 0)));
    var c: Cross;
    c.m = m;
    c.lmin = min(lm, min(min(ln, ls), min(lw, le)));
    c.lmax = max(lm, max(max(ln, ls), max(lw, le)));
    return c;
}

fn is_edge(c: Cross) -> bool {
    return !(c.lmax - c.lmin < max(EDGE_MIN, c.lmax * EDGE_REL));
}

struct Marked {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
};

// First of two passes (a CPU rasterizer runs both sides of every branch, so the edge
// blend of a one-pass shader would cost every pixel): every pixel is copied, and edge
// pixels get depth 0, the others 1. The second pass, `fs_fxaa_edge`, drawn at depth 0
// with an `Equal` test, blends only the edge pixels (whole pixel groups without an edge
// are skipped). Together: the one-pass FXAA's pixels exactly.
@fragment
fn fs_fxaa_mark(@builtin(position) pos: vec4<f32>) -> Marked {
    let c = cross_at(vec2<i32>(pos.xy), vec2<i32>(textureDimensions(src)));
    var o: Marked;
    o.color = vec4<f32>(c.m, 1.0);
    o.depth = select(1.0, 0.0, is_edge(c));
    return o;
}

// The blend of an edge pixel (see `fs_fxaa_mark`).
@fragment
fn fs_fxaa_edge(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let dims = vec2<i32>(textureDimensions(src));
    let p = vec2<i32>(pos.xy);
    let c = cross_at(p, dims);
    let lmin = c.lmin;
    let lmax = c.lmax;
    let inv = 1.0 / vec2<f32>(dims);
    let uv = pos.xy * inv;
    // Diagonal neighbours: the gradient's direction. Texel centres, so loads (a
    // load costs a fraction of a filtered sample on a CPU rasterizer).
    let lnw = luma(near(p, dims, vec2<i32>(-1, -1)));
    let lne = luma(near(p, dims, vec2<i32>(1, -1)));
    let lsw = luma(near(p, dims, vec2<i32>(-1, 1)));
    let lse = luma(near(p, dims, vec2<i32>(1, 1)));
    var dir = vec2<f32>(-((lnw + lne) - (lsw + lse)), (lnw + lsw) - (lne + lse));
    let reduce = max((lnw + lne + lsw + lse) * 0.25 * REDUCE_MUL, REDUCE_MIN);
    let scale = 1.0 / (min(abs(dir.x), abs(dir.y)) + reduce);
    dir = clamp(dir * scale, vec2<f32>(-SPAN_MAX), vec2<f32>(SPAN_MAX)) * inv;
    let a = 0.5 * (tap(uv + dir * (1.0 / 3.0 - 0.5)) + tap(uv + dir * (2.0 / 3.0 - 0.5)));
    let b = a * 0.5 + 0.25 * (tap(uv - dir * 0.5) + tap(uv + dir * 0.5));
    let lb = luma(b);
    let lo = min(lmin, min(min(lnw, lne), min(lsw, lse)));
    let up = max(lmax, max(max(lnw, lne), max(lsw, lse)));
    if (lb < lo || lb > up) {
        return vec4<f32>(a, 1.0);
    }
    return vec4<f32>(b, 1.0);
}
