//! The frame on the GPU (wgpu): a compute pass culls cluster boxes and
//! writes the indirect commands, an optional depth-only Z-prepass, then
//! the shading pass; both draw passes draw the whole scene with one
//! `multi_draw_indexed_indirect` call over the clusters' commands.
//!
//! **Culled clusters keep their slot** with an instance count of zero
//! (rather than being compacted). The command buffer then holds one
//! command per cluster in cluster order whatever the camera, so the draw
//! order, and with it the picture, is the same with culling on or off
//! (byte for byte, which the tests check), and the call needs no count
//! buffer. `multi_draw_indexed_indirect_count` would only pay with
//! compaction, which atomics would make order-dependent; it is not used
//! (the statistics name the call that ran).

use std::time::Instant;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::camera::{frustum_box, Camera};
use crate::hiz::{pyramid_size, Pyramid};
use crate::lights::{grid_frame, lights, LightGrid, LightReport, GRID};
use crate::partition::{Cluster, Partition};
use crate::scene::Scene;
use crate::spray::SprayPoint;
use crate::ViewError;
use topovox_gpu::device::{Device, DeviceOptions};
use topovox_gpu::GpuError;

mod pipelines;

pub use topovox::render::Culling;

/// What one frame is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameOptions {
    /// Picture width in pixels.
    pub width: u32,
    /// Picture height in pixels.
    pub height: u32,
    /// The camera.
    pub camera: Camera,
    /// Cluster culling.
    pub culling: Culling,
    /// Depth-only pass first, then shading with an equal depth test.
    pub prepass: bool,
    /// Linear to sRGB on output.
    pub gamma: bool,
    /// Colour surfaces by their light-grid cell's list length (blue: no
    /// light, red: the longest list) instead of shading them.
    pub light_grid_view: bool,
    /// With occlusion culling: read the Hi-Z pyramid back into
    /// [`Frame::hiz`] (for tests and pictures).
    pub read_hiz: bool,
    /// Draw the scene's triangles (off: only the spray's points, when
    /// there are any; culling still runs and is reported).
    pub mesh: bool,
    /// Draw every cluster's box over the picture, green where the cluster
    /// was drawn and red where culling dropped it.
    pub boxes: bool,
}

impl FrameOptions {
    /// A `width × height` frame from `camera` with the defaults of `render
    /// --gpu`: occlusion culling, no prepass, gamma, the mesh shaded, no
    /// boxes.
    pub fn new(width: u32, height: u32, camera: Camera) -> FrameOptions {
        FrameOptions {
            width,
            height,
            camera,
            culling: Culling::Occlusion,
            prepass: false,
            gamma: true,
            light_grid_view: false,
            read_hiz: false,
            mesh: true,
            boxes: false,
        }
    }
}

/// Per-pass GPU time in milliseconds (timestamp queries), where the
/// adapter writes them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// The culling compute pass.
    pub cull_ms: f64,
    /// The depth pass: the Z-prepass, or occlusion culling's depth pass
    /// (0 when neither runs).
    pub depth_ms: f64,
    /// Building the Hi-Z pyramid and testing the clusters (0 without
    /// occlusion culling).
    pub hiz_ms: f64,
    /// The shading pass.
    pub shade_ms: f64,
}

/// What a frame drew and how long it took.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameStats {
    /// Clusters in the scene.
    pub clusters: u32,
    /// Clusters kept by the frustum test (all of them without culling).
    pub clusters_after_frustum: u32,
    /// Clusters kept by the occlusion test too (with occlusion culling).
    pub clusters_after_occlusion: Option<u32>,
    /// Triangles in the scene.
    pub triangles: u64,
    /// Triangles of the kept clusters (0 with the mesh hidden).
    pub triangles_drawn: u64,
    /// Spray points drawn.
    pub points_drawn: u64,
    /// The draw call that ran.
    pub multi_draw: &'static str,
    /// Wall time from encoding to the picture read back.
    pub cpu_ms: f64,
    /// GPU time per pass, if the adapter has timestamps.
    pub gpu: Option<PassTimes>,
}

/// A rendered frame: RGBA8 rows top to bottom, and which clusters the GPU kept.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 4` bytes.
    pub rgba: Vec<u8>,
    /// Per cluster, whether its command was drawn.
    pub kept: Vec<bool>,
    /// The Hi-Z pyramid, when asked for.
    pub hiz: Option<Pyramid>,
    /// Counts and times.
    pub stats: FrameStats,
}

