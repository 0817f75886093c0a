//! Headless rendering into a texture and reading it back as an image.

use anyhow::Context;
use image::RgbaImage;

use crate::render::{FrameView, Gpu, Renderer};

/// Colour format of offscreen frames (sRGB, so PNGs look as the window does).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// An offscreen colour target of a fixed size with its read-back buffer.
pub struct Offscreen {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row_bytes: u32,
}

impl Offscreen {
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Offscreen {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("offscreen frame"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OFFSCREEN_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        // Rows copied into buffers are padded to 256 bytes.
        let padded_row_bytes = (width * 4).div_ceil(256) * 256;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("offscreen readback"),
            size: u64::from(padded_row_bytes) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Offscreen {
            texture,
            view,
            readback,
            width,
            height,
            padded_row_bytes,
        }
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Renders one frame and returns it as an image.
    pub fn render(
        &self,
        gpu: &Gpu,
        renderer: &mut Renderer,
        view: &FrameView,
    ) -> anyhow::Result<RgbaImage> {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer.render(
            gpu,
            &mut encoder,
            &self.view,
            (self.width, self.height),
            view,
        );
        gpu.queue.submit([encoder.finish()]);
        self.read(gpu)
    }

    /// The texture frames are drawn into.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Reads the texture back as an image (the last frame drawn into it).
    pub fn read(&self, gpu: &Gpu) -> anyhow::Result<RgbaImage> {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row_bytes),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        gpu.queue.submit([encoder.finish()]);
        let slice = self.readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .context("waiting for the offscreen frame")?;
        let mut pixels = Vec::with_capacity((self.width * self.height * 4) as usize);
        {
            let mapped = slice
                .get_mapped_range()
                .context("reading the offscreen frame back")?;
            for row in mapped.chunks_exact(self.padded_row_bytes as usize) {
                pixels.extend_from_slice(&row[..(self.width * 4) as usize]);
            }
        }
        self.readback.unmap();
        RgbaImage::from_raw(self.width, self.height, pixels)
            .context("offscreen frame has the wrong number of pixels")
    }
}
