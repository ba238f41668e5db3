//! Running a planned job on a loaded mesh: the voxels, and the facts the
//! summaries report.

use std::time::Instant;

use serde_json::{json, Value};
use topovox::attributes::carry::{carry, CarryOptions};
use topovox::attributes::{Appearance, VoxelAttributes};
use topovox::grid::bricks::BrickBits;
use topovox::grid::sparse::SparseBricks;
use topovox::voxelize::{self, Options, Progress, Report, Stop};
use topovox::{DenseBits, GridSpec, MeshRef, VoxelSource};

use crate::error::{JobError, Result};
#[cfg(feature = "gpu")]
use crate::facts::GpuCounts;
use crate::facts::{GpuFacts, SolidFacts};
use crate::plan::{GpuPath, Plan, SolidPlan, SurfaceMethod};

/// A voxel set in whichever storage the path produced.
#[derive(Clone, Debug)]
pub enum Voxels {
    /// One bit per voxel (references, solids).
    Dense(DenseBits),
    /// Sparse 8³ bricks (the fast paths).
    Bricks(BrickBits),
    /// Sorted non-empty bricks (the tiled path, grids past a brick index).
    Sparse(SparseBricks),
}

impl Voxels {
    /// The voxels as a [`VoxelSource`].
    pub fn source(&self) -> &(dyn VoxelSource + Send + Sync) {
        match self {
            Voxels::Dense(d) => d,
            Voxels::Bricks(b) => b,
            Voxels::Sparse(s) => s,
        }
    }

    /// The same voxels, dense.
    pub fn to_dense(&self) -> DenseBits {
        match self {
            Voxels::Dense(d) => d.clone(),
            Voxels::Bricks(b) => b.to_dense(),
            Voxels::Sparse(s) => s.to_dense(),
        }
    }
}

impl VoxelSource for Voxels {
    fn dims(&self) -> [u32; 3] {
        self.source().dims()
    }
    fn count(&self) -> u64 {
        self.source().count()
    }
    fn for_each_set(&self, f: &mut dyn FnMut(u32, u32, u32)) {
        self.source().for_each_set(f)
    }
    fn fill_i_planes(&self, i0: u32, count: u32, k_fastest: bool, out: &mut [u8]) {
        self.source().fill_i_planes(i0, count, k_fastest, out)
    }
    fn for_each_brick(&self, f: &mut dyn FnMut([u32; 3], &topovox::grid::bricks::Brick)) {
        self.source().for_each_brick(f)
    }
}

/// What a job made.
#[derive(Debug)]
pub struct Voxelized {
    /// The voxels.
    pub voxels: Voxels,
    /// The grid they are on.
    pub grid: GridSpec,
    /// The path that ran (`fast`, `scanline`, `reference`, `gpu`, `parity`, …).
    pub method: &'static str,
    /// Triangle preparation counts (zero for solids) and the voxel count.
    pub report: Report,
    /// Solid modes: closedness, the winding number's work, fill and hollow facts.
    pub solid: Option<SolidFacts>,
    /// The GPU path: adapter, timings, triangles on each side.
    pub gpu: Option<GpuFacts>,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// Seconds spent voxelizing: from the loaded mesh to the voxels in
    /// memory (fitting the grid and choosing the path included).
    pub voxelize_s: f64,
    /// The tile edge when the tiled path ran.
    pub tile: Option<u32>,
    /// The kernel each tile ran (surface modes on the tiled path).
    pub tile_kernel: Option<&'static str>,
}

/// The mesh's refusal (a surface mode on segments alone) or what the
/// user should know before voxelizing it.
pub(crate) fn input_warnings(plan: &Plan, mesh: MeshRef<'_>, name: &str) -> Result<Vec<String>> {
    let is_line = plan.is_line();
    if !is_line && mesh.triangles.is_empty() {
        return Err(JobError::invalid(format!(
            "{name}: has only line segments; surface modes need triangles (use --mode line26 or line6)"
        )));
    }
    Ok(if !is_line && !mesh.segments.is_empty() {
        vec![format!(
            "{name}: {} line segments ignored by surface mode {} (line26 and line6 voxelize them)",
            mesh.segments.len(),
            plan.request.mode.name()
        )]
    } else {
        Vec::new()
    })
}

