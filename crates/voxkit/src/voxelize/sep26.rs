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
//! **Fast path.** `cover`'s exact traversal enumerates the candidate voxels
//! of each triangle; each candidate gets the four diagonal tests, in `i64`
//! relative to the triangle for all but huge triangles (`TriSetup`).
//! Parallel over z-slabs like `cover`.
//!
//! **Reference:** [`reference::sep26`], the definition evaluated with the
//! generic `i128` predicate for every voxel of each triangle's bounding box.

use super::cover::cover_triangle;
use super::driver::{run_slabs, Filter, Kernel};
use super::targets::{dominant_axes, fits_i64, PixelTest, TriSetup, DIAGONALS};
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::{prepare, LatticeTriangle};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// 26-separating voxelization, fast path, into sparse brick storage.
pub fn sep26(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    let (tris, prepare_stats) = prepare(mesh, grid);
    let (bits, voxels) = run_slabs(&Sep26Kernel { traversal: opts.traversal }, &tris, grid.dims(), opts);
    (bits, Report { prepare: prepare_stats, voxels })
}

struct Sep26Kernel {
    traversal: Traversal,
}

impl Kernel<LatticeTriangle> for Sep26Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            filtered::<i64>(tri, lo, hi, self.traversal, slab);
        } else {
            filtered::<i128>(tri, lo, hi, self.traversal, slab);
        }
    }
}

fn filtered<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], traversal: Traversal, slab: &mut BrickSlab<'_>) {
    let s = TriSetup::<T>::new(tri);
    let dirs = DIAGONALS.map(|(o, d)| {
        let o = o.map(T::from_i64);
        (o, s.plane(o), s.dir(tri, d))
    });
    // Plane values of the voxel's corners span [vc + lo, vc + hi].
    let (mut vlo, mut vhi) = (T::ZERO, T::ZERO);
    for c in s.n {
        let x = c * T::from_i64(ONE);
        if x < T::ZERO {
            vlo = vlo + x;
        } else {
            vhi = vhi + x;
        }
    }
    let (u, v, w) = dominant_axes(tri);
    let pix = PixelTest::new(&s, tri, (u, v, w));
    // cover emits a column's voxels together: decide once per column
    // whether its pixel lies strictly inside the projected triangle.
    let mut column = (i64::MIN, i64::MIN, false);
    let keep = |ijk: [i64; 3]| {
        let c = s.local(ijk.map(|x| x * ONE));
        let vc = s.plane(c);
        if (ijk[u], ijk[v]) != (column.0, column.1) {
            let mut pc = c;
            pc[u] = pc[u] + T::from_i64(ONE / 2);
            pc[v] = pc[v] + T::from_i64(ONE / 2);
            column = (ijk[u], ijk[v], pix.strictly_inside(&s.line_values(&pix.dw, pc)));
        }
        if column.2 {
            // Every point of the voxel's plane section projects strictly
            // inside the triangle, so a diagonal is hit iff the (displaced)
            // corners are not all on one side: for an affine plane value,
            // opposite corners average to the centre's value, so corners
            // on both sides put some opposite pair on both sides.
            return vc + vlo < s.bn && vc + vhi >= s.bn;
        }
        dirs.iter().any(|(o, vo, ds)| s.segment_hits_with(ds, [c[0] + o[0], c[1] + o[1], c[2] + o[2]], vc + *vo))
    };
    cover_triangle(tri, lo, hi, traversal, &mut Filter { slab, keep });
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
