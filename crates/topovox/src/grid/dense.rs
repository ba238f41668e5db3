//! Dense voxel storage: one bit per voxel.

use rayon::prelude::*;

/// A dense grid of bits, one per voxel.
///
/// Layout: rows along `i` (x) packed into `u64` words, each row padded to
/// whole words; rows ordered by `j`, then `k`. Word index of voxel
/// `(i,j,k)` is `(k * ny + j) * words_per_row + i / 64`, bit `i % 64`.
/// A z-slab `[k0, k1)` is therefore one contiguous run of words, which is
/// what lets the parallel driver hand slabs to threads without atomics.
///
/// # Guarantees
/// Padding bits past `nx` in each row are always zero, so equality of the
/// word vectors is equality of the voxel sets.
#[derive(Clone, PartialEq, Eq)]
pub struct DenseBits {
    dims: [u32; 3],
    words_per_row: usize,
    words: Vec<u64>,
}

impl std::fmt::Debug for DenseBits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "DenseBits {{ dims: {:?}, set: {} }}", self.dims, self.count())
    }
}

impl DenseBits {
    /// An all-clear grid. Memory comes from the allocator zeroed, so pages
    /// never written cost nothing on systems with lazy zero pages.
    pub fn new(dims: [u32; 3]) -> DenseBits {
        let words_per_row = (dims[0] as usize).div_ceil(64);
        let n = words_per_row * dims[1] as usize * dims[2] as usize;
        DenseBits { dims, words_per_row, words: vec![0u64; n] }
    }

    /// Voxels along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Words per `i` row.
    pub fn words_per_row(&self) -> usize {
        self.words_per_row
    }

    /// The raw words, in the layout described on the type.
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    #[inline]
    fn word_index(&self, i: u32, j: u32, k: u32) -> usize {
        (k as usize * self.dims[1] as usize + j as usize) * self.words_per_row + (i as usize >> 6)
    }

