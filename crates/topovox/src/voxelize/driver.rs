//! The parallel driver: bins lattice triangles into z-slabs and runs a
//! per-triangle kernel on each slab, one rayon task per slab.
//!
//! Parallelism is a driver, not a second algorithm: a [`Kernel`] is a pure
//! function of one triangle and the voxel box it may touch. Each slab owns
//! its brick-index entries of the [`BrickBits`] exclusively and allocates
//! bricks from its own pool; kernels only OR bits in. Pools are merged in
//! slab order, so the result is bit-identical for any thread count and slab
//! height.
//!
//! # Implementation notes
//!
//! Two parallel drivers for a per-triangle `Kernel`.
//! *Triangles* (grids up to 512³): the mesh's vertices are snapped once
//! (`SnappedMesh`), each thread takes a contiguous range of triangles,
//! prepares each as it reads it and runs the kernel over the whole grid into
//! its own bricks; the parts are merged by union in index order. *Slabs*
//! (larger grids): bins triangles into z-slabs of whole brick layers (in
//! parallel parts) and runs the kernel on each slab as one rayon task,
//! preparing each triangle from the snapped vertices as the slab reads it
//! (no list of prepared triangles is stored); each slab owns its
//! brick-index entries and fills its own brick pool; pools are merged in
//! slab order, renumbering only the entries each slab allocated. `cover`
//! and `sep26` collect a larger triangle's voxels in `BoxBricks` (its
//! box's bricks, on the stack; `driver::buffered`) and OR each into the
//! slab once. A `Sink` receives voxels; `Filter` puts a mode's exact
//! predicate in front of a slab (`FilterUnset` asks it only about voxels not
//! yet set; both hand it the voxel as three values, not an array). Both
//! drivers skip a kernel whose small box (up to 8 voxels) is already all
//! set, brick by brick with a bit mask: kernels only set voxels of their
//! box. At small grids the per-triangle path is short enough that a wide
//! load of an array just written by narrow stores (a store-forwarding
//! stall) shows in the profile; docs/bench-log/ lists the ones removed. In
//! the slab driver a kernel may put costly voxel tests off (`Deferred`,
//! `Kernel::run_deferring`/`finish`) until the slab's other triangles have
//! run, and then test only the voxels still unset: the union is the same.
//! `sep26` does so for voxels whose steepest diagonal misses; the triangle
//! driver takes none (its whole-grid lookups miss the cache).

use rayon::prelude::*;

use super::{Options, Report};
use crate::geom::lattice::{LatticeTriangle, PrepareStats, SnappedMesh};
use crate::grid::bricks::{block2_offset, BoxBricks, BrickBits, BrickSlab, BRICK};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// Which parallel driver runs a mode's fast path. Every choice gives the
/// same voxels; the choice exists so tests can pin each driver and
/// benchmarks can compare them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Driver {
    /// [`Driver::Triangles`] on grids of at most [`TRIANGLES_MAX_BRICKS`]
    /// bricks, [`Driver::Slabs`] on larger ones (default).
    #[default]
    Auto,
    /// Prepare every triangle, bin them into z-slabs, one task per slab
    /// ([`run_slabs`]).
    Slabs,
    /// Contiguous ranges of triangles in parallel, each prepared and
    /// voxelized as it is read into a whole-grid brick set of its own; the
    /// sets are merged by union ([`run_triangles`]). Chosen explicitly, it
    /// gives every thread a part however few triangles there are (so tests
    /// exercise the union on small meshes).
    Triangles,
}

/// Largest grid (in 8³ bricks: 2^18 is 512³ voxels) on which
/// [`Driver::Auto`] runs triangles in parallel. On such grids a per-thread
/// whole-grid brick index is small and its union costs little, and
/// skipping the stored triangle list and the slab binning is what makes
/// small grids fast; on larger ones slabs keep each thread's bricks in its
/// own cache.
pub const TRIANGLES_MAX_BRICKS: u64 = 1 << 18;

