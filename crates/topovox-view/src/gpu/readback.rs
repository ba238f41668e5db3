//! What a frame reads back once its passes ran: the picture (when not
//! presented), which clusters were kept, the culling counters, the pass
//! timestamps and (when asked) the Hi-Z pyramid — decoded into a [`Frame`].

use std::time::Instant;

use topovox_gpu::device::mapped;

use super::passes::{occlusion, Targets};
use super::{aligned_row, Frame, FrameOptions, FrameStats, GpuScene, PassTimes, Renderer};
use crate::hiz::Pyramid;
use crate::ViewError;

/// The readback buffers of one frame.
pub(super) struct Readbacks {
    pixels: Option<wgpu::Buffer>,
    commands: wgpu::Buffer,
    counters: wgpu::Buffer,
    times: Option<wgpu::Buffer>,
    hiz: Option<(Vec<wgpu::Buffer>, Vec<[u32; 2]>)>,
}

impl Renderer {
    fn readback(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.dev.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Records the copies into readback buffers: the picture when `pixels`,
    /// the commands, the counters, the timestamps and the pyramid levels.
    pub(super) fn readbacks(
        &self,
        enc: &mut wgpu::CommandEncoder,
        (s, o, t): (&GpuScene, &FrameOptions, &Targets),
        pixels: bool,
        hiz: Option<&(wgpu::Texture, Vec<[u32; 2]>)>,
        queries: Option<&wgpu::QuerySet>,
    ) -> Readbacks {
        let row = aligned_row(o.width);
        let pixels = pixels.then(|| {
            let b = self.readback("picture", row as u64 * o.height as u64);
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: &t.colour,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &b,
                    layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(o.height) },
                },
                wgpu::Extent3d { width: o.width, height: o.height, depth_or_array_layers: 1 },
            );
            b
        });
        let hiz = hiz.filter(|_| o.read_hiz).map(|h| self.copy_levels(enc, h));
        let cmd_bytes = 20 * (s.clusters.len() as u64).max(1);
        let commands = self.readback("commands", cmd_bytes);
        enc.copy_buffer_to_buffer(&s.commands, 0, &commands, 0, cmd_bytes);
        let counters = self.readback("counters", 16);
        enc.copy_buffer_to_buffer(&s.counters, 0, &counters, 0, 16);
        let times = queries.map(|q| {
            let resolve = self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = self.readback("timestamps readback", 64);
            enc.resolve_query_set(q, 0..8, &resolve, 0);
            enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, 64);
            read
        });
        Readbacks { pixels, commands, counters, times, hiz }
    }

    /// Waits for the submitted frame and decodes what it read back.
    pub(super) fn read_frame(&self, s: &GpuScene, o: &FrameOptions, r: Readbacks, t0: Instant) -> Result<Frame, ViewError> {
        let all: Vec<&wgpu::Buffer> = [r.pixels.as_ref(), Some(&r.commands), Some(&r.counters), r.times.as_ref()]
            .into_iter()
            .flatten()
            .chain(r.hiz.iter().flat_map(|(bufs, _)| bufs.iter()))
            .collect();
        self.dev.map_all(&all.iter().map(|b| b.slice(..)).collect::<Vec<_>>())?;
        let n = s.clusters.len();
        let mut rgba = Vec::with_capacity(4 * o.width as usize * o.height as usize);
        if let Some(pixels) = &r.pixels {
            let (data, row) = (mapped(pixels.slice(..))?, aligned_row(o.width) as usize);
            for y in 0..o.height as usize {
                rgba.extend_from_slice(&data[y * row..y * row + 4 * o.width as usize]);
            }
        }
        let kept: Vec<bool> = {
            let data = mapped(r.commands.slice(..))?;
            let words: &[u32] = bytemuck::cast_slice(&data);
            (0..n).map(|c| words[5 * c + 1] != 0).collect()
        };
        let counters: [u32; 4] = {
            let data = mapped(r.counters.slice(..))?;
            let w: &[u32] = bytemuck::cast_slice(&data);
            [w[0], w[1], w[2], w[3]]
        };
        let hiz = r.hiz.map(|(bufs, sizes)| read_pyramid(&bufs, sizes, o)).transpose()?;
        let gpu = r.times.map(|t| self.pass_times(&t, o)).transpose()?;
        let stats = frame_stats(s, o, counters, gpu, t0);
        Ok(Frame { width: o.width, height: o.height, rgba, kept, hiz, stats })
    }

    /// The passes' GPU times from the timestamps (ms).
    fn pass_times(&self, t: &wgpu::Buffer, o: &FrameOptions) -> Result<PassTimes, ViewError> {
        let data = mapped(t.slice(..))?;
        let w: &[u64] = bytemuck::cast_slice(&data);
        let period = self.dev.queue.get_timestamp_period() as f64 * 1e-6;
        let span = |i: usize| w[2 * i + 1].saturating_sub(w[2 * i]) as f64 * period;
        let occ = occlusion(o);
        Ok(PassTimes {
            cull_ms: span(0),
            depth_ms: if o.prepass || occ { span(1) } else { 0.0 },
            shade_ms: span(2),
            hiz_ms: if occ { span(3) } else { 0.0 },
        })
    }
}

/// The pyramid's levels, as rows of depths.
fn read_pyramid(bufs: &[wgpu::Buffer], sizes: Vec<[u32; 2]>, o: &FrameOptions) -> Result<Pyramid, ViewError> {
    let mut levels = Vec::with_capacity(bufs.len());
    for (b, [w, h]) in bufs.iter().zip(&sizes) {
        let data = mapped(b.slice(..))?;
        let row = aligned_row(*w) as usize;
        let mut level = Vec::with_capacity((*w * *h) as usize);
        for y in 0..*h as usize {
            level.extend_from_slice(bytemuck::cast_slice::<u8, f32>(&data[y * row..y * row + 4 * *w as usize]));
        }
        levels.push(level);
    }
    Ok(Pyramid { sizes, levels, picture: [o.width, o.height] })
}

/// The frame's statistics from the culling counters `[after frustum,
/// triangles drawn, after occlusion, triangles drawn after occlusion]`.
fn frame_stats(s: &GpuScene, o: &FrameOptions, counters: [u32; 4], gpu: Option<PassTimes>, t0: Instant) -> FrameStats {
    let [after, drawn, after_occ, drawn_occ] = counters;
    let occ = occlusion(o);
    FrameStats {
        clusters: s.clusters.len() as u32,
        clusters_after_frustum: after,
        clusters_after_occlusion: occ.then_some(after_occ),
        triangles: s.triangles,
        triangles_drawn: match (o.mesh, occ) {
            (false, _) => 0,
            (true, true) => u64::from(drawn_occ),
            (true, false) => u64::from(drawn),
        },
        points_drawn: u64::from(s.point_count),
        multi_draw: "multi_draw_indexed_indirect",
        cpu_ms: t0.elapsed().as_secs_f64() * 1e3,
        gpu,
    }
}
