// Surface voxelization on the GPU (`cover`, `sep26`, `sep6`): one workgroup per
// triangle, its threads striding over the columns of the triangle's
// dominant-axis projection. Each column's candidate range along the
// dominant axis is bounded in f32 (with a one-voxel margin, far wider than
// the f32 error), and every candidate is decided by the exact 13-axis
// separating axis test in i64 on lattice coordinates relative to the
// triangle's box, the same predicate as the CPU reference
// (`topovox::voxelize::cover::reference::triangle_box_overlap`).
// For `sep26` and `sep6` (subsets of `cover`) a voxel that passes the
// cover test is then decided by the modes' definitions: does the triangle
// meet one of the voxel's space diagonals (sep26) or crosshair segments
// (sep6), displaced by Laine's infinitesimal δ = −(ε, ε², ε³)? That is
// `topovox::geom::perturb::segment_meets_triangle`, ported predicate for
// predicate: five orientation signs, each the lexicographic sign of the
// determinant at δ = 0 and its three partial differences.
// Triangles are sent only when the i64 products cannot overflow.

struct Tri {
    // Voxel index of the box's low corner; box size in voxels (inclusive count).
    origin: vec3<i32>,
    pad0: i32,
    size: vec3<u32>,
    pad1: u32,
    // Vertices relative to origin * ONE, in lattice units.
    a: vec3<i32>,
    pad2: i32,
    b: vec3<i32>,
    pad3: i32,
    c: vec3<i32>,
    pad4: i32,
};



@group(0) @binding(0) var<storage, read> tris: array<Tri>;
@group(0) @binding(1) var<storage, read_write> bits: array<atomic<u32>>;
@group(0) @binding(2) var<uniform> params: Params;

fn min0(v: i64) -> i64 { return select(v, 0li, v > 0li); }
fn max0(v: i64) -> i64 { return select(v, 0li, v < 0li); }

// Does the axis separate the triangle (v0, v1, v2) from the box [lo, lo + ONE]?
fn separates(ax: vec3<i64>, v0: vec3<i64>, v1: vec3<i64>, v2: vec3<i64>, lo: vec3<i64>) -> bool {
    let p0 = dot64(ax, v0);
    let p1 = dot64(ax, v1);
    let p2 = dot64(ax, v2);
    let tmin = min(p0, min(p1, p2));
    let tmax = max(p0, max(p1, p2));
    let base = dot64(ax, lo);
    let s = ax * ONE;
    let bmin = base + min0(s.x) + min0(s.y) + min0(s.z);
    let bmax = base + max0(s.x) + max0(s.y) + max0(s.z);
    return tmax < bmin || tmin > bmax;
}

fn overlaps(v0: vec3<i64>, v1: vec3<i64>, v2: vec3<i64>, n: vec3<i64>, lo: vec3<i64>) -> bool {
    // Box normals.
    if (separates(vec3<i64>(1li, 0li, 0li), v0, v1, v2, lo)) { return false; }
    if (separates(vec3<i64>(0li, 1li, 0li), v0, v1, v2, lo)) { return false; }
    if (separates(vec3<i64>(0li, 0li, 1li), v0, v1, v2, lo)) { return false; }
    // Triangle normal.
    if (separates(n, v0, v1, v2, lo)) { return false; }
    // Edge × box edge.
    let e = array<vec3<i64>, 3>(v1 - v0, v2 - v1, v0 - v2);
    for (var i = 0u; i < 3u; i++) {
        let ei = e[i];
        if (separates(vec3<i64>(0li, -ei.z, ei.y), v0, v1, v2, lo)) { return false; }
        if (separates(vec3<i64>(ei.z, 0li, -ei.x), v0, v1, v2, lo)) { return false; }
        if (separates(vec3<i64>(-ei.y, ei.x, 0li), v0, v1, v2, lo)) { return false; }
    }
    return true;
}