/// Runs `kernel` over the triangles of `mesh` on `grid` with the driver
/// `opts.driver` asks for.
pub fn run_mesh<K: Kernel<LatticeTriangle>>(kernel: &K, mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    let bricks: u64 = grid.dims().iter().map(|&d| d.div_ceil(BRICK) as u64).product();
    let triangles = match opts.driver {
        Driver::Auto => bricks <= TRIANGLES_MAX_BRICKS,
        Driver::Slabs => false,
        Driver::Triangles => true,
    };
    if triangles {
        run_triangles(kernel, mesh, grid, opts)
    } else {
        let items = Snapped { snapped: SnappedMesh::new(mesh, grid), tris: mesh.triangles };
        let (bits, voxels, prepare) = slabs_over(kernel, &items, grid.dims(), opts);
        (bits, Report { prepare, voxels })
    }
}

/// Fewest triangles worth a part of their own in [`run_triangles`].
const MIN_PART: usize = 8192;

/// The triangle-parallel driver: the mesh's vertices are snapped once,
/// then each of up to one part per thread takes a contiguous range of
/// triangles, prepares each as it reads it (exactly as [`prepare`](crate::geom::lattice::prepare) does)
/// and runs `kernel` on it over the whole grid, into a brick set of its
/// own. The parts are merged by [`BrickBits::union_canonical`], so the
/// result does not depend on the number of parts.
pub fn run_triangles<K: Kernel<LatticeTriangle>>(
    kernel: &K,
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    opts: &Options<'_>,
) -> (BrickBits, Report) {
    let snapped = SnappedMesh::new(mesh, grid);
    let dims = grid.dims();
    let n = mesh.triangles.len();
    let min_part = if opts.driver == Driver::Triangles { 1 } else { MIN_PART };
    let parts = rayon::current_num_threads().min(n.div_ceil(min_part)).max(1);
    if let Some(p) = opts.progress {
        p.set_total(parts as u64);
    }
    let done: Vec<(BrickBits, PrepareStats)> = (0..parts)
        .into_par_iter()
        .map(|part| {
            let mut bits = BrickBits::new(dims);
            let mut st = PrepareStats::default();
            let layers = bits.brick_dims()[2];
            let mut slabs = bits.slabs_mut(layers);
            let mut slab = slabs.pop().expect("one slab holds the whole grid");
            let mut deferred = Deferred::off();
            // In chunks, so a requested stop is seen within one chunk.
            for chunk in mesh.triangles[part * n / parts..(part + 1) * n / parts].chunks(STOP_CHUNK) {
                if opts.stopped() {
                    break;
                }
                for tri in chunk {
                    // Inlined: as a call (`triangle` calls it from two
                    // places), its first loads of `lo` and `hi` stalled on
                    // the stores just made (store forwarding).
                    snapped.triangle(
                        tri,
                        &mut st,
                        #[inline(always)]
                        |t, lo, hi| run_unless_full(kernel, t, lo, hi, &mut slab, &mut deferred),
                    );
                }
            }
            kernel.finish(&mut deferred, &mut slab);
            let pool = slab.into_pool();
            bits.merge_slabs(vec![pool]);
            if let Some(p) = opts.progress {
                p.advance(1);
            }
            (bits, st)
        })
        .collect();
    let prepare = done.iter().fold(PrepareStats::default(), |a, d| a.merge(d.1));
    let grids: Vec<BrickBits> = done.into_iter().map(|d| d.0).collect();
    let (bits, voxels) = BrickBits::union_canonical(&grids);
    (bits, Report { prepare, voxels })
}

/// Triangles the triangle-parallel driver runs between two looks at
/// [`Options::stop`].
const STOP_CHUNK: usize = 4096;

/// Voxels in the inclusive box `[lo, hi]` (not empty).
#[inline(always)]
pub(crate) fn box_volume(lo: [i64; 3], hi: [i64; 3]) -> i64 {
    (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1)
}

