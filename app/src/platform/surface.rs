//! Surfaces to draw on: a window's swap chain (desktop, Android's native window, iOS's Metal
//! layer, all through wgpu) or an offscreen texture read back as an image (host tests).

use anyhow::Context;
use image::RgbaImage;

use crate::render::offscreen::OFFSCREEN_FORMAT;
use crate::render::{Gpu, Offscreen};

/// Something frames are drawn into.
pub trait DrawSurface {
    /// Size in physical pixels.
    fn size_px(&self) -> (u32, u32);
    /// Physical pixels per UI point (the platform's scale factor: 3 on many phones).
    fn scale_factor(&self) -> f32;
    fn format(&self) -> wgpu::TextureFormat;
    /// The texture to draw the next frame into; None when the surface cannot draw now
    /// (occluded, or being recreated after a resize).
    fn begin_frame(&mut self, gpu: &Gpu) -> anyhow::Result<Option<wgpu::TextureView>>;
    /// Shows (or keeps) the frame drawn since [`Self::begin_frame`], after it was submitted.
    fn end_frame(&mut self, gpu: &Gpu) -> anyhow::Result<()>;
}

/// A window's surface and its configuration.
pub struct WindowSurface {
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    scale_factor: f32,
    frame: Option<wgpu::SurfaceTexture>,
}

impl WindowSurface {
    /// Configures `surface` for `gpu` at `size_px` (an sRGB format when offered, vsync).
    pub fn new(
        gpu: &Gpu,
        surface: wgpu::Surface<'static>,
        size_px: (u32, u32),
        scale_factor: f32,
    ) -> anyhow::Result<WindowSurface> {
        let mut config = surface
            .get_default_config(&gpu.adapter, size_px.0.max(1), size_px.1.max(1))
            .context("the window surface is not supported by the adapter")?;
        let caps = surface.get_capabilities(&gpu.adapter);
        if let Some(srgb) = caps.formats.iter().copied().find(|f| f.is_srgb()) {
            config.format = srgb;
        }
        // Mailbox shows the newest frame without tearing and without the UI thread waiting for a
        // vertical blank; FIFO where the surface offers nothing else.
        config.present_mode = if caps.present_modes.contains(&wgpu::PresentMode::Mailbox) {
            wgpu::PresentMode::Mailbox
        } else {
            wgpu::PresentMode::AutoVsync
        };
        surface.configure(&gpu.device, &config);
        Ok(WindowSurface {
            surface,
            config,
            scale_factor,
            frame: None,
        })
    }

    /// The window was resized (or the phone rotated) or its scale factor changed.
    pub fn resize(&mut self, gpu: &Gpu, size_px: (u32, u32), scale_factor: f32) {
        self.config.width = size_px.0.max(1);
        self.config.height = size_px.1.max(1);
        self.scale_factor = scale_factor;
        self.surface.configure(&gpu.device, &self.config);
    }
}

impl DrawSurface for WindowSurface {
    fn size_px(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    fn scale_factor(&self) -> f32 {
        self.scale_factor
    }

    fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    fn begin_frame(&mut self, gpu: &Gpu) -> anyhow::Result<Option<wgpu::TextureView>> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&gpu.device, &self.config);
                return Ok(None);
            }
            _ => return Ok(None),
        };
        let view = frame.texture.create_view(&Default::default());
        self.frame = Some(frame);
        Ok(Some(view))
    }

    fn end_frame(&mut self, gpu: &Gpu) -> anyhow::Result<()> {
        if let Some(frame) = self.frame.take() {
            gpu.queue.present(frame);
        }
        Ok(())
    }
}

/// An offscreen colour texture of a fixed size; each frame drawn can be read back.
pub struct OffscreenSurface {
    target: Offscreen,
    scale_factor: f32,
}

impl OffscreenSurface {
    pub fn new(gpu: &Gpu, size_px: (u32, u32), scale_factor: f32) -> OffscreenSurface {
        OffscreenSurface {
            target: Offscreen::new(&gpu.device, size_px.0.max(1), size_px.1.max(1)),
            scale_factor,
        }
    }

    /// The last frame drawn, as an image.
    pub fn read(&self, gpu: &Gpu) -> anyhow::Result<RgbaImage> {
        self.target.read(gpu)
    }
}

impl DrawSurface for OffscreenSurface {
    fn size_px(&self) -> (u32, u32) {
        self.target.size()
    }

    fn scale_factor(&self) -> f32 {
        self.scale_factor
    }

    fn format(&self) -> wgpu::TextureFormat {
        OFFSCREEN_FORMAT
    }

    fn begin_frame(&mut self, _gpu: &Gpu) -> anyhow::Result<Option<wgpu::TextureView>> {
        Ok(Some(self.target.view().clone()))
    }

    fn end_frame(&mut self, _gpu: &Gpu) -> anyhow::Result<()> {
        Ok(())
    }
}
