//! The compute path: triangles on the lattice → bits in z-slabs on the GPU.

use std::time::Instant;

use topovox::geom::fixed::ONE;
use topovox::geom::lattice::{prepare, LatticeTriangle};
use topovox::voxelize::{Options, Report};
use topovox::{BrickBits, GridSpec, MeshRef};
use wgpu::util::DeviceExt;

use crate::slabs::in_slab;
use crate::{Gpu, GpuError};

/// Largest relative coordinate (lattice units) for which the shader's i64
/// products cannot overflow in `cover`: the separating axis test multiplies
/// a normal component (≤ 2R²) by a coordinate (≤ R) and sums six such
/// terms, and 12·(2^19)³ < 2^63.
const LIMIT_COVER: i64 = 1 << 19;

/// The same for `sep26`/`sep6`, whose orientation determinants take
/// differences of coordinates (≤ 2R) three at a time: 3·2·(2^19)³ < 2^63.
const LIMIT_TARGETS: i64 = 1 << 18;

pub use topovox::voxelize::GpuPath;

/// The surface modes the GPU path runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuMode {
    /// Conservative cover.
    Cover,
    /// Laine's minimal 26-separating (space diagonals).
    Sep26,
    /// Laine's thin 6-separating (crosshair).
    Sep6,
}

impl GpuMode {
    /// The GPU mode for a core mode, if the GPU path has it.
    pub fn of(mode: topovox::voxelize::Mode) -> Option<GpuMode> {
        match mode {
            topovox::voxelize::Mode::Cover => Some(GpuMode::Cover),
            topovox::voxelize::Mode::Sep26 => Some(GpuMode::Sep26),
            topovox::voxelize::Mode::Sep6 => Some(GpuMode::Sep6),
            _ => None,
        }
    }

    fn code(self) -> u32 {
        match self {
            GpuMode::Cover => 0,
            GpuMode::Sep26 => 1,
            GpuMode::Sep6 => 2,
        }
    }

    fn limit(self) -> i64 {
        match self {
            GpuMode::Cover => LIMIT_COVER,
            _ => LIMIT_TARGETS,
        }
    }
}

/// Seconds spent in each stage.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Snapping on the CPU, packing and uploading triangles.
    pub upload_s: f64,
    /// From submission until the GPU finished (all slabs).
    pub voxelize_s: f64,
    /// Reading the slabs back into bricks.
    pub download_s: f64,
    /// The CPU's share (triangles too large for the shader's i64 products).
    pub cpu_s: f64,
    /// Slabs the grid was cut into.
    pub slabs: u32,
    /// GPU time of the voxelization passes by timestamp queries (None when
    /// the adapter has none).
    pub gpu_s: Option<f64>,
}

