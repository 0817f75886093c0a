//! A replay's committed expectation: the tree hash and every frame's checksum, checked against
//! `NAME.expected.json` (rewritten first with `SYLVA_BLESS=1`). Shared by the session tests.

use std::path::Path;

use serde::{Deserialize, Serialize};
use sylva_app::session::ReplayReport;

#[derive(Serialize, Deserialize, PartialEq, Debug)]
struct Expected {
    tree_sha256: String,
    frames: usize,
    frame_sha256: Vec<String>,
    /// The garden's file, for a session that plants several trees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    garden_sha256: Option<String>,
}

/// Asserts that `report` has the tree and frames of `expected_path` (after writing them there
/// when `bless`), naming the first frame that differs.
pub fn assert_replay_matches(report: &ReplayReport, expected_path: &Path, bless: bool) {
    let actual = Expected {
        tree_sha256: report.tree_sha256.clone(),
        frames: report.num_frames,
        frame_sha256: report.frame_sha256.clone(),
        garden_sha256: report.garden_sha256.clone(),
    };
    if bless {
        std::fs::write(
            expected_path,
            serde_json::to_string_pretty(&actual).expect("json"),
        )
        .expect("write expected");
    }
    let expected: Expected =
        serde_json::from_str(&std::fs::read_to_string(expected_path).expect("expected file"))
            .expect("expected json");
    assert_eq!(actual.tree_sha256, expected.tree_sha256, "tree differs");
    assert_eq!(
        actual.garden_sha256, expected.garden_sha256,
        "garden differs"
    );
    assert_eq!(actual.frames, expected.frames);
    let first_bad = actual
        .frame_sha256
        .iter()
        .zip(&expected.frame_sha256)
        .position(|(a, e)| a != e);
    assert_eq!(
        first_bad, None,
        "frame checksums differ from frame {first_bad:?} on"
    );
}
