//! The complete scanline path (`--method scanline`) for `cover`, `sep26`
//! and `sep6`: projected scanlines whose every voxel range is exact.
//!
//! This work is based on: the projected optimal scanline idea (seed `000`:
//! project each triangle along its dominant axis, walk it scanline by
//! scanline) made exact with M. Schwarz, H.-P. Seidel, "Fast Parallel
//! Surface and Solid Voxelization on GPUs", ACM TOG 29(6), 2010, §3.1
//! (triangle/box overlap = bounding box, plane and nine projected edge
//! tests), each test solved for a range instead of evaluated per voxel.
//!
//! **Guarantee.** `cover`: exactly the voxels whose closed box meets a
//! triangle, identical to [`super::cover`]'s reference. `sep26`, `sep6`:
//! `cover`'s scanline voxels are the candidates, and each is kept iff the
//! mode's exact target test (Laine's space diagonals / 3D crosshair, with
//! the tie rule of [`crate::geom::perturb`]) passes, so the output is
//! exactly the definition. Published scanline voxelizers (the `pos` mode)
//! leave gaps because they join edge voxels with lines; here there is
//! nothing to fill, since no voxel is ever skipped by construction.
//!
//! **How.** With `w` the dominant axis of the normal and `(u, v, w)` a
//! cyclic permutation of `(x, y, z)`, each scanline is a row `v` of the
//! projection along `w`. Every test of the overlap theorem is linear in the
//! voxel index, and along a row:
//! - the three `(u, v)` edge tests classify each column as outside the
//!   projected triangle, on its boundary (the square straddles an edge) or
//!   inside it (the edge value at the square's worst corner is `>= 0`).
//!   `classify` does this for 16 columns at once in straight-line `f64`
//!   code (exact: the values are integers below `2^46`) that compiles to
//!   packed SIMD compares and minima; by convexity the columns that meet
//!   the projection are one contiguous run.
//! - the plane test gives each column its range of `w`: a floor division at
//!   the run's first column, then an exact remainder step per column
//!   (`|n_u| <= n_w`, so the range moves by at most one).
//! - inside columns need nothing else (a plane point in the voxel projects
//!   into the triangle, so it is a triangle point): the range is emitted as
//!   one run of bits. Boundary columns test their few voxels against the
//!   `(v, w)` and `(w, u)` edges.
//!
//! Triangles with a voxel box over `SMALL_BOX` (8192) voxels walk exact row spans
//! instead (`cover`'s row walker with incremental bounds, so the cost is
//! per row and per run, not per bounding-box column) and emit inside
//! columns as runs along the row, one per layer `t`, when the plane is
//! shallow along the row: the columns of layer `t` solve two linear
//! inequalities exactly.
//!
//! Parallel over z-slabs with the shared driver: deterministic for any
//! thread count. **Reference:** the modes' brute-force references; the
//! tests compare voxel for voxel.

use super::cover::{cover_triangle_runs, edges_2d, run, set};
use super::driver::{run_mesh, run_slabs, Filter, Kernel, Sink};
use super::targets::{CROSSHAIR, DIAGONALS};
use super::{Mode, Options, Report};
use crate::geom::divide::div_floor;
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::P3;
use crate::geom::setup::{fits_i64, DirSetup, TriSetup};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// Whether [`scanline`] implements `mode`.
pub fn supports(mode: Mode) -> bool {
    matches!(mode, Mode::Cover | Mode::Sep26 | Mode::Sep6)
}

