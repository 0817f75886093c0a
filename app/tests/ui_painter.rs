//! The lean UI painter (`render::ui_painter`, the UI of a window on a CPU rasteriser) draws
//! egui's output as egui-wgpu's renderer does: the same UI, painted by both over the same
//! background into an sRGB target, differs by at most a couple of levels in any pixel.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test ui_painter`

use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::ui_painter::UiPainter;
use sylva_app::render::{Gpu, Offscreen};

const SIZE: (u32, u32) = (480, 320);

/// A UI with text, filled and rounded shapes, a translucent plate and an image.
fn run_ui(ctx: &egui::Context) -> egui::FullOutput {
    let raw = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(SIZE.0 as f32, SIZE.1 as f32),
        )),
        ..Default::default()
    };
    ctx.run_ui(raw, |ui| {
        egui::Panel::right("side").show(ui, |ui| {
            ui.label("Tools");
            let _ = ui.button("Brush");
            let mut value = 0.4;
            ui.add(egui::Slider::new(&mut value, 0.0..=1.0).vertical());
        });
        egui::Panel::bottom("bottom").show(ui, |ui| {
            ui.horizontal(|ui| {
                let _ = ui.button("Pause");
                ui.label("Frame 120");
            });
        });
        let view = ui.available_rect_before_wrap();
        let painter = ui.painter_at(view);
        painter.rect_filled(
            egui::Rect::from_center_size(view.center(), egui::vec2(200.0, 50.0)),
            8.0,
            egui::Color32::from_black_alpha(160),
        );
        painter.text(
            view.center(),
            egui::Align2::CENTER_CENTER,
            "Tap the ground",
            egui::FontId::proportional(18.0),
            egui::Color32::WHITE,
        );
        let image =
            egui::ColorImage::from_rgba_unmultiplied([4, 4], &[200u8, 40, 40, 255].repeat(16));
        let texture = ui
            .ctx()
            .load_texture("swatch", image, egui::TextureOptions::NEAREST);
        let rect =
            egui::Rect::from_min_size(view.min + egui::vec2(10.0, 10.0), egui::vec2(40.0, 40.0));
        painter.image(
            texture.id(),
            rect,
            egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            egui::Color32::WHITE,
        );
    })
}

/// Paints `output` over a mid-grey background with `paint`.
fn draw(
    gpu: &Gpu,
    target: &Offscreen,
    paint: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::TextureView),
) -> image::RgbaImage {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let _clear = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("background"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.view(),
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 0.2,
                        g: 0.3,
                        b: 0.1,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }
    paint(&mut encoder, target.view());
    gpu.queue.submit([encoder.finish()]);
    target.read(gpu).expect("read back")
}

fn ui_pass<'a>(
    encoder: &'a mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
) -> wgpu::RenderPass<'a> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("ui"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

#[test]
fn the_lean_painter_draws_what_egui_wgpu_draws() {
    let gpu = Gpu::headless().expect("a wgpu adapter (lavapipe: WGPU_BACKEND=vulkan)");
    let ctx = egui::Context::default();
    let output = run_ui(&ctx);
    let ppp = output.pixels_per_point;
    let jobs = ctx.tessellate(output.shapes.clone(), ppp);
    let target = Offscreen::new(&gpu.device, SIZE.0, SIZE.1);

    let mut reference = egui_wgpu::Renderer::new(&gpu.device, OFFSCREEN_FORMAT, Default::default());
    let screen = egui_wgpu::ScreenDescriptor {
        size_in_pixels: [SIZE.0, SIZE.1],
        pixels_per_point: ppp,
    };
    let by_egui_wgpu = draw(&gpu, &target, |encoder, view| {
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                reference.update_texture(&gpu.device, &gpu.queue, *id, delta);
            }
        }
        reference.update_buffers(&gpu.device, &gpu.queue, encoder, &jobs, &screen);
        let pass = ui_pass(encoder, view);
        reference.render(&mut pass.forget_lifetime(), &jobs, &screen);
    });

    let mut lean = UiPainter::new(&gpu.device, OFFSCREEN_FORMAT);
    lean.set_textures(&gpu.device, &gpu.queue, &output.textures_delta);
    lean.prepare(&gpu.device, &gpu.queue, &jobs, SIZE, ppp);
    let by_lean = draw(&gpu, &target, |encoder, view| {
        let mut pass = ui_pass(encoder, view);
        lean.paint(&mut pass);
    });
    lean.free_textures(&output.textures_delta);

    let background = by_lean.get_pixel(5, 5).0;
    let mut num_ui_pixels = 0;
    let mut max_difference = 0;
    for (a, b) in by_egui_wgpu.pixels().zip(by_lean.pixels()) {
        if a.0 != background {
            num_ui_pixels += 1;
        }
        let d =
            a.0.iter()
                .zip(b.0)
                .map(|(x, y)| x.abs_diff(y))
                .max()
                .unwrap_or(0);
        max_difference = max_difference.max(d);
    }
    println!("{num_ui_pixels} px of UI, largest difference {max_difference} levels");
    assert!(
        num_ui_pixels > 20_000,
        "the UI was drawn ({num_ui_pixels} px)"
    );
    // The swatch image is drawn (red over the grey-green background).
    let swatch = by_lean.get_pixel(30, 30).0;
    assert!(swatch[0] > 150 && swatch[1] < 80, "swatch {swatch:?}");
    assert!(
        max_difference <= 2,
        "the painters differ by {max_difference} levels"
    );
}