    /// Whether voxel `(i,j,k)` is set. Panics if out of range.
    #[inline]
    pub fn get(&self, i: u32, j: u32, k: u32) -> bool {
        assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2], "voxel out of range");
        (self.words[self.word_index(i, j, k)] >> (i & 63)) & 1 == 1
    }

    /// Sets voxel `(i,j,k)`. Panics if out of range.
    #[inline]
    pub fn set(&mut self, i: u32, j: u32, k: u32) {
        assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2], "voxel out of range");
        let w = self.word_index(i, j, k);
        self.words[w] |= 1u64 << (i & 63);
    }

    /// Clears voxel `(i,j,k)`. Panics if out of range.
    #[inline]
    pub fn clear(&mut self, i: u32, j: u32, k: u32) {
        assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2], "voxel out of range");
        let w = self.word_index(i, j, k);
        self.words[w] &= !(1u64 << (i & 63));
    }

    /// The rows (`j`, then `k`; `words_per_row` words each), mutable.
    pub fn rows_mut(&mut self) -> std::slice::ChunksExactMut<'_, u64> {
        let wpr = self.words_per_row.max(1);
        self.words.chunks_exact_mut(wpr)
    }

    /// [`Self::rows_mut`] as a rayon parallel iterator (row order is the index).
    pub fn par_rows_mut(&mut self) -> rayon::slice::ChunksExactMut<'_, u64> {
        let wpr = self.words_per_row.max(1);
        self.words.par_chunks_exact_mut(wpr)
    }

    /// Sets voxels `i0 ..= i1` of one row (as returned by [`Self::rows_mut`]).
    pub fn fill_row(row: &mut [u64], i0: u32, i1: u32) {
        let (w0, w1) = ((i0 / 64) as usize, (i1 / 64) as usize);
        let lo_mask = u64::MAX << (i0 % 64);
        let hi_mask = u64::MAX >> (63 - i1 % 64);
        if w0 == w1 {
            row[w0] |= lo_mask & hi_mask;
            return;
        }
        row[w0] |= lo_mask;
        for w in &mut row[w0 + 1..w1] {
            *w = u64::MAX;
        }
        row[w1] |= hi_mask;
    }

    /// Sets every voxel of the inclusive box `[lo, hi]`, a row of words at
    /// a time. The box must lie inside the grid.
    pub fn fill_box(&mut self, lo: [u32; 3], hi: [u32; 3]) {
        assert!((0..3).all(|a| lo[a] <= hi[a] && hi[a] < self.dims[a]), "box {lo:?}..={hi:?} outside the grid {:?}", self.dims);
        let wpr = self.words_per_row;
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                let row = (k as usize * self.dims[1] as usize + j as usize) * wpr;
                Self::fill_row(&mut self.words[row..row + wpr], lo[0], hi[0]);
            }
        }
    }

    /// Sets every voxel `other` sets (same dims).
    pub fn or_assign(&mut self, other: &DenseBits) {
        assert_eq!(self.dims, other.dims, "or_assign: dims differ");
        self.words.par_iter_mut().zip(other.words.par_iter()).for_each(|(a, b)| *a |= b);
    }

    /// Clears the bits past `nx` in each row (after word-wise shifts).
    pub fn clear_padding(&mut self) {
        let tail = self.dims[0] % 64;
        if tail != 0 {
            let mask = (1u64 << tail) - 1;
            self.par_rows_mut().for_each(|row| *row.last_mut().expect("rows have words") &= mask);
        }
    }

    /// Is `(i, j, k)` inside the grid and set? Signed coordinates, so
    /// neighbour lookups need no bounds checks of their own.
    #[inline]
    pub fn get_signed(&self, i: i64, j: i64, k: i64) -> bool {
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        (0..nx).contains(&i) && (0..ny).contains(&j) && (0..nz).contains(&k) && self.get(i as u32, j as u32, k as u32)
    }

    /// Number of set voxels.
    pub fn count(&self) -> u64 {
        self.words.par_chunks(1 << 16).map(super::count_bits).sum()
    }

    /// Faces between a set voxel and an unset one or the grid's outside:
    /// the area of the set's boundary, in voxel faces.
    pub fn boundary_faces(&self) -> u64 {
        let [_, ny, nz] = self.dims.map(|d| d as usize);
        let w = self.words_per_row;
        let row = |j: usize, k: usize| &self.words[(k * ny + j) * w..(k * ny + j + 1) * w];
        let differ = |a: &[u64], b: Option<&[u64]>| -> u64 {
            a.iter().enumerate().map(|(n, &x)| u64::from((x ^ b.map_or(0, |b| b[n])).count_ones())).sum()
        };
        (0..nz)
            .into_par_iter()
            .map(|k| {
                let mut faces = 0;
                for j in 0..ny {
                    let r = row(j, k);
                    // Along x: changes between neighbours, the ends against
                    // the outside (padding bits are zero).
                    let mut carry = 0;
                    for &x in r {
                        faces += u64::from((x ^ ((x << 1) | carry)).count_ones());
                        carry = x >> 63;
                    }
                    faces += carry;
                    faces += differ(r, (j + 1 < ny).then(|| row(j + 1, k)));
                    faces += differ(r, k.checked_sub(1).map(|b| row(j, b)));
                    if j == 0 {
                        faces += differ(r, None);
                    }
                    if k + 1 == nz {
                        faces += differ(r, None);
                    }
                }
                faces
            })
            .sum()
    }

    /// Calls `f(i, j, k)` for every set voxel, in order of `k`, then `j`, then `i`.
    pub fn for_each_set(&self, mut f: impl FnMut(u32, u32, u32)) {
        let wpr = self.words_per_row;
        if wpr == 0 {
            return;
        }
        for (row, chunk) in self.words.chunks_exact(wpr).enumerate() {
            let j = (row % self.dims[1] as usize) as u32;
            let k = (row / self.dims[1] as usize) as u32;
            for (wi, &w) in chunk.iter().enumerate() {
                let mut w = w;
                while w != 0 {
                    let b = w.trailing_zeros();
                    f((wi as u32) * 64 + b, j, k);
                    w &= w - 1;
                }
            }
        }
    }

    /// The first voxel (in `k`, `j`, `i` order) where `self` and `other`
    /// differ, or `None` if equal. Panics if dims differ.
    pub fn first_difference(&self, other: &DenseBits) -> Option<[u32; 3]> {
        assert_eq!(self.dims, other.dims, "grids of different dims");
        let wpr = self.words_per_row;
        let idx = self.words.iter().zip(&other.words).position(|(a, b)| a != b)?;
        let diff = self.words[idx] ^ other.words[idx];
        let row = idx / wpr;
        let i = (idx % wpr) as u32 * 64 + diff.trailing_zeros();
        Some([i, (row % self.dims[1] as usize) as u32, (row / self.dims[1] as usize) as u32])
    }

    /// ORs the 8 bits of `byte` into voxels `(i0 .. i0+8, j, k)`; `i0` is a
    /// multiple of 8 and bits past `nx` must be zero.
    #[inline]
    pub fn or_byte(&mut self, i0: u32, j: u32, k: u32, byte: u8) {
        debug_assert!(i0 % 8 == 0 && j < self.dims[1] && k < self.dims[2]);
        let w = self.word_index(i0, j, k);
        self.words[w] |= (byte as u64) << (i0 & 63);
    }

    /// Fills `out` with the bits of the `count` planes `i0 .. i0+count` as
    /// bytes (0 or 1). Plane `p` occupies `out[p*ny*nz .. (p+1)*ny*nz]`,
    /// laid out `[j][k]` (k fastest) when `k_fastest`, else `[k][j]`.
    /// Cost is proportional to the number of words read plus voxels set.
    pub fn fill_i_planes(&self, i0: u32, count: u32, k_fastest: bool, out: &mut [u8]) {
        let (ny, nz) = (self.dims[1] as usize, self.dims[2] as usize);
        let plane = ny * nz;
        assert!(i0 + count <= self.dims[0] && out.len() >= plane * count as usize);
        out[..plane * count as usize].fill(0);
        let (w0, w1) = (i0 as usize / 64, (i0 + count - 1) as usize / 64);
        for k in 0..nz {
            for j in 0..ny {
                let base = (k * ny + j) * self.words_per_row;
                for wi in w0..=w1 {
                    let mut w = self.words[base + wi];
                    while w != 0 {
                        let b = w.trailing_zeros() as usize;
                        w &= w - 1;
                        let i = wi * 64 + b;
                        if i < i0 as usize || i >= (i0 + count) as usize {
                            continue;
                        }
                        let pos = if k_fastest { j * nz + k } else { k * ny + j };
                        out[(i - i0 as usize) * plane + pos] = 1;
                    }
                }
            }
        }
    }
}

