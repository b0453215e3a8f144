// The instance-id pass (`gpu/ids.rs`): no lighting, one sample per pixel.
// `fs_ids` writes (instance id, depth in mm) per pixel; `fs_cover` marks the pixels one
// body covers when drawn alone. The instance id arrives as the draw's instance index
// (each body is drawn as instance `id` of one).

struct U {
    view_proj: mat4x4<f32>,
    // Camera centre (world, m); w unused.
    cam_pos: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: U;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) id: u32,
};

@vertex
fn vs_ids(@location(0) pos: vec3<f32>, @builtin(instance_index) id: u32) -> VOut {
    var o: VOut;
    o.clip = u.view_proj * vec4<f32>(pos, 1.0);
    o.world = pos;
    o.id = id;
    return o;
}

// Depth: the Euclidean distance of the surface point from the camera centre, in
// millimetres, rounded and clamped to 16 bits (DEPTH_UNITS_PER_M in rh-contract).
@fragment
fn fs_ids(i: VOut) -> @location(0) vec2<u32> {
    let mm = length(i.world - u.cam_pos.xyz) * 1000.0;
    return vec2<u32>(i.id, u32(clamp(round(mm), 1.0, 65535.0)));
}

@vertex
fn vs_cover(@location(0) pos: vec3<f32>) -> @builtin(position) vec4<f32> {
    return u.view_proj * vec4<f32>(pos, 1.0);
}

@fragment
fn fs_cover() -> @location(0) u32 {
    return 1u;
}
