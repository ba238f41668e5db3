//! Memory: what the machine has (`/proc/meminfo`), sizes as people read
//! them, and the budget a read may take (`--max-memory`; a fuzzer's limit),
//! which refuses a hostile file's claim before anything is allocated.

use crate::error::ErrorKind;

/// Memory available to this process: the machine's (`/proc/meminfo`),
/// and under an address-space limit (`ulimit -v`, `prlimit --as`) no more
/// than what the limit leaves beside the address space already mapped
/// (None if unknown): past it an allocation fails and aborts the process.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    let machine = kb * 1024;
    Some(address_space_left().map_or(machine, |left| left.min(machine)))
}

/// What the soft address-space limit leaves (`Max address space` of
/// `/proc/self/limits` less `VmSize`), if there is a limit.
fn address_space_left() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
    let soft: u64 = line.split_whitespace().nth(3)?.parse().ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let size = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let kb: u64 = size.split_whitespace().nth(1)?.parse().ok()?;
    Some(soft.saturating_sub(kb * 1024))
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

/// Reads that need less than this are not checked against the available
/// memory (every machine topovox runs on has that much): reading `/proc`
/// for each of a hundred thousand small files would cost more than
/// reading them.
pub(crate) const UNCHECKED_BYTES: u64 = 64 << 20;

/// The most memory a dense read may take, set by [`set_dense_read_budget`]
/// (0: nine tenths of the available memory).
static DENSE_READ_BUDGET: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Caps the memory the readers may give a dense grid (the CLI's
/// `--max-memory`; a fuzzer's memory limit): a file claiming a larger
/// grid is refused with [`ErrorKind::TooLarge`], and callers that can
/// read it sparsely ([`read_voxels_sparse`](crate::read_voxels_sparse)) do. `0` restores the default,
/// nine tenths of the available memory.
pub fn set_dense_read_budget(bytes: u64) {
    DENSE_READ_BUDGET.store(bytes, std::sync::atomic::Ordering::Relaxed);
}

/// A dense grid for a reader, refused when the file claims one that would
/// not fit in the memory a read may take (a hostile file of a few bytes
/// can claim billions of voxels; allocating them would abort the process).
pub(crate) fn dense_grid(dims: [u32; 3]) -> Result<topovox::DenseBits, ErrorKind> {
    // In u128: three u32 extents overflow u64.
    let need = u64::try_from((dims[0] as u128).div_ceil(64) * 8 * dims[1] as u128 * dims[2] as u128).unwrap_or(u64::MAX);
    let budget = DENSE_READ_BUDGET.load(std::sync::atomic::Ordering::Relaxed);
    // Small grids are never refused (see UNCHECKED_BYTES).
    if need > UNCHECKED_BYTES || (budget != 0 && need > budget) {
        let limit = read_limit();
        if need > limit {
            return Err(ErrorKind::TooLarge { dims, need: bytes(need), available: bytes(limit) });
        }
    }
    Ok(topovox::DenseBits::new(dims))
}

/// The memory one read may take: the budget [`set_dense_read_budget`] set
/// (`--max-memory`), at most nine tenths of the available memory (where
/// that cannot be read, 1 TiB stands for it).
pub(crate) fn read_limit() -> u64 {
    let budget = DENSE_READ_BUDGET.load(std::sync::atomic::Ordering::Relaxed);
    let avail = available_memory().unwrap_or(1 << 40) / 10 * 9;
    if budget == 0 {
        avail
    } else {
        budget.min(avail)
    }
}
