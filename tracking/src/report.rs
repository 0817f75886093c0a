//! Runs the tracker over a whole TUM sequence and measures it: per-stage timings, tracked
//! fraction and, with ground truth, the trajectory errors of [`crate::metrics`].

use crate::frame::{FrameOutput, TrackingState};
use crate::measure::MeasureError;
use crate::metrics::{PosePair, TrajectoryErrors, trajectory_errors};
use crate::run_scale::{RunScale, RunScaleError, ScaleOptions, run_scale};
use crate::sequence::{FrameSource, SequenceError, SourceEvent, TumSequence, decode_depth_m};
use crate::tracker::{Tracker, TrackerConfig, TrackerError};
use glam::DAffine3;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Largest time gap when pairing a frame with its ground-truth pose (TUM's associate.py: 20 ms).
pub const MAX_GROUNDTRUTH_GAP_S: f64 = 0.02;
/// Anchor depth when the first frame has no depth map, metres.
pub const DEFAULT_ANCHOR_DEPTH_M: f64 = 2.0;

/// Something the run could not do.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Sequence(#[from] SequenceError),
    #[error(transparent)]
    Tracker(#[from] TrackerError),
    #[error(transparent)]
    Scale(#[from] RunScaleError),
    /// Every listed frame was unreadable: there is nothing to track or to measure.
    #[error(
        "no frame of {path} could be read ({num_skipped} listed, all skipped): nothing was tracked"
    )]
    NoFrameRead { path: PathBuf, num_skipped: usize },
}

/// A frame the source could not read.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SkippedFrame {
    pub index: usize,
    pub path: PathBuf,
    pub reason: String,
}

/// Milliseconds spent per stage over the run.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct StageTimings {
    pub decode_ms: Vec<f64>,
    pub track_ms: Vec<f64>,
}

/// Everything measured on one run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TrackReport {
    pub sequence: PathBuf,
    pub frames: usize,
    /// Frames that had a pose when the tracker returned them (when an app would show them).
    pub tracked_frames: usize,
    /// `tracked_frames` over all frames.
    pub tracked_fraction: f64,
    /// Frames whose pose was found only later (the initializer's back-filled frames before
    /// the first map, relocalised frames): counted in the errors, not in `tracked_fraction`.
    pub late_posed_frames: usize,
    pub errors: Option<TrajectoryErrors>,
    pub median_decode_ms: f64,
    /// Median tracking time per frame, decode excluded.
    pub ms_per_frame: f64,
    pub num_keyframes: usize,
    pub num_map_points: usize,
    pub skipped: Vec<SkippedFrame>,
    /// The tracker's own scale: the camera's height at its first map.
    pub scale_source: Option<crate::scale::ScaleSource>,
    /// The run's metric scale (the median camera height, or a known length), the camera's
    /// height and the measurements made with it. Positions, the plane and the errors of this
    /// report are in its metres.
    pub scale: RunScale,
    /// Rolling-shutter readout time used at the end of the run (given or estimated), ms.
    pub rolling_shutter_readout_ms: f64,
    /// The ground plane in the world at the end of the run.
    pub plane: Option<crate::frame::Plane>,
    /// Per frame: index, timestamp, state, `world_from_camera` translation (if tracked).
    pub trajectory: Vec<TrajectoryRow>,
    /// True positions of the tracked frames, aligned estimated positions (for plots).
    #[serde(skip)]
    pub aligned: Vec<([f64; 3], [f64; 3])>,
}

/// One frame of the trajectory.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TrajectoryRow {
    pub index: usize,
    pub timestamp_s: f64,
    pub state: TrackingState,
    pub position: Option<[f64; 3]>,
    /// `world_from_camera` rotation as a quaternion (x, y, z, w), if tracked.
    pub orientation: Option<[f64; 4]>,
    /// Map points tracked in the frame.
    pub num_points: usize,
}

/// Tracks every frame of a TUM sequence. `progress` is called after each frame with (done,
/// total); `on_skip` with each unreadable frame. The scale comes from the median camera
/// height at `config.holding_height_m`.
pub fn run_sequence(
    root: &Path,
    config: TrackerConfig,
    progress: impl FnMut(usize, usize),
    on_skip: impl FnMut(&SkippedFrame),
) -> Result<TrackReport, RunError> {
    run_sequence_from(root, config, 0, progress, on_skip)
}

/// [`run_sequence`] with the scale's inputs (holding height, a known length) and measurements
/// (`sylva track`'s entry). Picks in frames the footage lacks are refused before tracking.
pub fn run_sequence_scaled(
    root: &Path,
    config: TrackerConfig,
    options: &ScaleOptions,
    progress: impl FnMut(usize, usize),
    on_skip: impl FnMut(&SkippedFrame),
) -> Result<TrackReport, RunError> {
    let sequence = TumSequence::open(root)?;
    run_opened(root, sequence, config, options, progress, on_skip)
}

