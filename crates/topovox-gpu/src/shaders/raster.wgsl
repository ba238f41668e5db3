// The rasterizer path (appended to cover.wgsl, whose bindings and `column`
// it shares). After Schwarz & Seidel 2010 and the seeds: each triangle is
// projected along its dominant axis w (the "swizzle", done here in the
// vertex shader since wgpu has no geometry shaders) onto an N×N viewport
// whose pixel (u, v) is the voxel column (u, v). Coverage:
// - without hardware conservative rasterization (lavapipe): each triangle
//   is drawn as its pixel-aligned bounding rectangle, and the fragment
//   shader culls pixels outside the projected triangle by the edge test
//   against the pixel square (offset by half the pixel diagonal, with a
//   margin of 1/16 pixel far above the f32 error) — seed 003's "expand,
//   then cull with the AABB and edge tests". Expanding the triangle itself
//   (moving each edge out and intersecting) is ill-conditioned for
//   slivers, whose offset edges are nearly parallel; the rectangle is not;
// - hardware conservative rasterization: the triangle itself;
// each visited pixel then decides the voxels of its column by the exact
// tests of `column`, so extra pixels cost time, never correctness;
// - MSAA (approximate): plain multisampled rasterization, no expansion; a
//   pixel none of whose samples the triangle covers is never visited, so
//   voxels are missed (the caller counts them).

struct VOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) tri: u32,
};

// params.mode: bits 0-1 the voxelization mode; bit 4: draw each triangle
// as its pixel-aligned bounding rectangle (6 vertices) instead of itself.
const QUADS: u32 = 16u;

fn projected(t: Tri, s: Setup) -> array<vec2<f32>, 3> {
    let o = vec2<f32>(f32(t.origin[s.u]), f32(t.origin[s.v]));
    let q = array<vec3<i64>, 3>(s.v0, s.v1, s.v2);
    var p: array<vec2<f32>, 3>;
    for (var c = 0; c < 3; c++) {
        p[c] = o + vec2<f32>(f32(q[c][s.u]), f32(q[c][s.v])) / 4096.0;
    }
    return p;
}

@vertex
fn vs(@builtin(vertex_index) vi: u32) -> VOut {
    var out: VOut;
    let per = select(3u, 6u, (params.mode & QUADS) != 0u);
    let ti = vi / per;
    let corner = vi % per;
    out.tri = ti;
    let t = tris[ti];
    let s = setup(t);
    var at: vec2<f32>;
    if (per == 6u) {
        // The triangle's voxel box, projected: integer pixel bounds.
        let size = vec3<i32>(t.size);
        let lo = vec2<f32>(f32(t.origin[s.u]), f32(t.origin[s.v]));
        let hi = lo + vec2<f32>(f32(size[s.u]), f32(size[s.v]));
        let xs = array<f32, 6>(lo.x, hi.x, hi.x, lo.x, hi.x, lo.x);
        let ys = array<f32, 6>(lo.y, lo.y, hi.y, lo.y, hi.y, hi.y);
        at = vec2<f32>(xs[corner], ys[corner]);
    } else {
        at = projected(t, s)[corner];
    }
    let side = f32(params.side);
    out.pos = vec4<f32>(at.x / side * 2.0 - 1.0, 1.0 - at.y / side * 2.0, 0.5, 1.0);
    return out;
}

@fragment
fn fs(in: VOut) -> @location(0) vec4<f32> {
    let t = tris[in.tri];
    let s = setup(t);
    let size = vec3<i32>(t.size);
    let px = floor(in.pos.xy);
    let cu = i32(px.x) - t.origin[s.u];
    let cv = i32(px.y) - t.origin[s.v];
    // AABB cull: the triangle's box.
    if (cu < 0 || cv < 0 || cu >= size[s.u] || cv >= size[s.v]) { return vec4<f32>(0.0); }
    // Edge cull: a pixel square clearly outside one projected edge (by a
    // margin far above the f32 error) cannot hold a voxel the triangle meets.
    let p = projected(t, s);
    let area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    let sgn = select(-1.0, 1.0, area >= 0.0);
    let centre = px + vec2<f32>(0.5);
    for (var e = 0; e < 3; e++) {
        let a = p[e];
        let b = p[(e + 1) % 3];
        let n = sgn * vec2<f32>(b.y - a.y, a.x - b.x);
        if (dot(n, centre - a) > 0.5 * (abs(n.x) + abs(n.y)) + length(n) / 16.0) { return vec4<f32>(0.0); }
    }
    column(t, s, cu, cv);
    return vec4<f32>(0.0);
}