/// A pipeline that copies a frame onto a window's texture format.
pub struct Blit {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl Frame {
    /// The picture as RGB rows (alpha dropped), as PNG writers take it.
    pub fn rgb(&self) -> Vec<u8> {
        self.rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
    }
}

/// The frame's uniform block (`frame.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FrameUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    f_lo: [f32; 4],
    f_hi: [f32; 4],
    grid_lo: [f32; 4],
    grid_cell: [f32; 4],
    params: [u32; 4],
}

/// Pixels between the picture's corner and the overlay text.
pub const OVERLAY_MARGIN: f32 = 4.0;
/// Overlay glyphs are 8×8 font texels drawn this many pixels wide.
pub const GLYPH_SCALE: f32 = 2.0;

/// One overlay glyph (`text.wgsl`): its top-left pixel and ASCII code.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Glyph {
    at: [f32; 2],
    code: u32,
}

/// font8x8's 128 ASCII glyphs side by side in a 1024×8 texture, one byte
/// per texel (255 where the glyph is drawn; bit 0 of a row is its left).
fn font_atlas(device: &wgpu::Device, queue: &wgpu::Queue) -> wgpu::TextureView {
    let mut texels = vec![0u8; 1024 * 8];
    for (code, rows) in font8x8::legacy::BASIC_LEGACY.iter().enumerate() {
        for (y, row) in rows.iter().enumerate() {
            for x in 0..8 {
                if row & (1 << x) != 0 {
                    texels[y * 1024 + code * 8 + x] = 255;
                }
            }
        }
    }
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("font"),
            size: wgpu::Extent3d { width: 1024, height: 8, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &texels,
    );
    texture.create_view(&Default::default())
}

/// A cluster box as `cull.wgsl` reads it.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ClusterBox {
    lo: [f32; 4],
    hi: [f32; 4],
}

/// A scene on the device: its buffers and what the CPU knows of it.
pub struct GpuScene {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    commands: wgpu::Buffer,
    commands_init: Vec<u32>,
    /// The commands the previous frame drew (the two-pass depth pass).
    prev_commands: wgpu::Buffer,
    counters: wgpu::Buffer,
    cull_group: wgpu::BindGroup,
    shade_group: wgpu::BindGroup,
    boxes_group: Option<wgpu::BindGroup>,
    text_group: wgpu::BindGroup,
    /// The overlay's glyphs ([`Renderer::set_overlay`]) and their count.
    overlay: Option<(wgpu::Buffer, u32)>,
    uniform: wgpu::Buffer,
    /// The clusters, in command order.
    pub clusters: Vec<Cluster>,
    /// The light grid as the GPU built it (read back).
    pub grid: LightGrid,
    /// Milliseconds the GPU build took (submit to read back).
    pub grid_ms: f64,
    /// The longest cell list (the light-grid view's red).
    grid_max: u32,
    /// Lights and the emissive triangles they came from.
    pub lights: LightReport,
    /// Scene box.
    pub bounds: (Vec3, Vec3),
    /// Triangles.
    pub triangles: u64,
    /// The spray's points ([`Renderer::add_points`]): the buffer (its
    /// size the capacity) and how many it holds.
    points: Option<wgpu::Buffer>,
    point_count: u32,
}

/// An open device with the frame's pipelines.
pub struct Renderer {
    /// The device, shared layer of `topovox-gpu`.
    pub(crate) dev: Device,
    /// The frame's pipelines and layouts.
    p: pipelines::Pipelines,
    font: wgpu::TextureView,
    timestamps: bool,
    max_side: u32,
}

pub(crate) const COLOUR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub(crate) const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub(crate) const HIZ: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// The largest side of the texture array's layers.
pub const MAX_TEXTURE_SIDE: u32 = 2048;
/// The most bytes the texture array takes.
pub const MAX_TEXTURE_BYTES: u64 = 512 << 20;
/// Background, written as is (not gamma corrected).
const BACKGROUND: wgpu::Color = wgpu::Color { r: 0.10, g: 0.10, b: 0.12, a: 1.0 };

