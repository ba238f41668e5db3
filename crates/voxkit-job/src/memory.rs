//! How much memory there is, and refusing grids that cannot fit.

use voxkit::GridSpec;

use crate::error::{JobError, Result};

pub use voxkit_io::{available_memory, bytes};

/// Grids whose dense storage is below this are not checked (every machine
/// voxkit runs on has that much; reading `/proc/meminfo` per job would cost
/// more than a small job itself).
const UNCHECKED_BYTES: u64 = 256 << 20;

/// Fails if a dense grid of `grid` would not fit in available memory.
pub fn check_memory(grid: &GridSpec) -> Result<()> {
    let need = grid.dense_bytes();
    if need < UNCHECKED_BYTES {
        return Ok(());
    }
    if let Some(avail) = available_memory() {
        // Leave headroom for the mesh, the writer's buffers and the system.
        if need > avail / 10 * 9 {
            let [x, y, z] = grid.dims();
            return Err(JobError::failed(format!(
                "grid {x}x{y}x{z} needs {} of dense storage (1 bit per voxel) but only {} of memory is available; lower the resolution",
                bytes(need),
                bytes(avail)
            )));
        }
    }
    Ok(())
}
