// The Hi-Z pyramid (see hiz.rs): level 0 from the depth pass, padded with
// 0 to powers of two; each further level the maximum of 2×2 texels below.

@group(0) @binding(0) var depth: texture_depth_2d;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn copy_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let out = textureDimensions(dst);
    if id.x >= out.x || id.y >= out.y {
        return;
    }
    let size = textureDimensions(depth);
    var d = 0.0;
    if id.x < size.x && id.y < size.y {
        d = textureLoad(depth, vec2<u32>(id.xy), 0);
    }
    textureStore(dst, vec2<u32>(id.xy), vec4<f32>(d, 0.0, 0.0, 0.0));
}

@compute @workgroup_size(8, 8)
fn reduce(@builtin(global_invocation_id) id: vec3<u32>) {
    let out = textureDimensions(dst);
    if id.x >= out.x || id.y >= out.y {
        return;
    }
    let s = textureDimensions(src) - vec2<u32>(1u, 1u);
    let a = 2u * id.xy;
    let b = min(a + vec2<u32>(1u, 1u), s);
    let m = max(max(textureLoad(src, a, 0).x, textureLoad(src, vec2<u32>(b.x, a.y), 0).x),
                max(textureLoad(src, vec2<u32>(a.x, b.y), 0).x, textureLoad(src, b, 0).x));
    textureStore(dst, vec2<u32>(id.xy), vec4<f32>(m, 0.0, 0.0, 0.0));
}
