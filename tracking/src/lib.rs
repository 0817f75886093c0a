//! # sylva-tracking
//!
//! Camera tracking for Sylva's AR view: footage readers, a monocular tracker (frame, tracker,
//! map), the RANSAC ground plane, metric scale and the scene depth mesh used for occlusion and
//! for pruning a tree to the real scene.
//!
//! **Spaces.** `world_from_camera` maps camera coordinates (OpenCV convention: X right, Y down,
//! Z forward, metres after scale is fixed) into the world: metres, Y up along the ground-plane
//! normal, origin on the ground plane. The tracker's metres are its first guess (the holding height
//! at its first map); a [`scale::MetricScale`] (the median camera height, or a known length
//! picked with [`measure`]) is the one factor that corrects them, as [`run_scale`] does for a run.
//!
//! **Features.** `opencv` (default on desktop): feature tracking, PnP and video readers through
//! OpenCV; OpenCV types never leave the `cv` module. Without it (mobile targets) the tracker
//! still builds and runs on the portable vision backend ([`vision`], chosen by
//! [`TrackerConfig::backend`], selectable on desktop too); only the video readers need OpenCV.

pub mod ba;
pub mod camera;
pub mod features;
pub mod frame;
pub mod ground_plane;
pub mod input_file;
pub mod linalg;
pub mod lk;
pub mod map;
pub mod measure;
pub mod metrics;
pub mod pose;
pub mod rolling_shutter;
pub mod run_scale;
pub mod scale;
pub mod sequence;
pub mod world;

mod backend;
#[cfg(feature = "opencv")]
pub mod cv;
mod fusion;
mod initializer;
mod mapping;
mod relocalise;
pub mod report;
pub mod tracker;
pub mod vision;

pub use backend::VisionBackend;
pub use camera::{Camera, CameraError};
pub use frame::{Frame, FrameOutput, GrayImage, Plane, TrackedPoint, TrackingState};
pub use sequence::{FrameSource, SequenceError, SourceEvent, TumSequence};
pub use tracker::{Tracker, TrackerConfig, TrackerError};

pub mod depth_mesh;
pub mod occupancy;

/// Cases per fuzzed property in the readers' unit tests: 2000, or `PROPTEST_CASES` (the README's
/// long fuzzing run).
#[cfg(test)]
pub(crate) fn fuzz_config() -> proptest::prelude::ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2000);
    proptest::prelude::ProptestConfig {
        cases,
        ..Default::default()
    }
}
