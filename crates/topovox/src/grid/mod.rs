//! Grids: the specification (where voxels are) and storage (which are set).

pub mod brick;
pub mod bricks;
pub mod dense;
pub mod sparse;
pub mod spec;

/// Set bits in `words`. Most words of a surface voxelization are zero;
/// skipping them avoids a software popcount on targets without POPCNT.
pub(crate) fn count_bits<'a>(words: impl IntoIterator<Item = &'a u64>) -> u64 {
    words.into_iter().filter(|&&w| w != 0).map(|w| w.count_ones() as u64).sum()
}

/// Read access shared by the storages ([`dense::DenseBits`],
/// [`bricks::BrickBits`]), so writers and checks take either.
pub trait VoxelSource: Sync {
    /// Voxels along x, y, z.
    fn dims(&self) -> [u32; 3];
    /// Number of set voxels.
    fn count(&self) -> u64;
    /// Calls `f(i, j, k)` for every set voxel, in order of `k`, then `j`, then `i`.
    fn for_each_set(&self, f: &mut dyn FnMut(u32, u32, u32));
    /// Fills `out` with the `count` planes `i0 .. i0+count` as bytes (0 or 1);
    /// plane `p` occupies `out[p*ny*nz .. (p+1)*ny*nz]`, laid out `[j][k]`
    /// (k fastest) when `k_fastest`, else `[k][j]`.
    fn fill_i_planes(&self, i0: u32, count: u32, k_fastest: bool, out: &mut [u8]);

    /// Calls `f([bi, bj, bk], bits)` for every 8×8×8 brick holding a set
    /// voxel, in order of `bk`, then `bj`, then `bi` (bit layout of
    /// [`brick::Brick`]). The sparse storages hand out their bricks; the
    /// default gathers them from [`VoxelSource::for_each_set`].
    fn for_each_brick(&self, f: &mut dyn FnMut([u32; 3], &brick::Brick)) {
        let mut map: std::collections::BTreeMap<[u32; 3], brick::Brick> = std::collections::BTreeMap::new();
        self.for_each_set(&mut |i, j, k| {
            brick::set_in_brick(map.entry([k / 8, j / 8, i / 8]).or_insert([0; 8]), i, j, k);
        });
        for (kji, b) in &map {
            f([kji[2], kji[1], kji[0]], b);
        }
    }

    /// [`VoxelSource::for_each_brick`], except that a run of `n` full
    /// bricks along `bi` may come as one call `f(first brick, full, n)`
    /// (sparse solids keep their interiors as such runs; sparse writers
    /// store them as constant tiles). Other bricks come with `n = 1`.
    fn for_each_brick_run(&self, f: &mut dyn FnMut([u32; 3], &brick::Brick, u32)) {
        self.for_each_brick(&mut |b, bits| f(b, bits, 1))
    }
}