/// Largest voxel box checked for being already set before its primitive's
/// kernel runs.
const FULL_CHECK_MAX: i64 = 8;

/// Runs `kernel` on `prim` unless its (small) box is already all set: a
/// kernel only sets voxels of its box, so it could add nothing. At small
/// resolutions most triangles lie in a voxel or two that earlier triangles
/// have set, and the exact setup of the modes' targets is skipped for them.
/// A full [`Deferred`] has its tests run first.
#[inline(always)]
fn run_unless_full<P, K: Kernel<P>>(
    kernel: &K,
    prim: &P,
    lo: [i64; 3],
    hi: [i64; 3],
    slab: &mut BrickSlab<'_>,
    deferred: &mut Deferred<P>,
) {
    if box_volume(lo, hi) <= FULL_CHECK_MAX && slab.all_set(lo, hi) {
        return;
    }
    if deferred.is_full() {
        kernel.finish(deferred, slab);
    }
    kernel.run_deferring(prim, lo, hi, slab, deferred);
}

/// Smallest voxel box whose voxels [`buffered`] collects in a [`BoxBricks`]
/// (from 64: `cover` at 1024³ −2.5 %, `sep26` at 512³ +5 %).
const BUFFER_MIN_VOLUME: i64 = 256;

/// Runs `f` with a [`BoxBricks`] for the box `[lo, hi]` if it holds more
/// than [`BUFFER_MIN_VOLUME`] voxels in at most
/// [`BOX_BRICKS_MAX`](crate::grid::bricks::BOX_BRICKS_MAX) bricks,
/// then ORs the buffer into `slab`; otherwise with `None` (`f` sets voxels
/// in `slab` directly). `f` reads `slab` either way (already set voxels).
#[inline(always)]
pub(crate) fn buffered(lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>, f: impl FnOnce(&mut BrickSlab<'_>, Option<&mut BoxBricks>)) {
    let buf = if box_volume(lo, hi) > BUFFER_MIN_VOLUME { BoxBricks::new(lo, hi) } else { None };
    match buf {
        Some(mut b) => {
            f(slab, Some(&mut b));
            b.flush(slab);
        }
        None => f(slab, None),
    }
}

/// An input primitive on the lattice: it knows which voxels it may touch.
pub trait Primitive: Sync {
    /// The inclusive voxel index box whose closed voxels meet the
    /// primitive's bounding box, clamped to `dims`; `None` if empty.
    fn voxel_bounds(&self, dims: [u32; 3]) -> Option<([i64; 3], [i64; 3])>;
}

impl Primitive for LatticeTriangle {
    #[inline]
    fn voxel_bounds(&self, dims: [u32; 3]) -> Option<([i64; 3], [i64; 3])> {
        LatticeTriangle::voxel_bounds(self, dims)
    }
}

/// A per-primitive voxelization kernel.
pub trait Kernel<P>: Sync {
    /// Sets, in `slab`, the voxels of `prim` whose indices lie in the inclusive
    /// box `[lo, hi]` (already clamped to the grid and to the slab's layers).
    fn run(&self, prim: &P, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>);

    /// [`Self::run`], free to leave costly voxel tests in `deferred` for
    /// [`Self::finish`]; the drivers call this one. By default, `run`.
    #[inline(always)]
    fn run_deferring(&self, prim: &P, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>, deferred: &mut Deferred<P>) {
        let _ = deferred;
        self.run(prim, lo, hi, slab);
    }

    /// Runs the tests [`Self::run_deferring`] left in `deferred` (and
    /// empties it), once every primitive of the slab has run or when it
    /// is [full](Deferred::is_full). By default there are none.
    fn finish(&self, deferred: &mut Deferred<P>, slab: &mut BrickSlab<'_>) {
        let _ = (deferred, slab);
    }
}

/// Voxels whose exact test a kernel puts off ([`Kernel::run_deferring`])
/// until the other primitives of its slab have run: a voxel of the union
/// that one primitive's cheap tests miss is usually set by a neighbour's,
/// and [`Kernel::finish`] tests only those still unset. The union, and
/// so the result, is the same whenever the test runs. Grouped by
/// primitive. Only the slab driver takes them ([`Self::is_on`]): in
/// [`run_triangles`]' whole-grid bricks the later lookups miss the cache,
/// and `sep26` measured slower there (1024³ on the bunny, 1 thread: 120
/// → 127 ms, against 118 → 103 ms with slabs).
pub struct Deferred<P> {
    /// Per primitive: it and the end of its voxels in `voxels`.
    groups: Vec<(P, usize)>,
    voxels: Vec<[u32; 3]>,
    /// [`Self::is_full`] from this many voxels on.
    limit: usize,
    /// See [`Self::is_on`].
    on: bool,
}

/// Deferred voxels past which the driver has a slab's kept tests run
/// before its next primitive, unless [`Options::defer_limit`] says
/// otherwise (12 bytes each: 3 MB).
const DEFERRED_MAX: usize = 1 << 18;

impl<P> Deferred<P> {
    /// An empty list, [full](Self::is_full) from `limit` voxels on (`0`:
    /// 2^18).
    pub fn new(limit: usize) -> Self {
        Deferred { groups: Vec::new(), voxels: Vec::new(), limit: if limit == 0 { DEFERRED_MAX } else { limit }, on: true }
    }

    /// A list that takes nothing: kernels test every voxel at once.
    pub fn off() -> Self {
        Deferred { groups: Vec::new(), voxels: Vec::new(), limit: DEFERRED_MAX, on: false }
    }

    /// May kernels put tests off into this list?
    #[inline(always)]
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// Are there enough deferred voxels to run their tests now?
    #[inline(always)]
    pub fn is_full(&self) -> bool {
        self.voxels.len() >= self.limit
    }

    /// Takes every group, in order: the primitive and its voxels; leaves
    /// `self` empty.
    pub fn drain(&mut self, mut f: impl FnMut(&P, &[[u32; 3]])) {
        let mut start = 0;
        for (p, end) in &self.groups {
            f(p, &self.voxels[start..*end]);
            start = *end;
        }
        self.groups.clear();
        self.voxels.clear();
    }
}

impl<P: Clone> Deferred<P> {
    /// Where the voxels of the next primitive start ([`Self::close`]).
    #[inline(always)]
    pub fn mark(&self) -> usize {
        self.voxels.len()
    }

    /// Defers voxel `(i, j, k)`'s test.
    #[inline(always)]
    pub fn push(&mut self, i: u32, j: u32, k: u32) {
        self.voxels.push([i, j, k]);
    }

    /// Ends `prim`'s group, begun at `mark` (nothing if it deferred no
    /// voxel).
    #[inline(always)]
    pub fn close(&mut self, prim: &P, mark: usize) {
        if self.voxels.len() > mark {
            self.groups.push((prim.clone(), self.voxels.len()));
        }
    }
}

/// Where a traversal emits voxels: a slab, or a filter in front of one.
pub trait Sink {
    /// Emits voxel `(i, j, k)` (inside the grid).
    fn set(&mut self, i: u32, j: u32, k: u32);

    /// Emits the `len` voxels from `p` along `axis` (all inside the grid).
    #[inline(always)]
    fn set_run(&mut self, axis: usize, p: [u32; 3], len: u32) {
        let mut q = p;
        for _ in 0..len {
            self.set(q[0], q[1], q[2]);
            q[axis] += 1;
        }
    }

    /// Emits the voxels `p + (b % 4, b / 4 % 4, b / 16)` for each bit `b`
    /// of `mask` (`span4_voxel`), in order (all inside the grid and the
    /// slab; `p` itself need not be).
    #[inline(always)]
    fn set_span4(&mut self, p: [i64; 3], mut mask: u64) {
        while mask != 0 {
            let b = mask.trailing_zeros();
            mask &= mask - 1;
            let [i, j, k] = span4_voxel(p, b);
            self.set(i, j, k);
        }
    }

    /// Emits the voxels `p +` [`block2_offset`]`(o)` of the 2×2×2 block
    /// from `p` for each bit `o` of `mask`, in order (all inside the grid
    /// and the slab).
    #[inline(always)]
    fn set_block2(&mut self, p: [u32; 3], mut mask: u8) {
        while mask != 0 {
            let o = mask.trailing_zeros();
            mask &= mask - 1;
            let d = block2_offset(o);
            self.set(p[0] + d[0], p[1] + d[1], p[2] + d[2]);
        }
    }
}

/// Bit `b` of a [`Sink::set_span4`] mask is the voxel `(b % 4, b / 4 % 4,
/// b / 16)` from the span's first: these strides along each axis.
pub(crate) const SPAN4_STRIDE: [i64; 3] = [1, 4, 16];

/// The voxel offset `(b % 4, b / 4 % 4, b / 16)` of bit `b` of a
/// [`Sink::set_span4`] mask.
#[inline(always)]
pub(crate) fn span4_offset(b: u32) -> [i64; 3] {
    let b = b as i64;
    [b % 4, b / 4 % 4, b / 16]
}

/// The voxel of bit `b` of a [`Sink::set_span4`] mask whose span starts
/// at `p`.
#[inline(always)]
fn span4_voxel(p: [i64; 3], b: u32) -> [u32; 3] {
    let d = span4_offset(b);
    std::array::from_fn(|a| (p[a] + d[a]) as u32)
}

impl Sink for BrickSlab<'_> {
    #[inline(always)]
    fn set(&mut self, i: u32, j: u32, k: u32) {
        BrickSlab::set(self, i, j, k);
    }

    #[inline(always)]
    fn set_run(&mut self, axis: usize, p: [u32; 3], len: u32) {
        BrickSlab::set_run(self, axis, p[0], p[1], p[2], len);
    }
}

