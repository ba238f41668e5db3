//! One file per subcommand.

pub mod batch;
pub mod bench;
mod brute;
pub mod check;
pub mod convert;
pub mod gaps;
pub mod info;
pub mod raster;
pub mod remesh;
pub mod render;
pub mod sample;
#[cfg(feature = "gpu")]
pub mod scene;
pub mod sdf;
#[cfg(feature = "gpu")]
pub mod spray;
#[cfg(feature = "gpu")]
pub mod view;
pub mod voxelize;
