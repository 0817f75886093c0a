//! The phone shells' entry points ([`ShellApp`]: frame in, touch in, draw, pause/resume,
//! autosave) driven on the host with the bundled demo footage, as a phone would drive them:
//!
//! - through the platform-tracker path, with the poses and feature points an AR session would
//!   hand over: the sequence's recorded tracking from Sylva's own tracker (run once here on
//!   the images, no ground truth), its ground plane as the platform's plane;
//! - through the own-tracker path, with the camera images only.
//!
//! Each records a session into app storage that `sylva replay` replays to the same tree and
//! the same frames; and both paths design the same tree from the same footage and touches.

mod phone_demo;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use image::RgbaImage;
use phone_demo::{demo_frames, top_pixel};
use sylva_app::platform::{
    DrawSurface, OffscreenSurface, ShellApp, StorageLocation, TouchInput, TrackerChoice,
};
use sylva_app::render::offscreen::Offscreen;
use sylva_app::render::resources::letterbox;
use sylva_app::render::{FrameView, Gpu, Renderer};
use sylva_app::state::TouchPhase;

/// Frames of the demo used (of 240).
const NUM_FRAMES: usize = 240;
/// A 6-inch phone's screen held upright, then turned on its side: 360 x 780 points, at half
/// the pixels of a 1080 x 2340 phone (scale 1.5 instead of 3) to keep the software renderer
/// quick; the UI lays out the same.
const PORTRAIT_PX: (u32, u32) = (540, 1170);
const LANDSCAPE_PX: (u32, u32) = (1170, 540);
const PHONE_SCALE: f32 = 1.5;
/// The shell draws every this many frames, and every frame with touches to apply (a phone
/// draws every frame; the software renderer here is slow).
const DRAW_EVERY_FRAMES: usize = 10;
/// The app goes to the background after this many frames shown, and comes back rotated.
const PAUSE_AT_FRAME: usize = 150;
/// Camera frames that arrive while the app is in the background (dropped).
const FRAMES_WHILE_PAUSED: usize = 4;

/// The surface pixel of a camera-image pixel (the image is letterboxed into the surface).
fn surface_px(app: &ShellApp, surface: &dyn DrawSurface, image_px: Vec2) -> Vec2 {
    let k = app.player().footage.intrinsics;
    let [x, y, w, h] = letterbox(surface.size_px(), &k);
    Vec2::new(
        x + image_px.x / k.width as f32 * w,
        y + image_px.y / k.height as f32 * h,
    )
}

/// The AR view of the shown frame as `sylva replay` renders it (session frame size, no UI).
fn render_ar_view(app: &ShellApp, gpu: &Gpu, renderer: &mut Renderer) -> Option<RgbaImage> {
    let player = app.player();
    let camera = player.camera_in_tree()?;
    let design = &player.design;
    let mut mesher = sylva_app::tree_model::TreeMesher::default();
    match design.is_planted() {
        true => renderer.set_tree(gpu, mesher.mesh_in(&design.tree, design.params.season)),
        false => renderer.set_tree(gpu, &Default::default()),
    }
    let image = player.image.as_ref()?;
    renderer.set_camera_image(gpu, image.as_raw(), player.footage.intrinsics);
    let occluder =
        sylva_app::planting::occluder_in_tree(&player.scene()?.occluder, &design.tree_from_world());
    renderer.set_occluder(gpu, &occluder);
    let [width, height] = player.session.frame_size;
    let target = Offscreen::new(&gpu.device, width, height);
    let view = FrameView::augmented(camera, player.ground_in_tree());
    Some(target.render(gpu, renderer, &view).expect("render"))
}

/// What a shell run produced.
struct ShellRun {
    tree_sha256: String,
    session: PathBuf,
    num_shown: usize,
    /// Shown-frame index and its AR view, for comparison with the replay's frames.
    views: Vec<(usize, RgbaImage)>,
}

