//! Whole-grid sparse storage without a brick index: a sorted list of the
//! 8×8×8 bricks that hold a set voxel.
//!
//! [`super::bricks::BrickBits`] keeps a dense index of 4 bytes per brick,
//! which at 16384³ is 32 GiB before a single voxel is set. `SparseBricks`
//! stores only the non-empty bricks (8 bytes of key and 64 of bits each),
//! so its size follows the surface, not the grid: the tiled driver
//! ([`crate::voxelize::tiled`]) fills one tile's `BrickBits` at a time and
//! moves its bricks here.

use super::bricks::{Brick, BrickBits, BRICK};
use super::dense::DenseBits;
use super::VoxelSource;
use rayon::prelude::*;

/// Bits per brick coordinate in a key (grids up to 2^24 voxels per axis).
const KEY_BITS: u32 = 21;
const KEY_MASK: u64 = (1 << KEY_BITS) - 1;

/// The key of brick `(bi, bj, bk)`: ordered by `bk`, then `bj`, then `bi`.
#[inline]
fn key(b: [u32; 3]) -> u64 {
    ((b[2] as u64) << (2 * KEY_BITS)) | ((b[1] as u64) << KEY_BITS) | b[0] as u64
}

#[inline]
fn unkey(k: u64) -> [u32; 3] {
    [(k & KEY_MASK) as u32, ((k >> KEY_BITS) & KEY_MASK) as u32, (k >> (2 * KEY_BITS)) as u32]
}

/// Every bit of a brick set.
pub const FULL: Brick = [u64::MAX; 8];

/// A sparse grid of bits: the non-empty 8³ bricks, sorted by `(bk, bj, bi)`,
/// and runs of full bricks along `bi` stored as constant tiles (a solid's
/// interior is a few runs per brick row, never its voxels).
///
/// # Guarantees
/// Keys are strictly increasing (each brick once), no stored brick is
/// empty, full runs are sorted, within one brick row and disjoint from the
/// stored bricks, and no bit outside `dims` is set (a full brick lies
/// wholly inside the grid).
#[derive(Clone, Debug, Default)]
pub struct SparseBricks {
    dims: [u32; 3],
    keys: Vec<u64>,
    bricks: Vec<Brick>,
    /// Runs of full bricks: the key of the first and how many follow along `bi`.
    full: Vec<(u64, u32)>,
}

impl SparseBricks {
    /// Largest voxels per axis: brick coordinates fit in 21 bits.
    pub const MAX_DIM: u32 = (1 << KEY_BITS) * BRICK;

    /// An empty grid. Panics if an axis exceeds [`SparseBricks::MAX_DIM`].
    pub fn new(dims: [u32; 3]) -> SparseBricks {
        assert!(dims.iter().all(|&d| d <= Self::MAX_DIM), "grid {dims:?} beyond the sparse key range");
        SparseBricks { dims, keys: Vec::new(), bricks: Vec::new(), full: Vec::new() }
    }

    /// A grid from bricks and runs of full bricks already in key order
    /// (runs as `(first brick, length along bi)`), as a solid's brick rows
    /// produce them. Panics if the order or the grid is violated.
    pub fn from_sorted(dims: [u32; 3], bricks: Vec<([u32; 3], Brick)>, full: Vec<([u32; 3], u32)>) -> SparseBricks {
        let mut out = SparseBricks::new(dims);
        out.keys = bricks.iter().map(|(b, _)| key(*b)).collect();
        out.bricks = bricks.into_iter().map(|(_, b)| b).collect();
        out.full = full.iter().map(|&(b, n)| (key(b), n)).collect();
        assert!(out.keys.windows(2).all(|w| w[0] < w[1]), "bricks out of order");
        assert!(out.full.windows(2).all(|w| w[0].0 + w[0].1 as u64 <= w[1].0), "full runs out of order");
        for &(b, n) in &full {
            assert!(n > 0 && (0..3).all(|a| (b[a] + if a == 0 { n } else { 1 }) * BRICK <= dims[a]), "full run outside the grid");
        }
        assert!(out.keys.iter().all(|k| out.full_at(*k).is_none()), "a brick inside a full run");
        out
    }

