// GPU frustum culling of cluster boxes (seed 002): the tests of
// `camera::visible`, expression for expression. Each cluster keeps its
// command slot; a culled one gets instance count 0 (see gpu.rs for why).

struct ClusterBox {
    lo: vec4<f32>,
    hi: vec4<f32>,
}

@group(0) @binding(1) var<storage, read> boxes: array<ClusterBox>;
// Five words per cluster: index count, instance count, first index, base vertex, first instance.
@group(0) @binding(2) var<storage, read_write> commands: array<u32>;
// 0: clusters kept, 1: triangles drawn.
@group(0) @binding(3) var<storage, read_write> counters: array<atomic<u32>>;

fn clip_of(p: vec3<f32>) -> vec4<f32> {
    let m = frame.view_proj;
    return ((m[0] * p.x + m[1] * p.y) + m[2] * p.z) + m[3];
}

fn visible(lo: vec3<f32>, hi: vec3<f32>) -> bool {
    if any(hi < frame.f_lo.xyz) || any(lo > frame.f_hi.xyz) {
        return false;
    }
    var out = array<u32, 6>(0u, 0u, 0u, 0u, 0u, 0u);
    for (var c = 0u; c < 8u; c++) {
        let p = vec3<f32>(select(lo.x, hi.x, (c & 1u) != 0u), select(lo.y, hi.y, (c & 2u) != 0u), select(lo.z, hi.z, (c & 4u) != 0u));
        let q = clip_of(p);
        out[0] += u32(q.x < -q.w);
        out[1] += u32(q.x > q.w);
        out[2] += u32(q.y < -q.w);
        out[3] += u32(q.y > q.w);
        out[4] += u32(q.z < 0.0);
        out[5] += u32(q.z > q.w);
    }
    return out[0] < 8u && out[1] < 8u && out[2] < 8u && out[3] < 8u && out[4] < 8u && out[5] < 8u;
}

@compute @workgroup_size(64)
fn cull(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if n >= frame.params.x {
        return;
    }
    var keep = true;
    if frame.params.y != 0u {
        keep = visible(boxes[n].lo.xyz, boxes[n].hi.xyz);
    }
    commands[5u * n + 1u] = select(0u, 1u, keep);
    if keep {
        atomicAdd(&counters[0], 1u);
        atomicAdd(&counters[1], commands[5u * n] / 3u);
    }
}

// Hi-Z occlusion test of the frustum survivors (hiz.rs, `Pyramid::occluded`).
@group(1) @binding(0) var hiz: texture_2d<f32>;

const DEPTH_EPS: f32 = 1e-6;

fn hiz_at(l: u32, x: u32, y: u32) -> f32 {
    // Level sizes from level 0's: lavapipe (Mesa 22.3) answered
    // textureDimensions(hiz, l) with wrong heights.
    let size = max(textureDimensions(hiz) >> vec2<u32>(l, l), vec2<u32>(1u, 1u));
    return textureLoad(hiz, vec2<u32>(min(x, size.x - 1u), min(y, size.y - 1u)), i32(l)).x;
}

fn occluded(lo: vec3<f32>, hi: vec3<f32>) -> bool {
    var nlo = vec3<f32>(1e30);
    var nhi = vec3<f32>(-1e30);
    for (var c = 0u; c < 8u; c++) {
        let p = vec3<f32>(select(lo.x, hi.x, (c & 1u) != 0u), select(lo.y, hi.y, (c & 2u) != 0u), select(lo.z, hi.z, (c & 4u) != 0u));
        let q = clip_of(p);
        if q.w <= 0.0 {
            return false;
        }
        let n = q.xyz / q.w;
        nlo = min(nlo, n);
        nhi = max(nhi, n);
    }
    let w = f32(frame.params.w & 0xffffu);
    let h = f32(frame.params.w >> 16u);
    let x0 = u32(clamp(floor((nlo.x * 0.5 + 0.5) * w) - 1.0, 0.0, w - 1.0));
    let x1 = u32(clamp(floor((nhi.x * 0.5 + 0.5) * w) + 1.0, 0.0, w - 1.0));
    let y0 = u32(clamp(floor((0.5 - nhi.y * 0.5) * h) - 1.0, 0.0, h - 1.0));
    let y1 = u32(clamp(floor((0.5 - nlo.y * 0.5) * h) + 1.0, 0.0, h - 1.0));
    let levels = textureNumLevels(hiz);
    var l = 0u;
    while l + 1u < levels && (((x1 >> l) - (x0 >> l)) > 1u || ((y1 >> l) - (y0 >> l)) > 1u) {
        l++;
    }
    let d = max(max(hiz_at(l, x0 >> l, y0 >> l), hiz_at(l, x1 >> l, y0 >> l)), max(hiz_at(l, x0 >> l, y1 >> l), hiz_at(l, x1 >> l, y1 >> l)));
    return nlo.z > d + DEPTH_EPS;
}

@compute @workgroup_size(64)
fn occlude(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if n >= frame.params.x || commands[5u * n + 1u] == 0u {
        return;
    }
    if occluded(boxes[n].lo.xyz, boxes[n].hi.xyz) {
        commands[5u * n + 1u] = 0u;
    } else {
        atomicAdd(&counters[2], 1u);
        atomicAdd(&counters[3], commands[5u * n] / 3u);
    }
}
