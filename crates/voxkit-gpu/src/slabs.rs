//! The slab plumbing shared by every GPU pass: how many z-layers of bits fit
//! the device's storage-buffer limit, the output and readback buffers, and
//! one submit–wait–read cycle.

use std::time::Instant;

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
}

impl Gpu {
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
            self.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let out = buffer("slab bits", wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST);
        let staging = buffer("slab readback", wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        self.check()?;
        Ok(Slabs { words_per_row, layer_bytes, nk_max, out, staging })
    }

    /// Copies the first `nk` layers of the slab to the readback buffer,
    /// submits `encoder`, waits, and hands the words to `read`. Returns the
    /// seconds spent running (submit to finish) and reading.
    pub(crate) fn finish_slab(
        &self,
        s: &Slabs,
        mut encoder: wgpu::CommandEncoder,
        nk: u32,
        read: impl FnOnce(&[u32]),
    ) -> Result<(f64, f64), GpuError> {
        let used = s.layer_bytes * nk as u64;
        encoder.copy_buffer_to_buffer(&s.out, 0, &s.staging, 0, used);
        let t_run = Instant::now();
        self.queue.submit([encoder.finish()]);
        let slice = s.staging.slice(0..used);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| GpuError::Device(e.to_string()))?;
        self.check()?;
        rx.recv().map_err(|e| GpuError::Readback(e.to_string()))?.map_err(|e| GpuError::Readback(e.to_string()))?;
        let run_s = t_run.elapsed().as_secs_f64();
        let t_read = Instant::now();
        {
            let view = slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
            read(bytemuck::cast_slice(&view));
        }
        s.staging.unmap();
        Ok((run_s, t_read.elapsed().as_secs_f64()))
    }
}
