//! The window's UI over a design state, driven as the desktop shell drives it: every event the
//! UI emits (controls, and touches on the AR view in camera-image pixels) is applied to the
//! design before the next frame. Shared by the UI tests.

use egui_kittest::Harness;
use sylva_app::render::Intrinsics;
use sylva_app::state::DesignState;
use sylva_app::ui::{UiState, sylva_ui, touch};

pub struct App {
    pub ui: UiState,
    pub design: DesignState,
}

impl App {
    /// The UI over `design`, its tree planted and the ground found (no hint in the way).
    #[allow(dead_code)] // not every test binary starts planted
    pub fn planted(design: DesignState) -> App {
        App {
            ui: UiState {
                ground_found: true,
                planted: true,
                ..UiState::default()
            },
            design,
        }
    }
}

/// A kittest harness of `app`'s UI at `width` × `height` points, run once.
pub fn harness(app: App, width: f32, height: f32) -> Harness<'static, App> {
    harness_at_scale(app, width, height, 1.0)
}

/// The same at `pixels_per_point` (a phone's scale factor).
pub fn harness_at_scale(
    app: App,
    width: f32,
    height: f32,
    pixels_per_point: f32,
) -> Harness<'static, App> {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(width, height))
        .with_pixels_per_point(pixels_per_point)
        .build_ui_state(
            |ui, app: &mut App| {
                let mut events = Vec::new();
                let view = sylva_ui(ui, &mut app.ui, &app.design, &mut events);
                if let Some(camera) = app.design.world_camera() {
                    touch::view_touches_ui(
                        ui,
                        view,
                        window_pixels(ui.ctx()),
                        &camera.intrinsics,
                        &mut events,
                    );
                }
                for e in events {
                    app.design.apply(&e);
                }
            },
            app,
        );
    harness.run();
    harness
}

/// The window's size in pixels (what the renderer letterboxes the camera image into).
pub fn window_pixels(ctx: &egui::Context) -> (u32, u32) {
    let size = ctx.content_rect().size() * ctx.pixels_per_point();
    (size.x.round() as u32, size.y.round() as u32)
}

/// Where camera-image pixel `pixel` is drawn in the harness's window, points.
#[allow(dead_code)] // not every test binary touches the view
pub fn window_pos(h: &Harness<'static, App>, k: &Intrinsics, pixel: glam::Vec2) -> egui::Pos2 {
    touch::window_from_image(pixel, h.ctx.pixels_per_point(), window_pixels(&h.ctx), k)
}
