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
//! voxels by their centres (what `topovox check` certifies), not only for a
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
//! set; each gets its seven segment tests: first every segment's plane
//! test (its ends' sides of the displaced plane), gathered into a mask
//! without a branch per segment, then the three edge orientations of
//! the segments that cross the plane. All
//! seven segments lie on lines through the voxel's random point `m`, so
//! these are dot products with one cross product per edge at `m`, exact
//! (`i64` relative to the triangle; nothing is set up per direction).
//! The points' plane values are the voxel corner's plus their offsets'.
//! For triangles in a box of at most 27 voxels (each voxel is then a
//! candidate of several triangles) the offsets come from a per-thread
//! cache of recent voxels instead of the hash (at 32³ on the bunny each
//! voxel is a candidate about fifteen times).
//!
//! **Reference:** [`reference::bubble`], the same targets for every voxel
//! of each triangle's bounding box.

use super::cover::cover_triangle;
use super::driver::{run_mesh, FilterUnset, Kernel};
use super::targets::is_tiny;
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::{segment_meets_triangle, P3};
use crate::geom::setup::{dot, fits_i64, TriSetup};
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

/// Voxel `ijk`'s random points as offsets from its low corner: its own
/// point's three, then each face's two inside the face (on axes
/// `axis + 1`, `axis + 2` mod 3; low and high face per axis). Each offset
/// is `1 ..= ONE − 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Offsets {
    /// The voxel's random point.
    pub m: [u16; 3],
    /// The faces' random points (low and high face per axis).
    pub faces: [[u16; 2]; 6],
}

/// [`voxel_point`] and [`face_points`] of voxel `ijk` as [`Offsets`], the
/// same values: the seven hashes share their first words (`i`, then `j`,
/// then `k`, each either the voxel's or one more), so 16 rounds make them
/// instead of 28.
#[inline]
pub fn offsets(seed: u64, ijk: [i64; 3]) -> Offsets {
    let [i, j, k] = ijk;
    let (a, b) = (round(start(seed), i), round(start(seed), i + 1));
    let (aa, ab, ba) = (round(a, j), round(a, j + 1), round(b, j));
    let (aaa, aab, aba, baa) = (round(aa, k), round(aa, k + 1), round(ab, k), round(ba, k));
    // Face hashes by face (low and high per axis), then the voxel's.
    let h = [round(aaa, 0), round(baa, 0), round(aaa, 1), round(aba, 1), round(aaa, 2), round(aab, 2), round(aaa, 3)];
    Offsets {
        m: std::array::from_fn(|a| offset(h[6], a as u32) as u16),
        faces: std::array::from_fn(|f| {
            let axis = f / 2;
            [offset(h[f], ((axis + 1) % 3) as u32) as u16, offset(h[f], ((axis + 2) % 3) as u32) as u16]
        }),
    }
}

impl Offsets {
    /// The lattice points these offsets place in voxel `ijk`: its random
    /// point and its six faces'.
    pub fn points(&self, ijk: [i64; 3]) -> (P3, [P3; 6]) {
        let corner = ijk.map(|c| c * ONE);
        let voxel = std::array::from_fn(|a| corner[a] + self.m[a] as i64);
        let faces = std::array::from_fn(|f| {
            let axis = f / 2;
            let mut p = corner;
            p[axis] += (f % 2) as i64 * ONE;
            p[(axis + 1) % 3] += self.faces[f][0] as i64;
            p[(axis + 2) % 3] += self.faces[f][1] as i64;
            p
        });
        (voxel, faces)
    }
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
    run_mesh(&BubbleKernel { seed, traversal: opts.traversal, offset: [0; 3], prefetch: wider_than_cache(grid.dims()) }, mesh, grid, opts)
}

/// The fast path on prepared triangles translated by `-offset` voxels (a
/// tile of a larger grid whose voxel `offset` is this grid's voxel 0): the
/// random points are drawn for the voxels' indices in the whole grid.
pub fn bubble_lattice(tris: &[LatticeTriangle], dims: [u32; 3], seed: u64, offset: [i64; 3], opts: &Options<'_>) -> BrickBits {
    super::driver::run_slabs(&BubbleKernel { seed, traversal: opts.traversal, offset, prefetch: wider_than_cache(dims) }, tris, dims, opts)
        .0
}

#[derive(Clone, Copy)]
struct BubbleKernel {
    seed: u64,
    traversal: Traversal,
    /// Index in the whole grid of this grid's voxel 0.
    offset: [i64; 3],
    /// Read a tiny triangle's cache slots at once before its tests
    /// ([`OffsetCache::prefetch`]).
    prefetch: bool,
}

/// Is a grid of `dims` wider than the [`OffsetCache`]'s block on some
/// axis? Then its voxels evict each other's slots, and a triangle's
/// slots are worth reading at once before its tests (bunny, 1 thread:
/// 128³ 4–7 % faster, 256³ unchanged). On a grid the block holds, the
/// slots of its surface stay in the CPU's cache, and reading them first
/// cost 32³ 4 %.
fn wider_than_cache(dims: [u32; 3]) -> bool {
    dims.iter().any(|&d| d > 1 << CACHE_BITS)
}

