//! Metric scale for a monocular map (whose unit is arbitrary): from the camera's height above the
//! ground plane and the height the user holds the phone at, or from a known distance between two
//! picked points.
//!
//! The tracker fixes its world once, from the camera's height above the plane at the first map
//! and the holding height ([`crate::world::WorldFrame`]): one frame, so a dip of the hand at
//! that moment scales the whole world. A [`MetricScale`] corrects that world afterwards by one
//! factor about its origin (which lies on the ground, so the plane stays put): from the median
//! of the camera's height over the frames ([`CameraHeights`]) or from a known length marked in
//! one frame ([`scale_from_known_length`]), each with its uncertainty.

use crate::frame::Plane;
use glam::DVec3;
use std::ops::RangeInclusive;

/// Default holding height of a phone above the ground, metres.
pub const DEFAULT_HOLDING_HEIGHT_M: f64 = 1.5;

/// Holding heights accepted, metres: a phone held near the ground by a crouching user up to one
/// held overhead from a step.
pub const HOLDING_HEIGHT_RANGE_M: RangeInclusive<f64> = 0.3..=3.0;

/// Fewest frames with a height for [`CameraHeights::scale`].
pub const MIN_HEIGHT_FRAMES: usize = 5;

/// A scale input no tracker could use.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ScaleError {
    #[error(
        "holding height {height_m} m is not a height a phone is held at ({} to {} m)",
        HOLDING_HEIGHT_RANGE_M.start(),
        HOLDING_HEIGHT_RANGE_M.end()
    )]
    HoldingHeight { height_m: f64 },
    #[error("known length {length_m} m must be a finite length above 1 cm")]
    KnownLength { length_m: f64 },
}

/// `height_m` when it is finite and inside [`HOLDING_HEIGHT_RANGE_M`].
pub fn validate_holding_height_m(height_m: f64) -> Result<f64, ScaleError> {
    if height_m.is_finite() && HOLDING_HEIGHT_RANGE_M.contains(&height_m) {
        Ok(height_m)
    } else {
        Err(ScaleError::HoldingHeight { height_m })
    }
}

/// Where the metric scale came from (reported).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ScaleSource {
    /// Camera height above the plane taken as `holding_height_m`; `num_frames` frames' heights
    /// were combined (their median; 1 for the tracker's first map).
    CameraHeight {
        holding_height_m: f64,
        #[serde(default = "one")]
        num_frames: usize,
    },
    /// Two picked points `distance_m` apart, in frame `frame` when known.
    KnownDistance {
        distance_m: f64,
        #[serde(default)]
        frame: Option<usize>,
    },
}

fn one() -> usize {
    1
}

impl ScaleSource {
    /// A one-word name for `key=value` lines: `camera_height` or `known_length`.
    pub fn key(&self) -> &'static str {
        match self {
            Self::CameraHeight { .. } => "camera_height",
            Self::KnownDistance { .. } => "known_length",
        }
    }
}

impl std::fmt::Display for ScaleSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::CameraHeight {
                holding_height_m,
                num_frames: 1,
            } => write!(
                f,
                "the camera's height (held {holding_height_m} m above the ground)"
            ),
            Self::CameraHeight {
                holding_height_m,
                num_frames,
            } => write!(
                f,
                "the camera's height (held {holding_height_m} m above the ground; median of \
                 {num_frames} frames)"
            ),
            Self::KnownDistance {
                distance_m,
                frame: Some(frame),
            } => write!(f, "a known length ({distance_m} m marked in frame {frame})"),
            Self::KnownDistance { distance_m, .. } => {
                write!(f, "two picked points {distance_m} m apart")
            }
        }
    }
}

/// A correction of the tracker's world to metres, with where it came from.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MetricScale {
    /// Metres per unit of the tracker's world (1 when the tracker's first guess stands).
    pub metres_per_unit: f64,
    pub source: ScaleSource,
    /// One standard deviation of `metres_per_unit`, relative (0.01 = ±1%).
    pub relative_sigma: f64,
}

impl std::fmt::Display for MetricScale {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ±{:.1}% (1σ)",
            self.source,
            100.0 * self.relative_sigma
        )
    }
}

/// The camera's height above the ground plane, frame by frame, in the tracker's world unit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraHeights {
    heights: Vec<f64>,
}

/// Median and robust standard deviation (1.4826 × the median absolute deviation).
fn median_and_sigma(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    };
    let mut v = values.to_vec();
    let m = median(&mut v);
    let mut deviations: Vec<f64> = values.iter().map(|x| (x - m).abs()).collect();
    Some((m, 1.4826 * median(&mut deviations)))
}

impl CameraHeights {
    /// Adds the height of `camera_center` above `plane` (both in the world); heights on or
    /// below the plane, or not finite, are left out.
    pub fn push(&mut self, plane: &Plane, camera_center: DVec3) {
        let height = plane.signed_distance(camera_center);
        if height.is_finite() && height > 1e-9 {
            self.heights.push(height);
        }
    }

    pub fn num_frames(&self) -> usize {
        self.heights.len()
    }

    /// The median height and the robust spread of the heights around it, world units.
    pub fn median_and_spread(&self) -> Option<(f64, f64)> {
        median_and_sigma(&self.heights)
    }

