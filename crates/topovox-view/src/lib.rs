//! # topovox-view
//!
//! topovox's GPU renderer of meshes and voxel grids, built after the
//! real-time renderer of seed 002 (`shared/seeds/002_*.txt`) on wgpu:
//!
//! - [`partition`]: the 8×8×8 scene partition into clusters, one indirect
//!   command each, the whole scene drawn by one
//!   `multi_draw_indexed_indirect` call;
//! - [`camera`]: the camera and the CPU reference of the GPU frustum test
//!   (world-space and clip-space separating axes), run in a compute pass
//!   (`shaders/cull.wgsl`);
//! - [`lights`]: lights merged from emissive triangles, attenuation
//!   `i / (d³ + 1)`, the 32³ light grid (built on the GPU by
//!   `shaders/grid.wgsl`; the CPU build is its reference);
//! - [`hiz`]: Hi-Z occlusion culling — a depth pass of the frustum
//!   survivors, a max-depth pyramid built on the GPU, each box tested at
//!   the level where it covers at most 2×2 texels (CPU reference kept),
//!   in one pass or two (the previous frame's clusters first);
//! - [`gpu`]: the frame — culling passes, optional Z-prepass, Blinn–Phong
//!   shading over the fragment's light-grid cell, gamma — rendered
//!   headless and read back;
//! - [`scenes`]: deterministic test scenes (the Cornell box, the city);
//! - [`spray`]: the ray spray into a point cloud (BVH, light samples,
//!   shadow rays), drawn as points lit towards the viewer each frame;
//! - `window` (feature `window`): the interactive viewer.
//!
//! Base-colour textures come from one texture array; the alpha test (glTF
//! `MASK`, OBJ `map_d`) runs in the depth passes and the shading pass.
//! The cluster boxes can be drawn over the picture (`shaders/boxes.wgsl`),
//! green where drawn and red where culled, and lines of text
//! (`shaders/text.wgsl`, font8x8 glyphs): the viewer's statistics.

pub mod camera;
pub mod gpu;
pub mod hiz;
pub mod lights;
pub mod partition;
pub mod scene;
pub mod scenes;
pub mod spray;
#[cfg(feature = "window")]
pub mod window;

pub use camera::Camera;
pub use gpu::{Culling, Frame, FrameOptions, FrameStats, GpuScene, Renderer};
pub use scene::Scene;

use thiserror::Error;

/// Why a frame could not be rendered.
#[derive(Debug, Error)]
pub enum ViewError {
    /// The device layer (`topovox_gpu::device`): no adapter, a device
    /// error, a failed readback.
    #[error(transparent)]
    Gpu(#[from] topovox_gpu::GpuError),
    /// Nothing to draw.
    #[error("the scene has no drawable triangles")]
    EmptyScene,
    /// The window could not be opened or presented to.
    #[error("window: {0} (a display is needed: set DISPLAY, or run under xvfb-run)")]
    Window(String),
    /// A picture larger than the device's textures.
    #[error("picture {width}x{height}: each side must be 1..={max} on this adapter")]
    Size {
        /// Asked width.
        width: u32,
        /// Asked height.
        height: u32,
        /// The adapter's largest texture side.
        max: u32,
    },
}

impl ViewError {
    /// A device error with this message.
    pub fn device(msg: String) -> ViewError {
        ViewError::Gpu(topovox_gpu::GpuError::Device(msg))
    }
}