/// What the user should know of a result: empty, or with primitives skipped.
pub(crate) fn output_warnings(plan: &Plan, name: &str, report: &Report, warnings: &mut Vec<String>) {
    let p = report.prepare;
    if report.voxels == 0 {
        warnings.push(if plan.solid.is_none() && p.input > 0 && p.outside + p.degenerate + p.non_finite + p.invalid_index == p.input {
            format!("{name}: the result is empty: every triangle lies outside the grid (or is degenerate)")
        } else {
            format!("{name}: the result is empty: no voxel is set")
        });
    }
    if p.non_finite + p.invalid_index > 0 {
        warnings.push(format!("{name}: skipped {} primitives with invalid vertices", p.non_finite + p.invalid_index));
    }
}

/// Runs `plan` on `mesh` (named `name` in messages) on the grid its request
/// fits to `bounds`. Runs on the current rayon pool. Once `stop` is
/// requested the work left is skipped and the result is
/// [`JobError::Interrupted`].
pub fn voxelize(plan: &Plan, mesh: MeshRef<'_>, name: &str, progress: Option<&dyn Progress>, stop: Option<&Stop>) -> Result<Voxelized> {
    let mut warnings = input_warnings(plan, mesh, name)?;
    let t = Instant::now();
    let grid = plan.request.grid.fit(&mesh.bounds())?;
    let budget = crate::memory::budget(plan.request.max_memory);
    let tile = tile_for(plan, &grid, budget);
    if tile.is_none() {
        let why = if plan.solid.is_some() {
            "the reference and gpu solids (not tiled yet; parity, winding and flood fills are, hollowed or not)"
        } else {
            "--method reference (the fast, scanline and gpu paths are tiled)"
        };
        crate::memory::check_memory(&grid, budget, why)?;
    }
    let surface_method = if plan.request.method == crate::plan::Method::Auto && plan.solid.is_none() {
        crate::plan::auto_method(plan.core, mesh, &grid).0
    } else {
        plan.surface_method
    };
    let mut opts = Options { progress, stop, ..Options::default() };
    if tile.is_some() {
        opts.brick_capacity = brick_capacity(plan, mesh, &grid, name, budget)?;
    }
    let opts = opts;
    let mut gpu = None;
    let mut tile_kernel = None;
    let (voxels, report, method, solid) = if let (Some(t), Some(sp)) = (tile, &plan.solid) {
        let out = crate::solid::run_sparse(sp, mesh, name, &grid, t, &opts)?;
        warnings.extend(out.warnings);
        let voxels = out.bits.count();
        (Voxels::Sparse(out.bits), Report { voxels, prepare: Default::default() }, out.method, Some(out.facts))
    } else if let (Some(t), SurfaceMethod::Gpu) = (tile, surface_method) {
        // Each tile on the GPU: the same voxels as the GPU on the whole grid.
        let (s, r, facts) = gpu_tiled(plan.core, plan.request.gpu_path, mesh, &grid, t, &opts)?;
        gpu = Some(facts);
        tile_kernel = Some("gpu");
        (Voxels::Sparse(s), r, "tiled", None)
    } else if let Some(t) = tile {
        // Each tile runs the fast path's kernel, or the scanline path's when
        // asked for (`auto` keeps the fast one: on the bunny at 4096–16384
        // the two are within 5–12 %, the kernels being a small part of a
        // tiled run; BENCHMARKS.md).
        let (kernel, name) = match plan.request.method {
            crate::plan::Method::Scanline => (voxelize::tiled::TileKernel::Scanline, "scanline"),
            _ => (voxelize::tiled::TileKernel::Fast, "fast"),
        };
        let (s, r) = voxelize::tiled::tiled_with(plan.core, kernel, mesh, &grid, t, &opts).map_err(|e| JobError::invalid(e.to_string()))?;
        tile_kernel = Some(name);
        (Voxels::Sparse(s), r, "tiled", None)
    } else if let Some(sp) = &plan.solid {
        let out = crate::solid::run(sp, mesh, name, &grid, &opts)?;
        warnings.extend(out.warnings);
        let voxels = out.bits.count();
        (Voxels::Dense(out.bits), Report { voxels, prepare: Default::default() }, out.method, Some(out.facts))
    } else {
        let (v, r) = untiled_surface(plan, surface_method, mesh, &grid, &opts, (&mut gpu, &mut warnings))?;
        (v, r, surface_method.name(), None)
    };
    if stop.is_some_and(Stop::requested) {
        return Err(JobError::Interrupted);
    }
    let voxelize_s = t.elapsed().as_secs_f64();
    output_warnings(plan, name, &report, &mut warnings);
    Ok(Voxelized { voxels, grid, method, report, solid, gpu, warnings, voxelize_s, tile, tile_kernel })
}

