//! Alternating single-diagonal 6-separating voxelization (`diagonal`).
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §6 (Fig. 14: one
//! space diagonal per voxel, alternating so that the diagonals of
//! neighbouring voxels join).
//!
//! **Target.** Voxel `(i,j,k)`'s single body diagonal joining its corner
//! whose three lattice indices (counted from the grid origin) are odd to
//! the opposite corner, whose three are even. The pattern repeats every 2
//! voxels; face-adjacent voxels' diagonals meet at their shared corners, so
//! the targets form a connected network that no 6-connected path of voxels
//! crosses without a set voxel. Ties follow [`crate::geom::perturb`].
//!
//! **Guarantee.** 6-separating for closed surfaces (certified by `topovox
//! check` in the tests); a subset of `cover` and of `sep26` (its one
//! diagonal is one of `sep26`'s four). The simplest target of all — one
//! segment — but not the fewest voxels (README compares it with `sep6` and
//! `ss6`).
//!
//! **Fast path.** By the lines of the diagonals through all-even corners,
//! which carry exactly the voxels' own diagonals: each such line that
//! meets the triangle sets the voxel whose diagonal on it straddles the
//! plane. Triangles of a few voxels test their few lines one by one
//! (`diagonal_lines`); larger ones take them row by row as exact spans
//! (`line_spans.rs`); huge ones (beyond `i64`) take `cover`'s exact
//! traversal as candidates, each with its one target's test
//! (`LazyTargets`, `i128`).
//!
//! **Reference:** [`reference::diagonal`].

use super::cover::cover_triangle;
use super::driver::{run_mesh, Filter, Kernel};
use super::targets::{diagonal_lines, is_tiny, LazyTargets, DIAGONALS, DIAGONAL_SET};
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::{segment_meets_triangle, P3};
use crate::geom::setup::fits_i64;
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// The index into [`DIAGONALS`] of voxel `ijk`'s diagonal: the one through
/// its all-odd corner `c_odd` and all-even corner. Per axis the odd corner
/// index is `i` if `i` is odd, else `i + 1`; the diagonal runs between the
/// corners that differ on every axis, so it is fixed by which axes have the
/// odd corner on the low side.
pub fn which(ijk: [i64; 3]) -> usize {
    // Per axis: is the odd corner on the voxel's low side? The diagonal
    // joins corner offsets `c` and `1 − c`; DIAGONALS[n] starts at offset
    // (0,0,0), (1,0,0), (0,1,0) or (0,0,1), so it is found from either end.
    let odd_low = ijk.map(|c| c.rem_euclid(2) == 1);
    let key = |lo: [bool; 3]| -> usize {
        match lo {
            [false, false, false] | [true, true, true] => 0,
            [true, false, false] | [false, true, true] => 1,
            [false, true, false] | [true, false, true] => 2,
            _ => 3,
        }
    };
    key(odd_low)
}

/// The target segment of voxel `ijk`.
pub fn target(ijk: [i64; 3]) -> [P3; 2] {
    let (o, d) = DIAGONALS[which(ijk)];
    let a: P3 = std::array::from_fn(|c| ijk[c] * ONE + o[c]);
    [a, std::array::from_fn(|c| a[c] + d[c])]
}

/// Alternating-diagonal voxelization, fast path, into sparse bricks.
pub fn diagonal(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&DiagonalKernel { traversal: opts.traversal }, mesh, grid, opts)
}

/// The fast path on already prepared triangles. The pattern repeats every
/// 2 voxels, so triangles translated by an even number of voxels (the tiled
/// driver's tiles) get the same voxels, translated.
pub fn diagonal_lattice(tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> BrickBits {
    super::driver::run_slabs(&DiagonalKernel { traversal: opts.traversal }, tris, dims, opts).0
}

struct DiagonalKernel {
    traversal: Traversal,
}

impl Kernel<LatticeTriangle> for DiagonalKernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        // Integer test first: most triangles at 32³ pass no space diagonal.
        // Then the tiny ones by the diagonals' lines.
        if is_tiny(lo, hi) {
            let (blo, bhi) = tri.bounds();
            if !DIAGONAL_SET.may_meet(blo, bhi) {
                return;
            }
            if fits_i64(tri) {
                return diagonal_lines::<true>(tri, lo, hi, slab);
            }
        }
        if fits_i64(tri) {
            let sp = super::line_spans::SpanSetup::new(tri);
            super::driver::buffered(lo, hi, slab, |slab, buf| match buf {
                Some(b) => sp.diagonals(2, lo, hi, b),
                None => sp.diagonals(2, lo, hi, slab),
            });
        } else {
            filtered::<i128>(tri, lo, hi, self.traversal, slab);
        }
    }
}

fn filtered<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], traversal: Traversal, slab: &mut BrickSlab<'_>) {
    let targets = LazyTargets::<T, 4>::new(tri, &DIAGONAL_SET);
    let keep = |i: i64, j: i64, k: i64| targets.hits(which([i, j, k]), [i, j, k]);
    cover_triangle(tri, lo, hi, traversal, &mut Filter { slab, keep });
}

/// The slow, obviously correct definition.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;

    /// Does `t` meet voxel `ijk`'s diagonal?
    pub fn hit(t: &LatticeTriangle, ijk: [i64; 3]) -> bool {
        segment_meets_triangle(target(ijk), t.v, true)
    }

    /// Brute force over each triangle's bounding box.
    pub fn diagonal(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, hit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_diagonal_joins_the_all_odd_and_the_all_even_corner() {
        for i in -3..4i64 {
            for j in -3..4i64 {
                for k in -3..4i64 {
                    let [a, b] = target([i, j, k]);
                    let corners = [a, b].map(|p| p.map(|c| c.div_euclid(ONE)));
                    let odd = |c: [i64; 3]| c.iter().all(|x| x.rem_euclid(2) == 1);
                    let even = |c: [i64; 3]| c.iter().all(|x| x.rem_euclid(2) == 0);
                    assert!((odd(corners[0]) && even(corners[1])) || (even(corners[0]) && odd(corners[1])), "{i} {j} {k}: {corners:?}");
                    assert!(corners.iter().all(|c| (0..3).all(|x| c[x] == [i, j, k][x] || c[x] == [i, j, k][x] + 1)));
                }
            }
        }
    }
}