/// What [`Gpu::cover`] did.
#[derive(Clone, Copy, Debug)]
pub struct CoverReport {
    /// Triangle counts and voxels, as the CPU paths report them.
    pub report: Report,
    /// Triangles voxelized on the GPU.
    pub gpu_triangles: u64,
    /// Triangles voxelized by the CPU fast path (too large for i64 on the GPU).
    pub cpu_triangles: u64,
    /// Where the time went.
    pub timings: Timings,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuTri {
    origin: [i32; 4],
    size: [u32; 4],
    a: [i32; 4],
    b: [i32; 4],
    c: [i32; 4],
}

impl Gpu {
    /// `cover` of `mesh` on `grid`: the same voxels as
    /// [`topovox::voxelize::cover::reference::cover`].
    pub fn cover(&self, mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(BrickBits, CoverReport), GpuError> {
        self.voxelize(GpuMode::Cover, mesh, grid)
    }

    /// `mode` of `mesh` on `grid` by the compute path: the same voxels as the mode's CPU reference.
    pub fn voxelize(&self, mode: GpuMode, mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(BrickBits, CoverReport), GpuError> {
        self.voxelize_with(mode, GpuPath::Compute, mesh, grid)
    }

    /// `mode` of `mesh` on `grid` by `path` (see [`GpuPath`]; all but
    /// [`GpuPath::MsaaApprox`] give the reference's voxels).
    pub fn voxelize_with(
        &self,
        mode: GpuMode,
        path: GpuPath,
        mesh: MeshRef<'_>,
        grid: &GridSpec,
    ) -> Result<(BrickBits, CoverReport), GpuError> {
        let t0 = Instant::now();
        let (tris, prepare_stats) = prepare(mesh, grid);
        let snapping_s = t0.elapsed().as_secs_f64();
        let (bits, mut report) = self.voxelize_lattice(mode, path, &tris, grid.dims())?;
        report.report.prepare = prepare_stats;
        report.timings.upload_s += snapping_s;
        Ok((bits, report))
    }

    /// `mode` by `path` on triangles already snapped to a grid of `dims`
    /// (a whole grid, or one tile of a tiled run with its triangles moved
    /// by whole voxels): the voxels of [`Gpu::voxelize_with`]. The
    /// report's preparation counts are zero.
    pub fn voxelize_lattice(
        &self,
        mode: GpuMode,
        path: GpuPath,
        tris: &[LatticeTriangle],
        dims: [u32; 3],
    ) -> Result<(BrickBits, CoverReport), GpuError> {
        let t0 = Instant::now();
        let (on_gpu, on_cpu) = split_triangles(mode, tris, dims);
        let mut timings = Timings { upload_s: t0.elapsed().as_secs_f64(), ..Timings::default() };

        let slabs = self.slabs(dims)?;
        let (words_per_row, out) = (slabs.words_per_row, &slabs.out);
        let side = dims.iter().copied().max().unwrap_or(1);
        let target = match path {
            GpuPath::Compute => None,
            GpuPath::Raster | GpuPath::MsaaApprox => Some(self.raster_target(side, path == GpuPath::MsaaApprox)?),
        };
        let expand = if path == GpuPath::Raster && !self.raster.hardware_conservative { crate::params::QUADS } else { 0 };
        let max_batch = (self.max_slab_bytes / std::mem::size_of::<GpuTri>() as u64).clamp(1, 1 << 22) as usize;
        let mut bits = BrickBits::new(dims);
        for (k0, nk) in slabs.layers(dims[2]) {
            let t_up = Instant::now();
            let slab = in_slab(&on_gpu, k0, nk);
            let mut encoder = self.dev.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("slab") });
            encoder.clear_buffer(out, 0, None);
            let mut keep = Vec::new();
            let mut passes = 0u32;
            for batch in slab.chunks(max_batch) {
                let tri_buf = self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("triangles"),
                    contents: bytemuck::cast_slice(batch),
                    usage: wgpu::BufferUsages::STORAGE,
                });
                let par_buf = self.params(dims, &slabs, (k0, nk), batch.len() as u32, mode.code() | expand, side);
                let bind = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("cover"),
                    layout: &self.layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: tri_buf.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: out.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 2, resource: par_buf.as_entire_binding() },
                    ],
                });
                match &target {
                    None => self.compute_pass(&mut encoder, &slabs, passes, &self.cover, &bind, batch.len() as u32),
                    Some(view) => {
                        let pipeline = if path == GpuPath::MsaaApprox { &self.raster.msaa } else { &self.raster.conservative };
                        let per = if expand != 0 { 6 } else { 3 };
                        raster_pass(&mut encoder, view, slabs.render_timestamps(passes), pipeline, &bind, per * batch.len() as u32);
                    }
                }
                passes += 1;
                keep.push((tri_buf, par_buf, bind));
            }
            timings.upload_s += t_up.elapsed().as_secs_f64();
            let done = self.finish_slab(&slabs, encoder, nk, passes, |words| unpack_rows(words, words_per_row, k0, &mut bits))?;
            timings.add_slab(done);
        }
        let t_cpu = Instant::now();
        cpu_share(mode, &on_cpu, &mut bits);
        timings.cpu_s = t_cpu.elapsed().as_secs_f64();
        let voxels = bits.count();
        let report = CoverReport {
            report: Report { prepare: Default::default(), voxels },
            gpu_triangles: on_gpu.len() as u64,
            cpu_triangles: on_cpu.len() as u64,
            timings,
        };
        Ok((bits, report))
    }
}

