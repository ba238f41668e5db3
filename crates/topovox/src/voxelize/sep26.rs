//! Laine's minimal 26-separating surface voxelization (`sep26`).
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §5.1 (targets that
//! connect the voxel's corners; the space-diagonal target of Fig. 11b).
//!
//! **Guarantee.** Voxel `(i,j,k)` is set iff some (snapped, non-degenerate)
//! triangle meets one of the voxel's four space diagonals, displaced by the
//! tie rule of [`crate::geom::perturb`]. For a closed surface the result is
//! 26-separating; it is a subset of `cover` (every diagonal lies in the
//! closed voxel).
//!
//! **Fast path.** Per triangle, the columns of its dominant-axis projection
//! whose pixel meets the projected triangle; in each, the two to four
//! voxels around the plane's depth; an exact corner-sign test (a plane that
//! separates a voxel's corners crosses one of its space diagonals, and the
//! steepest of them, joining the lowest and highest corners, always);
//! then, in pixels not strictly inside all three edges, the steepest
//! diagonal's edge values stepped along the column by additions. Where
//! it misses, the other three: with the slab driver, put off until the
//! slab's other triangles have run (the driver's `Deferred`) and tested
//! only if none of those set the voxel (the union is the same; at 1024³
//! on the bunny 98 % of the 1.9 M put-off voxels are set by then);
//! otherwise at once, for the edges the pixel is not strictly inside of.
//! Triangles in a box of at most 27 voxels go by the diagonals' lines
//! instead (`tiny`). Exact integers (`i64` relative to the triangle for
//! all but huge triangles, `TriSetup`), parallel over z-slabs like `cover`.
//!
//! **Reference:** [`reference::sep26`], the definition evaluated with the
//! generic `i128` predicate for every voxel of each triangle's bounding box.

use super::cover::{PlaneRange, Setup as CoverSetup};
use super::driver::{buffered, run_mesh, run_slabs, Deferred, Kernel};
use super::targets::{diagonal_lines, is_tiny, LazyTargets, PixelTest, DIAGONALS, DIAGONAL_SET};
use super::{Options, Report};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::P3;
use crate::geom::setup::{dominant_axes, fits_i64, DirSetup, TriSetup};
use crate::grid::bricks::{BoxBricks, BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// 26-separating voxelization, fast path, into sparse brick storage.
pub fn sep26(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&Sep26Kernel, mesh, grid, opts)
}

/// The fast path on already prepared triangles (the GPU path hands it the
/// triangles too large for its 64-bit shader arithmetic).
pub fn sep26_lattice(tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> BrickBits {
    run_slabs(&Sep26Kernel, tris, dims, opts).0
}

struct Sep26Kernel;

/// A triangle whose box [`is_tiny`], by the diagonals' lines
/// ([`diagonal_lines`]). Nothing to do if no space diagonal passes its box
/// (most triangles at 32³, `TargetSet::may_meet`).
#[inline(never)]
fn tiny(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let (blo, bhi) = tri.bounds();
    if !DIAGONAL_SET.may_meet(blo, bhi) {
        return;
    }
    diagonal_lines::<false>(tri, lo, hi, slab);
}

impl Kernel<LatticeTriangle> for Sep26Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        self.run_deferring(tri, lo, hi, slab, &mut Deferred::off());
    }

    #[inline(always)]
    fn run_deferring(
        &self,
        tri: &LatticeTriangle,
        lo: [i64; 3],
        hi: [i64; 3],
        slab: &mut BrickSlab<'_>,
        deferred: &mut Deferred<LatticeTriangle>,
    ) {
        if !fits_i64(tri) {
            project::<i128>(tri, lo, hi, slab, deferred);
        } else if is_tiny(lo, hi) {
            tiny(tri, lo, hi, slab);
        } else {
            project::<i64>(tri, lo, hi, slab, deferred);
        }
    }

    fn finish(&self, deferred: &mut Deferred<LatticeTriangle>, slab: &mut BrickSlab<'_>) {
        deferred.drain(|tri, voxels| {
            if fits_i64(tri) {
                retest::<i64>(tri, voxels, slab);
            } else {
                retest::<i128>(tri, voxels, slab);
            }
        });
    }
}

/// The deferred voxels of `tri` (those [`project`] found its steepest
/// diagonal to miss, in columns near its edges): each still unset once
/// the slab's other triangles have run gets the definition, all four
/// diagonals ([`LazyTargets`], set up only if one is still unset). At
/// 1024³ on the bunny fewer than 2 % are.
#[inline(never)]
fn retest<T: PlaneInt>(tri: &LatticeTriangle, voxels: &[[u32; 3]], slab: &mut BrickSlab<'_>) {
    let mut targets = None;
    for &[i, j, k] in voxels {
        if slab.get(i, j, k) {
            continue;
        }
        let t = targets.get_or_insert_with(|| LazyTargets::<T, 4>::new(tri, &DIAGONAL_SET));
        let ijk = [i, j, k].map(|c| c as i64);
        if (0..4).any(|n| t.hits(n, ijk)) {
            slab.set(i, j, k);
        }
    }
}

