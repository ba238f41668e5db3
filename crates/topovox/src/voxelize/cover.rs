//! Conservative surface voxelization (`cover`).
//!
//! This work is based on: M. Schwarz, H.-P. Seidel, "Fast Parallel Surface
//! and Solid Voxelization on GPUs", ACM TOG 29(6), 2010 (the triangle/box
//! overlap test with per-triangle setup, §3.1), and T. Akenine-Möller, "Fast
//! 3D Triangle-Box Overlap Testing", JGT 6(1), 2001 (the separating axis
//! test used by the reference).
//!
//! **Guarantee.** Voxel `(i,j,k)` is set iff its closed box meets at least
//! one closed (snapped, non-degenerate) triangle. Exact touches — a vertex,
//! edge or face lying on a voxel face, edge or corner — count as meeting, so
//! a vertex on a corner shared by eight voxels sets all eight. For a closed
//! surface the result is 26-separating.
//!
//! **Tie rule and exactness.** Vertices are snapped to the lattice of
//! [`crate::geom::fixed`]; every comparison below is on exact integers
//! (`i64`, `i128` where products need it), so the fast path and the
//! reference decide every touch the same way. Zero-area triangles (after
//! snapping) are skipped and counted.
//!
//! **Cost.** Per triangle: constant setup; then, for each column of the
//! dominant-axis projection, a few additions to track the plane's range
//! exactly; and per candidate voxel (those the plane crosses) at most six
//! integer edge tests. Small triangles scan, row by row, the span of their
//! box's columns inside the projection (one division per edge); large ones
//! walk rows with exact incremental edge bounds, so their work is
//! proportional to their area, not to their bounding box.
//!
//! **Reference:** [`reference::cover`], the separating axis test on all
//! thirteen axes for every voxel of each triangle's bounding box.
//!
//! # Implementation notes
//!
//! `cover_triangle` is also the candidate enumerator of the modes below
//! (each is a subset of `cover`). Short paths for small triangles: one
//! voxel, one run (single-voxel span on two axes: no test), one 2D
//! projection test (single-voxel span on one axis), the octant test for
//! 2×2×2 spans (one plane and nine edge values at the block's centre
//! lattice point, each selecting a mask of octants), the tiny-box SAT with
//! per-projection bit masks (other spans up to 4: each projection's
//! passing squares copied along its axis into a 64-bit mask of the 4×4×4
//! span and ANDed), with no branch per voxel on a test's outcome. Both
//! hand their voxels over as one mask (`Sink::set_block2`, `set_span4`),
//! so `FilterUnset` reads which are already set in one go. Boxes up to 1024
//! voxels: each row's span of columns inside the projection (the three
//! edge functions solved per row), the plane's range of `t` tracked along
//! it, six incremental edge tests per candidate; larger ones: row walkers.
//!
//! Per triangle (Schwarz & Seidel 2010, in exact integers):
//! 1. Setup: normal `n`, dominant axis `w` (largest `|n_w|`), and the three
//!    projections' edge functions with critical-corner offsets (`uv` = the
//!    dominant plane, `vw`, `wu`). Plane values are computed relative to the
//!    traversed box's corner, in `i64` for triangles under ~126 voxels across
//!    and `i128` above that.
//! 2. Along a row of the dominant projection, the range of voxels the plane
//!    crosses moves by at most one per column (`|n_u| ≤ n_w`), so it is
//!    tracked exactly with additions only.
//! 3. Two traversals (`Options::traversal`; the result does not depend on it):
//!    - *scan* (small boxes, the common case): every column of the box, the
//!      dominant-plane edge functions as running sums; in the plane's range,
//!      the six other edge tests per voxel.
//!    - *walk rows* (large triangles): Bresenham-style edge walkers (one
//!      division per edge, then an add and a compare per row) give each row's
//!      exact column span, its *interior* span (square entirely inside the
//!      projected triangle: the plane test alone decides there, since a plane
//!      point inside the voxel projects inside the triangle) and the `t` range
//!      allowed by the `vw` edges; boundary columns test the `wu` edges.
//!
//! Deviation from the paper: the paper tests every voxel of the bounding box
//! with the plane test and all three projections; we enumerate only the
//! voxels the plane crosses and only test what is not implied. The result is
//! the same set, which the tests check against the brute-force SAT reference
//! for every traversal, thread count and slab height (`topovox_testkit::agree`).

use super::driver::{buffered, run_mesh, run_slabs, span4_offset, Kernel, Sink, SPAN4_STRIDE};
use super::{Options, Report, Traversal};
use crate::geom::divide::{ceil_div, div_floor, floor_div};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::{prepare, LatticeTriangle};
use crate::grid::bricks::{block2_offset, BrickBits, BrickSlab};
use crate::grid::dense::DenseBits;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// Conservative surface voxelization, fast path (parallel over z-slabs),
/// into sparse brick storage (`.to_dense()` for a dense grid).
pub fn cover(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&CoverKernel { traversal: opts.traversal }, mesh, grid, opts)
}

/// The fast path on already prepared triangles.
pub fn cover_lattice(tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> BrickBits {
    run_slabs(&CoverKernel { traversal: opts.traversal }, tris, dims, opts).0
}

/// A 2D edge function `f(p, q) = a·p + b·q + c` over voxel indices; the
/// projected voxel square is not outside the edge iff `f >= 0`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Edge2 {
    pub a: i64,
    pub b: i64,
    pub c: i64,
}

/// Schwarz–Seidel edge functions of the triangle projected onto the plane of
/// axes `(p, q)`, oriented by `sigma` (the sign of the normal's third
/// component, `+1` when it is zero: the projection is then a segment and
/// its edges face both ways, so either sign is exact).
///
/// The critical-corner offset `max(0, a)·1 + max(0, b)·1` makes
/// `f(corner) >= 0` equivalent to "some point of the unit square is on the
/// inner side of the edge" — the separating axis test on that edge normal.
pub(crate) fn edges_2d(tri: &LatticeTriangle, p: usize, q: usize, sigma: i64) -> [Edge2; 3] {
    std::array::from_fn(|i| {
        let e = tri.edge(i);
        let v = tri.v[i];
        let a = -e[q] * sigma;
        let b = e[p] * sigma;
        let c = -(a * v[p] + b * v[q]) + (a * ONE).max(0) + (b * ONE).max(0);
        Edge2 { a: a * ONE, b: b * ONE, c }
    })
}

