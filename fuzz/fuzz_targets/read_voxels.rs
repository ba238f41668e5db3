//! Fuzzes the voxel-file readers (npy, binvox, vox, text).
#![no_main]

use libfuzzer_sys::fuzz_target;
use voxkit_io::VoxelFormat;

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
    for f in
        [VoxelFormat::Npy, VoxelFormat::Binvox, VoxelFormat::Vox, VoxelFormat::Text, VoxelFormat::Schem, VoxelFormat::Vti, VoxelFormat::Ply]
    {
        let _ = voxkit_io::read_voxels_bytes(data, f);
    }
    }
);
