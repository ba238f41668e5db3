//! The parallel driver: bins lattice triangles into z-slabs and runs a
//! per-triangle kernel on each slab, one rayon task per slab.
//!
//! Parallelism is a driver, not a second algorithm: a [`Kernel`] is a pure
//! function of one triangle and the voxel box it may touch. Each slab owns
//! its words of the [`DenseBits`] exclusively, and kernels only OR bits in,
//! so the result is bit-identical for any thread count and slab height.

use rayon::prelude::*;

use super::Options;
use crate::geom::lattice::LatticeTriangle;
use crate::grid::dense::{DenseBits, SlabMut};

/// A per-triangle voxelization kernel.
pub trait Kernel: Sync {
    /// Sets, in `slab`, the voxels of `tri` whose indices lie in the inclusive
    /// box `[lo, hi]` (already clamped to the grid and to the slab's layers).
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut SlabMut<'_>);
}

/// Runs `kernel` over `tris` on a grid of `dims`, in parallel over z-slabs.
/// Returns the grid and the number of voxels set (counted by each slab's
/// task while its words are still in cache).
pub fn run_slabs<K: Kernel>(kernel: &K, tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> (DenseBits, u64) {
    let mut grid = DenseBits::new(dims);
    let nz = dims[2];
    let height = if opts.slab_height > 0 {
        opts.slab_height
    } else {
        let threads = rayon::current_num_threads() as u32;
        (nz / (16 * threads)).clamp(4, 64)
    };
    let nslabs = nz.div_ceil(height) as usize;
    let bounds: Vec<Option<([i64; 3], [i64; 3])>> = tris.par_iter().map(|t| t.voxel_bounds(dims)).collect();
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nslabs];
    for (idx, b) in bounds.iter().enumerate() {
        if let Some((lo, hi)) = b {
            for s in (lo[2] as u32 / height)..=(hi[2] as u32 / height) {
                bins[s as usize].push(idx as u32);
            }
        }
    }
    if let Some(p) = opts.progress {
        p.set_total(nslabs as u64);
    }
    let mut slabs = grid.slabs_mut(height);
    let count = slabs
        .par_iter_mut()
        .zip(bins.par_iter())
        .map(|(slab, bin)| {
            for &idx in bin {
                let Some((mut lo, mut hi)) = bounds[idx as usize] else { continue };
                lo[2] = lo[2].max(slab.k0 as i64);
                hi[2] = hi[2].min(slab.k1 as i64 - 1);
                if lo[2] <= hi[2] {
                    kernel.run(&tris[idx as usize], lo, hi, slab);
                }
            }
            if let Some(p) = opts.progress {
                p.advance(1);
            }
            slab.count()
        })
        .sum();
    drop(slabs);
    (grid, count)
}
