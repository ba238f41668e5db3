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
//! projection. Every test of the overlap theorem is linear in the voxel
//! index, so per row:
//! - the three `(u, v)` edge tests give the row's exact column span;
//! - the three `(v, w)` edge tests give one `w` range for the whole row;
//! - per column, the plane test and the three `(w, u)` edge tests give
//!   lower or upper bounds `floor((α + β·u) / d)` on `w`.
//!
//! The column loop evaluates those five bounds for a batch of columns in
//! straight-line `f64` code (exact: every value is an integer below `2^52`
//! for triangles up to 14 voxels across; floor division is an estimate by
//! the reciprocal corrected with the exact remainder), which the compiler
//! turns into packed SIMD; then each column's range `[w0, w1]` is emitted
//! whole. No voxel is tested individually. Larger triangles take the scalar
//! twin: the same bounds walked incrementally in exact integers along each
//! row (`cover`'s row walker), which costs per row, not per column.
//!
//! Parallel over z-slabs with the shared driver: deterministic for any
//! thread count. **Reference:** the modes' brute-force references; the
//! tests compare voxel for voxel.

use super::cover::{cover_triangle, edges_2d, set};
use super::driver::{run_slabs, Filter, Kernel, Sink};
use super::targets::{fits_i64, DirSetup, TriSetup, CROSSHAIR, DIAGONALS};
use super::{Mode, Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::{prepare, LatticeTriangle};
use crate::geom::perturb::P3;
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
    let (tris, prepare_stats) = prepare(mesh, grid);
    let (bits, voxels) = run_slabs(&ScanKernel { mode }, &tris, grid.dims(), opts);
    Some((bits, Report { prepare: prepare_stats, voxels }))
}

/// Whether the scanline path is expected to beat the triangle-box fast path
/// for `mode` on this mesh and grid (what `--method auto` asks): for modes
/// where it measured faster, when nearly all triangles are small enough
/// in voxels for the batched column loop (a deterministic sample of up to
/// 4096 triangles is looked at).
pub fn prefers(mode: Mode, mesh: MeshRef<'_>, grid: &GridSpec) -> bool {
    if !PREFERRED.contains(&mode) || mesh.triangles.is_empty() {
        return false;
    }
    let step = mesh.triangles.len().div_ceil(4096);
    let limit = (F64_EXTENT_LIMIT / ONE) as f64 * grid.voxel_size();
    let (mut small, mut seen) = (0usize, 0usize);
    for t in mesh.triangles.iter().step_by(step) {
        let Some(p) = t.iter().map(|&i| mesh.positions.get(i as usize).copied()).collect::<Option<Vec<_>>>() else { continue };
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        seen += 1;
        if (hi - lo).max_element() <= limit {
            small += 1;
        }
    }
    seen > 0 && small * 10 >= seen * 9
}

/// Modes whose scanline path measured faster than the fast path on meshes
/// of small triangles (BENCHMARKS.md).
const PREFERRED: [Mode; 1] = [Mode::Cover];

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
    let keep = |ijk: [i64; 3]| {
        (0..N).any(|i| {
            let o = segs[i].0;
            s.segment_hits(&dirs[i], s.local([ijk[0] * ONE + o[0], ijk[1] * ONE + o[1], ijk[2] * ONE + o[2]]))
        })
    };
    scan_triangle(tri, lo, hi, &mut Filter { slab, keep });
}

/// Triangles up to this extent (lattice units) take the `f64` batch path;
/// see the module doc for the bound.
const F64_EXTENT_LIMIT: i64 = 14 * ONE;

/// Columns per batch of the vectorised loop.
const BATCH: usize = 8;

