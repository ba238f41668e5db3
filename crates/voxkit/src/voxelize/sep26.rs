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
//! separates a voxel's corners crosses one of its space diagonals); then
//! the diagonal tests, only for the edges the pixel is not strictly inside
//! of. Exact integers (`i64` relative to the triangle for all but huge
//! triangles, `TriSetup`), parallel over z-slabs like `cover`.
//!
//! **Reference:** [`reference::sep26`], the definition evaluated with the
//! generic `i128` predicate for every voxel of each triangle's bounding box.

use super::driver::{run_mesh, run_slabs, Kernel};
use super::targets::{dominant_axes, fits_i64, PixelTest, TriSetup, DIAGONALS};
use super::{Options, Report};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::grid::bricks::{BrickBits, BrickSlab};
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

impl Kernel<LatticeTriangle> for Sep26Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            project::<i64>(tri, lo, hi, slab);
        } else {
            project::<i128>(tri, lo, hi, slab);
        }
    }
}

/// One triangle, restricted to the voxel box `[lo, hi]`: the columns of
/// the dominant-axis projection whose pixel meets the projected triangle,
/// the few voxels of each around the plane's depth, a corner-sign test,
/// then the diagonal tests for the edges the pixel is not strictly inside.
fn project<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let s = TriSetup::<T>::new(tri);
    let dirs = DIAGONALS.map(|(o, d)| {
        let o = o.map(T::from_i64);
        (o, s.plane(o), s.dir(tri, d))
    });
    // Plane values of a voxel's corners span [vc + vlo, vc + vhi], vc at
    // its low corner.
    let (mut vlo, mut vhi) = (T::ZERO, T::ZERO);
    for c in s.n {
        let x = c * T::from_i64(ONE);
        if x < T::ZERO {
            vlo = vlo + x;
        } else {
            vhi = vhi + x;
        }
    }
    let n = tri.normal();
    let (u, v, w) = dominant_axes(tri);
    let pix = PixelTest::new(&s, tri, (u, v, w));
    let step_w = s.n[w] * T::from_i64(ONE);
    let (nu, nv) = (T::from_i64(n[u]), T::from_i64(n[v]));
    let inv_nw = 1.0 / n[w] as f64;
    let one = T::from_i64(ONE);
    // Edge values of the w-line are affine in the pixel centre: step them along u.
    let mut c0 = s.a;
    (c0[u], c0[v]) = (lo[u] * ONE + H, lo[v] * ONE + H);
    let mut c1 = c0;
    c1[u] += ONE;
    let (o0, o1) = (s.line_values(&pix.dw, s.local(c0)), s.line_values(&pix.dw, s.local(c1)));
    let step: [T; 3] = std::array::from_fn(|i| o1[i] - o0[i]);
    for iv in lo[v]..=hi[v] {
        let mut c = s.a;
        (c[u], c[v]) = (lo[u] * ONE + H, iv * ONE + H);
        let mut pc = s.local(c);
        let mut o = s.line_values(&pix.dw, pc);
        for iu in lo[u]..=hi[u] {
            if iu > lo[u] {
                pc[u] = pc[u] + one;
                for i in 0..3 {
                    o[i] = o[i] + step[i];
                }
            }
            if pix.misses(&o) {
                continue;
            }
            // Edges the pixel lies strictly inside of: a diagonal's crossing
            // with the plane lies in the voxel, so projects into the pixel,
            // and those edges' tests are known to pass.
            let safe = pix.strictly_inside_edges(&o);
            // Over the pixel the plane's depth moves by at most one voxel
            // from the centre's (|n_u|, |n_v| <= |n_w|); the f64 estimate
            // (truncated) is within two lattice units of it. The corner test
            // is exact.
            let depth = s.a[w] - ((nu * pc[u] + nv * pc[v]).to_f64() * inv_nw) as i64;
            let t0 = (depth - ONE - 2).div_euclid(ONE).max(lo[w]);
            let t1 = (depth + ONE + 2).div_euclid(ONE).min(hi[w]);
            if t0 > t1 {
                continue;
            }
            let mut corner = [0i64; 3];
            (corner[u], corner[v], corner[w]) = (iu * ONE, iv * ONE, t0 * ONE);
            let mut p = s.local(corner);
            let mut vc = s.plane(p);
            for t in t0..=t1 {
                if t > t0 {
                    vc = vc + step_w;
                    p[w] = p[w] + T::from_i64(ONE);
                }
                // Corners all on one side: no diagonal straddles the plane.
                if vc + vlo >= s.bn || vc + vhi < s.bn {
                    continue;
                }
                // Otherwise some opposite pair straddles (opposite corners
                // average to the centre's value).
                let hit = safe == [true; 3]
                    || dirs
                        .iter()
                        .any(|(o, vo, ds)| s.segment_hits_unsafe_edges(ds, [p[0] + o[0], p[1] + o[1], p[2] + o[2]], vc + *vo, safe));
                if hit {
                    let mut ijk = [0u32; 3];
                    (ijk[u], ijk[v], ijk[w]) = (iu as u32, iv as u32, t as u32);
                    slab.set(ijk[0], ijk[1], ijk[2]);
                }
            }
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
