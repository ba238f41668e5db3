//! 18- and 26-tunnel-free surface voxelization (`tunnel18`, `tunnel26`).
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §5.2.2 (tunnel-free
//! voxelizations: targets that join the voxel centre to every point where
//! it meets a neighbour of the given adjacency).
//!
//! **Targets.** Segments from the voxel's centre `m`:
//! - `tunnel18`: to its 6 face centres (the 3D crosshair of `sep6`) and to
//!   its 12 edge midpoints;
//! - `tunnel26`: also to its 8 corners (the 4 space diagonals of `sep26`).
//!
//! Voxel `(i,j,k)` is set iff some (snapped, non-degenerate) triangle meets
//! one of its targets, every target displaced by the tie rule of
//! [`crate::geom::perturb`].
//!
//! **Guarantee.** No segment between the centres of two 18-adjacent
//! (26-adjacent) unset voxels meets the surface: such a segment passes
//! through the shared face centre, edge midpoint (or corner) and is the
//! union of two targets, one of each voxel; displaced alike, a surface
//! meeting it meets one of them. `tunnel26 ⊇ tunnel18 ⊇ sep6`, `tunnel26 ⊇
//! sep26`, and both are subsets of `cover` (every target lies in the
//! closed voxel). `topovox check` counts 6-, 18- and 26-tunnels.
//!
//! **Fast path.** `cover`'s exact traversal enumerates candidates not yet
//! set; each gets the tests of its targets (`PairedTargets`, `i64` for
//! all but huge triangles). The targets come in opposite pairs on the 13 (9)
//! lines through the centre, so one comparison per line says whether one
//! of its two targets crosses the plane, and the lines' edge sides come
//! from the centre's pivot cross: for a triangle in a box of at most
//! 64 voxels (`TABLE_BOX`), for all lines at once from a table keyed by each
//! cross product's sign pattern; for larger ones, or where a line may lie
//! on an edge's plane (a tie), three dot products per line, stopping at
//! the first line that hits.
//!
//! **Reference:** [`reference::tunnel`], every target of every voxel of each
//! triangle's bounding box with the generic `i128` predicate.

use super::cover::cover_triangle;
use super::driver::{box_volume, run_mesh, FilterUnset, Kernel};
use super::targets::{forms_reached, PairedTargets, TargetSet};
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::{segment_meets_triangle, P3};
use crate::geom::setup::fits_i64;
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// Which tunnels the targets close.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TunnelTarget {
    /// Centre to face centres and edge midpoints.
    Eighteen,
    /// Also centre to corners.
    TwentySix,
}

/// The target segments of a voxel with low corner at the origin, as
/// `(start, direction)`: start at the centre `(H, H, H)`.
pub fn targets(target: TunnelTarget) -> Vec<(P3, P3)> {
    let mut out = Vec::new();
    for dz in -1..=1i64 {
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                let n = dx.abs() + dy.abs() + dz.abs();
                let keep = match target {
                    TunnelTarget::Eighteen => n == 1 || n == 2,
                    TunnelTarget::TwentySix => n >= 1,
                };
                if keep {
                    out.push(([H, H, H], [dx * H, dy * H, dz * H]));
                }
            }
        }
    }
    out
}

/// Tunnel-free voxelization, fast path, into sparse bricks.
pub fn tunnel(mesh: MeshRef<'_>, grid: &GridSpec, target: TunnelTarget, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&TunnelKernel::new(target, opts), mesh, grid, opts)
}

/// The fast path on already prepared triangles.
pub fn tunnel_lattice(tris: &[LatticeTriangle], dims: [u32; 3], target: TunnelTarget, opts: &Options<'_>) -> BrickBits {
    super::driver::run_slabs(&TunnelKernel::new(target, opts), tris, dims, opts).0
}

/// Largest voxel box of a triangle whose candidates take the sign tables
/// ([`PairedTargets::any`]); larger triangles' go line by line. In a large
/// triangle's voxels the first line tested usually passes, so stopping
/// there beats deciding all lines: 1024³ on the bunny, 1 thread, 157 →
/// 138 ms with this bound (all by tables before), 128³–512³ unchanged
/// (the 27 voxels of `is_tiny` were 3 % slower at 256³).
const TABLE_BOX: i64 = 64;

struct TunnelKernel {
    dirs: TargetSet<26>,
    traversal: Traversal,
}

impl TunnelKernel {
    fn new(target: TunnelTarget, opts: &Options<'_>) -> TunnelKernel {
        let dirs = TargetSet::new(&targets(target));
        assert!(dirs.paired(), "the tunnels' targets come in opposite pairs");
        TunnelKernel { dirs, traversal: opts.traversal }
    }
}

impl Kernel<LatticeTriangle> for TunnelKernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        // Integer tests first: most triangles at 32³ pass no target line.
        let (blo, bhi) = tri.bounds();
        let reached = forms_reached(blo, bhi);
        if !self.dirs.may_meet_reached(reached) {
            return;
        }
        if !fits_i64(tri) {
            filtered::<i128, false>(tri, &self.dirs, reached, lo, hi, self.traversal, slab);
        } else if box_volume(lo, hi) <= TABLE_BOX {
            filtered::<i64, true>(tri, &self.dirs, reached, lo, hi, self.traversal, slab);
        } else {
            filtered::<i64, false>(tri, &self.dirs, reached, lo, hi, self.traversal, slab);
        }
    }
}

fn filtered<T: PlaneInt, const TABLE: bool>(
    tri: &LatticeTriangle,
    dirs: &TargetSet<26>,
    reached: u16,
    lo: [i64; 3],
    hi: [i64; 3],
    traversal: Traversal,
    slab: &mut BrickSlab<'_>,
) {
    let targets = PairedTargets::<T, 26>::new(tri, dirs, reached);
    let keep = |i: i64, j: i64, k: i64| targets.any::<TABLE>([i, j, k]);
    cover_triangle(tri, lo, hi, traversal, &mut FilterUnset { slab, keep });
}

/// The slow, obviously correct definition.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;

    /// The definition: does `t` meet one of voxel `ijk`'s targets?
    pub fn hit(t: &LatticeTriangle, ijk: [i64; 3], target: TunnelTarget) -> bool {
        let c = ijk.map(|x| x * ONE);
        targets(target).iter().any(|(o, d)| {
            let a = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
            segment_meets_triangle([a, [a[0] + d[0], a[1] + d[1], a[2] + d[2]]], t.v, true)
        })
    }

    /// Brute force over each triangle's bounding box.
    pub fn tunnel(mesh: MeshRef<'_>, grid: &GridSpec, target: TunnelTarget) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, |t, ijk| hit(t, ijk, target))
    }
}
