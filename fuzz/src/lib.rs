//! What the fuzz targets share: the panic hook that lets fenced panics of
//! third-party parsers pass, and the checks on voxels a reader returns.

use voxkit_io::VoxelFormat;

/// Installs a panic hook under which only panics outside voxkit-io's fence
/// are crashes: third-party parsers that panic on malformed input run
/// inside the fence, which turns the panic into an error (as the CLI does).
pub fn fence_panics() {
    let abort = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !voxkit_io::panic_is_fenced() {
            abort(info)
        }
    }));
}

/// Largest grid (in 64-bit words) whose every voxel the checks visit. A file
/// may claim any grid that fits in memory and the reader allocates it
/// untouched; visiting gigabytes of it would only measure the memory.
const MAX_VISITED_WORDS: u64 = 1 << 20;

/// Reads `data` as `format`: any bytes give voxels or an error, never a
/// panic; the voxels read are inside their grid, counted right, and carry at
/// most one attribute per voxel.
pub fn check_voxels(data: &[u8], format: VoxelFormat) {
    let Ok(v) = voxkit_io::read_voxels_bytes(data, format) else { return };
    let [nx, ny, nz] = v.bits.dims();
    if (nx as u64).div_ceil(64) * ny as u64 * nz as u64 > MAX_VISITED_WORDS {
        return;
    }
    let mut n = 0u64;
    v.bits.for_each_set(|i, j, k| {
        assert!(i < nx && j < ny && k < nz);
        n += 1;
    });
    assert_eq!(n, v.bits.count());
    if let Some(a) = &v.attributes {
        assert!(a.keys.len() as u64 <= n);
    }
}
