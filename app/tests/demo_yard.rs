//! The app's demo session on `test-data/demo_yard` (issue 20, the demo as a first impression and
//! Done-when 7): a tap on the lawn behind the box plants a Norway spruce of 12 years; replayed
//! headlessly it stands 3.5–6 m tall, its crown in view (the leader's tip just above the
//! frame at the shown frame), and the occluder the app builds from
//! the tracked points hides part of it (the box in front of its foot) while showing most of
//! it. The session replays to the committed tree hash and frame checksums (lavapipe);
//! `SYLVA_BLESS=1` re-records it from `demo_script::yard_session` and rewrites them.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test demo_yard -- --nocapture`

mod expected;

use std::path::PathBuf;

use sylva_app::demo_script::{YARD_TAP_FRAME, yard_session};
use sylva_app::footage::Footage;
use sylva_app::planting::{camera_in_tree, occluder_in_tree};
use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::{FrameView, Gpu, Offscreen, Renderer, TreeMesh};
use sylva_app::session::{Session, frame_occluders, replay};
use sylva_app::tree_model::mesh_of;

/// The frame the README's picture shows, and where the box is in front of the tree's foot.
const SHOWN_FRAME: usize = 120;

fn sessions_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions")
}

#[test]
fn the_demo_yard_session_plants_a_spruce_behind_the_box_with_its_crown_in_view_and_its_foot_hidden()
{
    let session_path = sessions_dir().join("demo_yard.session.json");
    let expected_path = sessions_dir().join("demo_yard.expected.json");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_yard");
    let footage = Footage::open(&root).expect("the demo sequence is in the repository");
    let bless = std::env::var_os("SYLVA_BLESS").is_some();
    if bless {
        let session = yard_session(&footage, PathBuf::from("../../../test-data/demo_yard"))
            .expect("demo script");
        session.save(&session_path).expect("write session");
    }
    let session = Session::load(&session_path).expect("committed session");

    let out = tempfile::tempdir().expect("temp dir");
    let mut shown = None;
    let mut planted_frame = None;
    let report = replay(&session_path, Some(out.path()), true, |step, state| {
        if planted_frame.is_none() && state.world_from_tree.is_some() {
            planted_frame = Some(step);
        }
        if step == SHOWN_FRAME {
            shown = Some((
                mesh_of(&state.tree),
                state.world_from_tree,
                state.tree.clone(),
            ));
        }
    })
    .expect("replay");
    let planted_frame = planted_frame.expect("the tap plants the tree");
    assert!(
        planted_frame >= YARD_TAP_FRAME,
        "planted by the tap at frame {YARD_TAP_FRAME}, not before ({planted_frame})"
    );
    let (tree_mesh, world_from_tree, tree) = shown.expect("the shown frame is replayed");
    let world_from_tree = world_from_tree.expect("planted by the shown frame");
    let (low, high) = tree_mesh.bounds().expect("a grown tree");
    let height_m = high.y - low.y;
    assert!(
        (3.5..=6.0).contains(&height_m),
        "a 12-year spruce stands 3.5-6 m tall, got {height_m:.2} m ({} internodes)",
        tree.skeleton.len()
    );

    // Drawn as the replay draws it: the tree alone, and behind the occluder of the tracked points.
    let gpu = Gpu::headless().expect("lavapipe");
    let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
    let [width, height] = session.frame_size;
    let target = Offscreen::new(&gpu.device, width, height);
    let tree_from_world = world_from_tree.inverse();
    let mut images = None;
    for (step, camera, occluder) in frame_occluders(&session, &footage) {
        if step > SHOWN_FRAME {
            break;
        }
        if step != SHOWN_FRAME {
            continue;
        }
        // The crown is in the picture: its middle well inside, its tip reported (the leader's
        // tip stands about 40 px above the frame at the shown frame).
        let in_picture = |y_m: f32| {
            let p = world_from_tree.transform_point3(glam::Vec3::new(0.0, y_m, 0.0));
            camera.pixel_from_world(p).expect("in front of the camera")
        };
        let (middle, tip) = (in_picture(0.5 * (low.y + high.y)), in_picture(high.y));
        println!("crown middle at pixel {middle}, tip at {tip}");
        assert!(
            middle.y > 0.0 && middle.y < footage.intrinsics.height as f32,
            "the crown's middle at pixel {middle} is out of the picture"
        );
        let mut view = FrameView::augmented(camera_in_tree(&camera, &tree_from_world), None);
        view.show_camera_image = false;
        let occluder = occluder_in_tree(&occluder, &tree_from_world);
        let mut draw = |tree: &TreeMesh, occlude: bool| {
            renderer.set_tree(&gpu, tree);
            view.occlude = occlude;
            renderer.set_occluder(&gpu, &occluder);
            target.render(&gpu, &mut renderer, &view).expect("render")
        };
        images = Some([
            draw(&TreeMesh::default(), false),
            draw(&tree_mesh, false),
            draw(&tree_mesh, true),
        ]);
    }
    let [empty, alone, behind] = images.expect("the shown frame has a pose");
    let differs = |a: &image::Rgba<u8>, b: &image::Rgba<u8>| {
        a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 8)
    };
    let (mut num_tree, mut num_hidden) = (0usize, 0usize);
    for ((e, a), b) in empty.pixels().zip(alone.pixels()).zip(behind.pixels()) {
        if differs(a, e) {
            num_tree += 1;
            num_hidden += usize::from(!differs(b, e));
        }
    }
    let hidden = num_hidden as f64 / num_tree.max(1) as f64;
    println!(
        "frame {SHOWN_FRAME}: spruce {height_m:.2} m tall, {num_tree} tree pixels, {:.1}% hidden by the tracked occluder; planted at frame {planted_frame}",
        100.0 * hidden
    );
    assert!(
        num_hidden >= 20 && hidden <= 0.25,
        "part of the tree hidden, most shown: {num_hidden} of {num_tree} pixels hidden"
    );

    expected::assert_replay_matches(&report, &expected_path, bless);
    println!("{}", report.summary_line());
}
