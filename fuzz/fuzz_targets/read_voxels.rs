//! Fuzzes the voxel-file readers (npy, binvox, vox, text).
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox_io::VoxelFormat;

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    for f in
        [VoxelFormat::Npy, VoxelFormat::Binvox, VoxelFormat::Vox, VoxelFormat::Text, VoxelFormat::Schem, VoxelFormat::Vti, VoxelFormat::Ply, VoxelFormat::Vdb]
    {
        let _ = topovox_io::read_voxels_bytes(data, f, &topovox_io::ReadOptions::default());
    }
    }
);
