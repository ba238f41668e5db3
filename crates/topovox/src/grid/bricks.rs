//! Sparse voxel storage: 8×8×8 bricks allocated on demand.
//!
//! A brick is 512 bits — one 64-byte cache line — so the voxels a small
//! triangle sets fall in a handful of cache lines, and memory is only
//! allocated where the surface is. At 1024³ the bunny's surface touches
//! about 6 MB of bricks where a dense grid needs 103 MB of freshly faulted
//! pages, which is most of the cost of a dense result.

use rayon::prelude::*;

pub use super::brick::{set_in_brick, Brick, BRICK};
use super::dense::DenseBits;
use super::VoxelSource;

const SHIFT: u32 = 3;

/// Smallest brick index [`BrickBits::new`] zeroes in parallel.
const PAR_ZERO_MIN: usize = 1 << 20;

/// The offset `(di, dj, dk)` from a 2×2×2 block's first voxel of bit `o`
/// (`di + 2·dj + 4·dk`) of a block mask ([`SlabView::block2_set`]).
#[inline(always)]
pub fn block2_offset(o: u32) -> [u32; 3] {
    [o & 1, o >> 1 & 1, o >> 2]
}

/// A sparse grid of bits in 8×8×8 bricks.
///
/// # Guarantees
/// Every allocated brick is referenced by exactly one index entry; bits of
/// a brick outside `dims` (in the last, partial bricks) are never set.
/// Brick order depends only on the input, never on the thread count.
#[derive(Clone)]
pub struct BrickBits {
    dims: [u32; 3],
    bdims: [u32; 3],
    /// `0` = empty, else `1 + brick id`; layout `(bk * by + bj) * bx + bi`.
    index: Vec<u32>,
    bricks: Vec<Brick>,
}

impl std::fmt::Debug for BrickBits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "BrickBits {{ dims: {:?}, bricks: {}, set: {} }}", self.dims, self.bricks.len(), self.count())
    }
}

impl BrickBits {
    /// An empty grid.
    pub fn new(dims: [u32; 3]) -> BrickBits {
        let bdims = dims.map(|d| d.div_ceil(BRICK));
        let n = bdims.iter().map(|&b| b as usize).product();
        // A large index is zeroed by every thread, not by one (`calloc`
        // clears memory the allocator reuses serially: 4 ms at 1024³).
        let index = if n >= PAR_ZERO_MIN { (0..n).into_par_iter().map(|_| 0).collect() } else { vec![0; n] };
        BrickBits { dims, bdims, index, bricks: Vec::new() }
    }

    /// Voxels along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Allocated bricks.
    pub fn brick_count(&self) -> usize {
        self.bricks.len()
    }

    /// Bytes used by the index and the bricks.
    pub fn memory_bytes(&self) -> usize {
        self.index.len() * 4 + self.bricks.len() * 64
    }

    #[inline]
    fn brick_of(&self, i: u32, j: u32, k: u32) -> Option<&Brick> {
        let b = ((k >> SHIFT) as usize * self.bdims[1] as usize + (j >> SHIFT) as usize) * self.bdims[0] as usize + (i >> SHIFT) as usize;
        match self.index[b] {
            0 => None,
            id => Some(&self.bricks[id as usize - 1]),
        }
    }