/// [`run_sequence`] from the sequence's frame `first_frame` on (the frames before it dropped,
/// as if the footage began there): how the tracker's start depends on where the footage starts.
/// `first_frame` past the end is [`RunError::NoFrameRead`].
pub fn run_sequence_from(
    root: &Path,
    config: TrackerConfig,
    first_frame: usize,
    progress: impl FnMut(usize, usize),
    on_skip: impl FnMut(&SkippedFrame),
) -> Result<TrackReport, RunError> {
    let options = ScaleOptions {
        holding_height_m: config.holding_height_m,
        ..ScaleOptions::default()
    };
    let mut sequence = TumSequence::open(root)?;
    sequence
        .frames
        .drain(..first_frame.min(sequence.frames.len()));
    run_opened(root, sequence, config, &options, progress, on_skip)
}

fn run_opened(
    root: &Path,
    sequence: TumSequence,
    mut config: TrackerConfig,
    options: &ScaleOptions,
    mut progress: impl FnMut(usize, usize),
    mut on_skip: impl FnMut(&SkippedFrame),
) -> Result<TrackReport, RunError> {
    config.holding_height_m = crate::scale::validate_holding_height_m(options.holding_height_m)
        .map_err(RunScaleError::from)?;
    let num_frames = sequence.frames.len();
    let check = |frame: usize| {
        (frame < num_frames)
            .then_some(())
            .ok_or(MeasureError::NoFrame { frame, num_frames })
    };
    if let Some(k) = &options.known_length {
        check(k.pixels.frame).map_err(RunScaleError::KnownLength)?;
    }
    for p in &options.measures {
        check(p.frame).map_err(RunScaleError::Measure)?;
    }
    let mut source = sequence.source();
    let total = source.len_hint().unwrap_or(0);
    let mut tracker = Tracker::new(sequence.camera, config)?;
    let mut outputs: Vec<FrameOutput> = Vec::new();
    let mut timings = StageTimings::default();
    let mut skipped = Vec::new();
    let mut num_posed_when_shown = 0;
    let mut done = 0;
    loop {
        let start = Instant::now();
        let Some(event) = source.next_event() else {
            break;
        };
        timings.decode_ms.push(start.elapsed().as_secs_f64() * 1e3);
        done += 1;
        match event {
            SourceEvent::Frame(frame) => {
                let up = sequence.up_in_camera_at(frame.timestamp_s);
                let start = Instant::now();
                let output = tracker.track(&frame, up.map(|u| u * 9.81))?;
                timings.track_ms.push(start.elapsed().as_secs_f64() * 1e3);
                num_posed_when_shown += usize::from(output.world_from_camera.is_some());
                outputs.push(output);
                for late in tracker.take_late_poses() {
                    if let Some(o) = outputs.iter_mut().find(|o| o.index == late.index) {
                        o.world_from_camera = Some(late.world_from_camera);
                        o.state = TrackingState::Ok;
                    }
                }
            }
            SourceEvent::Skipped {
                index,
                path,
                reason,
            } => {
                let skip = SkippedFrame {
                    index,
                    path,
                    reason,
                };
                on_skip(&skip);
                skipped.push(skip);
            }
        }
        progress(done, total);
    }
    if outputs.is_empty() {
        return Err(RunError::NoFrameRead {
            path: root.to_path_buf(),
            num_skipped: skipped.len(),
        });
    }
    let scale = run_scale(&outputs, &sequence.camera, num_frames, options)?;
    Ok(summarise(
        &sequence,
        &tracker,
        outputs,
        num_posed_when_shown,
        timings,
        skipped,
        scale,
    ))
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn summarise(
    sequence: &TumSequence,
    tracker: &Tracker,
    outputs: Vec<FrameOutput>,
    num_posed_when_shown: usize,
    timings: StageTimings,
    skipped: Vec<SkippedFrame>,
    scale: RunScale,
) -> TrackReport {
    let frames = sequence.frames.len();
    // The tracker's world in the run's metres: one factor about the origin, on the ground.
    let metres_per_unit = scale.metres_per_unit();
    let metric = |mut pose: DAffine3| {
        pose.translation *= metres_per_unit;
        pose
    };
    let tracked: Vec<&FrameOutput> = outputs
        .iter()
        .filter(|o| o.world_from_camera.is_some())
        .collect();
    let pairs: Vec<PosePair> = tracked
        .iter()
        .filter_map(|o| {
            Some(PosePair {
                index: o.index,
                estimated: metric(o.world_from_camera?),
                truth: sequence.groundtruth_at(o.timestamp_s, MAX_GROUNDTRUTH_GAP_S)?,
            })
        })
        .collect();
    let first_truth = sequence
        .frames
        .first()
        .and_then(|f| sequence.groundtruth_at(f.timestamp_s, MAX_GROUNDTRUTH_GAP_S));
    let errors = first_truth.and_then(|first| {
        trajectory_errors(
            &pairs,
            &sequence.camera,
            &first,
            first_anchor_depth_m(sequence),
        )
    });
    let aligned = match &errors {
        Some(e) => pairs
            .iter()
            .map(|p| {
                let est = e.alignment.transform_point(p.estimated.translation);
                (p.truth.translation.to_array(), est.to_array())
            })
            .collect(),
        None => Vec::new(),
    };
    let trajectory = outputs
        .iter()
        .map(|o| TrajectoryRow {
            index: o.index,
            timestamp_s: o.timestamp_s,
            state: o.state,
            position: o
                .world_from_camera
                .map(|a: DAffine3| metric(a).translation.to_array()),
            orientation: o
                .world_from_camera
                .map(|a| glam::DQuat::from_mat3(&a.matrix3).normalize().to_array()),
            num_points: o.tracked_points.len(),
        })
        .collect();
    TrackReport {
        sequence: sequence.root.clone(),
        frames,
        tracked_frames: num_posed_when_shown,
        tracked_fraction: num_posed_when_shown as f64 / frames.max(1) as f64,
        late_posed_frames: tracked.len().saturating_sub(num_posed_when_shown),
        errors,
        median_decode_ms: median(timings.decode_ms.clone()),
        ms_per_frame: median(timings.track_ms.clone()),
        num_keyframes: tracker.map().keyframes.len(),
        num_map_points: tracker.map().points.len(),
        skipped,
        scale_source: tracker.world().map(|w| w.scale_source),
        rolling_shutter_readout_ms: tracker.rolling_shutter_readout_s() * 1e3,
        plane: tracker.world().map(|w| {
            let plane = w.plane_in_world();
            crate::frame::Plane {
                offset: plane.offset * metres_per_unit,
                ..plane
            }
        }),
        scale,
        trajectory,
        aligned,
    }
}

/// Median valid depth of the first frame's depth map (the anchors' depth).
fn first_anchor_depth_m(sequence: &TumSequence) -> f64 {
    let (Some(first), Some(scale)) = (sequence.frames.first(), sequence.camera.depth_scale) else {
        return DEFAULT_ANCHOR_DEPTH_M;
    };
    let Some(depth) = sequence
        .depth
        .iter()
        .find(|d| (d.timestamp_s - first.timestamp_s).abs() < 0.05)
    else {
        return DEFAULT_ANCHOR_DEPTH_M;
    };
    match decode_depth_m(&depth.path, scale) {
        Ok((_, _, metres)) => {
            let valid: Vec<f64> = metres
                .iter()
                .filter(|&&d| d > 0.0)
                .map(|&d| d as f64)
                .collect();
            if valid.is_empty() {
                DEFAULT_ANCHOR_DEPTH_M
            } else {
                median(valid)
            }
        }
        Err(_) => DEFAULT_ANCHOR_DEPTH_M,
    }
}

impl TrackReport {
    /// The closing `key=value` line (error fields only with ground truth; the scale's fields
    /// once there is a scale).
    pub fn summary_line(&self) -> String {
        let mut line = format!(
            "frames={} tracked_fraction={:.3} late_posed_frames={}",
            self.frames, self.tracked_fraction, self.late_posed_frames
        );
        if let Some(e) = &self.errors {
            line += &format!(
                " ate_rmse_m={:.4} window_ate_m={:.4} scale_spread={:.3} rot_err_deg={:.3} anchor_px={:.2} scale_error={:+.4} ate_se3_m={:.4}",
                e.ate_rmse_m,
                e.window_ate_m,
                e.scale_spread,
                e.rot_err_deg,
                e.anchor_px,
                e.scale_error,
                e.ate_se3_m
            );
        }
        if let Some(m) = &self.scale.metric {
            line += &format!(
                " scale_source={} scale_sigma={:.4}",
                m.source.key(),
                m.relative_sigma
            );
        }
        if let Some(h) = &self.scale.camera_height {
            line += &format!(" camera_height_m={:.3}", h.median_m);
        }
        line + &format!(" ms_per_frame={:.2}", self.ms_per_frame)
    }

    /// One `measured_m=` line per measurement asked for.
    pub fn measurement_lines(&self) -> Vec<String> {
        self.scale
            .measurements
            .iter()
            .map(|m| {
                let p = &m.pixels;
                format!(
                    "measure frame={} a={:.1},{:.1} on {} b={:.1},{:.1} on {} measured_m={:.4} sigma_m={:.4}",
                    p.frame,
                    p.a.x,
                    p.a.y,
                    m.surfaces[0].key(),
                    p.b.x,
                    p.b.y,
                    m.surfaces[1].key(),
                    m.measured_m,
                    m.sigma_m
                )
            })
            .collect()
    }
}
