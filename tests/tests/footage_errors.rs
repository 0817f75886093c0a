//! Issue 5, item 5: unreadable frames are skipped with a warning naming the file and tracking
//! goes on; a bad camera.txt or an unreadable sequence is a clear error.

use std::fs;
use std::path::Path;
use sylva_tests::shared_data_dir;
use sylva_tracking::report::run_sequence;
use sylva_tracking::{TrackerConfig, TumSequence};

/// A copy of the first `n` frames of fr1_rpy in `dir` (rgb.txt, camera.txt, groundtruth.txt).
fn copy_head(dir: &Path, n: usize) -> Vec<String> {
    let source = shared_data_dir().join("tum_fr1_rpy");
    fs::create_dir_all(dir.join("rgb")).expect("rgb folder");
    for name in ["camera.txt", "groundtruth.txt", "accelerometer.txt"] {
        fs::copy(source.join(name), dir.join(name)).expect(name);
    }
    let list = fs::read_to_string(source.join("rgb.txt")).expect("rgb.txt");
    let lines: Vec<String> = list
        .lines()
        .filter(|l| !l.starts_with('#'))
        .take(n)
        .map(str::to_owned)
        .collect();
    for line in &lines {
        let file = line.split_whitespace().nth(1).expect("file column");
        fs::copy(source.join(file), dir.join(file)).expect("frame");
    }
    fs::write(dir.join("rgb.txt"), lines.join("\n")).expect("write rgb.txt");
    lines
        .iter()
        .map(|l| l.split_whitespace().nth(1).unwrap_or("").to_owned())
        .collect()
}

#[test]
fn corrupt_truncated_and_missing_frames_are_skipped_by_name_and_tracking_goes_on() {
    let dir = tempfile::tempdir().expect("temp dir");
    let files = copy_head(dir.path(), 120);
    fs::write(dir.path().join(&files[30]), b"not a jpeg at all").expect("corrupt");
    let whole = fs::read(dir.path().join(&files[31])).expect("read");
    fs::write(dir.path().join(&files[31]), &whole[..whole.len() / 3]).expect("truncate");
    fs::remove_file(dir.path().join(&files[32])).expect("remove");
    let mut warnings = Vec::new();
    let report = run_sequence(
        dir.path(),
        TrackerConfig::default(),
        |_, _| {},
        |s| warnings.push(format!("{}: {}", s.path.display(), s.reason)),
    )
    .expect("the run goes on");
    for k in [30, 31, 32] {
        assert!(
            warnings.iter().any(|w| w.contains(&files[k])),
            "no warning names {} (warnings: {warnings:?})",
            files[k]
        );
    }
    assert_eq!(report.frames, 120);
    let tracked_after = report
        .trajectory
        .iter()
        .filter(|r| r.index > 32 && r.position.is_some())
        .count();
    assert!(
        tracked_after > 40,
        "only {tracked_after} frames tracked after the bad ones"
    );
}

#[test]
fn a_bad_camera_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    copy_head(dir.path(), 5);
    // The error opening the sequence with `camera` as its camera.txt.
    let open_with = |camera: &str| {
        fs::write(dir.path().join("camera.txt"), camera).expect("write");
        let err = TumSequence::open(dir.path()).expect_err("bad camera.txt accepted");
        err.to_string()
    };
    let text = open_with("width 640\nheight 480\nfx five hundred\n");
    assert!(
        text.contains("camera.txt") && text.contains("line 3"),
        "{text}"
    );
    // A size no camera has (it would size the per-frame grids) is refused too.
    let text = open_with("width 1000000000\nheight 480\nfx 500\nfy 500\ncx 320\ncy 240\n");
    assert!(
        text.contains("camera.txt") && text.contains("1000000000"),
        "{text}"
    );
}

#[test]
fn a_missing_sequence_or_frame_list_is_an_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let missing = dir.path().join("nowhere");
    assert!(
        TumSequence::open(&missing)
            .unwrap_err()
            .to_string()
            .contains("nowhere")
    );
    copy_head(dir.path(), 5);
    fs::write(dir.path().join("rgb.txt"), "1.0\n").expect("write");
    let text = TumSequence::open(dir.path()).unwrap_err().to_string();
    assert!(
        text.contains("rgb.txt") && text.contains("line 1"),
        "{text}"
    );
}
