//! [`Gpu`]: an open device with the voxelization pipelines; the passes
//! themselves are in `compute.rs` and `solid.rs`.

use crate::device::{self, headless, Device, REQUIRED};
use crate::pipelines::{RasterPipelines, SolidPipelines, COMMON};
use crate::GpuError;

/// An open GPU device with the voxelization pipelines.
pub struct Gpu {
    pub(crate) dev: Device,
    pub(crate) cover: wgpu::ComputePipeline,
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) solid: SolidPipelines,
    pub(crate) raster: RasterPipelines,
    /// Largest storage buffer the output slab may use, in bytes.
    pub(crate) max_slab_bytes: u64,
}

impl Gpu {
    /// Opens the default adapter (high performance preferred) with the
    /// features the exact path needs.
    pub fn new() -> Result<Gpu, GpuError> {
        let dev = Device::open(
            &wgpu::Instance::new(headless()),
            &device::DeviceOptions {
                label: "topovox",
                surface: None,
                required: REQUIRED,
                optional: wgpu::Features::CONSERVATIVE_RASTERIZATION | wgpu::Features::TIMESTAMP_QUERY,
            },
        )?;
        let limits = &dev.limits;
        let max_slab_bytes = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size).min(1 << 30);
        let module = dev.shader("cover", &[COMMON, include_str!("shaders/cover.wgsl")]);
        let device = &dev.device;
        // The rasterizer shares this layout: triangles and parameters are
        // read in the vertex and fragment stages, bits written in fragments.
        let all = wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: if read_only { all } else { wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT },
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("voxelize"),
            entries: &[
                storage(0, true),
                storage(1, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: all,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("voxelize"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let cover = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("cover"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let solid = SolidPipelines::new(&dev);
        let hardware_conservative = dev.features.contains(wgpu::Features::CONSERVATIVE_RASTERIZATION);
        let raster = RasterPipelines::new(&dev, &pl, hardware_conservative);
        dev.check()?;
        Ok(Gpu { dev, cover, layout, solid, raster, max_slab_bytes })
    }

    /// The first error the device reported since the last check, if any.
    pub(crate) fn check(&self) -> Result<(), GpuError> {
        self.dev.check()
    }

    /// The adapter's name and backend, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter(&self) -> String {
        self.dev.adapter_name()
    }

    /// True for software adapters (lavapipe, WARP): correct, not fast (see also [`hardware_adapter`](crate::hardware_adapter)).
    pub fn is_software(&self) -> bool {
        self.dev.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Caps the output slab size (tests use it to force many slabs).
    pub fn set_max_slab_bytes(&mut self, bytes: u64) {
        self.max_slab_bytes = bytes.max(4);
    }
}
