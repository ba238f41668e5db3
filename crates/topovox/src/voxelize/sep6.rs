//! Laine's thin 6-separating surface voxelization (`sep6`), from a single
//! 2D projection.
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §5.2 (the 3D
//! crosshair target, thinness, and "voxelization with a single 2D
//! projection").
//!
//! **Guarantee.** Voxel `(i,j,k)` is set iff some (snapped, non-degenerate)
//! triangle meets one of the voxel's three crosshair segments (face centre
//! to opposite face centre through the voxel centre), displaced by the tie
//! rule of [`crate::geom::perturb`]. For a closed surface the result is
//! 6-separating; it is thin: a planar triangle sets at most one voxel per
//! column along its normal's dominant axis; it is a subset of `cover`.
//!
//! **Fast path** (Laine's column rule, on all three axes). A line through
//! pixel centres along an axis the plane is not parallel to, if it meets
//! the (displaced) triangle, hits the crosshair segment of exactly one
//! voxel of its column — the one whose segment straddles the plane — and
//! every crosshair hit is one of these. Triangles in a box of at most 27
//! voxels (most at 128³) test the few such lines in their box one by one
//! (`tiny`); larger ones take each axis's lines row by row as exact spans,
//! with the straddling voxel stepped along the row
//! (`line_spans.rs`); huge ones (beyond `i64`) take Laine's
//! single-projection algorithm (`project`, in `i128`): along the dominant
//! axis `w` the column rule, and for a pixel whose square meets the
//! projection but whose centre does not, exact tests of the two
//! perpendicular segments of the few voxels around the plane's depth. All
//! tests are exact integers.
//!
//! **Reference:** [`reference::sep6`], the definition evaluated with the
//! generic `i128` predicate for every voxel of each triangle's bounding box.

use super::driver::{run_mesh, run_slabs, Kernel};
use super::targets::{is_tiny, PixelTest, CROSSHAIR_SET};
use super::{Options, Report};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::setup::{all_one_side, dominant_axes, edge_side, fits_i64, TriSetup};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// Thin 6-separating voxelization, fast path, into sparse brick storage.
pub fn sep6(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&Sep6Kernel, mesh, grid, opts)
}

/// The fast path on already prepared triangles (the GPU path hands it the
/// triangles too large for its 64-bit shader arithmetic).
pub fn sep6_lattice(tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> BrickBits {
    run_slabs(&Sep6Kernel, tris, dims, opts).0
}

struct Sep6Kernel;

/// A triangle whose box [`is_tiny`], by the crosshair segments' lines: for
/// each axis `a` the triangle's plane is not parallel to, the `a`-lines
/// through pixel centres (`p`, `q` at `m·ONE + H`) that the (displaced)
/// line meets the triangle on, each setting the one voxel of its column
/// whose `a` segment straddles the plane ([`TriSetup::straddling_step`], as
/// Laine's algorithm does along the dominant axis). Every crosshair hit
/// is one of these, whatever the axis, so this is the definition; a
/// triangle about a voxel wide has about one such line per axis, against
/// `cover`'s traversal of its box and three targets per candidate. Only
/// pixel centres in the triangle's box (grown by a lattice unit for the
/// tie rule) can be inside it. Nothing to do if the box holds mid-planes
/// on fewer than two axes (`TargetSet::may_meet`).
#[inline(never)]
fn tiny(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let (blo, bhi) = tri.bounds();
    if !CROSSHAIR_SET.may_meet(blo, bhi) {
        return;
    }
    let s = TriSetup::<i64>::new(tri);
    // One instance per axis: its index arithmetic is constant (1 thread
    // at 128³: −27 %, at 256³: −37 %).
    tiny_axis::<0>(tri, &s, (blo, bhi), (lo, hi), slab);
    tiny_axis::<1>(tri, &s, (blo, bhi), (lo, hi), slab);
    tiny_axis::<2>(tri, &s, (blo, bhi), (lo, hi), slab);
}

/// The lines along axis `A` of [`tiny`].
#[inline(always)]
fn tiny_axis<const A: usize>(
    tri: &LatticeTriangle,
    s: &TriSetup<i64>,
    (blo, bhi): ([i64; 3], [i64; 3]),
    (lo, hi): ([i64; 3], [i64; 3]),
    slab: &mut BrickSlab<'_>,
) {
    if s.n[A] == 0 {
        // Parallel lines never cross the displaced plane.
        return;
    }
    // Pixel indices along `c` whose centre is in the grown box and the voxel box.
    let centres = |c: usize| {
        let first = -(H + 1 - blo[c]).div_euclid(ONE);
        let last = (bhi[c] + 1 - H).div_euclid(ONE);
        (first.max(lo[c]), last.min(hi[c]))
    };
    let (a, p, q) = (A, (A + 1) % 3, (A + 2) % 3);
    let ((p0, p1), (q0, q1)) = (centres(p), centres(q));
    let mut d = [0; 3];
    d[a] = ONE;
    for iq in q0..=q1 {
        for ip in p0..=p1 {
            let mut c = s.a;
            (c[p], c[q]) = (ip * ONE + H, iq * ONE + H);
            let pc = s.local(c);
            // The line's orientation against edge `i`: the `a`
            // component of the pivot cross, a 2D edge function.
            let side = |i: usize| {
                let (x, y) = (s.rel[i], s.rel[(i + 1) % 3]);
                let o = (x[p] - pc[p]) * (y[q] - pc[q]) - (x[q] - pc[q]) * (y[p] - pc[p]);
                edge_side(o, || crate::geom::lattice::cross(tri.edge(i), d))
            };
            if !all_one_side(side) {
                continue;
            }
            let t = s.straddling_step(s.n[a], s.n[p] * pc[p] + s.n[q] * pc[q], s.a[a]);
            if t >= lo[a] && t <= hi[a] {
                let mut ijk = [0u32; 3];
                (ijk[a], ijk[p], ijk[q]) = (t as u32, ip as u32, iq as u32);
                slab.set(ijk[0], ijk[1], ijk[2]);
            }
        }
    }
}

impl Kernel<LatticeTriangle> for Sep6Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if !fits_i64(tri) {
            project::<i128>(tri, lo, hi, slab);
        } else if is_tiny(lo, hi) {
            tiny(tri, lo, hi, slab);
        } else {
            let sp = super::line_spans::SpanSetup::new(tri);
            super::driver::buffered(lo, hi, slab, |slab, buf| match buf {
                Some(b) => sp.crosshair(lo, hi, b),
                None => sp.crosshair(lo, hi, slab),
            });
        }
    }
}

