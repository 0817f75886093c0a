//! The Scale tab on the demo's own footage (issue 20, Done-when 1): the tracked frames of the
//! demo session (poses, ground plane and tracked points, as the window shows them) feed the
//! design's scale; the "Known length" and "Measure" buttons are driven by their labels, and the
//! taps land where a user would tap: the true ends of a length on the synthetic garden's ground
//! (`test-data/demo_garden`'s `scene.json`: the plane y = 0), projected through each frame's
//! true camera, never taken from the tracker's output.

#[allow(dead_code)] // the solids and the alignment are for other tests
mod garden_truth;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use glam::{DAffine3, DVec3, Vec2};
use sylva_app::footage::Footage;
use sylva_app::scale::ScaleTool;
use sylva_app::session::{Session, TimedEvent, frame_camera, replay};
use sylva_app::state::{DesignState, InputEvent, TouchPhase};
use sylva_app::ui::{UiState, sylva_ui};
use sylva_tracking::Camera;

struct App {
    ui: UiState,
    design: DesignState,
    session: Session,
    footage: Footage,
    /// Steps of the session shown so far.
    shown: usize,
}

fn session_path() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/sessions/demo_garden.session.json")
}

impl App {
    fn new() -> App {
        let session = Session::load(&session_path()).expect("the demo session");
        let footage = Footage::open(&garden_truth::root()).expect("test-data/demo_garden");
        App {
            ui: UiState {
                ground_found: true,
                planted: true,
                playing: false,
                ..UiState::default()
            },
            design: session.initial_design(),
            session,
            footage,
            shown: 0,
        }
    }

    /// Shows the session's recorded frames up to footage frame `index` (the tracking the window
    /// showed; none of the session's touches).
    fn show_up_to(&mut self, index: usize) {
        while self.shown < self.session.frames.len()
            && self.session.frames[self.shown].index <= index
        {
            let record = &self.session.frames[self.shown];
            let camera = frame_camera(record, &self.footage);
            self.design.observe_scene(
                &self.footage.intrinsics,
                camera.map(|c| c.world_from_camera),
                record.ground_plane(),
                &record.observations(),
            );
            self.design.scale.set_frame_index(record.index);
            self.design.advance_frame(camera, record.time_s, 1.0 / 30.0);
            self.shown += 1;
        }
    }
}

fn harness(app: App) -> Harness<'static, App> {
    let mut harness = Harness::new_ui_state(
        |ui, app: &mut App| {
            let mut events = Vec::new();
            sylva_ui(ui, &mut app.ui, &app.design, &mut events);
            for e in events {
                app.design.apply(&e);
            }
        },
        app,
    );
    harness.set_size(egui::vec2(1280.0, 800.0));
    harness.run();
    harness
}

/// The generator's camera and its true poses.
struct Truth {
    camera: Camera,
    world_from_camera: Vec<DAffine3>,
}

impl Truth {
    fn load() -> Truth {
        let k = Footage::open(&garden_truth::root())
            .expect("footage")
            .intrinsics;
        Truth {
            camera: Camera::pinhole(
                k.width,
                k.height,
                k.fx as f64,
                k.fy as f64,
                k.cx as f64,
                k.cy as f64,
            ),
            world_from_camera: garden_truth::true_poses(),
        }
    }

    /// Where `frame`'s true camera sees the ground point at (x, z): a tap on it.
    fn tap_at(&self, frame: usize, x: f64, z: f64) -> Vec2 {
        let in_camera = self.world_from_camera[frame]
            .inverse()
            .transform_point3(DVec3::new(x, 0.0, z));
        let pixel = self.camera.pixel_from_camera(in_camera).expect("in front");
        assert!(
            self.camera.contains(pixel, 20.0),
            "({x}, {z}) at {pixel} in frame {frame}"
        );
        pixel.as_vec2()
    }
}

/// A tap (touch down and up on the spot) at an image pixel.
fn tap_events(pixel: Vec2) -> [InputEvent; 2] {
    [TouchPhase::Start, TouchPhase::End].map(|phase| InputEvent::Touch {
        phase,
        id: 1,
        x: pixel.x,
        y: pixel.y,
    })
}

fn tap(h: &mut Harness<'static, App>, pixel: Vec2) {
    for e in tap_events(pixel) {
        h.state_mut().design.apply(&e);
    }
    h.run();
}

fn label_containing(h: &Harness<'static, App>, text: &str) -> String {
    // AccessKit keeps a label's text in its value.
    let node = h.get_by_label_contains(text);
    let node = node.accesskit_node();
    node.value().or_else(|| node.label()).expect("a label")
}

/// The metres in "Distance: 2.06 m ± 0.03 m".
fn distance_m(label: &str) -> f64 {
    label
        .strip_prefix("Distance: ")
        .and_then(|rest| rest.split(' ').next())
        .and_then(|m| m.parse().ok())
        .unwrap_or_else(|| panic!("no distance in {label:?}"))
}

