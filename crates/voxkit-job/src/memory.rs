//! How much memory there is, and refusing grids that cannot fit.

use voxkit::GridSpec;

use crate::error::{JobError, Result};

/// Memory available to this process, from `/proc/meminfo` (None if unknown).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Human-readable byte count.
pub fn bytes(n: u64) -> String {
    const U: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = n as f64;
    let mut u = 0;
    while v >= 1024.0 && u < U.len() - 1 {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{n} B")
    } else {
        format!("{v:.1} {}", U[u])
    }
}

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
