//! Modes, methods and solid options by the names users give them, and the
//! validated plan of a job: which core mode and which path will run.

use topovox::choice::Choice;
use topovox::topology::runs::Connectivity;
use topovox::GridSpec;

use crate::error::{JobError, Result};
use crate::grid::GridRequest;
use crate::invalid;

topovox::choice! {
    /// A voxelization mode as the CLI and the Python package name it.
    pub enum Mode: "mode" default Cover {
        /// Conservative surface: every voxel whose closed box meets a triangle.
        Cover = "cover",
        /// Laine's minimal 26-separating surface (space-diagonal target).
        Sep26 = "sep26",
        /// Laine's thin 6-separating surface (3D crosshair target).
        Sep6 = "sep6",
        /// Schwarz–Seidel 6-separating surface.
        Ss6 = "ss6",
        /// 18-tunnel-free surface: targets from the centre to face centres and edge midpoints.
        Tunnel18 = "tunnel18",
        /// 26-tunnel-free surface: also from the centre to the corners.
        Tunnel26 = "tunnel26",
        /// Randomized 6-separating surface: the crosshair's joins at random points (seed).
        Bubble = "bubble",
        /// 6-separating surface from one alternating body diagonal per voxel.
        Diagonal = "diagonal",
        /// Solid: voxels whose centre is inside.
        Solid = "solid",
        /// Solid united with a surface mode (surface), so thin parts never vanish.
        SolidSurface = "solid+surface",
        /// 6-connected polyline voxelization.
        Line6 = "line6",
        /// 26-connected polyline voxelization.
        Line26 = "line26",
        /// Projected optimal scanline, as published.
        Pos = "pos",
    }
}

impl Mode {
    /// The user-facing name.
    pub fn name(self) -> &'static str {
        Choice::name(self)
    }

    /// The mode called `name`, in any case.
    pub fn parse(name: &str) -> Result<Mode> {
        Ok(Choice::parse(name)?)
    }

    /// Whether this is a solid mode.
    pub fn is_solid(self) -> bool {
        matches!(self, Mode::Solid | Mode::SolidSurface)
    }

    /// The core surface/line mode (solid modes have none); `bubble` with seed 0.
    pub fn core(self) -> Result<topovox::voxelize::Mode> {
        self.core_seeded(0)
    }

    /// The core surface/line mode, `bubble` drawing its points from `seed`.
    pub fn core_seeded(self, seed: u64) -> Result<topovox::voxelize::Mode> {
        use topovox::voxelize::Mode as Core;
        Ok(match self {
            Mode::Cover => Core::Cover,
            Mode::Sep26 => Core::Sep26,
            Mode::Sep6 => Core::Sep6,
            Mode::Ss6 => Core::Ss6,
            Mode::Line26 => Core::Line26,
            Mode::Line6 => Core::Line6,
            Mode::Pos => Core::Pos,
            Mode::Tunnel18 => Core::Tunnel18,
            Mode::Tunnel26 => Core::Tunnel26,
            Mode::Bubble => Core::Bubble { seed },
            Mode::Diagonal => Core::Diagonal,
            Mode::Solid | Mode::SolidSurface => invalid!("mode '{}' is a solid mode", self.name()),
        })
    }
}

topovox::choice! {
    /// A method as users name it.
    pub enum Method: "method" default Auto {
        /// The fastest correct method for the mode.
        Auto = "auto",
        /// The slow brute-force reference implementation of the mode.
        Reference = "reference",
        /// The triangle/box fast path (Schwarz & Seidel 2010), parallel.
        Fast = "fast",
        /// Projected optimal scanline fast path.
        Scanline = "scanline",
        /// GPU (wgpu).
        Gpu = "gpu",
        /// Solid by ray parity.
        Parity = "parity",
        /// Solid by generalized winding number.
        Winding = "winding",
    }
}

