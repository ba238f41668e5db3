//! Stage two of argument handling: raw arguments → a validated plan.

use anyhow::{bail, Context, Result};
use glam::DVec3;
use voxkit::{Aabb, GridSpec};

use crate::args::{GridArgs, Method, Mode};

/// The grid request, validated but not yet fitted to a mesh.
#[derive(Clone, Debug)]
pub struct GridRequest {
    kind: GridKind,
    /// Voxels of margin on every side of a fitted grid.
    pad: u32,
}

#[derive(Clone, Debug)]
enum GridKind {
    /// Longest side spans N voxels.
    Resolution(u64),
    /// Fit to the bounding box with this voxel size.
    VoxelSize(f64),
    /// Fully explicit.
    Explicit { origin: DVec3, voxel_size: f64, dims: [u64; 3] },
}

impl GridRequest {
    /// Checks that the grid options form one of the three documented ways.
    pub fn from_args(g: &GridArgs) -> Result<GridRequest> {
        let kind = GridKind::from_args(g)?;
        let pad = g.pad.unwrap_or(0);
        if pad > 0 && matches!(kind, GridKind::Explicit { .. }) {
            bail!("--pad applies to fitted grids (--resolution or --voxel-size), not to an explicit --origin/--dims grid");
        }
        Ok(GridRequest { kind, pad })
    }

    /// The grid for a mesh with these bounds.
    pub fn fit(&self, bounds: &Aabb) -> Result<GridSpec> {
        let g = self.kind.fit(bounds)?;
        if self.pad == 0 {
            return Ok(g);
        }
        let (p, s) = (self.pad as f64, g.voxel_size());
        GridSpec::new(g.origin() - DVec3::splat(p * s), s, g.dims().map(|d| d as u64 + 2 * self.pad as u64)).context("invalid grid")
    }
}

impl GridKind {
    fn from_args(g: &GridArgs) -> Result<GridKind> {
        if g.origin.is_some() || g.dims.is_some() {
            let (Some(o), Some(s), Some(d)) = (&g.origin, g.voxel_size, &g.dims) else {
                bail!("an explicit grid needs all of --origin X,Y,Z --voxel-size S --dims NX,NY,NZ");
            };
            if o.len() != 3 || d.len() != 3 {
                bail!("--origin and --dims take three comma-separated values (X,Y,Z and NX,NY,NZ)");
            }
            if g.resolution.is_some() {
                bail!("--resolution cannot be combined with an explicit grid (--origin/--dims)");
            }
            return Ok(GridKind::Explicit { origin: DVec3::new(o[0], o[1], o[2]), voxel_size: s, dims: [d[0], d[1], d[2]] });
        }
        match (g.resolution, g.voxel_size) {
            (Some(_), Some(_)) => bail!("give either --resolution or --voxel-size, not both"),
            (Some(n), None) => Ok(GridKind::Resolution(n)),
            (None, Some(s)) => Ok(GridKind::VoxelSize(s)),
            (None, None) => Ok(GridKind::Resolution(128)),
        }
    }

    fn fit(&self, bounds: &Aabb) -> Result<GridSpec> {
        let g = match *self {
            GridKind::Resolution(n) => GridSpec::from_resolution(bounds, n),
            GridKind::VoxelSize(s) => GridSpec::from_voxel_size(bounds, s),
            GridKind::Explicit { origin, voxel_size, dims } => GridSpec::new(origin, voxel_size, dims),
        };
        g.context("invalid grid")
    }
}

/// The core surface/line mode of a CLI mode (solid modes are planned by
/// [`solid_plan`]).
pub fn core_mode(mode: Mode) -> Result<voxkit::voxelize::Mode> {
    use voxkit::voxelize::Mode as Core;
    Ok(match mode {
        Mode::Cover => Core::Cover,
        Mode::Sep26 => Core::Sep26,
        Mode::Sep6 => Core::Sep6,
        Mode::Ss6 => Core::Ss6,
        Mode::Line26 => Core::Line26,
        Mode::Line6 => Core::Line6,
        Mode::Pos => Core::Pos,
        Mode::Solid | Mode::SolidSurface => bail!("mode '{}' is a solid mode, planned by solid_plan", mode_name(mode)),
    })
}

