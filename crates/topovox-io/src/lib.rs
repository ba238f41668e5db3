//! # topovox-io
//!
//! Readers for triangle meshes (OBJ with MTL and textures, STL, PLY,
//! glTF/GLB), polylines (`.lines`, OBJ `l`) and SVG outlines, and writers
//! and readers for voxel grids: NumPy `.npy` and `.npz`, binvox,
//! MagicaVoxel `.vox`, Minecraft `.schem`, text, VTK `.vti`, PLY point
//! clouds, OpenVDB `.vdb`, Zarr v3, and meshes of the voxels (`.obj`,
//! `.glb`); PNG pictures. One file per format. Every failure is an [`IoError`] naming the file and
//! the problem; no reader panics on malformed input (the third-party
//! parsers are additionally fenced with `catch_unwind`).
//!
//! **Architecture Invariant:** outputs are written to a temporary file in the
//! destination directory and renamed into place, so a failure never leaves a
//! half-written file ([`atomic::write_atomically`]).

pub mod atomic;
pub mod binvox;
mod budget;
pub mod error;
mod fence;
mod former_name;
pub mod gltf;
mod load_estimate;
pub mod mesh_out;
pub mod mesh_report;
mod meshes;
pub mod npy;
pub mod npz;
pub mod obj;
pub mod off;
pub mod orient;
pub mod pixels;
pub mod ply;
mod ply_ascii;
mod ply_binary;
mod ply_payload;
pub mod png;
pub mod points;
pub mod polyline;
mod resources;
mod runs;
pub mod schem;
mod spacing;
pub mod spray_cloud;
pub mod stl;
pub mod svg;
pub mod text;
pub mod texture;
pub mod vdb;
pub mod vox;
pub mod voxel_mesh;
mod voxels;
pub mod vti;
pub mod zarr;

pub use budget::{available_memory, bytes, set_dense_read_budget};
pub(crate) use budget::{dense_grid, read_limit, UNCHECKED_BYTES};
pub use error::{ErrorKind, IoError};
pub use fence::{fenced, panic_is_fenced};
pub use mesh_report::{validate_mesh, LoadedMesh, MeshReport};
pub use meshes::{is_mesh_file, read_mesh, read_mesh_bytes, read_svg, MeshFormat};
pub use png::{write_png, write_png_rgba};
pub use resources::{open_regular, read_regular, ReadOptions};
pub(crate) use runs::runs;
pub(crate) use spacing::half_diagonal;
pub use spacing::{size_from_json, size_json};
pub use voxels::{
    is_voxel_file, read_voxels, read_voxels_bytes, read_voxels_sparse, write_voxels, write_voxels_with, LoadedVoxels, SparseVoxels,
    VoxelFormat, WriteOptions,
};
