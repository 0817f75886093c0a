//! Screenshots of the app on a phone (issue 22, Done-when 6): the phone shell's entry points
//! ([`ShellApp`]: frames in, touches in, draw) driven with the demo footage and the platform
//! tracking an AR session would hand over (as `platform_shell.rs` does), the tree planted by a
//! tap on the ground and grown by a stroke, then drawn offscreen at a 6-inch phone's portrait
//! (1080 × 2340 pixels) and landscape (2340 × 1080) sizes at scale factor 3, the camera image
//! shown as the phone shell shows it (upright, cropped to fill the screen:
//! [`DisplayTransform::phone`]). Each screenshot matches its golden (`golden/phone_*.png`, the
//! README's pictures; tolerance in `golden_compare`, the frame-time line left out), the camera
//! image fills the screen edge to edge, and no panel of the UI covers the planted tree.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test phone_screenshots`

mod golden_compare;
mod phone_demo;

use glam::{Vec2, Vec3};
use image::RgbaImage;
use sylva_app::platform::{
    DisplayTransform, OffscreenSurface, ShellApp, StorageLocation, TouchInput, TrackerChoice,
};
use sylva_app::render::Gpu;
use sylva_app::render::resources::letterbox;
use sylva_app::state::TouchPhase;

/// Frames of the demo fed (the screenshots show the last, the planted tree still mid-screen).
const NUM_FRAMES: usize = 60;
const PORTRAIT_PX: (u32, u32) = (1080, 2340);
const LANDSCAPE_PX: (u32, u32) = (2340, 1080);
const PHONE_SCALE: f32 = 3.0;

/// The surface pixel where the sensor image's pixel `image_px` is shown.
fn surface_px(app: &ShellApp, display: DisplayTransform, size: (u32, u32), image_px: Vec2) -> Vec2 {
    let k = app.player().footage.intrinsics;
    let shown = display.shown_from_sensor_px(image_px, (k.width, k.height), size);
    let shown_k = display.shown_intrinsics(&k, size);
    let [x, y, w, h] = letterbox(size, &shown_k);
    Vec2::new(
        x + shown.x / shown_k.width as f32 * w,
        y + shown.y / shown_k.height as f32 * h,
    )
}

/// The planted tree's box on the surface, points.
fn tree_rect(app: &ShellApp, display: DisplayTransform, size: (u32, u32)) -> egui::Rect {
    let player = app.player();
    let camera = player.camera_in_tree().expect("the tree is seen");
    let points: Vec<egui::Pos2> = player
        .design
        .tree
        .skeleton
        .internodes
        .iter()
        .flat_map(|n| [n.start, n.end])
        .filter_map(|p| camera.pixel_from_world(p))
        .map(|p| {
            let s = surface_px(app, display, size, p) / PHONE_SCALE;
            egui::pos2(s.x, s.y)
        })
        .collect();
    egui::Rect::from_points(&points)
}

/// Draws the shown frame into a new surface of `size` and checks it against its golden.
fn screenshot(app: &mut ShellApp, gpu: &Gpu, size: (u32, u32), name: &str) -> RgbaImage {
    let mut surface = OffscreenSurface::new(gpu, size, PHONE_SCALE);
    // Twice: the first frame lays the UI out (egui sizes its panels from the previous frame).
    for _ in 0..2 {
        assert!(app.draw(gpu, &mut surface).expect("draw"), "drawn");
    }
    let shot = surface.read(gpu).expect("read back");
    assert_eq!(shot.dimensions(), size);
    let display = DisplayTransform::phone(0);
    let tree = tree_rect(app, display, size);
    let screen = egui::Rect::from_min_size(
        egui::Pos2::ZERO,
        egui::vec2(size.0 as f32, size.1 as f32) / PHONE_SCALE,
    );
    println!("{name}: tree {tree:?} on a {screen:?} screen");
    assert!(screen.contains_rect(tree), "{name}: the tree is in view");
    let panels = &app.player().ui.panel_rects;
    assert!(!panels.is_empty(), "{name}: the panels were recorded");
    for panel in panels {
        assert!(
            !panel.intersects(tree),
            "{name}: a panel {panel:?} covers the tree {tree:?}"
        );
    }
    // The camera image fills the screen: no black bar along any edge.
    let black_rows = |rows: &mut dyn Iterator<Item = u32>, horizontal: bool| {
        rows.take_while(|&i| {
            let line: Vec<_> = if horizontal {
                (0..size.0).map(|x| shot.get_pixel(x, i)).collect()
            } else {
                (0..size.1).map(|y| shot.get_pixel(i, y)).collect()
            };
            line.iter().all(|p| p.0[0] < 8 && p.0[1] < 8 && p.0[2] < 8)
        })
        .count()
    };
    for (what, bars) in [
        ("top", black_rows(&mut (0..size.1), true)),
        ("bottom", black_rows(&mut (0..size.1).rev(), true)),
        ("left", black_rows(&mut (0..size.0), false)),
        ("right", black_rows(&mut (0..size.0).rev(), false)),
    ] {
        assert_eq!(
            bars, 0,
            "{name}: {bars} black lines at the {what}: letterboxed"
        );
    }
    // The frame-time line along the bottom of the view shows wall-clock figures: left out of
    // the comparison (the view ends where the lowest wide panel starts).
    let view_bottom = panels
        .iter()
        .filter(|p| p.top() > 0.5 * screen.height() && p.width() > 0.5 * screen.width())
        .map(|p| p.top())
        .fold(screen.bottom(), f32::min);
    let line_px = (40.0 * PHONE_SCALE) as u32;
    let bottom_px = (view_bottom * PHONE_SCALE) as u32;
    let timings = [0, bottom_px.saturating_sub(line_px), size.0, line_px];
    golden_compare::assert_matches_golden_except(name, &shot, &[timings]);
    shot
}