/// Drives the shell's entry points over `frames` as a phone does: each frame in, then a draw
/// with the touches since the last one; the user plants the tree on the ground and paints a
/// stroke up from its top; halfway the app goes to the background, frames arrive and are
/// dropped, and it comes back rotated to landscape; the tree autosaves all along.
fn drive_shell(storage: &Path, choice: TrackerChoice) -> ShellRun {
    let (intrinsics, frames) = demo_frames(choice == TrackerChoice::Platform, NUM_FRAMES);
    let storage = StorageLocation::new(storage);
    let mut app =
        ShellApp::start(&storage, intrinsics, 30.0, choice, "demo camera").expect("starts");
    let gpu = Gpu::headless().expect("a GPU (lavapipe: mesa-vulkan-drivers, WGPU_BACKEND=vulkan)");
    let mut surface = OffscreenSurface::new(&gpu, PORTRAIT_PX, PHONE_SCALE);
    let mut renderer = Renderer::new(&gpu, sylva_app::render::offscreen::OFFSCREEN_FORMAT);
    let seedling = app.player().design.tree.skeleton.len();
    let clock = Instant::now();
    let (mut shown, mut first_ground, mut finger) = (0, None, Vec2::ZERO);
    let mut views = Vec::new();
    let mut autosaves = 0;
    let mut frames = frames.into_iter();
    while let Some(frame) = frames.next() {
        let time_s = frame.time_s;
        assert!(app.frame(frame).expect("frame in"), "frame {shown} shown");
        assert_eq!(app.player().frame, shown, "frames are shown once, in order");
        if app.player().ground().is_some() && first_ground.is_none() {
            first_ground = Some(shown);
        }
        if shown % 40 == 0
            && let Some(view) = render_ar_view(&app, &gpu, &mut renderer)
        {
            views.push((shown, view));
        }
        let touch = |app: &mut ShellApp, surface: &OffscreenSurface, phase, image_px: Vec2| {
            let p = surface_px(app, surface, image_px);
            app.touch(TouchInput {
                phase,
                id: 0,
                x_px: p.x,
                y_px: p.y,
            });
        };
        let num_events = app.player().session.events.len();
        let mut touched = true;
        match first_ground.map(|g| shown - g) {
            // A tap on the ground at the world origin plants the tree there.
            Some(5) => {
                let origin = app
                    .player()
                    .camera()
                    .and_then(|c| c.pixel_from_world(Vec3::ZERO))
                    .expect("the origin is in view");
                touch(&mut app, &surface, TouchPhase::Start, origin);
                touch(&mut app, &surface, TouchPhase::End, origin);
            }
            Some(10) => {
                finger = top_pixel(&app).expect("the planted tree is in view");
                touch(&mut app, &surface, TouchPhase::Start, finger);
            }
            Some(11..50) => {
                finger += Vec2::new(1.0, -4.0);
                touch(&mut app, &surface, TouchPhase::Move, finger);
            }
            Some(50) => touch(&mut app, &surface, TouchPhase::End, finger),
            _ => touched = false,
        }
        if touched || shown % DRAW_EVERY_FRAMES == 0 {
            assert!(app.draw(&gpu, &mut surface).expect("draw"), "drawn");
        }
        if touched {
            assert!(
                app.player().session.events.len() > num_events,
                "the touch at frame {shown} reached the design through the UI"
            );
        }
        let now = clock + Duration::from_secs_f64(time_s);
        autosaves += usize::from(app.poll_autosave(now).expect("autosave"));
        shown += 1;
        if shown == PAUSE_AT_FRAME {
            app.pause().expect("pause saves the tree");
            let saved = sylva_core::Tree::load(app.autosave_path()).expect("the autosaved tree");
            assert_eq!(
                saved.to_json_bytes().expect("json"),
                app.player().design.tree.to_json_bytes().expect("json"),
                "pausing saves the tree as it is"
            );
            let saved = sylva_app::session::Session::load(&app.session_dir().join("session.json"))
                .expect("pausing writes the session so far");
            assert_eq!(saved.frames.len(), PAUSE_AT_FRAME);
            let before = app.player().design.tree_sha256();
            // The window is destroyed; camera frames that still come are dropped.
            drop(surface);
            for frame in frames.by_ref().take(FRAMES_WHILE_PAUSED) {
                assert!(!app.frame(frame).expect("frame while paused"), "dropped");
            }
            app.resume();
            surface = OffscreenSurface::new(&gpu, LANDSCAPE_PX, PHONE_SCALE);
            assert_eq!(
                app.player().design.tree_sha256(),
                before,
                "the design survives"
            );
        }
    }
    let first_ground = first_ground.expect("the ground is found");
    assert!(
        first_ground < 120,
        "ground found only at frame {first_ground}"
    );
    assert!(app.player().design.is_planted(), "the tap planted the tree");
    let grown = app.player().design.tree.skeleton.len();
    assert!(
        grown > seedling,
        "the stroke grew the tree ({seedling} -> {grown} internodes)"
    );
    assert!(autosaves >= 1, "the tree autosaved while it changed");
    let last = surface.read(&gpu).expect("the last frame reads back");
    assert_eq!(last.dimensions(), LANDSCAPE_PX);
    let tree_sha256 = app.player().design.tree_sha256();
    println!(
        "{choice:?}: {shown} frames shown, ground at {first_ground}, {seedling} -> {grown} internodes, {autosaves} autosaves, tree_sha256={tree_sha256}"
    );
    let session = app.finish().expect("the session is written");
    ShellRun {
        tree_sha256,
        session,
        num_shown: shown,
        views,
    }
}