/// Largest `extent + 2 voxels` (lattice units) for which the plane test is
/// exact in `i64`: plane values are bounded by `24·B³ < 2^62` when `B <= 2^19`.
const I64_PLANE_LIMIT: i64 = 1 << 19;

/// Per-triangle setup of the fast test, in axes permuted so that `w` is the
/// dominant axis of the normal and `(u, v, w)` is a cyclic (right-handed)
/// permutation of `(x, y, z)`. Plane values are relative to the voxel
/// `origin` (the low corner of the box being traversed), which keeps them
/// small enough for `i64` on all but huge triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Setup<T> {
    w: usize,
    uv: [Edge2; 3],
    vw: [Edge2; 3],
    wu: [Edge2; 3],
    origin: [i64; 3],
    /// Normal, oriented so `n[w] > 0`, scaled to voxel-index units (`× ONE`).
    n: [T; 3],
    /// Plane value offsets at the voxel's min- and max-side critical corners.
    d_min: T,
    d_max: T,
    inv_nw: f64,
    /// The triangle's own (unclamped) voxel span along `w`; bounds estimates.
    span_w: (i64, i64),
}

impl<T: PlaneInt> Setup<T> {
    pub(crate) fn new(tri: &LatticeTriangle, origin: [i64; 3]) -> Setup<T> {
        let n = tri.normal();
        let w = (0..3).fold(0, |best, a| if n[a].abs() > n[best].abs() { a } else { best });
        let (u, v) = ((w + 1) % 3, (w + 2) % 3);
        let sign = |x: i64| if x >= 0 { 1 } else { -1 };
        let uv = edges_2d(tri, u, v, sign(n[w]));
        let vw = edges_2d(tri, v, w, sign(n[u]));
        let wu = edges_2d(tri, w, u, sign(n[v]));
        let flip = if n[w] < 0 { -1 } else { 1 };
        let no: [T; 3] = std::array::from_fn(|a| T::from_i64(n[a] * flip));
        let one = T::from_i64(ONE);
        let v0: [T; 3] = std::array::from_fn(|a| T::from_i64(tri.v[0][a] - origin[a] * ONE));
        let nv0 = no[0] * v0[0] + no[1] * v0[1] + no[2] * v0[2];
        let (mut d_min, mut d_max) = (-nv0, -nv0);
        for c in no {
            let t = c * one;
            if t < T::ZERO {
                d_min = d_min + t;
            } else {
                d_max = d_max + t;
            }
        }
        let n_idx = no.map(|c| c * one);
        let (tlo, thi) = tri.bounds();
        let span_w = crate::geom::fixed::voxel_span(tlo[w], thi[w]);
        Setup { w, uv, vw, wu, origin, n: n_idx, d_min, d_max, inv_nw: 1.0 / n_idx[w].to_f64(), span_w }
    }
}

impl<T: PlaneInt> Setup<T> {
    /// The dominant axis `w` (`(u, v, w)` cyclic).
    pub(crate) fn w(&self) -> usize {
        self.w
    }

    /// `n_u` and `n_w` scaled as [`PlaneRange`] steps them.
    pub(crate) fn steps(&self) -> (T, T) {
        (self.n[(self.w + 1) % 3], self.n[self.w])
    }

    /// Moves the plane range's thresholds: afterwards [`PlaneRange`] gives
    /// the voxels whose corners' highest plane value (relative to the
    /// first vertex, with `n` oriented so `n_w > 0`) is `>= hi` and lowest
    /// `<= lo`, instead of `>= 0` and `<= 0`.
    pub(crate) fn shift_plane(&mut self, hi: T, lo: T) {
        self.d_max = self.d_max - hi;
        self.d_min = self.d_min - lo;
    }
}

struct CoverKernel {
    traversal: Traversal,
}

impl Kernel<LatticeTriangle> for CoverKernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        buffered(lo, hi, slab, |slab, buf| match buf {
            Some(b) => cover_triangle(tri, lo, hi, self.traversal, b),
            None => cover_triangle(tri, lo, hi, self.traversal, slab),
        });
    }
}

/// Emits into `out` exactly the voxels of the inclusive index box `[lo, hi]`
/// whose closed box meets `tri` (each at most once). Every mode whose
/// target lies inside the voxel is a subset of this, so their fast paths
/// use it to enumerate candidates.
pub(crate) fn cover_triangle<O: Sink>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], traversal: Traversal, out: &mut O) {
    let (blo, bhi) = tri.bounds();
    if traversal == Traversal::Auto && small_triangle(tri, (blo, bhi), lo, hi, out) {
        return;
    }
    let extent = (0..3).map(|a| bhi[a] - blo[a]).max().unwrap_or(0);
    if extent + 2 * ONE <= I64_PLANE_LIMIT {
        let s = Setup::<i64>::new(tri, lo);
        let volume: i64 = (0..3).map(|a| hi[a] - lo[a] + 1).product();
        let scan = match traversal {
            Traversal::Auto => volume <= SMALL_BOX,
            Traversal::ScanBoxes => true,
            Traversal::WalkRows => false,
        };
        if scan {
            match s.w {
                0 => scan_box::<O, 0>(&s, lo, hi, out),
                1 => scan_box::<O, 1>(&s, lo, hi, out),
                _ => scan_box::<O, 2>(&s, lo, hi, out),
            }
        } else {
            dispatch::<i64, O, false>(&s, lo, hi, out);
        }
    } else {
        dispatch::<i128, O, false>(&Setup::new(tri, lo), lo, hi, out);
    }
}