/// The surface/line paths `--method` can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceMethod {
    /// Brute force from the definition.
    Reference,
    /// The GPU compute path (`voxkit-gpu`).
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
/// [`auto_method`] may pick the scanline path instead.
pub fn resolve_method(mode: Mode, method: Method) -> Result<(voxkit::voxelize::Mode, SurfaceMethod)> {
    let core = core_mode(mode)?;
    let m = match method {
        Method::Auto | Method::Fast => SurfaceMethod::Fast,
        Method::Reference => SurfaceMethod::Reference,
        Method::Scanline if voxkit::voxelize::scanline::supports(core) => SurfaceMethod::Scanline,
        Method::Scanline => {
            bail!("--method scanline exists for cover, sep26 and sep6, not {}; use auto, fast or reference", mode_name(mode))
        }
        Method::Gpu if !cfg!(feature = "gpu") => {
            bail!("--method gpu: this voxkit was built without the `gpu` feature; use auto, fast or reference")
        }
        Method::Gpu if gpu_has(core) => SurfaceMethod::Gpu,
        Method::Gpu => bail!(
            "--method gpu exists for cover, sep26 and sep6 so far; {} on the GPU is not built yet (use auto, fast or reference)",
            mode_name(mode)
        ),
        Method::Parity | Method::Winding => bail!("--method {} applies only to --mode solid", method_name(method)),
    };
    Ok((core, m))
}

/// What `--method auto` runs for a surface mode on this mesh and grid: the
/// scanline path where it measured faster ([`voxkit::voxelize::scanline::prefers`]:
/// `cover` and `sep26` on meshes whose triangles span a few voxels or
/// more, `sep6` on meshes of very large faces), the fast path otherwise.
pub fn auto_method(mode: voxkit::voxelize::Mode, mesh: voxkit::MeshRef<'_>, grid: &GridSpec) -> SurfaceMethod {
    if gpu_preferred(mode, grid) {
        return SurfaceMethod::Gpu;
    }
    if !voxkit::voxelize::scanline::prefers(mode, mesh, grid) {
        return SurfaceMethod::Fast;
    }
    SurfaceMethod::Scanline
}

/// Grids from this many voxels on the longest side are offered to a
/// hardware GPU by `--method auto`.
#[cfg(feature = "gpu")]
pub const GPU_AUTO_MIN_SIDE: u32 = 512;

/// `--method auto` on a large `cover`, `sep26` or `sep6` job: is there a hardware GPU adapter?
/// Software adapters (lavapipe, WARP) are slower than the CPU paths, so
/// they are not used unless asked for (`--method gpu`).
#[cfg(feature = "gpu")]
fn gpu_preferred(mode: voxkit::voxelize::Mode, grid: &GridSpec) -> bool {
    if !gpu_has(mode) || grid.dims().iter().copied().max().unwrap_or(0) < GPU_AUTO_MIN_SIDE {
        return false;
    }
    match voxkit_gpu::hardware_adapter() {
        Ok(hardware) => hardware,
        Err(e) => {
            eprintln!("voxkit: note: {e}; using the CPU");
            false
        }
    }
}

/// Does the GPU path have this surface mode?
#[cfg(feature = "gpu")]
fn gpu_has(mode: voxkit::voxelize::Mode) -> bool {
    voxkit_gpu::GpuMode::of(mode).is_some()
}

#[cfg(not(feature = "gpu"))]
fn gpu_has(_mode: voxkit::voxelize::Mode) -> bool {
    false
}

