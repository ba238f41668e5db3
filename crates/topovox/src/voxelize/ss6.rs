//! Schwarz & Seidel's 6-separating surface voxelization (`ss6`).
//!
//! This work is based on: M. Schwarz, H.-P. Seidel, "Fast Parallel Surface
//! and Solid Voxelization on GPUs", ACM TOG 29(6), 2010, §3.2 (6-separating
//! surface voxelization: the plane test against the voxel's inscribed
//! octahedron, and 2D "diamond" edge tests in the three axis projections).
//!
//! **Definition.** With voxel centre `m`, half size `h` and triangle normal
//! `n`, voxel `(i,j,k)` is set iff for some (snapped, non-degenerate)
//! triangle whose bounding box meets the voxel:
//! - plane test: `|n·(m − v₀)| <= h·max(|nx|, |ny|, |nz|)` (the plane meets
//!   the octahedron spanned by the face centres), and
//! - for each axis plane `xy`, `yz`, `zx` and each edge `i`, with the edge's
//!   2D normal `nₑ` turned inward by the sign of the dropped normal
//!   component (`+` when it is zero): `nₑ·(m − vᵢ) + h·max(|nₑ|) >= 0` (the
//!   projected edge's half-plane meets the pixel's diamond).
//!
//! Ties follow [`crate::geom::perturb`] (the voxel's octahedron and
//! diamonds displaced by `δ`; a test whose value does not depend on the
//! displacement passes when it is `>= 0`).
//!
//! **Guarantee.** 6-separating for closed surfaces (Laine 2013 §5.2.2: the
//! octahedron test contains the crosshair target), so `sep6 ⊆ ss6`, and not
//! minimal; a subset of `cover`.
//!
//! **Fast path.** The plane test passes one voxel per column of the
//! dominant-axis projection; where the pixel lies strictly inside the
//! projected triangle that voxel is set untested, elsewhere it gets the
//! test above (`columns`). Triangles in a box of at most 27 voxels take
//! `cover`'s exact traversal with the test on each candidate. All in `i64`
//! (relative to the first vertex) or `i128`.
//!
//! **Reference:** [`reference::ss6`], the formulas above in `i128` with
//! the perturbation evaluated symbolically, for every voxel of each
//! triangle's bounding box.

use super::cover::cover_triangle;
use super::driver::{run_mesh, FilterUnset, Kernel};
use super::targets::{is_tiny, PixelTest};
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::bias;
use crate::geom::setup::{dominant_axes, fits_i64, TriSetup};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// Schwarz–Seidel 6-separating voxelization, fast path, into sparse bricks.
pub fn ss6(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&Ss6Kernel { traversal: opts.traversal }, mesh, grid, opts)
}

/// The fast path on already prepared triangles.
pub fn ss6_lattice(tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> BrickBits {
    super::driver::run_slabs(&Ss6Kernel { traversal: opts.traversal }, tris, dims, opts).0
}

struct Ss6Kernel {
    traversal: Traversal,
}

impl Kernel<LatticeTriangle> for Ss6Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            filtered::<i64>(tri, lo, hi, self.traversal, slab);
        } else {
            filtered::<i128>(tri, lo, hi, self.traversal, slab);
        }
    }
}

/// A linear test `g·(m − a) + c >= bias` on the voxel centre `m`, with `a`
/// the triangle's first vertex.
#[derive(Clone, Copy)]
struct Lin<T> {
    g: [T; 3],
    c: T,
}

/// The three diamond tests of the projection along axis `c` (onto `p`,
/// `q`), into `tests[2 + 3c ..]`.
#[inline(always)]
fn diamond_tests<T: PlaneInt>(tri: &LatticeTriangle, n: [i64; 3], tests: &mut [Lin<T>; 11], (c, p, q): (usize, usize, usize)) {
    let a = tri.v[0];
    let sgn = if n[c] >= 0 { 1 } else { -1 };
    for i in 0..3 {
        let e = tri.edge(i);
        let mut g = [0i64; 3];
        g[p] = -e[q] * sgn;
        g[q] = e[p] * sgn;
        // Relative to a: g·(m − vᵢ) = g·(m − a) − g·(vᵢ − a).
        let vi = tri.v[i];
        let off = g[p] * (vi[p] - a[p]) + g[q] * (vi[q] - a[q]);
        let c0 = H * g[p].abs().max(g[q].abs()) - off - bias(g);
        tests[2 + 3 * c + i] = Lin { g: g.map(T::from_i64), c: T::from_i64(c0) };
    }
}

