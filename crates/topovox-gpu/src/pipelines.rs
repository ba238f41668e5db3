//! The voxelization shaders' pipelines: the rasterizer path's
//! (conservative and 4× MSAA, with its colour target) and the parity
//! solid's three passes, built once per [`Gpu`].

use crate::device::Device;
use crate::{Gpu, GpuError};

/// The definitions every voxelization shader starts with.
pub(crate) const COMMON: &str = include_str!("shaders/common.wgsl");

/// The rasterizer path's pipelines: conservative (hardware, or expansion
/// in the vertex shader) and 4× MSAA.
pub(crate) struct RasterPipelines {
    pub(crate) conservative: wgpu::RenderPipeline,
    pub(crate) msaa: wgpu::RenderPipeline,
    pub(crate) hardware_conservative: bool,
}

/// Samples of the MSAA approximation.
pub(crate) const MSAA_SAMPLES: u32 = 4;

impl RasterPipelines {
    pub(crate) fn new(dev: &Device, layout: &wgpu::PipelineLayout, hardware_conservative: bool) -> RasterPipelines {
        let module = dev.shader("raster", &[COMMON, include_str!("shaders/cover.wgsl"), include_str!("shaders/raster.wgsl")]);
        let device = &dev.device;
        let pipeline = |conservative: bool, samples: u32| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("raster"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState { conservative, ..Default::default() },
                depth_stencil: None,
                multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
                // A colour target is required (ECOSYSTEM.md: lavapipe rejects attachment-less passes); nothing is written to it.
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: wgpu::TextureFormat::R8Unorm,
                        blend: None,
                        write_mask: wgpu::ColorWrites::empty(),
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        RasterPipelines { conservative: pipeline(hardware_conservative, 1), msaa: pipeline(false, MSAA_SAMPLES), hardware_conservative }
    }
}

impl Gpu {
    /// The rasterizer's colour target: `side`², never written.
    pub(crate) fn raster_target(&self, side: u32, msaa: bool) -> Result<wgpu::TextureView, GpuError> {
        if side > self.dev.max_texture_side() {
            return Err(GpuError::Unsupported(format!(
                "the rasterizer path on grids over {} voxels on a side (the adapter's largest viewport); use the compute path",
                self.dev.max_texture_side()
            )));
        }
        let tex = self.dev.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("raster target"),
            size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: if msaa { MSAA_SAMPLES } else { 1 },
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        Ok(tex.create_view(&wgpu::TextureViewDescriptor::default()))
    }

    /// True when the adapter rasterizes conservatively in hardware.
    pub fn hardware_conservative(&self) -> bool {
        self.raster.hardware_conservative
    }
}

/// The three passes of the parity solid and their bind group layout.
pub(crate) struct SolidPipelines {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) flips: wgpu::ComputePipeline,
    pub(crate) xor_list: wgpu::ComputePipeline,
    pub(crate) prefix: wgpu::ComputePipeline,
}

impl SolidPipelines {
    pub(crate) fn new(dev: &Device) -> SolidPipelines {
        let module = dev.shader("solid", &[COMMON, include_str!("shaders/solid.wgsl")]);
        let device = &dev.device;
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("solid"),
            entries: &[
                entry(0, wgpu::BufferBindingType::Storage { read_only: true }),
                entry(1, wgpu::BufferBindingType::Storage { read_only: false }),
                entry(2, wgpu::BufferBindingType::Uniform),
                entry(3, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("solid"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |name: &'static str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(&pl),
                module: &module,
                entry_point: Some(name),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        SolidPipelines { flips: pipeline("flips"), xor_list: pipeline("xor_list"), prefix: pipeline("prefix"), layout }
    }
}