/// The definitions the frame's shaders start with.
const FRAME: &str = include_str!("../shaders/frame.wgsl");

impl Renderer {
    /// Opens the default adapter (high performance preferred).
    pub fn new() -> Result<Renderer, ViewError> {
        Renderer::open(&wgpu::Instance::new(topovox_gpu::headless()), None)
    }

    /// Opens an adapter of `instance` (one that can present to `surface`,
    /// when given).
    pub fn open(instance: &wgpu::Instance, surface: Option<&wgpu::Surface<'_>>) -> Result<Renderer, ViewError> {
        let dev = Device::open(
            instance,
            &DeviceOptions { label: "topovox view", surface, required: &[], optional: wgpu::Features::TIMESTAMP_QUERY },
        )?;
        let r = Renderer {
            p: pipelines::Pipelines::new(&dev),
            font: font_atlas(&dev.device, &dev.queue),
            timestamps: dev.features.contains(wgpu::Features::TIMESTAMP_QUERY),
            max_side: dev.limits.max_texture_dimension_2d,
            dev,
        };
        r.check()?;
        Ok(r)
    }

    /// Shows a window's surface texture.
    pub fn present_texture(&self, texture: wgpu::SurfaceTexture) {
        self.dev.queue.present(texture);
    }

    /// The largest picture side the adapter takes.
    pub fn max_side(&self) -> u32 {
        self.max_side
    }

    /// The adapter's name and backend.
    pub fn adapter(&self) -> String {
        self.dev.adapter_name()
    }

    fn check(&self) -> Result<(), ViewError> {
        Ok(self.dev.check()?)
    }

