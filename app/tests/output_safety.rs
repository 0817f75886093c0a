//! Regression tests for the ways issue 21 found to destroy a user's files or run away, each
//! through the real `sylva` binary: every one is refused before anything is written, with an
//! error naming the file, and the files already there are left byte for byte.

use std::path::Path;
use std::process::{Command, Output};

fn sylva(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("sylva runs")
}

fn grow(dir: &Path, species: &str, years: &str, outputs: &[&str]) -> Output {
    let mut args = vec!["grow", "--species", species, "--years", years];
    args.extend_from_slice(outputs);
    sylva(dir, &args)
}

fn refused(output: &Output, words: &[&str]) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "refused: {stderr}");
    for w in words {
        assert!(stderr.contains(w), "the error says {w:?}: {stderr}");
    }
}

fn species_file(dir: &Path) -> Vec<u8> {
    let bytes =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../core/species/birch.json"))
            .expect("preset file");
    std::fs::write(dir.join("my.json"), &bytes).expect("copy");
    bytes
}

/// The committed demo session (footage referenced absolutely) as JSON, to be cut or damaged.
fn demo_session() -> serde_json::Value {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(manifest.join("tests/sessions/demo_garden.session.json"))
        .expect("session");
    let mut session: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    session["footage"] = serde_json::json!(manifest.join("../test-data/demo_garden"));
    session
}

#[test]
fn grow_refuses_to_write_its_tree_over_the_species_file_it_reads() {
    let dir = tempfile::tempdir().expect("dir");
    let species = species_file(dir.path());
    let out = grow(dir.path(), "my.json", "2", &["--out", "./my.json"]);
    refused(&out, &["my.json", "input"]);
    assert_eq!(
        std::fs::read(dir.path().join("my.json")).expect("read"),
        species
    );
}

#[test]
fn grow_refuses_two_outputs_naming_one_file() {
    let dir = tempfile::tempdir().expect("dir");
    let out = grow(
        dir.path(),
        "birch",
        "2",
        &["--out", "t.json", "--glb", "t.json"],
    );
    refused(&out, &["t.json", "one file"]);
    assert!(!dir.path().join("t.json").exists(), "nothing written");
    let out = grow(
        dir.path(),
        "birch",
        "2",
        &["--out", "t.mtl", "--obj", "t.obj"],
    );
    refused(&out, &["t.mtl"]);
}

#[test]
fn outputs_that_are_read_only_devices_fifos_or_folders_are_refused() {
    let dir = tempfile::tempdir().expect("dir");
    let locked = dir.path().join("locked.json");
    std::fs::write(&locked, b"keep me").expect("write");
    let mut perms = std::fs::metadata(&locked).expect("meta").permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&locked, perms).expect("chmod");
    let out = grow(dir.path(), "birch", "2", &["--out", "locked.json"]);
    refused(&out, &["locked.json", "read-only"]);
    assert_eq!(std::fs::read(&locked).expect("read"), b"keep me");
    let out = grow(
        dir.path(),
        "birch",
        "2",
        &["--out", "t.json", "--glb", "/dev/null"],
    );
    refused(&out, &["/dev/null", "device"]);
    assert!(
        !dir.path().join("t.json").exists(),
        "refused before anything is written"
    );
    let fifo = dir.path().join("pipe.json");
    if Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let out = grow(dir.path(), "birch", "2", &["--out", "pipe.json"]);
        refused(&out, &["pipe.json", "FIFO"]);
    }
    std::fs::create_dir(dir.path().join("folder.glb")).expect("mkdir");
    let out = grow(
        dir.path(),
        "birch",
        "2",
        &["--out", "t.json", "--glb", "folder.glb"],
    );
    refused(&out, &["folder.glb", "folder"]);
}

#[test]
fn a_species_asking_for_a_hundred_thousand_iterations_is_refused_at_once() {
    let dir = tempfile::tempdir().expect("dir");
    let text = String::from_utf8(species_file(dir.path())).expect("utf8");
    let mut species: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    species["years_per_iteration"] = serde_json::json!(0.01);
    std::fs::write(dir.path().join("fast.json"), species.to_string()).expect("write");
    let started = std::time::Instant::now();
    let out = grow(dir.path(), "fast.json", "1000", &["--out", "t.json"]);
    refused(&out, &["100000 growth iterations", "at most 1000"]);
    assert!(started.elapsed().as_secs() < 30, "refused before growing");
}

#[test]
fn replay_refuses_a_used_folder_and_forced_leaves_no_stale_frame() {
    let dir = tempfile::tempdir().expect("dir");
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).expect("mkdir");
    for name in [
        "frame_0013.png",
        "frame_0059.png",
        "tree.json",
        "my-notes.txt",
    ] {
        std::fs::write(out_dir.join(name), b"old").expect("write");
    }
    let mut session = demo_session();
    session["frames"]
        .as_array_mut()
        .expect("frames")
        .truncate(3);
    session["events"].as_array_mut().expect("events").clear();
    std::fs::write(dir.path().join("s.json"), session.to_string()).expect("write");
    let out = sylva(dir.path(), &["replay", "s.json", "--out", "out"]);
    refused(&out, &["out", "not empty", "--force"]);
    assert_eq!(
        std::fs::read(out_dir.join("frame_0059.png")).expect("kept"),
        b"old"
    );
    let out = sylva(dir.path(), &["replay", "s.json", "--out", "out", "--force"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(&out_dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame_0000.png",
            "frame_0001.png",
            "frame_0002.png",
            "my-notes.txt",
            "placement.json",
            "tree.glb",
            "tree.json"
        ],
        "only this replay's files, and the user's own"
    );
}

#[test]
fn a_session_growing_a_hundred_thousand_iterations_at_once_fails_its_check_naming_the_file() {
    let dir = tempfile::tempdir().expect("dir");
    let mut session = demo_session();
    session["events"]
        .as_array_mut()
        .expect("events")
        .push(serde_json::json!({
            "frame": 1, "time_s": 1700000000.1, "event": {"kind": "grow", "iterations": 100000}
        }));
    std::fs::write(dir.path().join("big.json"), session.to_string()).expect("write");
    let started = std::time::Instant::now();
    let out = sylva(dir.path(), &["replay", "big.json", "--out", "out"]);
    refused(&out, &["big.json", "100000 iterations at once"]);
    assert!(started.elapsed().as_secs() < 60, "refused before replaying");
}