/// The scanline path for `cover`, `sep26` or `sep6`, parallel over
/// z-slabs, into sparse bricks. `None` for other modes.
pub fn scanline(mode: Mode, mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> Option<(BrickBits, Report)> {
    if !supports(mode) {
        return None;
    }
    Some(run_mesh(&ScanKernel { mode }, mesh, grid, opts))
}

/// The scanline path on prepared triangles of a grid of `dims` (one tile
/// of the tiled driver, or a whole grid). `None` for modes it does not
/// implement.
pub fn scanline_lattice(mode: Mode, tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> Option<BrickBits> {
    supports(mode).then(|| run_slabs(&ScanKernel { mode }, tris, dims, opts).0)
}

/// Whether the scanline path is expected to beat the triangle-box fast path
/// by a wide margin (20 % or more) for `mode` on this mesh and grid (what
/// `--method auto` asks), from the measurements in docs/bench-log/ on two
/// machines: with triangles of up to a hundred voxels the two are within
/// −23 %…+16 % of each other, the sign changing with the machine and the
/// mesh, so the fast path is kept; on faces of hundreds of voxels
/// `cover`'s runs replace per-voxel work (a box at 512: 2.1× faster).
/// `sep26` and `sep6` never gained 20 % (a box: −6 % and +11 %; the
/// teapot at 4096: −75 % and +1 %). So: `cover` only, when the median
/// triangle extent (over a deterministic sample of up to 4096 triangles)
/// reaches [`PREFER_EXTENT_VOXELS`].
pub fn prefers(mode: Mode, mesh: MeshRef<'_>, grid: &GridSpec) -> bool {
    let threshold = match mode {
        Mode::Cover => PREFER_EXTENT_VOXELS,
        _ => return false,
    };
    if mesh.triangles.is_empty() {
        return false;
    }
    let step = mesh.triangles.len().div_ceil(4096);
    let mut extents: Vec<f64> = mesh
        .triangles
        .iter()
        .step_by(step)
        .filter_map(|t| {
            let [a, b, c] = [mesh.positions.get(t[0] as usize)?, mesh.positions.get(t[1] as usize)?, mesh.positions.get(t[2] as usize)?];
            let e = ((a.max(*b).max(*c) - a.min(*b).min(*c)) / grid.voxel_size().0).max_element();
            e.is_finite().then_some(e)
        })
        .collect();
    if extents.is_empty() {
        return false;
    }
    let mid = extents.len() / 2;
    let (_, median, _) = extents.select_nth_unstable_by(mid, f64::total_cmp);
    *median >= threshold
}

/// Median triangle extent (voxels) from which `auto` takes the scanline
/// path for `cover`.
pub const PREFER_EXTENT_VOXELS: f64 = 128.0;

struct ScanKernel {
    mode: Mode,
}

impl Kernel<LatticeTriangle> for ScanKernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        match (self.mode, fits_i64(tri)) {
            (Mode::Sep26, true) => targets::<i64, 4>(tri, lo, hi, &DIAGONALS, slab),
            (Mode::Sep26, false) => targets::<i128, 4>(tri, lo, hi, &DIAGONALS, slab),
            (Mode::Sep6, true) => targets::<i64, 3>(tri, lo, hi, &CROSSHAIR, slab),
            (Mode::Sep6, false) => targets::<i128, 3>(tri, lo, hi, &CROSSHAIR, slab),
            _ => scan_triangle(tri, lo, hi, slab),
        }
    }
}

/// `cover`'s scanline voxels of `tri`, kept iff the triangle meets one of
/// the voxel's target segments (start offset, direction).
fn targets<T: PlaneInt, const N: usize>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], segs: &[(P3, P3); N], slab: &mut BrickSlab<'_>) {
    let s = TriSetup::<T>::new(tri);
    let dirs: [DirSetup<T>; N] = std::array::from_fn(|i| s.dir(tri, segs[i].1));
    let keep = |i: i64, j: i64, k: i64| {
        let ijk = [i, j, k];
        (0..N).any(|i| {
            let o = segs[i].0;
            s.segment_hits(&dirs[i], s.local([ijk[0] * ONE + o[0], ijk[1] * ONE + o[1], ijk[2] * ONE + o[2]]))
        })
    };
    scan_triangle(tri, lo, hi, &mut Filter { slab, keep });
}

/// Triangles whose voxel box has at most this many voxels scan the box's
/// rows ([`scan_rows`]); larger ones walk exact row spans.
const SMALL_BOX: i64 = 8192;

