//! The window's UI over a design state, driven as the desktop shell drives it: every event the
//! UI emits is applied to the design before the next frame. Shared by the UI tests.

use egui_kittest::Harness;
use sylva_app::state::DesignState;
use sylva_app::ui::{UiState, sylva_ui};

pub struct App {
    pub ui: UiState,
    pub design: DesignState,
}

/// A kittest harness of `app`'s UI at `width` × `height` points, run once.
pub fn harness(app: App, width: f32, height: f32) -> Harness<'static, App> {
    let mut harness = Harness::new_ui_state(
        |ui, app: &mut App| {
            let mut events = Vec::new();
            sylva_ui(ui, &mut app.ui, &app.design, &mut events);
            for e in events {
                app.design.apply(&e);
            }
        },
        app,
    );
    harness.set_size(egui::vec2(width, height));
    harness.run();
    harness
}
