//! Issue 20, Done-when 6: under Xvfb (lavapipe), `sylva view --frame 200` keeps the window
//! drawing while the tracker catches up on the 200 frames before it (a seek past the tracked
//! frames fast-forwards, a bounded amount of tracking per redraw), then plays on; the frame-time
//! report (`--frame-report N`) counts the redraws made while seeking and measures those after.
//! A check that the window draws, not a timed test: the frame times are printed, not asserted.
//!
//! Needs `Xvfb` (scripts/setup.sh installs it); fails loudly without.

mod xvfb;

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The `key=value` field of a report line.
fn field<'a>(line: &'a str, key: &str) -> &'a str {
    line.split_whitespace()
        .find_map(|f| f.strip_prefix(key)?.strip_prefix('='))
        .unwrap_or_else(|| panic!("no {key}= in {line:?}"))
}

#[test]
fn seeking_to_frame_200_keeps_the_window_drawing_and_then_plays() {
    let (_xvfb, display) = xvfb::start_xvfb(190);
    let dir = tempfile::tempdir().expect("temp dir");
    let demo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden");
    let xdg = dir.path().join("xdg");
    std::fs::create_dir_all(&xdg).expect("xdg dir");
    #[cfg(unix)]
    std::os::unix::fs::PermissionsExt::set_mode(
        &mut std::fs::metadata(&xdg).expect("xdg").permissions(),
        0o700,
    );
    let started = Instant::now();
    let child = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .arg("view")
        .arg(&demo)
        .args(["--window-size", "1280x800", "--frame", "200"])
        .args(["--plant-at-origin", "--frame-report", "5"])
        .current_dir(dir.path())
        .env("DISPLAY", &display)
        .env("WGPU_BACKEND", "vulkan")
        .env("XDG_RUNTIME_DIR", &xdg)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the sylva binary runs");
    let deadline = Duration::from_secs(600);
    let mut child = child;
    while child.try_wait().expect("waits").is_none() {
        if started.elapsed() > deadline {
            let _ = child.kill();
            panic!("the window did not reach frame 200 and report within {deadline:?}");
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    let output = child.wait_with_output().expect("output");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "sylva view failed:\n{stdout}\n{stderr}"
    );
    print!("{stdout}");
    println!("in {:.1} s", started.elapsed().as_secs_f64());
    let line = stdout
        .lines()
        .find(|l| l.starts_with("frame_report"))
        .unwrap_or_else(|| panic!("no frame report in:\n{stdout}\n{stderr}"));
    let drawn_while_seeking: usize = field(line, "drawn_while_seeking").parse().expect("count");
    let (first, last) = field(line, "footage_frames")
        .split_once("..")
        .expect("first..last");
    let first: usize = first.parse().expect("frame");
    let last: usize = last.parse().expect("frame");
    // The seek takes several redraws (each tracks for at most 200 ms, then draws the progress).
    assert!(
        drawn_while_seeking >= 2,
        "the window drew {drawn_while_seeking} times while seeking"
    );
    assert!(
        first >= 200,
        "the measured frames start at {first}, before the seek's 200"
    );
    assert!(last >= first, "{first}..{last}");
    assert!(
        stdout.contains("frame    median_ms="),
        "no frame times in the report:\n{stdout}"
    );
}
