//! The streaming path of `sylva view` (a live camera or a video file): frames arrive one by one,
//! are tracked in order and shown as they come, and `--record DIR` writes them as a TUM folder
//! with the session, which re-opens and replays like recorded footage. This machine has no
//! camera, so the stream is a video file written from the bundled demo sequence with OpenCV's
//! VideoWriter (MJPG in AVI) and read back through the same `VideoSource` a camera uses.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use opencv::core::Size;
use opencv::prelude::*;
use opencv::{imgcodecs, videoio};
use sylva_app::cmd_app::{ViewArgs, ViewSource, demo_sequence, stream_player};
use sylva_app::footage::Footage;
use sylva_app::live_capture::StreamInput;
use sylva_app::player::Player;
use sylva_app::state::{InputEvent, TouchPhase};
use sylva_tracking::{Camera, TumSequence};

/// Writes the first `count` frames of the demo sequence (640 x 480) as an MJPG AVI at 30 Hz.
fn demo_video(dir: &Path, count: usize) -> PathBuf {
    let demo = demo_sequence().expect("the bundled demo sequence test-data/demo_garden");
    let footage = Footage::open(&demo).expect("demo footage");
    assert!(
        footage.len() >= count,
        "the demo has {} frames",
        footage.len()
    );
    let path = dir.join("demo.avi");
    let fourcc = videoio::VideoWriter::fourcc('M', 'J', 'P', 'G').expect("fourcc");
    let mut writer =
        videoio::VideoWriter::new(&path, fourcc, 30.0, Size::new(640, 480), true).expect("writer");
    assert!(
        writer.is_opened().expect("is_opened"),
        "cannot write {}",
        path.display()
    );
    for frame in &footage.frames[..count] {
        let bgr = imgcodecs::imread(&frame.rgb, imgcodecs::IMREAD_COLOR).expect("imread");
        assert_eq!(
            (bgr.cols(), bgr.rows()),
            (640, 480),
            "{}",
            frame.rgb.display()
        );
        writer.write(&bgr).expect("write frame");
    }
    writer.release().expect("close the video");
    path
}

/// The pixel of the tree's highest point in the shown frame.
fn top_pixel(player: &Player) -> Option<Vec2> {
    let top = player
        .design
        .tree
        .skeleton
        .internodes
        .iter()
        .map(|i| i.end)
        .max_by(|a, b| a.y.total_cmp(&b.y))?;
    player.camera_in_tree()?.pixel_from_world(top)
}

fn view_args(video: &Path) -> ViewArgs {
    ViewArgs {
        sequence: Some(video.to_owned()),
        camera: None,
        calibration: None,
        record: None,
        frame: 0,
        paused: false,
        orbit: false,
        plant_at_origin: false,
        frame_report: None,
        window_size: (1120, 720),
        restore: false,
    }
}