    /// The scale that puts the median height at `holding_height_m`. Its uncertainty is the
    /// frames' spread around the median, relative: how far the camera strayed from one height
    /// (the walk's bob, a lowered arm), the error of the assumption that it is held at one. The
    /// error of the entered height itself is the user's and is not in it. None with fewer than
    /// [`MIN_HEIGHT_FRAMES`] frames or an invalid height.
    pub fn scale(&self, holding_height_m: f64) -> Option<MetricScale> {
        let holding_height_m = validate_holding_height_m(holding_height_m).ok()?;
        if self.heights.len() < MIN_HEIGHT_FRAMES {
            return None;
        }
        let (median, spread) = self.median_and_spread()?;
        Some(MetricScale {
            metres_per_unit: holding_height_m / median,
            source: ScaleSource::CameraHeight {
                holding_height_m,
                num_frames: self.heights.len(),
            },
            relative_sigma: spread / median,
        })
    }
}

/// Metres per world unit from two points `distance` world units apart (with one standard
/// deviation `distance_sigma`) that are `length_m` apart, marked in `frame`.
pub fn scale_from_known_length(
    distance: f64,
    distance_sigma: f64,
    length_m: f64,
    frame: usize,
) -> Result<Option<MetricScale>, ScaleError> {
    if !(length_m.is_finite() && length_m >= 0.01) {
        return Err(ScaleError::KnownLength { length_m });
    }
    Ok(
        scale_from_known_distance(DVec3::ZERO, DVec3::X * distance, length_m).map(|scale| {
            MetricScale {
                metres_per_unit: scale,
                source: ScaleSource::KnownDistance {
                    distance_m: length_m,
                    frame: Some(frame),
                },
                relative_sigma: distance_sigma.abs() / distance,
            }
        }),
    )
}

/// Metres per map unit from the camera centre's height above the plane. None when the camera
/// is (almost) on the plane.
pub fn scale_from_camera_height(
    plane: &Plane,
    camera_center: DVec3,
    holding_height_m: f64,
) -> Option<f64> {
    let height = plane.signed_distance(camera_center).abs();
    (height > 1e-9 && holding_height_m > 0.0).then(|| holding_height_m / height)
}

/// Metres per map unit from two map points a known distance apart.
pub fn scale_from_known_distance(a: DVec3, b: DVec3, distance_m: f64) -> Option<f64> {
    let d = a.distance(b);
    (d > 1e-12 && distance_m > 0.0 && d.is_finite()).then(|| distance_m / d)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLOOR: Plane = Plane {
        normal: DVec3::Y,
        offset: 0.0,
    };

    #[test]
    fn a_camera_two_units_above_the_plane_held_at_one_and_a_half_metres_gives_0_75() {
        let s = scale_from_camera_height(&FLOOR, DVec3::new(3.0, 2.0, -1.0), 1.5).expect("scale");
        assert!((s - 0.75).abs() < 1e-12);
        assert!(scale_from_known_distance(DVec3::ZERO, DVec3::X * 4.0, 2.0) == Some(0.5));
    }

    #[test]
    fn the_median_height_ignores_one_frame_where_the_arm_dropped() {
        let mut heights = CameraHeights::default();
        for i in 0..41 {
            let bob = 0.01 * (i as f64 * 0.7).sin();
            heights.push(&FLOOR, DVec3::new(i as f64, 2.0 + bob, 0.0));
        }
        // A frame at half the height (the first map could have been made there).
        heights.push(&FLOOR, DVec3::new(0.0, 1.0, 0.0));
        let scale = heights.scale(1.5).expect("scale");
        assert!(
            (scale.metres_per_unit - 0.75).abs() < 0.005,
            "{}",
            scale.metres_per_unit
        );
        assert!(
            scale.relative_sigma > 0.001 && scale.relative_sigma < 0.01,
            "{}",
            scale.relative_sigma
        );
        assert_eq!(
            scale.source,
            ScaleSource::CameraHeight {
                holding_height_m: 1.5,
                num_frames: 42
            }
        );
    }

    #[test]
    fn holding_heights_outside_a_sane_range_are_refused() {
        for bad in [f64::NAN, f64::INFINITY, -1.5, 0.0, 0.1, 12.0] {
            assert!(validate_holding_height_m(bad).is_err(), "{bad}");
            let mut heights = CameraHeights::default();
            (0..10).for_each(|_| heights.push(&FLOOR, DVec3::Y));
            assert!(heights.scale(bad).is_none(), "{bad}");
        }
        assert_eq!(validate_holding_height_m(1.2), Ok(1.2));
    }

    #[test]
    fn a_known_length_gives_its_scale_and_the_relative_uncertainty_of_the_distance() {
        let scale = scale_from_known_length(4.0, 0.04, 2.0, 17)
            .expect("valid")
            .expect("scale");
        assert!((scale.metres_per_unit - 0.5).abs() < 1e-12);
        assert!((scale.relative_sigma - 0.01).abs() < 1e-12);
        assert_eq!(scale.source.key(), "known_length");
        assert!(scale_from_known_length(4.0, 0.0, f64::NAN, 1).is_err());
        assert!(scale_from_known_length(4.0, 0.0, 0.0, 1).is_err());
        assert_eq!(scale_from_known_length(0.0, 0.0, 1.0, 1), Ok(None));
    }
}
