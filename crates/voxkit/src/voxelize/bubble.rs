//! Randomized 6-separating surface voxelization (`bubble`).
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §6 (targets that
//! vary per voxel; the randomized target of Fig. 13a, here in 3D).
//!
//! **Targets.** The 3D crosshair of `sep6` with its joins moved: each voxel
//! has a random point `m` strictly inside it (instead of its centre) and
//! each face a random point strictly inside the face (instead of the face
//! centre), shared by the two voxels of the face. A voxel's target is the
//! six segments from `m` to the points of its six faces, and one more from
//! its centre to `m`. Points are lattice points drawn from a hash of
//! `(seed, voxel or face)`, so the same seed gives the same voxels, on any
//! path and thread count.
//!
//! *Where we had to choose:* Laine's figure joins the random points only.
//! Separation is about which side of the surface a voxel is on; with the
//! centre on the target, an unset voxel's whole target — centre included —
//! is on one side, so the guarantee holds for the usual classification of
//! voxels by their centres (what `voxkit check` certifies), not only for a
//! classification by the random points.
//!
//! **Guarantee.** 6-separating for closed surfaces, like `sep6`: two
//! face-adjacent unset voxels' targets join their centres through the
//! shared face point, so a 6-connected path of unset voxels is a path of
//! target segments that the surface does not meet. Irregular pattern; a
//! subset of `cover` (every target lies in the closed voxel). Ties follow
//! [`crate::geom::perturb`].
//!
//! **Fast path.** `cover`'s exact traversal enumerates candidates not yet
//! set; each gets its seven segment tests, cheapest first: the ends'
//! sides of the displaced plane, then the three edge orientations. All
//! seven segments lie on lines through the voxel's random point `m`, so
//! these are dot products with one cross product per edge at `m`, exact
//! (`i64` relative to the triangle; nothing is set up per direction).
//!
//! **Reference:** [`reference::bubble`], the same targets for every voxel
//! of each triangle's bounding box.

use super::cover::cover_triangle;
use super::driver::{run_mesh, FilterUnset, Kernel};
use super::targets::{fits_i64, TriSetup};
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::{segment_meets_triangle, P3};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// A well-mixed 64-bit hash of the seed and four words (SplitMix64 rounds).
fn hash(seed: u64, words: [i64; 4]) -> u64 {
    words.iter().fold(start(seed), |x, &w| round(x, w))
}

/// The state [`hash`] starts from.
#[inline(always)]
fn start(seed: u64) -> u64 {
    seed ^ 0x9e37_79b9_7f4a_7c15
}

/// One SplitMix64 round of [`hash`], taking in the word `w`.
#[inline(always)]
fn round(x: u64, w: i64) -> u64 {
    let x = (x ^ w as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    let z = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// [`voxel_point`] and [`face_points`] of voxel `ijk` at once, the same
/// values: the seven hashes share their first words (`i`, then `j`, then
/// `k`, each either the voxel's or one more), so 16 rounds make them
/// instead of 28.
#[inline]
pub fn points(seed: u64, ijk: [i64; 3]) -> (P3, [P3; 6]) {
    let [i, j, k] = ijk;
    let (a, b) = (round(start(seed), i), round(start(seed), i + 1));
    let (aa, ab, ba) = (round(a, j), round(a, j + 1), round(b, j));
    let (aaa, aab, aba, baa) = (round(aa, k), round(aa, k + 1), round(ab, k), round(ba, k));
    // Face hashes by face (low and high per axis), then the voxel's.
    let h = [round(aaa, 0), round(baa, 0), round(aaa, 1), round(aba, 1), round(aaa, 2), round(aab, 2), round(aaa, 3)];
    let voxel = std::array::from_fn(|a| ijk[a] * ONE + offset(h[6], a as u32));
    let faces = std::array::from_fn(|f| {
        let axis = f / 2;
        std::array::from_fn(|a| (ijk[a] + (a == axis && f % 2 == 1) as i64) * ONE + if a == axis { 0 } else { offset(h[f], a as u32) })
    });
    (voxel, faces)
}

/// A lattice offset strictly inside a voxel side: `1 ..= ONE − 1`.
fn offset(h: u64, which: u32) -> i64 {
    1 + ((h >> (which * 21)) & 0x1f_ffff) as i64 % (ONE - 1)
}

/// The random point of voxel `ijk` (lattice coordinates).
pub fn voxel_point(seed: u64, ijk: [i64; 3]) -> P3 {
    let h = hash(seed, [ijk[0], ijk[1], ijk[2], 3]);
    std::array::from_fn(|a| ijk[a] * ONE + offset(h, a as u32))
}

/// The random point of the face of voxel `ijk` perpendicular to `axis` on
/// its low side (the high side of voxel `ijk − e_axis`).
pub fn face_point(seed: u64, ijk: [i64; 3], axis: usize) -> P3 {
    let h = hash(seed, [ijk[0], ijk[1], ijk[2], axis as i64]);
    std::array::from_fn(|a| ijk[a] * ONE + if a == axis { 0 } else { offset(h, a as u32) })
}

/// The random points of voxel `ijk`'s six faces (low and high face per axis).
pub fn face_points(seed: u64, ijk: [i64; 3]) -> [P3; 6] {
    std::array::from_fn(|f| {
        let axis = f / 2;
        let mut v = ijk;
        v[axis] += (f % 2) as i64;
        face_point(seed, v, axis)
    })
}

/// The seven target segments of voxel `ijk`: from its random point to its
/// six faces' (low and high face per axis), then from its centre to its
/// random point.
pub fn targets(seed: u64, ijk: [i64; 3]) -> [[P3; 2]; 7] {
    let m = voxel_point(seed, ijk);
    let faces = face_points(seed, ijk);
    std::array::from_fn(|f| if f == 6 { [ijk.map(|c| c * ONE + ONE / 2), m] } else { [m, faces[f]] })
}

/// Does `t` meet one of voxel `ijk`'s targets?
pub fn hit(t: &LatticeTriangle, ijk: [i64; 3], seed: u64) -> bool {
    targets(seed, ijk).iter().any(|s| segment_meets_triangle(*s, t.v, true))
}

/// Randomized 6-separating voxelization, fast path, into sparse bricks.
pub fn bubble(mesh: MeshRef<'_>, grid: &GridSpec, seed: u64, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&BubbleKernel { seed, traversal: opts.traversal, offset: [0; 3] }, mesh, grid, opts)
}

/// The fast path on prepared triangles translated by `-offset` voxels (a
/// tile of a larger grid whose voxel `offset` is this grid's voxel 0): the
/// random points are drawn for the voxels' indices in the whole grid.
pub fn bubble_lattice(tris: &[LatticeTriangle], dims: [u32; 3], seed: u64, offset: [i64; 3], opts: &Options<'_>) -> BrickBits {
    super::driver::run_slabs(&BubbleKernel { seed, traversal: opts.traversal, offset }, tris, dims, opts).0
}

struct BubbleKernel {
    seed: u64,
    traversal: Traversal,
    /// Index in the whole grid of this grid's voxel 0.
    offset: [i64; 3],
}

impl Kernel<LatticeTriangle> for BubbleKernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            filtered::<i64>(tri, self.seed, self.offset, lo, hi, self.traversal, slab);
        } else {
            filtered::<i128>(tri, self.seed, self.offset, lo, hi, self.traversal, slab);
        }
    }
}