    /// Partitions the scene, builds its lights and light grid, and uploads it.
    pub fn upload(&self, scene: &Scene) -> Result<GpuScene, ViewError> {
        let bounds = scene.bounds().ok_or(ViewError::EmptyScene)?;
        let part = Partition::new(scene);
        let (lights, report) = lights(scene);
        let t_grid = Instant::now();
        let light_buf = self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lights"),
            contents: bytemuck::cast_slice(&nonempty(&lights)),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let (grid, ranges, light_indices) = self.light_grid(scene, &light_buf, lights.len() as u32)?;
        let grid_ms = t_grid.elapsed().as_secs_f64() * 1e3;
        let init = |label, contents: &[u8], usage| {
            self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        use wgpu::BufferUsages as U;
        let vertices = init("vertices", bytemuck::cast_slice(&scene.vertices), U::VERTEX);
        let indices = init("indices", bytemuck::cast_slice(&part.indices), U::INDEX);
        let boxes: Vec<ClusterBox> =
            part.clusters.iter().map(|c| ClusterBox { lo: c.lo.extend(0.0).to_array(), hi: c.hi.extend(0.0).to_array() }).collect();
        let commands_init: Vec<u32> = part.clusters.iter().flat_map(|c| [c.index_count, 1, c.first_index, 0, 0]).collect();
        let boxes = init("cluster boxes", bytemuck::cast_slice(&boxes), U::STORAGE);
        let commands = init("commands", bytemuck::cast_slice(&commands_init), U::STORAGE | U::INDIRECT | U::COPY_DST | U::COPY_SRC);
        let counters = init("counters", &[0u8; 16], U::STORAGE | U::COPY_DST | U::COPY_SRC);
        let prev_commands = init("previous commands", bytemuck::cast_slice(&commands_init), U::INDIRECT | U::COPY_DST);
        let uniform = self.dev.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: U::UNIFORM | U::COPY_DST,
            mapped_at_creation: false,
        });
        let materials = init("materials", bytemuck::cast_slice(&nonempty(&scene.materials)), U::STORAGE);
        let textures = self.texture_array(&scene.textures)?;
        let texture_view = textures
            .create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() });
        let sampler = self.dev.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("textures"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let group = |layout, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> =
                entries.iter().map(|(binding, b)| wgpu::BindGroupEntry { binding: *binding, resource: b.as_entire_binding() }).collect();
            self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout, entries: &entries })
        };
        let cull_group = group(&self.p.layouts.cull, &[(0, &uniform), (1, &boxes), (2, &commands), (3, &counters)]);
        let boxes_group = self.p.boxes.as_ref().map(|(_, layout)| group(layout, &[(0, &uniform), (1, &boxes), (2, &commands)]));
        let text_group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("overlay text"),
            layout: &self.p.layouts.text,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&self.font) },
            ],
        });
        let buffers = [(0, &uniform), (4, &materials), (5, &light_buf), (6, &ranges), (7, &light_indices)];
        let mut entries: Vec<wgpu::BindGroupEntry> =
            buffers.iter().map(|(binding, b)| wgpu::BindGroupEntry { binding: *binding, resource: b.as_entire_binding() }).collect();
        entries.push(wgpu::BindGroupEntry { binding: 8, resource: wgpu::BindingResource::TextureView(&texture_view) });
        entries.push(wgpu::BindGroupEntry { binding: 9, resource: wgpu::BindingResource::Sampler(&sampler) });
        let shade_group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shade"),
            layout: &self.p.layouts.shade,
            entries: &entries,
        });
        self.check()?;
        Ok(GpuScene {
            vertices,
            indices,
            commands,
            commands_init,
            prev_commands,
            counters,
            cull_group,
            shade_group,
            boxes_group,
            text_group,
            overlay: None,
            uniform,
            clusters: part.clusters,
            grid_max: grid.stats().2,
            grid,
            grid_ms,
            lights: report,
            bounds,
            triangles: scene.triangles() as u64,
            points: None,
            point_count: 0,
        })
    }

    /// The scene's textures as one array of sRGB layers (sampled as
    /// linear colour; alpha stays linear), every texture resized to the
    /// array's square side: the largest texture side, at most
    /// [`MAX_TEXTURE_SIDE`] and halved until the array fits in
    /// [`MAX_TEXTURE_BYTES`]. One white texel when there is none.
    fn texture_array(&self, textures: &[topovox::attributes::Texture]) -> Result<wgpu::Texture, ViewError> {
        let layers = textures.len().max(1) as u32;
        let max_layers = self.dev.device.limits().max_texture_array_layers;
        if layers > max_layers {
            return Err(ViewError::device(format!("{layers} textures: this adapter takes at most {max_layers} in one array")));
        }
        let mut side = textures.iter().map(|t| t.width.max(t.height)).max().unwrap_or(1).clamp(1, MAX_TEXTURE_SIDE.min(self.max_side));
        while side > 1 && u64::from(side) * u64::from(side) * 4 * u64::from(layers) > MAX_TEXTURE_BYTES {
            side /= 2;
        }
        let texture = self.dev.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("textures"),
            size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let white = [255u8; 4];
        for layer in 0..layers {
            let texels: Vec<u8> = match textures.get(layer as usize) {
                None => white.repeat((side * side) as usize),
                Some(t) if t.width == side && t.height == side && t.rgba.len() == (4 * side * side) as usize => t.rgba.clone(),
                Some(t) => match image::RgbaImage::from_raw(t.width, t.height, t.rgba.clone()) {
                    Some(img) => image::imageops::resize(&img, side, side, image::imageops::FilterType::Triangle).into_raw(),
                    None => {
                        return Err(ViewError::device(format!("texture {}: {} bytes for {}x{}", t.name, t.rgba.len(), t.width, t.height)))
                    }
                },
            };
            self.dev.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                    aspect: wgpu::TextureAspect::All,
                },
                &texels,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * side), rows_per_image: Some(side) },
                wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 1 },
            );
        }
        Ok(texture)
    }

    /// Adds spray points to the scene (drawn by every later frame); the
    /// buffer grows by doubling, so adding a cursor's spray at a time
    /// stays cheap.
    pub fn add_points(&self, s: &mut GpuScene, points: &[SprayPoint]) -> Result<(), ViewError> {
        if points.is_empty() {
            return Ok(());
        }
        let stride = std::mem::size_of::<SprayPoint>() as u64;
        let count = u64::from(s.point_count) + points.len() as u64;
        let max = self.dev.device.limits().max_buffer_size / stride;
        if count > max.min(u64::from(u32::MAX)) {
            return Err(ViewError::device(format!("{count} spray points exceed this adapter's largest buffer ({max} points)")));
        }
        let capacity = s.points.as_ref().map_or(0, |b| b.size() / stride);
        if count > capacity {
            let size = count.max(2 * capacity).max(1024).min(max) * stride;
            let grown = self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("spray points"),
                size,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            if let Some(old) = &s.points {
                let mut enc = self.dev.device.create_command_encoder(&Default::default());
                enc.copy_buffer_to_buffer(old, 0, &grown, 0, u64::from(s.point_count) * stride);
                self.dev.queue.submit([enc.finish()]);
            }
            s.points = Some(grown);
        }
        let buffer = s.points.as_ref().expect("grown above");
        self.dev.queue.write_buffer(buffer, u64::from(s.point_count) * stride, bytemuck::cast_slice(points));
        s.point_count = count as u32;
        self.check()
    }

    /// Text drawn over every later frame from the top-left corner, one
    /// line per string, 16-pixel glyphs (ASCII; other characters show as
    /// `?`), until set again; an empty list draws none.
    pub fn set_overlay(&self, s: &mut GpuScene, lines: &[String]) {
        let step = 8.0 * GLYPH_SCALE;
        let glyphs: Vec<Glyph> = lines
            .iter()
            .enumerate()
            .flat_map(|(l, line)| {
                line.chars().enumerate().map(move |(i, c)| Glyph {
                    at: [OVERLAY_MARGIN + i as f32 * step, OVERLAY_MARGIN + l as f32 * (step + 2.0)],
                    code: if c.is_ascii() { c as u32 } else { u32::from(b'?') },
                })
            })
            .collect();
        s.overlay = (!glyphs.is_empty()).then(|| {
            let buffer = self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("overlay glyphs"),
                contents: bytemuck::cast_slice(&glyphs),
                usage: wgpu::BufferUsages::VERTEX,
            });
            (buffer, glyphs.len() as u32)
        });
    }

    /// Drops the scene's spray points.
    pub fn clear_points(&self, s: &mut GpuScene) {
        s.points = None;
        s.point_count = 0;
    }

    /// Renders one frame and reads it back.
    pub fn render(&self, s: &GpuScene, o: &FrameOptions) -> Result<Frame, ViewError> {
        self.frame(s, o, None)
    }

    /// Renders one frame into `target` through `blit` (a window's surface
    /// texture) instead of reading the picture back; the statistics are
    /// read back as for [`Renderer::render`].
    pub fn present(&self, s: &GpuScene, o: &FrameOptions, blit: &Blit, target: &wgpu::TextureView) -> Result<FrameStats, ViewError> {
        Ok(self.frame(s, o, Some((blit, target)))?.stats)
    }

    /// A pipeline copying frames onto textures of `format`.
    pub fn blit(&self, format: wgpu::TextureFormat) -> Blit {
        let module = self.dev.shader("blit", &[include_str!("../shaders/blit.wgsl")]);
        let layout = self.dev.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blit"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pl = self.dev.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = self.dev.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("blit"),
            layout: Some(&pl),
            vertex: wgpu::VertexState { module: &module, entry_point: Some("vs"), compilation_options: Default::default(), buffers: &[] },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Blit { pipeline, layout }
    }

    fn frame(&self, s: &GpuScene, o: &FrameOptions, present: Option<(&Blit, &wgpu::TextureView)>) -> Result<Frame, ViewError> {
        if o.width == 0 || o.height == 0 || o.width > self.max_side || o.height > self.max_side {
            return Err(ViewError::Size { width: o.width, height: o.height, max: self.max_side });
        }
        if o.boxes && self.p.boxes.is_none() {
            return Err(ViewError::device(
                "the cluster-box wireframe needs vertex shaders that read storage buffers, which this adapter lacks".into(),
            ));
        }
        let t0 = Instant::now();
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

        let queries = self.timestamps.then(|| {
            self.dev.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass times"),
                ty: wgpu::QueryType::Timestamp,
                count: 8,
            })
        });
        let stamp = |i: u32| {
            queries.as_ref().map(|q| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(2 * i),
                end_of_pass_write_index: Some(2 * i + 1),
            })
        };
        let mut enc = self.dev.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cull"),
                timestamp_writes: queries.as_ref().map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: q,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
            });
            pass.set_pipeline(&self.p.cull);
            pass.set_bind_group(0, &s.cull_group, &[]);
            pass.dispatch_workgroups(n.div_ceil(64).max(1), 1, 1);
        }
        let texture = |format, usage| {
            self.dev.device.create_texture(&wgpu::TextureDescriptor {
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
        let colour =
            texture(COLOUR, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING);
        let occlusion = matches!(o.culling, Culling::Occlusion | Culling::OcclusionTwoPass);
        let two_pass = o.culling == Culling::OcclusionTwoPass;
        let depth = texture(DEPTH, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING);
        let (cview, dview) = (colour.create_view(&Default::default()), depth.create_view(&Default::default()));
        let draw_all = |pass: &mut wgpu::RenderPass<'_>, commands: &wgpu::Buffer| {
            pass.set_bind_group(0, &s.shade_group, &[]);
            pass.set_vertex_buffer(0, s.vertices.slice(..));
            pass.set_index_buffer(s.indices.slice(..), wgpu::IndexFormat::Uint32);
            if n > 0 {
                pass.multi_draw_indexed_indirect(commands, 0, n);
            }
        };
        if o.prepass || occlusion {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("depth pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &dview,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: stamp(1),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.p.prepass);
            draw_all(&mut pass, if two_pass { &s.prev_commands } else { &s.commands });
        }
        let hiz = occlusion.then(|| self.occlusion_passes(&mut enc, s, &depth, o, queries.as_ref()));
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shade"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &cview,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(BACKGROUND), store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &dview,
                    depth_ops: Some(wgpu::Operations {
                        load: if o.prepass { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(1.0) },
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: stamp(2),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // After a two-pass depth pass the depth holds only the previous
            // frame's clusters: shade over it with a less-or-equal test.
            pass.set_pipeline(match (o.prepass, two_pass) {
                (false, _) => &self.p.shade,
                (true, false) => &self.p.shade_equal,
                (true, true) => &self.p.shade_lequal,
            });
            if o.mesh {
                draw_all(&mut pass, &s.commands);
            }
            if let (Some(points), true) = (&s.points, s.point_count > 0) {
                pass.set_pipeline(&self.p.points);
                pass.set_bind_group(0, &s.shade_group, &[]);
                pass.set_vertex_buffer(0, points.slice(..));
                pass.draw(0..s.point_count, 0..1);
            }
        }
        let boxes = match (o.boxes && n > 0, &self.p.boxes, &s.boxes_group) {
            (true, Some((pipeline, _)), Some(group)) => Some((pipeline, group)),
            _ => None,
        };
        if boxes.is_some() || s.overlay.is_some() {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("cluster boxes and text"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &cview,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
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
        enc.copy_buffer_to_buffer(&s.commands, 0, &s.prev_commands, 0, 20 * n.max(1) as u64);
        let row = aligned_row(o.width);
        let readback = |label, size| {
            self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let pixels = present.is_none().then(|| readback("picture", row as u64 * o.height as u64));
        match (present, &pixels) {
            (Some((blit, target)), _) => {
                let group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: None,
                    layout: &blit.layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&cview) }],
                });
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("blit"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(BACKGROUND), store: wgpu::StoreOp::Store },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&blit.pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.draw(0..3, 0..1);
            }
            (None, Some(pixels)) => enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: &colour,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: pixels,
                    layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(o.height) },
                },
                wgpu::Extent3d { width: o.width, height: o.height, depth_or_array_layers: 1 },
            ),
            (None, None) => unreachable!("frames not presented are read back"),
        }
        let hiz_read = match (&hiz, o.read_hiz) {
            (Some(h), true) => Some(self.copy_levels(&mut enc, h)),
            _ => None,
        };
        let cmd_bytes = 20 * n.max(1) as u64;
        let cmds = readback("commands", cmd_bytes);
        enc.copy_buffer_to_buffer(&s.commands, 0, &cmds, 0, cmd_bytes);
        let counts = readback("counters", 16);
        enc.copy_buffer_to_buffer(&s.counters, 0, &counts, 0, 16);
        let times = queries.as_ref().map(|q| {
            let resolve = self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = readback("timestamps readback", 64);
            enc.resolve_query_set(q, 0..8, &resolve, 0);
            enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, 64);
            read
        });
        self.dev.queue.submit([enc.finish()]);
        let mapped: Vec<&wgpu::Buffer> = [pixels.as_ref(), Some(&cmds), Some(&counts), times.as_ref()]
            .into_iter()
            .flatten()
            .chain(hiz_read.iter().flat_map(|(bufs, _)| bufs.iter()))
            .collect();
        self.dev.map_all(&mapped.iter().map(|b| b.slice(..)).collect::<Vec<_>>())?;
        let mut rgba = Vec::with_capacity(4 * o.width as usize * o.height as usize);
        if let Some(pixels) = &pixels {
            let data = pixels.slice(..).get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
            for y in 0..o.height as usize {
                rgba.extend_from_slice(&data[y * row as usize..y * row as usize + 4 * o.width as usize]);
            }
        }
        let kept: Vec<bool> = {
            let data = cmds.slice(..).get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
            let words: &[u32] = bytemuck::cast_slice(&data);
            (0..n as usize).map(|c| words[5 * c + 1] != 0).collect()
        };
        let [after, drawn, after_occ, drawn_occ] = {
            let data = counts.slice(..).get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
            let w: &[u32] = bytemuck::cast_slice(&data);
            [w[0], w[1], w[2], w[3]]
        };
        let hiz = match hiz_read {
            Some((bufs, sizes)) => {
                let mut levels = Vec::with_capacity(bufs.len());
                for (b, [w, h]) in bufs.iter().zip(&sizes) {
                    let data = b.slice(..).get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
                    let row = aligned_row(*w) as usize;
                    let mut level = Vec::with_capacity((*w * *h) as usize);
                    for y in 0..*h as usize {
                        level.extend_from_slice(bytemuck::cast_slice::<u8, f32>(&data[y * row..y * row + 4 * *w as usize]));
                    }
                    levels.push(level);
                }
                Some(Pyramid { sizes, levels, picture: [o.width, o.height] })
            }
            None => None,
        };
        let gpu = match times {
            Some(t) => {
                let data = t.slice(..).get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
                let w: &[u64] = bytemuck::cast_slice(&data);
                let period = self.dev.queue.get_timestamp_period() as f64 * 1e-6;
                let span = |i: usize| w[2 * i + 1].saturating_sub(w[2 * i]) as f64 * period;
                Some(PassTimes {
                    cull_ms: span(0),
                    depth_ms: if o.prepass || occlusion { span(1) } else { 0.0 },
                    shade_ms: span(2),
                    hiz_ms: if occlusion { span(3) } else { 0.0 },
                })
            }
            None => None,
        };
        let stats = FrameStats {
            clusters: n,
            clusters_after_frustum: after,
            clusters_after_occlusion: occlusion.then_some(after_occ),
            triangles: s.triangles,
            triangles_drawn: if !o.mesh {
                0
            } else if occlusion {
                u64::from(drawn_occ)
            } else {
                u64::from(drawn)
            },
            points_drawn: u64::from(s.point_count),
            multi_draw: "multi_draw_indexed_indirect",
            cpu_ms: t0.elapsed().as_secs_f64() * 1e3,
            gpu,
        };
        Ok(Frame { width: o.width, height: o.height, rgba, kept, hiz, stats })
    }

    /// Builds the Hi-Z pyramid from the depth pass and runs the occlusion
    /// test over the frustum survivors; returns the pyramid texture and
    /// its level sizes.
    fn occlusion_passes(
        &self,
        enc: &mut wgpu::CommandEncoder,
        s: &GpuScene,
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
            // level but the one written (level 1 for level 0: unused).
            let (src, dst) = (level(if l == 0 { 1.min(count - 1) } else { l - 1 }), level(l));
            let src = if l == 0 && count == 1 { None } else { Some(src) };
            let dummy;
            let src_view = match &src {
                Some(v) => v,
                None => {
                    dummy = self.dummy_float();
                    &dummy
                }
            };
            let group = self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.p.layouts.hiz,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_view) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(src_view) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&dst) },
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

    /// Builds the light grid on the GPU (count, scan, fill) and reads it
    /// back; returns it with the ranges and indices buffers the shading
    /// pass binds.
    fn light_grid(&self, scene: &Scene, lights: &wgpu::Buffer, count: u32) -> Result<(LightGrid, wgpu::Buffer, wgpu::Buffer), ViewError> {
        use wgpu::BufferUsages as U;
        let (lo, cell, unit) = grid_frame(scene);
        let cells = (GRID * GRID * GRID) as u64;
        let u = GridUniform { lo: lo.extend(0.0).to_array(), cell: cell.extend(0.0).to_array(), counts: [count, 0, 0, 0] };
        let uniform = self.dev.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("light grid"),
            contents: bytemuck::bytes_of(&u),
            usage: U::UNIFORM,
        });
        let buffer = |label, size: u64, usage| {
            self.dev.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let ranges = buffer("light ranges", 8 * cells, U::STORAGE | U::COPY_SRC);
        let total = buffer("light total", 4, U::STORAGE | U::COPY_SRC);
        let placeholder = buffer("no light indices yet", 4, U::STORAGE);
        let group = |indices: &wgpu::Buffer| {
            self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.p.layouts.grid,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: lights.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: ranges.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: indices.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: total.as_entire_binding() },
                ],
            })
        };
        let groups = (cells as u32).div_ceil(64);
        let mut enc = self.dev.device.create_command_encoder(&Default::default());
        {
            let g = group(&placeholder);
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &g, &[]);
            pass.set_pipeline(&self.p.grid_count);
            pass.dispatch_workgroups(groups, 1, 1);
            pass.set_pipeline(&self.p.grid_scan);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let total_read = self.read_buffers(enc, &[(&total, 4)])?;
        let n = u32::from_le_bytes(total_read[0][..4].try_into().expect("4 bytes")) as u64;
        let indices = buffer("light indices", 4 * n.max(1), U::STORAGE | U::COPY_SRC);
        let mut enc = self.dev.device.create_command_encoder(&Default::default());
        {
            let g = group(&indices);
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &g, &[]);
            pass.set_pipeline(&self.p.grid_fill);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        let read = self.read_buffers(enc, &[(&ranges, 8 * cells), (&indices, 4 * n.max(1))])?;
        let ranges_v: Vec<[u32; 2]> = bytemuck::cast_slice::<u8, u32>(&read[0]).chunks_exact(2).map(|p| [p[0], p[1]]).collect();
        let indices_v: Vec<u32> = bytemuck::cast_slice::<u8, u32>(&read[1])[..n as usize].to_vec();
        Ok((LightGrid { lo, cell, unit, ranges: ranges_v, indices: indices_v }, ranges, indices))
    }

    /// Submits `enc` after copying each buffer's first bytes to a readback
    /// buffer, waits, and returns the bytes.
    fn read_buffers(&self, enc: wgpu::CommandEncoder, bufs: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>, ViewError> {
        Ok(self.dev.read_buffers(enc, bufs)?)
    }

    /// A 1×1 float texture view, bound where a pass reads no source level.
    fn dummy_float(&self) -> wgpu::TextureView {
        self.dev
            .device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("unused"),
                size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: HIZ,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default())
    }

    /// Copies every pyramid level into a readback buffer.
    fn copy_levels(&self, enc: &mut wgpu::CommandEncoder, hiz: &(wgpu::Texture, Vec<[u32; 2]>)) -> (Vec<wgpu::Buffer>, Vec<[u32; 2]>) {
        let (tex, sizes) = hiz;
        let bufs = sizes
            .iter()
            .enumerate()
            .map(|(l, &[w, h])| {
                let row = aligned_row(w);
                let buf = self.dev.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("hi-z level readback"),
                    size: row as u64 * h as u64,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                enc.copy_texture_to_buffer(
                    wgpu::TexelCopyTextureInfo {
                        texture: tex,
                        mip_level: l as u32,
                        origin: wgpu::Origin3d::ZERO,
                        aspect: wgpu::TextureAspect::All,
                    },
                    wgpu::TexelCopyBufferInfo {
                        buffer: &buf,
                        layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(h) },
                    },
                    wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                );
                buf
            })
            .collect();
        (bufs, sizes.clone())
    }
}

/// Bindings may not be empty: one zeroed element stands for none.
fn nonempty<T: Pod + Zeroable>(v: &[T]) -> Vec<T> {
    if v.is_empty() {
        vec![T::zeroed()]
    } else {
        v.to_vec()
    }
}

/// The light grid pass's uniform block (`grid.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GridUniform {
    lo: [f32; 4],
    cell: [f32; 4],
    counts: [u32; 4],
}

/// Bytes per row of a 4-byte-texel copy, aligned as copies require.
fn aligned_row(width: u32) -> u32 {
    (4 * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}
