//! The editing tools driven through the window's UI (issue 20, Done-when 5): each tool is chosen
//! by its button and used with one finger (the mouse) on the AR view, as a user would; the tests
//! then check the tree the design holds. The depth tool (flat crown) is in `ui.rs`, the scene
//! modes in `scene_mode_ui.rs`.

mod ui_harness;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::{Vec2, Vec3};
use sylva_app::render::{Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, Tool};
use sylva_core::NodeId;
use ui_harness::App;

fn camera() -> ViewCamera {
    let k = Intrinsics::from_fov(640, 480, 1.0);
    ViewCamera::looking_at(k, Vec3::new(0.0, 1.0, 3.2), Vec3::new(0.0, 0.9, 0.0))
}

/// A design planted at the origin, seen by [`camera`], grown to `years` (0: the seedling).
fn app(years: f32) -> App {
    let mut design = DesignState::new(7, Parameters::default());
    design.advance_frame(Some(camera()), 0.0, 1.0 / 30.0);
    if years > 0.0 {
        design.apply(&InputEvent::Parameters {
            parameters: Parameters {
                years,
                ..design.params.clone()
            },
        });
    }
    App::planted(design)
}

fn harness(app: App) -> Harness<'static, App> {
    ui_harness::harness(app, 1100.0, 700.0)
}

fn choose(h: &mut Harness<'static, App>, label: &str) {
    h.get_by_label(label).click();
    h.run();
}

/// A drag with the mouse (one finger) through `pixels` of the camera image.
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

fn pixel(p: Vec3) -> Vec2 {
    camera()
        .pixel_from_world(p)
        .expect("in front of the camera")
}

#[test]
fn the_lasso_grows_the_crown_inside_the_drawn_outline() {
    let mut h = harness(app(0.0));
    choose(&mut h, "Lasso crown");
    assert_eq!(h.state().design.tool(), Tool::LassoCrown);
    let before = h.state().design.tree.clone();
    // A circle on the plane through the base facing the camera (z = 0), around the seedling.
    let (centre, radius_m) = (Vec2::new(0.0, 1.0), 0.6);
    let outline: Vec<Vec2> = (0..=60)
        .map(|i| {
            let p = centre + Vec2::from_angle(i as f32 / 60.0 * std::f32::consts::TAU) * radius_m;
            pixel(Vec3::new(p.x, p.y, 0.0))
        })
        .collect();
    drag_through(&mut h, &outline);
    let tree = &h.state().design.tree;
    let l = tree.species.internode_length_m;
    let grown: Vec<_> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.born_iteration > before.iteration)
        .collect();
    let outside: Vec<Vec3> = grown
        .iter()
        .map(|n| n.end)
        .filter(|e| Vec2::new(e.x, e.y).distance(centre) > radius_m + l)
        .collect();
    let depth = grown.iter().map(|n| n.end.z.abs()).fold(0.0, f32::max);
    println!(
        "lasso: {} internodes grew in {} iterations, {} outside the outline + l ({l:.3} m), \
         crown depth ±{depth:.2} m",
        grown.len(),
        tree.iteration - before.iteration,
        outside.len()
    );
    assert!(grown.len() >= 60, "only {} internodes grew", grown.len());
    assert!(outside.is_empty(), "outside the outline: {outside:?}");
    // The outline is inflated into a round envelope, not a flat one.
    assert!(depth > 0.3 * radius_m, "crown depth only ±{depth} m");
    // One undo step takes it all back.
    h.get_by_label("Undo").click();
    h.run();
    assert_eq!(h.state().design.tree.skeleton, before.skeleton);
}

/// A branch of order 1 whose first internode's midpoint is nearest the middle of the view.
fn branch_near_the_middle(design: &DesignState) -> NodeId {
    let middle = Vec2::new(320.0, 240.0);
    let nodes = &design.tree.skeleton.internodes;
    let (i, _) = nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.order == 1 && n.parent.is_some_and(|p| nodes[p.index()].order == 0))
        .map(|(i, n)| (i, pixel(0.5 * (n.start + n.end)).distance(middle)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("the tree has branches");
    NodeId(i as u32)
}

#[test]
fn the_width_tool_gives_the_branches_drawn_over_the_width_on_its_slider() {
    let mut h = harness(app(6.0));
    choose(&mut h, "Width");
    h.get_by_role_and_label(egui::Role::Slider, "Branch width (cm)")
        .set_value_accesskit(4.0);
    h.run();
    assert_eq!(
        h.state().design.tool(),
        Tool::Width { diameter_m: 0.04 },
        "the slider sets the tool's width"
    );
    let target = branch_near_the_middle(&h.state().design);
    let node = h.state().design.tree.skeleton.get(target).clone();
    let before = node.diameter;
    let path: Vec<Vec2> = (0..=8)
        .map(|i| pixel(node.start.lerp(node.end, i as f32 / 8.0)))
        .collect();
    drag_through(&mut h, &path);
    let tree = &h.state().design.tree;
    let constrained: Vec<_> = tree
        .skeleton
        .internodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.width_constraint.is_some())
        .collect();
    let after = tree.skeleton.get(target).diameter;
    println!(
        "width tool: branch {target:?} {:.1} mm -> {:.1} mm; {} internodes drawn over",
        before * 1000.0,
        after * 1000.0,
        constrained.len()
    );
    assert!(
        constrained.iter().any(|(i, _)| *i == target.index()),
        "the branch drawn over got no width"
    );
    for (i, n) in &constrained {
        assert!(
            (n.diameter - 0.04).abs() < 1e-5,
            "internode {i} is {} m wide, the slider says 4 cm",
            n.diameter
        );
        // Only what the finger passed over (the pick radius about the stroke).
        let mid = pixel(0.5 * (n.start + n.end));
        let near = path
            .iter()
            .map(|p| p.distance(mid))
            .fold(f32::MAX, f32::min);
        assert!(near <= 26.0, "internode {i} is {near} px from the stroke");
    }
    assert!((after - before).abs() > 0.005, "the width did not change");
}

