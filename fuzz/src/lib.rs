//! What the fuzz targets share: the panic hook that lets fenced panics of
//! third-party parsers pass, and the checks on voxels a reader returns.

use topovox_io::VoxelFormat;

/// Installs a panic hook under which only panics outside topovox-io's fence
/// are crashes: third-party parsers that panic on malformed input run
/// inside the fence, which turns the panic into an error (as the CLI does).
pub fn fence_panics() {
    let abort = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !topovox_io::panic_is_fenced() {
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
    // The sparse .vdb and .npz readers never panic either, and where both
    // readers succeed they give the same voxels and attributes.
    let sparse = match format {
        VoxelFormat::Vdb => topovox_io::vdb::read_sparse(data, true).ok(),
        VoxelFormat::Npz => topovox_io::npz::read_sparse_from(std::io::Cursor::new(data), data.len() as u64).ok(),
        _ => None,
    };
    let Ok(v) = topovox_io::read_voxels_bytes(data, format) else { return };
    let [nx, ny, nz] = v.bits.dims();
    if (nx as u64).div_ceil(64) * ny as u64 * nz as u64 > MAX_VISITED_WORDS {
        return;
    }
    if let Some(s) = &sparse {
        assert_eq!(s.bits.dims(), v.bits.dims());
        assert_eq!(s.bits.count(), v.bits.count());
        assert_eq!(format!("{:?}", s.placement), format!("{:?}", v.placement)); // NaN-proof
        topovox::VoxelSource::for_each_set(&s.bits, &mut |i, j, k| assert!(v.bits.get(i, j, k)));
        // As text, NaN-proof too: a float attribute read from the file may
        // be NaN, which both readers pass on alike (`==` would fail on it).
        assert_eq!(format!("{:?}", s.attributes), format!("{:?}", v.attributes));
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
