//! The frame's pipelines and bind group layouts, built once per device:
//! the compute passes (cluster culling, Hi-Z, the light grid), the draws
//! (depth, shade, spray points) and the overlays (cluster boxes, text).

use topovox_gpu::Device;

use super::{Glyph, COLOUR, DEPTH, FRAME, HIZ};
use crate::scene::Vertex;
use crate::spray::SprayPoint;

/// Every pipeline and layout a frame uses.
pub(super) struct Pipelines {
    pub cull: wgpu::ComputePipeline,
    pub occlude: wgpu::ComputePipeline,
    pub hiz_copy: wgpu::ComputePipeline,
    pub hiz_reduce: wgpu::ComputePipeline,
    pub grid_count: wgpu::ComputePipeline,
    pub grid_scan: wgpu::ComputePipeline,
    pub grid_fill: wgpu::ComputePipeline,
    pub layouts: Layouts,
    pub prepass: wgpu::RenderPipeline,
    pub shade: wgpu::RenderPipeline,
    pub shade_equal: wgpu::RenderPipeline,
    pub shade_lequal: wgpu::RenderPipeline,
    pub points: wgpu::RenderPipeline,
    /// The cluster-box wireframe, where vertex shaders may read storage
    /// buffers (a downlevel capability every desktop driver has).
    pub boxes: Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    pub text: wgpu::RenderPipeline,
}

/// The bind group layouts the frame's groups are made with.
pub(super) struct Layouts {
    pub cull: wgpu::BindGroupLayout,
    pub shade: wgpu::BindGroupLayout,
    pub hiz: wgpu::BindGroupLayout,
    pub hiz_read: wgpu::BindGroupLayout,
    pub grid: wgpu::BindGroupLayout,
    pub text: wgpu::BindGroupLayout,
}

use wgpu::BufferBindingType::{Storage, Uniform};
use wgpu::ShaderStages as S;

/// A buffer binding.
fn buffer(binding: u32, visibility: S, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

/// A 2D texture binding of the compute passes.
fn texture(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: S::COMPUTE,
        ty: wgpu::BindingType::Texture { sample_type, view_dimension: wgpu::TextureViewDimension::D2, multisampled: false },
        count: None,
    }
}

const FLOAT: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };

fn layout(device: &wgpu::Device, label: &str, entries: &[wgpu::BindGroupLayoutEntry]) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
}

impl Layouts {
    fn new(device: &wgpu::Device) -> Layouts {
        let ro = Storage { read_only: true };
        let rw = Storage { read_only: false };
        let array = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let sampler = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering);
        let fragment = |binding, ty| wgpu::BindGroupLayoutEntry { binding, visibility: S::FRAGMENT, ty, count: None };
        let hiz_out = wgpu::BindGroupLayoutEntry {
            binding: 2,
            visibility: S::COMPUTE,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: HIZ,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        };
        let glyphs = wgpu::BindingType::Texture { sample_type: FLOAT, view_dimension: wgpu::TextureViewDimension::D2, multisampled: false };
        let c = S::COMPUTE;
        Layouts {
            cull: layout(device, "cull", &[buffer(0, c, Uniform), buffer(1, c, ro), buffer(2, c, rw), buffer(3, c, rw)]),
            shade: layout(
                device,
                "shade",
                &[
                    buffer(0, S::VERTEX | S::FRAGMENT, Uniform),
                    buffer(4, S::FRAGMENT, ro),
                    buffer(5, S::FRAGMENT, ro),
                    buffer(6, S::FRAGMENT, ro),
                    buffer(7, S::FRAGMENT, ro),
                    fragment(8, array),
                    fragment(9, sampler),
                ],
            ),
            hiz: layout(device, "hiz build", &[texture(0, wgpu::TextureSampleType::Depth), texture(1, FLOAT), hiz_out]),
            hiz_read: layout(device, "hiz read", &[texture(0, FLOAT)]),
            grid: layout(
                device,
                "light grid",
                &[buffer(0, c, Uniform), buffer(1, c, ro), buffer(2, c, rw), buffer(3, c, rw), buffer(4, c, rw)],
            ),
            text: layout(device, "overlay text", &[buffer(0, S::VERTEX | S::FRAGMENT, Uniform), fragment(1, glyphs)]),
        }
    }
}

/// What the frame's render pipelines differ in.
struct PipelineParts<'a> {
    label: &'a str,
    layout: &'a wgpu::PipelineLayout,
    module: &'a wgpu::ShaderModule,
    /// Vertex and fragment entry points.
    entry: (&'a str, &'a str),
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    topology: wgpu::PrimitiveTopology,
    /// Depth write and test against [`DEPTH`], or no depth attachment.
    depth: Option<(bool, wgpu::CompareFunction)>,
    targets: &'a [Option<wgpu::ColorTargetState>],
}

