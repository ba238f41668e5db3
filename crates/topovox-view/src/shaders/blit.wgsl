// Copies the rendered frame onto a window's texture (same size).

@group(0) @binding(0) var frame_texture: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the viewport.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let size = textureDimensions(frame_texture);
    let at = min(vec2<u32>(p.xy), size - vec2<u32>(1u, 1u));
    return textureLoad(frame_texture, at, 0);
}
