//! A lean painter for egui's output on a CPU rasteriser (the interactive window on lavapipe).
//!
//! egui-wgpu's fragment shader carries a second, software texture filter behind a uniform flag
//! (four texel loads and integer wrap arithmetic, for egui's snapshot tests). A GPU skips the
//! branch that is not taken; lavapipe's JIT runs every branch of a shader under a lane mask, so
//! each UI pixel paid for both filters and the wrap modes' integer divisions: about 100–150 ns a
//! pixel, some 20–25 ms of CPU a redraw for the 240 k UI pixels of the 1280×800 window, more than
//! the whole AR view. This painter draws the same meshes with the same colour arithmetic as
//! egui-wgpu's sRGB-target path (vertex colour times texel in gamma space, dithered to 8 bits,
//! then to linear for the sRGB target, premultiplied-alpha blending) in a shader without
//! branches. It keeps egui's textures itself (the font atlas and any image the UI loads).
//!
//! Offscreen frames (screenshots, UI goldens) and GPUs keep egui-wgpu's renderer
//! ([`UiPainterKind::EguiWgpu`]), so their pixels do not change.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};

/// Which painter draws the UI.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UiPainterKind {
    /// egui-wgpu's own renderer (offscreen frames, GPUs).
    #[default]
    EguiWgpu,
    /// [`UiPainter`]: the same pixels' arithmetic in a branch-free shader (CPU rasterisers).
    Lean,
}

/// The painter for an interactive view's UI on `adapter`: the lean one on a CPU rasteriser,
/// egui-wgpu's on a GPU.
pub fn interactive_ui_painter(adapter: &wgpu::AdapterInfo) -> UiPainterKind {
    painter_for(adapter.device_type)
}

fn painter_for(device_type: wgpu::DeviceType) -> UiPainterKind {
    match device_type {
        wgpu::DeviceType::Cpu => UiPainterKind::Lean,
        _ => UiPainterKind::EguiWgpu,
    }
}

/// One vertex as the shader reads it (egui's vertex: position in points, texture coordinate,
/// premultiplied sRGBA colour).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct UiVertex {
    pos: [f32; 2],
    uv: [f32; 2],
    color: [u8; 4],
}

const UI_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x2, 1 => Float32x2, 2 => Unorm8x4];

/// Mirrors `Locals` in ui_painter.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Locals {
    /// Target size in points (pixels divided by pixels per point).
    screen_size_pt: [f32; 2],
    _pad: [f32; 2],
}

struct UiTexture {
    texture: wgpu::Texture,
    options: egui::TextureOptions,
    group: wgpu::BindGroup,
}

/// A growable GPU buffer of one usage.
struct GrowBuffer {
    buffer: wgpu::Buffer,
    usage: wgpu::BufferUsages,
    label: &'static str,
}

impl GrowBuffer {
    fn new(device: &wgpu::Device, usage: wgpu::BufferUsages, label: &'static str) -> Self {
        GrowBuffer {
            buffer: Self::make(device, usage, label, 64 * 1024),
            usage,
            label,
        }
    }

    fn make(
        device: &wgpu::Device,
        usage: wgpu::BufferUsages,
        label: &'static str,
        size: u64,
    ) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Writes `bytes` at the start, growing the buffer (to the next power of two) when needed.
    fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) {
        let needed = (bytes.len() as u64).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
        if needed > self.buffer.size() {
            self.buffer = Self::make(device, self.usage, self.label, needed.next_power_of_two());
        }
        if bytes.is_empty() {
            return;
        }
        if bytes.len() as u64 == needed {
            queue.write_buffer(&self.buffer, 0, bytes);
        } else {
            let mut padded = bytes.to_vec();
            padded.resize(needed as usize, 0);
            queue.write_buffer(&self.buffer, 0, &padded);
        }
    }
}

/// One draw: a mesh's index range, its base vertex, texture and scissor rectangle (pixels).
struct Draw {
    indices: std::ops::Range<u32>,
    base_vertex: i32,
    texture: egui::TextureId,
    scissor: [u32; 4],
}

/// Draws egui's tessellated output into a target of one colour format.
pub struct UiPainter {
    pipeline: wgpu::RenderPipeline,
    texture_layout: wgpu::BindGroupLayout,
    locals: wgpu::Buffer,
    locals_group: wgpu::BindGroup,
    samplers: HashMap<egui::TextureOptions, wgpu::Sampler>,
    textures: HashMap<egui::TextureId, UiTexture>,
    vertices: GrowBuffer,
    indices: GrowBuffer,
    draws: Vec<Draw>,
}

