//! The slab plumbing shared by every GPU pass: how many z-layers of bits fit
//! the device's storage-buffer limit, the output and readback buffers, and
//! one submit–wait–read cycle.

use std::time::Instant;

use wgpu::util::DeviceExt;

use crate::device::mapped;
use crate::params::Params;
use crate::{Gpu, GpuError};

/// The grid cut into z-slabs of 32-bit words (bit `i % 32` of word
/// `row · words_per_row + i / 32`, rows `j + ny · (k − k0)`).
pub(crate) struct Slabs {
    pub words_per_row: u64,
    pub layer_bytes: u64,
    /// Layers per slab (the last may have fewer).
    pub nk_max: u32,
    pub out: wgpu::Buffer,
    pub staging: wgpu::Buffer,
    /// GPU timestamps around each pass, where the adapter has them.
    pub queries: Option<Queries>,
}

/// Passes per slab that get timestamps (more are run untimed, and the
/// slab's GPU time is then not reported).
pub(crate) const TIMED_PASSES: u32 = 32;

/// A query set of begin/end timestamps per pass and its readback.
pub(crate) struct Queries {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
}

impl Slabs {
    /// The slabs of a grid `nz` layers deep: `(first layer, layers)`.
    pub fn layers(&self, nz: u32) -> impl Iterator<Item = (u32, u32)> {
        let step = self.nk_max;
        (0..nz).step_by(step as usize).map(move |k0| (k0, step.min(nz - k0)))
    }

    /// Timestamp writes for compute pass `pass` of the current slab.
    pub fn compute_timestamps(&self, pass: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let q = self.queries.as_ref().filter(|_| pass < TIMED_PASSES)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &q.set,
            beginning_of_pass_write_index: Some(2 * pass),
            end_of_pass_write_index: Some(2 * pass + 1),
        })
    }

    /// Timestamp writes for render pass `pass` of the current slab.
    pub fn render_timestamps(&self, pass: u32) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let q = self.queries.as_ref().filter(|_| pass < TIMED_PASSES)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: &q.set,
            beginning_of_pass_write_index: Some(2 * pass),
            end_of_pass_write_index: Some(2 * pass + 1),
        })
    }
}

/// The items of `sorted` (by lowest layer, each with its inclusive layer
/// range) that reach into layers `k0 .. k0 + nk`.
pub(crate) fn in_slab<T: Copy>(sorted: &[(T, [i64; 2])], k0: u32, nk: u32) -> Vec<T> {
    let (klo, khi) = (k0 as i64, (k0 + nk) as i64 - 1);
    // Stop at the first item starting above the slab.
    sorted.iter().take_while(|t| t.1[0] <= khi).filter(|t| t.1[1] >= klo).map(|t| t.0).collect()
}

impl crate::Timings {
    /// Adds one slab's run, read and timestamped GPU seconds (the GPU time
    /// stays known only while every slab has it).
    pub(crate) fn add_slab(&mut self, (run_s, read_s, gpu_s): (f64, f64, Option<f64>)) {
        self.voxelize_s += run_s;
        self.download_s += read_s;
        self.gpu_s = match (self.gpu_s, gpu_s, self.slabs) {
            (None, Some(g), 0) => Some(g),
            (Some(t), Some(g), _) => Some(t + g),
            _ => None,
        };
        self.slabs += 1;
    }
}

impl Gpu {
    /// The uniform parameters of one pass ([`Params`]).
    pub(crate) fn params(&self, dims: [u32; 3], s: &Slabs, (k0, nk): (u32, u32), count: u32, mode: u32, side: u32) -> wgpu::Buffer {
        let params = Params { dims, k0, nk, words_per_row: s.words_per_row as u32, count, mode, side, pad: [0; 3] };
        self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        })
    }

    /// Records one compute pass of `groups` workgroups (spread over a
    /// second dimension past 65 535, as the shaders expect), timed as pass
    /// `pass` of the slab.
    pub(crate) fn compute_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        s: &Slabs,
        pass: u32,
        pipeline: &wgpu::ComputePipeline,
        bind: &wgpu::BindGroup,
        groups: u32,
    ) {
        let mut p = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("topovox"), timestamp_writes: s.compute_timestamps(pass) });
        p.set_pipeline(pipeline);
        p.set_bind_group(0, bind, &[]);
        p.dispatch_workgroups(groups.clamp(1, 65535), groups.div_ceil(65535).max(1), 1);
    }

    /// Slabs for a grid of `dims`, or an error if one layer is already too large.
    pub(crate) fn slabs(&self, dims: [u32; 3]) -> Result<Slabs, GpuError> {
        let words_per_row = dims[0].div_ceil(32) as u64;
        let layer_bytes = words_per_row * dims[1] as u64 * 4;
        if layer_bytes > self.max_slab_bytes {
            return Err(GpuError::Unsupported(format!(
                "grids whose single z-layer ({layer_bytes} bytes) exceeds the device's storage buffer limit ({} bytes)",
                self.max_slab_bytes
            )));
        }
        let nk_max = ((self.max_slab_bytes / layer_bytes) as u32).clamp(1, dims[2]);
        let size = layer_bytes * nk_max as u64;
        let buffer = |label, usage| {
            self.dev.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let out = buffer("slab bits", wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST);
        let staging = buffer("slab readback", wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let queries = self.dev.timestamps().then(|| {
            let bytes = 16 * TIMED_PASSES as u64;
            Queries {
                set: self.dev.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2 * TIMED_PASSES,
                }),
                resolve: self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamps"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                read: self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamps readback"),
                    size: bytes,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
            }
        });
        self.check()?;
        Ok(Slabs { words_per_row, layer_bytes, nk_max, out, staging, queries })
    }

    /// Copies the first `nk` layers of the slab to the readback buffer,
    /// submits `encoder` (which ran `passes` passes), waits, and hands the
    /// words to `read`. Returns the seconds spent running (submit to
    /// finish), reading, and the passes' GPU time by timestamps (when the
    /// adapter has them and every pass was timed).
    pub(crate) fn finish_slab(
        &self,
        s: &Slabs,
        mut encoder: wgpu::CommandEncoder,
        nk: u32,
        passes: u32,
        read: impl FnOnce(&[u32]),
    ) -> Result<(f64, f64, Option<f64>), GpuError> {
        let used = s.layer_bytes * nk as u64;
        encoder.copy_buffer_to_buffer(&s.out, 0, &s.staging, 0, used);
        let timed = s.queries.as_ref().filter(|_| passes > 0 && passes <= TIMED_PASSES);
        if let Some(q) = timed {
            encoder.resolve_query_set(&q.set, 0..2 * passes, &q.resolve, 0);
            encoder.copy_buffer_to_buffer(&q.resolve, 0, &q.read, 0, 16 * passes as u64);
        }
        let t_run = Instant::now();
        self.dev.queue.submit([encoder.finish()]);
        let slice = s.staging.slice(0..used);
        let stamps = timed.map(|q| (q, q.read.slice(0..16 * passes as u64)));
        let mut slices = vec![slice];
        slices.extend(stamps.map(|(_, ts)| ts));
        self.dev.map_all(&slices)?;
        let run_s = t_run.elapsed().as_secs_f64();
        let mut gpu_s = None;
        if let Some((q, ts)) = stamps {
            gpu_s = self.dev.timestamp_seconds(bytemuck::cast_slice(&mapped(ts)?));
            q.read.unmap();
        }
        let t_read = Instant::now();
        {
            read(bytemuck::cast_slice(&mapped(slice)?));
        }
        s.staging.unmap();
        Ok((run_s, t_read.elapsed().as_secs_f64(), gpu_s))
    }
}
