//! The scene control (issue 20): the Tree tab's "Scene" buttons set the mode the design grows
//! in, and the mode changes the tree as its label says. The scene is a wall 0.35 m behind the
//! tree, seen as tracked points (pixel and depth) by one camera, exactly what the app's
//! occupancy map is built from.

mod ui_harness;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::{Vec2, Vec3};
use sylva_app::planting::SceneChoice;
use sylva_app::render::{GroundPlane, Intrinsics, ViewCamera};
use sylva_app::scene_tracking::{SCENE_LATENCY_FRAMES, SceneOccupancy};
use sylva_app::state::{DesignState, InputEvent, Parameters};
use sylva_app::ui::UiState;
use sylva_tracking::depth_mesh::Observation;
use ui_harness::App;

const WALL_Z_M: f32 = -0.35;

fn camera() -> ViewCamera {
    let k = Intrinsics::from_fov(640, 480, 1.0);
    ViewCamera::looking_at(k, Vec3::new(0.0, 1.2, 2.5), Vec3::new(0.0, 0.6, 0.0))
}

/// The wall (plane z = WALL_Z_M) and the ground in front of it, as tracked points on a grid of
/// pixels.
fn wall_points(camera: &ViewCamera) -> Vec<Observation> {
    let k = camera.intrinsics;
    let eye = camera.position();
    let mut observations = Vec::new();
    for row in 0..16 {
        for column in 0..21 {
            let pixel = Vec2::new(column as f32 * 31.9 + 1.0, row as f32 * 31.9 + 1.0);
            let ray = k.ray_from_pixel(pixel);
            let direction = camera.world_from_camera.transform_vector3(ray);
            let to_wall = (WALL_Z_M - eye.z) / direction.z;
            let to_ground = if direction.y < 0.0 {
                -eye.y / direction.y
            } else {
                f32::INFINITY
            };
            // `ray` has camera z = 1, so the ray parameter is the depth.
            let depth_m = to_wall.min(to_ground);
            observations.push(Observation {
                id: observations.len() as u64,
                pixel,
                depth_m,
            });
        }
    }
    observations
}

fn app() -> App {
    let mut design = DesignState::new(7, Parameters::default());
    let camera = camera();
    // The camera holds still while a keyframe joins the map.
    for step in 0..=SCENE_LATENCY_FRAMES {
        design.observe_scene(
            &camera.intrinsics,
            Some(camera.world_from_camera),
            Some(GroundPlane::default()),
            &wall_points(&camera),
        );
        design.advance_frame(Some(camera), step as f64 / 30.0, 1.0 / 30.0);
    }
    assert_eq!(design.num_scene_keyframes(), 1);
    App::planted(design)
}

fn harness(app: App) -> Harness<'static, App> {
    ui_harness::harness(app, 1100.0, 700.0)
}

/// Internodes reaching more than 10 cm (two voxels) into the wall where the camera saw it (the
/// wall beyond the picture is unknown to the app, as it would be on site).
fn num_in_wall(design: &DesignState) -> usize {
    let camera = camera();
    let k = camera.intrinsics;
    design
        .tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| {
            n.end.z < WALL_Z_M - 0.1
                && camera.pixel_from_world(n.end).is_some_and(|p| {
                    p.x >= 0.0 && p.y >= 0.0 && p.x < k.width as f32 && p.y < k.height as f32
                })
        })
        .count()
}

fn grown_with(choice: Option<SceneChoice>) -> DesignState {
    let mut h = harness(app());
    if let Some(choice) = choice {
        h.get_by_label("Tree").click();
        h.run();
        h.get_by_label(choice.label()).click();
        h.run();
        assert_eq!(h.state().design.params.scene_mode, choice);
    }
    let mut design = h.into_state().design;
    design.apply(&InputEvent::Grow { iterations: 6 });
    design
}

#[test]
fn the_scene_buttons_keep_the_tree_out_of_a_wall_that_free_growth_enters() {
    let free = grown_with(None);
    let in_front = grown_with(Some(SceneChoice::GrowInFront));
    let (n_free, n_front) = (free.tree.skeleton.len(), in_front.tree.skeleton.len());
    println!(
        "free: {n_free} internodes, {} in the wall; in front: {n_front}, {} in the wall",
        num_in_wall(&free),
        num_in_wall(&in_front)
    );
    assert!(num_in_wall(&free) > 0, "the free tree must reach the wall");
    assert_eq!(num_in_wall(&in_front), 0, "grow in front entered the wall");
    assert!(n_front * 2 >= n_free, "grow in front stopped the tree");

    // "Prune to the scene" cuts what the free tree pushed into the wall, at once.
    let mut h = harness(App {
        ui: UiState {
            ground_found: true,
            planted: true,
            ..UiState::default()
        },
        design: free,
    });
    h.get_by_label("Tree").click();
    h.run();
    h.get_by_label(SceneChoice::PruneToScene.label()).click();
    h.run();
    let pruned = &h.state().design;
    assert_eq!(pruned.params.scene_mode, SceneChoice::PruneToScene);
    assert_eq!(
        num_in_wall(pruned),
        0,
        "pruning left internodes in the wall"
    );
    assert!(pruned.tree.skeleton.len() < n_free, "pruning cut nothing");
}

#[test]
fn the_window_s_occupancy_worker_builds_the_same_map_as_a_replay_at_every_frame() {
    let intrinsics = camera().intrinsics;
    let mut inline = SceneOccupancy::new(&intrinsics);
    let mut worker = SceneOccupancy::with_worker(&intrinsics);
    for step in 0..40 {
        // The camera steps sideways 0.2 m every 8 frames: a keyframe each time.
        let eye = Vec3::new(0.2 * (step / 8) as f32 - 0.4, 1.2, 2.5);
        let camera = ViewCamera::looking_at(intrinsics, eye, Vec3::new(0.0, 0.6, 0.0));
        let points = wall_points(&camera);
        let pose = Some(camera.world_from_camera);
        assert_eq!(
            inline.observe(&points, pose, true),
            worker.observe(&points, pose, true)
        );
        let (a, b) = (inline.map(), worker.map());
        assert_eq!(a.num_keyframes(), b.num_keyframes(), "frame {step}");
        for x in -10..=10 {
            for z in -10..=10 {
                let p = Vec3::new(0.1 * x as f32, 0.5, 0.1 * z as f32);
                assert_eq!(a.is_free(p), b.is_free(p), "frame {step}, {p}");
            }
        }
    }
    assert_eq!(inline.map().num_keyframes(), 4, "keyframes due by frame 40");
}
