//! Meshes of voxel results: [`greedy`] quads of the boundary faces.

pub mod greedy;
pub mod watertight;
