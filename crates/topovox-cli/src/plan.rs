//! Stage two of argument handling: raw arguments → the job's validated
//! types (`topovox-job`, shared with the Python package and batches).

use anyhow::Result;
use topovox_job::{GridOptions, GridRequest};

use crate::args::{Fill, GpuPathArg, GridArgs, MemoryArgs, Method, Mode, VoxelizeArgs};

/// Fails if a dense grid of `grid` would not fit in the memory available
/// (the commands that need one: render, bench, gaps).
pub fn check_memory(grid: &topovox::GridSpec) -> topovox_job::Result<()> {
    topovox_job::check_memory(grid, topovox_job::budget(None), "this command")
}

impl From<Mode> for topovox_job::Mode {
    fn from(m: Mode) -> topovox_job::Mode {
        use topovox_job::Mode as J;
        match m {
            Mode::Cover => J::Cover,
            Mode::Sep26 => J::Sep26,
            Mode::Sep6 => J::Sep6,
            Mode::Ss6 => J::Ss6,
            Mode::Solid => J::Solid,
            Mode::SolidSurface => J::SolidSurface,
            Mode::Line6 => J::Line6,
            Mode::Line26 => J::Line26,
            Mode::Pos => J::Pos,
            Mode::Tunnel18 => J::Tunnel18,
            Mode::Tunnel26 => J::Tunnel26,
            Mode::Bubble => J::Bubble,
            Mode::Diagonal => J::Diagonal,
        }
    }
}

impl From<Method> for topovox_job::Method {
    fn from(m: Method) -> topovox_job::Method {
        use topovox_job::Method as J;
        match m {
            Method::Auto => J::Auto,
            Method::Reference => J::Reference,
            Method::Fast => J::Fast,
            Method::Scanline => J::Scanline,
            Method::Gpu => J::Gpu,
            Method::Parity => J::Parity,
            Method::Winding => J::Winding,
        }
    }
}

/// The grid options as the job takes them.
pub fn grid_options(g: &GridArgs) -> GridOptions {
    GridOptions { resolution: g.resolution, voxel_size: g.voxel_size, origin: g.origin.clone(), dims: g.dims.clone(), pad: g.pad }
}

/// Checks that the grid options form one of the three documented ways.
pub fn grid_request(g: &GridArgs) -> Result<GridRequest> {
    Ok(GridRequest::new(&grid_options(g))?)
}

/// The validated plan of `topovox voxelize`.
pub fn voxelize_plan(a: &VoxelizeArgs) -> Result<topovox_job::Plan> {
    plan_from(a.mode, a.method, &a.grid, a.surface, a.fill, a.hollow.as_deref(), a.gpu_path, a.seed, &a.memory)
}

/// A validated plan from the voxelization options of `voxelize` and `batch`.
#[allow(clippy::too_many_arguments)]
pub fn plan_from(
    mode: Mode,
    method: Method,
    grid: &GridArgs,
    surface: Option<Mode>,
    fill: Option<Fill>,
    hollow: Option<&str>,
    gpu_path: GpuPathArg,
    seed: u64,
    memory: &MemoryArgs,
) -> Result<topovox_job::Plan> {
    let request = topovox_job::Request {
        mode: mode.into(),
        method: method.into(),
        grid: grid_request(grid)?,
        surface: surface.map(Into::into),
        fill: fill.map(|f| match f {
            Fill::Flood => topovox_job::Fill::Flood,
        }),
        hollow: hollow.map(|h| if h == "6" { 6 } else { 26 }),
        gpu_path: gpu_path_name(gpu_path).1,
        seed,
        tile: memory.tile,
        max_memory: memory.max_memory.as_deref().map(topovox_job::parse_size).transpose()?,
        writer_bytes_per_brick: 0,
    };
    Ok(topovox_job::Plan::new(request)?)
}

/// The name and the job's value of `--gpu-path`.
pub fn gpu_path_name(p: GpuPathArg) -> (&'static str, topovox_job::GpuPath) {
    match p {
        GpuPathArg::Compute => ("compute", topovox_job::GpuPath::Compute),
        GpuPathArg::Raster => ("raster", topovox_job::GpuPath::Raster),
        GpuPathArg::MsaaApprox => ("msaa-approx", topovox_job::GpuPath::MsaaApprox),
    }
}

/// The core surface/line mode of a CLI mode.
pub fn core_mode(mode: Mode) -> Result<topovox::voxelize::Mode> {
    Ok(topovox_job::Mode::from(mode).core()?)
}

/// The user-facing name of a mode.
pub fn mode_name(m: Mode) -> &'static str {
    topovox_job::Mode::from(m).name()
}