/// The short paths of [`cover_triangle`] for triangles whose own voxel
/// span (unclamped) is a single voxel on at least one axis; returns `false`
/// for the others, which take the general traversal.
///
/// - One voxel on two or three axes: every point of the triangle lies
///   strictly inside those voxels' slabs, and the triangle (connected)
///   projects onto the remaining axis as its whole span, so every voxel of
///   the box is met: the box is emitted as one run, with no test.
/// - One voxel on one axis `r`: every point lies strictly inside that slab,
///   so voxel `(p, q, r)` is met iff the projection onto the `(p, q)` plane
///   meets its square: the three projected edge functions (the separating
///   axis test in 2D; the square's own axes hold inside the span).
#[inline(always)]
fn small_triangle<O: Sink>(tri: &LatticeTriangle, (blo, bhi): ([i64; 3], [i64; 3]), lo: [i64; 3], hi: [i64; 3], out: &mut O) -> bool {
    let span: [(i64, i64); 3] = std::array::from_fn(|a| crate::geom::fixed::voxel_span(blo[a], bhi[a]));
    let single: [bool; 3] = std::array::from_fn(|a| span[a].0 == span[a].1);
    match single.iter().filter(|&&b| b).count() {
        3 => out.set(lo[0] as u32, lo[1] as u32, lo[2] as u32),
        2 => {
            let a = (0..3).find(|&a| !single[a]).unwrap_or(0);
            out.set_run(a, lo.map(|c| c as u32), (hi[a] - lo[a] + 1) as u32);
        }
        // One instance per axis: constant indexing.
        1 if single[0] => one_slab::<O, 0>(tri, lo, hi, out),
        1 if single[1] => one_slab::<O, 1>(tri, lo, hi, out),
        1 => one_slab::<O, 2>(tri, lo, hi, out),
        _ if (0..3).all(|a| span[a].1 - span[a].0 < TINY) => {
            let n = span.map(|s| (s.1 - s.0 + 1) as usize);
            // Decided here, where the spans are in registers: compared as
            // an array in `tiny_box`, they were one wide load that stalled
            // on the narrow stores just made (store forwarding).
            let octant = (n[0] == 2) & (n[1] == 2) & (n[2] == 2);
            tiny_box(tri, span.map(|s| s.0), n, octant, lo, hi, out)
        }
        _ => return false,
    }
    true
}

/// [`small_triangle`] for a triangle inside one slab of axis `R`: the
/// three edge functions of its projection along `R`, per square.
#[inline(always)]
fn one_slab<O: Sink, const R: usize>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (r, p, q) = (R, (R + 1) % 3, (R + 2) % 3);
    let n = tri.normal();
    let e = edges_2d(tri, p, q, if n[r] >= 0 { 1 } else { -1 });
    let mut ijk = [0u32; 3];
    ijk[r] = lo[r] as u32;
    for iq in lo[q]..=hi[q] {
        let row: [i64; 3] = std::array::from_fn(|i| e[i].b * iq + e[i].c);
        for ip in lo[p]..=hi[p] {
            if (e[0].a * ip + row[0]) | (e[1].a * ip + row[1]) | (e[2].a * ip + row[2]) >= 0 {
                ijk[p] = ip as u32;
                ijk[q] = iq as u32;
                out.set(ijk[0], ijk[1], ijk[2]);
            }
        }
    }
}

/// Largest voxel span per axis that [`tiny_box`] takes.
const TINY: i64 = 4;

/// The full separating axis test for a triangle whose voxel span is at
/// most [`TINY`] voxels on every axis, in small integers relative to the
/// span's low corner: the three projections' edge tests are evaluated once
/// per square of each face of the span (a bit mask per projection), the
/// plane test once per voxel, and a voxel is set iff its three squares and
/// its plane test pass. The box axes hold inside the span; these are the
/// other ten axes, so this is the definition, not an approximation. Only
/// voxels of `[lo, hi]` are emitted.
#[inline(never)]
fn tiny_box<O: Sink>(tri: &LatticeTriangle, base: [i64; 3], n: [usize; 3], octant: bool, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    // Most tiny triangles span 2×2×2 voxels (`octant`; about two thirds at
    // 128³ on the bunny): those take the octant test.
    if octant {
        octants(tri, base, lo, hi, out)
    } else {
        tiny_box_n(tri, base, n, lo, hi, out)
    }
}

/// Octants whose coordinate along axis `c` is the upper one (bit
/// `i + 2j + 4k` of a mask is the voxel `base + (i, j, k)`), and the lower.
const UPPER: [u8; 3] = [0b1010_1010, 0b1100_1100, 0b1111_0000];
const LOWER: [u8; 3] = [0b0101_0101, 0b0011_0011, 0b0000_1111];

/// The octants reaching out along axis `c` in the direction a value with
/// slope `slope` along `c` increases (none if it is flat).
#[inline(always)]
fn rising(c: usize, slope: i64) -> u8 {
    // Without branches: the slopes' signs are the triangle's, random.
    (UPPER[c] & 0u8.wrapping_sub((slope > 0) as u8)) | (LOWER[c] & 0u8.wrapping_sub((slope < 0) as u8))
}