    /// Whether voxel `(i,j,k)` is set. Panics if out of range.
    pub fn get(&self, i: u32, j: u32, k: u32) -> bool {
        assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2], "voxel out of range");
        self.brick_of(i, j, k).is_some_and(|b| (b[(k & 7) as usize] >> (((j & 7) << 3) | (i & 7))) & 1 == 1)
    }

    /// Sets voxel `(i,j,k)`. Panics if out of range.
    pub fn set(&mut self, i: u32, j: u32, k: u32) {
        assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2], "voxel out of range");
        let b = ((k >> SHIFT) as usize * self.bdims[1] as usize + (j >> SHIFT) as usize) * self.bdims[0] as usize + (i >> SHIFT) as usize;
        if self.index[b] == 0 {
            self.bricks.push([0; 8]);
            self.index[b] = self.bricks.len() as u32;
        }
        let id = self.index[b] as usize - 1;
        set_in_brick(&mut self.bricks[id], i, j, k);
    }

    /// ORs `bits` into brick `(bi, bj, bk)`. Panics if the brick is out of
    /// range; bits outside the grid must be clear.
    pub fn insert_brick(&mut self, b: [u32; 3], bits: Brick) {
        assert!((0..3).all(|a| b[a] < self.bdims[a]), "brick out of range");
        let n = (b[2] as usize * self.bdims[1] as usize + b[1] as usize) * self.bdims[0] as usize + b[0] as usize;
        if self.index[n] == 0 {
            self.bricks.push([0; 8]);
            self.index[n] = self.bricks.len() as u32;
        }
        let slot = &mut self.bricks[self.index[n] as usize - 1];
        for (w, x) in slot.iter_mut().zip(bits) {
            *w |= x;
        }
    }

    /// The brick index (`0` empty, else `1 +` position in the second
    /// slice; layout `(bk * by + bj) * bx + bi`) and the bricks.
    pub fn raw(&self) -> (&[u32], &[Brick]) {
        (&self.index, &self.bricks)
    }

    /// Bricks along x, y, z.
    pub fn brick_dims(&self) -> [u32; 3] {
        self.bdims
    }

    /// Brick `(bi, bj, bk)` (word `z & 7`, bit `(y & 7) * 8 + (x & 7)`), or
    /// `None` where no voxel of it is set.
    #[inline]
    pub fn brick(&self, bi: u32, bj: u32, bk: u32) -> Option<&Brick> {
        match self.index[((bk * self.bdims[1] + bj) * self.bdims[0] + bi) as usize] {
            0 => None,
            id => Some(&self.bricks[id as usize - 1]),
        }
    }

    /// The same voxels as any voxel source, in bricks.
    pub fn from_source(src: &dyn VoxelSource) -> BrickBits {
        let mut b = BrickBits::new(src.dims());
        src.for_each_set(&mut |i, j, k| b.set(i, j, k));
        b
    }

    /// Number of set voxels.
    pub fn count(&self) -> u64 {
        self.bricks.par_chunks(1 << 13).map(|c| super::count_bits(c.iter().flatten())).sum()
    }

    /// The same voxels in dense storage.
    pub fn to_dense(&self) -> DenseBits {
        let mut d = DenseBits::new(self.dims);
        let [bx, by, _] = self.bdims;
        for (b, &id) in self.index.iter().enumerate() {
            if id == 0 {
                continue;
            }
            let brick = &self.bricks[id as usize - 1];
            let (bi, bj, bk) = (b as u32 % bx, (b as u32 / bx) % by, b as u32 / (bx * by));
            for (z, &w) in brick.iter().enumerate() {
                for y in 0..8u32 {
                    let byte = ((w >> (y * 8)) & 0xff) as u8;
                    if byte != 0 {
                        d.or_byte(bi * 8, bj * 8 + y, bk * 8 + z as u32, byte);
                    }
                }
            }
        }
        d
    }

    /// Splits the grid into slabs of `height_bricks` brick layers, each
    /// owning its index entries and a fresh brick pool. Hand the filled
    /// slabs back to [`BrickBits::merge_slabs`].
    pub fn slabs_mut(&mut self, height_bricks: u32) -> Vec<BrickSlab<'_>> {
        let h = height_bricks.max(1);
        let layer = self.bdims[0] as usize * self.bdims[1] as usize;
        let (bx, by, nz) = (self.bdims[0], self.bdims[1], self.dims[2]);
        if layer == 0 {
            return Vec::new();
        }
        self.index
            .chunks_mut(layer * h as usize)
            .enumerate()
            .map(|(n, index)| {
                let bk0 = n as u32 * h;
                let k0 = bk0 * BRICK;
                SlabView {
                    k0,
                    k1: ((bk0 + h) * BRICK).min(nz),
                    bk0,
                    bx,
                    by,
                    index,
                    pool: Vec::new(),
                    entries: Vec::new(),
                    last: (u64::MAX, 0),
                }
            })
            .collect()
    }

    /// Gathers the slabs' brick pools into the grid, in slab order, and
    /// renumbers their index entries: only the entries each pool lists,
    /// not the whole index (most of which no slab touched).
    pub fn merge_slabs(&mut self, pools: Vec<SlabPool>) {
        let mut offsets = Vec::with_capacity(pools.len());
        let mut total = self.bricks.len();
        for p in &pools {
            offsets.push(total as u32);
            total += p.bricks.len();
        }
        // Each slab numbered its bricks from 1; shift them past earlier slabs.
        let mut rest: &mut [u32] = &mut self.index;
        let mut parts = Vec::with_capacity(pools.len());
        for p in &pools {
            let all = std::mem::take(&mut rest);
            let (idx, tail) = all.split_at_mut(p.index_len.min(all.len()));
            parts.push(idx);
            rest = tail;
        }
        parts.into_par_iter().zip(pools.par_iter()).zip(offsets.par_iter()).for_each(|((idx, p), &off)| {
            for (n, &e) in p.entries.iter().enumerate() {
                idx[e as usize] = off + n as u32 + 1;
            }
        });
        self.bricks.reserve(total - self.bricks.len());
        for p in pools {
            self.bricks.extend(p.bricks);
        }
    }

    /// The union of grids of the same dims, with bricks numbered in index
    /// order, so the result does not depend on how the voxels were split
    /// among `parts` (the triangle-parallel driver's merge). Returns the
    /// grid and its voxel count. Panics if `parts` is empty or dims differ.
    pub fn union_canonical(parts: &[BrickBits]) -> (BrickBits, u64) {
        let dims = parts[0].dims;
        assert!(parts.iter().all(|p| p.dims == dims), "union of grids of different dims");
        let mut out = BrickBits::new(dims);
        let chunk = 1 << 14;
        let pools: Vec<(SlabPool, u64)> = out
            .index
            .par_chunks_mut(chunk)
            .enumerate()
            .map(|(c, idx)| {
                let base = c * chunk;
                let mut pool = Vec::new();
                let mut entries = Vec::new();
                let mut count = 0;
                for (e, slot) in idx.iter_mut().enumerate() {
                    let mut b: Brick = [0; 8];
                    let mut any = false;
                    for p in parts {
                        let id = p.index[base + e];
                        if id != 0 {
                            any = true;
                            for (w, x) in b.iter_mut().zip(&p.bricks[id as usize - 1]) {
                                *w |= x;
                            }
                        }
                    }
                    if any {
                        count += super::count_bits(b.iter());
                        pool.push(b);
                        entries.push(e as u32);
                        *slot = pool.len() as u32;
                    }
                }
                (SlabPool { index_len: idx.len(), bricks: pool, entries }, count)
            })
            .collect();
        let count = pools.iter().map(|p| p.1).sum();
        out.merge_slabs(pools.into_iter().map(|p| p.0).collect());
        (out, count)
    }

    /// The set voxels in order of `k`, then `j`, then `i`.
    pub fn for_each_set(&self, mut f: impl FnMut(u32, u32, u32)) {
        let [bx, by, bz] = self.bdims;
        // Per layer of bricks, the non-empty bricks of each brick row
        // (`rows[r]`: brick row `bj` and its `(bi, id)` in `occupied`), so
        // each of the layer's 64 voxel rows visits only those.
        let mut occupied: Vec<(u32, u32)> = Vec::new();
        let mut rows: Vec<(u32, std::ops::Range<usize>)> = Vec::new();
        for bk in 0..bz {
            occupied.clear();
            rows.clear();
            for bj in 0..by {
                let row = ((bk * by + bj) * bx) as usize;
                let start = occupied.len();
                for (bi, &id) in self.index[row..row + bx as usize].iter().enumerate() {
                    if id != 0 {
                        occupied.push((bi as u32, id));
                    }
                }
                if occupied.len() > start {
                    rows.push((bj, start..occupied.len()));
                }
            }
            for z in 0..8u32 {
                let k = bk * 8 + z;
                if k >= self.dims[2] {
                    break;
                }
                for (bj, range) in &rows {
                    for y in 0..8u32 {
                        let j = bj * 8 + y;
                        if j >= self.dims[1] {
                            break;
                        }
                        for &(bi, id) in &occupied[range.clone()] {
                            let mut byte = (self.bricks[id as usize - 1][z as usize] >> (y * 8)) & 0xff;
                            while byte != 0 {
                                let x = byte.trailing_zeros();
                                byte &= byte - 1;
                                f(bi * 8 + x, j, k);
                            }
                        }
                    }
                }
            }
        }
    }
}

