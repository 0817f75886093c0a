//! The render pipelines of the scene, all from `scene.wgsl` and sharing bind group 0.

use crate::render::mesh::{CardInstance, LitVertex};

/// Depth format of the scene and of the sun's shadow map.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// MSAA samples of the scene pass on a real GPU and in offscreen frames (leaves use alpha to
/// coverage).
pub const SAMPLE_COUNT: u32 = 4;

/// The scene pass's samples for an interactive view on `adapter`: [`SAMPLE_COUNT`] on a GPU; one
/// on a CPU rasteriser (lavapipe), where every sample is rasterised and resolved on the CPU, the
/// leaves' edges then cut by an alpha test instead of coverage.
pub fn interactive_sample_count(adapter: &wgpu::AdapterInfo) -> u32 {
    match adapter.device_type {
        wgpu::DeviceType::Cpu => 1,
        _ => SAMPLE_COUNT,
    }
}

/// Every pipeline the scene pass and the shadow pass use.
pub struct Pipelines {
    /// MSAA samples of the scene pass's targets.
    pub sample_count: u32,
    pub scene_layout: wgpu::BindGroupLayout,
    pub shadow_layout: wgpu::BindGroupLayout,
    /// Group 1 of every pipeline: the tree's leaf card and bark textures and their sampler.
    pub tree_layout: wgpu::BindGroupLayout,
    pub background: wgpu::RenderPipeline,
    pub occluder: wgpu::RenderPipeline,
    pub ground_shadow: wgpu::RenderPipeline,
    pub ground_lawn: wgpu::RenderPipeline,
    pub branches: wgpu::RenderPipeline,
    /// Leaf cards: instances of one quad, alpha to coverage (an alpha test at one sample), lit on
    /// both sides.
    pub cards: wgpu::RenderPipeline,
    pub fruit: wgpu::RenderPipeline,
    pub wire: wgpu::RenderPipeline,
    pub points: wgpu::RenderPipeline,
    pub brush: wgpu::RenderPipeline,
    pub shadow_branches: wgpu::RenderPipeline,
    pub shadow_cards: wgpu::RenderPipeline,
}

const LIT_ATTRIBUTES: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32, 3 => Float32x2];
const POSITION_ATTRIBUTES: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];
const CARD_ATTRIBUTES: [wgpu::VertexAttribute; 5] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3, 4 => Float32
];

/// One [`CardInstance`] per instance; the vertex index picks the quad's corner.
fn card_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<CardInstance>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &CARD_ATTRIBUTES,
    }
}

fn lit_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<LitVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &LIT_ATTRIBUTES,
    }
}

fn position_layout(step_mode: wgpu::VertexStepMode) -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: 12,
        step_mode,
        attributes: &POSITION_ATTRIBUTES,
    }
}

/// How one pipeline differs from the others.
struct Spec<'a> {
    label: &'a str,
    vs: &'a str,
    fs: Option<&'a str>,
    buffer: Option<wgpu::VertexBufferLayout<'static>>,
    topology: wgpu::PrimitiveTopology,
    cull: Option<wgpu::Face>,
    depth_write: bool,
    depth_compare: wgpu::CompareFunction,
    blend: Option<wgpu::BlendState>,
    write_mask: wgpu::ColorWrites,
    alpha_to_coverage: bool,
}

impl Spec<'_> {
    fn opaque<'a>(label: &'a str, vs: &'a str, fs: &'a str) -> Spec<'a> {
        Spec {
            label,
            vs,
            fs: Some(fs),
            buffer: None,
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull: None,
            depth_write: true,
            depth_compare: wgpu::CompareFunction::Less,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
            alpha_to_coverage: false,
        }
    }

    fn blended(mut self) -> Self {
        self.blend = Some(wgpu::BlendState::ALPHA_BLENDING);
        self.depth_write = false;
        self.depth_compare = wgpu::CompareFunction::LessEqual;
        self
    }
}