/// A tiled surface (or sparse solid) holds its non-empty bricks: refused
/// before any work when they would not fit in `budget`, and their count
/// (to reserve at once) otherwise.
fn brick_capacity(plan: &Plan, mesh: MeshRef<'_>, grid: &GridSpec, name: &str, budget: u64) -> Result<usize> {
    let mut e = match &plan.solid {
        None => crate::memory::tiled_estimate(mesh, grid),
        Some(sp) => crate::memory::sparse_solid_estimate(mesh, grid, sp.method == crate::plan::SolidMethod::Flood),
    };
    e.bytes += e.bricks * plan.request.writer_bytes_per_brick;
    if e.bytes > budget {
        let [x, y, z] = grid.dims();
        return Err(JobError::failed(format!(
            "{name}: the {} on the {x}x{y}x{z} grid needs about {} (up to {} bricks of 8x8x8 voxels), more than the {} this run may use; raise --max-memory or lower the resolution",
            if plan.solid.is_some() { "solid" } else { "surface" },
            crate::memory::bytes(e.bytes),
            e.bricks,
            crate::memory::bytes(budget)
        )));
    }
    Ok(usize::try_from(e.bricks).unwrap_or(0))
}

/// A surface or line mode on the whole grid by `method`; the GPU's facts
/// and warnings go to `out`.
fn untiled_surface(
    plan: &Plan,
    method: SurfaceMethod,
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    opts: &Options<'_>,
    out: (&mut Option<GpuFacts>, &mut Vec<String>),
) -> Result<(Voxels, Report)> {
    let mode = plan.core;
    Ok(match method {
        SurfaceMethod::Reference => {
            let (b, r) = voxelize::reference(mode, mesh, grid);
            (Voxels::Dense(b), r)
        }
        SurfaceMethod::Scanline => {
            let (b, r) = voxelize::scanline::scanline(mode, mesh, grid, opts)
                .ok_or_else(|| JobError::invalid(format!("--method scanline exists for cover, sep26 and sep6, not {}", mode.name())))?;
            (Voxels::Bricks(b), r)
        }
        SurfaceMethod::Fast => {
            let (b, r) = voxelize::fast(mode, mesh, grid, opts);
            (Voxels::Bricks(b), r)
        }
        SurfaceMethod::Gpu => {
            let (b, r, facts, w) = gpu_voxelize(mode, plan.request.gpu_path, mesh, grid)?;
            *out.0 = Some(facts);
            out.1.extend(w);
            (Voxels::Bricks(b), r)
        }
    })
}

/// The tile edge of the tiled path, when it runs: asked for with `--tile`,
/// or chosen for a surface mode on the fast path whose grid does not fit
/// densely in `budget` or whose whole-grid brick index (4 bytes per 8³
/// voxels) would take more than a quarter of it, and for a solid with a
/// sparse path whose dense grid would take more than a quarter of it.
pub(crate) fn tile_for(plan: &Plan, grid: &GridSpec, budget: u64) -> Option<u32> {
    if plan.request.tile.is_some() {
        return plan.request.tile;
    }
    let fast = matches!(
        plan.request.method,
        crate::plan::Method::Auto | crate::plan::Method::Fast | crate::plan::Method::Scanline | crate::plan::Method::Gpu
    );
    let sparse_solid = plan.solid.as_ref().is_some_and(SolidPlan::has_sparse_path);
    let tileable = if plan.solid.is_some() { sparse_solid } else { fast };
    if !tileable {
        return None;
    }
    if sparse_solid {
        // A dense solid past a quarter of the budget: the sparse one keeps
        // only the bricks the surface cuts and runs for the interior.
        return (!crate::memory::dense_fits(grid, budget / 4)).then_some(voxelize::tiled::DEFAULT_TILE);
    }
    let index: u64 = grid.dims().iter().map(|&d| d.div_ceil(8) as u64).product::<u64>() * 4;
    (!crate::memory::dense_fits(grid, budget) || index > budget / 4).then_some(voxelize::tiled::DEFAULT_TILE)
}