impl VoxelSource for BrickBits {
    fn dims(&self) -> [u32; 3] {
        self.dims
    }

    fn count(&self) -> u64 {
        BrickBits::count(self)
    }

    fn for_each_set(&self, f: &mut dyn FnMut(u32, u32, u32)) {
        BrickBits::for_each_set(self, f)
    }

    fn for_each_brick(&self, f: &mut dyn FnMut([u32; 3], &Brick)) {
        let [bx, by, _] = self.bdims;
        for (n, &id) in self.index.iter().enumerate() {
            if id != 0 {
                let n = n as u32;
                f([n % bx, (n / bx) % by, n / (bx * by)], &self.bricks[id as usize - 1]);
            }
        }
    }

    fn fill_i_planes(&self, i0: u32, count: u32, k_fastest: bool, out: &mut [u8]) {
        let (ny, nz) = (self.dims[1] as usize, self.dims[2] as usize);
        let plane = ny * nz;
        assert!(count > 0 && i0 + count <= self.dims[0] && out.len() >= plane * count as usize);
        out[..plane * count as usize].fill(0);
        let [bx, by, bz] = self.bdims;
        let (b0, b1) = (i0 / 8, (i0 + count - 1) / 8);
        for bk in 0..bz {
            for bj in 0..by {
                for bi in b0..=b1.min(bx - 1) {
                    let id = self.index[((bk * by + bj) * bx + bi) as usize];
                    if id == 0 {
                        continue;
                    }
                    brick_to_planes([bi, bj, bk], &self.bricks[id as usize - 1], i0, count, k_fastest, [ny, nz], out);
                }
            }
        }
    }
}