    /// The full run holding brick `k`, if any.
    fn full_at(&self, k: u64) -> Option<usize> {
        let n = self.full.partition_point(|r| r.0 <= k);
        (n > 0 && k < self.full[n - 1].0 + self.full[n - 1].1 as u64).then(|| n - 1)
    }

    /// Bricks in full runs.
    pub fn full_bricks(&self) -> u64 {
        self.full.iter().map(|r| r.1 as u64).sum()
    }

    /// The runs of full bricks: `(first brick, length along bi)`, in key order.
    pub fn full_runs(&self) -> impl Iterator<Item = ([u32; 3], u32)> + '_ {
        self.full.iter().map(|&(k, n)| (unkey(k), n))
    }

    /// The union of this grid and `surface`, a grid without full runs (a
    /// solid and its surface shell): bricks inside a full run are dropped,
    /// bricks at the same key are merged.
    pub fn union(&self, surface: &SparseBricks) -> SparseBricks {
        assert!(surface.full.is_empty() && surface.dims == self.dims, "union with a grid of full runs or another shape");
        // Both brick lists are sorted by key: one merge, as in merge sort.
        let mut out = SparseBricks::new(self.dims);
        out.keys.reserve(self.keys.len() + surface.keys.len());
        out.bricks.reserve(self.keys.len() + surface.keys.len());
        let (mut a, mut b) = (0, 0);
        while a < self.keys.len() || b < surface.keys.len() {
            let ka = self.keys.get(a).copied().unwrap_or(u64::MAX);
            let kb = surface.keys.get(b).copied().unwrap_or(u64::MAX);
            if ka < kb {
                out.keys.push(ka);
                out.bricks.push(self.bricks[a]);
                a += 1;
            } else if kb < ka {
                if self.full_at(kb).is_none() {
                    out.keys.push(kb);
                    out.bricks.push(surface.bricks[b]);
                }
                b += 1;
            } else {
                out.keys.push(ka);
                out.bricks.push(std::array::from_fn(|w| self.bricks[a][w] | surface.bricks[b][w]));
                a += 1;
                b += 1;
            }
        }
        out.full = self.full.clone();
        out
    }

    /// This grid with voxels set or cleared as `changes` say (`(voxel,
    /// set)`; a voxel given twice takes its last value): full runs holding
    /// a changed brick are split around it.
    pub fn with_changes(&self, changes: &[([u32; 3], bool)]) -> SparseBricks {
        let mut touched: Vec<(u64, usize)> = changes.iter().enumerate().map(|(n, (v, _))| (key(v.map(|c| c / BRICK)), n)).collect();
        touched.sort_unstable();
        let mut changed: Vec<([u32; 3], Brick)> = Vec::new();
        for group in touched.chunk_by(|a, b| a.0 == b.0) {
            let at = unkey(group[0].0);
            let mut bits = self.brick_bits(at);
            for &(_, n) in group {
                let (v, set) = changes[n];
                let slot = (v[2] % BRICK) * 64 + (v[1] % BRICK) * 8 + v[0] % BRICK;
                let (w, bit) = ((slot / 64) as usize, slot % 64);
                if set {
                    bits[w] |= 1 << bit;
                } else {
                    bits[w] &= !(1 << bit);
                }
            }
            changed.push((at, bits));
        }
        let is_changed = |k: u64| changed.binary_search_by_key(&k, |(b, _)| key(*b)).is_ok();
        let mut bricks: Vec<([u32; 3], Brick)> =
            self.keys.iter().zip(&self.bricks).filter(|(k, _)| !is_changed(**k)).map(|(k, b)| (unkey(*k), *b)).collect();
        bricks.extend(changed.iter().copied());
        let mut runs = Vec::with_capacity(self.full.len());
        for &(k, n) in &self.full {
            // Split the run around its changed bricks (a run stays in one row).
            let mut start = k;
            for b in k..k + n as u64 {
                if is_changed(b) {
                    if b > start {
                        runs.push((unkey(start), (b - start) as u32));
                    }
                    start = b + 1;
                }
            }
            if k + (n as u64) > start {
                runs.push((unkey(start), (k + n as u64 - start) as u32));
            }
        }
        SparseBricks::from_parts(self.dims, bricks, runs)
    }

    /// Builds a grid from bricks in any order; bricks given twice are
    /// merged by union, empty ones dropped. Brick coordinates must lie in
    /// the grid and bits outside `dims` must be clear.
    pub fn from_bricks(dims: [u32; 3], bricks: impl IntoIterator<Item = ([u32; 3], Brick)>) -> SparseBricks {
        let mut out = SparseBricks::new(dims);
        for (b, bits) in bricks {
            out.keys.push(key(b));
            out.bricks.push(bits);
        }
        out.finish();
        out
    }

    /// Builds a grid from bricks and runs of full bricks in any order, as a
    /// reader finds them (a file's leaves and active tiles): bricks given
    /// twice are merged, empty ones dropped, full ones and overlapping or
    /// touching runs of a row joined into runs, bricks inside a run
    /// dropped. Brick coordinates must lie in the grid, bits outside
    /// `dims` must be clear and runs must lie wholly inside it.
    pub fn from_parts(dims: [u32; 3], bricks: Vec<([u32; 3], Brick)>, runs: Vec<([u32; 3], u32)>) -> SparseBricks {
        let mut out = SparseBricks::from_bricks(dims, bricks);
        let mut full: Vec<(u64, u32)> = runs.iter().filter(|r| r.1 > 0).map(|&(b, n)| (key(b), n)).collect();
        // Full bricks become runs of one (a brick full of bits is wholly inside the grid).
        full.extend(out.keys.iter().zip(&out.bricks).filter(|(_, b)| **b == FULL).map(|(k, _)| (*k, 1)));
        full.sort_unstable();
        // A run never leaves its row (bi + n <= the row's bricks), so two
        // runs of a row overlap or touch iff the next starts by the end of
        // the last; runs of different rows are 2^21 keys apart.
        let mut joined: Vec<(u64, u32)> = Vec::with_capacity(full.len());
        for (k, n) in full {
            match joined.last_mut() {
                Some(last) if k <= last.0 + last.1 as u64 => last.1 = last.1.max((k + n as u64 - last.0) as u32),
                _ => joined.push((k, n)),
            }
        }
        out.full = joined;
        for &(k, n) in &out.full {
            let b = unkey(k);
            assert!((0..3).all(|a| (b[a] + if a == 0 { n } else { 1 }) * BRICK <= dims[a]), "full run outside the grid");
        }
        let keep: Vec<bool> = out.keys.iter().map(|&k| out.full_at(k).is_none()).collect();
        let mut n = 0;
        out.keys.retain(|_| (keep[n], n += 1).0);
        let mut n = 0;
        out.bricks.retain(|_| (keep[n], n += 1).0);
        out
    }

    /// Appends the bricks of `tile`, a grid whose voxel `(0,0,0)` is this
    /// grid's voxel `origin` (a multiple of 8 on every axis). Call
    /// [`SparseBricks::finish`] after the last tile.
    pub fn push_tile(&mut self, origin: [u32; 3], tile: &BrickBits) {
        debug_assert!(origin.iter().all(|o| o % BRICK == 0));
        let base = origin.map(|o| o / BRICK);
        tile.for_each_brick(&mut |b, bits| {
            self.keys.push(key([b[0] + base[0], b[1] + base[1], b[2] + base[2]]));
            self.bricks.push(*bits);
        });
    }

    /// Makes room for `additional` more bricks at once, so pushing tiles
    /// never grows the vectors by doubling (which briefly holds twice the
    /// bricks). Untouched room costs address space, not memory.
    pub fn reserve(&mut self, additional: usize) {
        self.keys.reserve_exact(additional);
        self.bricks.reserve_exact(additional);
    }

    /// Restores the order after [`SparseBricks::push_tile`] (tiles pushed
    /// in key order need no sort): sorts by key, merges repeated keys,
    /// drops empty bricks. In place: besides the bricks, it holds one
    /// 4-byte index per brick.
    pub fn finish(&mut self) {
        if !self.keys.windows(2).all(|w| w[0] < w[1]) {
            let mut order: Vec<u32> = (0..self.keys.len() as u32).collect();
            order.par_sort_unstable_by_key(|&n| (self.keys[n as usize], n));
            permute_in_place(&mut self.keys, &mut self.bricks, &mut order);
            // Merge repeated keys (now adjacent) into their first brick.
            let mut w = 0;
            for r in 0..self.keys.len() {
                if w > 0 && self.keys[w - 1] == self.keys[r] {
                    let b = self.bricks[r];
                    for (x, y) in self.bricks[w - 1].iter_mut().zip(b) {
                        *x |= y;
                    }
                } else {
                    self.keys[w] = self.keys[r];
                    self.bricks[w] = self.bricks[r];
                    w += 1;
                }
            }
            self.keys.truncate(w);
            self.bricks.truncate(w);
        }
        let mut w = 0;
        for r in 0..self.keys.len() {
            if self.bricks[r].iter().any(|&x| x != 0) {
                self.keys[w] = self.keys[r];
                self.bricks[w] = self.bricks[r];
                w += 1;
            }
        }
        self.keys.truncate(w);
        self.bricks.truncate(w);
        self.keys.shrink_to_fit();
        self.bricks.shrink_to_fit();
    }

    /// Voxels along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Stored bricks (not counting those of full runs).
    pub fn brick_count(&self) -> usize {
        self.bricks.len()
    }

    /// Bytes used by keys, bricks and full runs.
    pub fn memory_bytes(&self) -> usize {
        self.keys.len() * 8 + self.bricks.len() * 64 + self.full.len() * 16
    }

    /// Number of set voxels.
    pub fn count(&self) -> u64 {
        super::count_bits(self.bricks.iter().flatten()) + self.full_bricks() * (BRICK * BRICK * BRICK) as u64
    }

    /// Is voxel `(i, j, k)` set?
    pub fn get(&self, i: u32, j: u32, k: u32) -> bool {
        let kb = key([i / BRICK, j / BRICK, k / BRICK]);
        match self.keys.binary_search(&kb) {
            Ok(n) => self.bricks[n][(k % BRICK) as usize] >> ((j % BRICK) * 8 + i % BRICK) & 1 == 1,
            Err(_) => self.full_at(kb).is_some(),
        }
    }

    /// The bits of brick `b`: stored, full (in a run), or empty.
    pub fn brick_bits(&self, b: [u32; 3]) -> Brick {
        let k = key(b);
        match self.keys.binary_search(&k) {
            Ok(n) => self.bricks[n],
            Err(_) if self.full_at(k).is_some() => FULL,
            Err(_) => [0; 8],
        }
    }

    /// The stored (not full-run) bricks' bits, in key order (beside
    /// [`SparseBricks::stored_bricks`]).
    pub fn stored_bits(&self) -> &[Brick] {
        &self.bricks
    }

    /// The coordinates of the stored (not full-run) bricks, in key order.
    pub fn stored_bricks(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.keys.iter().map(|&k| unkey(k))
    }

    /// Calls `f(brick coordinates, bits)` for every non-empty brick, full
    /// runs brick by brick, in order of `bk`, then `bj`, then `bi`.
    pub fn for_each_brick(&self, mut f: impl FnMut([u32; 3], &Brick)) {
        self.for_each_brick_run(|b, bits, n| (0..n).for_each(|x| f([b[0] + x, b[1], b[2]], bits)));
    }

    /// Calls `f(first brick, bits, n)` for every stored brick (`n = 1`) and
    /// every run of `n` full bricks, in key order.
    pub fn for_each_brick_run(&self, f: impl FnMut([u32; 3], &Brick, u32)) {
        self.for_each_brick_run_in(0..u64::MAX, f)
    }

    /// [`SparseBricks::for_each_brick_run`] for the bricks and runs whose
    /// (first) key lies in `keys`.
    fn for_each_brick_run_in(&self, keys: std::ops::Range<u64>, mut f: impl FnMut([u32; 3], &Brick, u32)) {
        let (k0, k1) = (self.keys.partition_point(|&k| k < keys.start), self.keys.partition_point(|&k| k < keys.end));
        let (r0, r1) = (self.full.partition_point(|r| r.0 < keys.start), self.full.partition_point(|r| r.0 < keys.end));
        let mut runs = self.full[r0..r1].iter().peekable();
        for (k, b) in self.keys[k0..k1].iter().zip(&self.bricks[k0..k1]) {
            while let Some(&&(r, n)) = runs.peek().filter(|r| r.0 < *k) {
                f(unkey(r), &FULL, n);
                runs.next();
            }
            f(unkey(*k), b, 1);
        }
        for &(r, n) in runs {
            f(unkey(r), &FULL, n);
        }
    }

    /// [`SparseBricks::for_each_brick`] for the bricks of the brick
    /// layers `layers` (`bk` in that range) only, found by binary search.
    pub fn for_each_brick_in_layers(&self, layers: std::ops::Range<u32>, mut f: impl FnMut([u32; 3], &Brick)) {
        let keys = key([0, 0, layers.start])..key([0, 0, layers.end]);
        self.for_each_brick_run_in(keys, |b, bits, n| (0..n).for_each(|x| f([b[0] + x, b[1], b[2]], bits)));
    }

    /// Whether any brick (or run of full bricks) lies in the brick layers
    /// `layers`: two binary searches, without visiting the bricks.
    pub fn any_in_layers(&self, layers: std::ops::Range<u32>) -> bool {
        let keys = key([0, 0, layers.start])..key([0, 0, layers.end]);
        let first = self.keys.partition_point(|&k| k < keys.start);
        let first_run = self.full.partition_point(|&(k, _)| k < keys.start);
        self.keys.get(first).is_some_and(|k| keys.contains(k)) || self.full.get(first_run).is_some_and(|(k, _)| keys.contains(k))
    }

    /// The box `(lo, hi)` (inclusive, in bricks) of every stored brick
    /// and full run; `None` when there are none.
    pub fn brick_bounds(&self) -> Option<([u32; 3], [u32; 3])> {
        let mut bounds: Option<([u32; 3], [u32; 3])> = None;
        self.for_each_brick_run(|b, _, n| {
            let last = [b[0] + n - 1, b[1], b[2]];
            let (lo, hi) = bounds.get_or_insert((b, last));
            for a in 0..3 {
                lo[a] = lo[a].min(b[a]);
                hi[a] = hi[a].max(last[a]);
            }
        });
        bounds
    }

    /// The same bricks and full runs moved by `by` bricks into a grid of
    /// `dims` (a window of this one, or a grid it is a window of): every
    /// one must land inside it, and voxels past `dims` must be clear.
    pub fn moved(&self, by: [i64; 3], dims: [u32; 3]) -> SparseBricks {
        let (mut bricks, mut runs) = (Vec::new(), Vec::new());
        self.for_each_brick_run(|b, bits, n| {
            let to: [u32; 3] = std::array::from_fn(|a| u32::try_from(b[a] as i64 + by[a]).expect("a brick moved outside the grid"));
            if *bits == FULL {
                runs.push((to, n));
            } else {
                bricks.push((to, *bits));
            }
        });
        SparseBricks::from_parts(dims, bricks, runs)
    }

    /// The same voxels, dense.
    pub fn to_dense(&self) -> DenseBits {
        let mut d = DenseBits::new(self.dims);
        VoxelSource::for_each_set(self, &mut |i, j, k| d.set(i, j, k));
        d
    }
}

