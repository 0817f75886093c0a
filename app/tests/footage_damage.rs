//! Issue 21: damaged footage through the app's own commands. `sylva replay` of footage whose
//! camera file is wrong (fx 0, a width no texture holds) or whose frame is a cut-off JPEG fails
//! naming the file, instead of writing flat frames; `sylva track` with no readable frame exits
//! non-zero, logs every skipped frame on stderr (a pipe here, not a terminal) and refuses
//! numeric options out of range; the renderer fits a camera image over the device's texture
//! limit instead of panicking.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test footage_damage`

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::Vec3;
use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::{FrameView, Gpu, Intrinsics, Offscreen, Renderer, ViewCamera};

fn demo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden")
}

fn copy_dir(from: &Path, to: &Path) {
    fs::create_dir_all(to).expect("create");
    for entry in fs::read_dir(from).expect("read_dir") {
        let entry = entry.expect("entry");
        let target = to.join(entry.file_name());
        if entry.file_type().expect("type").is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            fs::copy(entry.path(), &target).expect("copy");
        }
    }
}

/// A copy of the demo footage in `dir/footage` and the committed demo session replaying it,
/// `dir/session.json`.
fn footage_and_session(dir: &Path) -> (PathBuf, PathBuf) {
    let footage = dir.join("footage");
    copy_dir(&demo(), &footage);
    let committed =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions/demo_garden.session.json");
    let mut session: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(committed).expect("session")).expect("JSON");
    session["footage"] = serde_json::json!(footage);
    let session_path = dir.join("session.json");
    fs::write(&session_path, session.to_string()).expect("write session");
    (footage, session_path)
}

fn sylva(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(args)
        .output()
        .expect("sylva runs")
}

fn replay(session: &Path, out: &Path) -> Output {
    sylva(&[
        "replay".as_ref(),
        session.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ])
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The demo's camera file with `key` set to `value`.
fn set_camera_value(footage: &Path, key: &str, value: &str) {
    let path = footage.join("camera.txt");
    let text = fs::read_to_string(&path).expect("camera.txt");
    let changed: Vec<String> = text
        .lines()
        .map(|l| match l.split_whitespace().next() {
            Some(k) if k == key => format!("{key} {value}"),
            _ => l.to_owned(),
        })
        .collect();
    fs::write(&path, changed.join("\n")).expect("write camera.txt");
}

#[test]
fn replay_of_footage_with_zero_focal_length_fails_naming_the_camera_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (footage, session) = footage_and_session(dir.path());
    set_camera_value(&footage, "fx", "0");
    let output = replay(&session, &dir.path().join("out"));
    let text = stderr(&output);
    assert!(!output.status.success(), "replay exited 0: {text}");
    assert!(
        text.contains("camera.txt") && text.contains("focal"),
        "{text}"
    );
    assert!(!dir.path().join("out/frame_0000.png").exists());
}

#[test]
fn replay_of_footage_wider_than_any_texture_fails_naming_the_camera_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (footage, session) = footage_and_session(dir.path());
    set_camera_value(&footage, "width", "17000");
    let output = replay(&session, &dir.path().join("out"));
    let text = stderr(&output);
    assert!(!output.status.success(), "replay exited 0: {text}");
    assert!(
        text.contains("camera.txt") && text.contains("17000"),
        "{text}"
    );
}

#[test]
fn replay_of_footage_with_a_cut_off_jpeg_fails_naming_the_frame() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (footage, session) = footage_and_session(dir.path());
    let list = fs::read_to_string(footage.join("rgb.txt")).expect("rgb.txt");
    let first = list
        .lines()
        .find(|l| !l.starts_with('#'))
        .and_then(|l| l.split_whitespace().nth(1))
        .expect("a frame")
        .to_owned();
    let path = footage.join(&first);
    let whole = fs::read(&path).expect("frame");
    fs::write(&path, &whole[..whole.len() / 3]).expect("truncate");
    let output = replay(&session, &dir.path().join("out"));
    let text = stderr(&output);
    assert!(!output.status.success(), "replay exited 0: {text}");
    assert!(
        text.contains(&first) && text.contains("truncated"),
        "{text}"
    );
}