impl Sink for BoxBricks {
    #[inline(always)]
    fn set(&mut self, i: u32, j: u32, k: u32) {
        BoxBricks::set(self, i, j, k);
    }
}

impl Sink for crate::grid::dense::DenseBits {
    #[inline(always)]
    fn set(&mut self, i: u32, j: u32, k: u32) {
        crate::grid::dense::DenseBits::set(self, i, j, k);
    }
}

/// Passes on to `slab` only the voxels `keep` accepts: a mode whose voxels
/// are a subset of `cover` runs the `cover` traversal through one of these.
pub struct Filter<'s, 'b, F> {
    /// Destination.
    pub slab: &'s mut BrickSlab<'b>,
    /// The mode's exact per-voxel predicate.
    pub keep: F,
}

impl<F: FnMut(i64, i64, i64) -> bool> Sink for Filter<'_, '_, F> {
    #[inline(always)]
    fn set(&mut self, i: u32, j: u32, k: u32) {
        // Three values, not an array, as in `FilterUnset`.
        if (self.keep)(i as i64, j as i64, k as i64) {
            self.slab.set(i, j, k);
        }
    }
}

/// [`Filter`] for expensive predicates: asks `keep` only about voxels
/// not yet set (a triangle's neighbours have set most of its voxels).
pub struct FilterUnset<'s, 'b, F> {
    /// Destination.
    pub slab: &'s mut BrickSlab<'b>,
    /// The mode's exact per-voxel predicate.
    pub keep: F,
}