impl VoxelSource for SparseBricks {
    fn dims(&self) -> [u32; 3] {
        self.dims
    }

    fn count(&self) -> u64 {
        SparseBricks::count(self)
    }

    fn for_each_set(&self, f: &mut dyn FnMut(u32, u32, u32)) {
        if self.full.is_empty() {
            layer_voxels(&self.keys, &self.bricks, f);
            return;
        }
        // With full runs: each layer's bricks gathered, then walked alike.
        let (mut keys, mut bricks) = (Vec::new(), Vec::new());
        let mut layer = None;
        self.for_each_brick(|b, bits| {
            if layer != Some(b[2]) {
                layer_voxels(&keys, &bricks, f);
                keys.clear();
                bricks.clear();
                layer = Some(b[2]);
            }
            keys.push(key(b));
            bricks.push(*bits);
        });
        layer_voxels(&keys, &bricks, f);
    }

    fn fill_i_planes(&self, i0: u32, count: u32, k_fastest: bool, out: &mut [u8]) {
        let (ny, nz) = (self.dims[1] as usize, self.dims[2] as usize);
        let plane = ny * nz;
        assert!(count > 0 && i0 + count <= self.dims[0] && out.len() >= plane * count as usize);
        out[..plane * count as usize].fill(0);
        let (b0, b1) = (i0 / BRICK, (i0 + count - 1) / BRICK);
        self.for_each_brick(|[bi, bj, bk], brick| {
            if bi >= b0 && bi <= b1 {
                super::bricks::brick_to_planes([bi, bj, bk], brick, i0, count, k_fastest, [ny, nz], out);
            }
        });
    }