/// The first `n` frames of the demo footage in `dir`; returns the frame files.
fn short_footage(dir: &Path, n: usize) -> Vec<String> {
    copy_dir(&demo(), dir);
    let list = fs::read_to_string(dir.join("rgb.txt")).expect("rgb.txt");
    let rows: Vec<&str> = list.lines().filter(|l| !l.starts_with('#')).collect();
    fs::write(dir.join("rgb.txt"), rows[..n].join("\n")).expect("write rgb.txt");
    rows[..n]
        .iter()
        .map(|r| r.split_whitespace().nth(1).unwrap_or("").to_owned())
        .collect()
}

#[test]
fn track_with_every_frame_unreadable_exits_non_zero_logging_each_skip() {
    let dir = tempfile::tempdir().expect("temp dir");
    let files = short_footage(dir.path(), 4);
    for file in &files {
        fs::write(dir.path().join(file), b"not a jpeg").expect("corrupt");
    }
    let output = sylva(&["track".as_ref(), dir.path().as_os_str()]);
    let text = stderr(&output);
    assert!(!output.status.success(), "track exited 0: {text}");
    assert!(
        text.contains("no frame") && text.contains("all skipped"),
        "{text}"
    );
    for file in &files {
        assert!(
            text.contains(&format!(
                "warning: skipped frame {}",
                dir.path().join(file).display()
            )),
            "no warning for {file} on stderr: {text}"
        );
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!stdout.contains("NaN"), "{stdout}");
}

#[test]
fn track_with_frames_but_none_tracked_exits_non_zero_saying_so() {
    let dir = tempfile::tempdir().expect("temp dir");
    // One frame: the tracker cannot start a map from it.
    short_footage(dir.path(), 1);
    let output = sylva(&["track".as_ref(), dir.path().as_os_str()]);
    let text = stderr(&output);
    assert!(!output.status.success(), "track exited 0: {text}");
    assert!(text.contains("was tracked"), "{text}");
}

#[test]
fn track_refuses_numeric_options_that_are_not_finite_or_in_range() {
    let dir = tempfile::tempdir().expect("temp dir");
    short_footage(dir.path(), 2);
    for option in [
        "--holding-height-m=nan",
        "--holding-height-m=0",
        "--holding-height-m=-5",
        "--readout-ms=inf",
        "--readout-ms=-1",
        "--known-length=0:1,1:2,2:nan",
        "--measure=0:nan,1:2,2",
    ] {
        let output = sylva(&["track".as_ref(), dir.path().as_os_str(), option.as_ref()]);
        let text = stderr(&output);
        assert!(!output.status.success(), "{option} accepted: {text}");
        let value = option.rsplit(['=', ':', ',']).next().unwrap_or(option);
        assert!(
            text.contains(value) || text.contains("nan"),
            "{option}: {text}"
        );
    }
}

#[test]
fn a_camera_image_over_the_texture_limit_is_scaled_down_not_a_panic() {
    let gpu = Gpu::headless().expect("a headless GPU (lavapipe)");
    let max_side = gpu.device.limits().max_texture_dimension_2d;
    // Wider than the limit, 8:1, red on the left half and blue on the right.
    let (width, height) = (max_side + 8, (max_side + 8) / 8);
    let mut rgba = vec![0u8; width as usize * height as usize * 4];
    for (i, pixel) in rgba.chunks_exact_mut(4).enumerate() {
        let left = (i % width as usize) < width as usize / 2;
        pixel.copy_from_slice(&if left {
            [255, 0, 0, 255]
        } else {
            [0, 0, 255, 255]
        });
    }
    let intrinsics = Intrinsics::from_fov(width, height, 1.2);
    let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
    renderer.set_camera_image(&gpu, &rgba, intrinsics);
    let target = Offscreen::new(&gpu.device, 256, 64);
    let camera = ViewCamera::looking_at(
        Intrinsics::from_fov(256, 64, 1.2),
        Vec3::new(0.0, 1.5, 3.0),
        Vec3::ZERO,
    );
    let image = target
        .render(&gpu, &mut renderer, &FrameView::augmented(camera, None))
        .expect("renders");
    let (left, right) = (image.get_pixel(40, 32).0, image.get_pixel(216, 32).0);
    assert!(
        left[0] > 200 && left[2] < 50 && right[2] > 200 && right[0] < 50,
        "the background is not the scaled image: left {left:?}, right {right:?}"
    );
}
