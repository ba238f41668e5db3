//! Why the GPU path could not run: one error type, its messages naming
//! what is missing.

use thiserror::Error;

/// Why the GPU path could not run.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter (no Vulkan/Metal/DX12 driver).
    #[error("no GPU adapter found (install a Vulkan driver; on Linux without a GPU, Mesa's lavapipe: apt install mesa-vulkan-drivers)")]
    NoAdapter,
    /// The adapter lacks something the exact path needs.
    #[error("GPU adapter {adapter} lacks {what}")]
    MissingFeature {
        /// Adapter name.
        adapter: String,
        /// What is missing.
        what: &'static str,
    },
    /// The device could not be created or was lost.
    #[error("GPU device: {0}")]
    Device(String),
    /// A buffer could not be read back.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// A mode or feature the GPU path does not have yet.
    #[error("the GPU path does not support {0} yet")]
    Unsupported(String),
}