/// One triangle, restricted to the voxel box `[lo, hi]`: the columns of
/// the dominant-axis projection whose pixel meets the projected triangle;
/// in each, exactly the voxels whose corners straddle the displaced plane
/// (tracked along the row by `cover`'s exact plane range, with its
/// thresholds moved by the perturbation's bias); then the diagonal tests
/// for the edges the pixel is not strictly inside.
fn project<T: PlaneInt>(
    tri: &LatticeTriangle,
    lo: [i64; 3],
    hi: [i64; 3],
    slab: &mut BrickSlab<'_>,
    deferred: &mut Deferred<LatticeTriangle>,
) {
    let mark = deferred.mark();
    // Whether to put tests off is a constant of each instance: the path
    // that tests at once stays as it was without the option (a run-time
    // choice measured 3 % slower at 512³).
    buffered(lo, hi, slab, |slab, buf| match (deferred.is_on(), dominant_axes(tri).2) {
        (true, 0) => project_deferring::<T, 0>(tri, lo, hi, slab, buf, deferred),
        (true, 1) => project_deferring::<T, 1>(tri, lo, hi, slab, buf, deferred),
        (true, _) => project_deferring::<T, 2>(tri, lo, hi, slab, buf, deferred),
        (false, 0) => project_w::<T, 0, false>(tri, lo, hi, slab, buf, deferred),
        (false, 1) => project_w::<T, 1, false>(tri, lo, hi, slab, buf, deferred),
        (false, _) => project_w::<T, 2, false>(tri, lo, hi, slab, buf, deferred),
    });
    deferred.close(tri, mark);
}

/// [`project_w`] putting tests off, as a call of its own: inlined
/// beside the other instances, it slowed them (512³, 1 thread: +5 %).
#[inline(never)]
fn project_deferring<T: PlaneInt, const W: usize>(
    tri: &LatticeTriangle,
    lo: [i64; 3],
    hi: [i64; 3],
    slab: &mut BrickSlab<'_>,
    buf: Option<&mut BoxBricks>,
    deferred: &mut Deferred<LatticeTriangle>,
) {
    project_w::<T, W, true>(tri, lo, hi, slab, buf, deferred);
}

#[inline(always)]
fn project_w<T: PlaneInt, const W: usize, const DEFER: bool>(
    tri: &LatticeTriangle,
    lo: [i64; 3],
    hi: [i64; 3],
    slab: &mut BrickSlab<'_>,
    mut buf: Option<&mut BoxBricks>,
    deferred: &mut Deferred<LatticeTriangle>,
) {
    let s = TriSetup::<T>::new(tri);
    // The diagonal along which the plane value changes most (its signs
    // are the normal's) joins the voxel's lowest and highest corners, so
    // it crosses the plane wherever any diagonal does: tested first, it
    // ends most hits' tests. (Built in that order, not swapped after: a
    // swap of two direction setups is a call to memmove.)
    let n = tri.normal();
    let slope = |d: P3| (n[0] as f64 * d[0] as f64 + n[1] as f64 * d[1] as f64 + n[2] as f64 * d[2] as f64).abs();
    let steepest = (1..4).fold(0, |b, i| if slope(DIAGONALS[i].1) > slope(DIAGONALS[b].1) { i } else { b });
    let dir = |k: usize| {
        let (o, d) = DIAGONALS[if k == 0 {
            steepest
        } else if k == steepest {
            0
        } else {
            k
        }];
        let o = o.map(T::from_i64);
        (o, s.plane(o), s.dir(tri, d))
    };
    // The other three only for testing at once: put off, they are set up
    // (rarely) by `retest`, and here the steepest's copies fill the
    // array, never read.
    let dirs: [_; 4] = if DEFER {
        let d = dir(0);
        [d; 4]
    } else {
        std::array::from_fn(dir)
    };
    let (u, v, w) = ((W + 1) % 3, (W + 2) % 3, W);
    debug_assert_eq!(dominant_axes(tri), (u, v, w));
    let steep_w = dirs[0].2.line_steps(w);
    let pix = PixelTest::new(&s, tri, (u, v, w));
    // Some corner's displaced copy is on each side of the plane: with n
    // oriented so n_w > 0 (`flip`), the corners' values relative to the
    // first vertex reach `>= hi` and `<= lo` (the bias is 0 or 1).
    let bn = s.bn;
    let (shift_hi, shift_lo) = if n[w] > 0 { (bn, bn - T::from_i64(1)) } else { (T::from_i64(1) - bn, -bn) };
    let mut range = CoverSetup::<T>::new(tri, lo);
    debug_assert_eq!(range.w(), w);
    range.shift_plane(shift_hi, shift_lo);
    let (nu, nw) = range.steps();
    // Pixel bounds are affine in the pixel centre: step them along u.
    let mut c0 = s.a;
    (c0[u], c0[v]) = (lo[u] * ONE + H, lo[v] * ONE + H);
    let mut c1 = c0;
    c1[u] += ONE;
    let delta = pix.bounds(&s, s.local(c0)).delta(&pix.bounds(&s, s.local(c1)));
    for iv in lo[v]..=hi[v] {
        let mut c = s.a;
        (c[u], c[v]) = (lo[u] * ONE + H, iv * ONE + H);
        let mut b = pix.bounds(&s, s.local(c));
        // Only the row's pixels that meet the projection.
        let (a0, a1) = b.row_span(&delta, lo[u], hi[u]);
        if a0 > a1 {
            continue;
        }
        b.advance(&delta, T::from_i64(a0 - lo[u]));
        let mut plane = PlaneRange::at::<W>(&range, a0, iv);
        let mut iu = a0;
        loop {
            debug_assert!(!b.misses());
            let (ta, tb) = (plane.t0.max(lo[w]), plane.t1.min(hi[w]));
            if ta <= tb {
                let col = Column { iu, iv, ta, tb, safe: b.strictly_inside_edges() };
                column::<T, DEFER>(&s, &dirs, (u, v, w), &steep_w, col, (slab, buf.as_deref_mut(), deferred));
            }
            if iu == a1 {
                break;
            }
            iu += 1;
            plane.next_column(nu, nw);
            b.step(&delta);
        }
    }
}

