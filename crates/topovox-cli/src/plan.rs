//! Stage two of argument handling: raw arguments → the job's validated
//! types (`topovox-job`, shared with the Python package and batches).

use anyhow::Result;
use topovox_job::{GridOptions, GridRequest, JobOptions};

use crate::args::{ExportArgs, GridArgs, JobArgs};

/// Fails if a dense grid of `grid` would not fit in the memory available
/// (the commands that need one: render, bench, gaps).
pub fn check_memory(grid: &topovox::GridSpec) -> topovox_job::Result<()> {
    topovox_job::check_memory(grid, topovox_job::budget(None), "this command")
}

/// The grid options as the job takes them.
pub fn grid_options(g: &GridArgs) -> GridOptions {
    GridOptions {
        resolution: g.resolution,
        voxel_size: g.voxel_size,
        origin: g.origin.clone(),
        dims: g.dims.clone(),
        pad: g.pad,
        fit: g.fit,
    }
}

/// Checks that the grid options form one of the three documented ways.
pub fn grid_request(g: &GridArgs) -> Result<GridRequest> {
    Ok(GridRequest::new(&grid_options(g))?)
}

/// The export flags into `o` (those `convert` shares with the job flags).
pub fn export_options(e: &ExportArgs, o: &mut JobOptions) {
    o.colour_rule = e.colour_rule;
    o.normals = e.normals;
    o.attributes = e.attributes;
    o.dither = e.dither;
    o.block_palette = e.block_palette.clone();
    o.up = e.up.unwrap_or_default();
    o.watertight = e.watertight.is_none_or(|w| w.on());
    o.triangulate = e.triangulate;
}

/// The job options of `voxelize` and `batch`.
pub fn job_options(a: &JobArgs, threads: Option<usize>) -> Result<JobOptions> {
    let mut o = JobOptions {
        mode: a.mode,
        method: a.method,
        grid: grid_options(&a.grid),
        surface: a.surface,
        fill: a.fill,
        hollow: a.hollow,
        gpu_path: a.gpu_path,
        seed: a.seed,
        tile: a.memory.tile,
        max_memory: a.memory.max_memory,
        allow_external_paths: a.allow_external_paths,
        threads,
        ..JobOptions::default()
    };
    export_options(&a.export, &mut o);
    Ok(o)
}

/// The core surface/line mode of a mode.
pub fn core_mode(mode: topovox_job::Mode) -> Result<topovox::voxelize::Mode> {
    Ok(mode.core()?)
}