/// Sets in `out` (laid out as [`VoxelSource::fill_i_planes`] says, for a
/// grid of `ny × nz` planes) the voxels of brick `b` in planes `i0 ..
/// i0 + count`.
pub(crate) fn brick_to_planes(b: [u32; 3], brick: &Brick, i0: u32, count: u32, k_fastest: bool, [ny, nz]: [usize; 2], out: &mut [u8]) {
    let plane = ny * nz;
    for (z, &w) in brick.iter().enumerate() {
        let mut w = w;
        while w != 0 {
            let bit = w.trailing_zeros();
            w &= w - 1;
            let (i, j, k) = (b[0] * 8 + (bit & 7), b[1] * 8 + (bit >> 3), b[2] * 8 + z as u32);
            if i < i0 || i >= i0 + count {
                continue;
            }
            let pos = if k_fastest { j as usize * nz + k as usize } else { k as usize * ny + j as usize };
            out[(i - i0) as usize * plane + pos] = 1;
        }
    }
}

/// A mutable view of the brick layers of one slab, with its own pool.
pub struct SlabView<'a> {
    /// First voxel layer of the slab.
    pub k0: u32,
    /// One past its last voxel layer.
    pub k1: u32,
    bk0: u32,
    bx: u32,
    by: u32,
    index: &'a mut [u32],
    pool: Vec<Brick>,
    /// The index entry (in `index`) of each brick of `pool`, in order.
    entries: Vec<u32>,
    /// The brick coordinates (packed by [`brick_key`]) and pool slot of
    /// the last voxel set: consecutive voxels mostly share a brick, and the
    /// key costs shifts where the index entry costs multiplications.
    last: (u64, usize),
}

/// The brick coordinates of voxel `(i, j, k)` packed into one word
/// (`i >> 3` in bits 0–20, `j >> 3` in 21–41, `k >> 3` in 42–62).
#[inline(always)]
fn brick_key(i: u32, j: u32, k: u32) -> u64 {
    (i >> SHIFT) as u64 | ((j >> SHIFT) as u64) << 21 | ((k >> SHIFT) as u64) << 42
}

/// The slab type handed to kernels.
pub type BrickSlab<'a> = SlabView<'a>;

