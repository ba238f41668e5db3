//! What the fuzz targets share: the panic hook that lets fenced panics of
//! third-party parsers pass, and the checks on voxels a reader returns.

use topovox_io::VoxelFormat;

/// Installs a panic hook under which only panics outside topovox-io's fence
/// are crashes: third-party parsers that panic on malformed input run
/// inside the fence, which turns the panic into an error (as the CLI does).
pub fn fence_panics() {
    // Dense reads stay well inside libFuzzer's 2 GB memory limit: a file
    // claiming a larger grid is refused as too large (the CLI then reads it
    // sparsely), which is the answer the targets check for.
    topovox_io::set_dense_read_budget(512 << 20);
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
    let Ok(v) = topovox_io::read_voxels_bytes(data, format, &topovox_io::ReadOptions::default()) else { return };
    check_loaded(&v, sparse.as_ref());
}

/// The checks on what a dense reader returned, and where the sparse reader
/// succeeded too, that both agree.
pub fn check_loaded(v: &topovox_io::LoadedVoxels, sparse: Option<&topovox_io::SparseVoxels>) {
    let [nx, ny, nz] = v.bits.dims();
    if (nx as u64).div_ceil(64) * ny as u64 * nz as u64 > MAX_VISITED_WORDS {
        return;
    }
    if let Some(s) = sparse {
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

/// Where a file of a fuzzed Zarr folder starts: this line, then its path
/// (relative to the folder) up to a newline, then its bytes.
pub const ZARR_FILE_MARK: &[u8] = b"\n@@FILE ";

/// Lays `data` out as a Zarr folder at `dir` (emptied first): the bytes up
/// to the first [`ZARR_FILE_MARK`] are `zarr.json`, then each marked part
/// is one more file. Paths are kept only if every component is a plain
/// name (letters, digits, `.`, `_`, `-`; not `.` or `..`), so the harness
/// itself never writes outside `dir`; what the reader does with the
/// names in `zarr.json` (separators, keys) is what is fuzzed.
pub fn zarr_folder(data: &[u8], dir: &std::path::Path) {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).expect("scratch folder");
    let mut parts = split(data, ZARR_FILE_MARK).into_iter();
    let _ = std::fs::write(dir.join("zarr.json"), parts.next().unwrap_or_default());
    for part in parts.take(64) {
        let (name, bytes) = match part.iter().position(|&b| b == b'\n') {
            Some(n) => (&part[..n], &part[n + 1..]),
            None => (part, &[][..]),
        };
        let Ok(name) = std::str::from_utf8(name) else { continue };
        let plain = |c: &str| !c.is_empty() && c != "." && c != ".." && c.bytes().all(|b| b.is_ascii_alphanumeric() || b"._-".contains(&b));
        if name.is_empty() || !name.split('/').all(plain) {
            continue;
        }
        let path = dir.join(name);
        if let Some(parent) = path.parent() {
            let _ = std::fs::create_dir_all(parent);
        }
        let _ = std::fs::write(path, bytes);
    }
}

fn split<'a>(data: &'a [u8], mark: &[u8]) -> Vec<&'a [u8]> {
    let mut out = Vec::new();
    let mut rest = data;
    while let Some(at) = rest.windows(mark.len()).position(|w| w == mark) {
        out.push(&rest[..at]);
        rest = &rest[at + mark.len()..];
    }
    out.push(rest);
    out
}