impl<F: FnMut(i64, i64, i64) -> bool> Sink for FilterUnset<'_, '_, F> {
    #[inline(always)]
    fn set(&mut self, i: u32, j: u32, k: u32) {
        // The voxel as three values, not an array: `keep` is called from
        // several places of the traversal and not inlined, and an array
        // argument went through memory, its first wide load waiting on
        // the stores just made (store forwarding).
        if !self.slab.get(i, j, k) && (self.keep)(i as i64, j as i64, k as i64) {
            self.slab.set(i, j, k);
        }
    }

    /// Which voxels are set, read into a mask first (no branch per voxel
    /// on it); `keep` is asked about the others, in order.
    #[inline(always)]
    fn set_span4(&mut self, p: [i64; 3], mask: u64) {
        let (mut rest, mut set) = (mask, 0u64);
        while rest != 0 {
            let b = rest.trailing_zeros();
            rest &= rest - 1;
            let [i, j, k] = span4_voxel(p, b);
            set |= (self.slab.get(i, j, k) as u64) << b;
        }
        let mut rest = mask & !set;
        while rest != 0 {
            let b = rest.trailing_zeros();
            rest &= rest - 1;
            let [i, j, k] = span4_voxel(p, b);
            if (self.keep)(i as i64, j as i64, k as i64) {
                self.slab.set(i, j, k);
            }
        }
    }