/// [`tiny_box`] for a span of 2×2×2 voxels: the triangle lies in the
/// closed block of the eight voxels, so it meets a voxel iff it meets the
/// voxel's octant around the block's centre lattice point `P` (the
/// octant's other sides hold the whole block). The separating axis test
/// against an octant needs one value per axis at `P`: an octant meets the
/// closed half-space `f >= 0` of an affine `f` iff `f(P) >= 0` or `f`
/// rises along one of its directions. That decides the plane (both sides
/// of it, with `f = ±(n·(x − v₀))`) and, in each axis projection, the
/// three edges' inner half-planes; the box axes hold, as the triangle
/// reaches both sides of `P` on every axis. Nine edge values and one
/// plane value, against the 3 × 4 squares and 8 plane tests of the
/// general case.
#[inline(always)]
fn octants<O: Sink>(tri: &LatticeTriangle, base: [i64; 3], lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    // Vertices relative to P.
    let v: [[i64; 3]; 3] = tri.v.map(|p| std::array::from_fn(|a| p[a] - (base[a] + 1) * ONE));
    let rel = LatticeTriangle { v };
    let n = rel.normal();
    // The plane's value n·(x − v₀) at P; the octant meets the plane iff it
    // reaches a value of the other sign (or P is on it).
    let h = -(n[0] * v[0][0] + n[1] * v[0][1] + n[2] * v[0][2]);
    let mut mask = match h {
        0 => 0xff,
        h if h > 0 => rising(0, -n[0]) | rising(1, -n[1]) | rising(2, -n[2]),
        _ => rising(0, n[0]) | rising(1, n[1]) | rising(2, n[2]),
    };
    // Indexed loops: with them the compiler unrolls both (iterating over
    // `n` and `v` instead cost this test its whole gain).
    #[allow(clippy::needless_range_loop)]
    for r in 0..3 {
        let (p, q) = ((r + 1) % 3, (r + 2) % 3);
        let sigma = if n[r] >= 0 { 1 } else { -1 };
        for i in 0..3 {
            let e = rel.edge(i);
            let (a, b) = (-e[q] * sigma, e[p] * sigma);
            // The edge function a·(x_p − v_p) + b·(x_q − v_q) at P.
            // Where the value at P is not positive, every octant keeps
            // (all ones), without a branch.
            let outside = a * v[i][p] + b * v[i][q] > 0;
            mask &= rising(p, a) | rising(q, b) | 0u8.wrapping_sub(!outside as u8);
        }
    }
    // The whole block in the box (nearly always): at once, so a filter can
    // read which of its voxels are already set in one go.
    if (0..3).all(|a| base[a] >= lo[a] && base[a] < hi[a]) {
        out.set_block2(base.map(|c| c as u32), mask);
        return;
    }
    while mask != 0 {
        let d = block2_offset(mask.trailing_zeros());
        mask &= mask - 1;
        let ijk: [i64; 3] = std::array::from_fn(|a| base[a] + d[a] as i64);
        if (0..3).all(|a| ijk[a] >= lo[a] && ijk[a] <= hi[a]) {
            out.set(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
        }
    }
}

/// [`tiny_box_n`]'s masks are those of `Sink::set_span4` (4×4×4 voxels
/// in 64 bits, bit `i + 4j + 16k`): spans up to [`TINY`] fit.
const STRIDE: [i64; 3] = SPAN4_STRIDE;
const _: () = assert!(TINY <= 4, "tiny spans must fit a 4×4×4 mask");

/// Per axis `r`: a mask with a bit at every coordinate along `r` (`0..4`)
/// and 0 on the other two. Multiplying a mask whose bits all have
/// coordinate 0 along `r` by it copies each bit along `r` (no carries: the
/// copies' bits are distinct).
const SPREAD: [u64; 3] = [0xf, 0x1111, 0x0001_0001_0001_0001];

/// The body of [`tiny_box`] for spans other than 2×2×2, by bit masks over
/// the span's voxels (at most 4×4×4): per projection, the squares that
/// pass their three edge tests, each copied along the projection's axis
/// to the voxels over it; their `AND` holds the voxels whose three squares
/// pass, and only those get the plane test. No branch per voxel on the
/// tests' outcomes (at 256³ most boxes are 2–3 voxels a side, and those
/// branches were the path's cost).
#[inline(always)]
fn tiny_box_n<O: Sink>(tri: &LatticeTriangle, base: [i64; 3], n: [usize; 3], lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let rel = LatticeTriangle { v: tri.v.map(|p| std::array::from_fn(|a| p[a] - base[a] * ONE)) };
    let nrm = rel.normal();
    let mut cand = u64::MAX;
    for r in 0..3 {
        let (p, q) = ((r + 1) % 3, (r + 2) % 3);
        let e = edges_2d(&rel, p, q, if nrm[r] >= 0 { 1 } else { -1 });
        // The squares (ip, iq) of the projection along r that pass, at
        // the voxels of coordinate 0 along r.
        let mut squares = 0u64;
        for ip in 0..n[p] as i64 {
            for iq in 0..n[q] as i64 {
                let pass =
                    (e[0].a * ip + e[0].b * iq + e[0].c) | (e[1].a * ip + e[1].b * iq + e[1].c) | (e[2].a * ip + e[2].b * iq + e[2].c) >= 0;
                squares |= (pass as u64) << (ip * STRIDE[p] + iq * STRIDE[q]);
            }
        }
        cand &= squares * SPREAD[r];
    }
    // Only voxels of `[lo, hi]` (a slab or the grid may cut the span).
    if (0..3).any(|a| base[a] < lo[a] || base[a] + n[a] as i64 - 1 > hi[a]) {
        let range = |a: usize| {
            let (from, to) = ((lo[a] - base[a]).max(0), (hi[a] - base[a]).min(n[a] as i64 - 1));
            (from..=to).fold(0u64, |m, x| m | 1 << (x * STRIDE[a]))
        };
        cand &= range(0) * range(1) * range(2);
    }
    // Plane values at each voxel's lowest and highest corners along n.
    let n0 = nrm[0] * rel.v[0][0] + nrm[1] * rel.v[0][1] + nrm[2] * rel.v[0][2];
    let (mut dmin, mut dmax) = (-n0, -n0);
    for c in nrm {
        if c < 0 {
            dmin += c * ONE;
        } else {
            dmax += c * ONE;
        }
    }
    let mut met = 0u64;
    while cand != 0 {
        let b = cand.trailing_zeros();
        cand &= cand - 1;
        let [i, j, k] = span4_offset(b);
        let g = (nrm[0] * i + nrm[1] * j + nrm[2] * k) * ONE;
        met |= (((g + dmin <= 0) & (g + dmax >= 0)) as u64) << b;
    }
    out.set_span4(base, met);
}

/// The row walk of [`cover_triangle`] with run emission: in each row, the
/// columns inside the projected triangle are emitted as runs — along the
/// row (one run per layer `t`, solved exactly from the plane inequalities)
/// when the plane is shallow along the row, else one run along `w` per
/// column. The scanline path uses it for large triangles.
pub(crate) fn cover_triangle_runs<O: Sink>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (blo, bhi) = tri.bounds();
    let extent = (0..3).map(|a| bhi[a] - blo[a]).max().unwrap_or(0);
    if extent + 2 * ONE <= I64_PLANE_LIMIT {
        dispatch::<i64, O, true>(&Setup::new(tri, lo), lo, hi, out);
    } else {
        dispatch::<i128, O, true>(&Setup::new(tri, lo), lo, hi, out);
    }
}

