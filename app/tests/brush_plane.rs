//! The brush plane follows the device (Longay 2014 §5.2, §5.4.2): while a finger is held still
//! and the camera moves forward, the stroke's new world points move with the camera and stay at
//! the stroke's starting camera distance, and so do the attraction points the core stroke adds
//! (what the tree grows towards). Frames are fed exactly as `sylva replay` feeds them.

use glam::{Mat4, Vec2, Vec3};
use sylva_app::render::{Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};

#[test]
fn stroke_points_move_with_a_forward_moving_camera_at_constant_distance() {
    let k = Intrinsics::from_fov(640, 480, 1.0);
    let start = ViewCamera::looking_at(k, Vec3::new(0.0, 0.8, 3.0), Vec3::new(0.0, 0.6, 0.0));
    let forward = start.world_from_camera.z_axis.truncate();
    let camera_at = |i: usize| {
        let mut c = start;
        c.world_from_camera =
            Mat4::from_translation(forward * 0.03 * i as f32) * start.world_from_camera;
        c
    };
    // No growth while painting, so that every brushed attraction point stays to be checked.
    let params = Parameters {
        grow_speed: 0.0,
        ..Parameters::default()
    };
    let mut design = DesignState::new(3, params);
    design.advance_frame(Some(camera_at(0)), 0.0, 1.0 / 30.0);
    let finger = Vec2::new(380.0, 150.0);
    design.apply(&InputEvent::Touch {
        phase: TouchPhase::Start,
        id: 0,
        x: finger.x - 20.0,
        y: finger.y,
    });
    design.apply(&InputEvent::Touch {
        phase: TouchPhase::Move,
        id: 0,
        x: finger.x,
        y: finger.y,
    });
    for i in 1..=20 {
        design.advance_frame(Some(camera_at(i)), i as f64 / 30.0, 1.0 / 30.0);
    }
    let stroke = design.stroke.clone().expect("stroke in progress");
    let depth = stroke.depth;
    assert!(
        depth > 1.0,
        "the plane starts at the tree's depth, got {depth}"
    );
    assert!(
        stroke.points.len() >= 21,
        "one point per move and per frame: {}",
        stroke.points.len()
    );
    let frame_points = &stroke.points[stroke.points.len() - 20..];
    for (i, point) in frame_points.iter().enumerate() {
        let camera = camera_at(i + 1);
        let in_camera = camera.camera_from_world().transform_point3(*point);
        assert!(
            (in_camera.z - depth).abs() < 1e-4,
            "point {i} at camera depth {} instead of {depth}",
            in_camera.z
        );
        let pixel = camera
            .intrinsics
            .pixel_from_camera(in_camera)
            .expect("in front");
        assert!(
            pixel.distance(finger) < 1e-2,
            "point {i} is not under the finger: {pixel}"
        );
    }
    // The points advance with the camera: each step by the camera's own displacement.
    for pair in frame_points.windows(2) {
        let step = pair[1] - pair[0];
        assert!(
            (step - forward * 0.03).length() < 1e-4,
            "stroke moved by {step}, camera by {}",
            forward * 0.03
        );
    }
    let total = frame_points[19] - frame_points[0];
    assert!(
        total.length() > 0.5,
        "the stroke lengthened by {} m",
        total.length()
    );
    // What the tree grows towards follows too: every brushed attraction point lies in the
    // volume swept by the brush along the moving stroke, and the last ones around its end.
    let radius = Parameters::default().brush_radius;
    let polyline_distance = |p: Vec3| {
        stroke
            .points
            .windows(2)
            .map(|w| {
                let d = w[1] - w[0];
                let t = ((p - w[0]).dot(d) / d.length_squared().max(1e-12)).clamp(0.0, 1.0);
                p.distance(w[0] + d * t)
            })
            .fold(f32::INFINITY, f32::min)
    };
    let attraction = &design.tree.environment.attraction.points;
    let brushed: Vec<Vec3> = attraction
        .iter()
        .filter(|p| p.persistent)
        .map(|p| p.position)
        .collect();
    assert!(brushed.len() > 20, "only {} brushed points", brushed.len());
    let farthest = brushed
        .iter()
        .map(|&p| polyline_distance(p))
        .fold(0.0, f32::max);
    assert!(
        farthest <= radius + 1e-4,
        "a brushed point lies {farthest} m from the moving stroke (brush radius {radius})"
    );
    let end = frame_points[19];
    let near_end = brushed
        .iter()
        .filter(|p| p.distance(end) <= radius + 1e-4)
        .count();
    assert!(
        near_end > 0,
        "no attraction point around the stroke's end {end}"
    );
    let first = frame_points[0];
    let reach = brushed
        .iter()
        .map(|p| (*p - first).dot(forward))
        .fold(f32::NEG_INFINITY, f32::max);
    println!(
        "{} brushed points, all within {farthest:.3} m of the stroke; {near_end} around its end, reaching {reach:.2} m forward of the first frame's point",
        brushed.len()
    );
    assert!(
        reach > 0.5,
        "the attraction points reach only {reach} m forward"
    );
}
