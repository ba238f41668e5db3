//! Fuzzes the .npy voxel reader (what `check`, `convert` and `render`
//! read): any bytes give voxels or an error, never a panic; the voxels
//! read are inside their grid and carry at most one attribute per voxel.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(
    init: {
        // Third-party parsers that panic on malformed input run inside
        // voxkit-io's fence, which turns the panic into an error (as the CLI
        // does); only panics outside it are crashes.
        let abort = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !voxkit_io::panic_is_fenced() {
                abort(info)
            }
        }));
    },
    |data: &[u8]| {
    if let Ok(v) = voxkit_io::read_voxels_bytes(data, voxkit_io::VoxelFormat::Npy) {
        let [nx, ny, nz] = v.bits.dims();
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
    }
);
