//! What the job tests share: the repository's files and plans.

// Each test file is its own crate and uses some of these.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use topovox::GridSpec;
use topovox_job::{GridOptions, GridRequest, Method, Mode, Plan, Request};

/// A path in the repository.
pub fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(p)
}

/// The plan of `mode` at `resolution` (tiles of `tile` when given), every
/// other option at its default.
pub fn plan(mode: &str, resolution: u64, tile: Option<u32>) -> Plan {
    let grid = GridOptions { resolution: Some(resolution), ..GridOptions::default() };
    plan_with(mode, Method::Auto, GridRequest::new(&grid).unwrap(), tile)
}

/// The plan of `mode` by `method` on `grid` (tiles of `tile` when given),
/// every other option at its default.
pub fn plan_with(mode: &str, method: Method, grid: GridRequest, tile: Option<u32>) -> Plan {
    Plan::new(Request {
        mode: Mode::parse(mode).unwrap(),
        method,
        grid,
        surface: None,
        fill: None,
        hollow: None,
        gpu_path: topovox_job::GpuPath::Compute,
        seed: 0,
        tile,
        max_memory: None,
        writer_bytes_per_brick: 0,
    })
    .unwrap()
}

/// The request for exactly `grid` (its origin, voxel size and dims).
pub fn on_grid(grid: &GridSpec) -> GridRequest {
    GridRequest::new(&GridOptions {
        origin: Some(grid.origin().to_array().to_vec()),
        voxel_size: Some(grid.voxel_size()),
        dims: Some(grid.dims().map(u64::from).to_vec()),
        ..GridOptions::default()
    })
    .unwrap()
}
