// Solid voxelization by ray parity on the GPU (Schwarz & Seidel 2010, §4):
// triangle-parallel parity flips, then a prefix pass per row.
//
// `flips`: one workgroup per triangle, its threads striding over the grid
// rows (j, k) whose centre line may cross it. A row crosses the triangle
// iff the three edge orientation values of the displaced line agree; the
// crossing's first voxel i0 (voxels i >= i0 have it on their −x ray) is
// the exact floor division of `topovox::topology::inside::row_crossings`,
// ported term for term in i64 (triangles whose terms could overflow are
// done on the CPU and arrive through `xor_list`). The flip is an atomicXor
// of bit i0 of the row, so the order of triangles does not matter.
// `prefix`: one thread per row turns flips into inside bits (prefix XOR).

struct STri {
    // First vertex, absolute lattice coordinates.
    a: vec3<i32>,
    pad0: i32,
    // Second and third vertices relative to the first.
    b: vec3<i32>,
    pad1: i32,
    c: vec3<i32>,
    pad2: i32,
};


const H: i64 = 2048li;

@group(0) @binding(0) var<storage, read> tris: array<STri>;
@group(0) @binding(1) var<storage, read_write> bits: array<atomic<u32>>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read> list: array<vec2<u32>>;

// Laine's tie bias for a gradient g (δ = −(ε, ε², ε³)): 1 if the first
// non-zero component is positive, else 0.
fn bias(g: vec3<i64>) -> i64 {
    if (g.x != 0li) { return select(0li, 1li, g.x > 0li); }
    if (g.y != 0li) { return select(0li, 1li, g.y > 0li); }
    if (g.z != 0li) { return select(0li, 1li, g.z > 0li); }
    return 0li;
}

// floor(a / b) for b > 0.
fn floor_div(a: i64, b: i64) -> i64 {
    var q = a / b;
    if (a % b != 0li && a < 0li) { q = q - 1li; }
    return q;
}

@compute @workgroup_size(64)
fn flips(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let t_index = wg.x + wg.y * 65535u;
    if (t_index >= params.count) { return; }
    let t = tris[t_index];
    let A = vec3<i64>(t.a);
    let r = array<vec3<i64>, 3>(vec3<i64>(0li), vec3<i64>(t.b), vec3<i64>(t.c));
    let n = cross64(r[1] - r[0], r[2] - r[0]);
    // Parallel to the rays: a displaced ray misses it.
    if (n.x == 0li) { return; }
    let bn = bias(n);
    var m: array<vec3<i64>, 3>;
    var be: array<i64, 3>;
    var c: array<i64, 3>;
    for (var e = 0; e < 3; e++) {
        let ed = r[(e + 1) % 3] - r[e];
        // e × (ONE, 0, 0)
        m[e] = vec3<i64>(0li, ed.z * ONE, -ed.y * ONE);
        be[e] = bias(-m[e]);
        c[e] = ONE * cross64(r[e], r[(e + 1) % 3]).x;
    }
    let lo = A + min(r[0], min(r[1], r[2]));
    let hi = A + max(r[0], max(r[1], r[2]));
    let j0 = max(floor_div(lo.y - H - 1li, ONE), 0li);
    let j1 = min(floor_div(hi.y - H + 1li, ONE), i64(params.dims.y) - 1li);
    let k0 = max(floor_div(lo.z - H - 1li, ONE), i64(params.k0));
    let k1 = min(floor_div(hi.z - H + 1li, ONE), i64(params.k0 + params.nk) - 1li);
    if (j0 > j1 || k0 > k1) { return; }
    let nj = u32(j1 - j0 + 1li);
    let rows = nj * u32(k1 - k0 + 1li);
    let nx = i64(params.dims.x);
    for (var q = lid; q < rows; q += 64u) {
        let j = j0 + i64(q % nj);
        let k = k0 + i64(q / nj);
        let p = vec3<i64>(0li, j * ONE + H - A.y, k * ONE + H - A.z);
        let i0_ = (c[0] - dot(p, m[0])) >= be[0];
        let i1_ = (c[1] - dot(p, m[1])) >= be[1];
        let i2_ = (c[2] - dot(p, m[2])) >= be[2];
        if (!(i0_ == i1_ && i1_ == i2_)) { continue; }
        let v0 = n.y * p.y + n.z * p.z;
        var x_star: i64;
        if (n.x > 0li) {
            x_star = A.x - floor_div(v0 - bn, n.x);
        } else {
            x_star = A.x + floor_div(v0 - bn, -n.x) + 1li;
        }
        let i0 = clamp(floor_div(x_star - H + ONE - 1li, ONE), 0li, nx);
        if (i0 < nx) {
            let row = u32(j) + params.dims.y * (u32(k) - params.k0);
            let i = u32(i0);
            atomicXor(&bits[row * params.words_per_row + i / 32u], 1u << (i % 32u));
        }
    }
}

// Flips computed on the CPU: (word, mask) pairs.
@compute @workgroup_size(64)
fn xor_list(@builtin(global_invocation_id) gid: vec3<u32>) {
    let at = gid.x + gid.y * 65535u * 64u;
    if (at >= params.count) { return; }
    let e = list[at];
    atomicXor(&bits[e.x], e.y);
}

// Flips → inside bits: the prefix XOR along each row of the slab.
@compute @workgroup_size(64)
fn prefix(@builtin(global_invocation_id) gid: vec3<u32>) {
    let row = gid.x + gid.y * 65535u * 64u;
    if (row >= params.dims.y * params.nk) { return; }
    var carry = 0u;
    for (var w = 0u; w < params.words_per_row; w++) {
        let at = row * params.words_per_row + w;
        var x = atomicLoad(&bits[at]);
        x ^= x << 1u;
        x ^= x << 2u;
        x ^= x << 4u;
        x ^= x << 8u;
        x ^= x << 16u;
        if (carry == 1u) { x = ~x; }
        carry = x >> 31u;
        let valid = params.dims.x - 32u * w;
        if (valid < 32u) { x &= (1u << valid) - 1u; }
        atomicStore(&bits[at], x);
    }
}
