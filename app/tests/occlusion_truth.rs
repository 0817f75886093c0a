//! Issue 20, Done-when 3, measured: a tree planted by a tap behind the box of the bundled
//! synthetic garden, replayed through the app's path, drawn by the app's renderer with the
//! occluder the app builds from tracked points, against the same tree drawn with the
//! generator's true box and wall as the occluder (placed in the tracked world by the Sim(3)
//! alignment of the camera frames). On the tree's pixels (the tree drawn without occlusion) the
//! composited frame is right where both agree on hidden or shown. Printed per frame; the test
//! asserts the bounds that hold (below). A second report gives the cause measured: the tracked
//! points on the box per frame and the occluder's depth over the box's pixels.
//!
//! `SYLVA_OCCLUSION_DIR=DIR` keeps the three drawings of each frame (tree alone, behind the true
//! solids, behind the app's occluder).
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test occlusion_truth -- --nocapture`

mod garden_truth;

use std::path::Path;

use garden_truth::{root, true_blocks, true_poses, truth_from_tracked};
use glam::Vec3;
use sylva_app::demo_script::{scripted_session, tap};
use sylva_app::footage::Footage;
use sylva_app::planting::{camera_in_tree, occluder_in_tree};
use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::{FrameView, Gpu, OccluderMesh, Offscreen, Renderer, TreeMesh, ViewCamera};
use sylva_app::scene_tracking::SceneMesher;
use sylva_app::session::{Session, frame_camera, frame_occluders, replay};
use sylva_app::state::{InputEvent, Parameters};
use sylva_app::tree_model::mesh_of;
use sylva_core::species::Species;

/// Behind the box as the second half of the walk sees it (true world).
const PLANT_AT: Vec3 = Vec3::new(1.15, 0.0, -0.8);
const TAP_FRAME: usize = 20;
const GROW_FRAMES: [usize; 8] = [40, 60, 80, 100, 120, 140, 160, 180];
const EVAL_FRAMES: std::ops::RangeInclusive<usize> = 120..=235;
/// What holds with the solids on the ground (measured 2026-12-01: 93.8% of 245 465 tree pixels
/// right, 93.8% where the true solids cover, 99.4% of the 25 802 behind them hidden; 92.9%,
/// 92.9% and 99.1% on 2026-12-02 with the species' leaf cards drawn, a fuller crown; 93.4%,
/// 93.4% and 98.3% once the solids are carved by the free rays of the tracked points; 93.7%,
/// 93.7% and 98.2% of 215 825 tree pixels after merging). Since the solids are shaped by the
/// usable points only (tracks whose positions spread, sliding along a silhouette, still link a
/// group but no longer stretch the wall's solid up to 60 cm in front of it): 96.0%, 96.0% and
/// 95.8% of the 27 084 behind the true box or wall hidden. Issue 20 asks 95% right: met. What
/// is left: the box's right half has no tracked point, so its solid reaches there through a
/// track triangulated off its silhouette (15 cm out), and the tracked wall stands about 10 cm
/// in front of the true wall (its points do).
const MIN_RIGHT: f64 = 0.955;
const MIN_COVERED_RIGHT: f64 = 0.955;
const MIN_HIDDEN_RIGHT: f64 = 0.95;

/// The generator's solids as closed triangle meshes, in the tracked world.
fn true_occluder(tracked_from_truth: impl Fn(Vec3) -> Vec3) -> OccluderMesh {
    let mut mesh = OccluderMesh::default();
    for (_, min, max) in true_blocks() {
        mesh.add_box(min, max);
    }
    for p in &mut mesh.positions {
        *p = tracked_from_truth(*p);
    }
    mesh
}

fn differs(a: &image::RgbaImage, b: &image::RgbaImage) -> Vec<bool> {
    a.pixels()
        .zip(b.pixels())
        .map(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 8))
        .collect()
}

#[test]
fn the_tracked_occluder_hides_a_tree_planted_behind_the_box_where_the_true_box_does() {
    let footage = Footage::open(&root()).expect("demo footage");
    let truth = true_poses();
    let species = Species::by_name("norway_spruce").expect("preset");
    let session = scripted_session(&footage, root(), Parameters::default(), |step, _state| {
        let mut events = Vec::new();
        if step == TAP_FRAME + 1 {
            let camera = ViewCamera::new(
                footage.intrinsics,
                glam::DMat4::from(truth[TAP_FRAME]).as_mat4(),
            );
            events.extend(tap(camera.pixel_from_world(PLANT_AT).expect("in view")));
        } else if step == TAP_FRAME + 2 {
            events.push(InputEvent::Parameters {
                parameters: Parameters::for_species(&species),
            });
        } else if GROW_FRAMES.contains(&step) {
            events.push(InputEvent::Grow { iterations: 1 });
        }
        events
    })
    .expect("scripted session");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("behind_the_box.session.json");
    session.save(&path).expect("save");
    let session = Session::load(&path).expect("load");

    let (truth_from_tracked, _) = truth_from_tracked(&session);
    let tracked_from_truth = |p: Vec3| {
        let q = p.as_dvec3() - truth_from_tracked.translation;
        (truth_from_tracked.rotation.inverse() * q / truth_from_tracked.scale).as_vec3()
    };

    // The tree as shown at each evaluated frame, replayed through the app's path.
    let mut shown: Vec<(usize, TreeMesh, glam::Affine3A)> = Vec::new();
    replay(&path, None, false, |step, state| {
        if EVAL_FRAMES.contains(&step)
            && step % 5 == 0
            && let Some(world_from_tree) = state.world_from_tree
        {
            shown.push((step, mesh_of(&state.tree), world_from_tree));
        }
    })
    .expect("replay");

    let gpu = Gpu::headless().expect("lavapipe");
    let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
    let [width, height] = session.frame_size;
    let target = Offscreen::new(&gpu.device, width, height);
    let truth_mesh = true_occluder(tracked_from_truth);
    let (mut num_right, mut num_tree, mut num_hidden, mut num_hidden_right) = (0, 0, 0, 0);
    let (mut num_covered, mut num_covered_right) = (0, 0);
    // The occluder as the replay builds it: every frame's observations, in order.
    for (step, camera, occluder) in frame_occluders(&session, &footage) {
        let Some((_, tree, world_from_tree)) = shown.iter().find(|s| s.0 == step) else {
            continue;
        };
        let world_camera = camera;
        let tree_from_world = world_from_tree.inverse();
        let camera = camera_in_tree(&camera, &tree_from_world);
        let mut view = FrameView::augmented(camera, None);
        view.show_camera_image = false;
        let mut draw = |tree: &TreeMesh, occluder: Option<&OccluderMesh>| {
            renderer.set_tree(&gpu, tree);
            view.occlude = occluder.is_some();
            renderer.set_occluder(
                &gpu,
                &occluder_in_tree(
                    occluder.unwrap_or(&OccluderMesh::default()),
                    &tree_from_world,
                ),
            );
            target.render(&gpu, &mut renderer, &view).expect("render")
        };
        let empty = draw(&TreeMesh::default(), None);
        let images = [
            draw(tree, None),
            draw(tree, Some(&truth_mesh)),
            draw(tree, Some(&occluder)),
        ];
        if let Some(dir) = std::env::var_os("SYLVA_OCCLUSION_DIR") {
            for (name, image) in ["tree", "true", "app"].iter().zip(&images) {
                let path = Path::new(&dir).join(format!("frame_{step:04}_{name}.png"));
                image.save(&path).expect("write image");
            }
        }
        let tree_px = differs(&images[0], &empty);
        let true_px = differs(&images[1], &empty);
        let app_px = differs(&images[2], &empty);
        if let Some(dir) = std::env::var_os("SYLVA_OCCLUSION_DIR") {
            // Green: right where the true solids hide or show the tree; red: hidden by the
            // app's occluder only; blue: shown by it only.
            let errors = image::RgbaImage::from_fn(width, height, |x, y| {
                let i = (y * width + x) as usize;
                image::Rgba(match (tree_px[i], true_px[i], app_px[i]) {
                    (false, ..) => [0, 0, 0, 255],
                    (true, a, b) if a == b => [0, 140, 0, 255],
                    (true, true, false) => [255, 0, 0, 255],
                    (true, ..) => [0, 80, 255, 255],
                })
            });
            let path = Path::new(&dir).join(format!("frame_{step:04}_errors.png"));
            errors.save(&path).expect("write image");
        }
        let pixel_camera = world_camera.intrinsics.scaled_to(width, height);
        let (mut right, mut n, mut hidden, mut hidden_right) = (0, 0, 0, 0);
        for i in 0..tree_px.len() {
            if !tree_px[i] {
                continue;
            }
            n += 1;
            right += usize::from(true_px[i] == app_px[i]);
            // Where the true box or wall lies along the pixel's ray, in front or behind.
            let pixel = glam::Vec2::new((i as u32 % width) as f32, (i as u32 / width) as f32);
            let dir = world_camera
                .world_from_camera
                .transform_vector3(pixel_camera.ray_from_pixel(pixel))
                .normalize();
            if nearest_hit(&truth_mesh, world_camera.position(), dir).is_some() {
                num_covered += 1;
                num_covered_right += usize::from(true_px[i] == app_px[i]);
            }
            if !true_px[i] {
                hidden += 1;
                hidden_right += usize::from(!app_px[i]);
            }
        }
        println!(
            "frame {step}: {n} tree pixels, {:.1}% right; {hidden} behind the true box or wall, {:.1}% of them hidden",
            100.0 * right as f64 / n.max(1) as f64,
            100.0 * hidden_right as f64 / hidden.max(1) as f64
        );
        (num_right, num_tree) = (num_right + right, num_tree + n);
        (num_hidden, num_hidden_right) = (num_hidden + hidden, num_hidden_right + hidden_right);
    }
    let right = num_right as f64 / num_tree.max(1) as f64;
    let hidden_right = num_hidden_right as f64 / num_hidden.max(1) as f64;
    println!(
        "all evaluated frames: {num_tree} tree pixels, {:.1}% right; {num_hidden} behind the true box or wall, {:.1}% of them hidden",
        100.0 * right,
        100.0 * hidden_right
    );
    let covered_right = num_covered_right as f64 / num_covered.max(1) as f64;
    println!(
        "tree pixels where the true box or wall lies along the ray: {num_covered}, {:.1}% right",
        100.0 * covered_right
    );
    assert!(num_hidden > 0, "the tree must stand partly behind the box");
    // Issue 20 asks 95% where the occluder covers; what the tracked points give is asserted
    // (see the report above and the README's occlusion paragraph).
    assert!(
        right >= MIN_RIGHT
            && covered_right >= MIN_COVERED_RIGHT
            && hidden_right >= MIN_HIDDEN_RIGHT,
        "composited frames right on {:.1}% of the tree's pixels (at least {:.0}% asked), {:.1}% where the true solids cover (at least {:.0}%), {:.1}% of those behind them hidden (at least {:.0}%)",
        100.0 * right,
        100.0 * MIN_RIGHT,
        100.0 * covered_right,
        100.0 * MIN_COVERED_RIGHT,
        100.0 * hidden_right,
        100.0 * MIN_HIDDEN_RIGHT
    );
}

/// Distance along a unit ray to a triangle (Möller–Trumbore), if hit in front.
fn ray_triangle(origin: Vec3, dir: Vec3, [a, b, c]: [Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-4).then_some(t)
}

/// Distance to the nearest triangle of `mesh` along a unit ray.
fn nearest_hit(mesh: &OccluderMesh, origin: Vec3, dir: Vec3) -> Option<f32> {
    mesh.indices
        .chunks_exact(3)
        .filter_map(|t| {
            let corner = |i: u32| mesh.positions[i as usize];
            ray_triangle(origin, dir, [corner(t[0]), corner(t[1]), corner(t[2])])
        })
        .min_by(f32::total_cmp)
}

/// The cause, measured on the demo session: how many tracked points lie on the true box in a
/// frame (within 3 cm of its surface, in the generator's world), and over the box's pixels
/// (every 4th pixel of each 4th row), whether the app's occluder has no surface there, one
/// farther than the box (by more than 5%), nearer, or at the box's depth. A report.
#[test]
fn report_the_tracked_points_on_the_box_and_the_occluder_depth_over_it() {
    let footage = Footage::open(&root()).expect("demo footage");
    let session_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/sessions/demo_garden.session.json");
    let session = Session::load(&session_path).expect("demo session");
    let (truth_from_tracked, _) = truth_from_tracked(&session);
    let truth_of = |p: Vec3| {
        (truth_from_tracked.rotation * (p.as_dvec3() * truth_from_tracked.scale)
            + truth_from_tracked.translation)
            .as_vec3()
    };
    let tracked_from_truth = |p: Vec3| {
        let q = p.as_dvec3() - truth_from_tracked.translation;
        (truth_from_tracked.rotation.inverse() * q / truth_from_tracked.scale).as_vec3()
    };
    let (_, box_min, box_max) = true_blocks()
        .into_iter()
        .find(|b| b.0 == "box")
        .expect("the garden has a box");
    // Above the (flat) ground only: the generator's box reaches below it.
    let mut box_mesh = OccluderMesh::default();
    box_mesh.add_box(box_min.with_y(0.0), box_max);
    for p in &mut box_mesh.positions {
        *p = tracked_from_truth(*p);
    }
    let k = footage.intrinsics;
    let mut mesher = SceneMesher::new(&k);
    for (step, record) in session.frames.iter().enumerate() {
        let Some(camera) = frame_camera(record, &footage) else {
            continue;
        };
        let observations = record.observations();
        let occluder = mesher.update(
            &observations,
            camera.world_from_camera,
            record.ground_plane(),
        );
        if step % 20 != 0 {
            continue;
        }
        let num_on_box = observations
            .iter()
            .filter(|o| {
                let point = camera
                    .world_from_camera
                    .transform_point3(k.ray_from_pixel(o.pixel) * o.depth_m);
                let outside =
                    (truth_of(point) - (box_min + box_max) * 0.5).abs() - (box_max - box_min) * 0.5;
                outside.max_element().abs() < 0.03
            })
            .count();
        let eye = camera.position();
        let (mut num_box, mut hole, mut farther, mut nearer) = (0, 0, 0, 0);
        for v in (0..k.height).step_by(4) {
            for u in (0..k.width).step_by(4) {
                let ray = k.ray_from_pixel(glam::Vec2::new(u as f32, v as f32));
                let dir = camera.world_from_camera.transform_vector3(ray).normalize();
                let Some(t_box) = nearest_hit(&box_mesh, eye, dir) else {
                    continue;
                };
                num_box += 1;
                match nearest_hit(&occluder, eye, dir) {
                    None => hole += 1,
                    Some(t) if t > t_box * 1.05 => farther += 1,
                    Some(t) if t < t_box * 0.95 => nearer += 1,
                    Some(_) => {}
                }
            }
        }
        let percent = |n: usize| 100.0 * n as f64 / num_box.max(1) as f64;
        println!(
            "frame {step}: {} tracked points, {num_on_box} on the box; over the box: no occluder {:.0}%, farther {:.0}%, nearer {:.0}%, right {:.0}%",
            observations.len(),
            percent(hole),
            percent(farther),
            percent(nearer),
            percent(num_box - hole - farther - nearer),
        );
    }
}