impl SlabView<'_> {
    /// Sets voxel `(i, j, k)`; `k` must lie in `[k0, k1)`, `i`, `j` in range.
    #[inline(always)]
    pub fn set(&mut self, i: u32, j: u32, k: u32) {
        debug_assert!(k >= self.k0 && k < self.k1);
        let slot = self.slot(i, j, k);
        set_in_brick(&mut self.pool[slot], i, j, k);
    }

    /// Sets the `len` voxels from `(i, j, k)` along `axis` (0, 1 or 2), all
    /// inside the slab and the grid: one brick lookup and one `OR` per
    /// brick the run touches (per brick word along z).
    #[inline(always)]
    pub fn set_run(&mut self, axis: usize, i: u32, j: u32, k: u32, len: u32) {
        let mut p = [i, j, k];
        let end = p[axis] + len;
        while p[axis] < end {
            let at = p[axis] & 7;
            let n = (8 - at).min(end - p[axis]);
            let slot = self.slot(p[0], p[1], p[2]);
            let ones = (1u64 << n) - 1;
            let brick = &mut self.pool[slot];
            match axis {
                0 => brick[(p[2] & 7) as usize] |= ones << (((p[1] & 7) << 3) | at),
                1 => {
                    // One bit per byte: bytes at..at+n of the word, column x & 7.
                    let bytes = 0x0101_0101_0101_0101u64 >> ((8 - n) << 3);
                    brick[(p[2] & 7) as usize] |= (bytes << (at << 3)) << (p[0] & 7);
                }
                _ => {
                    let bit = 1u64 << (((p[1] & 7) << 3) | (p[0] & 7));
                    for z in at..at + n {
                        brick[z as usize] |= bit;
                    }
                }
            }
            p[axis] += n;
        }
    }

    /// Is voxel `(i, j, k)` set (by this slab)? Allocates nothing.
    #[inline(always)]
    pub fn get(&self, i: u32, j: u32, k: u32) -> bool {
        debug_assert!(k >= self.k0 && k < self.k1);
        let key = brick_key(i, j, k);
        let slot = if self.last.0 == key {
            self.last.1
        } else {
            match self.index[self.entry(i, j, k)] {
                0 => return false,
                id => id as usize - 1,
            }
        };
        self.pool[slot][(k & 7) as usize] >> (((j & 7) << 3) | (i & 7)) & 1 == 1
    }

    /// Which voxels of the 2×2×2 block from `(i, j, k)` are set (by this
    /// slab): bit `di + 2·dj + 4·dk` for voxel `(i + di, j + dj, k + dk)`
    /// ([`block2_offset`]).
    /// The block must lie in the slab's layers and the grid. One brick
    /// lookup when the block lies in one brick (seven in eight blocks
    /// along each axis), else one per voxel.
    #[inline(always)]
    pub fn block2_set(&self, i: u32, j: u32, k: u32) -> u8 {
        if (i & 7) == 7 || (j & 7) == 7 || (k & 7) == 7 {
            return (0..8).fold(0, |m, o| {
                let [di, dj, dk] = block2_offset(o);
                m | (self.get(i + di, j + dj, k + dk) as u8) << o
            });
        }
        let key = brick_key(i, j, k);
        let slot = if self.last.0 == key {
            self.last.1
        } else {
            match self.index[self.entry(i, j, k)] {
                0 => return 0,
                id => id as usize - 1,
            }
        };
        let brick = &self.pool[slot];
        let shift = ((j & 7) << 3) | (i & 7);
        // Per layer: bits (0, 0), (1, 0), (0, 1), (1, 1) of the block's
        // column pairs, from bits 0, 1, 8, 9 of the shifted word.
        let layer = |w: u64| {
            let w = w >> shift;
            (w & 3 | (w >> 6) & 0xc) as u8
        };
        layer(brick[(k & 7) as usize]) | layer(brick[(k & 7) as usize + 1]) << 4
    }

    /// Are all voxels of the inclusive box `[lo, hi]` set (by this slab)?
    /// A box inside one brick (a small triangle's, mostly) is one brick
    /// lookup and a masked compare per brick word.
    #[inline(always)]
    pub fn all_set(&self, lo: [i64; 3], hi: [i64; 3]) -> bool {
        let (l0, l1, l2) = (lo[0] as u32, lo[1] as u32, lo[2] as u32);
        let (h0, h1, h2) = (hi[0] as u32, hi[1] as u32, hi[2] as u32);
        if (l0 ^ h0) | (l1 ^ h1) | (l2 ^ h2) >= BRICK {
            return self.all_set_across([l0, l1, l2], [h0, h1, h2]);
        }
        self.all_set_in_brick([l0, l1, l2], [h0, h1, h2])
    }

    /// [`Self::all_set`] for a box inside one brick.
    #[inline(always)]
    fn all_set_in_brick(&self, [l0, l1, l2]: [u32; 3], [h0, h1, h2]: [u32; 3]) -> bool {
        let key = brick_key(l0, l1, l2);
        let slot = if self.last.0 == key {
            self.last.1
        } else {
            match self.index[self.entry(l0, l1, l2)] {
                0 => return false,
                id => id as usize - 1,
            }
        };
        // The box's x range in one row of the brick, repeated over its y rows.
        let row = ((2u64 << (h0 - l0)) - 1) << (l0 & 7);
        let rows = (0x0101_0101_0101_0101u64 >> ((7 - (h1 - l1)) << 3)) << ((l1 & 7) << 3);
        let mask = row * rows;
        let brick = &self.pool[slot];
        let mut all = true;
        for k in l2 & 7..=h2 & 7 {
            all &= brick[k as usize] & mask == mask;
        }
        all
    }

    /// [`Self::all_set`] for a box across brick borders: the box cut by
    /// the brick borders, each part by [`Self::all_set_in_brick`].
    #[inline(never)]
    fn all_set_across(&self, lo: [u32; 3], hi: [u32; 3]) -> bool {
        // Each part runs from its first voxel to the end of that voxel's
        // brick, clamped to `hi`.
        let end = |c: u32, h: u32| (c | (BRICK - 1)).min(h);
        let mut k = lo[2];
        while k <= hi[2] {
            let k1 = end(k, hi[2]);
            let mut j = lo[1];
            while j <= hi[1] {
                let j1 = end(j, hi[1]);
                let mut i = lo[0];
                while i <= hi[0] {
                    let i1 = end(i, hi[0]);
                    if !self.all_set_in_brick([i, j, k], [i1, j1, k1]) {
                        return false;
                    }
                    i = i1 + 1;
                }
                j = j1 + 1;
            }
            k = k1 + 1;
        }
        true
    }

    /// The pool slot of the brick holding voxel `(i, j, k)`, allocating it
    /// if needed.
    #[inline(always)]
    fn slot(&mut self, i: u32, j: u32, k: u32) -> usize {
        let key = brick_key(i, j, k);
        if self.last.0 == key {
            return self.last.1;
        }
        self.slot_miss(i, j, k, key)
    }

    /// The slab's brick-index entry of the brick holding voxel `(i, j, k)`.
    #[inline(always)]
    fn entry(&self, i: u32, j: u32, k: u32) -> usize {
        (((k >> SHIFT) - self.bk0) as usize * self.by as usize + (j >> SHIFT) as usize) * self.bx as usize + (i >> SHIFT) as usize
    }

    #[inline(never)]
    fn slot_miss(&mut self, i: u32, j: u32, k: u32, key: u64) -> usize {
        let b = self.entry(i, j, k);
        let mut id = self.index[b];
        if id == 0 {
            self.pool.push([0; 8]);
            self.entries.push(b as u32);
            id = self.pool.len() as u32;
            self.index[b] = id;
        }
        self.last = (key, id as usize - 1);
        id as usize - 1
    }

    /// Set voxels in this slab.
    pub fn count(&self) -> u64 {
        super::count_bits(self.pool.iter().flatten())
    }

    /// Index entries this slab owns and its pool, for [`BrickBits::merge_slabs`].
    pub fn into_pool(self) -> SlabPool {
        SlabPool { index_len: self.index.len(), bricks: self.pool, entries: self.entries }
    }
}