fn filtered<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], traversal: Traversal, slab: &mut BrickSlab<'_>) {
    let a = tri.v[0];
    let n = tri.normal();
    let r = H * n.iter().map(|c| c.abs()).max().unwrap_or(0);
    let t = T::from_i64;
    // On the stack: at small grids a heap allocation per triangle shows.
    let mut tests = [Lin { g: [T::ZERO; 3], c: T::ZERO }; 11];
    // Plane: n·d + r >= bias(n) and −n·d + r >= bias(−n).
    tests[0] = Lin { g: n.map(t), c: t(r - bias(n)) };
    tests[1] = Lin { g: n.map(|c| t(-c)), c: t(r - bias(n.map(|c| -c))) };
    // Per axis, with constant axes: indexed by a loop variable, the
    // edges and normals lived in memory and each test waited on the
    // stores just made (a fifth of `ss6` at 128³).
    diamond_tests(tri, n, &mut tests, (0, 1, 2));
    diamond_tests(tri, n, &mut tests, (1, 2, 0));
    diamond_tests(tri, n, &mut tests, (2, 0, 1));
    let keep = |i: i64, j: i64, k: i64| {
        let ijk = [i, j, k];
        let d: [T; 3] = std::array::from_fn(|x| t(ijk[x] * ONE + H - a[x]));
        tests.iter().all(|l| l.g[0] * d[0] + l.g[1] * d[1] + l.g[2] * d[2] + l.c >= T::ZERO)
    };
    if traversal == Traversal::Auto && !is_tiny(lo, hi) {
        projected::<T>(tri, &tests, lo, hi, slab);
    } else {
        cover_triangle(tri, lo, hi, traversal, &mut FilterUnset { slab, keep });
    }
}

/// A triangle larger than tiny, by [`columns`]. `columns` asks only about
/// voxels that pass the plane test: the nine edge tests of `tests`, those
/// of the dominant projection (whose pixel straddles an edge) first, as
/// they fail most. Not inlined, and one `columns` per dominant axis
/// (constant indexing: 1024³ −10 %), apart from the tiny path's code (in
/// it, the tiny path measured +15 % at 128³).
#[inline(never)]
fn projected<T: PlaneInt>(tri: &LatticeTriangle, tests: &[Lin<T>; 11], lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let a = tri.v[0];
    let w = dominant_axes(tri).2;
    let mut edges = [tests[2]; 9];
    for (i, e) in edges.iter_mut().enumerate() {
        *e = tests[2 + (3 * w + i) % 9];
    }
    let edge_tests = |ijk: [i64; 3]| {
        let d: [T; 3] = std::array::from_fn(|x| T::from_i64(ijk[x] * ONE + H - a[x]));
        edges.iter().all(|l| l.g[0] * d[0] + l.g[1] * d[1] + l.g[2] * d[2] + l.c >= T::ZERO)
    };
    match w {
        0 => columns::<T, 0>(tri, lo, hi, edge_tests, slab),
        1 => columns::<T, 1>(tri, lo, hi, edge_tests, slab),
        _ => columns::<T, 2>(tri, lo, hi, edge_tests, slab),
    }
}

