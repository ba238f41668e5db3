//! Fuzzes the voxel-file readers (npy, binvox, vox, text).
#![no_main]

use libfuzzer_sys::fuzz_target;
use voxkit_io::VoxelFormat;

fuzz_target!(|data: &[u8]| {
    for f in
        [VoxelFormat::Npy, VoxelFormat::Binvox, VoxelFormat::Vox, VoxelFormat::Text, VoxelFormat::Schem, VoxelFormat::Vti, VoxelFormat::Ply]
    {
        let _ = voxkit_io::read_voxels_bytes(data, f);
    }
});
