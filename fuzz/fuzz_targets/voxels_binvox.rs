//! Fuzzes the .binvox voxel reader (what `check`, `convert` and `render`
//! read): any bytes give voxels or an error, never a panic; the voxels
//! read are inside their grid and carry at most one attribute per voxel.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(init: topovox_fuzz::fence_panics(), |data: &[u8]| topovox_fuzz::check_voxels(data, topovox_io::VoxelFormat::Binvox));