impl UiPainter {
    /// A painter drawing into targets of `format` (an sRGB format gets linear output, as
    /// egui-wgpu does for it).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> UiPainter {
        let shader = device.create_shader_module(wgpu::include_wgsl!("ui_painter.wgsl"));
        let locals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ui locals"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ui texture"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("ui painter"),
            bind_group_layouts: &[Some(&locals_layout), Some(&texture_layout)],
            immediate_size: 0,
        });
        let entry_point = if format.is_srgb() {
            "fs_linear_target"
        } else {
            "fs_gamma_target"
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ui painter"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<UiVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &UI_ATTRIBUTES,
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    // Premultiplied alpha, as egui paints.
                    blend: Some(wgpu::BlendState {
                        color: wgpu::BlendComponent {
                            src_factor: wgpu::BlendFactor::One,
                            dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                            operation: wgpu::BlendOperation::Add,
                        },
                        alpha: wgpu::BlendComponent {
                            src_factor: wgpu::BlendFactor::OneMinusDstAlpha,
                            dst_factor: wgpu::BlendFactor::One,
                            operation: wgpu::BlendOperation::Add,
                        },
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let locals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ui locals"),
            size: std::mem::size_of::<Locals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let locals_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ui locals"),
            layout: &locals_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: locals.as_entire_binding(),
            }],
        });
        UiPainter {
            pipeline,
            texture_layout,
            locals,
            locals_group,
            samplers: HashMap::new(),
            textures: HashMap::new(),
            vertices: GrowBuffer::new(device, wgpu::BufferUsages::VERTEX, "ui vertices"),
            indices: GrowBuffer::new(device, wgpu::BufferUsages::INDEX, "ui indices"),
            draws: Vec::new(),
        }
    }

    /// Applies egui's texture changes that come before painting (new and updated images).
    pub fn set_textures(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        delta: &egui::TexturesDelta,
    ) {
        // Each image's changes in order: a whole image, then patches of it.
        for (id, images) in &delta.set {
            for image in images {
                self.set_texture(device, queue, *id, image);
            }
        }
    }

    /// Applies egui's texture changes that come after painting (freed images).
    pub fn free_textures(&mut self, delta: &egui::TexturesDelta) {
        for id in &delta.free {
            if let Some(texture) = self.textures.remove(id) {
                texture.texture.destroy();
            }
        }
    }

    fn set_texture(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        id: egui::TextureId,
        delta: &egui::epaint::ImageDelta,
    ) {
        let egui::ImageData::Color(image) = &delta.image;
        let [width, height] = image.size.map(|s| s as u32);
        if width == 0 || height == 0 || image.pixels.len() != (width * height) as usize {
            return; // nothing to show (egui never sends such a delta)
        }
        let origin = match delta.pos {
            Some([x, y]) => {
                // A patch of an existing image; one that does not fit it is dropped.
                let fits = self.textures.get(&id).is_some_and(|t| {
                    x as u32 + width <= t.texture.width() && y as u32 + height <= t.texture.height()
                });
                if !fits {
                    return;
                }
                wgpu::Origin3d {
                    x: x as u32,
                    y: y as u32,
                    z: 0,
                }
            }
            None => {
                let texture = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("ui image"),
                    size: wgpu::Extent3d {
                        width,
                        height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    // egui's colours are gamma-encoded; the shader works on them as stored.
                    format: wgpu::TextureFormat::Rgba8Unorm,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                });
                let group = self.bind_group(device, &texture, delta.options);
                if let Some(old) = self.textures.insert(
                    id,
                    UiTexture {
                        texture,
                        options: delta.options,
                        group,
                    },
                ) {
                    old.texture.destroy();
                }
                wgpu::Origin3d::ZERO
            }
        };
        let Some(mut entry) = self.textures.remove(&id) else {
            return;
        };
        if entry.options != delta.options {
            entry.group = self.bind_group(device, &entry.texture, delta.options);
            entry.options = delta.options;
        }
        self.textures.insert(id, entry);
        let Some(entry) = self.textures.get(&id) else {
            return;
        };
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &entry.texture,
                mip_level: 0,
                origin,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(image.pixels.as_slice()),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * width),
                rows_per_image: Some(height),
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
    }

    fn bind_group(
        &mut self,
        device: &wgpu::Device,
        texture: &wgpu::Texture,
        options: egui::TextureOptions,
    ) -> wgpu::BindGroup {
        let sampler = self
            .samplers
            .entry(options)
            .or_insert_with(|| sampler_for(device, options));
        let view = texture.create_view(&Default::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ui image"),
            layout: &self.texture_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
            ],
        })
    }

    /// Uploads the meshes of `jobs` for a target of `size_px` at `pixels_per_point`, ready for
    /// [`Self::paint`]. Paint callbacks (the app has none) are skipped.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        jobs: &[egui::ClippedPrimitive],
        size_px: (u32, u32),
        pixels_per_point: f32,
    ) {
        let ppp = if pixels_per_point > 0.0 {
            pixels_per_point
        } else {
            1.0
        };
        let locals = Locals {
            screen_size_pt: [size_px.0 as f32 / ppp, size_px.1 as f32 / ppp],
            _pad: [0.0; 2],
        };
        queue.write_buffer(&self.locals, 0, bytemuck::bytes_of(&locals));
        self.draws.clear();
        let mut vertices: Vec<UiVertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        for job in jobs {
            let egui::epaint::Primitive::Mesh(mesh) = &job.primitive else {
                continue;
            };
            let scissor = scissor_px(job.clip_rect, ppp, size_px);
            if mesh.indices.is_empty() || scissor[2] == 0 || scissor[3] == 0 {
                continue;
            }
            let (Ok(base_vertex), Ok(first)) =
                (i32::try_from(vertices.len()), u32::try_from(indices.len()))
            else {
                break; // beyond any UI's size
            };
            vertices.extend(mesh.vertices.iter().map(|v| UiVertex {
                pos: [v.pos.x, v.pos.y],
                uv: [v.uv.x, v.uv.y],
                color: v.color.to_array(),
            }));
            indices.extend_from_slice(&mesh.indices);
            self.draws.push(Draw {
                indices: first..first + mesh.indices.len() as u32,
                base_vertex,
                texture: mesh.texture_id,
                scissor,
            });
        }
        self.vertices
            .write(device, queue, bytemuck::cast_slice(&vertices));
        self.indices
            .write(device, queue, bytemuck::cast_slice(&indices));
    }

    /// Records the meshes [`Self::prepare`] uploaded into `pass`.
    pub fn paint(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.draws.is_empty() {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.locals_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.buffer.slice(..));
        pass.set_index_buffer(self.indices.buffer.slice(..), wgpu::IndexFormat::Uint32);
        for draw in &self.draws {
            let Some(texture) = self.textures.get(&draw.texture) else {
                continue; // an image egui has not sent (or a user texture): not drawn
            };
            let [x, y, w, h] = draw.scissor;
            pass.set_scissor_rect(x, y, w, h);
            pass.set_bind_group(1, &texture.group, &[]);
            pass.draw_indexed(draw.indices.clone(), draw.base_vertex, 0..1);
        }
    }
}

