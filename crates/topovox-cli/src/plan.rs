//! Stage two of argument handling: raw arguments → the job's validated
//! types (`topovox-job`, shared with the Python package and batches).

use anyhow::Result;
use topovox_job::{GridOptions, GridRequest};

/// Fails if a dense grid of `grid` would not fit in the memory available
/// (the commands that need one: render, bench, gaps).
pub fn check_memory(grid: &topovox::GridSpec) -> topovox_job::Result<()> {
    topovox_job::check_memory(grid, topovox_job::budget(None), "this command")
}

/// Checks that the grid options form one of the three documented ways.
pub fn grid_request(g: &GridOptions) -> Result<GridRequest> {
    Ok(GridRequest::new(g)?)
}

/// The core surface/line mode of a mode.
pub fn core_mode(mode: topovox_job::Mode) -> Result<topovox::voxelize::Mode> {
    Ok(mode.core()?)
}
