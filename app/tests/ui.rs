//! UI tests driven by widget labels (egui_kittest): the α/β/γ triangle, the brush-radius slider
//! mid-stroke, undo, and the plain-language controls (issue 20), each changing the grown tree as
//! its label says.

mod ui_harness;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use sylva_app::render::{Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};
use sylva_app::ui::UiState;
use sylva_core::Tree;
use ui_harness::App;

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
    ui_harness::harness(app, 1100.0, 700.0)
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
    h.get_by_label("Advanced").click();
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

/// Age the plain-control tests grow their trees to, years.
const CONTROL_AGE_YEARS: f64 = 10.0;

/// Opens the "Tree" tab, lets `control` drive one plain control by its label, then grows the
/// tree to [`CONTROL_AGE_YEARS`] with the age slider. Returns the grown tree.
fn grown_after(control: impl FnOnce(&mut Harness<'static, App>)) -> Tree {
    let mut h = harness(app());
    h.get_by_label("Tree").click();
    h.run();
    control(&mut h);
    h.run();
    h.get_by_role_and_label(egui::Role::Slider, "Age (years)")
        .set_value_accesskit(CONTROL_AGE_YEARS);
    h.run();
    let tree = h.state().design.tree.clone();
    assert!(
        tree.age_years() >= CONTROL_AGE_YEARS as f32 - 0.5,
        "the age slider grew the tree only to {} years",
        tree.age_years()
    );
    tree
}

fn slide(label: &'static str, value: f64) -> impl FnOnce(&mut Harness<'static, App>) {
    move |h| {
        h.get_by_role_and_label(egui::Role::Slider, label)
            .set_value_accesskit(value)
    }
}

fn mean(values: impl Iterator<Item = f32>) -> f32 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / n.max(1) as f32
}

/// Mean elevation of the branches (order ≥ 1) above the horizontal, degrees.
fn mean_branch_elevation_deg(tree: &Tree) -> f32 {
    mean(
        tree.skeleton
            .internodes
            .iter()
            .filter(|n| n.order >= 1)
            .map(|n| n.heading().y.clamp(-1.0, 1.0).asin().to_degrees()),
    )
}

/// Mean angle between each branch's first internode and the axis it grows from, degrees.
fn mean_branching_angle_deg(tree: &Tree) -> f32 {
    let nodes = &tree.skeleton.internodes;
    mean(nodes.iter().filter_map(|n| {
        let parent = &nodes[n.parent?.index()];
        (n.order > parent.order).then(|| n.heading().angle_between(parent.heading()).to_degrees())
    }))
}

/// Mean turn between consecutive internodes of one axis, degrees.
fn mean_turn_along_axes_deg(tree: &Tree) -> f32 {
    let nodes = &tree.skeleton.internodes;
    mean(nodes.iter().filter_map(|n| {
        let parent = &nodes[n.parent?.index()];
        (n.order == parent.order).then(|| n.heading().angle_between(parent.heading()).to_degrees())
    }))
}

#[test]
fn weeping_lowers_the_branches_and_upright_raises_them() {
    let click =
        |label: &'static str| move |h: &mut Harness<'static, App>| h.get_by_label(label).click();
    let weeping = mean_branch_elevation_deg(&grown_after(click("Weeping")));
    let spreading = mean_branch_elevation_deg(&grown_after(click("Spreading")));
    let upright = mean_branch_elevation_deg(&grown_after(click("Upright")));
    println!(
        "mean branch elevation: upright {upright:.1}°, spreading {spreading:.1}°, weeping {weeping:.1}°"
    );
    assert!(
        weeping + 5.0 < spreading && spreading + 5.0 < upright,
        "upright {upright}°, spreading {spreading}°, weeping {weeping}°"
    );
    let slid = mean_branch_elevation_deg(&grown_after(slide("Crown: upright to weeping", 1.0)));
    assert!(
        (slid - weeping).abs() < 1e-3,
        "the slider's weeping end gives {slid}°"
    );
}

#[test]
fn a_denser_crown_keeps_more_branches() {
    let sparse = grown_after(slide("Density", 0.0)).skeleton.len();
    let dense = grown_after(slide("Density", 1.0)).skeleton.len();
    println!("density 0: {sparse} internodes, density 1: {dense}");
    assert!(
        dense as f32 > 1.2 * sparse as f32,
        "sparse {sparse}, dense {dense}"
    );
}

#[test]
fn a_wider_branch_angle_opens_the_branches_from_their_axis() {
    let narrow = mean_branching_angle_deg(&grown_after(slide("Branch angle (°)", 20.0)));
    let wide = mean_branching_angle_deg(&grown_after(slide("Branch angle (°)", 70.0)));
    println!("branch angle 20°: branches leave at {narrow:.1}°, 70°: {wide:.1}°");
    assert!(wide > narrow + 15.0, "narrow {narrow}°, wide {wide}°");
}

#[test]
fn more_vigour_grows_a_bigger_tree() {
    let height = |t: &Tree| {
        t.skeleton
            .internodes
            .iter()
            .map(|n| n.end.y)
            .fold(0.0, f32::max)
    };
    let weak = grown_after(slide("Vigour", 0.1));
    let strong = grown_after(slide("Vigour", 0.9));
    println!(
        "vigour 0.1: {} internodes, {:.2} m tall; 0.9: {} internodes, {:.2} m",
        weak.skeleton.len(),
        height(&weak),
        strong.skeleton.len(),
        height(&strong)
    );
    assert!(strong.skeleton.len() > 2 * weak.skeleton.len());
    assert!(height(&strong) > height(&weak));
}

#[test]
fn a_straighter_tree_turns_less_along_its_axes() {
    let wavy = mean_turn_along_axes_deg(&grown_after(slide("Straightness", 0.1)));
    let straight = mean_turn_along_axes_deg(&grown_after(slide("Straightness", 0.9)));
    println!("mean turn along axes: straightness 0.1 {wavy:.1}°, 0.9 {straight:.1}°");
    assert!(straight + 3.0 < wavy, "straight {straight}°, wavy {wavy}°");
}

#[test]
fn the_depth_limit_flattens_the_crown_across_the_view() {
    // The test camera looks along −Z: the slab is about the plane z = 0.
    let depth_of = |tree: &Tree| {
        let mut z: Vec<f32> = tree
            .skeleton
            .internodes
            .iter()
            .map(|n| n.end.z.abs())
            .collect();
        z.sort_by(f32::total_cmp);
        z[z.len() * 95 / 100]
    };
    let free = depth_of(&grown_after(|_| {}));
    let flat_tree = grown_after(|h| {
        h.get_by_label("Flat crown (depth limit facing the view)")
            .click();
        h.run();
        h.get_by_role_and_label(egui::Role::Slider, "Depth limit (m)")
            .set_value_accesskit(0.2);
    });
    let flat = depth_of(&flat_tree);
    let l = flat_tree.species.internode_length_m;
    println!("95th percentile |z|: free {free:.2} m, depth limit 0.2 m {flat:.2} m");
    assert!(flat <= 0.2 + 2.0 * l, "the flat crown reaches {flat} m");
    assert!(free > flat + 0.3, "free {free} m, flat {flat} m");
}
