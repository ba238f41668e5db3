//! # topovox core
//!
//! Turns triangle meshes into voxel grids with an exactly stated guarantee.
//! This crate does no I/O: it knows nothing of files, clocks, environment or
//! logging. Readers and writers live in `topovox-io`, the command line in
//! `topovox-cli`.
//!
//! Entry points:
//! - [`GridSpec`] — origin, voxel size and dims; voxel `(i,j,k)` is the
//!   *closed* box `[origin + (i,j,k)·s, origin + (i+1,j+1,k+1)·s]`.
//! - [`MeshRef`] — a borrowed view of positions, triangles and segments.
//! - [`voxelize::fast`] and [`voxelize::reference`] — every surface and line
//!   mode ([`voxelize::Mode`], all 11): `cover`, Laine's `sep26` and
//!   `sep6`, Schwarz–Seidel `ss6`, the tunnel-free `tunnel18` and
//!   `tunnel26`, the randomized `bubble`, the single-`diagonal` target,
//!   the polyline modes `line26` and `line6`, and the published scanline
//!   algorithm `pos` (no guarantee, kept to measure); one file per mode,
//!   each with its brute-force reference (the definition). Also
//!   [`voxelize::scanline`] (the exact scanline path of `cover`, `sep26`,
//!   `sep6`) and [`voxelize::tiled`] (grids past memory, tile by tile).
//! - Solids ([`voxelize::solid`], [`voxelize::winding`],
//!   [`voxelize::fill`]): parity, the generalized winding number, flood
//!   fill of a surface shell, hollowing.
//! - [`distance`] — distance fields: the exact distance from voxel
//!   centres to the mesh, in a narrow band or on every voxel.
//! - [`query`] — the same distance, the closest point, the winding number
//!   and inside at any point ([`query::Query`]).
//! - [`attributes`] (colours, materials, normals, coverage carried into
//!   the voxels), [`export`] (greedy quads of the voxels' boundary) and
//!   [`render`] (CPU ray casting of a grid).
//! - [`raster`] — the same in 2D: curves (4-/8-connected) and fills.
//! - [`topology::certify()`] — components, separation (with a witness),
//!   thinness and tunnels of a voxel set.
//! - [`BrickBits`] (sparse, the fast paths' result) and [`DenseBits`]
//!   (one bit per voxel, the references' result), both [`VoxelSource`]s.
//!
//! # Guarantees
//! Every predicate is evaluated in exact integer arithmetic on vertices
//! snapped to the lattice described in [`geom::fixed`], so every path
//! (reference, fast, any thread count) returns bit-identical grids.

pub use glam;

pub mod aabb;
pub mod attributes;
pub mod choice;
pub mod distance;
pub mod export;
pub mod geom;
pub mod grid;
pub mod mesh;
pub mod mesh_check;
pub mod query;
pub mod raster;
pub mod render;
pub mod stop;
pub mod surface;
pub mod topology;
pub mod voxelize;

#[cfg(test)]
mod test_rng;

/// The crate's README, whose example is compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctest;

pub use aabb::Aabb;
pub use grid::bricks::BrickBits;
pub use grid::dense::DenseBits;
pub use grid::spec::{GridError, GridSpec, VoxelSize};
pub use grid::VoxelSource;
pub use mesh::{in_range, Mesh, MeshRef, COORDINATE_LIMIT, MIN_VOXEL_SIZE};