/// A filled slab's bricks, for [`BrickBits::merge_slabs`].
pub struct SlabPool {
    /// How many index entries the slab owned.
    index_len: usize,
    /// Its bricks, numbered from 1 in its index entries.
    bricks: Vec<Brick>,
    /// The index entry (relative to the slab's first) of each brick.
    entries: Vec<u32>,
}

/// Most bricks a [`BoxBricks`] holds.
pub const BOX_BRICKS_MAX: usize = 12;

/// The bricks of one primitive's voxel box, on the stack: a kernel sets
/// voxels here with plain index arithmetic (no brick lookup and no branch
/// on which brick a voxel falls in), and [`BoxBricks::flush`] ORs each
/// brick that got a voxel into the slab with one lookup.
pub struct BoxBricks {
    /// Brick coordinates of the box's low corner.
    b0: [u32; 3],
    /// Bricks along x, and in one xy layer.
    nx: u32,
    nxy: u32,
    len: usize,
    bricks: [Brick; BOX_BRICKS_MAX],
}

impl BoxBricks {
    /// A buffer for the inclusive voxel box `[lo, hi]`, or `None` if it
    /// touches more than [`BOX_BRICKS_MAX`] bricks.
    #[inline(always)]
    pub fn new(lo: [i64; 3], hi: [i64; 3]) -> Option<BoxBricks> {
        let b0 = lo.map(|c| (c as u32) >> SHIFT);
        let n: [u32; 3] = std::array::from_fn(|a| ((hi[a] as u32) >> SHIFT) - b0[a] + 1);
        // In u128 (three factors below 2^29): a huge box's brick count
        // must not wrap to a small one.
        let len = n.iter().map(|&c| c as u128).product::<u128>();
        (len <= BOX_BRICKS_MAX as u128).then(|| BoxBricks {
            b0,
            nx: n[0],
            nxy: n[0] * n[1],
            len: len as usize,
            bricks: [[0; 8]; BOX_BRICKS_MAX],
        })
    }

    /// Sets voxel `(i, j, k)`, which must lie in the box.
    #[inline(always)]
    pub fn set(&mut self, i: u32, j: u32, k: u32) {
        let b = ((k >> SHIFT) - self.b0[2]) * self.nxy + ((j >> SHIFT) - self.b0[1]) * self.nx + ((i >> SHIFT) - self.b0[0]);
        set_in_brick(&mut self.bricks[b as usize], i, j, k);
    }

