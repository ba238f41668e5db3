//! `solid` by ray parity on the GPU: flips per (triangle, row), a prefix
//! pass per row; the same voxels as [`topovox::voxelize::solid::parity`].

use std::time::Instant;

use topovox::geom::fixed::ONE;
use topovox::geom::lattice::LatticeTriangle;
use topovox::grid::dense::DenseBits;
use topovox::topology::inside::{row_crossings, snap_all};
use topovox::voxelize::solid::{inspect, SolidReport};
use topovox::{GridSpec, MeshRef};
use wgpu::util::DeviceExt;

use crate::slabs::{in_slab, Slabs};
use crate::{Gpu, GpuError, Timings};

/// Largest triangle extent + 2 voxels (lattice units) whose row-crossing
/// terms stay exact in the shader's i64 (as the CPU's `fits_i64`).
const LIMIT: i64 = 1 << 18;

/// What [`Gpu::solid_parity`] did.
#[derive(Clone, Copy, Debug)]
pub struct SolidGpuReport {
    /// Closedness and counts, as the CPU parity reports them.
    pub solid: SolidReport,
    /// Triangles whose crossings the GPU computed.
    pub gpu_triangles: u64,
    /// Triangles whose crossings the CPU computed (too large for i64).
    pub cpu_triangles: u64,
    /// Where the time went.
    pub timings: Timings,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct STri {
    a: [i32; 4],
    b: [i32; 4],
    c: [i32; 4],
}

impl Gpu {
    /// `solid` by ray parity: the same voxels as
    /// [`topovox::voxelize::solid::parity`] (exact for closed, consistently
    /// oriented meshes; the report says whether this one is).
    pub fn solid_parity(&self, mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(DenseBits, SolidGpuReport), GpuError> {
        let t0 = Instant::now();
        let snapped = snap_all(mesh, grid).map_err(|e| GpuError::Unsupported(e.to_string()))?;
        let mut solid = inspect(&snapped);
        let dims = grid.dims();
        let (on_gpu, on_cpu) = split_triangles(snapped.crossing_triangles());
        // The CPU's share: its crossings, as (row, i0) flips.
        let cpu_flips: Vec<(u32, u32)> = row_crossings(&on_cpu, dims).into_iter().filter(|h| h.1 < dims[0]).map(|h| (h.0, h.1)).collect();
        let mut timings = Timings { upload_s: t0.elapsed().as_secs_f64(), ..Timings::default() };

        let slabs = self.slabs(dims)?;
        let mut bits = DenseBits::new(dims);
        for (k0, nk) in slabs.layers(dims[2]) {
            let t_up = Instant::now();
            let slab = in_slab(&on_gpu, k0, nk);
            let list = slab_flips(&cpu_flips, dims, (k0, nk), slabs.words_per_row);
            let mut encoder = self.dev.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("solid slab") });
            encoder.clear_buffer(&slabs.out, 0, None);
            let (passes, _keep) = self.solid_passes(&mut encoder, &slabs, (dims, k0, nk), &slab, &list);
            timings.upload_s += t_up.elapsed().as_secs_f64();
            let start = k0 as usize * dims[1] as usize;
            let done = self.finish_slab(&slabs, encoder, nk, passes, |words| copy_rows(words, slabs.words_per_row, start, &mut bits))?;
            timings.add_slab(done);
        }
        solid.voxels = bits.count();
        let report = SolidGpuReport { solid, gpu_triangles: on_gpu.len() as u64, cpu_triangles: on_cpu.len() as u64, timings };
        Ok((bits, report))
    }