#[test]
fn a_phone_shows_the_planted_tree_over_the_camera_filling_portrait_and_landscape_screens() {
    let (intrinsics, frames) = phone_demo::demo_frames(true, NUM_FRAMES);
    let dir = tempfile::tempdir().expect("tempdir");
    let storage = StorageLocation::new(dir.path());
    let mut app = ShellApp::start(
        &storage,
        intrinsics,
        30.0,
        TrackerChoice::Platform,
        "demo camera",
    )
    .expect("starts");
    let display = DisplayTransform::phone(0);
    app.set_display(display);
    let gpu = Gpu::headless().expect("a GPU (lavapipe: mesa-vulkan-drivers, WGPU_BACKEND=vulkan)");
    let mut surface = OffscreenSurface::new(&gpu, PORTRAIT_PX, PHONE_SCALE);
    let (mut first_ground, mut finger) = (None, Vec2::ZERO);
    for (shown, frame) in frames.into_iter().enumerate() {
        assert!(app.frame(frame).expect("frame in"), "frame {shown} shown");
        if app.player().ground().is_some() && first_ground.is_none() {
            first_ground = Some(shown);
        }
        let touch = |app: &mut ShellApp, phase, image_px: Vec2| {
            let p = surface_px(app, display, PORTRAIT_PX, image_px);
            app.touch(TouchInput {
                phase,
                id: 0,
                x_px: p.x,
                y_px: p.y,
            });
        };
        let num_events = app.player().session.events.len();
        let touched = match first_ground.map(|g| shown - g) {
            // A tap on the ground plants the tree there: below the world origin's place in the
            // middle of the screen, clear of the controls docked along the bottom.
            Some(3) => {
                let origin = app
                    .player()
                    .camera()
                    .and_then(|c| c.pixel_from_world(Vec3::ZERO))
                    .expect("the origin is in view");
                let k = app.player().footage.intrinsics;
                let sensor = (k.width, k.height);
                let on_screen = surface_px(&app, display, PORTRAIT_PX, origin);
                let tap = Vec2::new(
                    0.5 * PORTRAIT_PX.0 as f32,
                    on_screen.y.min(0.6 * PORTRAIT_PX.1 as f32),
                );
                let shown_k = display.shown_intrinsics(&k, PORTRAIT_PX);
                let shown = tap
                    * Vec2::new(
                        shown_k.width as f32 / PORTRAIT_PX.0 as f32,
                        shown_k.height as f32 / PORTRAIT_PX.1 as f32,
                    );
                let at = display.sensor_from_shown_px(shown, sensor, PORTRAIT_PX);
                touch(&mut app, TouchPhase::Start, at);
                touch(&mut app, TouchPhase::End, at);
                true
            }
            Some(6) => {
                finger = phone_demo::top_pixel(&app).expect("the planted tree is in view");
                touch(&mut app, TouchPhase::Start, finger);
                true
            }
            Some(7..36) => {
                finger += Vec2::new(0.5, -3.0);
                touch(&mut app, TouchPhase::Move, finger);
                shown % 3 == 0
            }
            Some(36) => {
                touch(&mut app, TouchPhase::End, finger);
                true
            }
            _ => false,
        };
        // Drawn now and then (the software renderer is slow at this size), and the frames
        // before the tap too: the UI lays out in a frame before it takes a touch.
        let before_tap = matches!(first_ground.map(|g| shown - g), Some(0..3));
        if touched || before_tap || shown % 20 == 0 {
            assert!(app.draw(&gpu, &mut surface).expect("draw"), "drawn");
        }
        if touched {
            assert!(
                app.player().session.events.len() > num_events,
                "the touch at frame {shown} reached the design through the UI"
            );
        }
    }
    let first_ground = first_ground.expect("the ground is found");
    assert!(
        first_ground + 40 < NUM_FRAMES,
        "ground found at frame {first_ground}"
    );
    assert!(app.player().design.is_planted(), "the tap planted the tree");
    println!(
        "ground at frame {first_ground}; the tree has {} internodes",
        app.player().design.tree.skeleton.len()
    );
    screenshot(&mut app, &gpu, PORTRAIT_PX, "phone_portrait");
    screenshot(&mut app, &gpu, LANDSCAPE_PX, "phone_landscape");
}