impl Method {
    /// The user-facing name.
    pub fn name(self) -> &'static str {
        Choice::name(self)
    }

    /// The method called `name`, in any case.
    pub fn parse(name: &str) -> Result<Method> {
        Ok(Choice::parse(name)?)
    }
}

pub use topovox::voxelize::GpuPath;

/// The surface/line paths a method can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceMethod {
    /// Brute force from the definition.
    Reference,
    /// The GPU compute path (`topovox-gpu`).
    Gpu,
    /// The triangle-box path (parallel, sparse).
    Fast,
    /// The exact scanline path (cover, sep26, sep6).
    Scanline,
}

impl SurfaceMethod {
    /// The name printed in summaries.
    pub fn name(self) -> &'static str {
        match self {
            SurfaceMethod::Reference => "reference",
            SurfaceMethod::Fast => "fast",
            SurfaceMethod::Scanline => "scanline",
            SurfaceMethod::Gpu => "gpu",
        }
    }
}

/// The core mode and the path that will run, or an error saying why none can.
/// `auto` resolves to the fast path here; once the mesh and grid are known,
/// [`auto_method`] may pick the scanline path or the GPU instead.
pub fn resolve_method(mode: Mode, method: Method) -> Result<(topovox::voxelize::Mode, SurfaceMethod)> {
    resolve_method_seeded(mode, method, 0)
}

/// [`resolve_method`] with the seed of `bubble`.
pub fn resolve_method_seeded(mode: Mode, method: Method, seed: u64) -> Result<(topovox::voxelize::Mode, SurfaceMethod)> {
    let core = mode.core_seeded(seed)?;
    let m = match method {
        Method::Auto | Method::Fast => SurfaceMethod::Fast,
        Method::Reference => SurfaceMethod::Reference,
        Method::Scanline if topovox::voxelize::scanline::supports(core) => SurfaceMethod::Scanline,
        Method::Scanline => {
            invalid!("--method scanline exists for cover, sep26 and sep6, not {}; use auto, fast or reference", mode.name())
        }
        Method::Gpu if !cfg!(feature = "gpu") => {
            invalid!("--method gpu: this topovox was built without the `gpu` feature; use auto, fast or reference")
        }
        Method::Gpu if gpu_has(core) => SurfaceMethod::Gpu,
        Method::Gpu => invalid!(
            "--method gpu exists for cover, sep26 and sep6 so far; {} on the GPU is not built yet (use auto, fast or reference)",
            mode.name()
        ),
        Method::Parity | Method::Winding => invalid!("--method {} applies only to --mode solid", method.name()),
    };
    Ok((core, m))
}

/// What `method auto` runs for a surface mode on this mesh and grid: a
/// hardware GPU on large grids of the modes it has, the scanline path
/// where it measured faster ([`topovox::voxelize::scanline::prefers`]), the
/// fast path otherwise. Also returns a note when probing for a GPU failed
/// in a way worth telling (never on a plain machine without one).
pub fn auto_method(mode: topovox::voxelize::Mode, mesh: topovox::MeshRef<'_>, grid: &GridSpec) -> (SurfaceMethod, Option<String>) {
    let (gpu, note) = gpu_preferred(mode, grid);
    if gpu {
        return (SurfaceMethod::Gpu, note);
    }
    if topovox::voxelize::scanline::prefers(mode, mesh, grid) {
        return (SurfaceMethod::Scanline, note);
    }
    (SurfaceMethod::Fast, note)
}

/// Grids from this many voxels on the longest side are offered to a
/// hardware GPU by `method auto`.
pub const GPU_AUTO_MIN_SIDE: u32 = 512;

/// `method auto` on a large `cover`, `sep26` or `sep6` job: is there a
/// hardware GPU adapter? Software adapters (lavapipe, WARP) are slower
/// than the CPU paths, so they are not used unless asked for.
#[cfg(feature = "gpu")]
fn gpu_preferred(mode: topovox::voxelize::Mode, grid: &GridSpec) -> (bool, Option<String>) {
    if !gpu_has(mode) || grid.dims().iter().copied().max().unwrap_or(0) < GPU_AUTO_MIN_SIDE {
        return (false, None);
    }
    match topovox_gpu::hardware_adapter() {
        Ok(hardware) => (hardware, None),
        Err(e) => (false, Some(format!("{e}; using the CPU"))),
    }
}