    /// ORs the buffered bricks into `slab` (the box must lie in its layers).
    #[inline(always)]
    pub fn flush(&self, slab: &mut SlabView<'_>) {
        for (n, brick) in self.bricks[..self.len].iter().enumerate() {
            if brick.iter().fold(0, |a, w| a | w) == 0 {
                continue;
            }
            let n = n as u32;
            let b = [self.b0[0] + n % self.nx, self.b0[1] + n % self.nxy / self.nx, self.b0[2] + n / self.nxy];
            let slot = slab.slot(b[0] << SHIFT, b[1] << SHIFT, b[2] << SHIFT);
            for (w, x) in slab.pool[slot].iter_mut().zip(brick) {
                *w |= x;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::VoxelSource;

    #[test]
    fn runs_set_the_same_bits_as_single_voxels() {
        let dims = [21, 19, 23];
        for axis in 0..3 {
            for start in [0u32, 3, 7, 8, 13] {
                for len in [1u32, 2, 5, 8, 9, 17] {
                    if start + len > dims[axis] {
                        continue;
                    }
                    let mut p = [3u32, 6, 2];
                    p[axis] = start;
                    let (mut a, mut b) = (BrickBits::new(dims), BrickBits::new(dims));
                    // One slab holds the whole grid (8 brick layers > 23 voxels).
                    let mut slabs = a.slabs_mut(8);
                    assert_eq!(slabs.len(), 1);
                    slabs[0].set_run(axis, p[0], p[1], p[2], len);
                    let pools = slabs.into_iter().map(|s| s.into_pool()).collect();
                    a.merge_slabs(pools);
                    let mut q = p;
                    for _ in 0..len {
                        b.set(q[0], q[1], q[2]);
                        q[axis] += 1;
                    }
                    let mut got = Vec::new();
                    a.for_each_set(|i, j, k| got.push([i, j, k]));
                    let mut want = Vec::new();
                    b.for_each_set(|i, j, k| want.push([i, j, k]));
                    assert_eq!(got, want, "axis {axis} start {start} len {len}");
                }
            }
        }
    }

    /// Sets the voxels of `[0, upto)` in `slab` but about one in `one_in`,
    /// drawn from `seed`, in order `i`, then `j`, then `k`.
    fn set_at_random(slab: &mut BrickSlab<'_>, upto: [u32; 3], seed: u64, one_in: u64) {
        let mut rng = crate::test_rng::Xorshift(seed);
        for k in 0..upto[2] {
            for j in 0..upto[1] {
                for i in 0..upto[0] {
                    if rng.below(one_in) != 0 {
                        slab.set(i, j, k);
                    }
                }
            }
        }
    }

    #[test]
    fn all_set_agrees_with_single_voxels() {
        // Boxes inside one brick and across brick borders, over a slab
        // whose voxels are set densely but not completely.
        let dims = [19u32, 18, 21];
        let mut grid = BrickBits::new(dims);
        let mut slabs = grid.slabs_mut(8);
        let slab = &mut slabs[0];
        set_at_random(slab, dims, 0x9e37_79b9_7f4a_7c15, 16);
        let (mut full, mut checked) = (0, 0);
        for lo in [[0i64, 0, 0], [3, 5, 6], [6, 7, 7], [7, 1, 4], [9, 9, 15]] {
            for ext in [[0i64, 0, 0], [1, 0, 0], [0, 1, 1], [1, 1, 1], [0, 2, 1], [2, 0, 0], [3, 3, 3]] {
                let hi = [lo[0] + ext[0], lo[1] + ext[1], lo[2] + ext[2]];
                let want =
                    (lo[2]..=hi[2]).all(|k| (lo[1]..=hi[1]).all(|j| (lo[0]..=hi[0]).all(|i| slab.get(i as u32, j as u32, k as u32))));
                assert_eq!(slab.all_set(lo, hi), want, "{lo:?} {hi:?}");
                full += want as u32;
                checked += 1;
            }
        }
        assert!(full > 0 && full < checked, "{full} of {checked} boxes full");
    }

    #[test]
    fn block2_set_agrees_with_single_voxels() {
        // Every 2×2×2 block of a slab set at random (half its voxels),
        // inside bricks and across their borders, some in bricks never
        // allocated (the last brick column along x stays empty).
        let dims = [20u32, 18, 16];
        let mut grid = BrickBits::new(dims);
        let mut slabs = grid.slabs_mut(2);
        let slab = &mut slabs[0];
        set_at_random(slab, [16, dims[1], 16], 0x2b1c_3d4e_5f60_7182, 2);
        let mut seen = [false; 256];
        for k in 0..15 {
            for j in 0..dims[1] - 1 {
                for i in 0..dims[0] - 1 {
                    let want = (0..8).fold(0u8, |m, o| {
                        let [di, dj, dk] = block2_offset(o);
                        m | (slab.get(i + di, j + dj, k + dk) as u8) << o
                    });
                    assert_eq!(slab.block2_set(i, j, k), want, "block at {:?}", [i, j, k]);
                    seen[want as usize] = true;
                }
            }
        }
        assert!(seen.iter().filter(|&&s| s).count() > 200, "most of the 256 patterns occur");
    }

    #[test]
    fn all_set_across_a_missing_brick_is_false() {
        // Only brick (0, 0, 0) is allocated, and full.
        let mut grid = BrickBits::new([20, 20, 20]);
        let mut slabs = grid.slabs_mut(8);
        let slab = &mut slabs[0];
        for k in 0..8 {
            for j in 0..8 {
                for i in 0..8 {
                    slab.set(i, j, k);
                }
            }
        }
        assert!(slab.all_set([5, 5, 5], [7, 7, 7]));
        assert!(slab.all_set([0, 0, 0], [7, 7, 7]));
        for hi in [[8i64, 7, 7], [7, 8, 7], [7, 7, 8], [9, 9, 9]] {
            assert!(!slab.all_set([6, 6, 6], hi), "{hi:?}");
        }
    }

    fn random_pair(dims: [u32; 3], n: usize, seed: u64) -> (BrickBits, DenseBits) {
        let mut b = BrickBits::new(dims);
        let mut d = DenseBits::new(dims);
        let mut x = seed;
        for _ in 0..n {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let (i, j, k) = ((x >> 11) as u32 % dims[0], (x >> 27) as u32 % dims[1], (x >> 43) as u32 % dims[2]);
            b.set(i, j, k);
            d.set(i, j, k);
        }
        (b, d)
    }

    #[test]
    fn bricks_hold_the_same_voxels_as_dense_storage() {
        // Dims that are not multiples of 8 exercise the partial bricks.
        for dims in [[1, 1, 1], [13, 70, 5], [64, 9, 17], [130, 3, 40]] {
            let (b, d) = random_pair(dims, 500, dims[0] as u64);
            assert_eq!(b.to_dense(), d);
            assert_eq!(VoxelSource::count(&b), d.count());
            for (i, j, k) in [(0, 0, 0), (dims[0] - 1, dims[1] - 1, dims[2] - 1)] {
                assert_eq!(b.get(i, j, k), d.get(i, j, k));
            }
            let (mut vb, mut vd) = (Vec::new(), Vec::new());
            b.for_each_set(|i, j, k| vb.push([i, j, k]));
            d.for_each_set(|i, j, k| vd.push([i, j, k]));
            assert_eq!(vb, vd, "iteration order must be k, j, i for both");
            let plane = (dims[1] * dims[2]) as usize;
            for (i0, count) in [(0, dims[0]), (dims[0] / 2, dims[0] - dims[0] / 2), (dims[0] - 1, 1)] {
                for kf in [true, false] {
                    let mut ob = vec![7u8; plane * count as usize];
                    let mut od = vec![9u8; plane * count as usize];
                    VoxelSource::fill_i_planes(&b, i0, count, kf, &mut ob);
                    VoxelSource::fill_i_planes(&d, i0, count, kf, &mut od);
                    assert_eq!(ob, od);
                }
            }
        }
    }

    #[test]
    fn box_bricks_flush_the_voxels_set_in_them() {
        let dims = [40, 33, 29];
        for (lo, hi) in [([3i64, 5, 2], [17i64, 14, 9]), ([0, 0, 0], [7, 7, 7]), ([30, 20, 20], [39, 32, 28]), ([8, 8, 8], [8, 8, 8])] {
            let mut buf = BoxBricks::new(lo, hi).expect("a small box");
            let mut want = DenseBits::new(dims);
            let mut n = 0u32;
            for k in lo[2]..=hi[2] {
                for j in lo[1]..=hi[1] {
                    for i in lo[0]..=hi[0] {
                        n += 1;
                        // A scattered subset of the box, corners included.
                        if n % 3 == 0 || [i, j, k] == lo || [i, j, k] == hi {
                            buf.set(i as u32, j as u32, k as u32);
                            want.set(i as u32, j as u32, k as u32);
                        }
                    }
                }
            }
            let mut g = BrickBits::new(dims);
            let mut slabs = g.slabs_mut(8);
            buf.flush(&mut slabs[0]);
            let pools = slabs.into_iter().map(|s| s.into_pool()).collect();
            g.merge_slabs(pools);
            assert_eq!(g.to_dense(), want, "{lo:?} {hi:?}");
        }
        assert!(BoxBricks::new([0, 0, 0], [31, 31, 0]).is_none(), "16 bricks do not fit");
        let far = (1i64 << 31) - 1;
        assert!(BoxBricks::new([0, 0, 0], [far, far, far]).is_none(), "2^84 bricks do not wrap to a few");
    }

    #[test]
    fn slabs_merge_into_one_grid() {
        let dims = [20, 20, 50];
        let mut g = BrickBits::new(dims);
        let mut d = DenseBits::new(dims);
        let slabs = g.slabs_mut(2);
        assert_eq!(slabs.len(), 4);
        let mut pools = Vec::new();
        for mut s in slabs {
            for k in s.k0..s.k1 {
                s.set(k % 20, (3 * k) % 20, k);
                d.set(k % 20, (3 * k) % 20, k);
            }
            pools.push(s.into_pool());
        }
        g.merge_slabs(pools);
        assert_eq!(g.to_dense(), d);
        assert!(g.memory_bytes() < DenseBits::new(dims).words().len() * 8 + 4096);
    }
}