impl super::VoxelSource for DenseBits {
    fn dims(&self) -> [u32; 3] {
        self.dims
    }

    fn count(&self) -> u64 {
        DenseBits::count(self)
    }

    fn for_each_set(&self, f: &mut dyn FnMut(u32, u32, u32)) {
        DenseBits::for_each_set(self, f)
    }

    fn fill_i_planes(&self, i0: u32, count: u32, k_fastest: bool, out: &mut [u8]) {
        DenseBits::fill_i_planes(self, i0, count, k_fastest, out)
    }

    /// Brick by brick from the words: each brick's 64 row bytes are read
    /// directly (a row's byte `bi` holds voxels `8·bi .. 8·bi + 7`).
    fn for_each_brick(&self, f: &mut dyn FnMut([u32; 3], &super::brick::Brick)) {
        let [nx, ny, nz] = self.dims;
        let wpr = self.words_per_row;
        let byte = |j: u32, k: u32, bi: u32| -> u64 {
            if j >= ny || k >= nz {
                return 0;
            }
            let w = self.words[(k as usize * ny as usize + j as usize) * wpr + bi as usize / 8];
            (w >> ((bi % 8) * 8)) & 0xff
        };
        for bk in 0..nz.div_ceil(8) {
            for bj in 0..ny.div_ceil(8) {
                for bi in 0..nx.div_ceil(8) {
                    let mut brick = [0u64; 8];
                    for (z, w) in brick.iter_mut().enumerate() {
                        for y in 0..8 {
                            *w |= byte(bj * 8 + y, bk * 8 + z as u32, bi) << (y * 8);
                        }
                    }
                    if brick != [0; 8] {
                        f([bi, bj, bk], &brick);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_faces_count_every_face_against_the_outside() {
        for dims in [[1, 1, 1], [5, 3, 2], [64, 2, 3], [70, 4, 5]] {
            let mut b = DenseBits::new(dims);
            let mut brute = 0;
            let mut x = 7u64;
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
                        if x >> 62 != 0 {
                            b.set(i, j, k);
                        }
                    }
                }
            }
            let set = |i: i64, j: i64, k: i64| b.get_signed(i, j, k);
            for k in 0..dims[2] as i64 {
                for j in 0..dims[1] as i64 {
                    for i in 0..dims[0] as i64 {
                        if set(i, j, k) {
                            brute += [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
                                .iter()
                                .filter(|d| !set(i + d.0, j + d.1, k + d.2))
                                .count() as u64;
                        }
                    }
                }
            }
            assert_eq!(b.boundary_faces(), brute, "{dims:?}");
        }
    }

    #[test]
    fn set_get_count_and_iterate() {
        let mut g = DenseBits::new([70, 3, 2]);
        g.set(0, 0, 0);
        g.set(69, 2, 1);
        g.set(64, 1, 1);
        assert!(g.get(69, 2, 1) && g.get(0, 0, 0) && !g.get(1, 0, 0));
        assert_eq!(g.count(), 3);
        let mut v = Vec::new();
        g.for_each_set(|i, j, k| v.push([i, j, k]));
        assert_eq!(v, vec![[0, 0, 0], [64, 1, 1], [69, 2, 1]]);
    }

    #[test]
    fn first_difference_names_the_voxel() {
        let a = DenseBits::new([5, 4, 7]);
        let mut b = a.clone();
        b.set(3, 2, 6);
        assert_eq!(a.first_difference(&b), Some([3, 2, 6]));
        assert_eq!(a.first_difference(&a), None);
    }

    #[test]
    fn planes_in_both_orders() {
        let mut g = DenseBits::new([3, 2, 4]);
        g.set(1, 1, 3);
        let mut out = vec![9u8; 2 * 2 * 4];
        g.fill_i_planes(1, 2, true, &mut out);
        assert_eq!(out.iter().filter(|&&b| b == 1).count(), 1);
        assert_eq!(out[4 + 3], 1);
        g.fill_i_planes(1, 2, false, &mut out);
        assert_eq!(out[3 * 2 + 1], 1);
    }
}

#[cfg(test)]
mod brick_tests {
    use super::*;
    use crate::grid::sparse::SparseBricks;

    /// Bricks read from the words give back the same grid, each brick once,
    /// in key order, on dims that are not multiples of 8 or 64.
    #[test]
    fn for_each_brick_reads_every_voxel_once() {
        let dims = [131, 21, 17];
        let mut d = DenseBits::new(dims);
        let mut s = 99u64;
        for _ in 0..2000 {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            d.set((s >> 20) as u32 % dims[0], (s >> 35) as u32 % dims[1], (s >> 50) as u32 % dims[2]);
        }
        d.fill_box([64, 8, 8], [71, 15, 15]);
        let mut bricks = Vec::new();
        crate::grid::VoxelSource::for_each_brick(&d, &mut |b, bits| bricks.push((b, *bits)));
        assert!(bricks.windows(2).all(|w| (w[0].0[2], w[0].0[1], w[0].0[0]) < (w[1].0[2], w[1].0[1], w[1].0[0])));
        assert!(bricks.contains(&([8, 1, 1], crate::grid::sparse::FULL)));
        assert_eq!(SparseBricks::from_bricks(dims, bricks).to_dense(), d);
    }
}
