//! Stage two of argument handling: raw arguments → the job's validated
//! types (`voxkit-job`, shared with the Python package and batches).

use anyhow::Result;
use voxkit_job::{GridOptions, GridRequest};

use crate::args::{Fill, GpuPathArg, GridArgs, MemoryArgs, Method, Mode, VoxelizeArgs};

/// Fails if a dense grid of `grid` would not fit in the memory available
/// (the commands that need one: render, bench, gaps).
pub fn check_memory(grid: &voxkit::GridSpec) -> voxkit_job::Result<()> {
    voxkit_job::check_memory(grid, voxkit_job::budget(None), "this command")
}

impl From<Mode> for voxkit_job::Mode {
    fn from(m: Mode) -> voxkit_job::Mode {
        use voxkit_job::Mode as J;
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

impl From<Method> for voxkit_job::Method {
    fn from(m: Method) -> voxkit_job::Method {
        use voxkit_job::Method as J;
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

/// The validated plan of `voxkit voxelize`.
pub fn voxelize_plan(a: &VoxelizeArgs) -> Result<voxkit_job::Plan> {
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
) -> Result<voxkit_job::Plan> {
    let request = voxkit_job::Request {
        mode: mode.into(),
        method: method.into(),
        grid: grid_request(grid)?,
        surface: surface.map(Into::into),
        fill: fill.map(|f| match f {
            Fill::Flood => voxkit_job::Fill::Flood,
        }),
        hollow: hollow.map(|h| if h == "6" { 6 } else { 26 }),
        gpu_path: gpu_path_name(gpu_path).1,
        seed,
        tile: memory.tile,
        max_memory: memory.max_memory.as_deref().map(voxkit_job::parse_size).transpose()?,
    };
    Ok(voxkit_job::Plan::new(request)?)
}

/// The name and the job's value of `--gpu-path`.
pub fn gpu_path_name(p: GpuPathArg) -> (&'static str, voxkit_job::GpuPath) {
    match p {
        GpuPathArg::Compute => ("compute", voxkit_job::GpuPath::Compute),
        GpuPathArg::Raster => ("raster", voxkit_job::GpuPath::Raster),
        GpuPathArg::MsaaApprox => ("msaa-approx", voxkit_job::GpuPath::MsaaApprox),
    }
}

/// The core surface/line mode of a CLI mode.
pub fn core_mode(mode: Mode) -> Result<voxkit::voxelize::Mode> {
    Ok(voxkit_job::Mode::from(mode).core()?)
}

/// The user-facing name of a mode.
pub fn mode_name(m: Mode) -> &'static str {
    voxkit_job::Mode::from(m).name()
}
