//! The Recreate mode driven through the window's UI (issue 23, Done-when 4): the "Recreate a
//! tree" tab starts marking, a tap on the view marks the trunk base and a drag traces the
//! crown's outline, as a user does; the marks land in the design's Recreate mode. Growing from
//! real footage is `recreate_session.rs`.

mod ui_harness;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::{Vec2, Vec3};
use sylva_app::render::{GroundPlane, Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, Parameters};
use ui_harness::App;

fn camera() -> ViewCamera {
    let k = Intrinsics::from_fov(640, 480, 1.0);
    ViewCamera::looking_at(k, Vec3::new(0.0, 1.5, 6.0), Vec3::new(0.0, 1.5, 0.0))
}

/// A drag with the mouse (one finger) through `pixels` of the camera image (one pixel: a tap).
fn drag_through(h: &mut Harness<'static, App>, pixels: &[Vec2]) {
    let k = camera().intrinsics;
    let points: Vec<egui::Pos2> = pixels
        .iter()
        .map(|p| ui_harness::window_pos(h, &k, *p))
        .collect();
    h.drag_at(points[0]);
    h.run();
    for p in &points[1..] {
        h.hover_at(*p);
        h.run();
    }
    h.drop_at(*points.last().expect("a drag has points"));
    h.run();
}

#[test]
fn the_recreate_tab_marks_the_trunk_base_with_a_tap_and_the_crown_with_a_drag() {
    let mut design = DesignState::new(7, Parameters::default());
    let ground = GroundPlane {
        point: Vec3::ZERO,
        normal: Vec3::Y,
    };
    let k = camera().intrinsics;
    design.observe_scene(&k, Some(camera().world_from_camera), Some(ground), &[]);
    design.advance_frame(Some(camera()), 0.0, 1.0 / 30.0);
    let mut h = ui_harness::harness(App::planted(design), 1100.0, 700.0);
    h.get_by_label("Recreate a tree").click();
    h.run();
    h.get_by_label("Start marking").click();
    h.run();
    assert!(h.state().design.recreate.active, "marking did not start");
    let tree_before = h.state().design.tree_sha256();
    drag_through(&mut h, &[Vec2::new(320.0, 420.0)]);
    let base = (h.state().design.recreate.base.clone()).expect("the tap marked the trunk base");
    assert_eq!(base.frame, 0);
    assert!(
        (base.pixel[0] - 320.0).abs() < 2.0 && (base.pixel[1] - 420.0).abs() < 2.0,
        "the base tap landed at {:?}",
        base.pixel
    );
    let outline: Vec<Vec2> = (0..=24)
        .map(|i| {
            let angle = i as f32 / 24.0 * std::f32::consts::TAU;
            Vec2::new(320.0, 300.0) + Vec2::from_angle(angle) * Vec2::new(60.0, 90.0)
        })
        .collect();
    drag_through(&mut h, &outline);
    let mode = &h.state().design.recreate;
    assert_eq!(mode.outlines.len(), 1, "the drag traced no outline");
    let traced = &mode.outlines[0].outline;
    assert!(traced.len() >= 12, "{} outline points", traced.len());
    assert!(
        traced.iter().all(|p| (p[1] - 300.0).abs() <= 92.0),
        "outline points off the drag: {traced:?}"
    );
    assert_eq!(
        h.state().design.tree_sha256(),
        tree_before,
        "marking touched the tree"
    );
}