/// A render pipeline of the frame: no face culling, no blending.
fn render_pipeline(device: &wgpu::Device, p: PipelineParts<'_>) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(p.label),
        layout: Some(p.layout),
        vertex: wgpu::VertexState {
            module: p.module,
            entry_point: Some(p.entry.0),
            compilation_options: Default::default(),
            buffers: p.buffers,
        },
        primitive: wgpu::PrimitiveState { topology: p.topology, cull_mode: None, ..Default::default() },
        depth_stencil: p.depth.map(|(write, compare)| wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(write),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: p.module,
            entry_point: Some(p.entry.1),
            compilation_options: Default::default(),
            targets: p.targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

fn pipeline_layout(device: &wgpu::Device, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::PipelineLayout {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: None, bind_group_layouts: &layouts, immediate_size: 0 })
}

fn compute(
    device: &wgpu::Device,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout(device, layouts)),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

const COLOUR_TARGET: [Option<wgpu::ColorTargetState>; 1] =
    [Some(wgpu::ColorTargetState { format: COLOUR, blend: None, write_mask: wgpu::ColorWrites::ALL })];

/// The depth, shade and point draws, in this order: prepass, shade, shade
/// after a prepass, shade over a partial prepass, points.
fn draws(dev: &Device, l: &Layouts) -> [wgpu::RenderPipeline; 5] {
    let device = &dev.device;
    let module = dev.shader("shade", &[FRAME, include_str!("../shaders/shade.wgsl"), include_str!("../shaders/points.wgsl")]);
    let layout = pipeline_layout(device, &[&l.shade]);
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32, 2 => Float32x3, 3 => Float32x2];
    let vertices = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attributes,
    })];
    // The depth-only passes run the alpha test too (fs_depth), so
    // cut-out texels neither hide nor occlude anything.
    let draw = |label, colour: bool, write: bool, compare| {
        let (entry, targets): (_, &[_]) = if colour { (("vs", "fs"), &COLOUR_TARGET) } else { (("vs", "fs_depth"), &[]) };
        let topology = wgpu::PrimitiveTopology::TriangleList;
        render_pipeline(
            device,
            PipelineParts {
                label,
                layout: &layout,
                module: &module,
                entry,
                buffers: &vertices,
                topology,
                depth: Some((write, compare)),
                targets,
            },
        )
    };
    let point_attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3, 4 => Float32x3];
    let points = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<SprayPoint>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &point_attributes,
    })];
    let spray = PipelineParts {
        label: "spray points",
        layout: &layout,
        module: &module,
        entry: ("vs_point", "fs_point"),
        buffers: &points,
        topology: wgpu::PrimitiveTopology::PointList,
        depth: Some((true, wgpu::CompareFunction::LessEqual)),
        targets: &COLOUR_TARGET,
    };
    use wgpu::CompareFunction::{Equal, Less, LessEqual};
    [
        draw("prepass", false, true, Less),
        draw("shade", true, true, Less),
        draw("shade after prepass", true, false, Equal),
        draw("shade over a partial prepass", true, true, LessEqual),
        render_pipeline(device, spray),
    ]
}

/// The cluster-box wireframe (where the adapter lets vertex shaders read
/// storage buffers) and the overlay text.
fn overlays(dev: &Device, l: &Layouts) -> (Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>, wgpu::RenderPipeline) {
    let device = &dev.device;
    let boxes = dev.adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::VERTEX_STORAGE).then(|| {
        let ro = Storage { read_only: true };
        let group = layout(device, "cluster boxes", &[buffer(0, S::VERTEX, Uniform), buffer(1, S::VERTEX, ro), buffer(2, S::VERTEX, ro)]);
        let module = dev.shader("cluster boxes", &[FRAME, include_str!("../shaders/boxes.wgsl")]);
        let parts = PipelineParts {
            label: "cluster boxes",
            layout: &pipeline_layout(device, &[&group]),
            module: &module,
            entry: ("vs_box", "fs_box"),
            buffers: &[],
            topology: wgpu::PrimitiveTopology::LineList,
            depth: None,
            targets: &COLOUR_TARGET,
        };
        (render_pipeline(device, parts), group)
    });
    let module = dev.shader("overlay text", &[FRAME, include_str!("../shaders/text.wgsl")]);
    let glyph_attributes = wgpu::vertex_attr_array![0 => Float32x2, 1 => Uint32];
    let glyphs = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Glyph>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &glyph_attributes,
    })];
    let parts = PipelineParts {
        label: "overlay text",
        layout: &pipeline_layout(device, &[&l.text]),
        module: &module,
        entry: ("vs_text", "fs_text"),
        buffers: &glyphs,
        topology: wgpu::PrimitiveTopology::TriangleStrip,
        depth: None,
        targets: &COLOUR_TARGET,
    };
    (boxes, render_pipeline(device, parts))
}

impl Pipelines {
    /// Builds every pipeline of the frame on `dev`.
    pub(super) fn new(dev: &Device) -> Pipelines {
        let device = &dev.device;
        let l = Layouts::new(device);
        let cull_module = dev.shader("cull", &[FRAME, include_str!("../shaders/cull.wgsl")]);
        let hiz_module = dev.shader("hiz", &[include_str!("../shaders/hiz.wgsl")]);
        let grid_module = dev.shader("light grid", &[include_str!("../shaders/grid.wgsl")]);
        let [prepass, shade, shade_equal, shade_lequal, points] = draws(dev, &l);
        let (boxes, text) = overlays(dev, &l);
        Pipelines {
            cull: compute(device, "cull", &[&l.cull], &cull_module, "cull"),
            occlude: compute(device, "occlude", &[&l.cull, &l.hiz_read], &cull_module, "occlude"),
            hiz_copy: compute(device, "hiz copy", &[&l.hiz], &hiz_module, "copy_depth"),
            hiz_reduce: compute(device, "hiz reduce", &[&l.hiz], &hiz_module, "reduce"),
            grid_count: compute(device, "light grid count", &[&l.grid], &grid_module, "count"),
            grid_scan: compute(device, "light grid scan", &[&l.grid], &grid_module, "scan"),
            grid_fill: compute(device, "light grid fill", &[&l.grid], &grid_module, "fill"),
            layouts: l,
            prepass,
            shade,
            shade_equal,
            shade_lequal,
            points,
            boxes,
            text,
        }
    }
}
