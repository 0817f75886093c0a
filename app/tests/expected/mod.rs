//! A replay's committed expectation: the tree hash, the number of frames and every frame's
//! thumbnail, checked against `NAME.expected.json` (rewritten first with `SYLVA_BLESS=1`).
//! Shared by the session tests.
//!
//! The tree hash is exact. Frames are compared by their thumbnails
//! (`sylva_app::session::frame_thumbnail`: the mean colour of 12 × 9 cells) within
//! [`MAX_CELL_DIFFERENCE`] and [`MAX_MEAN_DIFFERENCE`]: lavapipe on another CPU rasterises a few
//! edge pixels differently, so the frames' exact checksums (kept in the file too) match only on
//! a machine like the one that blessed them, while a tree that moved, vanished, lost its
//! occlusion or its season's colour changes cells by far more.

use std::path::Path;

use serde::{Deserialize, Serialize};
use sylva_app::session::ReplayReport;

/// Largest difference allowed in one cell's channel, of 255.
const MAX_CELL_DIFFERENCE: u8 = 10;
/// Largest mean difference over a frame's cells and channels, of 255.
const MAX_MEAN_DIFFERENCE: f64 = 1.5;

#[derive(Serialize, Deserialize, PartialEq, Debug)]
struct Expected {
    tree_sha256: String,
    frames: usize,
    frame_sha256: Vec<String>,
    /// Each frame's thumbnail, hexadecimal.
    #[serde(default)]
    frame_thumbnails: Vec<String>,
    /// The garden's file, for a session that plants several trees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    garden_sha256: Option<String>,
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(text: &str) -> Vec<u8> {
    (0..text.len() / 2)
        .map(|i| u8::from_str_radix(&text[2 * i..2 * i + 2], 16).expect("hex thumbnail"))
        .collect()
}

/// (largest, mean) difference between two thumbnails.
fn difference(a: &[u8], b: &[u8]) -> (u8, f64) {
    if a.len() != b.len() || a.is_empty() {
        return (u8::MAX, f64::from(u8::MAX));
    }
    let diffs = a.iter().zip(b).map(|(&x, &y)| x.abs_diff(y));
    let largest = diffs.clone().max().unwrap_or(0);
    let mean = diffs.map(f64::from).sum::<f64>() / a.len() as f64;
    (largest, mean)
}

/// Asserts that `report` has the tree and frames of `expected_path` (after writing them there
/// when `bless`), naming the first frame that differs.
pub fn assert_replay_matches(report: &ReplayReport, expected_path: &Path, bless: bool) {
    let actual = Expected {
        tree_sha256: report.tree_sha256.clone(),
        frames: report.num_frames,
        frame_sha256: report.frame_sha256.clone(),
        frame_thumbnails: report.frame_thumbnails.iter().map(|t| hex(t)).collect(),
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
    assert_eq!(
        actual.frame_sha256.len(),
        expected.frame_thumbnails.len(),
        "one thumbnail a rendered frame in {}",
        expected_path.display()
    );
    let mut exact = 0;
    for (i, (actual_sha, expected_sha)) in actual
        .frame_sha256
        .iter()
        .zip(&expected.frame_sha256)
        .enumerate()
    {
        if actual_sha == expected_sha {
            exact += 1;
            continue;
        }
        let (largest, mean) = difference(
            &report.frame_thumbnails[i],
            &unhex(&expected.frame_thumbnails[i]),
        );
        assert!(
            largest <= MAX_CELL_DIFFERENCE && mean <= MAX_MEAN_DIFFERENCE,
            "frame {i} differs from {}: a thumbnail cell by {largest}, on average {mean:.2} (at most {MAX_CELL_DIFFERENCE} and {MAX_MEAN_DIFFERENCE})",
            expected_path.display()
        );
    }
    println!(
        "{exact} of {} frames pixel-identical to the blessed ones; the others within the thumbnail tolerance",
        actual.frame_sha256.len()
    );
}