/// `sylva replay SESSION --out DIR`: its tree_sha256 and number of frames.
fn sylva_replay(session: &Path, out: &Path) -> (String, usize) {
    let output = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .arg("replay")
        .arg(session)
        .arg("--out")
        .arg(out)
        .env("WGPU_BACKEND", "vulkan")
        .output()
        .expect("run sylva replay");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "sylva replay failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let field = |key: &str| {
        stdout
            .split_whitespace()
            .find_map(|w| w.strip_prefix(key))
            .unwrap_or_else(|| panic!("no {key} in {stdout}"))
            .to_owned()
    };
    let frames = field("frames=").parse().expect("frame count");
    (field("tree_sha256="), frames)
}

/// Replays the run's session with `sylva replay` and checks the tree and the frames.
fn check_replay(run: &ShellRun, out: &Path) {
    let (tree_sha256, num_frames) = sylva_replay(&run.session, out);
    assert_eq!(
        num_frames, run.num_shown,
        "every shown frame is in the session"
    );
    assert_eq!(
        tree_sha256, run.tree_sha256,
        "the replay grows the same tree"
    );
    assert!(run.views.len() >= 4, "{} views compared", run.views.len());
    for (step, view) in &run.views {
        let path = out.join(format!("frame_{step:04}.png"));
        let replayed = image::open(&path).expect("replayed frame").to_rgba8();
        assert!(
            replayed == *view,
            "frame {step} replays differently from what the shell showed ({})",
            path.display()
        );
    }
}

#[test]
fn the_platform_tracker_path_records_a_session_that_sylva_replay_replays_to_the_same_tree_and_frames()
 {
    let dir = tempfile::tempdir().expect("temp dir");
    let run = drive_shell(&dir.path().join("files"), TrackerChoice::Platform);
    assert_eq!(
        run.session,
        dir.path().join("files/session-000/session.json")
    );
    check_replay(&run, &dir.path().join("replay"));
}

#[test]
fn the_own_tracker_path_on_images_only_records_the_frames_the_platform_path_would_and_replays() {
    let dir = tempfile::tempdir().expect("temp dir");
    let own = drive_shell(&dir.path().join("own"), TrackerChoice::Own);
    check_replay(&own, &dir.path().join("replay"));
    // The platform path fed the same tracker's output makes the same scene at every frame
    // before the pause (after it the own tracker missed the frames dropped while paused).
    let recorded = sylva_app::session::Session::load(&own.session)
        .expect("session")
        .frames;
    let (intrinsics, frames) = demo_frames(true, NUM_FRAMES);
    let (mut stream, feed) = sylva_app::platform::PlatformStream::new(
        intrinsics,
        30.0,
        TrackerChoice::Platform,
        "recorded poses",
    )
    .expect("stream");
    for (step, frame) in frames.into_iter().take(PAUSE_AT_FRAME).enumerate() {
        feed.push(frame);
        let Ok(sylva_app::live::LiveNext::Frame(shown)) =
            sylva_app::live::LiveStream::next(&mut stream, true)
        else {
            panic!("frame {step} tracked");
        };
        let record = &recorded[step];
        assert_eq!(
            record.world_from_camera,
            shown.scene.world_from_camera.map(|m| m.to_cols_array()),
            "pose of frame {step}"
        );
        assert_eq!(
            record.ground_plane(),
            shown.scene.ground,
            "ground at frame {step}"
        );
        assert!(
            record.observations() == shown.scene.observations,
            "tracked points of frame {step}"
        );
    }
}

/// The platform's frames must come with its tracking; one that does not is refused by name.
#[test]
fn a_platform_frame_without_tracking_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (intrinsics, mut frames) = demo_frames(false, NUM_FRAMES);
    let mut app = ShellApp::start(
        &StorageLocation::new(dir.path()),
        intrinsics,
        30.0,
        TrackerChoice::Platform,
        "ARCore camera",
    )
    .expect("starts");
    let frame = frames.swap_remove(0);
    let error = app.frame(frame).expect_err("refused");
    assert!(
        format!("{error:#}")
            .contains("ARCore camera: frame 0 came without the platform's tracking"),
        "{error:#}"
    );
}