#[test]
fn a_video_streamed_through_the_player_is_tracked_recorded_and_replays_to_the_same_tree() {
    let dir = tempfile::tempdir().expect("temp dir");
    let frames = 240;
    let video = demo_video(dir.path(), frames);
    let demo = demo_sequence().expect("demo");
    let record = dir.path().join("recorded");
    let args = ViewArgs {
        calibration: Some(demo.join("camera.txt")),
        record: Some(record.clone()),
        ..view_args(&video)
    };
    assert_eq!(
        args.source().expect("source"),
        ViewSource::Video(video.clone())
    );
    let (mut player, session_path) =
        stream_player(StreamInput::File(video.clone()), &args).expect("the video opens");
    assert!(player.is_live());
    assert_eq!(session_path, record.join("session.json"));

    let seedling = player.design.tree.skeleton.len();
    let (mut shown, mut posed, mut first_ground) = (0, 0, None);
    let mut finger = Vec2::ZERO;
    while player.next_live_frame().expect("streaming") {
        assert_eq!(player.frame, shown, "frames are shown once, in order");
        let scene = player.scene().expect("the shown frame is tracked");
        posed += usize::from(scene.world_from_camera.is_some());
        if scene.ground.is_some() && first_ground.is_none() {
            first_ground = Some(shown);
        }
        // A stroke up from the top of the seedling, as the user would paint it live.
        let since_ground = first_ground.map(|g| shown - g);
        let touch = |phase, p: Vec2| InputEvent::Touch {
            phase,
            id: 0,
            x: p.x,
            y: p.y,
        };
        match since_ground {
            // The user plants the tree by tapping the ground at the world origin.
            Some(5) => {
                if let Some(p) = player.camera().and_then(|c| c.pixel_from_world(Vec3::ZERO)) {
                    player.input(touch(TouchPhase::Start, p));
                    player.input(touch(TouchPhase::End, p));
                }
            }
            Some(10) => {
                if let Some(p) = top_pixel(&player) {
                    finger = p;
                    player.input(touch(TouchPhase::Start, finger));
                }
            }
            Some(11..50) => {
                finger += Vec2::new(1.0, -4.0);
                player.input(touch(TouchPhase::Move, finger));
            }
            Some(50) => player.input(touch(TouchPhase::End, finger)),
            _ => {}
        }
        shown += 1;
    }
    assert_eq!(shown, frames, "every frame of the video is shown");
    let first_ground = first_ground.expect("the ground plane is found");
    println!("posed {posed}/{shown} frames, ground found at frame {first_ground}");
    assert!(posed >= frames / 2, "posed {posed} of {frames} frames");
    assert!(
        first_ground < frames / 2,
        "ground found only at frame {first_ground}"
    );
    assert!(player.ground().is_some(), "the ground stays found");
    let grown = player.design.tree.skeleton.len();
    assert!(
        grown > seedling,
        "the stroke grew the tree ({seedling} -> {grown} internodes)"
    );

    player.finish_recording().expect("the recording completes");
    player
        .session
        .save(&session_path)
        .expect("save the session");
    let sequence = TumSequence::open(&record).expect("the recording is a TUM sequence");
    assert_eq!(sequence.frames.len(), frames);
    let calibration = Camera::from_file(&demo.join("camera.txt")).expect("calibration");
    assert_eq!(
        (
            sequence.camera.fx,
            sequence.camera.cx,
            sequence.camera.width
        ),
        (calibration.fx, calibration.cx, calibration.width)
    );
    assert_eq!(Footage::open(&record).expect("footage").len(), frames);

    let report = sylva_app::session::replay(&session_path, None, false, |_, _| {})
        .expect("the live session replays");
    assert_eq!(report.num_frames, frames);
    assert_eq!(report.tree_sha256, player.design.tree_sha256());
}

#[test]
fn a_video_without_calibration_gets_a_sixty_degree_camera_and_a_wrong_calibration_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let video = demo_video(dir.path(), 5);
    let (mut player, session_path) =
        stream_player(StreamInput::File(video.clone()), &view_args(&video)).expect("opens");
    let k = player.footage.intrinsics;
    assert_eq!((k.width, k.height), (640, 480));
    let fov_deg = 2.0 * (0.5 * 640.0 / k.fx).atan().to_degrees();
    assert!((fov_deg - 60.0).abs() < 1e-3, "field of view {fov_deg}°");
    assert!(
        !player.session_replayable(),
        "nothing recorded without --record"
    );
    assert_eq!(session_path, PathBuf::from("out/last-session.json"));
    let mut shown = 0;
    while player.next_live_frame().expect("streaming") {
        shown += 1;
    }
    assert_eq!(shown, 5);
    assert!(
        player.footage.is_empty(),
        "frames are not kept without --record"
    );

    let small = dir.path().join("small.txt");
    std::fs::write(
        &small,
        "width 320\nheight 240\nfx 260\nfy 260\ncx 160\ncy 120\n",
    )
    .expect("write calibration");
    let args = ViewArgs {
        calibration: Some(small),
        ..view_args(&video)
    };
    let err = stream_player(StreamInput::File(video.clone()), &args)
        .err()
        .expect("a 320 x 240 calibration for 640 x 480 frames is refused");
    let message = format!("{err:#}");
    assert!(
        message.contains("640 x 480") && message.contains("320 x 240"),
        "{message}"
    );
}

#[test]
fn stream_options_on_a_recorded_folder_are_refused_naming_the_option() {
    let demo = demo_sequence().expect("demo");
    let args = ViewArgs {
        record: Some(PathBuf::from("/tmp/nowhere")),
        ..view_args(&demo)
    };
    let message = format!("{:#}", args.source().expect_err("refused"));
    assert!(message.contains("--record"), "{message}");
}

#[test]
fn a_missing_camera_is_a_clear_error_naming_it_not_a_panic() {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(["view", "--camera", "7"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run sylva");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "no camera 7 here: {stderr}");
    assert!(stderr.contains("camera 7"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn a_path_that_does_not_exist_is_named_in_the_error() {
    let missing = PathBuf::from("/nonexistent/clip.mp4");
    let message = format!("{:#}", view_args(&missing).source().expect_err("refused"));
    assert!(
        message.contains("/nonexistent/clip.mp4") && message.contains("does not exist"),
        "{message}"
    );
}
