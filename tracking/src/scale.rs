//! Metric scale for a monocular map (whose unit is arbitrary): from the camera's height above the
//! ground plane and the height the user holds the phone at, or from a known distance between two
//! picked points.

use crate::frame::Plane;
use glam::DVec3;

/// Default holding height of a phone above the ground, metres.
pub const DEFAULT_HOLDING_HEIGHT_M: f64 = 1.5;

/// Where the metric scale came from (reported).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ScaleSource {
    /// Camera height above the plane taken as `holding_height_m`.
    CameraHeight { holding_height_m: f64 },
    /// Two picked points `distance_m` apart.
    KnownDistance { distance_m: f64 },
}

impl std::fmt::Display for ScaleSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::CameraHeight { holding_height_m } => {
                write!(
                    f,
                    "the camera's height (held {holding_height_m} m above the ground)"
                )
            }
            Self::KnownDistance { distance_m } => {
                write!(f, "two picked points {distance_m} m apart")
            }
        }
    }
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
    (d > 1e-12 && distance_m > 0.0).then(|| distance_m / d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_two_units_above_the_plane_held_at_one_and_a_half_metres_gives_0_75() {
        let plane = Plane {
            normal: DVec3::Y,
            offset: 0.0,
        };
        let s = scale_from_camera_height(&plane, DVec3::new(3.0, 2.0, -1.0), 1.5).expect("scale");
        assert!((s - 0.75).abs() < 1e-12);
        assert!(scale_from_known_distance(DVec3::ZERO, DVec3::X * 4.0, 2.0) == Some(0.5));
    }
}