impl Kernel<LatticeTriangle> for BubbleKernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            filtered::<i64>(self, tri, lo, hi, slab);
        } else {
            filtered::<i128>(self, tri, lo, hi, slab);
        }
    }
}

/// Candidate voxels by the bits of their index that pick a cache slot:
/// the low 5 of each axis (a 32³ block of the grid, 32 768 slots, 1.8 MB
/// per thread: against a 16³ block, 128³ on the bunny −4 %, 32³ −3 %; a
/// 64³ block was slower at 256³).
const CACHE_BITS: u32 = 5;

/// The [`Offsets`] of recently tested voxels, one per slot of a 32³
/// block (direct-mapped by index). A voxel is a candidate of every
/// triangle near it that has not yet set it — at 128³ on the bunny about
/// three times, at 32³ about fifteen — and the mesh's triangles come in
/// an order that stays near one place, so most hashes are found here.
struct OffsetCache {
    /// The seed the slots were drawn with.
    seed: u64,
    /// Per slot: the voxel's index in the whole grid (`[i64::MIN; 3]`:
    /// none) and its offsets.
    slots: Vec<([i64; 3], Offsets)>,
}

/// The [`OffsetCache`] slot of voxel `g` (index in the whole grid): the
/// low [`CACHE_BITS`] of each axis.
#[inline(always)]
fn slot(g: [i64; 3]) -> usize {
    let mask = (1 << CACHE_BITS) - 1;
    ((g[0] & mask) | (g[1] & mask) << CACHE_BITS | (g[2] & mask) << (2 * CACHE_BITS)) as usize
}

impl OffsetCache {
    /// Empties the cache unless it holds offsets of `seed`.
    fn for_seed(&mut self, seed: u64) {
        if self.seed != seed || self.slots.is_empty() {
            let none = ([i64::MIN; 3], Offsets { m: [0; 3], faces: [[0; 2]; 6] });
            self.slots.clear();
            self.slots.resize(1 << (3 * CACHE_BITS), none);
            self.seed = seed;
        }
    }

    /// Reads the slots at the ends of each row of the voxels from `lo` to
    /// `hi` (inclusive; a tiny box's rows span a cache line or two), so
    /// that the CPU fetches them at once while the triangle is set up
    /// rather than one by one as the traversal comes to them.
    #[inline(always)]
    fn prefetch(&self, lo: [i64; 3], hi: [i64; 3]) {
        // Loads nothing waits on but their sum, which is kept.
        let mut x = 0;
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in [lo[0], hi[0]] {
                    x ^= self.slots[slot([i, j, k])].0[0];
                }
            }
        }
        std::hint::black_box(x);
    }

    /// The offsets of voxel `g` (index in the whole grid) for the seed of
    /// [`Self::for_seed`].
    #[inline(always)]
    fn get(&mut self, g: [i64; 3]) -> Offsets {
        let entry = &mut self.slots[slot(g)];
        if entry.0 != g {
            *entry = (g, offsets(self.seed, g));
        }
        entry.1
    }
}

thread_local! {
    /// Each worker thread's cache (the results do not depend on it).
    static CACHE: std::cell::RefCell<OffsetCache> = const { std::cell::RefCell::new(OffsetCache { seed: 0, slots: Vec::new() }) };
}

/// The definition over `cover`'s voxels, for one triangle: with the
/// thread's [`OffsetCache`] for a triangle whose box [`is_tiny`] (a voxel
/// is then a candidate of several triangles), else hashing each candidate
/// (at 512³ most voxels are a candidate of one or two triangles, and the
/// cache for every triangle measured 3–4 % slower there).
fn filtered<T: PlaneInt>(kernel: &BubbleKernel, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let BubbleKernel { seed, traversal, offset, prefetch } = *kernel;
    let s = TriSetup::<T>::new(tri);
    let steps = Steps::new(&s);
    let g = |i: i64, j: i64, k: i64| [i + offset[0], j + offset[1], k + offset[2]];
    if is_tiny(lo, hi) {
        CACHE.with(|cache| {
            let cache = &mut *cache.borrow_mut();
            cache.for_seed(seed);
            if prefetch {
                cache.prefetch(g(lo[0], lo[1], lo[2]), g(hi[0], hi[1], hi[2]));
            }
            let keep = |i, j, k| hits::<T, false>(&s, &steps, tri, [i, j, k], cache.get(g(i, j, k)));
            cover_triangle(tri, lo, hi, traversal, &mut FilterUnset { slab, keep });
        });
    } else {
        let keep = |i, j, k| hits::<T, true>(&s, &steps, tri, [i, j, k], offsets(seed, g(i, j, k)));
        cover_triangle(tri, lo, hi, traversal, &mut FilterUnset { slab, keep });
    }
}

