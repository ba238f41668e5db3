//! What the job tests share: the repository's files and plans.

use std::path::{Path, PathBuf};

use topovox_job::{GridOptions, GridRequest, Method, Mode, Plan, Request};

/// A path in the repository.
pub fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(p)
}

/// The plan of `mode` at `resolution` (tiles of `tile` when given), every
/// other option at its default.
pub fn plan(mode: &str, resolution: u64, tile: Option<u32>) -> Plan {
    let grid = GridOptions { resolution: Some(resolution), ..GridOptions::default() };
    Plan::new(Request {
        mode: Mode::parse(mode).unwrap(),
        method: Method::Auto,
        grid: GridRequest::new(&grid).unwrap(),
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