/// A column of one pixel (`iu`, `iv`) of [`project_w`]'s projection:
/// the voxels `ta..=tb` along `w` whose corners straddle the plane, and
/// the pixel's edges it lies strictly inside of (`safe`).
#[derive(Clone, Copy)]
struct Column {
    iu: i64,
    iv: i64,
    ta: i64,
    tb: i64,
    safe: [bool; 3],
}

/// Sets the voxels of `col` that meet the triangle (`s`, its diagonal
/// directions `dirs`, the steepest first): into `buf` if given, else
/// `slab`; with `DEFER`, the voxels only the other three diagonals could
/// decide go to `deferred`. Inlined into [`project_w`]'s loop.
#[inline(always)]
fn column<T: PlaneInt, const DEFER: bool>(
    s: &TriSetup<T>,
    dirs: &[([T; 3], T, DirSetup<T>); 4],
    (u, v, w): (usize, usize, usize),
    steep_w: &[T; 3],
    col: Column,
    (slab, mut buf, deferred): (&mut BrickSlab<'_>, Option<&mut BoxBricks>, &mut Deferred<LatticeTriangle>),
) {
    let Column { iu, iv, ta, tb, safe } = col;
    // Edges the pixel lies strictly inside of: a diagonal's crossing with
    // the plane lies in the voxel, so projects into the pixel, and those
    // edges' tests are known to pass.
    let all_safe = safe == [true; 3];
    // The steepest diagonal crosses the plane in every voxel of the range:
    // its edge values at the column's first voxel, then stepped along t
    // (additions), decide most voxels.
    let mut steep = [T::ZERO; 3];
    if !all_safe {
        let mut corner = [0i64; 3];
        (corner[u], corner[v], corner[w]) = (iu * ONE, iv * ONE, ta * ONE);
        let p = s.local(corner);
        steep = s.line_values(&dirs[0].2, [p[0] + dirs[0].0[0], p[1] + dirs[0].0[1], p[2] + dirs[0].0[2]]);
    }
    for t in ta..=tb {
        let mut ijk = [0u32; 3];
        (ijk[u], ijk[v], ijk[w]) = (iu as u32, iv as u32, t as u32);
        // The corners straddle the plane, so the steepest diagonal crosses
        // it; the other three only matter where it misses the triangle.
        // With the slab driver they are tested later, and only if no other
        // triangle has set the voxel by then (at 1024³, 1.9 M voxels here,
        // 32 k of them still unset then); otherwise now, for the edges not
        // known to pass.
        let others = || {
            let mut corner = [0i64; 3];
            (corner[u], corner[v], corner[w]) = (iu * ONE, iv * ONE, t * ONE);
            let p = s.local(corner);
            let vc = s.plane(p);
            dirs[1..].iter().any(|(o, vo, ds)| s.segment_hits_unsafe_edges(ds, [p[0] + o[0], p[1] + o[1], p[2] + o[2]], vc + *vo, safe))
        };
        let hit = all_safe
            || dirs[0].2.inside(&steep)
            || if DEFER {
                deferred.push(ijk[0], ijk[1], ijk[2]);
                false
            } else {
                others()
            };
        if hit {
            match buf.as_deref_mut() {
                Some(b) => b.set(ijk[0], ijk[1], ijk[2]),
                None => slab.set(ijk[0], ijk[1], ijk[2]),
            }
        }
        for (x, d) in steep.iter_mut().zip(steep_w) {
            *x = *x + *d;
        }
    }
}

/// The slow, obviously correct definition of `sep26`.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;
    use crate::voxelize::targets::sep26_hit;

    /// Brute force over each triangle's bounding box.
    pub fn sep26(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, sep26_hit)
    }
}
