//! The passes of one frame, recorded in order: cull (compute), the depth
//! pass, the Hi-Z pyramid and occlusion test, shading (triangles and spray
//! points), the overlays (cluster boxes, text) and the output (a blit to a
//! window, or a copy for readback).

use super::{Blit, FrameOptions, FrameUniform, GpuScene, Renderer, BACKGROUND, COLOUR, DEPTH, HIZ};
use crate::camera::frustum_box;
use crate::hiz::pyramid_size;
use crate::Culling;

/// The frame's colour and depth targets.
pub(super) struct Targets {
    pub colour: wgpu::Texture,
    pub depth: wgpu::Texture,
    cview: wgpu::TextureView,
    dview: wgpu::TextureView,
}

impl Targets {
    pub(super) fn new(device: &wgpu::Device, o: &FrameOptions) -> Targets {
        let texture = |format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d { width: o.width, height: o.height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let colour = texture(COLOUR, U::RENDER_ATTACHMENT | U::COPY_SRC | U::TEXTURE_BINDING);
        let depth = texture(DEPTH, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING);
        let (cview, dview) = (colour.create_view(&Default::default()), depth.create_view(&Default::default()));
        Targets { colour, depth, cview, dview }
    }
}

/// Timestamps of render pass `i` (begin `2i`, end `2i + 1`).
fn stamp(queries: Option<&wgpu::QuerySet>, i: u32) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    queries.map(|q| wgpu::RenderPassTimestampWrites {
        query_set: q,
        beginning_of_pass_write_index: Some(2 * i),
        end_of_pass_write_index: Some(2 * i + 1),
    })
}

/// Draws every cluster the culling kept, by one multi-draw-indirect call.
fn draw_clusters(pass: &mut wgpu::RenderPass<'_>, s: &GpuScene, commands: &wgpu::Buffer) {
    let n = s.clusters.len() as u32;
    pass.set_bind_group(0, &s.shade_group, &[]);
    pass.set_vertex_buffer(0, s.vertices.slice(..));
    pass.set_index_buffer(s.indices.slice(..), wgpu::IndexFormat::Uint32);
    if n > 0 {
        pass.multi_draw_indexed_indirect(commands, 0, n);
    }
}

/// A colour attachment of the picture.
fn colour_attachment(view: &wgpu::TextureView, load: wgpu::LoadOp<wgpu::Color>) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
    })
}

/// Uses occlusion culling.
pub(super) fn occlusion(o: &FrameOptions) -> bool {
    matches!(o.culling, Culling::Occlusion | Culling::OcclusionTwoPass)
}

impl Renderer {
    /// Writes the frame's uniforms and resets its commands and counters.
    pub(super) fn write_uniforms(&self, s: &GpuScene, o: &FrameOptions) {
        let (lo, hi) = s.bounds;
        let (near, far) = o.camera.depth_range(lo, hi);
        let view_proj = o.camera.view_proj(o.width as f32 / o.height as f32, near, far);
        let (f_lo, f_hi) = frustum_box(view_proj);
        let n = s.clusters.len() as u32;
        let flags = u32::from(o.gamma) | if s.lights.lights == 0 { 2 } else { 0 } | if o.light_grid_view { 4 } else { 0 };
        let u = FrameUniform {
            view_proj: view_proj.to_cols_array_2d(),
            eye: o.camera.eye.extend((o.camera.target - o.camera.eye).length()).to_array(),
            f_lo: f_lo.extend(0.0).to_array(),
            f_hi: f_hi.extend(0.0).to_array(),
            grid_lo: s.grid.lo.extend(s.grid.unit).to_array(),
            grid_cell: s.grid.cell.extend(s.grid_max as f32).to_array(),
            params: [n, u32::from(o.culling != Culling::None), flags, o.width | (o.height << 16)],
        };
        self.dev.queue.write_buffer(&s.uniform, 0, bytemuck::bytes_of(&u));
        self.dev.queue.write_buffer(&s.commands, 0, bytemuck::cast_slice(&s.commands_init));
        self.dev.queue.write_buffer(&s.counters, 0, &[0u8; 16]);
    }