    /// The block's set voxels read at once ([`BrickSlab::block2_set`]),
    /// without a branch per voxel on whether it is set; `keep` is asked
    /// about the others, in order. (No voxel of the block is set between:
    /// each is asked once.)
    #[inline(always)]
    fn set_block2(&mut self, p: [u32; 3], mask: u8) {
        let mut mask = mask & !self.slab.block2_set(p[0], p[1], p[2]);
        while mask != 0 {
            let d = block2_offset(mask.trailing_zeros());
            mask &= mask - 1;
            let (i, j, k) = (p[0] + d[0], p[1] + d[1], p[2] + d[2]);
            if (self.keep)(i as i64, j as i64, k as i64) {
                self.slab.set(i, j, k);
            }
        }
    }
}

/// Fewest items in one part of the slab driver's parallel binning
/// ([`slabs_over`], which both `run_mesh` and [`run_slabs`] use).
const BIN_PART_MIN: usize = 4096;

/// Runs `kernel` over `tris` on a grid of `dims`, in parallel over z-slabs
/// (whole brick layers). Returns the grid and the number of voxels set
/// (counted by each slab's task while its bricks are still in cache).
pub fn run_slabs<P: Primitive, K: Kernel<P>>(kernel: &K, tris: &[P], dims: [u32; 3], opts: &Options<'_>) -> (BrickBits, u64) {
    let (bits, voxels, _) = slabs_over(kernel, &Prepared { prims: tris, dims }, dims, opts);
    (bits, voxels)
}

/// Where [`slabs_over`] takes its primitives from: item `idx` yields none,
/// one or (clipped) several, each with its voxel box clamped to the grid.
trait Items<P>: Sync {
    /// How many items there are.
    fn len(&self) -> usize;
    /// Calls `f(primitive, lo, hi)` for each primitive of item `idx`,
    /// counting the item in `st`.
    fn each(&self, idx: usize, st: &mut PrepareStats, f: impl FnMut(&P, [i64; 3], [i64; 3]));
}

/// Primitives already on the lattice.
struct Prepared<'a, P> {
    prims: &'a [P],
    dims: [u32; 3],
}

impl<P: Primitive> Items<P> for Prepared<'_, P> {
    fn len(&self) -> usize {
        self.prims.len()
    }

    #[inline(always)]
    fn each(&self, idx: usize, _: &mut PrepareStats, mut f: impl FnMut(&P, [i64; 3], [i64; 3])) {
        let p = &self.prims[idx];
        if let Some((lo, hi)) = p.voxel_bounds(self.dims) {
            f(p, lo, hi);
        }
    }
}

/// A mesh's triangles, prepared as they are read from its snapped
/// vertices (again in each slab a triangle reaches: cheaper than storing
/// every prepared triangle).
struct Snapped<'a> {
    snapped: SnappedMesh<'a>,
    tris: &'a [[u32; 3]],
}