/// Exact incremental bound of a linear constraint `a·x + b·y + c >= 0` on
/// integer `x`, stepped along `y` (Bresenham-style: one division at the
/// start, then an addition and a comparison per step).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Walker {
    /// `a > 0`: `x >= lo`; `lo = ceil(-(b·y + c) / a)`, `r = a·lo + b·y + c ∈ [0, a)`.
    Lower { lo: i64, r: i64, q: i64, m: i64, d: i64 },
    /// `a < 0`: `x <= hi`; `hi = floor((b·y + c) / -a)`, `r = (b·y + c) - (-a)·hi ∈ [0, -a)`.
    Upper { hi: i64, r: i64, q: i64, m: i64, d: i64 },
    /// `a == 0`: all `x` or none, as `n = b·y + c` is `>= 0` or not.
    Const { n: i64, b: i64 },
}

impl Walker {
    #[inline(always)]
    pub(crate) fn new(a: i64, b: i64, c: i64, y0: i64) -> Walker {
        let n = b * y0 + c;
        if a > 0 {
            let (q0, r0) = div_floor(n, a);
            let (lo, r) = (-q0, r0);
            let (q, m) = div_floor(-b, a);
            Walker::Lower { lo, r, q, m, d: a }
        } else if a < 0 {
            let d = -a;
            let (hi, r) = div_floor(n, d);
            let (q, m) = div_floor(b, d);
            Walker::Upper { hi, r, q, m, d }
        } else {
            Walker::Const { n, b }
        }
    }

    /// Moves to `y + 1`.
    #[inline(always)]
    pub(crate) fn step(&mut self) {
        match self {
            Walker::Lower { lo, r, q, m, d } => {
                *lo += *q;
                *r -= *m;
                if *r < 0 {
                    *lo += 1;
                    *r += *d;
                }
            }
            Walker::Upper { hi, r, q, m, d } => {
                *hi += *q;
                *r += *m;
                if *r >= *d {
                    *hi += 1;
                    *r -= *d;
                }
            }
            Walker::Const { n, b } => *n += *b,
        }
    }

    /// Intersects `[lo, hi]` with the allowed range at the current `y`.
    #[inline(always)]
    pub(crate) fn clip(&self, lo: &mut i64, hi: &mut i64) {
        match *self {
            Walker::Lower { lo: l, .. } => *lo = (*lo).max(l),
            Walker::Upper { hi: h, .. } => *hi = (*hi).min(h),
            Walker::Const { n, .. } => {
                if n < 0 {
                    *lo = 1;
                    *hi = 0;
                }
            }
        }
    }
}

/// Clips `[lo, hi]` by three walkers.
#[inline(always)]
fn clip3(w: &[Walker; 3], mut lo: i64, mut hi: i64) -> (i64, i64) {
    for x in w {
        x.clip(&mut lo, &mut hi);
    }
    (lo, hi)
}

/// The exact range `t0 ..= t1` of voxels along `w` whose box the triangle's
/// plane crosses, in column `(iu, iv)`, tracked along a row: `t0` is the
/// least `t` with `g_max(t) >= 0`, `t1` the greatest with `g_min(t) <= 0`,
/// and `g0 = g_max(t0)`, `g1 = g_min(t1)`. Moving one column changes both
/// by `n_u`, and the range by at most one since `|n_u| <= n_w`, so the
/// correction loops run a step or two: additions and comparisons only.
#[derive(Clone, Copy)]
pub(crate) struct PlaneRange<T> {
    pub(crate) t0: i64,
    pub(crate) t1: i64,
    g0: T,
    g1: T,
}

impl<T: PlaneInt> PlaneRange<T> {
    /// The range at column `(iu, iv)`: an f64 estimate (clamped to the
    /// triangle's span) made exact by the correction loops.
    #[inline(always)]
    pub(crate) fn at<const W: usize>(s: &Setup<T>, iu: i64, iv: i64) -> PlaneRange<T> {
        let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
        let o = s.origin;
        let est = |x: f64| x.clamp((s.span_w.0 - 1) as f64, (s.span_w.1 + 1) as f64) as i64;
        let base = s.n[v] * T::from_i64(iv - o[v]) + s.n[u] * T::from_i64(iu - o[u]);
        let t0 = est(-(base + s.d_max).to_f64() * s.inv_nw + o[w] as f64);
        let t1 = est(-(base + s.d_min).to_f64() * s.inv_nw + o[w] as f64);
        let g0 = base + s.n[w] * T::from_i64(t0 - o[w]) + s.d_max;
        let g1 = base + s.n[w] * T::from_i64(t1 - o[w]) + s.d_min;
        let mut r = PlaneRange { t0, t1, g0, g1 };
        r.correct(s.n[w]);
        r
    }

    /// Moves to the next column along `u`. Since `|n_u| <= n_w`, each end
    /// of the range moves by at most one: one conditional step each way,
    /// without loops.
    #[inline(always)]
    pub(crate) fn next_column(&mut self, nu: T, nw: T) {
        let (g0, g1) = (self.g0 + nu, self.g1 + nu);
        // g0 was in [0, n_w): now in [-n_w, 2 n_w).
        let (down, up) = (g0 >= nw, g0 < T::ZERO);
        self.t0 += up as i64 - down as i64;
        self.g0 = if down {
            g0 - nw
        } else if up {
            g0 + nw
        } else {
            g0
        };
        // g1 was in (-n_w, 0]: now in (-2 n_w, n_w].
        let (up, down) = (g1 <= -nw, g1 > T::ZERO);
        self.t1 += up as i64 - down as i64;
        self.g1 = if up {
            g1 + nw
        } else if down {
            g1 - nw
        } else {
            g1
        };
    }

    #[inline(always)]
    fn correct(&mut self, nw: T) {
        while self.g0 - nw >= T::ZERO {
            self.t0 -= 1;
            self.g0 = self.g0 - nw;
        }
        while self.g0 < T::ZERO {
            self.t0 += 1;
            self.g0 = self.g0 + nw;
        }
        while self.g1 + nw <= T::ZERO {
            self.t1 += 1;
            self.g1 = self.g1 + nw;
        }
        while self.g1 > T::ZERO {
            self.t1 -= 1;
            self.g1 = self.g1 - nw;
        }
    }
}

/// Voxel boxes up to this many voxels are scanned directly ([`scan_box`]);
/// larger ones use the row walkers of [`traverse`], whose setup pays off
/// only when rows are long.
const SMALL_BOX: i64 = 1024;