/// Carries the mesh's colours, materials, normals and coverage into the
/// voxels (see [`topovox::attributes::carry`]); `None` for line modes.
/// Dense, brick and tiled grids alike (carrying works from the set
/// voxels' keys); see [`check_attributes_carried`] for its memory.
pub fn attributes(plan: &Plan, mesh: MeshRef<'_>, appearance: &Appearance, v: &Voxelized, opts: &CarryOptions) -> Option<VoxelAttributes> {
    (!plan.is_line()).then(|| carry(mesh, appearance, &v.grid, v.voxels.source(), opts))
}

/// Bytes per set voxel that carried attributes take (key, flag, coverage,
/// colour, material, normal).
pub const ATTRIBUTE_BYTES_PER_VOXEL: u64 = 32;

/// True when `format` gets every attribute array: `.vti` always, `.vdb`
/// and `.zarr` when `asked` (`--attributes`).
pub fn every_attribute(format: crate::output::Output, asked: bool) -> bool {
    use crate::output::Output::Voxels;
    use topovox_io::VoxelFormat as F;
    format == Voxels(F::Vti) || (asked && matches!(format, Voxels(F::Vdb | F::Zarr)))
}

/// Refuses carrying attributes that would not fit in the run's memory
/// (`--max-memory`, else most of the available memory): about
/// [`ATTRIBUTE_BYTES_PER_VOXEL`] per set voxel, all held at once (a tiled
/// grid's voxels past memory, or a sparse solid's interior, can pass it).
pub fn check_attributes_carried(plan: &Plan, v: &Voxelized) -> Result<()> {
    let voxels = v.voxels.source().count();
    let need = voxels.saturating_mul(ATTRIBUTE_BYTES_PER_VOXEL);
    let budget = crate::memory::budget(plan.request.max_memory);
    if need > budget {
        return Err(JobError::failed(format!(
            "attributes of {voxels} voxels need about {} ({ATTRIBUTE_BYTES_PER_VOXEL} bytes each, held at once), more than the {} this run may use; drop the colours and attributes (an output without them), or use a coarser grid",
            crate::memory::bytes(need),
            crate::memory::bytes(budget)
        )));
    }
    Ok(())
}

impl Voxelized {
    /// A solid mode's test of the mesh: closed and consistently oriented
    /// (`Some(true)`), not (`Some(false)`); `None` when nothing tested it.
    pub fn mesh_closed(&self) -> Option<bool> {
        self.solid.as_ref().and_then(SolidFacts::closed)
    }

    /// The facts `topovox voxelize --json` reports about the voxelization
    /// (mode, method, grid, counts, triangles, solid and GPU facts).
    pub fn facts(&self, plan: &Plan) -> Value {
        let o = self.grid.origin();
        let p = self.report.prepare;
        json!({
            "mode": plan.request.mode.name(),
            "method": self.method,
            "origin": [o.x, o.y, o.z],
            "voxel_size": topovox_io::size_json(self.grid.voxel_size()),
            "dims": self.grid.dims(),
            "voxels": self.report.voxels,
            "voxelize_s": self.voxelize_s,
            "tile": self.tile,
            "tile_kernel": self.tile_kernel,
            "peak_memory_bytes": crate::memory::peak_memory(),
            "triangles": if plan.solid.is_some() { Value::Null } else { json!({
                "input": p.input,
                "voxelized": p.output,
                "skipped_degenerate": p.degenerate,
                "skipped_non_finite": p.non_finite,
                "skipped_invalid_index": p.invalid_index,
                "outside_grid": p.outside,
                "clipped": p.clipped,
            })},
            "solid": self.solid,
            "gpu": self.gpu,
        })
    }
}

/// A GPU error as the job reports it.
#[cfg(feature = "gpu")]
pub(crate) fn gpu_failed(e: topovox_gpu::GpuError) -> JobError {
    JobError::failed(format!("--method gpu: {e}"))
}

/// The GPU, and the mode and path a `--method gpu` run asks of it.
#[cfg(feature = "gpu")]
pub(crate) fn gpu_setup(mode: voxelize::Mode, path: GpuPath) -> Result<(topovox_gpu::Gpu, topovox_gpu::GpuMode, GpuPath)> {
    let gm = topovox_gpu::GpuMode::of(mode)
        .ok_or_else(|| JobError::invalid(format!("--method gpu: {} on the GPU is not built yet", mode.name())))?;
    Ok((topovox_gpu::Gpu::new().map_err(gpu_failed)?, gm, path))
}