fn det3(a: vec3<i64>, b: vec3<i64>, c: vec3<i64>) -> i64 {
    return dot64(a, cross64(b, c));
}

// det[p1 − p0, p2 − p0, p3 − p0] with the points whose flag is set moved by d.
fn det_at(p0: vec3<i64>, p1: vec3<i64>, p2: vec3<i64>, p3: vec3<i64>, f: vec4<bool>, d: vec3<i64>) -> i64 {
    let q0 = p0 + select(vec3<i64>(0li), d, f.x);
    let q1 = p1 + select(vec3<i64>(0li), d, f.y);
    let q2 = p2 + select(vec3<i64>(0li), d, f.z);
    let q3 = p3 + select(vec3<i64>(0li), d, f.w);
    return det3(q1 - q0, q2 - q0, q3 - q0);
}

fn sign64(v: i64) -> i32 {
    return select(select(0, -1, v < 0li), 1, v > 0li);
}

// Sign of the orientation with the flagged points displaced by δ = −(ε, ε², ε³).
fn orient(p0: vec3<i64>, p1: vec3<i64>, p2: vec3<i64>, p3: vec3<i64>, f: vec4<bool>) -> i32 {
    let d0 = det_at(p0, p1, p2, p3, f, vec3<i64>(0li));
    if (d0 != 0li) { return sign64(d0); }
    let dx = det_at(p0, p1, p2, p3, f, vec3<i64>(-1li, 0li, 0li)) - d0;
    if (dx != 0li) { return sign64(dx); }
    let dy = det_at(p0, p1, p2, p3, f, vec3<i64>(0li, -1li, 0li)) - d0;
    if (dy != 0li) { return sign64(dy); }
    return sign64(det_at(p0, p1, p2, p3, f, vec3<i64>(0li, 0li, -1li)) - d0);
}

// Does the target segment [s0, s1] (displaced) meet the closed triangle?
fn segment_meets_triangle(s0: vec3<i64>, s1: vec3<i64>, t0: vec3<i64>, t1: vec3<i64>, t2: vec3<i64>) -> bool {
    let tri_pt = vec4<bool>(false, false, false, true);
    let sp = orient(t0, t1, t2, s0, tri_pt);
    let sq = orient(t0, t1, t2, s1, tri_pt);
    if (sp == 0 || sp == sq) { return false; }
    let seg = vec4<bool>(true, true, false, false);
    let e0 = orient(s0, s1, t0, t1, seg);
    let e1 = orient(s0, s1, t1, t2, seg);
    let e2 = orient(s0, s1, t2, t0, seg);
    return e0 != 0 && e0 == e1 && e1 == e2;
}

fn target_hit(v0: vec3<i64>, v1: vec3<i64>, v2: vec3<i64>, lo: vec3<i64>) -> bool {
    let h = ONE / 2li;
    if ((params.mode & 3u) == 1u) {
        // The four space diagonals.
        let o = array<vec3<i64>, 4>(vec3<i64>(0li, 0li, 0li), vec3<i64>(ONE, 0li, 0li), vec3<i64>(0li, ONE, 0li), vec3<i64>(0li, 0li, ONE));
        let d = array<vec3<i64>, 4>(vec3<i64>(ONE, ONE, ONE), vec3<i64>(-ONE, ONE, ONE), vec3<i64>(ONE, -ONE, ONE), vec3<i64>(ONE, ONE, -ONE));
        for (var q = 0u; q < 4u; q++) {
            let p = lo + o[q];
            if (segment_meets_triangle(p, p + d[q], v0, v1, v2)) { return true; }
        }
        return false;
    }
    // The three crosshair segments.
    let o = array<vec3<i64>, 3>(vec3<i64>(0li, h, h), vec3<i64>(h, 0li, h), vec3<i64>(h, h, 0li));
    let d = array<vec3<i64>, 3>(vec3<i64>(ONE, 0li, 0li), vec3<i64>(0li, ONE, 0li), vec3<i64>(0li, 0li, ONE));
    for (var q = 0u; q < 3u; q++) {
        let p = lo + o[q];
        if (segment_meets_triangle(p, p + d[q], v0, v1, v2)) { return true; }
    }
    return false;
}