    fn for_each_brick(&self, f: &mut dyn FnMut([u32; 3], &Brick)) {
        SparseBricks::for_each_brick(self, f)
    }

    fn for_each_brick_run(&self, f: &mut dyn FnMut([u32; 3], &Brick, u32)) {
        SparseBricks::for_each_brick_run(self, f)
    }
}

/// Calls `f(i, j, k)` for the set voxels of sorted bricks, in order of `k`,
/// then `j`, then `i`: bricks of one layer `bk` are contiguous, and within
/// it those of one row `bj`, in order of `bi`, so each layer is walked
/// voxel row by voxel row.
fn layer_voxels(keys: &[u64], bricks: &[Brick], f: &mut dyn FnMut(u32, u32, u32)) {
    let mut start = 0;
    while start < keys.len() {
        let bk = unkey(keys[start])[2];
        let end = start + keys[start..].iter().take_while(|&&k| unkey(k)[2] == bk).count();
        for z in 0..BRICK {
            let k = bk * BRICK + z;
            let mut row = start;
            while row < end {
                let bj = unkey(keys[row])[1];
                let row_end = row + keys[row..end].iter().take_while(|&&k| unkey(k)[1] == bj).count();
                for y in 0..BRICK {
                    for n in row..row_end {
                        let bi = unkey(keys[n])[0];
                        let mut byte = (bricks[n][z as usize] >> (y * 8)) & 0xff;
                        while byte != 0 {
                            let x = byte.trailing_zeros();
                            byte &= byte - 1;
                            f(bi * BRICK + x, bj * BRICK + y, k);
                        }
                    }
                }
                row = row_end;
            }
        }
        start = end;
    }
}