/// A surface mode on the GPU: the voxels, the report, facts, warnings.
#[cfg(feature = "gpu")]
fn gpu_voxelize(
    mode: voxelize::Mode,
    path: GpuPath,
    mesh: MeshRef<'_>,
    grid: &GridSpec,
) -> Result<(BrickBits, Report, GpuFacts, Vec<String>)> {
    use topovox_gpu::GpuPath as P;
    let (gpu, gm, gp) = gpu_setup(mode, path)?;
    let fail = gpu_failed;
    let (bits, r) = gpu.voxelize_with(gm, gp, mesh, grid).map_err(fail)?;
    let mut warnings = Vec::new();
    // The approximation says what it misses: the exact voxels by the compute path.
    let missed = if gp == P::MsaaApprox {
        let (exact, _) = gpu.voxelize(gm, mesh, grid).map_err(fail)?;
        let mut missed = 0u64;
        exact.for_each_set(|i, j, k| missed += !bits.get(i, j, k) as u64);
        warnings.push(format!("--gpu-path msaa-approx is approximate: it missed {missed} of the mode's {} voxels", exact.count()));
        Some(missed)
    } else {
        None
    };
    let t = r.timings;
    let facts = GpuFacts {
        path: path.to_string(),
        adapter: gpu.adapter(),
        software: gpu.is_software(),
        run: crate::facts::GpuRun::Whole {
            counts: GpuCounts {
                hardware_conservative: gpu.hardware_conservative(),
                gpu_triangles: r.gpu_triangles,
                cpu_triangles: r.cpu_triangles,
            },
            missed_voxels: missed,
            upload_s: t.upload_s,
            gpu_s: t.voxelize_s,
            gpu_time_s: t.gpu_s,
            download_s: t.download_s,
            cpu_share_s: t.cpu_s,
            slabs: t.slabs,
        },
    };
    Ok((bits, r.report, facts, warnings))
}

/// The GPU path tile by tile (grids past memory, or `--tile`): each tile's
/// triangles, snapped once to the whole grid and moved by whole voxels,
/// go through [`topovox_gpu::Gpu::voxelize_lattice`].
#[cfg(feature = "gpu")]
fn gpu_tiled(
    mode: voxelize::Mode,
    path: GpuPath,
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    tile: u32,
    opts: &Options<'_>,
) -> Result<(SparseBricks, Report, GpuFacts)> {
    if path == GpuPath::MsaaApprox {
        return Err(JobError::invalid(
            "--gpu-path msaa-approx does not run tiled (it is checked against a whole-grid run); use compute or raster",
        ));
    }
    let (gpu, gm, gp) = gpu_setup(mode, path)?;
    let mut c = [0u64; 3];
    let (s, r) = voxelize::tiled::tiled_by(mesh, grid, tile, opts, |tris, size| {
        let (bits, r) = gpu.voxelize_lattice(gm, gp, tris, size)?;
        c[0] += r.gpu_triangles;
        c[1] += r.cpu_triangles;
        c[2] += 1;
        Ok(bits)
    })
    .map_err(|e| JobError::invalid(e.to_string()))?
    .map_err(gpu_failed)?;
    let facts = GpuFacts {
        path: path.to_string(),
        adapter: gpu.adapter(),
        software: gpu.is_software(),
        run: crate::facts::GpuRun::Tiled {
            counts: GpuCounts { hardware_conservative: gpu.hardware_conservative(), gpu_triangles: c[0], cpu_triangles: c[1] },
            tiles: c[2],
        },
    };
    Ok((s, r, facts))
}

#[cfg(not(feature = "gpu"))]
fn gpu_tiled(
    _mode: voxelize::Mode,
    _path: GpuPath,
    _mesh: MeshRef<'_>,
    _grid: &GridSpec,
    _tile: u32,
    _opts: &Options<'_>,
) -> Result<(SparseBricks, Report, GpuFacts)> {
    Err(no_gpu())
}

/// What `--method gpu` says in a build without the `gpu` feature.
#[cfg(not(feature = "gpu"))]
fn no_gpu() -> JobError {
    JobError::invalid("--method gpu: this topovox was built without the `gpu` feature")
}

#[cfg(not(feature = "gpu"))]
fn gpu_voxelize(
    _mode: voxelize::Mode,
    _path: GpuPath,
    _mesh: MeshRef<'_>,
    _grid: &GridSpec,
) -> Result<(BrickBits, Report, GpuFacts, Vec<String>)> {
    Err(no_gpu())
}
