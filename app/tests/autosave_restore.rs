//! Under Xvfb: starting `sylva view` with an earlier autosave present keeps it (rotated to
//! `out/last-session.1.tree.json`, byte for byte) and writes nothing while the design is
//! unchanged; `sylva view --restore` brings it back, and SIGTERM closes the window as its close
//! button does, flushing the autosave: the tree autosaved then has the earlier tree's hash, and
//! the recorded session replays to it.
//!
//! Needs `Xvfb` (scripts/setup.sh installs it); fails loudly without.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use sha2::Digest;
use sylva_core::Tree;
use sylva_core::species::Species;

mod xvfb;

use xvfb::{Killed, start_xvfb};

fn demo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden")
}

fn sha256(bytes: &[u8]) -> String {
    format!("{:x}", sha2::Sha256::digest(bytes))
}

/// Runs `sylva view DEMO --paused [extra]` in `dir` until its window is up and the first frame
/// shown, then sends SIGTERM and waits for it to exit; returns its standard output.
fn view_then_sigterm(display: &str, dir: &Path, extra: &[&str]) -> String {
    let child = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .arg("view")
        .arg(demo())
        .arg("--paused")
        .args(extra)
        .current_dir(dir)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start sylva");
    let mut app = Killed(child);
    let stdout = app.0.stdout.take().expect("stdout");
    let (lines_tx, lines_rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if lines_tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut printed = Vec::new();
    // "autosaving …" is printed once the earlier autosave is kept (and restored) and just
    // before the window opens.
    let deadline = Instant::now() + Duration::from_secs(120);
    while !printed.iter().any(|l: &String| l.starts_with("autosaving")) {
        let left = deadline.saturating_duration_since(Instant::now());
        match lines_rx.recv_timeout(left) {
            Ok(line) => printed.push(line),
            Err(_) => panic!("sylva view printed only {printed:?}"),
        }
    }
    // Let the window open and draw (lavapipe on a loaded machine is slow).
    std::thread::sleep(Duration::from_secs(8));
    assert!(
        app.0.try_wait().expect("poll").is_none(),
        "the window closed by itself: {printed:?}"
    );
    let pid = app.0.id().to_string();
    let status = Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .expect("kill");
    assert!(status.success());
    let deadline = Instant::now() + Duration::from_secs(60);
    let exit = loop {
        if let Some(exit) = app.0.try_wait().expect("poll") {
            break exit;
        }
        assert!(Instant::now() < deadline, "no exit 60 s after SIGTERM");
        std::thread::sleep(Duration::from_millis(200));
    };
    printed.extend(lines_rx.try_iter());
    assert!(
        exit.success(),
        "SIGTERM closes the window cleanly: {exit:?} {printed:?}"
    );
    printed.join("\n")
}

#[test]
fn an_earlier_autosave_is_kept_on_start_and_restored_with_the_same_tree_hash() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    std::fs::create_dir(&out).expect("out/");
    let mut tree = Tree::new(Species::by_name("oak").expect("preset"), 11);
    tree.grow(7, None);
    let earlier = out.join("last-session.tree.json");
    tree.save(&earlier).expect("earlier autosave");
    let earlier_bytes = std::fs::read(&earlier).expect("read");
    let earlier_hash = sha256(&earlier_bytes);
    std::fs::write(
        out.join("last-session.tree.placement.json"),
        r#"{"world_from_tree":[1,0,0,0,1,0,0,0,1,0,0,0]}"#,
    )
    .expect("placement");

    let (_xvfb, display) = start_xvfb(290);
    // 1. A plain start keeps the earlier autosave and writes nothing while nothing changed.
    let printed = view_then_sigterm(&display, dir.path(), &[]);
    let kept = out.join("last-session.1.tree.json");
    assert!(
        printed.contains("the earlier design is kept in"),
        "{printed}"
    );
    assert_eq!(
        std::fs::read(&kept).expect("kept as .1"),
        earlier_bytes,
        "the earlier autosave is kept byte for byte"
    );
    assert!(
        !earlier.exists(),
        "an unchanged design is not autosaved over anything"
    );

    // 2. --restore brings it back; SIGTERM flushes the restored design as the autosave.
    let printed = view_then_sigterm(&display, dir.path(), &["--restore"]);
    assert!(printed.contains("restored"), "{printed}");
    let flushed = std::fs::read(&earlier).expect("the autosave flushed on SIGTERM");
    assert_eq!(
        sha256(&flushed),
        earlier_hash,
        "the restored tree has the earlier tree's hash"
    );
    assert_eq!(
        std::fs::read(&kept).expect("still kept"),
        earlier_bytes,
        "restoring does not touch the kept autosave"
    );
    let session = out.join("last-session.json");
    let report = sylva_app::session::replay(&session, None, false, |_, _| {})
        .expect("the recorded session replays");
    assert_eq!(
        report.tree_sha256, earlier_hash,
        "the session replays to the restored tree"
    );
}
