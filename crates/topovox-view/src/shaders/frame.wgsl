// What every pass of a frame reads (Rust: `gpu::FrameUniform`).
struct Frame {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // The frustum's world-space bounding box.
    f_lo: vec4<f32>,
    f_hi: vec4<f32>,
    // Light grid: lower corner (w: one attenuation unit in world units), cell size (w: the longest list).
    grid_lo: vec4<f32>,
    grid_cell: vec4<f32>,
    // x: clusters, y: culling (0 none, 1 frustum or more), z: flags (1 gamma, 2 headlight,
    // 4 light-grid view), w: picture width | height << 16.
    params: vec4<u32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