/// Scans the box row by row in the dominant projection: in each row the
/// exact span of columns whose square meets the projected triangle (the
/// three dominant-plane edge functions solved for the column, one
/// division each), and along it, incrementally, the exact range of `t`
/// where the plane crosses the voxel (it moves by at most one per column
/// since `|n_u| <= n_w`). Only the voxels in that range get the remaining
/// six edge tests. Same predicates as [`traverse`], so the same voxels.
#[inline(always)]
fn scan_box<O: Sink, const W: usize>(s: &Setup<i64>, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    let (nu, nw) = (s.n[u], s.n[w]);
    let (uv, vw, wu) = (s.uv, s.vw, s.wu);
    for iv in lo[v]..=hi[v] {
        // The row's columns whose square meets the projected triangle: the
        // uv edge functions `a·iu + r >= 0`, each solved for `iu` (the
        // f64 estimate of `div_floor` made exact), so columns outside are
        // never visited.
        let (mut a0, mut a1) = (lo[u], hi[u]);
        for e in &uv {
            let r = e.b * iv + e.c;
            if e.a > 0 {
                a0 = a0.max(-div_floor(r, e.a).0);
            } else if e.a < 0 {
                a1 = a1.min(div_floor(r, -e.a).0);
            } else if r < 0 {
                a1 = a0 - 1;
            }
        }
        if a0 > a1 {
            continue;
        }
        let rvw: [i64; 3] = std::array::from_fn(|i| vw[i].a * iv + vw[i].c);
        // wu edge functions at (t = 0, iu = a0); each column adds `b`.
        let mut rwu: [i64; 3] = std::array::from_fn(|i| wu[i].b * a0 + wu[i].c);
        let mut plane = PlaneRange::at::<W>(s, a0, iv);
        let mut iu = a0;
        loop {
            let (ta, tb) = (plane.t0.max(lo[w]), plane.t1.min(hi[w]));
            if ta <= tb {
                // The six remaining edge functions at t = ta, then stepped along t.
                let mut f: [i64; 3] = std::array::from_fn(|i| vw[i].b * ta + rvw[i]);
                let mut g: [i64; 3] = std::array::from_fn(|i| wu[i].a * ta + rwu[i]);
                let mut t = ta;
                loop {
                    // `x | y | z` is negative iff one of them is: one branch per test group.
                    if (f[0] | f[1] | f[2] | g[0] | g[1] | g[2]) >= 0 {
                        set::<O, W>(out, iu, iv, t);
                    }
                    if t == tb {
                        break;
                    }
                    t += 1;
                    for i in 0..3 {
                        f[i] += vw[i].b;
                        g[i] += wu[i].a;
                    }
                }
            }
            if iu == a1 {
                break;
            }
            iu += 1;
            plane.next_column(nu, nw);
            for i in 0..3 {
                rwu[i] += wu[i].b;
            }
        }
    }
}

/// Selects the traversal compiled for the triangle's dominant axis, so the
/// mapping from `(u, v, w)` back to `(i, j, k)` is static.
#[inline(always)]
fn dispatch<T: PlaneInt, O: Sink, const RUNS: bool>(s: &Setup<T>, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    match s.w {
        0 => traverse::<T, O, 0, RUNS>(s, lo, hi, out),
        1 => traverse::<T, O, 1, RUNS>(s, lo, hi, out),
        _ => traverse::<T, O, 2, RUNS>(s, lo, hi, out),
    }
}

/// Walks the rows of the dominant-axis projection. In each row:
/// - the exact span of columns whose square meets the projected triangle,
///   and the *interior* span whose square lies entirely inside it;
/// - the exact range of `t` allowed by the `(v, w)` edge tests;
/// - along the row, incrementally (additions only), the exact range of `t`
///   where the plane crosses the voxel, which moves by at most one per
///   column since `|n_u| <= n_w`.
///
/// In interior columns the plane test alone decides (a plane point inside
/// the voxel projects inside the triangle, so it is a triangle point); in
/// boundary columns the `(w, u)` edge tests run per voxel.
#[inline(always)]
fn traverse<T: PlaneInt, O: Sink, const W: usize, const RUNS: bool>(s: &Setup<T>, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    let (nu, nw) = (s.n[u], s.n[w]);
    let y0 = lo[v];
    // Columns whose square meets the projected triangle; columns whose
    // square lies inside it (edge value at the far corner >= 0); and the t
    // range allowed by the (v, w) edge tests — each walked row by row.
    let mut outer: [Walker; 3] = std::array::from_fn(|i| Walker::new(s.uv[i].a, s.uv[i].b, s.uv[i].c, y0));
    let mut inner: [Walker; 3] = std::array::from_fn(|i| {
        let e = s.uv[i];
        Walker::new(e.a, e.b, e.c - e.a.abs() - e.b.abs(), y0)
    });
    let mut tband: [Walker; 3] = std::array::from_fn(|i| Walker::new(s.vw[i].b, s.vw[i].a, s.vw[i].c, y0));
    let (lo_w, hi_w) = (lo[w], hi[w]);
    for iv in lo[v]..=hi[v] {
        if iv > y0 {
            for x in outer.iter_mut().chain(inner.iter_mut()).chain(tband.iter_mut()) {
                x.step();
            }
        }
        let (a0, a1) = clip3(&outer, lo[u], hi[u]);
        if a0 > a1 {
            continue;
        }
        let (c0, c1) = clip3(&tband, lo_w, hi_w);
        if c0 > c1 {
            continue;
        }
        let (i0, i1) = clip3(&inner, a0, a1);
        let mut plane = PlaneRange::at::<W>(s, a0, iv);
        let mut iu = a0;
        loop {
            if RUNS && iu == i0 && i0 <= i1 {
                interior_runs::<T, O, W>(s, iv, (i0, i1), (c0, c1), &plane, out);
                if i1 == a1 {
                    break;
                }
                iu = i1 + 1;
                plane = PlaneRange::at::<W>(s, iu, iv);
                continue;
            }
            let (ta, tb) = (plane.t0.max(c0), plane.t1.min(c1));
            let mut t = ta;
            if iu >= i0 && iu <= i1 {
                while t <= tb {
                    set::<O, W>(out, iu, iv, t);
                    t += 1;
                }
            } else {
                let r: [i64; 3] = std::array::from_fn(|i| s.wu[i].b * iu + s.wu[i].c);
                while t <= tb {
                    if s.wu[0].a * t + r[0] >= 0 && s.wu[1].a * t + r[1] >= 0 && s.wu[2].a * t + r[2] >= 0 {
                        set::<O, W>(out, iu, iv, t);
                    }
                    t += 1;
                }
            }
            if iu == a1 {
                break;
            }
            iu += 1;
            plane.next_column(nu, nw);
        }
    }
}