fn unit(a: usize) -> [i64; 3] {
    let mut d = [0; 3];
    d[a] = ONE;
    d
}

/// Laine's single-projection algorithm for one triangle, restricted to the
/// voxel box `[lo, hi]`.
#[inline(never)]
fn project<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let s = TriSetup::<T>::new(tri);
    let n = tri.normal();
    let (u, v, w) = dominant_axes(tri);
    let pix = PixelTest::new(&s, tri, (u, v, w));
    let dw = &pix.dw;
    let (du, dv) = (s.dir(tri, unit(u)), s.dir(tri, unit(v)));
    let (nu, nv, nw) = (T::from_i64(n[u]), T::from_i64(n[v]), T::from_i64(n[w]));
    let (one, h) = (T::from_i64(ONE), T::from_i64(H));
    let inv_nw = 1.0 / n[w] as f64;
    let emit = |slab: &mut BrickSlab<'_>, iu: i64, iv: i64, t: i64| {
        let mut ijk = [0i64; 3];
        (ijk[u], ijk[v], ijk[w]) = (iu, iv, t);
        slab.set(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
    };
    // Edge values of the w-line are affine in the pixel centre: step them
    // along u by `step`.
    let mut c0 = s.a;
    (c0[u], c0[v]) = (lo[u] * ONE + H, lo[v] * ONE + H);
    let mut c1 = c0;
    c1[u] += ONE;
    let (o0, o1) = (s.line_values(dw, s.local(c0)), s.line_values(dw, s.local(c1)));
    let step: [T; 3] = std::array::from_fn(|i| o1[i] - o0[i]);
    for iv in lo[v]..=hi[v] {
        let mut c = s.a;
        (c[u], c[v]) = (lo[u] * ONE + H, iv * ONE + H);
        let mut pc = s.local(c);
        let mut o = s.line_values(dw, pc);
        for iu in lo[u]..=hi[u] {
            if iu > lo[u] {
                pc[u] = pc[u] + one;
                for i in 0..3 {
                    o[i] = o[i] + step[i];
                }
            }
            let inside = [0, 1, 2].map(|i| o[i] >= dw.be[i]);
            // Plane value along the column: V(W) = v0 + n_w·(W − a_w).
            let v0 = nu * pc[u] + nv * pc[v];
            if inside[0] == inside[1] && inside[1] == inside[2] {
                let t = s.straddling_step(nw, v0, T::from_i64(s.a[w]));
                if t >= T::from_i64(lo[w]) && t <= T::from_i64(hi[w]) {
                    emit(slab, iu, iv, t.to_i128() as i64);
                }
                continue;
            }
            // Centre outside: skip pixels whose square misses the projection.
            if pix.misses(&o) {
                continue;
            }
            // The plane's depth at the centre. Along a perpendicular
            // crosshair segment (half a voxel each way) it moves by at most
            // half a voxel (|n_u|, |n_v| <= |n_w|), so only segments at
            // depth t·ONE + H within H of it can be hit; one lattice unit of
            // margin covers the f64 rounding. The tests below are exact.
            let depth = s.a[w] as f64 - v0.to_f64() * inv_nw;
            let t0 = (((depth - (ONE + 1) as f64) / ONE as f64).floor() as i64).max(lo[w]);
            let t1 = (((depth + 1.0) / ONE as f64).floor() as i64).min(hi[w]);
            for t in t0..=t1 {
                let tw = T::from_i64(t * ONE + H - s.a[w]);
                let mut pu = pc;
                (pu[u], pu[w]) = (pc[u] - h, tw);
                let mut pv = pc;
                (pv[v], pv[w]) = (pc[v] - h, tw);
                if s.segment_hits(&du, pu) || s.segment_hits(&dv, pv) {
                    emit(slab, iu, iv, t);
                }
            }
        }
    }
}

/// The slow, obviously correct definition of `sep6`.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;
    use crate::voxelize::targets::sep6_hit;

    /// Brute force over each triangle's bounding box.
    pub fn sep6(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, sep6_hit)
    }
}