impl Pipelines {
    /// The pipelines for colour targets of `color_format` with `sample_count` samples (1 or 4).
    pub fn new(
        device: &wgpu::Device,
        color_format: wgpu::TextureFormat,
        sample_count: u32,
    ) -> Self {
        let shader = device.create_shader_module(wgpu::include_wgsl!("scene.wgsl"));
        let scene_layout = scene_bind_group_layout(device);
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sylva shadow globals"),
            entries: &[uniform_entry()],
        });
        let tree_layout = tree_bind_group_layout(device);
        let scene = pipeline_layout(device, &[&scene_layout, &tree_layout]);
        let shadow = pipeline_layout(device, &[&shadow_layout, &tree_layout]);
        let target = (color_format, sample_count);
        let make = |spec: Spec| make_scene_pipeline(device, &scene, &shader, target, spec);

        let background = make(Spec {
            depth_write: false,
            depth_compare: wgpu::CompareFunction::Always,
            ..Spec::opaque("background", "vs_fullscreen", "fs_background")
        });
        let occluder = make(Spec {
            buffer: Some(position_layout(wgpu::VertexStepMode::Vertex)),
            write_mask: wgpu::ColorWrites::empty(),
            ..Spec::opaque("occluder", "vs_position", "fs_depth_only")
        });
        let ground_shadow =
            make(Spec::opaque("ground shadow", "vs_ground_shadow", "fs_ground_shadow").blended());
        let ground_lawn =
            make(Spec::opaque("ground lawn", "vs_ground", "fs_ground_lawn").blended());
        let branches = make(Spec {
            buffer: Some(lit_layout()),
            cull: Some(wgpu::Face::Back),
            ..Spec::opaque("branches", "vs_lit", "fs_branch")
        });
        let fruit = make(Spec {
            buffer: Some(lit_layout()),
            cull: Some(wgpu::Face::Back),
            ..Spec::opaque("fruit", "vs_lit", "fs_fruit")
        });
        let multisampled = sample_count > 1;
        let cards = make(Spec {
            buffer: Some(card_layout()),
            alpha_to_coverage: multisampled,
            // The alpha goes to coverage only: the frame stays opaque where a leaf's edge is.
            write_mask: wgpu::ColorWrites::COLOR,
            ..Spec::opaque(
                "leaf cards",
                "vs_card",
                if multisampled {
                    "fs_card"
                } else {
                    "fs_card_tested"
                },
            )
        });
        let wire = make(Spec {
            buffer: Some(position_layout(wgpu::VertexStepMode::Vertex)),
            topology: wgpu::PrimitiveTopology::LineList,
            depth_write: false,
            depth_compare: wgpu::CompareFunction::Always,
            ..Spec::opaque("depth mesh wireframe", "vs_position", "fs_wire")
        });
        let points = make(Spec {
            buffer: Some(position_layout(wgpu::VertexStepMode::Instance)),
            depth_write: false,
            depth_compare: wgpu::CompareFunction::Always,
            ..Spec::opaque("feature points", "vs_points", "fs_points")
        });
        let brush = make(Spec::opaque("brush sphere", "vs_brush", "fs_brush").blended());
        let shadow_branches =
            make_shadow_pipeline(device, &shadow, &shader, lit_layout(), "vs_shadow", None);
        let shadow_cards = make_shadow_pipeline(
            device,
            &shadow,
            &shader,
            card_layout(),
            "vs_shadow_card",
            Some("fs_shadow_card"),
        );
        Pipelines {
            sample_count,
            scene_layout,
            shadow_layout,
            tree_layout,
            background,
            occluder,
            ground_shadow,
            ground_lawn,
            branches,
            cards,
            fruit,
            wire,
            points,
            brush,
            shadow_branches,
            shadow_cards,
        }
    }
}

fn uniform_entry() -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn scene_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty,
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("sylva scene globals"),
        entries: &[
            uniform_entry(),
            fragment(
                1,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            ),
            fragment(
                2,
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
            ),
            fragment(
                3,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            ),
            fragment(
                4,
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            ),
        ],
    })
}

/// The tree's textures: leaf card (binding 0) and bark (1), both filterable, and a repeating
/// trilinear sampler (2).
fn tree_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("sylva tree textures"),
        entries: &[
            texture(0),
            texture(1),
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    })
}

fn pipeline_layout(
    device: &wgpu::Device,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &layouts,
        immediate_size: 0,
    })
}

fn make_scene_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    (color_format, sample_count): (wgpu::TextureFormat, u32),
    spec: Spec,
) -> wgpu::RenderPipeline {
    let buffers = [spec.buffer];
    let targets = [Some(wgpu::ColorTargetState {
        format: color_format,
        blend: spec.blend,
        write_mask: spec.write_mask,
    })];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(spec.label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(spec.vs),
            compilation_options: Default::default(),
            buffers: if buffers[0].is_some() { &buffers } else { &[] },
        },
        primitive: wgpu::PrimitiveState {
            topology: spec.topology,
            cull_mode: spec.cull,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(spec.depth_write),
            depth_compare: Some(spec.depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: sample_count,
            mask: !0,
            alpha_to_coverage_enabled: spec.alpha_to_coverage,
        },
        fragment: spec.fs.map(|fs| wgpu::FragmentState {
            module: shader,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

fn make_shadow_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    buffer: wgpu::VertexBufferLayout<'static>,
    vs: &str,
    fs: Option<&str>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("sun shadow map"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(vs),
            compilation_options: Default::default(),
            buffers: &[Some(buffer)],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: wgpu::DepthBiasState {
                constant: 2,
                slope_scale: 2.0,
                clamp: 0.0,
            },
        }),
        multisample: Default::default(),
        fragment: fs.map(|fs| wgpu::FragmentState {
            module: shader,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}