#[test]
fn a_known_length_tapped_in_one_frame_sets_the_scale_and_the_measure_tool_reads_true_metres() {
    let truth = Truth::load();
    let mut app = App::new();
    app.show_up_to(120);
    let mut h = harness(app);
    h.get_by_label("Scale").click();
    h.run();
    let before = label_containing(&h, "Scale from");
    assert!(before.contains("camera's height"), "{before}");
    let mpu_before = h.state().design.scale.state.metres_per_unit();

    // A fence panel 1.5 m long on the ground, its ends tapped in frame 120.
    h.state_mut().ui.known_length_m = 1.5;
    h.get_by_label("Known length").click();
    h.run();
    assert_eq!(
        h.state().design.scale.tool,
        Some(ScaleTool::KnownLength { length_m: 1.5 })
    );
    tap(&mut h, truth.tap_at(120, -0.75, 0.5));
    tap(&mut h, truth.tap_at(120, 0.75, 0.5));
    let after = label_containing(&h, "Scale from");
    println!("before: {before} ({mpu_before:.4} m/unit)\nafter: {after}");
    assert!(
        after.contains("known length (1.5 m marked in frame 120)"),
        "{after}"
    );
    let mpu_after = h.state().design.scale.state.metres_per_unit();
    assert_ne!(
        mpu_before, mpu_after,
        "the known length left the scale as it was"
    );
    assert!(label_containing(&h, "Known length of").contains("1.50 m marked"));

    // Measure two ground points 2.06 m apart in frame 200.
    h.get_by_label("Measure").click();
    h.run();
    h.state_mut().show_up_to(200);
    h.run();
    let (a, b): ((f64, f64), (f64, f64)) = ((-0.5, -1.0), (0.5, 0.8));
    tap(&mut h, truth.tap_at(200, a.0, a.1));
    tap(&mut h, truth.tap_at(200, b.0, b.1));
    let label = label_containing(&h, "Distance:");
    let measured_m = distance_m(&label);
    let true_m = (a.0 - b.0).hypot(a.1 - b.1);
    println!("measured {label}, true {true_m:.3} m");
    assert!(
        (measured_m / true_m - 1.0).abs() < 0.03,
        "measured {measured_m:.3} m, true {true_m:.3} m"
    );
    // The tree was not touched by the tool's taps.
    assert!(!h.state().design.is_planted());
}

#[test]
fn the_camera_height_scales_the_world_and_an_impossible_height_is_refused() {
    let mut app = App::new();
    app.show_up_to(100);
    let held_at_1_5 = app.design.scale.state.metres_per_unit();
    app.design.apply(&InputEvent::HoldingHeight {
        holding_height_m: 1.2,
    });
    let held_at_1_2 = app.design.scale.state.metres_per_unit();
    assert!(
        (held_at_1_2 / held_at_1_5 - 0.8).abs() < 1e-9,
        "{held_at_1_5} then {held_at_1_2}"
    );
    app.design.apply(&InputEvent::HoldingHeight {
        holding_height_m: 40.0,
    });
    assert_eq!(app.design.scale.state.holding_height_m(), 1.2);
    let h = harness(app);
    let status = label_containing(&h, "Scale from");
    assert!(status.contains("held 1.2 m"), "{status}");
}

#[test]
fn a_session_replays_its_measure_taps_to_the_same_distance() {
    let truth = Truth::load();
    let mut session = Session::load(&session_path()).expect("the demo session");
    // The tool and two taps after frame 200 was shown, as the window records them.
    let step = session
        .frames
        .iter()
        .position(|f| f.index == 200)
        .expect("frame 200")
        + 1;
    let time_s = session.frames[step - 1].time_s;
    let mut measure = vec![InputEvent::ScaleTool {
        tool: Some(ScaleTool::Measure),
    }];
    measure.extend(tap_events(truth.tap_at(200, -0.5, -1.0)));
    measure.extend(tap_events(truth.tap_at(200, 0.5, 0.8)));
    // Before it, the known length marked after frame 120 was shown.
    let known_step = session
        .frames
        .iter()
        .position(|f| f.index == 120)
        .expect("frame 120")
        + 1;
    let known_time_s = session.frames[known_step - 1].time_s;
    let mut known = vec![InputEvent::ScaleTool {
        tool: Some(ScaleTool::KnownLength { length_m: 1.5 }),
    }];
    known.extend(tap_events(truth.tap_at(120, -0.75, 0.5)));
    known.extend(tap_events(truth.tap_at(120, 0.75, 0.5)));
    // None of the demo's own edits: the tree is not planted, only the scale matters.
    session.events.clear();
    let timed = |frame: usize, time_s: f64| {
        move |event| TimedEvent {
            frame,
            time_s,
            event,
        }
    };
    session
        .events
        .extend(known.into_iter().map(timed(known_step, known_time_s)));
    session
        .events
        .extend(measure.into_iter().map(timed(step, time_s)));
    session.frames.truncate(step + 1);
    let dir = std::env::temp_dir().join(format!("sylva-scale-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("measure.session.json");
    // The footage is found from the session's folder.
    session.footage = garden_truth::root();
    session.save(&path).expect("saved");
    let mut measured = Vec::new();
    for _ in 0..2 {
        let mut last = None;
        replay(&path, None, false, |_, state| {
            last = state.scale.measured.map(|m| m.distance_m)
        })
        .expect("replays");
        measured.push(last.expect("a distance measured in the replay"));
    }
    println!("replayed distances {measured:?}");
    assert_eq!(measured[0], measured[1]);
    let true_m = 1.0f64.hypot(1.8);
    assert!(
        (measured[0] / true_m - 1.0).abs() < 0.03,
        "replayed {:.3} m, true {true_m:.3} m",
        measured[0]
    );
    std::fs::remove_dir_all(&dir).ok();
}
