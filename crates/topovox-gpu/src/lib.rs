//! # topovox-gpu
//!
//! GPU voxelization through wgpu (Vulkan, Metal, DX12), giving exactly the
//! CPU's voxels.
//!
//! **What it runs** (after M. Schwarz, H.-P. Seidel, "Fast Parallel
//! Surface and Solid Voxelization on GPUs", 2010), for `cover`, `sep26`
//! and `sep6` ([`Gpu::voxelize`], [`GpuMode`]) along three paths
//! ([`GpuPath`]):
//! - **compute** (`compute.rs`, `shaders/cover.wgsl`): one workgroup per
//!   triangle, its threads striding over the columns of the dominant-axis
//!   projection, bits set with `atomicOr`;
//! - **raster** (`shaders/raster.wgsl`): each triangle projected along its
//!   dominant axis in the vertex shader, conservative coverage (hardware
//!   where the adapter has it, else the pixel-aligned bounding rectangle
//!   culled by exact tests in the fragment shader) — the same voxels;
//! - **MSAA approximation**: 4× MSAA without conservative coverage, which
//!   never sets a wrong voxel but misses some (counted in the report).
//!
//! Many meshes go in one dispatch ([`Gpu::voxelize_stacked`], `stacked.rs`):
//! each moved by whole voxels into its own layers of one tall grid.
//!
//! And the **solid** by parity ([`Gpu::solid_parity`], `solid.rs`,
//! `shaders/solid.wgsl`): triangle-parallel parity flips with `atomicXor`
//! at each row's first inside voxel, then a prefix XOR per row — the
//! voxels of the CPU's parity solid. Every path processes the grid in
//! z-slabs that fit the device's buffer limits; what a device cannot do
//! (a viewport smaller than the grid, a layer past the buffer limit) is a
//! [`GpuError::Unsupported`] naming it.
//!
//! **Exactness.** Vertices are snapped on the CPU to the lattice every
//! topovox path uses ([`topovox::geom::lattice::prepare`]); the shader decides
//! each candidate voxel by the exact separating axis test of the CPU
//! reference, and for `sep26`/`sep6` by the modes' target tests with the
//! same tie rule (Laine's perturbation, predicate for predicate), in 64-bit
//! integers on coordinates relative to the triangle's box (the adapter
//! must offer `SHADER_INT64`). A triangle whose relative coordinates could
//! overflow those products (spanning more than about 126 voxels for
//! `cover`, 62 for the others) is voxelized by the CPU's exact fast path
//! instead, and the two results are OR-ed. So the output equals the CPU reference voxel for
//! voxel; the tests check it on every shared mesh, rotations and random
//! triangles.

mod compute;
pub mod device;
mod params;
mod slabs;
mod solid;
mod stacked;

pub use compute::{CoverReport, GpuMode, GpuPath, Timings};
pub use device::Device;
pub use solid::SolidGpuReport;
pub use stacked::StackedReport;
mod error;
mod gpu;
mod pipelines;

pub use device::{hardware_adapter, headless, quiet_without_display};
pub use error::GpuError;
pub use gpu::Gpu;
