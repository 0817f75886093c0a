//! The scene at a reduced resolution for an interactive view on a slow (CPU) adapter: the scene
//! pass draws into a texture the size of the camera image instead of the window's drawn region,
//! and one pass stretches it over that region (bilinear) and clears the letterbox bars.
//!
//! The footage itself has no more detail than its own pixels, so drawing the AR view at the
//! footage's resolution loses none of the camera image; the tree is drawn as sharp as the video
//! it stands in. On lavapipe at 1280×800 with 640×480 footage this rasterises 2.8× fewer scene
//! pixels (307 k instead of 853 k). Offscreen frames (goldens, screenshots, session hashes)
//! always draw at full resolution ([`SceneResolution::Full`]).

use crate::render::camera::Intrinsics;
use crate::render::resources::letterbox;

/// The resolution the scene pass draws at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SceneResolution {
    /// The target's own pixels (offscreen frames, GPUs).
    #[default]
    Full,
    /// The camera image's pixels when the drawn region is larger, stretched over the region.
    Footage,
}

impl SceneResolution {
    /// The size to draw the scene at for a target of `size` showing an image taken with `k`,
    /// when it is smaller than the drawn region (None: draw into the target directly).
    pub fn reduced_size(self, size: (u32, u32), k: &Intrinsics) -> Option<(u32, u32)> {
        match self {
            SceneResolution::Full => None,
            SceneResolution::Footage => {
                let region = letterbox(size, k);
                let image = (k.width.max(1), k.height.max(1));
                let image_px = f64::from(image.0) * f64::from(image.1);
                let region_px = f64::from(region[2]) * f64::from(region[3]);
                (image_px < region_px).then_some(image)
            }
        }
    }
}

/// The resolution of an interactive view's scene on `adapter`: the footage's on a CPU
/// rasteriser (lavapipe, where every scene pixel costs CPU time the tracker also needs), full on
/// a GPU.
pub fn interactive_scene_resolution(adapter: &wgpu::AdapterInfo) -> SceneResolution {
    match adapter.device_type {
        wgpu::DeviceType::Cpu => SceneResolution::Footage,
        _ => SceneResolution::Full,
    }
}

/// The reduced-resolution scene target and the pass that stretches it over the window.
pub struct Upscaler {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    target: Option<UpscaleTarget>,
}

struct UpscaleTarget {
    size: (u32, u32),
    view: wgpu::TextureView,
    group: wgpu::BindGroup,
}

impl Upscaler {
    /// An upscaler drawing into targets of `color_format` (its scene texture has that format).
    pub fn new(device: &wgpu::Device, color_format: wgpu::TextureFormat) -> Upscaler {
        let shader = device.create_shader_module(wgpu::include_wgsl!("upscale.wgsl"));
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty,
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sylva upscale"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    1,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sylva upscale"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene upscale"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_upscale"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_upscale"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: color_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("scene upscale"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Upscaler {
            pipeline,
            layout,
            sampler,
            target: None,
        }
    }

    /// The scene texture of `size` (made again when the size changes), of `color_format`.
    pub fn scene_target(
        &mut self,
        device: &wgpu::Device,
        size: (u32, u32),
        color_format: wgpu::TextureFormat,
    ) -> wgpu::TextureView {
        if let Some(target) = self.target.as_ref().filter(|t| t.size == size) {
            return target.view.clone();
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("reduced scene"),
            size: wgpu::Extent3d {
                width: size.0.max(1),
                height: size.1.max(1),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: color_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sylva upscale"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        self.target = Some(UpscaleTarget {
            size,
            view: view.clone(),
            group,
        });
        view
    }

    /// Whether the scene texture of `size` exists (and holds what was last drawn into it).
    pub fn holds(&self, size: (u32, u32)) -> bool {
        self.target.as_ref().is_some_and(|t| t.size == size)
    }

    /// Records the pass that clears `target` and stretches the scene texture over `region`
    /// (x, y, w, h pixels of the target).
    pub fn stretch(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        region: [f32; 4],
    ) {
        let Some(scene) = &self.target else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene upscale"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(region[0], region[1], region[2], region[3], 0.0, 1.0);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.group, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_is_reduced_only_where_the_footage_is_smaller_than_the_drawn_region() {
        let k = Intrinsics::from_fov(640, 480, 1.0);
        assert_eq!(SceneResolution::Full.reduced_size((1280, 800), &k), None);
        // 1280×800 shows the 4:3 image in a 1067×800 region: drawn at 640×480.
        assert_eq!(
            SceneResolution::Footage.reduced_size((1280, 800), &k),
            Some((640, 480))
        );
        // A window as small as the footage, or smaller, draws directly.
        assert_eq!(SceneResolution::Footage.reduced_size((640, 480), &k), None);
        assert_eq!(SceneResolution::Footage.reduced_size((320, 240), &k), None);
    }
}
