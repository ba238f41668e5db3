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

use crate::camera::Camera;
use crate::hiz::Pyramid;
use crate::lights::{grid_frame, lights, LightGrid, LightReport, GRID};
use crate::partition::{Cluster, Partition};
use crate::scene::Scene;
use crate::spray::SprayPoint;
use crate::ViewError;
use topovox_gpu::device::{Device, DeviceOptions};

mod passes;
mod pipelines;
mod readback;

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
        let r = Renderer { p: pipelines::Pipelines::new(&dev), font: font_atlas(&dev.device, &dev.queue), dev };
        r.check()?;
        Ok(r)
    }

    /// Shows a window's surface texture.
    pub fn present_texture(&self, texture: wgpu::SurfaceTexture) {
        self.dev.queue.present(texture);
    }

    /// The largest picture side the adapter takes.
    pub fn max_side(&self) -> u32 {
        self.dev.max_texture_side()
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
        let shade_group = self.shade_group(scene, [(0, &uniform), (4, &materials), (5, &light_buf), (6, &ranges), (7, &light_indices)])?;
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

    /// The shading pass's group: its buffers, the scene's texture array
    /// and its sampler.
    fn shade_group(&self, scene: &Scene, buffers: [(u32, &wgpu::Buffer); 5]) -> Result<wgpu::BindGroup, ViewError> {
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
        let mut entries: Vec<wgpu::BindGroupEntry> =
            buffers.iter().map(|(binding, b)| wgpu::BindGroupEntry { binding: *binding, resource: b.as_entire_binding() }).collect();
        entries.push(wgpu::BindGroupEntry { binding: 8, resource: wgpu::BindingResource::TextureView(&texture_view) });
        entries.push(wgpu::BindGroupEntry { binding: 9, resource: wgpu::BindingResource::Sampler(&sampler) });
        Ok(self.dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shade"),
            layout: &self.p.layouts.shade,
            entries: &entries,
        }))
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
        let mut side = textures.iter().map(|t| t.width.max(t.height)).max().unwrap_or(1).clamp(1, MAX_TEXTURE_SIDE.min(self.max_side()));
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
        let max = self.max_side();
        if o.width == 0 || o.height == 0 || o.width > max || o.height > max {
            return Err(ViewError::Size { width: o.width, height: o.height, max });
        }
        if o.boxes && self.p.boxes.is_none() {
            return Err(ViewError::device(
                "the cluster-box wireframe needs vertex shaders that read storage buffers, which this adapter lacks".into(),
            ));
        }
        let t0 = Instant::now();
        self.write_uniforms(s, o);
        let queries = self.dev.timestamps().then(|| {
            self.dev.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass times"),
                ty: wgpu::QueryType::Timestamp,
                count: 8,
            })
        });
        let q = queries.as_ref();
        let mut enc = self.dev.device.create_command_encoder(&Default::default());
        self.cull_pass(&mut enc, s, q);
        let t = passes::Targets::new(&self.dev.device, o);
        if o.prepass || passes::occlusion(o) {
            self.depth_pass(&mut enc, s, o, &t, q);
        }
        let hiz = passes::occlusion(o).then(|| self.occlusion_passes(&mut enc, s, &t.depth, o, q));
        self.shade_pass(&mut enc, s, o, &t, q);
        self.overlay_pass(&mut enc, s, o, &t);
        enc.copy_buffer_to_buffer(&s.commands, 0, &s.prev_commands, 0, 20 * (s.clusters.len() as u64).max(1));
        if let Some((blit, target)) = present {
            self.blit_pass(&mut enc, &t, blit, target);
        }
        let reads = self.readbacks(&mut enc, (s, o, &t), present.is_none(), hiz.as_ref(), q);
        self.dev.queue.submit([enc.finish()]);
        self.read_frame(s, o, reads, t0)
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