/// Emits the interior columns `i0 ..= i1` of row `iv` (their squares lie
/// inside the projected triangle, so the plane test alone decides), clipped
/// to `c0 ..= c1` along `w`; `first` is the plane range at column `i0`.
///
/// If the plane's range over the block spans few layers compared with the
/// block's width, each layer `t` is one run along `u`: the columns where
/// `g_max(u, t) >= 0` and `g_min(u, t) <= 0`, two linear inequalities in `u`
/// solved exactly. Otherwise each column is one run along `w`.
#[inline(always)]
fn interior_runs<T: PlaneInt, O: Sink, const W: usize>(
    s: &Setup<T>,
    iv: i64,
    (i0, i1): (i64, i64),
    (c0, c1): (i64, i64),
    first: &PlaneRange<T>,
    out: &mut O,
) {
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    let width = i1 - i0 + 1;
    let last = PlaneRange::at::<W>(s, i1, iv);
    let (tmin, tmax) = (first.t0.min(last.t0).max(c0), first.t1.max(last.t1).min(c1));
    if tmin > tmax {
        return;
    }
    if 3 * (tmax - tmin + 1) > width {
        let mut plane = *first;
        for iu in i0..=i1 {
            let (ta, tb) = (plane.t0.max(c0), plane.t1.min(c1));
            if ta <= tb {
                run::<O, W>(out, W, iu, iv, ta, tb - ta + 1);
            }
            if iu < i1 {
                plane.next_column(s.n[u], s.n[w]);
            }
        }
        return;
    }
    // Plane values relative to the setup's origin `o` (as in `PlaneRange`,
    // so they stay in `T`): with u' = u − o_u,
    // g(u', t) = n_u·u' + n_v·(iv − o_v) + n_w·(t − o_w) + d.
    let o = s.origin;
    let base = s.n[v] * T::from_i64(iv - o[v]);
    let nu = s.n[u];
    for t in tmin..=tmax {
        let k = base + s.n[w] * T::from_i64(t - o[w]);
        // n_u·u' >= -(k + d_max)  and  n_u·u' <= -(k + d_min).
        let (lo_rhs, hi_rhs) = (-(k + s.d_max), -(k + s.d_min));
        let (mut ua, mut ub) = (i0 - o[u], i1 - o[u]);
        if nu > T::ZERO {
            ua = ua.max(ceil_div(lo_rhs, nu));
            ub = ub.min(floor_div(hi_rhs, nu));
        } else if nu < T::ZERO {
            ua = ua.max(ceil_div(-hi_rhs, -nu));
            ub = ub.min(floor_div(-lo_rhs, -nu));
        } else if lo_rhs > T::ZERO || hi_rhs < T::ZERO {
            continue;
        }
        let (ua, ub) = (ua + o[u], ub + o[u]);
        if ua <= ub {
            run::<O, W>(out, u, ua, iv, t, ub - ua + 1);
        }
    }
}

/// Emits `len` voxels from `(u, v, w)` along `axis`; `(u, v, w)` is a cyclic
/// shift of `(x, y, z)` by `W`.
#[inline(always)]
pub(crate) fn run<O: Sink, const W: usize>(out: &mut O, axis: usize, iu: i64, iv: i64, t: i64, len: i64) {
    let mut p = [0u32; 3];
    (p[(W + 1) % 3], p[(W + 2) % 3], p[W]) = (iu as u32, iv as u32, t as u32);
    out.set_run(axis, p, len as u32);
}

/// Sets voxel `(u, v, w)`; `(u, v, w)` is a cyclic shift of `(x, y, z)` by `W`.
#[inline(always)]
pub(crate) fn set<O: Sink, const W: usize>(out: &mut O, iu: i64, iv: i64, t: i64) {
    let (i, j, k) = match W {
        0 => (t, iu, iv),
        1 => (iv, t, iu),
        _ => (iu, iv, t),
    };
    out.set(i as u32, j as u32, k as u32);
}

/// The slow, obviously correct definition of `cover`.
pub mod reference {
    use super::*;

    /// Brute force: for every voxel of every triangle's bounding box, the
    /// exact separating axis test. Serial.
    pub fn cover(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        let (tris, prepare_stats) = prepare(mesh, grid);
        let bits = cover_lattice(&tris, grid.dims());
        let voxels = bits.count();
        (bits, Report { prepare: prepare_stats, voxels })
    }

    /// The reference on already prepared triangles.
    pub fn cover_lattice(tris: &[LatticeTriangle], dims: [u32; 3]) -> DenseBits {
        super::super::brute_force(tris, dims, triangle_box_overlap)
    }

