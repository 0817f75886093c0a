//! The default layout leaves the planted tree in view (issue 20, Done-when 5): at a desktop
//! window's 1280×800 and at a phone's 1080×2340 pixels held upright (scale factor 3, so
//! 360×780 points; the camera image letterboxed, or cropped to fill the screen as the phone shell
//! shows it), no panel and no control of the UI covers the tree's projected bounding box.
//! The tree is a 12-year-old maple framed as a user frames it: its crown filling most of the
//! camera image's height, in the middle.

mod ui_harness;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable, by};
use glam::Vec3;
use sylva_app::platform::DisplayTransform;
use sylva_app::render::{Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters};
use sylva_app::ui::UiState;
use sylva_core::Tree;
use ui_harness::App;

/// The share of the image's height (and width) the tree's bounding box may fill at most.
const FRAMED_FRACTION: f32 = 0.75;

fn bounds(tree: &Tree) -> (Vec3, Vec3) {
    tree.skeleton.internodes.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), n| (lo.min(n.start).min(n.end), hi.max(n.start).max(n.end)),
    )
}

/// A camera at eye height in front of the tree, far enough back that the tree's bounding box
/// fills [`FRAMED_FRACTION`] of the image in its tighter direction.
fn framing_camera(k: Intrinsics, tree: &Tree) -> ViewCamera {
    let (lo, hi) = bounds(tree);
    let centre = 0.5 * (lo + hi);
    let size = hi - lo;
    let depth_for = |extent_m: f32, focal_px: f32, image_px: u32| {
        extent_m * focal_px / (FRAMED_FRACTION * image_px as f32)
    };
    let distance =
        depth_for(size.y, k.fy, k.height).max(depth_for(size.x, k.fx, k.width)) + 0.5 * size.z;
    ViewCamera::looking_at(k, centre + Vec3::new(0.0, 0.0, distance), centre)
}

fn app(k: Intrinsics) -> App {
    let mut design = DesignState::new(7, Parameters::default());
    design.apply(&InputEvent::Parameters {
        parameters: Parameters {
            years: 12.0,
            ..Parameters::default()
        },
    });
    let camera = framing_camera(k, &design.tree);
    design.advance_frame(Some(camera), 0.0, 1.0 / 30.0);
    App {
        ui: UiState {
            ground_found: true,
            planted: true,
            num_frames: 300,
            ..UiState::default()
        },
        design,
    }
}

/// The tree's projected bounding box in the window, points.
fn tree_rect(h: &Harness<'static, App>) -> egui::Rect {
    let design = &h.state().design;
    let camera = design.camera.expect("the tree is seen");
    let points = design
        .tree
        .skeleton
        .internodes
        .iter()
        .flat_map(|n| [n.start, n.end])
        .filter_map(|p| camera.pixel_from_world(p))
        .map(|p| ui_harness::window_pos(h, &camera.intrinsics, p));
    egui::Rect::from_points(&points.collect::<Vec<_>>())
}

/// Checks that neither a panel nor any control of the UI overlaps the tree's box.
fn assert_tree_uncovered(h: &Harness<'static, App>, what: &str) {
    let tree = tree_rect(h);
    let screen = h.ctx.content_rect();
    println!("{what}: screen {screen:?}, tree {tree:?}");
    assert!(
        screen.contains_rect(tree),
        "{what}: the framing camera must show the whole tree ({tree:?} in {screen:?})"
    );
    assert!(
        tree.height() > 0.3 * screen.height().min(screen.width()),
        "{what}: the tree is too small to test with ({tree:?})"
    );
    let panels = &h.state().ui.panel_rects;
    assert!(panels.len() >= 2, "{what}: the panels were not recorded");
    for panel in panels {
        println!("  panel {panel:?}");
        assert!(
            !panel.intersects(tree),
            "{what}: a panel {panel:?} covers the tree {tree:?}"
        );
    }
    let controls = h.query_all(by().predicate(|node| {
        use egui::accesskit::Role;
        matches!(
            node.role(),
            Role::Button
                | Role::Slider
                | Role::SpinButton
                | Role::CheckBox
                | Role::ComboBox
                | Role::Label
                | Role::Tab
                | Role::TextInput
        )
    }));
    let mut num_controls = 0;
    for node in controls {
        num_controls += 1;
        let rect = node.rect();
        assert!(
            !rect.intersects(tree),
            "{what}: {:?} at {rect:?} covers the tree {tree:?}",
            node.accesskit_node().label()
        );
    }
    assert!(
        num_controls > 10,
        "{what}: only {num_controls} controls seen"
    );
}

#[test]
fn no_panel_covers_the_planted_tree_in_a_desktop_window() {
    let k = Intrinsics::from_fov(640, 480, 60f32.to_radians());
    let h = ui_harness::harness(app(k), 1280.0, 800.0);
    assert_tree_uncovered(&h, "1280×800");
}

#[test]
fn no_panel_covers_the_planted_tree_on_a_phone_held_upright() {
    // 1080×2340 pixels at scale factor 3: 360×780 points.
    for (what, k) in [
        (
            "phone, portrait camera",
            Intrinsics::from_fov(480, 640, 50f32.to_radians()),
        ),
        (
            "phone, landscape camera",
            Intrinsics::from_fov(640, 480, 60f32.to_radians()),
        ),
        (
            // As the phone shell shows its camera: cropped to fill the screen (the tree framed
            // in what is shown).
            "phone, camera filling the screen",
            DisplayTransform::phone(0).shown_intrinsics(
                &Intrinsics::from_fov(640, 480, 60f32.to_radians()),
                (1080, 2340),
            ),
        ),
    ] {
        let h = ui_harness::harness_at_scale(app(k), 360.0, 780.0, 3.0);
        assert_eq!(ui_harness::window_pixels(&h.ctx), (1080, 2340));
        assert_tree_uncovered(&h, what);
    }
}

#[test]
fn the_phone_layout_docks_the_controls_and_unfolds_more_on_request() {
    let k = Intrinsics::from_fov(480, 640, 50f32.to_radians());
    let mut h = ui_harness::harness_at_scale(app(k), 360.0, 780.0, 3.0);
    let screen = h.ctx.content_rect();
    // The tools are along the bottom, not in a side bar.
    let lasso = h.get_by_label("Lasso crown").rect();
    assert!(lasso.bottom() > 0.7 * screen.height(), "{lasso:?}");
    assert!(
        lasso.width() >= 44.0 && lasso.height() >= 44.0,
        "{lasso:?} is no finger target"
    );
    let brush_radius = |h: &Harness<'static, App>| {
        h.query_all_by_role_and_label(egui::accesskit::Role::Slider, "Brush radius")
            .count()
    };
    assert_eq!(brush_radius(&h), 0, "folded away by default");
    h.get_by_label("More").click();
    h.run();
    assert_eq!(brush_radius(&h), 1);
}