/// How a triangle's plane value changes from a voxel's low corner: to the
/// opposite face along each axis, and to the voxel's centre.
struct Steps<T> {
    across: [T; 3],
    centre: T,
}

impl<T: PlaneInt> Steps<T> {
    fn new(s: &TriSetup<T>) -> Self {
        let n = s.n;
        Steps { across: n.map(|c| c * T::from_i64(ONE)), centre: (n[0] + n[1] + n[2]) * T::from_i64(ONE / 2) }
    }
}

/// Does the triangle of `s` meet a target of voxel `ijk` (of the
/// triangle's grid) whose random points are `o`? Each random target
/// first gets the plane test (its ends on both sides of the displaced
/// plane), then its line's edge sides from the voxel's random point's
/// [`PivotCross`] (the same decision as [`segment_meets_triangle`],
/// without its generic 128-bit determinants or a per-direction setup).
/// Plane values are the voxel's low corner's plus the points' offsets'.
/// `STOP_AT_HIT`: return at the first segment that meets the triangle
/// (large triangles, where most candidates are hit: at 1024³ on the bunny
/// about 6 % faster), else test every crossing segment with no branch on each
/// outcome (tiny triangles: 32³ 4 % faster).
#[inline(always)]
fn hits<T: PlaneInt, const STOP_AT_HIT: bool>(s: &TriSetup<T>, steps: &Steps<T>, tri: &LatticeTriangle, ijk: [i64; 3], o: Offsets) -> bool {
    let n = s.n;
    let pc = s.local(ijk.map(|c| c * ONE));
    let vc = s.plane(pc);
    let m = o.m.map(|x| T::from_i64(x as i64));
    let inside = vc + n[0] * m[0] + n[1] * m[1] + n[2] * m[2] >= s.bn;
    let mi = o.m.map(|x| x as i64);
    // Every segment's direction (from the centre to the random point,
    // then from the random point to each face's) and which of them cross
    // the displaced plane, as a mask: no branch per segment on its plane
    // test, whose outcome is a coin toss.
    let mut dirs = [mi.map(|x| x - ONE / 2); 7];
    let mut crossing = ((vc + steps.centre >= s.bn) != inside) as u32;
    for f in 0..6 {
        let (axis, high) = (f / 2, f % 2 == 1);
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        let [fb, fc] = o.faces[f].map(|x| x as i64);
        let v = vc + n[b] * T::from_i64(fb) + n[c] * T::from_i64(fc) + if high { steps.across[axis] } else { T::ZERO };
        crossing |= (((v >= s.bn) != inside) as u32) << (f + 1);
        let d = &mut dirs[f + 1];
        d[axis] = if high { ONE } else { 0 } - mi[axis];
        d[b] = fb - mi[b];
        d[c] = fc - mi[c];
    }
    if crossing == 0 {
        return false;
    }
    // All seven lines pass through the random point: their edge sides
    // come from its one pivot cross.
    let w = s.pivot_cross(std::array::from_fn(|a| pc[a] + m[a]));
    let mut any = false;
    while crossing != 0 {
        let d = dirs[crossing.trailing_zeros() as usize];
        crossing &= crossing - 1;
        let dt = d.map(T::from_i64);
        let o = w.map(|wi| dot(dt, wi));
        let hit = if (o[0] == T::ZERO) | (o[1] == T::ZERO) | (o[2] == T::ZERO) {
            // A tie (rare): the tie rule's bias decides.
            s.line_hits(tri, &w, dt, d)
        } else {
            let (a, b, c) = (o[0] > T::ZERO, o[1] > T::ZERO, o[2] > T::ZERO);
            (a == b) & (a == c)
        };
        if STOP_AT_HIT && hit {
            return true;
        }
        any |= hit;
    }
    any
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
    fn the_cache_gives_each_seeds_offsets() {
        let mut cache = OffsetCache { seed: 0, slots: Vec::new() };
        // Voxels 32 apart share a slot; a new seed empties the cache.
        let voxels = [[0, 0, 0], [32, 0, 0], [0, 0, 0], [-32, 64, 96], [3, 5, 7], [35, 5, 7], [3, 5, 7]];
        for seed in [0, 5, 5, 6, 0] {
            cache.for_seed(seed);
            for g in voxels {
                assert_eq!(cache.get(g), offsets(seed, g), "seed {seed}, voxel {g:?}");
            }
        }
    }

    #[test]
    fn shared_hash_rounds_give_the_same_points() {
        for seed in [0, 7, u64::MAX] {
            for ijk in [[0, 0, 0], [-1, 5, -9], [1 << 40, -(1 << 33), 77]] {
                assert_eq!(offsets(seed, ijk).points(ijk), (voxel_point(seed, ijk), face_points(seed, ijk)), "{seed} {ijk:?}");
            }
        }
    }
}
