//! The committed demo session (240 frames of `test-data/demo_garden` with two brush strokes, a
//! brush-radius change, a prune by double tap and a three-finger bend) replays headlessly to the
//! committed tree hash and frame checksums (lavapipe). `SYLVA_BLESS=1` re-records the session
//! from the demo script and rewrites the expected values.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test replay`

mod expected;

use std::path::PathBuf;

use sylva_app::footage::Footage;
use sylva_app::session::{Session, replay};
use sylva_app::state::{InputEvent, TouchPhase};

fn sessions_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions")
}

#[test]
fn the_committed_demo_session_replays_to_the_committed_tree_and_frames() {
    let session_path = sessions_dir().join("demo_garden.session.json");
    let expected_path = sessions_dir().join("demo_garden.expected.json");
    let bless = std::env::var_os("SYLVA_BLESS").is_some();
    if bless {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden");
        let footage = Footage::open(&root).expect("the demo sequence is in the repository");
        let session = sylva_app::demo_script::demo_session(
            &footage,
            PathBuf::from("../../../test-data/demo_garden"),
        )
        .expect("demo script");
        session.save(&session_path).expect("write session");
    }
    let session = Session::load(&session_path).expect("committed session");
    let num_touch_starts = |ids: &[u64]| {
        session
            .events
            .iter()
            .filter(|e| matches!(e.event, InputEvent::Touch { phase: TouchPhase::Start, id, .. } if ids.contains(&id)))
            .count()
    };
    assert!(
        session.frames.len() >= 200,
        "a few hundred frames, got {}",
        session.frames.len()
    );
    assert!(num_touch_starts(&[0]) >= 4, "two strokes and a double tap");
    assert_eq!(num_touch_starts(&[1, 2, 3]), 3, "one three-finger bend");

    let out = tempfile::tempdir().expect("temp dir");
    let mut sizes = Vec::new();
    let report = replay(&session_path, Some(out.path()), true, |_, state| {
        sizes.push(state.tree.skeleton.len())
    })
    .expect("replay");
    assert!(out.path().join("frame_0000.png").exists() && out.path().join("tree.json").exists());
    let grown = sizes.iter().copied().max().unwrap_or(0);
    assert!(
        grown > sizes[0] + 10,
        "the strokes must grow the tree: {} -> {grown}",
        sizes[0]
    );
    assert!(
        sizes.windows(2).any(|w| w[1] < w[0]),
        "the double tap must prune"
    );

    expected::assert_replay_matches(&report, &expected_path, bless);
    println!("{}", report.summary_line());
}