impl Items<LatticeTriangle> for Snapped<'_> {
    fn len(&self) -> usize {
        self.tris.len()
    }

    #[inline(always)]
    fn each(&self, idx: usize, st: &mut PrepareStats, f: impl FnMut(&LatticeTriangle, [i64; 3], [i64; 3])) {
        self.snapped.triangle(&self.tris[idx], st, f);
    }
}

/// The slab driver over `items`; also returns the items' preparation
/// counts (each item counted once, when it is binned).
fn slabs_over<P, K: Kernel<P>, I: Items<P>>(kernel: &K, items: &I, dims: [u32; 3], opts: &Options<'_>) -> (BrickBits, u64, PrepareStats) {
    let mut grid = BrickBits::new(dims);
    let nz = dims[2];
    let height = if opts.slab_height > 0 {
        opts.slab_height.div_ceil(BRICK) * BRICK
    } else {
        // About eight slabs per thread: enough to balance, few enough that
        // few triangles straddle two (at 1024³ on 2 threads, 16 per thread
        // measured 7 % slower).
        let threads = rayon::current_num_threads() as u32;
        ((nz / (8 * threads)).clamp(BRICK, 64) / BRICK) * BRICK
    };
    let nslabs = nz.div_ceil(height) as usize;
    // Bins per contiguous part of the items, built in parallel; a slab
    // reads its bin of every part in order. Boxes are recomputed in the
    // slab rather than stored for every primitive.
    let n = items.len();
    let part = n.div_ceil(rayon::current_num_threads() * 4).max(BIN_PART_MIN);
    let binned: Vec<(Vec<Vec<u32>>, PrepareStats)> = (0..n.div_ceil(part))
        .into_par_iter()
        .map(|c| {
            let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nslabs];
            let mut st = PrepareStats::default();
            for idx in c * part..((c + 1) * part).min(n) {
                let (mut zlo, mut zhi) = (i64::MAX, i64::MIN);
                items.each(idx, &mut st, |_, lo, hi| {
                    zlo = zlo.min(lo[2]);
                    zhi = zhi.max(hi[2]);
                });
                if zlo <= zhi {
                    for s in (zlo as u32 / height)..=(zhi as u32 / height) {
                        bins[s as usize].push(idx as u32);
                    }
                }
            }
            (bins, st)
        })
        .collect();
    let prepare = binned.iter().fold(PrepareStats::default(), |a, b| a.merge(b.1));
    if let Some(p) = opts.progress {
        p.set_total(nslabs as u64);
    }
    let slabs = grid.slabs_mut(height / BRICK);
    let done: Vec<(crate::grid::bricks::SlabPool, u64)> = slabs
        .into_par_iter()
        .enumerate()
        // One deferral list for the slabs a task takes in turn: grown
        // once, not per slab.
        .map_init(
            || Deferred::new(opts.defer_limit),
            |deferred, (s, mut slab)| {
                let mut st = PrepareStats::default();
                let work = if opts.stopped() { &[][..] } else { &binned[..] };
                for &idx in work.iter().flat_map(|b| &b.0[s]) {
                    items.each(idx as usize, &mut st, |p, mut lo, mut hi| {
                        lo[2] = lo[2].max(slab.k0 as i64);
                        hi[2] = hi[2].min(slab.k1 as i64 - 1);
                        if lo[2] <= hi[2] {
                            run_unless_full(kernel, p, lo, hi, &mut slab, deferred);
                        }
                    });
                }
                kernel.finish(deferred, &mut slab);
                if let Some(p) = opts.progress {
                    p.advance(1);
                }
                let n = slab.count();
                (slab.into_pool(), n)
            },
        )
        .collect();
    let count = done.iter().map(|d| d.1).sum();
    grid.merge_slabs(done.into_iter().map(|d| d.0).collect());
    (grid, count, prepare)
}
