//! # topovox-gpu
//!
//! GPU voxelization through wgpu (Vulkan, Metal, DX12), giving exactly the
//! CPU's voxels.
//!
//! **What it runs** (after M. Schwarz, H.-P. Seidel, "Fast Parallel
//! Surface and Solid Voxelization on GPUs", 2010), for `cover`, `sep26`
//! and `sep6` ([`Gpu::voxelize`], [`GpuMode`]) along three paths
//! ([`GpuPath`]):
//! - **compute** (`compute.rs`, `shaders/cover.wgsl`): one workgroup per
//!   triangle, its threads striding over the columns of the dominant-axis
//!   projection, bits set with `atomicOr`;
//! - **raster** (`shaders/raster.wgsl`): each triangle projected along its
//!   dominant axis in the vertex shader, conservative coverage (hardware
//!   where the adapter has it, else the pixel-aligned bounding rectangle
//!   culled by exact tests in the fragment shader) — the same voxels;
//! - **MSAA approximation**: 4× MSAA without conservative coverage, which
//!   never sets a wrong voxel but misses some (counted in the report).
//!
//! And the **solid** by parity ([`Gpu::solid_parity`], `solid.rs`,
//! `shaders/solid.wgsl`): triangle-parallel parity flips with `atomicXor`
//! at each row's first inside voxel, then a prefix XOR per row — the
//! voxels of the CPU's parity solid. Every path processes the grid in
//! z-slabs that fit the device's buffer limits; what a device cannot do
//! (a viewport smaller than the grid, a layer past the buffer limit) is a
//! [`GpuError::Unsupported`] naming it.
//!
//! **Exactness.** Vertices are snapped on the CPU to the lattice every
//! topovox path uses ([`topovox::geom::lattice::prepare`]); the shader decides
//! each candidate voxel by the exact separating axis test of the CPU
//! reference, and for `sep26`/`sep6` by the modes' target tests with the
//! same tie rule (Laine's perturbation, predicate for predicate), in 64-bit
//! integers on coordinates relative to the triangle's box (the adapter
//! must offer `SHADER_INT64`). A triangle whose relative coordinates could
//! overflow those products (spanning more than about 126 voxels for
//! `cover`, 62 for the others) is voxelized by the CPU's exact fast path
//! instead, and the two results are OR-ed. So the output equals the CPU reference voxel for
//! voxel; the tests check it on every shared mesh, rotations and random
//! triangles.

mod compute;
pub mod device;
mod params;
mod slabs;
mod solid;

pub use compute::{CoverReport, GpuMode, GpuPath, Timings};
pub use device::Device;
pub use solid::SolidGpuReport;

use thiserror::Error;

/// Why the GPU path could not run.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter (no Vulkan/Metal/DX12 driver).
    #[error("no GPU adapter found (install a Vulkan driver; on Linux without a GPU, Mesa's lavapipe: apt install mesa-vulkan-drivers)")]
    NoAdapter,
    /// The adapter lacks something the exact path needs.
    #[error("GPU adapter {adapter} lacks {what}")]
    MissingFeature {
        /// Adapter name.
        adapter: String,
        /// What is missing.
        what: &'static str,
    },
    /// The device could not be created or was lost.
    #[error("GPU device: {0}")]
    Device(String),
    /// A buffer could not be read back.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// A mode or feature the GPU path does not have yet.
    #[error("the GPU path does not support {0} yet")]
    Unsupported(String),
}

/// The definitions every voxelization shader starts with.
const COMMON: &str = include_str!("shaders/common.wgsl");

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
    fn new(dev: &Device, layout: &wgpu::PipelineLayout, hardware_conservative: bool) -> RasterPipelines {
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
    fn new(dev: &Device) -> SolidPipelines {
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

/// The instance for headless work: Vulkan, Metal and DX12 (`WGPU_BACKEND`
/// chooses others). Not OpenGL: its EGL setup probes for a Wayland display
/// and, on a headless machine without `XDG_RUNTIME_DIR`, prints "error:"
/// lines on stderr of runs that succeed; no compute path uses it.
pub fn headless() -> wgpu::InstanceDescriptor {
    quiet_without_display();
    wgpu::InstanceDescriptor { backends: wgpu::Backends::PRIMARY, ..wgpu::InstanceDescriptor::new_without_display_handle() }.with_env()
}

/// On a machine without a display (no `WAYLAND_DISPLAY`, `DISPLAY` or
/// valid `XDG_RUNTIME_DIR`), turns off Mesa's Vulkan device-selection
/// layer (`NODEVICE_SELECT=1`) unless the user chose a device with it
/// (`MESA_VK_DEVICE_SELECT`): while devices are enumerated it looks for a
/// Wayland display and prints "error: XDG_RUNTIME_DIR is invalid" on
/// stderr of runs that succeed. It only orders devices by the display's,
/// which a machine without one does not have. Once per process; the CLI
/// calls it first thing, while it has one thread.
pub fn quiet_without_display() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let set = |v: &str| std::env::var_os(v).is_some_and(|x| !x.is_empty());
        let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
        let display = set("WAYLAND_DISPLAY") || set("DISPLAY") || runtime_dir;
        if !display && !set("MESA_VK_DEVICE_SELECT") && !set("NODEVICE_SELECT") {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    });
}

/// What the exact path cannot do without.
const REQUIRED: &[(wgpu::Features, &str)] = &[(wgpu::Features::SHADER_INT64, "64-bit integers in shaders (SHADER_INT64)")];

/// The default adapter (high performance preferred), if it has what the
/// exact path needs.
fn adapter() -> Result<wgpu::Adapter, GpuError> {
    device::adapter(&wgpu::Instance::new(headless()), None, REQUIRED)
}

/// Is the adapter [`Gpu::new`] would open a hardware one (not lavapipe or
/// WARP)? Asks for the adapter only: no device, no pipelines, so a caller
/// deciding whether to use the GPU pays little.
pub fn hardware_adapter() -> Result<bool, GpuError> {
    if !hardware_plausible() {
        return Ok(false);
    }
    Ok(adapter()?.get_info().device_type != wgpu::DeviceType::Cpu)
}

/// On Linux a hardware GPU is reached through a DRM render node or the
/// NVIDIA device files; without either there is none to find, and asking
/// the Vulkan loader would only wake Mesa's software driver and its
/// device-selection layer, which prints to stderr when no display is set
/// up (`XDG_RUNTIME_DIR is invalid`). Elsewhere (Metal, DX12), ask.
fn hardware_plausible() -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    let any_in = |dir: &str, prefix: &str| {
        std::fs::read_dir(dir).is_ok_and(|d| d.flatten().any(|e| e.file_name().to_string_lossy().starts_with(prefix)))
    };
    any_in("/dev/dri", "renderD") || any_in("/dev", "nvidia")
}

/// An open GPU device with the voxelization pipelines.
pub struct Gpu {
    dev: Device,
    cover: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    solid: SolidPipelines,
    raster: RasterPipelines,
    /// Largest storage buffer the output slab may use, in bytes.
    max_slab_bytes: u64,
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

    /// True for software adapters (lavapipe, WARP): correct, not fast (see also [`hardware_adapter`]).
    pub fn is_software(&self) -> bool {
        self.dev.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Caps the output slab size (tests use it to force many slabs).
    pub fn set_max_slab_bytes(&mut self, bytes: u64) {
        self.max_slab_bytes = bytes.max(4);
    }
}
