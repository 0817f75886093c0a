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

/// Issue 21: `path` made a named pipe (FIFO) in place of whatever was there.
#[cfg(unix)]
fn make_fifo(path: &Path) {
    let _ = fs::remove_file(path);
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
}

/// Runs `f` on a thread and fails (instead of hanging the suite) if it takes over a minute.
fn within_a_minute<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || sender.send(f()));
    receiver
        .recv_timeout(std::time::Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("{what} hung for a minute"))
}

#[cfg(unix)]
#[test]
fn a_fifo_frame_is_skipped_naming_it_without_hanging_the_run() {
    let dir = tempfile::tempdir().expect("temp dir");
    let files = copy_head(dir.path(), 40);
    make_fifo(&dir.path().join(&files[10]));
    let root = dir.path().to_path_buf();
    let (report, warnings) = within_a_minute("tracking past a FIFO frame", move || {
        let mut warnings = Vec::new();
        let report = run_sequence(
            &root,
            TrackerConfig::default(),
            |_, _| {},
            |s| warnings.push(format!("{}: {}", s.path.display(), s.reason)),
        );
        (report.map(|r| r.frames), warnings)
    });
    assert_eq!(report.expect("the run goes on"), 40);
    assert!(
        warnings
            .iter()
            .any(|w| w.contains(&files[10]) && w.contains("FIFO")),
        "{warnings:?}"
    );
}

#[cfg(unix)]
#[test]
fn fifo_or_device_lists_and_camera_files_are_refused_naming_them() {
    let dir = tempfile::tempdir().expect("temp dir");
    copy_head(dir.path(), 5);
    let root = dir.path().to_path_buf();
    // Each file in turn becomes a FIFO or `/dev/zero`; opening the sequence must refuse it
    // at once, naming it (a FIFO would block the reader, /dev/zero would fill the memory).
    for name in [
        "camera.txt",
        "rgb.txt",
        "groundtruth.txt",
        "accelerometer.txt",
    ] {
        let path = root.join(name);
        let saved = fs::read(&path).expect("saved copy");
        for device in [false, true] {
            if device {
                let _ = fs::remove_file(&path);
                std::os::unix::fs::symlink("/dev/zero", &path).expect("symlink");
            } else {
                make_fifo(&path);
            }
            let opened = root.clone();
            let text = within_a_minute(name, move || {
                TumSequence::open(&opened)
                    .map(|_| ())
                    .unwrap_err()
                    .to_string()
            });
            let expected = if device { "device" } else { "FIFO" };
            assert!(
                text.contains(name) && text.contains(expected),
                "{name}: {text}"
            );
        }
        fs::remove_file(&path).expect("remove");
        fs::write(&path, saved).expect("restore");
    }
}

#[test]
fn a_list_over_the_size_limit_is_refused_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    copy_head(dir.path(), 5);
    let list = dir.path().join("groundtruth.txt");
    // Sparse: larger than the limit without using the disk.
    fs::File::options()
        .write(true)
        .open(&list)
        .expect("open")
        .set_len(sylva_tracking::input_file::MAX_LIST_FILE_BYTES + 1)
        .expect("grow");
    let text = TumSequence::open(dir.path()).unwrap_err().to_string();
    assert!(
        text.contains("groundtruth.txt") && text.contains("larger than"),
        "{text}"
    );
}

#[test]
fn repeated_timestamps_in_a_frame_list_or_the_ground_truth_are_errors_naming_the_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    copy_head(dir.path(), 5);
    for name in ["rgb.txt", "groundtruth.txt"] {
        let path = dir.path().join(name);
        let saved = fs::read_to_string(&path).expect("read");
        let rows: Vec<&str> = saved
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
            .collect();
        // The third row's timestamp repeated on the next line.
        let stamp = rows[2].split_whitespace().next().expect("timestamp");
        let rest: Vec<&str> = rows[3].split_whitespace().skip(1).collect();
        let mut damaged: Vec<String> = rows.iter().map(|r| r.to_string()).collect();
        damaged[3] = format!("{stamp} {}", rest.join(" "));
        fs::write(&path, damaged.join("\n")).expect("write");
        let text = TumSequence::open(dir.path()).unwrap_err().to_string();
        assert!(
            text.contains(name) && text.contains("line 4") && text.contains("repeats"),
            "{name}: {text}"
        );
        fs::write(&path, saved).expect("restore");
    }
}

#[test]
fn zero_or_nan_ground_truth_quaternions_are_errors_naming_the_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    copy_head(dir.path(), 5);
    let path = dir.path().join("groundtruth.txt");
    let saved = fs::read_to_string(&path).expect("read");
    for quaternion in ["0 0 0 0", "nan 0 0 1"] {
        let mut lines: Vec<String> = saved.lines().map(str::to_owned).collect();
        let index = lines
            .iter()
            .position(|l| !l.starts_with('#'))
            .expect("a row")
            + 1;
        let words: Vec<&str> = lines[index].split_whitespace().take(4).collect();
        lines[index] = format!("{} {quaternion}", words.join(" "));
        fs::write(&path, lines.join("\n")).expect("write");
        let text = TumSequence::open(dir.path()).unwrap_err().to_string();
        assert!(
            text.contains("groundtruth.txt") && text.contains(&format!("line {}", index + 1)),
            "{quaternion}: {text}"
        );
    }
}

#[test]
fn a_sequence_whose_every_frame_is_unreadable_is_an_error_not_a_report() {
    let dir = tempfile::tempdir().expect("temp dir");
    let files = copy_head(dir.path(), 6);
    for file in &files {
        fs::write(dir.path().join(file), b"not an image").expect("corrupt");
    }
    let mut skipped = 0;
    let err = run_sequence(
        dir.path(),
        TrackerConfig::default(),
        |_, _| {},
        |_| skipped += 1,
    )
    .expect_err("nothing to measure");
    assert_eq!(skipped, 6);
    let text = err.to_string();
    assert!(
        text.contains("no frame") && text.contains("6 listed"),
        "{text}"
    );
}