/// ... and whose extent (lattice units) keeps every value of [`scan_rows`]
/// in `i64` (plane values below `2^61`).
const SMALL_EXTENT: i64 = (1 << 19) - 2 * ONE;

/// Emits exactly the voxels of `[lo, hi]` whose closed box meets `tri`.
pub(crate) fn scan_triangle<O: Sink>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (blo, bhi) = tri.bounds();
    let extent = (0..3).map(|a| bhi[a] - blo[a]).max().unwrap_or(0);
    let volume: i64 = (0..3).map(|a| hi[a] - lo[a] + 1).product();
    if volume > SMALL_BOX || extent > SMALL_EXTENT {
        // Large: exact row spans walked incrementally, runs emitted.
        cover_triangle_runs(tri, lo, hi, out);
        return;
    }
    let n = tri.normal();
    let w = (0..3).fold(0, |best, a| if n[a].abs() > n[best].abs() { a } else { best });
    match w {
        0 => scan_rows::<O, 0>(tri, n, lo, hi, out),
        1 => scan_rows::<O, 1>(tri, n, lo, hi, out),
        _ => scan_rows::<O, 2>(tri, n, lo, hi, out),
    }
}

/// The small-triangle path; see the module doc. Coordinates are relative
/// to `lo`, so every value stays small.
#[inline(always)]
fn scan_rows<O: Sink, const W: usize>(tri: &LatticeTriangle, n: [i64; 3], lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    let rel = LatticeTriangle { v: tri.v.map(|p| std::array::from_fn(|a| p[a] - lo[a] * ONE)) };
    let size: [i64; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
    let sign = |x: i64| if x >= 0 { 1 } else { -1 };
    // Edge functions `a·p + b·q + c >= 0` over voxel indices of the
    // projections (u, v), (v, w), (w, u), at each square's best corner. A
    // (u, v) square lies inside the projected triangle iff every edge is
    // non-negative at its worst corner too: `f >= |a| + |b|`.
    let uv = edges_2d(&rel, u, v, sign(n[w]));
    let vw = edges_2d(&rel, v, w, sign(n[u]));
    let wu = edges_2d(&rel, w, u, sign(n[v]));
    let inside: [i64; 3] = uv.map(|e| e.a.abs() + e.b.abs());

    // Plane, oriented so n_w > 0, in voxel-index units (× ONE): the voxel
    // at t is crossed iff t >= -floor((nu·u + nv·v + d_max) / nw) and
    // t <= floor(-(nu·u + nv·v + d_min) / nw).
    let flip = sign(n[w]);
    let no = n.map(|c| c * flip);
    let nv0 = no[0] * rel.v[0][0] + no[1] * rel.v[0][1] + no[2] * rel.v[0][2];
    let (d_min, d_max) = no.iter().fold((-nv0, -nv0), |(a, b), &c| if c < 0 { (a + c * ONE, b) } else { (a, b + c * ONE) });
    let (nu, nv, nw) = (no[u] * ONE, no[v] * ONE, no[w] * ONE);

    // (u, v) edge values as exact f64 integers (below 2^46 here) for the
    // vectorised classification of columns.
    let ea: [f64; 3] = uv.map(|e| e.a as f64);
    let inside_f: [f64; 3] = inside.map(|x| x as f64);
    for iv in 0..=size[v] {
        // The scanline: 16 columns at a time are classified (outside, on the
        // boundary, inside) by the vectorised loop of `classify`; the
        // columns that meet the projection are one contiguous run.
        let e0: [f64; 3] = std::array::from_fn(|i| (uv[i].b * iv + uv[i].c) as f64);
        let rvw: [i64; 3] = std::array::from_fn(|i| vw[i].a * iv + vw[i].c);
        // Plane range as F = floor(num / nw), R = num − F·nw ∈ [0, nw), set
        // at the run's first column; each column adds nu to num, and
        // |nu| <= nw moves F by at most one.
        let (mut f0, mut r0, mut f1, mut r1) = (0, 0, 0, 0);
        let mut started = false;
        let mut x0 = 0;
        while x0 <= size[u] {
            let n = (size[u] - x0 + 1).min(LANES as i64) as u32;
            let (outer, inner) = classify(&e0, &ea, &inside_f, x0 as f64);
            let outer = outer & ((1u32 << n) - 1);
            if outer == 0 {
                if started {
                    break;
                }
                x0 += LANES as i64;
                continue;
            }
            let first = x0 + outer.trailing_zeros() as i64;
            let last = x0 + (31 - outer.leading_zeros()) as i64;
            if !started {
                started = true;
                (f0, r0) = div_floor(d_max + nv * iv + nu * first, nw);
                (f1, r1) = div_floor(-d_min - nv * iv - nu * first, nw);
            }
            for iu in first..=last {
                let (t0, t1) = ((-f0).max(0), f1.min(size[w]));
                if t0 <= t1 {
                    if (inner >> (iu - x0)) & 1 == 1 {
                        // Inside the projection the plane test decides: a plane
                        // point in the voxel projects into the triangle. One run.
                        run::<O, W>(out, W, iu + lo[u], iv + lo[v], t0 + lo[w], t1 - t0 + 1);
                    } else {
                        // On its boundary: the (v, w) and (w, u) edge tests per voxel.
                        let rwu: [i64; 3] = std::array::from_fn(|i| wu[i].b * iu + wu[i].c);
                        for t in t0..=t1 {
                            let ok = (0..3).all(|i| vw[i].b * t + rvw[i] >= 0 && wu[i].a * t + rwu[i] >= 0);
                            if ok {
                                set::<O, W>(out, iu + lo[u], iv + lo[v], t + lo[w]);
                            }
                        }
                    }
                }
                step_floor(&mut f0, &mut r0, nu, nw);
                step_floor(&mut f1, &mut r1, -nu, nw);
            }
            if last < x0 + n as i64 - 1 {
                break;
            }
            x0 += LANES as i64;
        }
    }
}

/// Adds `delta` (`|delta| <= d`) to the numerator of `f = floor(num / d)`
/// with remainder `r = num − f·d ∈ [0, d)`, keeping both exact without a
/// division or a branch.
#[inline(always)]
fn step_floor(f: &mut i64, r: &mut i64, delta: i64, d: i64) {
    *r += delta;
    let s = (*r >= d) as i64 - (*r < 0) as i64;
    *f += s;
    *r -= s * d;
}

/// Columns classified per call of [`classify`].
const LANES: usize = 16;

/// The vectorised inner loop: for the columns `x0 .. x0 + 16` of a row, with
/// the (u, v) edge values `e0[i] + a[i]·x` (exact integers in `f64`), bit
/// `k` of the first mask says column `x0 + k` meets the projected triangle
/// (every edge `>= 0` at the square's best corner), of the second that its
/// square lies inside it (every edge `>= inside[i]`, the worst corner).
/// Straight-line code over a fixed 16 lanes: packed compares and minima,
/// then a bit gather.
#[inline(always)]
fn classify(e0: &[f64; 3], a: &[f64; 3], inside: &[f64; 3], x0: f64) -> (u32, u32) {
    let mut best = [0f64; LANES];
    let mut worst = [0f64; LANES];
    for k in 0..LANES {
        let x = x0 + k as f64;
        let (g0, g1, g2) = (e0[0] + a[0] * x, e0[1] + a[1] * x, e0[2] + a[2] * x);
        let m = if g0 < g1 { g0 } else { g1 };
        best[k] = if m < g2 { m } else { g2 };
        let (h0, h1, h2) = (g0 - inside[0], g1 - inside[1], g2 - inside[2]);
        let m = if h0 < h1 { h0 } else { h1 };
        worst[k] = if m < h2 { m } else { h2 };
    }
    let (mut outer, mut inner) = (0u32, 0u32);
    for k in 0..LANES {
        outer |= ((best[k] >= 0.0) as u32) << k;
        inner |= ((worst[k] >= 0.0) as u32) << k;
    }
    (outer, inner)
}