/// A clip rectangle in points as a scissor rectangle of whole pixels inside the target (x, y,
/// w, h), rounded as egui-wgpu rounds it.
pub fn scissor_px(clip: egui::Rect, pixels_per_point: f32, size_px: (u32, u32)) -> [u32; 4] {
    let px = |v: f32| (v * pixels_per_point).round().max(0.0) as u32;
    let x0 = px(clip.min.x).min(size_px.0);
    let y0 = px(clip.min.y).min(size_px.1);
    let x1 = px(clip.max.x).clamp(x0, size_px.0);
    let y1 = px(clip.max.y).clamp(y0, size_px.1);
    [x0, y0, x1 - x0, y1 - y0]
}

fn sampler_for(device: &wgpu::Device, options: egui::TextureOptions) -> wgpu::Sampler {
    let filter = |f: egui::TextureFilter| match f {
        egui::TextureFilter::Nearest => wgpu::FilterMode::Nearest,
        egui::TextureFilter::Linear => wgpu::FilterMode::Linear,
    };
    let address = match options.wrap_mode {
        egui::TextureWrapMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        egui::TextureWrapMode::Repeat => wgpu::AddressMode::Repeat,
        egui::TextureWrapMode::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
    };
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("ui image"),
        mag_filter: filter(options.magnification),
        min_filter: filter(options.minification),
        address_mode_u: address,
        address_mode_v: address,
        ..Default::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scissors_are_whole_pixels_inside_the_target() {
        let rect =
            |x0, y0, x1, y1| egui::Rect::from_min_max(egui::pos2(x0, y0), egui::pos2(x1, y1));
        assert_eq!(
            scissor_px(rect(0.0, 0.0, 1280.0, 25.0), 1.0, (1280, 800)),
            [0, 0, 1280, 25]
        );
        // Scaled by the pixels per point and rounded.
        assert_eq!(
            scissor_px(rect(10.2, 5.0, 20.6, 15.0), 2.0, (1280, 800)),
            [20, 10, 21, 20]
        );
        // Clipped to the target; a rectangle outside it is empty.
        assert_eq!(
            scissor_px(rect(-50.0, 700.0, 2000.0, 900.0), 1.0, (1280, 800)),
            [0, 700, 1280, 100]
        );
        let outside = scissor_px(rect(1300.0, 0.0, 1400.0, 10.0), 1.0, (1280, 800));
        assert_eq!(outside[2], 0);
        // Inverted rectangles are empty, not wrapped.
        assert_eq!(
            scissor_px(rect(50.0, 50.0, 10.0, 10.0), 1.0, (1280, 800))[2..],
            [0, 0]
        );
    }

    #[test]
    fn the_lean_painter_is_chosen_only_for_cpu_rasterisers() {
        assert_eq!(painter_for(wgpu::DeviceType::Cpu), UiPainterKind::Lean);
        for gpu in [
            wgpu::DeviceType::DiscreteGpu,
            wgpu::DeviceType::IntegratedGpu,
            wgpu::DeviceType::VirtualGpu,
            wgpu::DeviceType::Other,
        ] {
            assert_eq!(painter_for(gpu), UiPainterKind::EguiWgpu);
        }
    }
}