/// Reorders `keys` and `bricks` so that position `i` holds what was at
/// `order[i]`, following the permutation's cycles (no second copy of the
/// bricks); `order` is consumed (marked as it goes).
fn permute_in_place(keys: &mut [u64], bricks: &mut [Brick], order: &mut [u32]) {
    const DONE: u32 = u32::MAX;
    for i in 0..order.len() {
        if order[i] == DONE {
            continue;
        }
        let (k0, b0) = (keys[i], bricks[i]);
        let mut cur = i;
        loop {
            let next = order[cur] as usize;
            order[cur] = DONE;
            if next == i {
                keys[cur] = k0;
                bricks[cur] = b0;
                break;
            }
            keys[cur] = keys[next];
            bricks[cur] = bricks[next];
            cur = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_and_any_order_give_the_same_grid() {
        let dims = [40, 33, 17];
        let mut dense = DenseBits::new(dims);
        let mut state = 12345u64;
        for _ in 0..600 {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let (i, j, k) = ((state >> 20) as u32 % dims[0], (state >> 35) as u32 % dims[1], (state >> 50) as u32 % dims[2]);
            dense.set(i, j, k);
        }
        // Two tiles along x, pushed in reverse order.
        let mut sparse = SparseBricks::new(dims);
        for x0 in [32u32, 0] {
            let w = (dims[0] - x0).min(32);
            let mut tile = BrickBits::new([w, dims[1], dims[2]]);
            dense.for_each_set(|i, j, k| {
                if i >= x0 && i < x0 + w {
                    tile.set(i - x0, j, k);
                }
            });
            sparse.push_tile([x0, 0, 0], &tile);
        }
        sparse.finish();
        assert_eq!(sparse.to_dense(), dense);
        assert_eq!(sparse.count(), dense.count());
        let mut order = Vec::new();
        VoxelSource::for_each_set(&sparse, &mut |i, j, k| order.push((i, j, k)));
        let mut expect = Vec::new();
        dense.for_each_set(|i, j, k| expect.push((i, j, k)));
        assert_eq!(order, expect, "for_each_set is in (k, j, i) order");
        for (i, j, k) in [(0, 0, 0), (39, 32, 16), (17, 5, 9)] {
            assert_eq!(sparse.get(i, j, k), dense.get(i, j, k));
        }
        let (mut a, mut b) = (vec![0u8; 3 * 33 * 17], vec![0u8; 3 * 33 * 17]);
        for k_fastest in [false, true] {
            sparse.fill_i_planes(30, 3, k_fastest, &mut a);
            dense.fill_i_planes(30, 3, k_fastest, &mut b);
            assert_eq!(a, b);
        }
        let twice = SparseBricks::from_bricks(
            dims,
            sparse.keys.iter().zip(&sparse.bricks).chain(sparse.keys.iter().zip(&sparse.bricks)).map(|(k, b)| (unkey(*k), *b)),
        );
        assert_eq!(twice.to_dense(), dense);
    }

    #[test]
    fn union_with_a_surface_equals_the_dense_union() {
        let dims = [48, 24, 16];
        let one = |n: u32| -> Brick { std::array::from_fn(|w| if w as u32 == n % 8 { 1 << (n % 64) } else { 0 }) };
        // A solid: one full run of three bricks, bricks before, inside its row after it, and in another row.
        let solid =
            SparseBricks::from_sorted(dims, vec![([0, 0, 0], one(1)), ([5, 0, 0], one(2)), ([1, 2, 1], one(3))], vec![([1, 0, 0], 3)]);
        // A surface: bricks at the solid's keys, inside the full run, and elsewhere, before and after.
        let surface = SparseBricks::from_bricks(
            dims,
            [([0, 0, 0], one(9)), ([2, 0, 0], one(4)), ([4, 0, 0], one(5)), ([0, 1, 0], one(6)), ([5, 2, 1], one(7))],
        );
        let mut expect = solid.to_dense();
        VoxelSource::for_each_set(&surface, &mut |i, j, k| expect.set(i, j, k));
        let got = solid.union(&surface);
        assert_eq!(got.to_dense(), expect);
        assert_eq!(got.count(), expect.count());
        assert_eq!(got.full_bricks(), 3);
        assert!(got.keys.windows(2).all(|w| w[0] < w[1]));
    }

    /// Parts as a reader finds them — repeated and full bricks, bricks
    /// inside runs, runs overlapping and touching — give the grid of their
    /// union, normalised (`from_sorted` accepts its parts again).
    #[test]
    fn parts_in_any_order_are_normalised() {
        let dims = [64, 24, 16];
        let mut partial = [0u64; 8];
        partial[2] = 0x8001;
        let bricks = vec![
            ([7, 2, 1], partial),
            ([1, 0, 0], partial),
            ([7, 2, 1], [0, 1, 0, 0, 0, 0, 0, 0]),
            ([3, 1, 1], partial),
            ([5, 1, 1], FULL),
            ([0, 0, 0], [0; 8]),
        ];
        let runs = vec![([2, 1, 1], 2), ([0, 2, 0], 3), ([3, 1, 1], 2), ([6, 1, 1], 1), ([1, 2, 0], 1)];
        let got = SparseBricks::from_parts(dims, bricks.clone(), runs.clone());
        let mut want = DenseBits::new(dims);
        for (b, bits) in &bricks {
            for (z, &w) in bits.iter().enumerate() {
                for bit in 0..64 {
                    if w >> bit & 1 == 1 {
                        want.set(b[0] * 8 + bit % 8, b[1] * 8 + bit / 8, b[2] * 8 + z as u32);
                    }
                }
            }
        }
        for (b, n) in &runs {
            want.fill_box([b[0] * 8, b[1] * 8, b[2] * 8], [(b[0] + n) * 8 - 1, b[1] * 8 + 7, b[2] * 8 + 7]);
        }
        assert_eq!(got.to_dense(), want);
        assert_eq!(got.count(), want.count());
        // Runs (2..7, 1, 1) joined with the full brick 5, and (0..3, 2, 0).
        assert_eq!(got.full_runs().collect::<Vec<_>>(), [([0, 2, 0], 3), ([2, 1, 1], 5)]);
        assert_eq!(got.brick_count(), 2, "brick (3, 1, 1) lies in a run, (0, 0, 0) is empty");
        let parts: Vec<([u32; 3], Brick)> = got.keys.iter().zip(&got.bricks).map(|(k, b)| (unkey(*k), *b)).collect();
        let again = SparseBricks::from_sorted(dims, parts, got.full_runs().collect());
        assert_eq!(again.to_dense(), want);
    }
}
