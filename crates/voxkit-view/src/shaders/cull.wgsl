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
