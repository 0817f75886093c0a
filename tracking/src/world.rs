//! The world frame: the map (arbitrary unit, first camera at the origin) placed on the ground
//! plane. World origin = centroid of the plane inliers projected on the plane, world Y = plane
//! normal towards the camera, metres. Fixed once set, so a planted tree never moves; the plane
//! itself keeps being refined as points arrive.

use crate::frame::Plane;
use crate::ground_plane::{OrientedPlaneEstimator, PlaneEstimator, RansacConfig, fit_plane};
use crate::linalg::Similarity;
use crate::pose::Se3;
use crate::scale::{ScaleSource, scale_from_camera_height};
use glam::{DAffine3, DQuat, DVec3};

/// Largest angle between a fitted plane and gravity's "up" accepted as ground, degrees.
pub const MAX_GROUND_TILT_DEG: f64 = 30.0;

/// The map placed in the world.
#[derive(Clone, Debug)]
pub struct WorldFrame {
    /// Map coordinates to world metres.
    pub world_from_map: Similarity,
    /// The ground plane in map coordinates (refined over time).
    pub plane_in_map: Plane,
    pub scale_source: ScaleSource,
    /// Whether gravity (accelerometer) chose the plane.
    pub gravity_used: bool,
}

impl WorldFrame {
    /// Fits the ground plane to map points and fixes the world frame. `camera_center` is the
    /// current camera in the map; `up` the gravity-up direction in the map when known.
    pub fn from_points(
        points: &[DVec3],
        camera_center: DVec3,
        up: Option<DVec3>,
        holding_height_m: f64,
    ) -> Option<Self> {
        let spread = median_distance(points, camera_center)?;
        let config = RansacConfig {
            threshold: 0.02 * spread,
            min_inliers: 8,
            ..RansacConfig::default()
        };
        let towards_camera = |centroid: DVec3| camera_center - centroid;
        let centroid = points.iter().copied().sum::<DVec3>() / points.len() as f64;
        let orient = up.unwrap_or_else(|| towards_camera(centroid));
        let mut fit = fit_plane(&PlaneEstimator, points, &config, orient);
        let mut gravity_used = false;
        if let Some(up) = up {
            let tilted = fit.as_ref().is_none_or(|f| {
                f.model.normal.angle_between(up).to_degrees() > MAX_GROUND_TILT_DEG
            });
            if tilted {
                // No plane agrees with gravity: the lowest well-supported horizontal plane.
                let oriented = OrientedPlaneEstimator { normal: up };
                fit = fit_plane(&oriented, points, &config, up);
                if let Some(f) = fit.as_mut() {
                    f.model.normal = up;
                }
            }
            gravity_used = true;
        }
        let fit = fit?;
        let mut plane = fit.model;
        if plane.signed_distance(camera_center) < 0.0 {
            plane = Plane {
                normal: -plane.normal,
                offset: -plane.offset,
            };
        }
        let inliers: Vec<DVec3> = fit.inliers.iter().map(|&i| points[i]).collect();
        let inlier_centroid = inliers.iter().copied().sum::<DVec3>() / inliers.len().max(1) as f64;
        let origin = inlier_centroid - plane.normal * plane.signed_distance(inlier_centroid);
        let scale = scale_from_camera_height(&plane, camera_center, holding_height_m)?;
        let rotation = DQuat::from_rotation_arc(plane.normal, DVec3::Y);
        let world_from_map = Similarity {
            scale,
            rotation,
            translation: -scale * (rotation * origin),
        };
        Some(Self {
            world_from_map,
            plane_in_map: plane,
            scale_source: ScaleSource::CameraHeight {
                holding_height_m,
                num_frames: 1,
            },
            gravity_used,
        })
    }

    /// `world_from_camera` of a camera pose given in the map.
    pub fn world_from_camera(&self, map_from_camera: &Se3) -> DAffine3 {
        let s = &self.world_from_map;
        DAffine3::from_rotation_translation(
            s.rotation * map_from_camera.rotation,
            s.transform_point(map_from_camera.translation),
        )
    }

    /// The current ground plane in world coordinates.
    pub fn plane_in_world(&self) -> Plane {
        let s = &self.world_from_map;
        let normal = (s.rotation * self.plane_in_map.normal).normalize();
        let on_plane = s.transform_point(self.plane_in_map.normal * self.plane_in_map.offset);
        Plane {
            normal,
            offset: normal.dot(on_plane),
        }
    }

    /// Refits the plane to the current map points without moving the world frame.
    pub fn refine(&mut self, points: &[DVec3]) {
        let spread = points
            .iter()
            .map(|p| self.plane_in_map.signed_distance(*p).abs())
            .fold(0.0, f64::max);
        if points.len() < 8 || spread <= 0.0 {
            return;
        }
        let threshold = 0.02 / self.world_from_map.scale;
        let near: Vec<DVec3> = points
            .iter()
            .copied()
            .filter(|p| self.plane_in_map.signed_distance(*p).abs() <= threshold * 2.0)
            .collect();
        if let Some(plane) = crate::ground_plane::refine_plane(&near, self.plane_in_map.normal)
            && near.len() >= 8
        {
            self.plane_in_map = plane;
        }
    }
}

fn median_distance(points: &[DVec3], from: DVec3) -> Option<f64> {
    if points.len() < 8 {
        return None;
    }
    let mut d: Vec<f64> = points.iter().map(|p| p.distance(from)).collect();
    d.sort_by(f64::total_cmp);
    Some(d[d.len() / 2])
}