/// One triangle by the columns of its dominant-axis (`w`) projection. The
/// plane test alone passes exactly one voxel per column: with `n_w > 0`
/// and `d = m − a`, it asks `n·d ∈ [b − r, r − 1 + b]` (`b = bias(n)`,
/// `bias(−n) = 1 − b`, `r = H·n_w`), `2r = ONE·n_w` consecutive values,
/// and `n·d` steps by `ONE·n_w` along the column. That voxel `t*` is
/// tracked along each row by a remainder (it moves by at most one per
/// column as `|n_u| <= n_w`). Where the pixel square lies strictly inside
/// the projected triangle, the voxel is set with no further test: a point
/// `X` of the plane in the (displaced) octahedron projects strictly inside
/// the projection, so lies in the triangle, and its projections along the
/// other two axes lie in the projected triangle and in that projection's
/// (displaced) diamond, so every edge test passes. Where the square
/// misses the projection a `w` diamond test fails; the other columns run
/// the edge tests (`edge_tests`) on `t*`.
fn columns<T: PlaneInt, const W: usize>(
    tri: &LatticeTriangle,
    lo: [i64; 3],
    hi: [i64; 3],
    edge_tests: impl Fn([i64; 3]) -> bool,
    slab: &mut BrickSlab<'_>,
) {
    let s = TriSetup::<T>::new(tri);
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    let pix = PixelTest::new(&s, tri, (u, v, w));
    let n = tri.normal();
    let flip = if n[w] < 0 { -1 } else { 1 };
    let nf = n.map(|c| c * flip);
    let t = T::from_i64;
    let (nu, nv, d) = (t(nf[u]), t(nf[v]), t(nf[w] * ONE));
    // K = n·d − b + r at the voxel t = lo_w: t* = lo_w − floor(K / D).
    let kw = t(nf[w]) * t(lo[w] * ONE + H - s.a[w]) - t(bias(nf)) + t(H * nf[w]);
    let mut c0 = s.a;
    (c0[u], c0[v]) = (lo[u] * ONE + H, lo[v] * ONE + H);
    let mut c1 = c0;
    c1[u] += ONE;
    let b0 = pix.bounds(&s, s.local(c0));
    let delta = b0.delta(&pix.bounds(&s, s.local(c1)));
    let du = nu * t(ONE);
    for iv in lo[v]..=hi[v] {
        let mut c = c0;
        c[v] = iv * ONE + H;
        let pc = s.local(c);
        let mut b = pix.bounds(&s, pc);
        // Only the row's pixels that meet the projection: where the
        // square misses it, a `w` diamond test fails.
        let (a0, a1) = b.row_span(&delta, lo[u], hi[u]);
        if a0 > a1 {
            continue;
        }
        b.advance(&delta, t(a0 - lo[u]));
        let k = nu * pc[u] + nv * pc[v] + kw + du * t(a0 - lo[u]);
        let mut q = k.div_floor(d);
        let mut rem = k - q * d;
        let mut iu = a0;
        loop {
            debug_assert!(!b.misses());
            let tw = lo[w] - q.to_i128() as i64;
            if tw >= lo[w] && tw <= hi[w] {
                let mut ijk = [0i64; 3];
                (ijk[u], ijk[v], ijk[w]) = (iu, iv, tw);
                if b.strictly_inside_edges() == [true; 3] || edge_tests(ijk) {
                    slab.set(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
                }
            }
            if iu == a1 {
                break;
            }
            iu += 1;
            b.step(&delta);
            rem = rem + du;
            if rem >= d {
                rem = rem - d;
                q = q + t(1);
            } else if rem < T::ZERO {
                rem = rem + d;
                q = q - t(1);
            }
        }
    }
}

/// The slow, obviously correct definition of `ss6`.
pub mod reference {
    use super::*;
    use crate::geom::perturb::displaced_sign;
    use crate::grid::dense::DenseBits;

    /// Brute force over each triangle's bounding box.
    pub fn ss6(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, ss6_hit)
    }

    /// The formulas of the module documentation, with the displacement `δ`
    /// carried symbolically: a test `f(m + δ) >= 0` on an affine `f` with
    /// gradient `g` is `displaced_sign(f(m), g) >= 0`.
    pub fn ss6_hit(t: &LatticeTriangle, ijk: [i64; 3]) -> bool {
        let m: [i128; 3] = ijk.map(|c| (c * ONE + H) as i128);
        let v: [[i128; 3]; 3] = t.v.map(|p| p.map(|c| c as i128));
        let n: [i128; 3] = t.normal().map(|c| c as i128);
        let h = H as i128;
        let r = h * n.iter().map(|c| c.abs()).max().unwrap_or(0);
        let d: i128 = (0..3).map(|x| n[x] * (m[x] - v[0][x])).sum();
        if displaced_sign(d + r, n) < 0 || displaced_sign(r - d, n.map(|c| -c)) < 0 {
            return false;
        }
        for (c, &nc) in n.iter().enumerate() {
            let (p, q) = ((c + 1) % 3, (c + 2) % 3);
            let sgn = if nc >= 0 { 1 } else { -1 };
            for i in 0..3 {
                let (vi, vj) = (v[i], v[(i + 1) % 3]);
                let mut g = [0i128; 3];
                g[p] = -(vj[q] - vi[q]) * sgn;
                g[q] = (vj[p] - vi[p]) * sgn;
                let f = g[p] * (m[p] - vi[p]) + g[q] * (m[q] - vi[q]) + h * g[p].abs().max(g[q].abs());
                if displaced_sign(f, g) < 0 {
                    return false;
                }
            }
        }
        true
    }
}