    /// Exact separating axis test: does the closed triangle meet the closed
    /// box of voxel `ijk`? Axes: the three box normals, the triangle normal
    /// and the nine cross products of triangle edges with box edges. The
    /// sets are disjoint iff their projections on some axis are disjoint.
    pub fn triangle_box_overlap(t: &LatticeTriangle, ijk: [i64; 3]) -> bool {
        let one = ONE as i128;
        let corner: [i128; 3] = ijk.map(|c| c as i128 * one);
        let v: [[i128; 3]; 3] = t.v.map(|p| p.map(|c| c as i128));
        let e: [[i128; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|a| v[(i + 1) % 3][a] - v[i][a]));
        let cross = |a: [i128; 3], b: [i128; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        let unit = |a: usize| std::array::from_fn::<i128, 3, _>(|c| (c == a) as i128);
        let mut axes: Vec<[i128; 3]> = Vec::with_capacity(13);
        for a in 0..3 {
            axes.push(unit(a));
        }
        axes.push(cross(e[0], e[1]));
        for ei in &e {
            for a in 0..3 {
                axes.push(cross(*ei, unit(a)));
            }
        }
        let dot = |a: &[i128; 3], p: &[i128; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        for ax in &axes {
            let proj = v.map(|p| dot(ax, &p));
            let tmin = proj.iter().copied().min().unwrap_or(0);
            let tmax = proj.iter().copied().max().unwrap_or(0);
            let base = dot(ax, &corner);
            let bmin = base + ax.iter().map(|&c| (c * one).min(0)).sum::<i128>();
            let bmax = base + ax.iter().map(|&c| (c * one).max(0)).sum::<i128>();
            if tmax < bmin || tmin > bmax {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lt(v: [[i64; 3]; 3]) -> LatticeTriangle {
        LatticeTriangle { v: v.map(|p| p.map(|c| c * ONE)) }
    }

    fn both(t: LatticeTriangle, dims: [u32; 3]) -> (DenseBits, DenseBits) {
        let fast = cover_lattice(&[t], dims, &Options::default()).to_dense();
        let slow = reference::cover_lattice(&[t], dims);
        (fast, slow)
    }

    /// Triangles whose span is up to 4 voxels a side (the tiny paths,
    /// the bit masks of `tiny_box_n` among them), at random lattice
    /// points, some on voxel faces (ties) and some past the grid's sides
    /// (their boxes cut), against the separating axis test.
    #[test]
    fn tiny_spans_match_the_reference() {
        let mut rng = crate::test_rng::Xorshift(0x7171_5a4e);
        let dims = [5, 4, 6];
        let mut tested = [0usize; 5];
        for n in 0..20_000 {
            // A corner in or just outside the grid; vertices within 4 voxels of it.
            let corner: [i64; 3] = std::array::from_fn(|a| rng.signed(dims[a] as i64 + 1) * ONE);
            let snap = n % 4 == 0;
            let v: [[i64; 3]; 3] = std::array::from_fn(|_| {
                std::array::from_fn(|a| {
                    let off = rng.below(4 * ONE as u64 - 1) as i64;
                    corner[a] + if snap { off / ONE * ONE } else { off }
                })
            });
            let t = LatticeTriangle { v };
            if t.normal() == [0; 3] {
                continue;
            }
            let (lo, hi) = t.bounds();
            let span = (0..3).map(|a| crate::geom::fixed::voxel_span(lo[a], hi[a])).map(|(a, b)| (b - a + 1) as usize).max().unwrap_or(0);
            tested[span.min(4)] += 1;
            let (fast, slow) = both(t, dims);
            assert_eq!(fast, slow, "triangle {v:?}");
        }
        // Spans of 3 and 4 voxels were among them.
        assert!(tested[3] > 1000 && tested[4] > 1000, "{tested:?}");
    }

    #[test]
    fn vertex_on_a_corner_touches_all_eight() {
        // A tiny triangle whose vertex sits on the corner (2,2,2).
        let t = LatticeTriangle {
            v: [[2 * ONE, 2 * ONE, 2 * ONE], [2 * ONE - 5, 2 * ONE - 1, 2 * ONE - 3], [2 * ONE - 1, 2 * ONE - 7, 2 * ONE - 2]],
        };
        let (f, s) = both(t, [4, 4, 4]);
        assert_eq!(f, s);
        for (i, j, k) in [(1, 1, 1), (2, 2, 2), (1, 2, 1), (2, 1, 2)] {
            assert!(f.get(i, j, k), "{i} {j} {k}");
        }
        assert_eq!(f.count(), 8);
    }

    #[test]
    fn axis_aligned_triangle_on_a_grid_plane_sets_both_layers() {
        let t = lt([[0, 0, 2], [3, 0, 2], [0, 3, 2]]);
        let (f, s) = both(t, [4, 4, 4]);
        assert_eq!(f, s);
        assert!(f.get(0, 0, 1) && f.get(0, 0, 2));
        assert!(!f.get(0, 0, 0) && !f.get(0, 0, 3));
    }

    /// Collects emitted voxels (runs expanded), for calling a traversal
    /// directly on boxes no grid has to hold.
    #[derive(Default)]
    struct Collect(Vec<[i64; 3]>);

    impl Sink for Collect {
        fn set(&mut self, i: u32, j: u32, k: u32) {
            self.0.push([i as i64, j as i64, k as i64]);
        }
    }

    #[test]
    fn row_runs_far_from_the_origin_stay_exact() {
        // Large shallow triangles (row runs along u) near voxel 60 000 on
        // each axis: the plane values must stay relative to the box, or
        // n_u·u overflows i64.
        let far = 60_000i64;
        for axis in 0..3 {
            for slope in [0i64, 1, 3] {
                let (u, v, w) = ((axis + 1) % 3, (axis + 2) % 3, axis);
                let mut pts = [[0i64; 3]; 3];
                for (p, (a, b)) in pts.iter_mut().zip([(0i64, 0i64), (120, 15), (8, 117)]) {
                    p[u] = (far + a) * ONE + 1234;
                    p[v] = (far + b) * ONE + 77;
                    p[w] = (far + 40) * ONE + slope * a * ONE / 10 + 555;
                }
                let t = LatticeTriangle { v: pts };
                let (blo, bhi) = t.bounds();
                let lo: [i64; 3] = std::array::from_fn(|a| crate::geom::fixed::voxel_span(blo[a], bhi[a]).0);
                let hi: [i64; 3] = std::array::from_fn(|a| crate::geom::fixed::voxel_span(blo[a], bhi[a]).1);
                let mut got = Collect::default();
                cover_triangle_runs(&t, lo, hi, &mut got);
                let mut want = Collect::default();
                cover_triangle(&t, lo, hi, Traversal::WalkRows, &mut want);
                got.0.sort();
                want.0.sort();
                assert_eq!(got.0.len(), want.0.len(), "axis {axis} slope {slope}");
                assert!(got.0 == want.0, "axis {axis} slope {slope}");
                // Spot-check the definition on a sample of the box.
                for (n, ijk) in got.0.iter().enumerate().step_by(97) {
                    assert!(reference::triangle_box_overlap(&t, *ijk), "{n}: {ijk:?}");
                }
            }
        }
    }
}
