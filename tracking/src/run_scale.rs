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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Plane, TrackingState};
    use crate::measure::PICK_SIGMA_PX;
    use glam::{DAffine3, DMat3, DQuat, DVec2, DVec3};

    const FLOOR: Plane = Plane {
        normal: DVec3::Y,
        offset: 0.0,
    };

    /// Frame `index` of a walk along X, the camera `height` units above the floor looking
    /// down 34° towards −Z; without a pose when `tracked` is false.
    fn output(index: usize, height: f64, tracked: bool) -> FrameOutput {
        let pitch = 34f64.to_radians();
        let forward = DVec3::new(0.0, -pitch.sin(), -pitch.cos());
        let right = forward.cross(DVec3::Y).normalize();
        let down = forward.cross(right);
        let pose = DAffine3::from_rotation_translation(
            DQuat::from_mat3(&DMat3::from_cols(right, down, forward)),
            DVec3::new(0.1 * index as f64, height, 0.0),
        );
        FrameOutput {
            index,
            timestamp_s: index as f64 / 30.0,
            state: if tracked {
                TrackingState::Ok
            } else {
                TrackingState::Initializing
            },
            world_from_camera: tracked.then_some(pose),
            tracked_points: Vec::new(),
            plane: tracked.then_some(FLOOR),
        }
    }

    fn camera() -> Camera {
        Camera::pinhole(640, 480, 525.0, 525.0, 319.5, 239.5)
    }

    /// The pixel of a world point in frame `index` of `outputs`.
    fn pixel(outputs: &[FrameOutput], index: usize, world: DVec3) -> DVec2 {
        let pose = outputs[index].world_from_camera.expect("tracked");
        camera()
            .pixel_from_camera(pose.inverse().transform_point3(world))
            .expect("in front")
    }

    #[test]
    fn the_median_height_scales_the_run_and_a_known_length_overrides_it() {
        // Two frames untracked, the rest 2 units up: 0.75 m per unit at 1.5 m.
        let outputs: Vec<FrameOutput> = (0..20).map(|i| output(i, 2.0, i >= 2)).collect();
        let mut options = ScaleOptions {
            holding_height_m: 1.5,
            ..ScaleOptions::default()
        };
        let run = run_scale(&outputs, &camera(), 20, &options).expect("scale");
        assert!((run.metres_per_unit() - 0.75).abs() < 1e-9);
        let height = run.camera_height.expect("heights");
        assert!((height.median_m - 1.5).abs() < 1e-9 && height.num_frames == 18);
        // Ends of a 2-unit length on the floor in frame 10, said to be 1 m: 0.5 m per unit.
        let (a, b) = (DVec3::new(0.0, 0.0, -3.0), DVec3::new(2.0, 0.0, -3.0));
        let pixels = PixelPair {
            frame: 10,
            a: pixel(&outputs, 10, a),
            b: pixel(&outputs, 10, b),
        };
        options.known_length = Some(KnownLength {
            pixels,
            length_m: 1.0,
        });
        options.measures = vec![pixels];
        let run = run_scale(&outputs, &camera(), 20, &options).expect("scale");
        assert!((run.metres_per_unit() - 0.5).abs() < 1e-6);
        assert!((run.camera_height.expect("heights").median_m - 1.0).abs() < 1e-6);
        let measured = run.measurements[0];
        assert!((measured.measured_m - 1.0).abs() < 1e-6);
        assert_eq!(measured.surfaces, [Surface::Ground; 2]);
        // Picks on the same pixels: the pick and scale errors are the same one, counted twice.
        let relative = run.metric.expect("metric").relative_sigma;
        assert!(relative > 0.0 && relative < 0.02 * PICK_SIGMA_PX);
        assert!((measured.sigma_m - 2f64.sqrt() * relative).abs() < 1e-6);
    }

    #[test]
    fn marks_in_untracked_or_missing_frames_are_errors_naming_the_frame() {
        let outputs: Vec<FrameOutput> = (0..20).map(|i| output(i, 2.0, i >= 2)).collect();
        let pair = |frame| PixelPair {
            frame,
            a: DVec2::new(100.0, 300.0),
            b: DVec2::new(500.0, 300.0),
        };
        for (frame, expected) in [
            (1, "frame 1 has no camera pose"),
            (25, "frame 25: the footage has no such frame"),
        ] {
            let options = ScaleOptions {
                holding_height_m: 1.5,
                known_length: Some(KnownLength {
                    pixels: pair(frame),
                    length_m: 1.0,
                }),
                measures: Vec::new(),
            };
            let error = run_scale(&outputs, &camera(), 20, &options).expect_err("refused");
            assert!(error.to_string().contains(expected), "{error}");
        }
        let options = ScaleOptions {
            holding_height_m: 9.0,
            ..ScaleOptions::default()
        };
        assert!(run_scale(&outputs, &camera(), 20, &options).is_err());
    }
}
