//! The metric scale of a tracked run, and the measurements asked of it: the camera's height over
//! the frames, a known length marked in one frame, distances between picked points.
//!
//! The scale comes from the known length when one is given, else from the median camera height
//! and the holding height ([`crate::scale`]). Either way it is one factor on the tracker's world
//! (`metres_per_unit`); distances and the camera height are reported after it.

use crate::camera::Camera;
use crate::frame::FrameOutput;
use crate::measure::{Distance, FrameView, KnownLength, MeasureError, PixelPair, Surface};
use crate::scale::{CameraHeights, MetricScale, ScaleError, scale_from_known_length};

/// What the user asks of the run's scale.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScaleOptions {
    /// The phone's height above the ground, metres ([`crate::scale::HOLDING_HEIGHT_RANGE_M`]).
    pub holding_height_m: f64,
    /// Two pixels on the ends of something of known length: sets the scale.
    pub known_length: Option<KnownLength>,
    /// Pairs of pixels to measure between.
    pub measures: Vec<PixelPair>,
}

/// Something the scale or a measurement could not be made from.
#[derive(Debug, thiserror::Error)]
pub enum RunScaleError {
    #[error("known length: {0}")]
    KnownLength(MeasureError),
    #[error("measure: {0}")]
    Measure(MeasureError),
    #[error(transparent)]
    Scale(#[from] ScaleError),
}

/// One measurement, in metres of the run's scale.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Measurement {
    pub pixels: PixelPair,
    pub surfaces: [Surface; 2],
    pub measured_m: f64,
    /// One standard deviation: the picks' ([`crate::measure::PICK_SIGMA_PX`]) and the scale's.
    pub sigma_m: f64,
}

/// The camera's height above the ground over the run, metres of the run's scale.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CameraHeight {
    /// Median over the frames with a pose and a plane.
    pub median_m: f64,
    /// Robust standard deviation of the frames' heights around it.
    pub spread_m: f64,
    pub num_frames: usize,
}

/// The scale of a run and what was measured with it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RunScale {
    /// None when the run never found a ground plane and no known length was given.
    pub metric: Option<MetricScale>,
    /// The known length's ends and distance, in the tracker's world unit.
    pub known_length: Option<Distance>,
    pub camera_height: Option<CameraHeight>,
    pub measurements: Vec<Measurement>,
}

impl RunScale {
    /// Metres per unit of the tracker's world (1 without a scale).
    pub fn metres_per_unit(&self) -> f64 {
        self.metric.map_or(1.0, |m| m.metres_per_unit)
    }
}

/// The frame `frame` of `outputs`, ready for picks. `num_frames` counts the footage's frames.
pub fn frame_view<'a>(
    outputs: &'a [FrameOutput],
    camera: &'a Camera,
    frame: usize,
    num_frames: usize,
) -> Result<FrameView<'a>, MeasureError> {
    if frame >= num_frames {
        return Err(MeasureError::NoFrame { frame, num_frames });
    }
    let output = outputs
        .iter()
        .find(|o| o.index == frame)
        .ok_or(MeasureError::NotTracked { frame })?;
    let world_from_camera = output
        .world_from_camera
        .ok_or(MeasureError::NotTracked { frame })?;
    if output.plane.is_none() && output.tracked_points.is_empty() {
        return Err(MeasureError::NoPlane { frame });
    }
    Ok(FrameView {
        frame,
        camera,
        world_from_camera,
        plane: output.plane,
        points: &output.tracked_points,
    })
}

/// The camera's height above each frame's plane, for the frames that have both.
pub fn camera_heights(outputs: &[FrameOutput]) -> CameraHeights {
    let mut heights = CameraHeights::default();
    for output in outputs {
        if let (Some(pose), Some(plane)) = (output.world_from_camera, output.plane) {
            heights.push(&plane, pose.translation);
        }
    }
    heights
}

/// The run's scale from its frames (see the module doc).
pub fn run_scale(
    outputs: &[FrameOutput],
    camera: &Camera,
    num_frames: usize,
    options: &ScaleOptions,
) -> Result<RunScale, RunScaleError> {
    let holding_height_m = crate::scale::validate_holding_height_m(options.holding_height_m)?;
    let heights = camera_heights(outputs);
    let mut metric = heights.scale(holding_height_m);
    let mut known_length = None;
    if let Some(known) = &options.known_length {
        let p = &known.pixels;
        let distance = frame_view(outputs, camera, p.frame, num_frames)
            .and_then(|view| view.measure(p.a, p.b))
            .map_err(RunScaleError::KnownLength)?;
        metric =
            scale_from_known_length(distance.distance, distance.sigma, known.length_m, p.frame)?;
        known_length = Some(distance);
    }
    let scale = metric.map_or(1.0, |m| m.metres_per_unit);
    let relative_sigma = metric.map_or(0.0, |m| m.relative_sigma);
    let camera_height = heights
        .median_and_spread()
        .map(|(median, spread)| CameraHeight {
            median_m: median * scale,
            spread_m: spread * scale,
            num_frames: heights.num_frames(),
        });
    let measurements = options
        .measures
        .iter()
        .map(|p| {
            let d = frame_view(outputs, camera, p.frame, num_frames)
                .and_then(|view| view.measure(p.a, p.b))
                .map_err(RunScaleError::Measure)?;
            let measured_m = d.distance * scale;
            Ok(Measurement {
                pixels: *p,
                surfaces: [d.a.surface, d.b.surface],
                measured_m,
                sigma_m: (d.sigma * scale).hypot(measured_m * relative_sigma),
            })
        })
        .collect::<Result<Vec<_>, RunScaleError>>()?;
    Ok(RunScale {
        metric,
        known_length,
        camera_height,
        measurements,
    })
}