/// The definition over `cover`'s voxels: each random target first past the
/// plane test (its ends on both sides of the displaced plane), then its
/// line's edge sides from the voxel's random point's [`PivotCross`]
/// (the same decision as [`segment_meets_triangle`], without its generic
/// 128-bit determinants or a per-direction setup).
#[allow(clippy::too_many_arguments)]
fn filtered<T: PlaneInt>(
    tri: &LatticeTriangle,
    seed: u64,
    offset: [i64; 3],
    lo: [i64; 3],
    hi: [i64; 3],
    traversal: Traversal,
    slab: &mut BrickSlab<'_>,
) {
    let s = TriSetup::<T>::new(tri);
    let shift: [i64; 3] = offset.map(|o| o * ONE);
    let keep = |i: i64, j: i64, k: i64| {
        let ijk = [i, j, k];
        let g: [i64; 3] = std::array::from_fn(|a| ijk[a] + offset[a]);
        // Cheapest first: a segment whose ends lie on one side of the
        // displaced plane misses; most targets are decided here. The
        // voxel's random point starts six of them and ends the seventh.
        let local = |p: P3| -> (P3, [T; 3]) {
            let a: P3 = std::array::from_fn(|c| p[c] - shift[c]);
            (a, s.local(a))
        };
        let (m, faces) = points(seed, g);
        let (m, pm) = local(m);
        let inside = s.plane(pm) >= s.bn;
        // All seven lines pass through `m`: their edge sides come from one
        // pivot cross, made for the first segment that crosses the plane.
        let mut w = None;
        let mut line = |a: P3, b: P3| {
            let d: P3 = std::array::from_fn(|c| b[c] - a[c]);
            s.line_hits(tri, w.get_or_insert_with(|| s.pivot_cross(pm)), d.map(T::from_i64), d)
        };
        let (c, pc) = local(g.map(|x| x * ONE + ONE / 2));
        if (s.plane(pc) >= s.bn) != inside && line(c, m) {
            return true;
        }
        faces.iter().any(|&f| {
            let (f, pf) = local(f);
            (s.plane(pf) >= s.bn) != inside && line(m, f)
        })
    };
    cover_triangle(tri, lo, hi, traversal, &mut FilterUnset { slab, keep });
}

/// The slow, obviously correct definition.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;

    /// Brute force over each triangle's bounding box.
    pub fn bubble(mesh: MeshRef<'_>, grid: &GridSpec, seed: u64) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, |t, ijk| hit(t, ijk, seed))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_strictly_inside_and_faces_are_shared() {
        for seed in [0, 1, 99] {
            for ijk in [[0, 0, 0], [5, -3, 7], [1000, 2000, 3000]] {
                let m = voxel_point(seed, ijk);
                assert!((0..3).all(|a| m[a] > ijk[a] * ONE && m[a] < (ijk[a] + 1) * ONE));
                let t = targets(seed, ijk);
                for axis in 0..3 {
                    let mut up = ijk;
                    up[axis] += 1;
                    // The high face of ijk is the low face of its neighbour.
                    assert_eq!(t[2 * axis + 1][1], targets(seed, up)[2 * axis][1]);
                    assert_eq!(t[2 * axis][1][axis], ijk[axis] * ONE);
                }
            }
        }
        assert_ne!(voxel_point(1, [0, 0, 0]), voxel_point(2, [0, 0, 0]));
    }

    #[test]
    fn shared_hash_rounds_give_the_same_points() {
        for seed in [0, 7, u64::MAX] {
            for ijk in [[0, 0, 0], [-1, 5, -9], [1 << 40, -(1 << 33), 77]] {
                assert_eq!(points(seed, ijk), (voxel_point(seed, ijk), face_points(seed, ijk)), "{seed} {ijk:?}");
            }
        }
    }
}
