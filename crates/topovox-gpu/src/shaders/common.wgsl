// Shared by every topovox shader (prepended by the Rust side): the lattice
// unit, the per-pass parameters and 64-bit vector helpers.

const ONE: i64 = 4096li;

struct Params {
    // Grid dims; the slab holds layers k0 .. k0 + nk.
    dims: vec3<u32>,
    k0: u32,
    nk: u32,
    words_per_row: u32,
    count: u32,
    // 0 cover, 1 sep26, 2 sep6 (bits 0-1); QUADS (16): the rasterizer
    // draws bounding rectangles. The Rust twin is params.rs (a test checks
    // the two agree).
    mode: u32,
    // The rasterizer's viewport side N.
    side: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

fn cross64(p: vec3<i64>, q: vec3<i64>) -> vec3<i64> {
    return vec3<i64>(p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x);
}

fn dot64(p: vec3<i64>, q: vec3<i64>) -> i64 {
    return p.x * q.x + p.y * q.y + p.z * q.z;
}

