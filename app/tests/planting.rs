//! Planting where the user taps (issue 20): before the tap there is nothing to edit, a tap on
//! the ground plants the tree under the finger, dragging the trunk base moves it, and the tree's
//! own coordinates (tree space) do not change with where it stands.

use glam::{Vec2, Vec3};
use sylva_app::render::{GroundPlane, Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};

fn camera() -> ViewCamera {
    let intrinsics = Intrinsics::from_fov(640, 480, 60f32.to_radians());
    ViewCamera::looking_at(intrinsics, Vec3::new(0.3, 1.5, 3.0), Vec3::ZERO)
}

fn touch(phase: TouchPhase, p: Vec2) -> InputEvent {
    InputEvent::Touch {
        phase,
        id: 0,
        x: p.x,
        y: p.y,
    }
}

/// One frame: the ground plane and the camera, then `events`, then the frame is shown.
fn frame(state: &mut DesignState, time_s: f64, events: &[InputEvent]) {
    let camera = camera();
    state.observe_scene(
        &camera.intrinsics,
        Some(camera.world_from_camera),
        Some(GroundPlane::default()),
        &[],
    );
    state.advance_frame(Some(camera), time_s, 1.0 / 30.0);
    for e in events {
        state.apply(e);
    }
}

fn base_in_world(state: &DesignState) -> Vec3 {
    Vec3::from(state.world_from_tree.expect("planted").translation)
}

#[test]
fn a_tap_on_the_ground_plants_the_tree_there_and_dragging_the_trunk_base_moves_it() {
    let mut state = DesignState::unplanted(7, Parameters::default());
    let seedling = state.tree_sha256();
    let spot = Vec3::new(0.4, 0.0, -0.2);
    let spot_pixel = camera().pixel_from_world(spot).expect("in view");
    // Before planting a stroke paints nothing and nothing is planted.
    frame(&mut state, 0.0, &[touch(TouchPhase::Start, spot_pixel)]);
    for i in 1..20 {
        let p = spot_pixel + Vec2::new(0.0, -8.0 * i as f32);
        frame(&mut state, i as f64 / 30.0, &[touch(TouchPhase::Move, p)]);
    }
    frame(&mut state, 0.7, &[touch(TouchPhase::End, spot_pixel)]);
    assert!(!state.is_planted() && state.stroke.is_none() && state.camera.is_none());
    assert_eq!(
        state.tree_sha256(),
        seedling,
        "an unplanted tree is not edited"
    );

    // A tap plants the tree under the finger.
    frame(
        &mut state,
        1.0,
        &[
            touch(TouchPhase::Start, spot_pixel),
            touch(TouchPhase::End, spot_pixel),
        ],
    );
    let base = base_in_world(&state);
    assert!(
        base.distance(spot) < 1e-3,
        "planted at {base}, tapped {spot}"
    );
    frame(&mut state, 1.1, &[]);
    let seen = state.camera.expect("the camera in tree space");
    let base_pixel = seen.pixel_from_world(Vec3::ZERO).expect("base in view");
    assert!(
        base_pixel.distance(spot_pixel) < 0.1,
        "{base_pixel} vs {spot_pixel}"
    );

    // Dragging the trunk base moves the tree; its own shape (tree space) stays as it was.
    let there = Vec3::new(-0.3, 0.0, 0.3);
    let there_pixel = camera().pixel_from_world(there).expect("in view");
    frame(&mut state, 1.2, &[touch(TouchPhase::Start, base_pixel)]);
    for i in 1..=10 {
        let p = base_pixel.lerp(there_pixel, i as f32 / 10.0);
        frame(
            &mut state,
            1.2 + i as f64 / 30.0,
            &[touch(TouchPhase::Move, p)],
        );
    }
    frame(&mut state, 1.6, &[touch(TouchPhase::End, there_pixel)]);
    let moved = base_in_world(&state);
    assert!(
        moved.distance(there) < 1e-3,
        "moved to {moved}, dragged to {there}"
    );
    assert_eq!(state.tree_sha256(), seedling, "moving is not growing");
    assert!(state.stroke.is_none(), "the drag painted no stroke");
}
