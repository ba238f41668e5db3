//! Pictures of results: [`raycast`], a headless CPU renderer of voxel grids.

pub mod raycast;