#[cfg(not(feature = "gpu"))]
fn gpu_preferred(_mode: voxkit::voxelize::Mode, _grid: &GridSpec) -> bool {
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
#[derive(Clone, Copy, Debug)]
pub struct SolidPlan {
    /// How the inside is decided.
    pub method: SolidMethod,
    /// The surface united with the solid (`solid+surface`), or the shell of a flood fill.
    pub surface: Option<voxkit::voxelize::Mode>,
    /// Keep only the skin, 6- or 26-connected to the outside.
    pub hollow: Option<voxkit::topology::runs::Connectivity>,
}

/// Validates the solid options: `None` for a surface or line mode (where
/// they are refused if given).
pub fn solid_plan(a: &crate::args::VoxelizeArgs) -> Result<Option<SolidPlan>> {
    use voxkit::topology::runs::Connectivity;
    let solid = matches!(a.mode, Mode::Solid | Mode::SolidSurface);
    if !solid {
        if a.fill.is_some() || a.hollow.is_some() || a.surface.is_some() {
            bail!("--fill, --hollow and --surface apply to --mode solid and solid+surface");
        }
        return Ok(None);
    }
    let surface_mode = match a.surface.unwrap_or(Mode::Cover) {
        m @ (Mode::Cover | Mode::Sep26 | Mode::Sep6 | Mode::Ss6) => core_mode(m)?,
        m => bail!("--surface takes cover, sep26, sep6 or ss6, not {}", mode_name(m)),
    };
    let method = match (a.fill, a.method) {
        (Some(crate::args::Fill::Flood), Method::Auto) => SolidMethod::Flood,
        (Some(_), m) => bail!("--fill flood replaces the inside test; it cannot be combined with --method {}", method_name(m)),
        (None, Method::Auto) => SolidMethod::Auto,
        (None, Method::Parity) => SolidMethod::Parity,
        (None, Method::Winding) => SolidMethod::Winding,
        (None, Method::Reference) => SolidMethod::Reference,
        (None, Method::Gpu) if !cfg!(feature = "gpu") => bail!("--method gpu: this voxkit was built without the `gpu` feature"),
        (None, Method::Gpu) => SolidMethod::GpuParity,
        (None, m) => bail!("--method {} does not apply to solid modes (use auto, parity, winding or reference)", method_name(m)),
    };
    let surface = (a.mode == Mode::SolidSurface || method == SolidMethod::Flood).then_some(surface_mode);
    let hollow = match a.hollow.as_deref() {
        None => None,
        Some("6") => Some(Connectivity::Six),
        Some(_) => Some(Connectivity::TwentySix),
    };
    Ok(Some(SolidPlan { method, surface, hollow }))
}

pub fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::Cover => "cover",
        Mode::Sep26 => "sep26",
        Mode::Sep6 => "sep6",
        Mode::Ss6 => "ss6",
        Mode::Solid => "solid",
        Mode::SolidSurface => "solid+surface",
        Mode::Line6 => "line6",
        Mode::Line26 => "line26",
        Mode::Pos => "pos",
    }
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::Auto => "auto",
        Method::Reference => "reference",
        Method::Fast => "fast",
        Method::Scanline => "scanline",
        Method::Gpu => "gpu",
        Method::Parity => "parity",
        Method::Winding => "winding",
    }
}

/// The voxel format of an output: `--format` if given, else the extension.
pub fn output_format(format: Option<&str>, output: &std::path::Path) -> Result<Output> {
    use voxkit_io::VoxelFormat;
    let parse = |name: &str| match name.to_ascii_lowercase().as_str() {
        "obj" => Some(Output::Mesh(MeshKind::Obj)),
        "glb" => Some(Output::Mesh(MeshKind::Glb)),
        n => VoxelFormat::from_name(n).map(Output::Voxels),
    };
    match format {
        Some(f) => parse(f).with_context(|| format!("unknown --format {f:?} (expected one of: {}, obj, glb)", VoxelFormat::NAMES)),
        None => output.extension().and_then(|e| e.to_str()).and_then(parse).with_context(|| {
            format!(
                "{}: cannot tell the output format from the extension (use one of: {}, obj, glb, or --format)",
                output.display(),
                VoxelFormat::NAMES
            )
        }),
    }
}

/// What an output file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// A voxel format.
    Voxels(voxkit_io::VoxelFormat),
    /// A mesh of the voxels (greedy quads).
    Mesh(MeshKind),
}

/// Mesh formats for the voxels' boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshKind {
    /// Wavefront OBJ (+ MTL with colours).
    Obj,
    /// Binary glTF.
    Glb,
}

impl Output {
    /// The `--format` name.
    pub fn name(self) -> &'static str {
        match self {
            Output::Voxels(f) => f.name(),
            Output::Mesh(MeshKind::Obj) => "obj",
            Output::Mesh(MeshKind::Glb) => "glb",
        }
    }

    /// True when the output stores colours.
    pub fn has_colour(self) -> bool {
        match self {
            Output::Voxels(f) => f.has_colour(),
            Output::Mesh(_) => true,
        }
    }
}

/// Memory available to this process, from `/proc/meminfo` (None if unknown).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Human-readable byte count.
pub fn bytes(n: u64) -> String {
    const U: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = n as f64;
    let mut u = 0;
    while v >= 1024.0 && u < U.len() - 1 {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{n} B")
    } else {
        format!("{v:.1} {}", U[u])
    }
}

/// Fails if a dense grid of `grid` would not fit in available memory.
pub fn check_memory(grid: &GridSpec) -> Result<()> {
    let need = grid.dense_bytes();
    if let Some(avail) = available_memory() {
        // Leave headroom for the mesh, the writer's buffers and the system.
        if need > avail / 10 * 9 {
            let [x, y, z] = grid.dims();
            bail!(
                "grid {x}x{y}x{z} needs {} of dense storage (1 bit per voxel) but only {} of memory is available; lower the resolution",
                bytes(need),
                bytes(avail)
            );
        }
    }
    Ok(())
}
