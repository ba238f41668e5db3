// The cluster-box wireframe (seed 002's figures): each cluster's box as 12
// lines, green where the cluster was drawn, red where culling dropped it.
// One instance per cluster, 24 vertices (the edges' ends) each.

struct ClusterBox {
    lo: vec4<f32>,
    hi: vec4<f32>,
}

@group(0) @binding(1) var<storage, read> boxes: array<ClusterBox>;
// The indirect commands after culling: 5 words each, word 1 the instance count.
@group(0) @binding(2) var<storage, read> commands: array<u32>;

// Corner k of a box: bit 0 picks x, bit 1 y, bit 2 z (hi where set).
var<private> EDGE_ENDS: array<u32, 24> = array<u32, 24>(
    0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u,
    0u, 2u, 1u, 3u, 4u, 6u, 5u, 7u,
    0u, 4u, 1u, 5u, 2u, 6u, 3u, 7u,
);

struct BoxOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) kept: u32,
}

@vertex
fn vs_box(@builtin(vertex_index) v: u32, @builtin(instance_index) c: u32) -> BoxOut {
    let b = boxes[c];
    let k = EDGE_ENDS[v];
    let p = select(b.lo.xyz, b.hi.xyz, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
    var out: BoxOut;
    out.clip = frame.view_proj * vec4<f32>(p, 1.0);
    out.kept = select(0u, 1u, commands[5u * c + 1u] != 0u);
    return out;
}

@fragment
fn fs_box(in: BoxOut) -> @location(0) vec4<f32> {
    if in.kept != 0u {
        return vec4<f32>(0.2, 1.0, 0.4, 1.0);
    }
    return vec4<f32>(1.0, 0.2, 0.2, 1.0);
}
