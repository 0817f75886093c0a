//! Outside AR the tree view orbits, pans and zooms (egui_kittest): the bottom bar's switch opens
//! the 3D view, a drag across it turns the camera around the tree, the wheel brings it closer.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use sylva_app::state::{DesignState, Parameters};
use sylva_app::ui::orbit::{OrbitCamera, orbit_view_ui};
use sylva_app::ui::{UiState, sylva_ui};

struct App {
    ui: UiState,
    design: DesignState,
    orbit: OrbitCamera,
}

fn harness() -> Harness<'static, App> {
    let app = App {
        ui: UiState::default(),
        design: DesignState::new(7, Parameters::default()),
        orbit: OrbitCamera::default(),
    };
    let mut harness = Harness::new_ui_state(
        |ui, app: &mut App| {
            let mut events = Vec::new();
            let view = sylva_ui(ui, &mut app.ui, &app.design, &mut events);
            if app.ui.orbit_view {
                orbit_view_ui(ui, view, &mut app.orbit, 500.0);
            }
        },
        app,
    );
    harness.set_size(egui::vec2(1100.0, 700.0));
    harness.run();
    harness
}

#[test]
fn the_3d_view_opens_from_the_bottom_bar_and_orbits_and_zooms_with_the_pointer() {
    let mut h = harness();
    assert!(!h.state().ui.orbit_view);
    h.get_by_label("3D view (outside AR)").click();
    h.run();
    assert!(h.state().ui.orbit_view, "the switch opens the 3D view");

    let start = h.state().orbit;
    let centre = egui::pos2(450.0, 350.0);
    h.drag_at(centre);
    h.run();
    h.hover_at(centre + egui::vec2(60.0, 0.0));
    h.run();
    h.hover_at(centre + egui::vec2(120.0, 0.0));
    h.run();
    h.drop_at(centre + egui::vec2(120.0, 0.0));
    h.run();
    let turned = h.state().orbit;
    assert!(
        (turned.yaw - start.yaw).abs() > 0.3,
        "a 120-point drag turns the camera: yaw {} -> {}",
        start.yaw,
        turned.yaw
    );
    assert!((turned.distance - start.distance).abs() < 1e-5);
    assert_eq!(turned.target, start.target);

    h.hover_at(centre);
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 200.0),
        modifiers: egui::Modifiers::NONE,
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
    });
    for _ in 0..10 {
        h.run();
    }
    assert!(
        h.state().orbit.distance < turned.distance * 0.9,
        "scrolling up comes closer: {} -> {}",
        turned.distance,
        h.state().orbit.distance
    );
}