/// Emits exactly the voxels of `[lo, hi]` whose closed box meets `tri`.
pub(crate) fn scan_triangle<O: Sink>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (blo, bhi) = tri.bounds();
    let extent = (0..3).map(|a| bhi[a] - blo[a]).max().unwrap_or(0);
    if extent > F64_EXTENT_LIMIT {
        // The scalar twin: exact incremental bounds along each row.
        cover_triangle(tri, lo, hi, Traversal::WalkRows, out);
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

/// `floor(x)` for `|x| < 2^51` in plain additions and a comparison (so it
/// vectorises without SSE4.1's `roundpd`): adding and removing `1.5·2^52`
/// rounds to the nearest integer.
#[inline(always)]
fn floor_small(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0; // 1.5 · 2^52
    let r = (x + MAGIC) - MAGIC;
    if r > x {
        r - 1.0
    } else {
        r
    }
}

/// `floor(num / d)` for integers `|num| < 2^52`, `0 < d < 2^52`, quotient
/// well below `2^40`: the estimate `num · (1/d)` is off by at most one, and
/// the exact remainder `num − q·d` (all integers below `2^53`) corrects it.
#[inline(always)]
fn div_floor(num: f64, d: f64, inv: f64) -> f64 {
    let q = floor_small(num * inv);
    let r = num - q * d;
    let q = if r < 0.0 { q - 1.0 } else { q };
    if r >= d {
        q + 1.0
    } else {
        q
    }
}

/// One bound `floor((α + β·u) / d)` on `w` per column `u`.
#[derive(Clone, Copy, Debug, Default)]
struct Bound {
    alpha: f64,
    beta: f64,
    d: f64,
    inv: f64,
    /// `-inf` unless this is a lower bound (`w >= -floor(..)`).
    lower_off: f64,
    /// `+inf` unless this is an upper bound (`w <= floor(..)`).
    upper_off: f64,
}

impl Bound {
    #[inline(always)]
    fn new(alpha: i64, beta: i64, d: i64, lower: bool) -> Bound {
        let (d, inf) = (d as f64, f64::INFINITY);
        Bound {
            alpha: alpha as f64,
            beta: beta as f64,
            d,
            inv: 1.0 / d,
            lower_off: if lower { 0.0 } else { -inf },
            upper_off: if lower { inf } else { 0.0 },
        }
    }

    /// No constraint.
    fn none() -> Bound {
        Bound { alpha: 0.0, beta: 0.0, d: 1.0, inv: 1.0, lower_off: f64::NEG_INFINITY, upper_off: f64::INFINITY }
    }
}

impl Bound {
    /// The constraint `a·y + (β·x + α) >= 0` on an integer `y`, for each
    /// `x`: a lower bound on `y` if `a > 0`, an upper one if `a < 0`; `None`
    /// if `a = 0` (then it constrains `x` alone, see [`x_range`]).
    #[inline(always)]
    fn solving(a: i64, beta: i64, alpha: i64) -> Option<Bound> {
        match a.signum() {
            // y >= ceil(-(β·x + α) / a) = -floor((β·x + α) / a)
            1 => Some(Bound::new(alpha, beta, a, true)),
            // y <= floor((β·x + α) / -a)
            -1 => Some(Bound::new(alpha, beta, -a, false)),
            _ => None,
        }
    }

    /// Intersects `[l, h]` with this bound at `x`.
    #[inline(always)]
    fn clip(&self, x: f64, l: f64, h: f64) -> (f64, f64) {
        let q = div_floor(self.alpha + self.beta * x, self.d, self.inv);
        let (lq, hq) = (-q + self.lower_off, q + self.upper_off);
        (if lq > l { lq } else { l }, if hq < h { hq } else { h })
    }
}

/// The integers `x` in `[lo, hi]` with `β·x + α >= 0`.
fn x_range(beta: i64, alpha: i64, lo: i64, hi: i64) -> (i64, i64) {
    match beta.signum() {
        1 => (lo.max(-alpha.div_euclid(beta)), hi),
        -1 => (lo, hi.min(alpha.div_euclid(-beta))),
        _ if alpha >= 0 => (lo, hi),
        _ => (1, 0),
    }
}

/// Three linear constraints `a·y + b·x + c >= 0` solved for `y` per `x`,
/// and the range of `x` left by those with `a = 0`.
#[inline(always)]
fn solve3(edges: [(i64, i64, i64); 3], x_lo: i64, x_hi: i64) -> ([Bound; 3], (i64, i64)) {
    let mut xr = (x_lo, x_hi);
    let mut bounds = [Bound::none(); 3];
    for (b, &(a, beta, alpha)) in bounds.iter_mut().zip(&edges) {
        match Bound::solving(a, beta, alpha) {
            Some(s) => *b = s,
            None => xr = x_range(beta, alpha, xr.0, xr.1),
        }
    }
    (bounds, xr)
}

/// `(floor(n / d), n − d·floor(n / d))` for `d > 0`.
#[inline(always)]
fn div_rem(n: i64, d: i64) -> (i64, i64) {
    let q = div_floor(n as f64, d as f64, 1.0 / d as f64) as i64;
    (q, n - q * d)
}

/// The batch path; see the module doc. Coordinates are relative to `lo`,
/// so every value stays small.
#[inline(always)]
fn scan_rows<O: Sink, const W: usize>(tri: &LatticeTriangle, n: [i64; 3], lo: [i64; 3], hi: [i64; 3], out: &mut O) {
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    let rel = LatticeTriangle { v: tri.v.map(|p| std::array::from_fn(|a| p[a] - lo[a] * ONE)) };
    let size: [i64; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
    let sign = |x: i64| if x >= 0 { 1 } else { -1 };
    // Edge functions `a·p + b·q + c >= 0` over voxel indices of the
    // projections (u, v), (v, w), (w, u).
    let uv = edges_2d(&rel, u, v, sign(n[w]));
    let vw = edges_2d(&rel, v, w, sign(n[u]));
    let wu = edges_2d(&rel, w, u, sign(n[v]));

    // Per row, from the (u, v) edges: the columns whose square meets the
    // projected triangle, and those whose square lies inside it (edge value
    // at the square's worst corner >= 0); from the (v, w) edges: the row's
    // w range. Constraints that do not involve the solved variable narrow
    // the range of rows instead (for the interior span: of rows that have one).
    let (outer_b, (v0, v1)) = solve3(uv.map(|e| (e.a, e.b, e.c)), 0, size[v]);
    let (inner_b, (vi0, vi1)) = solve3(uv.map(|e| (e.a, e.b, e.c - e.a.abs() - e.b.abs())), 0, size[v]);
    let (vw_b, (v0, v1)) = solve3(vw.map(|e| (e.b, e.a, e.c)), v0, v1);
    // (w, u) edges with no w term constrain the columns.
    let (mut u0, mut u1) = (0, size[u]);
    for e in wu.iter().filter(|e| e.a == 0) {
        (u0, u1) = x_range(e.b, e.c, u0, u1);
    }
    if v0 > v1 || u0 > u1 {
        return;
    }

    // Plane, oriented so n_w > 0, in voxel-index units (× ONE). Per column:
    // w >= -floor((nu·u + nv·v + d_max) / nw) and
    // w <= floor(-(nu·u + nv·v + d_min) / nw); α gets `nv·v` per row.
    let flip = sign(n[w]);
    let no = n.map(|c| c * flip);
    let nv0 = no[0] * rel.v[0][0] + no[1] * rel.v[0][1] + no[2] * rel.v[0][2];
    let (d_min, d_max) = no.iter().fold((-nv0, -nv0), |(a, b), &c| if c < 0 { (a + c * ONE, b) } else { (a, b + c * ONE) });
    let (nu, nv, nw) = (no[u] * ONE, no[v] * ONE, no[w] * ONE);
    let (p_lo, p_hi) = (d_max, -d_min);

    let (u0f, u1f, wmax) = (u0 as f64, u1 as f64, size[w] as f64);
    let mut iv0 = v0;
    while iv0 <= v1 {
        // Eight rows at a time: column spans, interior spans and w ranges.
        let x0 = iv0 as f64;
        let (ra0, ra1) = ranges8(&outer_b, x0, u0f, u1f);
        let (ri0, ri1) = ranges8(&inner_b, x0, u0f, u1f);
        let (rc0, rc1) = ranges8(&vw_b, x0, 0.0, wmax);
        for r in 0..BATCH.min((v1 - iv0 + 1) as usize) {
            let (a0, a1, c0, c1) = (ra0[r], ra1[r], rc0[r], rc1[r]);
            if a0 > a1 || c0 > c1 {
                continue;
            }
            let iv = iv0 + r as i64;
            let (a0, a1) = (a0 as i64, a1 as i64);
            let (i0, i1) = if (vi0..=vi1).contains(&iv) { (ri0[r] as i64, ri1[r] as i64) } else { (1, 0) };
            // Plane range at column a0 exactly, then stepped along the row:
            // F = floor(num / nw), R = num − F·nw ∈ [0, nw); each column
            // adds nu to num, and |nu| <= nw moves F by at most one.
            let (mut f0, mut r0) = div_rem(p_lo + nv * iv + nu * a0, nw);
            let (mut f1, mut r1) = div_rem(p_hi - nv * iv - nu * a0, nw);
            let (c0, c1) = (c0 as i64, c1 as i64);
            for iu in a0..=a1 {
                let (t0, t1) = ((-f0).max(c0), f1.min(c1));
                if i0 <= iu && iu <= i1 {
                    // Inside the projection: the plane test decides; the
                    // whole range is one run along w.
                    if t0 <= t1 {
                        let mut p = [0u32; 3];
                        (p[u], p[v], p[w]) = ((iu + lo[u]) as u32, (iv + lo[v]) as u32, (t0 + lo[w]) as u32);
                        out.set_run(W, p, (t1 - t0 + 1) as u32);
                    }
                } else {
                    // On its boundary: the (w, u) edge tests per voxel.
                    let r: [i64; 3] = std::array::from_fn(|i| wu[i].b * iu + wu[i].c);
                    for t in t0..=t1 {
                        if wu[0].a * t + r[0] >= 0 && wu[1].a * t + r[1] >= 0 && wu[2].a * t + r[2] >= 0 {
                            set::<O, W>(out, iu + lo[u], iv + lo[v], t + lo[w]);
                        }
                    }
                }
                r0 += nu;
                let s0 = (r0 >= nw) as i64 - (r0 < 0) as i64;
                f0 += s0;
                r0 -= s0 * nw;
                r1 -= nu;
                let s1 = (r1 >= nw) as i64 - (r1 < 0) as i64;
                f1 += s1;
                r1 -= s1 * nw;
            }
        }
        iv0 += BATCH as i64;
    }
}

/// The vectorised inner loop: for the eight positions `x0, x0 + 1, …`, the
/// range `[l, h] ∩ [lo, hi]` allowed by `bounds`. Bounds are the outer
/// loop and positions the inner one, so each bound's fields are broadcast
/// and the eight lanes run as straight-line packed `f64` code.
#[inline(always)]
fn ranges8(bounds: &[Bound], x0: f64, lo: f64, hi: f64) -> ([f64; BATCH], [f64; BATCH]) {
    let xs: [f64; BATCH] = std::array::from_fn(|k| x0 + k as f64);
    let (mut l, mut h) = ([lo; BATCH], [hi; BATCH]);
    for b in bounds {
        for k in 0..BATCH {
            (l[k], h[k]) = b.clip(xs[k], l[k], h[k]);
        }
    }
    (l, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_division_is_exact_near_integers() {
        for d in [1i64, 3, 4096, 4097, 1 << 30, (1 << 40) + 7] {
            for num in [-(1i64 << 51) + 1, -d - 1, -d, -d + 1, -1, 0, 1, d - 1, d, d + 1, (1 << 51) - 1] {
                let q = div_floor(num as f64, d as f64, 1.0 / d as f64);
                assert_eq!(q as i64, num.div_euclid(d), "{num} / {d}");
            }
        }
    }

    #[test]
    fn floor_small_matches_floor() {
        for x in [-2.5, -2.0, -1.5, -0.5, -0.0, 0.0, 0.5, 1.0, 1.5, 2.5, 1e12 + 0.5, -1e12 - 0.5] {
            assert_eq!(floor_small(x), x.floor(), "{x}");
        }
    }
}