    /// Encodes one slab's passes (layers `k0..k0 + nk` of `dims`): the
    /// flips of `tris`, the CPU's flips `list`, then the prefix per row.
    /// How many passes, and the buffers they use (kept until submitted).
    fn solid_passes(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        slabs: &Slabs,
        (dims, k0, nk): ([u32; 3], u32, u32),
        tris: &[STri],
        list: &[[u32; 2]],
    ) -> (u32, Vec<(wgpu::Buffer, wgpu::Buffer, wgpu::Buffer, wgpu::BindGroup)>) {
        let empty_tris = [STri { a: [0; 4], b: [0; 4], c: [0; 4] }];
        let mut keep = Vec::new();
        let mut passes = 0u32;
        let mut pass_with = |encoder: &mut wgpu::CommandEncoder,
                             pipeline: &wgpu::ComputePipeline,
                             tris: &[STri],
                             flips: &[[u32; 2]],
                             count: u32,
                             groups: u32| {
            let list_buf = self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("cpu flips"),
                contents: bytemuck::cast_slice(if flips.is_empty() { &[[0u32; 2]][..] } else { flips }),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let tri_buf = self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("solid triangles"),
                contents: bytemuck::cast_slice(if tris.is_empty() { &empty_tris[..] } else { tris }),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let par_buf = self.params(dims, slabs, (k0, nk), count, 0, 0);
            let bind = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("solid"),
                layout: &self.solid.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: tri_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: slabs.out.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: par_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: list_buf.as_entire_binding() },
                ],
            });
            self.compute_pass(encoder, slabs, passes, pipeline, &bind, groups);
            passes += 1;
            keep.push((tri_buf, par_buf, list_buf, bind));
        };
        let max_batch = (self.max_slab_bytes / std::mem::size_of::<STri>() as u64).clamp(1, 1 << 22) as usize;
        for batch in tris.chunks(max_batch) {
            pass_with(encoder, &self.solid.flips, batch, &[], batch.len() as u32, batch.len() as u32);
        }
        // The CPU's flips, in chunks within the storage binding limit.
        for chunk in list.chunks((self.max_slab_bytes / 8).max(1) as usize) {
            pass_with(encoder, &self.solid.xor_list, &[], chunk, chunk.len() as u32, (chunk.len() as u32).div_ceil(64));
        }
        let rows = dims[1] * nk;
        pass_with(encoder, &self.solid.prefix, &[], &[], 0, rows.div_ceil(64));
        (passes, keep)
    }
}

/// The triangles the shader takes (the first vertex absolute, the others
/// relative to it, with the layers their crossings reach, sorted by them)
/// and those too large for its i64 terms (the CPU's share).
fn split_triangles(tris: Vec<LatticeTriangle>) -> (Vec<(STri, [i64; 2])>, Vec<LatticeTriangle>) {
    let mut on_gpu: Vec<(STri, [i64; 2])> = Vec::new();
    let mut on_cpu: Vec<LatticeTriangle> = Vec::new();
    for t in tris {
        let (lo, hi) = t.bounds();
        let extent = (0..3).map(|a| hi[a] - lo[a]).max().unwrap_or(0);
        if extent + 2 * ONE > LIMIT {
            on_cpu.push(t);
            continue;
        }
        let a = t.v[0];
        let rel = |p: [i64; 3]| [(p[0] - a[0]) as i32, (p[1] - a[1]) as i32, (p[2] - a[2]) as i32, 0];
        let layers = [(lo[2] - ONE / 2 - 1).div_euclid(ONE), (hi[2] - ONE / 2 + 1).div_euclid(ONE)];
        on_gpu.push((STri { a: [a[0] as i32, a[1] as i32, a[2] as i32, 0], b: rel(t.v[1]), c: rel(t.v[2]) }, layers));
    }
    on_gpu.sort_by_key(|t| t.1[0]);
    (on_gpu, on_cpu)
}

/// The CPU's flips `(row, i0)` in layers `k0..k0 + nk`, as (word, bit)
/// pairs of the slab (rows of `words_per_row` 32-bit words).
fn slab_flips(flips: &[(u32, u32)], dims: [u32; 3], (k0, nk): (u32, u32), words_per_row: u64) -> Vec<[u32; 2]> {
    flips
        .iter()
        .filter(|f| {
            let k = f.0 / dims[1];
            k >= k0 && k < k0 + nk
        })
        .map(|&(row, i0)| {
            let local_row = row - k0 * dims[1];
            [local_row * words_per_row as u32 + i0 / 32, 1u32 << (i0 % 32)]
        })
        .collect()
}

/// Copies a slab read back (rows of `words_per_row` 32-bit words) into
/// `bits`'s 64-bit rows from row `start`.
fn copy_rows(words: &[u32], words_per_row: u64, start: usize, bits: &mut DenseBits) {
    let wpr64 = bits.words_per_row();
    for (src, dst) in words.chunks_exact(words_per_row as usize).zip(bits.rows_mut().skip(start)) {
        for (w, d) in dst.iter_mut().enumerate().take(wpr64) {
            let lo = src.get(2 * w).copied().unwrap_or(0) as u64;
            let hi = src.get(2 * w + 1).copied().unwrap_or(0) as u64;
            *d = lo | hi << 32;
        }
    }
}