fn set_voxel(i: u32, j: u32, k: u32) {
    let row = j + params.dims.y * (k - params.k0);
    let word = row * params.words_per_row + i / 32u;
    atomicOr(&bits[word], 1u << (i % 32u));
}

// A triangle set up for its columns: vertices and normal (i64), the
// dominant axis w and the projection axes u, v after it.
struct Setup {
    v0: vec3<i64>,
    v1: vec3<i64>,
    v2: vec3<i64>,
    n: vec3<i64>,
    u: u32,
    v: u32,
    w: u32,
};

fn setup(t: Tri) -> Setup {
    let v0 = vec3<i64>(t.a);
    let v1 = vec3<i64>(t.b);
    let v2 = vec3<i64>(t.c);
    let n = cross64(v1 - v0, v2 - v0);
    let an = abs(n);
    var w = 2u;
    if (an.x >= an.y && an.x >= an.z) { w = 0u; } else if (an.y >= an.z) { w = 1u; }
    return Setup(v0, v1, v2, n, (w + 1u) % 3u, (w + 2u) % 3u, w);
}

// Every voxel of column (cu, cv) (relative to the triangle's box) that the
// mode sets, within the slab's layers.
fn column(t: Tri, s: Setup, cu: i32, cv: i32) {
    let size = vec3<i32>(t.size);
    let k_lo = max(0, i32(params.k0) - t.origin.z);
    let k_hi = min(size.z - 1, i32(params.k0 + params.nk) - 1 - t.origin.z);
    if (k_lo > k_hi) { return; }
    let lo_r = vec3<i32>(0, 0, k_lo);
    let hi_r = vec3<i32>(size.x - 1, size.y - 1, k_hi);
    let nf = vec3<f32>(f32(s.n.x), f32(s.n.y), f32(s.n.z));
    let d = f32(dot64(s.n, s.v0));
    let one = 4096.0;
    // The plane's range along w over the column's four corner lines.
    var wmin = 3.0e38;
    var wmax = -3.0e38;
    for (var q = 0; q < 4; q++) {
        let xu = f32(cu + (q & 1)) * one;
        let xv = f32(cv + (q >> 1)) * one;
        let xw = (d - nf[s.u] * xu - nf[s.v] * xv) / nf[s.w];
        wmin = min(wmin, xw);
        wmax = max(wmax, xw);
    }
    let w0 = max(lo_r[s.w], i32(floor(wmin / one)) - 1);
    let w1 = min(hi_r[s.w], i32(floor(wmax / one)) + 1);
    for (var cw = w0; cw <= w1; cw++) {
        var r = vec3<i32>(0, 0, 0);
        r[s.u] = cu;
        r[s.v] = cv;
        r[s.w] = cw;
        if (r.z < k_lo || r.z > k_hi) { continue; }
        let lo = vec3<i64>(r) * ONE;
        if (overlaps(s.v0, s.v1, s.v2, s.n, lo) && ((params.mode & 3u) == 0u || target_hit(s.v0, s.v1, s.v2, lo))) {
            let g = t.origin + r;
            set_voxel(u32(g.x), u32(g.y), u32(g.z));
        }
    }
}

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let t_index = wg.x + wg.y * 65535u;
    if (t_index >= params.count) { return; }
    let t = tris[t_index];
    let s = setup(t);
    let size = vec3<i32>(t.size);
    let nu = size[s.u];
    let columns = u32(size[s.u] * size[s.v]);
    for (var col = lid; col < columns; col += 64u) {
        column(t, s, i32(col) % nu, i32(col) / nu);
    }
}