/// Splits `tris` into those the shader takes (relative to their voxel
/// box's corner, with their z range, sorted by it) and those whose
/// coordinates pass the mode's i32 limit (the CPU's share); triangles
/// outside the grid are dropped.
fn split_triangles(mode: GpuMode, tris: &[LatticeTriangle], dims: [u32; 3]) -> (Vec<(GpuTri, [i64; 2])>, Vec<LatticeTriangle>) {
    let mut on_gpu: Vec<(GpuTri, [i64; 2])> = Vec::with_capacity(tris.len());
    let mut on_cpu: Vec<LatticeTriangle> = Vec::new();
    for t in tris {
        let Some((lo, hi)) = t.voxel_bounds(dims) else { continue };
        let base = lo.map(|c| c * ONE);
        let rel = t.v.map(|p| [p[0] - base[0], p[1] - base[1], p[2] - base[2]]);
        let box_reach = (0..3).map(|a| (hi[a] - lo[a] + 2) * ONE).max().unwrap_or(0);
        let reach = rel.iter().flatten().map(|c| c.abs()).max().unwrap_or(0).max(box_reach);
        if reach > mode.limit() {
            on_cpu.push(*t);
            continue;
        }
        let v = |p: [i64; 3]| [p[0] as i32, p[1] as i32, p[2] as i32, 0];
        let g = GpuTri {
            origin: [lo[0] as i32, lo[1] as i32, lo[2] as i32, 0],
            size: [(hi[0] - lo[0] + 1) as u32, (hi[1] - lo[1] + 1) as u32, (hi[2] - lo[2] + 1) as u32, 0],
            a: v(rel[0]),
            b: v(rel[1]),
            c: v(rel[2]),
        };
        on_gpu.push((g, [lo[2], hi[2]]));
    }
    on_gpu.sort_by_key(|t| t.1[0]);
    (on_gpu, on_cpu)
}

/// One raster pass drawing `vertices` into `view` (its colour discarded:
/// the fragment shader writes the slab).
fn raster_pass(
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    vertices: u32,
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("raster"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Discard },
        })],
        depth_stencil_attachment: None,
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind, &[]);
    pass.draw(0..vertices, 0..1);
}

/// Sets in `bits` the voxels of a slab read back from layer `k0`: rows of
/// `words_per_row` 32-bit words, one row per (j, k), j fastest.
fn unpack_rows(words: &[u32], words_per_row: u64, k0: u32, bits: &mut BrickBits) {
    let ny = bits.dims()[1];
    for (row, chunk) in words.chunks_exact(words_per_row as usize).enumerate() {
        let (j, k) = (row as u32 % ny, k0 + row as u32 / ny);
        for (w, &word) in chunk.iter().enumerate() {
            let mut m = word;
            while m != 0 {
                let b = m.trailing_zeros();
                m &= m - 1;
                bits.set(w as u32 * 32 + b, j, k);
            }
        }
    }
}

/// The CPU's share (`on_cpu`, too large for the shader), voxelized by
/// the same mode into `bits`.
fn cpu_share(mode: GpuMode, on_cpu: &[LatticeTriangle], bits: &mut BrickBits) {
    if on_cpu.is_empty() {
        return;
    }
    let (o, dims) = (Options::default(), bits.dims());
    let cpu = match mode {
        GpuMode::Cover => topovox::voxelize::cover::cover_lattice(on_cpu, dims, &o),
        GpuMode::Sep26 => topovox::voxelize::sep26::sep26_lattice(on_cpu, dims, &o),
        GpuMode::Sep6 => topovox::voxelize::sep6::sep6_lattice(on_cpu, dims, &o),
    };
    cpu.for_each_set(&mut |i, j, k| bits.set(i, j, k));
}