    /// The frustum test of every cluster (timestamps 0 and 1).
    pub(super) fn cull_pass(&self, enc: &mut wgpu::CommandEncoder, s: &GpuScene, queries: Option<&wgpu::QuerySet>) {
        let n = s.clusters.len() as u32;
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("cull"),
            timestamp_writes: queries.map(|q| wgpu::ComputePassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            }),
        });
        pass.set_pipeline(&self.p.cull);
        pass.set_bind_group(0, &s.cull_group, &[]);
        pass.dispatch_workgroups(n.div_ceil(64).max(1), 1, 1);
    }

    /// The depth-only pass of the prepass and of occlusion culling: the
    /// frustum survivors, or with two-pass occlusion the clusters the
    /// previous frame drew.
    pub(super) fn depth_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        s: &GpuScene,
        o: &FrameOptions,
        t: &Targets,
        queries: Option<&wgpu::QuerySet>,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("depth pass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.dview,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: stamp(queries, 1),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.p.prepass);
        let two_pass = o.culling == Culling::OcclusionTwoPass;
        draw_clusters(&mut pass, s, if two_pass { &s.prev_commands } else { &s.commands });
    }

    /// Shades the kept clusters and the spray points.
    pub(super) fn shade_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        s: &GpuScene,
        o: &FrameOptions,
        t: &Targets,
        queries: Option<&wgpu::QuerySet>,
    ) {
        let load = if o.prepass { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(1.0) };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shade"),
            color_attachments: &[colour_attachment(&t.cview, wgpu::LoadOp::Clear(BACKGROUND))],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.dview,
                depth_ops: Some(wgpu::Operations { load, store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: stamp(queries, 2),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        // After a two-pass depth pass the depth holds only the previous
        // frame's clusters: shade over it with a less-or-equal test.
        pass.set_pipeline(match (o.prepass, o.culling == Culling::OcclusionTwoPass) {
            (false, _) => &self.p.shade,
            (true, false) => &self.p.shade_equal,
            (true, true) => &self.p.shade_lequal,
        });
        if o.mesh {
            draw_clusters(&mut pass, s, &s.commands);
        }
        if let (Some(points), true) = (&s.points, s.point_count > 0) {
            pass.set_pipeline(&self.p.points);
            pass.set_bind_group(0, &s.shade_group, &[]);
            pass.set_vertex_buffer(0, points.slice(..));
            pass.draw(0..s.point_count, 0..1);
        }
    }

    /// The cluster boxes (when asked) and the overlay text over the picture.
    pub(super) fn overlay_pass(&self, enc: &mut wgpu::CommandEncoder, s: &GpuScene, o: &FrameOptions, t: &Targets) {
        let n = s.clusters.len() as u32;
        let boxes = match (o.boxes && n > 0, &self.p.boxes, &s.boxes_group) {
            (true, Some((pipeline, _)), Some(group)) => Some((pipeline, group)),
            _ => None,
        };
        if boxes.is_none() && s.overlay.is_none() {
            return;
        }
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("cluster boxes and text"),
            color_attachments: &[colour_attachment(&t.cview, wgpu::LoadOp::Load)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some((pipeline, group)) = boxes {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.draw(0..24, 0..n);
        }
        if let Some((glyphs, count)) = &s.overlay {
            pass.set_pipeline(&self.p.text);
            pass.set_bind_group(0, &s.text_group, &[]);
            pass.set_vertex_buffer(0, glyphs.slice(..));
            pass.draw(0..4, 0..*count);
        }
    }

    /// Draws the picture into a window's `target` through `blit`.
    pub(super) fn blit_pass(&self, enc: &mut wgpu::CommandEncoder, t: &Targets, blit: &Blit, target: &wgpu::TextureView) {
        let group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &blit.layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&t.cview) }],
        });
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("blit"),
            color_attachments: &[colour_attachment(target, wgpu::LoadOp::Clear(BACKGROUND))],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&blit.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Builds the Hi-Z pyramid from the depth pass and runs the occlusion
    /// test over the frustum survivors; returns the pyramid texture and
    /// its level sizes.
    pub(super) fn occlusion_passes(
        &self,
        enc: &mut wgpu::CommandEncoder,
        s: &GpuScene,
        depth: &wgpu::Texture,
        o: &FrameOptions,
        queries: Option<&wgpu::QuerySet>,
    ) -> (wgpu::Texture, Vec<[u32; 2]>) {
        let (tex, sizes) = self.hiz_pyramid(enc, depth, o, queries);
        let all = tex.create_view(&Default::default());
        let read_group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.p.layouts.hiz_read,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&all) }],
        });
        let n = s.clusters.len() as u32;
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("occlude"),
            timestamp_writes: queries.map(|q| wgpu::ComputePassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: None,
                end_of_pass_write_index: Some(7),
            }),
        });
        pass.set_pipeline(&self.p.occlude);
        pass.set_bind_group(0, &s.cull_group, &[]);
        pass.set_bind_group(1, &read_group, &[]);
        pass.dispatch_workgroups(n.div_ceil(64).max(1), 1, 1);
        drop(pass);
        (tex, sizes)
    }

    /// The Hi-Z pyramid of the depth: level 0 copies it, each next level
    /// takes the farthest of 2×2 texels (timestamp 6 at its start).
    fn hiz_pyramid(
        &self,
        enc: &mut wgpu::CommandEncoder,
        depth: &wgpu::Texture,
        o: &FrameOptions,
        queries: Option<&wgpu::QuerySet>,
    ) -> (wgpu::Texture, Vec<[u32; 2]>) {
        let ([w0, h0], count) = pyramid_size(o.width, o.height);
        let tex = self.dev.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("hi-z"),
            size: wgpu::Extent3d { width: w0, height: h0, depth_or_array_layers: 1 },
            mip_level_count: count,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HIZ,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let level =
            |l: u32| tex.create_view(&wgpu::TextureViewDescriptor { base_mip_level: l, mip_level_count: Some(1), ..Default::default() });
        let depth_view = depth.create_view(&wgpu::TextureViewDescriptor { aspect: wgpu::TextureAspect::DepthOnly, ..Default::default() });
        let sizes: Vec<[u32; 2]> = (0..count).map(|l| [(w0 >> l).max(1), (h0 >> l).max(1)]).collect();
        for l in 0..count {
            // Level 0 reads the depth; the source binding is then any
            // level but the one written (level 1 for level 0: unused, or
            // a dummy when there is no other level).
            let src = if l == 0 && count == 1 { self.dummy_float() } else { level(if l == 0 { 1 } else { l - 1 }) };
            let group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.p.layouts.hiz,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_view) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&src) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&level(l)) },
                ],
            });
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("hi-z level"),
                timestamp_writes: queries.filter(|_| l == 0).map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: q,
                    beginning_of_pass_write_index: Some(6),
                    end_of_pass_write_index: None,
                }),
            });
            pass.set_pipeline(if l == 0 { &self.p.hiz_copy } else { &self.p.hiz_reduce });
            pass.set_bind_group(0, &group, &[]);
            let [w, h] = sizes[l as usize];
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        (tex, sizes)
    }
}