#[test]
fn one_finger_with_the_bend_tool_moves_the_touched_branch_in_the_drag_direction() {
    let mut h = harness(app(6.0));
    choose(&mut h, "Bend");
    let target = branch_near_the_middle(&h.state().design);
    let node = h.state().design.tree.skeleton.get(target).clone();
    let grab = pixel(0.5 * (node.start + node.end));
    let before = h.state().design.tree.clone();
    let drag = Vec2::new(0.0, -60.0); // upwards in the image
    let path: Vec<Vec2> = (0..=6).map(|i| grab + drag * (i as f32 / 6.0)).collect();
    drag_through(&mut h, &path);
    let design = &h.state().design;
    let branch = design.selected_branch();
    assert!(!branch.is_empty(), "the bend tool selected no branch");
    let tip = *branch.last().expect("non-empty");
    let moved = pixel(design.tree.skeleton.get(tip).end) - pixel(before.skeleton.get(tip).end);
    let along = moved.dot(drag.normalize());
    println!(
        "bend: branch {:?} ({} internodes), tip moved {moved} px for a drag of {drag} px \
         ({along:.1} px along it)",
        branch[0],
        branch.len()
    );
    assert!(
        along > 0.3 * drag.length(),
        "the tip moved {moved} px for a drag of {drag}"
    );
    assert!(
        moved.perp_dot(drag.normalize()).abs() < along,
        "the tip moved more across the drag than along it: {moved}"
    );
    // The rest of the tree stays where it was (only the bent branch's subtree moves).
    let trunk = design.tree.skeleton.get(NodeId(0));
    assert_eq!(trunk.end, before.skeleton.get(NodeId(0)).end);
    assert!(design.undo_depth() > 0, "the bend is one undo step");
}

#[test]
fn a_tap_with_the_prune_tool_cuts_the_branch_under_the_finger() {
    let mut h = harness(app(6.0));
    choose(&mut h, "Prune");
    let target = branch_near_the_middle(&h.state().design);
    let node = h.state().design.tree.skeleton.get(target).clone();
    let before = h.state().design.tree.skeleton.len();
    let at = pixel(0.5 * (node.start + node.end));
    drag_through(&mut h, &[at]);
    let after = h.state().design.tree.skeleton.len();
    println!("prune tool: {before} -> {after} internodes");
    assert!(after < before, "nothing was cut");
}

#[test]
fn the_selected_branch_is_drawn_highlighted_over_the_view() {
    let mut h = harness(app(6.0));
    choose(&mut h, "Bend");
    let target = branch_near_the_middle(&h.state().design);
    let node = h.state().design.tree.skeleton.get(target).clone();
    let grab = pixel(0.5 * (node.start + node.end));
    // Touch and hold still: the branch is selected, and stays so after release.
    drag_through(&mut h, &[grab, grab]);
    let selected = h
        .state()
        .design
        .selected
        .expect("the touched branch is selected");
    h.run();
    let k = camera().intrinsics;
    let n = h.state().design.tree.skeleton.get(selected).clone();
    let ends = [n.start, n.end].map(|p| ui_harness::window_pos(&h, &k, pixel(p)));
    let highlight = h
        .output()
        .shapes
        .iter()
        .filter_map(|clipped| match &clipped.shape {
            egui::Shape::LineSegment { points, stroke } if stroke.width >= 5.0 => Some(*points),
            _ => None,
        })
        .any(|points| points[0].distance(ends[0]) < 1.0 && points[1].distance(ends[1]) < 1.0);
    assert!(
        highlight,
        "no thick line is drawn over the selected internode {selected:?}"
    );
}

#[test]
fn choosing_a_tool_is_recorded_and_old_sessions_keep_the_brush() {
    let mut h = harness(app(0.0));
    assert_eq!(h.state().design.tool(), Tool::Brush);
    choose(&mut h, "Width");
    assert!(matches!(h.state().design.tool(), Tool::Width { .. }));
    let event = InputEvent::Tool {
        tool: Tool::Width { diameter_m: 0.05 },
    };
    let json = serde_json::to_string(&event).expect("serialises");
    assert_eq!(
        serde_json::from_str::<InputEvent>(&json).expect("parses"),
        event,
        "{json}"
    );
    choose(&mut h, "Lasso crown");
    assert_eq!(h.state().design.tool(), Tool::LassoCrown);
    choose(&mut h, "Brush");
    assert_eq!(h.state().design.tool(), Tool::Brush);
}
