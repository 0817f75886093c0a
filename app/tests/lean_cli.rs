//! The lean `sylva` front: it grows trees on its own (no `sylva-app` beside it, no GPU, window or
//! OpenCV library), saves compact files the app loads, and hands every other subcommand to the
//! full app.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(binary: &Path, args: &[&str]) -> Output {
    Command::new(binary)
        .args(args)
        .output()
        .expect("the binary runs")
}

fn text(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// The front binary copied alone into `dir`.
fn alone_in(dir: &Path) -> PathBuf {
    let lone = dir.join("sylva");
    std::fs::copy(env!("CARGO_BIN_EXE_sylva"), &lone).expect("copied");
    lone
}

#[test]
fn the_front_grows_and_saves_a_compact_tree_without_the_full_app_beside_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let lone = alone_in(dir.path());
    let out = dir.path().join("birch.tree");
    let output = run(
        &lone,
        &[
            "grow",
            "--species",
            "birch",
            "--years",
            "5",
            "--out",
            out.to_str().expect("utf-8"),
            "--format",
            "compact",
        ],
    );
    assert!(output.status.success(), "{}", text(&output));
    let bytes = std::fs::read(&out).expect("saved");
    assert!(sylva_core::Tree::is_compact_file(&bytes));
    let tree = sylva_core::Tree::load(&out).expect("the compact file loads");
    assert!(text(&output).contains(&format!("internodes={}", tree.skeleton.len())));
    // Without the full app, the other subcommands fail with a clear message.
    let output = run(&lone, &["track", "nowhere"]);
    assert!(!output.status.success());
    assert!(text(&output).contains("sylva-app"), "{}", text(&output));
}

#[test]
fn other_subcommands_reach_the_full_app() {
    let output = run(Path::new(env!("CARGO_BIN_EXE_sylva")), &["--help"]);
    assert!(output.status.success(), "{}", text(&output));
    let help = text(&output);
    for subcommand in ["grow", "garden", "replay", "track", "recreate"] {
        assert!(
            help.contains(subcommand),
            "{subcommand} missing from {help}"
        );
    }
    let output = run(Path::new(env!("CARGO_BIN_EXE_sylva")), &["track", "--help"]);
    assert!(output.status.success(), "{}", text(&output));
    assert!(text(&output).contains("--report"), "{}", text(&output));
}

#[cfg(target_os = "linux")]
#[test]
fn the_front_links_no_gpu_window_or_opencv_library() {
    let Ok(output) = Command::new("ldd")
        .arg(env!("CARGO_BIN_EXE_sylva"))
        .output()
    else {
        eprintln!("no ldd here: nothing to check");
        return;
    };
    let libraries = String::from_utf8_lossy(&output.stdout).to_lowercase();
    for library in ["opencv", "vulkan", "wayland", "x11", "xcb", "tbb"] {
        assert!(!libraries.contains(library), "{library} in {libraries}");
    }
    assert!(libraries.lines().count() <= 8, "{libraries}");
}
