//! Helpers shared by Sylva's workspace-level tests (`tests/tests/*.rs`).

use std::path::PathBuf;

pub mod corners;
pub mod synthetic;

/// The shared test data folder: `$SYLVA_DATA`, else `../shared/test-data` beside the checkout.
///
/// Panics with a clear message when it is absent: data-driven tests fail loudly, never skip.
pub fn shared_data_dir() -> PathBuf {
    let dir = std::env::var_os("SYLVA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/test-data")
        });
    assert!(
        dir.is_dir(),
        "test data not found at {} (set SYLVA_DATA; the README says how to download the TUM sequences)",
        dir.display()
    );
    dir
}

/// The project's own data folder (`test-data/` at the workspace root).
pub fn project_data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data")
}

pub mod blackout {
    //! Forced losses of track: frames blanked in a TUM-layout sequence, and the comparison of
    //! the world after recovery with an unbroken run's.

    use std::ops::Range;
    use std::path::Path;
    use sylva_tracking::{
        FrameOutput, FrameSource, GrayImage, SourceEvent, Tracker, TrackerConfig, TrackingState,
        TumSequence,
    };

    /// A forced loss and what came after it.
    pub struct Recovery {
        /// The first frame after the blank that is tracked again.
        pub frame: usize,
        /// Camera-position distances, frame by frame from the recovery on, between the run with
        /// the blank and the unbroken run (frames with a pose in both), sorted.
        pub offsets: Vec<f64>,
    }

    impl Recovery {
        /// The median of [`Recovery::offsets`], metres.
        pub fn median_offset_m(&self) -> f64 {
            self.offsets
                .get(self.offsets.len() / 2)
                .copied()
                .unwrap_or(f64::INFINITY)
        }
    }

    /// Tracks the sequence at `root` up to frame `end` (exclusive) twice, unbroken and with the
    /// frames in `blank` turned black, and compares the worlds after the recovery; None when
    /// tracking never came back after the blank. Panics when a blanked frame was tracked.
    pub fn blank_and_recover(root: &Path, blank: Range<usize>, end: usize) -> Option<Recovery> {
        let clean = track_blanking(root, 0..0, end);
        let lost = track_blanking(root, blank.clone(), end);
        let frame = recovery_frame(&lost, blank)?;
        let offsets = world_offsets(&lost, &clean, frame);
        Some(Recovery { frame, offsets })
    }

    /// Tracks the sequence at `root` frame by frame up to frame `end` (exclusive), with the
    /// frames in `blank` turned black.
    fn track_blanking(root: &Path, blank: Range<usize>, end: usize) -> Vec<FrameOutput> {
        let sequence =
            TumSequence::open(root).unwrap_or_else(|e| panic!("{} is needed: {e}", root.display()));
        let mut source = sequence.source();
        let mut tracker = Tracker::new(sequence.camera, TrackerConfig::default()).expect("tracker");
        let mut outputs = Vec::new();
        while let Some(event) = source.next_event() {
            let SourceEvent::Frame(mut frame) = event else {
                panic!("{} has no bad frames", root.display());
            };
            if frame.index >= end {
                break;
            }
            if blank.contains(&frame.index) {
                frame.image = GrayImage::filled(frame.image.width, frame.image.height, 0);
            }
            let up = sequence.up_in_camera_at(frame.timestamp_s);
            outputs.push(tracker.track(&frame, up.map(|u| u * 9.81)).expect("track"));
        }
        outputs
    }

    /// The first frame after `blank` that is tracked again, if any; panics when a blanked frame
    /// was tracked.
    fn recovery_frame(outputs: &[FrameOutput], blank: Range<usize>) -> Option<usize> {
        for o in &outputs[blank.clone()] {
            assert_ne!(
                o.state,
                TrackingState::Ok,
                "blank frame {} tracked",
                o.index
            );
        }
        outputs[blank.end..]
            .iter()
            .find(|o| o.state == TrackingState::Ok)
            .map(|o| o.index)
    }

    /// Camera-position distances, frame by frame from frame `from`, between two runs over the
    /// same footage (frames with a pose in both), sorted.
    fn world_offsets(lost: &[FrameOutput], clean: &[FrameOutput], from: usize) -> Vec<f64> {
        let mut offsets: Vec<f64> = lost
            .iter()
            .zip(clean)
            .skip(from)
            .filter_map(|(l, c)| {
                Some(
                    l.world_from_camera?
                        .translation
                        .distance(c.world_from_camera?.translation),
                )
            })
            .collect();
        offsets.sort_by(f64::total_cmp);
        offsets
    }
}
