//! Where tests put meshes: random rotations, seeded generators, grids
//! fitted to a box, and meshes scaled or rotated onto them.

use glam::{DMat3, DQuat, DVec3};
use rand::{Rng, SeedableRng};
use topovox::{GridSpec, Mesh};

/// A uniformly random rotation.
pub fn random_rotation(rng: &mut impl Rng) -> DMat3 {
    loop {
        let q = DQuat::from_xyzw(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let len = q.length();
        if len > 0.1 && len <= 1.0 {
            return DMat3::from_quat(q / len);
        }
    }
}

/// A seeded RNG for reproducible tests.
pub fn rng(seed: u64) -> rand::rngs::SmallRng {
    rand::rngs::SmallRng::seed_from_u64(seed)
}

/// A grid of boxes fitted to `bounds`: each axis's edge a random 1 to 8
/// times `longest side / res` (so edges differ by up to 1:8, and no axis
/// has more than `res` voxels).
pub fn box_grid(bounds: &topovox::Aabb, res: u64, r: &mut impl Rng) -> GridSpec {
    let base = bounds.extent().max_element() / res as f64;
    let s = DVec3::new(base * r.random_range(1.0..8.0), base * r.random_range(1.0..8.0), base * r.random_range(1.0..8.0));
    GridSpec::from_voxel_size(bounds, s).unwrap()
}

/// `mesh` taken into index space of `grid` scaled per axis but not moved to
/// its origin: `p / s`; with [`unit_grid`] the same voxels are asked for on
/// unit cubes (the metamorphic twin of a grid of boxes).
pub fn scaled_to_unit(mesh: &Mesh, grid: &GridSpec) -> Mesh {
    let s = grid.voxel_size().0;
    let mut m = mesh.clone();
    m.transform(|p| p / s);
    m
}

/// `grid` with unit cubes and its origin divided by its voxel size: the grid
/// [`scaled_to_unit`]'s mesh is voxelized on.
pub fn unit_grid(grid: &GridSpec) -> GridSpec {
    GridSpec::new(grid.origin() / grid.voxel_size().0, 1.0, grid.dims().map(u64::from)).unwrap()
}

/// `mesh` rotated by `rot` about the centre of its bounding box.
pub fn rotated(mesh: &Mesh, rot: DMat3) -> Mesh {
    let b = mesh.as_ref().bounds();
    let c = (b.min + b.max) * 0.5;
    let mut m = mesh.clone();
    m.transform(|p| c + rot * (p - c));
    m
}
