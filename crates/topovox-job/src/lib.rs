//! # topovox-job
//!
//! A voxelization job as the `topovox` command line, the Python package and
//! `topovox batch` run it, so all three take the same options, fit the same
//! grids, pick the same paths and produce the same voxels, bit for bit:
//!
//! - [`GridOptions`] → [`GridRequest`] (validated before the mesh is read)
//!   → a [`topovox::GridSpec`] fitted to the mesh;
//! - [`Request`] (mode, method, solid options) → [`Plan`] (validated) →
//!   [`voxelize`] on a mesh → [`Voxelized`] (voxels, grid, the path that
//!   ran, facts for summaries);
//! - [`distance`]: distance fields ([`distance::sdf`]), signed by the solid;
//! - [`attributes`] carries colours into them; [`output::write`] writes
//!   any format; [`check::report`] certifies them.
//!
//! Errors are one [`JobError`]: bad options ([`JobError::Invalid`]), file
//! problems naming the file ([`JobError::Io`]), or failures while running.

mod error;
mod grid;
mod job;
mod memory;
mod plan;
mod run;
mod solid;

pub mod batch;
pub mod check;
pub mod distance;
pub mod facts;
pub mod many;
pub mod options;
pub mod output;
pub mod remesh;
pub mod sample;
pub mod table;

pub use error::{JobError, Result};
pub use grid::{Fit, GridOptions, GridRequest};
pub use job::{Done, Keep, Made, SdfDone, SdfJob, VoxelizeJob, Voxelizer};
pub use memory::{available_memory, budget, bytes, check_memory, dense_fits, parse_size, peak_memory, query_bytes};
pub use options::{ExportOptions, JobOptions, RunOptions, KEYWORDS};
pub use plan::{
    auto_method, gpu_has, resolve_method, Fill, GpuPath, Hollow, Method, Mode, Plan, Request, SolidMethod, SolidPlan, SurfaceMethod,
    GPU_AUTO_MIN_SIDE,
};
pub use run::{attributes, check_attributes_carried, every_attribute, voxelize, Voxelized, Voxels, ATTRIBUTE_BYTES_PER_VOXEL};
pub use solid::{has_volume, Outcome as SolidOutcome};
pub use table::{Keyword, OptionValue, Table};
pub use topovox::attributes::ColourRule;
pub use topovox::choice::{Choice, Switch, UnknownChoice};
pub use topovox_io::orient::Up;

/// The most worker threads any front end starts (`--threads`, `--jobs`,
/// `threads=`, `jobs=`): far more than cores only costs memory and time
/// (each thread reserves a stack), and a typo of a few zeros must not
/// start a million.
pub const MAX_THREADS: usize = 1024;

/// Checks a thread count given as `what` (the option's name as the user
/// wrote it: `--threads`, `--jobs`, `threads`): 1 to [`MAX_THREADS`].
pub fn check_threads(threads: usize, what: &str) -> Result<()> {
    if threads == 0 {
        return Err(JobError::invalid(format!("{what} must be at least 1")));
    }
    if threads > MAX_THREADS {
        let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
        return Err(JobError::invalid(format!("{what} {threads}: at most {MAX_THREADS} (this machine has {cores} cores)")));
    }
    Ok(())
}

/// A rayon pool of `threads` workers, of this call's own (`threads` is
/// checked by [`check_threads`]). Never shared: calls from different
/// threads (Python threads, a batch's meshes, Dask tasks) that each ask
/// for one thread run side by side, where one kept pool per count made
/// them queue on its single worker. Starting threads costs tens of
/// microseconds each; they end when the pool is dropped.
pub fn pool(threads: usize) -> Result<rayon::ThreadPool> {
    pool_for(Some(threads), "threads")
}

/// The one pool builder of every front end (`--threads`, `--jobs`,
/// `threads=`, `jobs=`): `threads` workers, or with `None` one per core
/// (rayon's default, which `RAYON_NUM_THREADS` overrides); the count is
/// named `what` in errors.
pub fn pool_for(threads: Option<usize>, what: &str) -> Result<rayon::ThreadPool> {
    if let Some(n) = threads {
        check_threads(n, what)?;
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| JobError::failed(format!("cannot start {} worker threads: {e}", threads.map_or("the".into(), |n| n.to_string()))))
}
