//! Test helpers for topovox (not published): shared meshes, generated
//! meshes, random rotations, proptest strategies aimed at edge cases, and
//! the [`agree`] harness that runs every path on one input and names the
//! first differing voxel.

mod agree;
mod meshes;
mod placing;
pub mod strategies;

pub use agree::{agree, agree_mode, assert_whole_voxel_shift};
pub use meshes::{box_mesh, shared_mesh, shared_meshes_dir, soup, sphere, SHARED_MESHES};
pub use placing::{box_grid, random_rotation, rng, rotated, scaled_to_unit, unit_grid};
