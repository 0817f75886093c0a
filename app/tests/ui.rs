//! UI tests driven by widget labels (egui_kittest): the α/β/γ triangle, the brush-radius slider
//! mid-stroke, and undo.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use sylva_app::render::{Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};
use sylva_app::ui::{UiState, sylva_ui};

struct App {
    ui: UiState,
    design: DesignState,
}

fn camera() -> ViewCamera {
    let k = Intrinsics::from_fov(640, 480, 1.0);
    ViewCamera::looking_at(k, Vec3::new(0.0, 0.8, 2.5), Vec3::new(0.0, 0.5, 0.0))
}

fn app() -> App {
    let mut design = DesignState::new(7, Parameters::default());
    design.advance_frame(Some(camera()), 0.0, 1.0 / 30.0);
    App {
        ui: UiState {
            ground_found: true,
            ..UiState::default()
        },
        design,
    }
}

fn harness(app: App) -> Harness<'static, App> {
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
    harness.set_size(egui::vec2(1100.0, 700.0));
    harness.run();
    harness
}

fn touch(design: &mut DesignState, phase: TouchPhase, x: f32, y: f32) {
    design.apply(&InputEvent::Touch { phase, id: 0, x, y });
}

/// One stroke upwards over 30 frames from above the seedling.
fn brush_stroke(design: &mut DesignState) {
    let cam = camera();
    let start = cam
        .pixel_from_world(Vec3::new(0.0, 0.8, 0.0))
        .expect("visible");
    touch(design, TouchPhase::Start, start.x, start.y);
    for i in 1..30 {
        touch(
            design,
            TouchPhase::Move,
            start.x + i as f32 * 2.0,
            start.y - i as f32 * 3.0,
        );
        design.advance_frame(Some(cam), i as f64 / 30.0, 1.0 / 30.0);
    }
    touch(design, TouchPhase::End, start.x + 60.0, start.y - 90.0);
}

#[test]
fn dragging_the_weights_triangle_keeps_the_sum_one_and_changes_growth() {
    let mut h = harness(app());
    h.get_by_label("Architecture").click();
    h.run();
    let rect = h.get_by_label("α β γ triangle").rect();
    let before = h.state().design.params.direction_weights;
    h.drag_at(rect.center());
    h.run();
    // Towards the bottom right corner (γ, tropism) and beyond it.
    h.hover_at(rect.right_bottom() + egui::vec2(-20.0, -15.0));
    h.run();
    h.hover_at(rect.right_bottom() + egui::vec2(30.0, 30.0));
    h.run();
    h.drop_at(rect.right_bottom() + egui::vec2(30.0, 30.0));
    h.run();
    let after = h.state().design.params.direction_weights;
    let sum: f32 = after.iter().sum();
    assert!((sum - 1.0).abs() < 1e-5, "α + β + γ = {sum} ({after:?})");
    assert!(after.iter().all(|w| *w >= 0.0));
    assert!(
        after[2] > before[2] + 0.3,
        "γ should grow towards its corner: {before:?} -> {after:?}"
    );

    let mut default_design = app().design;
    brush_stroke(&mut default_design);
    let mut changed = app().design;
    changed.apply(&InputEvent::Parameters {
        parameters: h.state().design.params.clone(),
    });
    brush_stroke(&mut changed);
    assert!(
        default_design.tree.skeleton.len() > 6,
        "the stroke must grow the tree"
    );
    assert_ne!(
        default_design.tree_sha256(),
        changed.tree_sha256(),
        "new weights must change growth"
    );
}

#[test]
fn the_brush_radius_slider_changes_the_radius_in_the_middle_of_a_stroke() {
    let mut h = harness(app());
    let cam = camera();
    let start = cam
        .pixel_from_world(Vec3::new(0.0, 0.8, 0.0))
        .expect("visible");
    {
        let design = &mut h.state_mut().design;
        touch(design, TouchPhase::Start, start.x, start.y);
        for i in 1..5 {
            touch(design, TouchPhase::Move, start.x + i as f32 * 4.0, start.y);
        }
    }
    h.get_by_role_and_label(egui::Role::Slider, "Brush radius")
        .set_value_accesskit(0.3);
    h.run();
    {
        let design = &mut h.state_mut().design;
        assert!(
            (design.params.brush_radius - 0.3).abs() < 1e-4,
            "slider did not set the radius"
        );
        for i in 5..9 {
            touch(design, TouchPhase::Move, start.x + i as f32 * 4.0, start.y);
        }
        let stroke = design.stroke.as_ref().expect("the stroke is still going");
        let default_radius = Parameters::default().brush_radius;
        assert!(
            stroke
                .radii
                .iter()
                .any(|r| (*r - default_radius).abs() < 1e-6),
            "{:?}",
            stroke.radii
        );
        assert!(
            stroke.radii.iter().any(|r| (*r - 0.3).abs() < 1e-4),
            "{:?}",
            stroke.radii
        );
        assert!((stroke.radii.last().copied().unwrap_or(0.0) - 0.3).abs() < 1e-4);
    }
}

#[test]
fn undo_restores_the_previous_tree() {
    let mut h = harness(app());
    let before = h.state().design.tree.skeleton.clone();
    h.state_mut()
        .design
        .apply(&InputEvent::Grow { iterations: 2 });
    assert_ne!(
        h.state().design.tree.skeleton,
        before,
        "growing must change the tree"
    );
    h.run();
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(h.state().design.tree.skeleton, before);
}