#[cfg(not(feature = "gpu"))]
fn gpu_preferred(_mode: topovox::voxelize::Mode, _grid: &GridSpec) -> (bool, Option<String>) {
    (false, None)
}

/// Does the GPU path have this surface mode?
#[cfg(feature = "gpu")]
pub fn gpu_has(mode: topovox::voxelize::Mode) -> bool {
    topovox_gpu::GpuMode::of(mode).is_some()
}

/// Does the GPU path have this surface mode?
#[cfg(not(feature = "gpu"))]
pub fn gpu_has(_mode: topovox::voxelize::Mode) -> bool {
    false
}

/// How a solid is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolidMethod {
    /// Parity if the mesh is closed and consistently oriented, else winding.
    Auto,
    /// Ray parity.
    Parity,
    /// Winding number.
    Winding,
    /// Brute-force exact winding number.
    Reference,
    /// Flood fill against a surface shell.
    Flood,
    /// Ray parity on the GPU.
    GpuParity,
}

/// A validated solid job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SolidPlan {
    /// How the inside is decided.
    pub method: SolidMethod,
    /// The surface united with the solid (`solid+surface`), or the shell of a flood fill.
    pub surface: Option<topovox::voxelize::Mode>,
    /// Keep only the skin, 6- or 26-connected to the outside.
    pub hollow: Option<Connectivity>,
}

impl SolidPlan {
    /// Whether it has a sparse path (for grids past memory): parity, the
    /// winding numbers (closed and generalized) and flood fills, alone or
    /// with a surface, hollowed or not; not the brute-force reference or
    /// the GPU.
    pub fn has_sparse_path(&self) -> bool {
        matches!(self.method, SolidMethod::Auto | SolidMethod::Parity | SolidMethod::Winding | SolidMethod::Flood)
    }
}

topovox::choice! {
    /// Solid filling strategies other than the inside test.
    pub enum Fill: "fill" {
        /// Everything not reachable from the grid boundary through unset
        /// voxels of a surface shell.
        Flood = "flood",
    }
}

topovox::choice! {
    /// Which voxels a hollowed solid keeps: those touching the outside.
    pub enum Hollow: "hollow connectivity" {
        /// Through a face.
        Six = "6",
        /// Through a face, an edge or a corner.
        TwentySix = "26",
    }
}

/// Everything a voxelization job is asked to do, before the mesh is read.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// The mode.
    pub mode: Mode,
    /// The method.
    pub method: Method,
    /// The grid.
    pub grid: GridRequest,
    /// Solid modes: the surface of `solid+surface` and of a flood fill's shell.
    pub surface: Option<Mode>,
    /// Solid modes: fill by flood instead of the inside test.
    pub fill: Option<Fill>,
    /// Solid modes: keep only the skin.
    pub hollow: Option<Hollow>,
    /// `method gpu`: which GPU path.
    pub gpu_path: GpuPath,
    /// `bubble`: the seed of its random points.
    pub seed: u64,
    /// Run the surface or line mode tile by tile with tiles of this many voxels (a
    /// multiple of 8); `None`: only when the grid does not fit densely.
    pub tile: Option<u32>,
    /// Memory the run may use (bytes); `None`: nine tenths of what is available.
    pub max_memory: Option<u64>,
    /// Bytes the output's writer holds per non-empty brick
    /// ([`crate::output::writer_bytes_per_brick`]; 0 when the voxels are
    /// not written, or streamed), counted when a tiled run's memory is
    /// checked before it starts.
    pub writer_bytes_per_brick: u64,
}

impl Request {
    /// A request for `mode` with every other option at its default.
    pub fn new(mode: Mode, grid: GridRequest) -> Request {
        Request {
            mode,
            method: Method::Auto,
            grid,
            surface: None,
            fill: None,
            hollow: None,
            gpu_path: GpuPath::Compute,
            seed: 0,
            tile: None,
            max_memory: None,
            writer_bytes_per_brick: 0,
        }
    }
}

/// A validated request.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// What was asked.
    pub request: Request,
    /// For solid modes, how the solid is made.
    pub solid: Option<SolidPlan>,
    /// For surface and line modes, the core mode.
    pub core: topovox::voxelize::Mode,
    /// For surface and line modes, the path (before `auto` sees the mesh).
    pub surface_method: SurfaceMethod,
}

impl Plan {
    /// Validates everything that does not need the mesh.
    pub fn new(request: Request) -> Result<Plan> {
        let solid = solid_plan(&request)?;
        if let Some(t) = request.tile {
            if t == 0 || t % 8 != 0 || t > 1 << 20 {
                return Err(JobError::invalid(format!("--tile {t}: must be a multiple of 8 from 8 to 1048576")));
            }
            if let Some(sp) = &solid {
                if !sp.has_sparse_path() {
                    return Err(JobError::invalid(
                        "--tile: the reference and gpu solids do not run tiled yet (parity, winding and flood fills do, hollowed or not)",
                    ));
                }
            } else if !matches!(request.method, Method::Auto | Method::Fast | Method::Scanline | Method::Gpu) {
                return Err(JobError::invalid("--tile runs the fast, scanline or gpu path: use --method auto, fast, scanline or gpu"));
            }
        }
        let (core, surface_method) = match solid {
            Some(_) => (topovox::voxelize::Mode::Cover, SurfaceMethod::Fast),
            None => resolve_method_seeded(request.mode, request.method, request.seed)?,
        };
        Ok(Plan { request, solid, core, surface_method })
    }

    /// Whether the job voxelizes polylines (line modes).
    pub fn is_line(&self) -> bool {
        self.solid.is_none() && matches!(self.core, topovox::voxelize::Mode::Line26 | topovox::voxelize::Mode::Line6)
    }
}

/// Validates the solid options: `None` for a surface or line mode (where
/// they are refused if given).
fn solid_plan(a: &Request) -> Result<Option<SolidPlan>> {
    if !a.mode.is_solid() {
        if a.fill.is_some() || a.hollow.is_some() || a.surface.is_some() {
            invalid!("--fill, --hollow and --surface apply to --mode solid and solid+surface");
        }
        return Ok(None);
    }
    let surface_mode = match a.surface.unwrap_or(Mode::Cover) {
        m @ (Mode::Cover | Mode::Sep26 | Mode::Sep6 | Mode::Ss6) => m.core()?,
        m => invalid!("--surface takes cover, sep26, sep6 or ss6, not {}", m.name()),
    };
    let method = match (a.fill, a.method) {
        (Some(Fill::Flood), Method::Auto) => SolidMethod::Flood,
        (Some(_), m) => invalid!("--fill flood replaces the inside test; it cannot be combined with --method {}", m.name()),
        (None, Method::Auto) => SolidMethod::Auto,
        (None, Method::Parity) => SolidMethod::Parity,
        (None, Method::Winding) => SolidMethod::Winding,
        (None, Method::Reference) => SolidMethod::Reference,
        (None, Method::Gpu) if !cfg!(feature = "gpu") => invalid!("--method gpu: this topovox was built without the `gpu` feature"),
        (None, Method::Gpu) => SolidMethod::GpuParity,
        (None, m) => invalid!("--method {} does not apply to solid modes (use auto, parity, winding or reference)", m.name()),
    };
    let surface = (a.mode == Mode::SolidSurface || method == SolidMethod::Flood).then_some(surface_mode);
    let hollow = a.hollow.map(|h| match h {
        Hollow::Six => Connectivity::Six,
        Hollow::TwentySix => Connectivity::TwentySix,
    });
    Ok(Some(SolidPlan { method, surface, hollow }))
}
