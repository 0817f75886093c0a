//! ARCore's values as the app's platform frame, with no ARCore call in sight (so the mapping is
//! tested on the host): poses are column-major 4 × 4 matrices of an OpenGL-style camera (X
//! right, Y up, looking along -Z) in a gravity-aligned world (Y up, metres); the point cloud is
//! `x, y, z, confidence` per point with an `int32` id each; a plane's centre pose has the
//! plane's normal as its local Y axis; the ambient light is a pixel intensity (0.5 neutral)
//! with an RGB colour correction.

use glam::{Mat4, Vec3};
use sylva_app::platform::{
    FeaturePoint, LightEstimate, PlatformIntrinsics, PlatformPlane, world_from_camera_of_gl,
};

/// ARCore's camera pose matrix as Sylva's `world_from_camera`.
pub fn world_from_camera_of_arcore(pose_col_major: &[f32; 16]) -> Mat4 {
    world_from_camera_of_gl(Mat4::from_cols_array(pose_col_major))
}

/// ARCore's image intrinsics (focal length, principal point, image size in pixels of the CPU
/// image) as the platform's intrinsics; None when ARCore reports an empty image.
pub fn intrinsics_of_arcore(
    focal: [f32; 2],
    principal: [f32; 2],
    size: [i32; 2],
) -> Option<PlatformIntrinsics> {
    let (width, height) = (u32::try_from(size[0]).ok()?, u32::try_from(size[1]).ok()?);
    (width > 0 && height > 0 && focal.iter().all(|f| f.is_finite() && *f > 0.0)).then_some(
        PlatformIntrinsics {
            width,
            height,
            fx: f64::from(focal[0]),
            fy: f64::from(focal[1]),
            cx: f64::from(principal[0]),
            cy: f64::from(principal[1]),
        },
    )
}

/// ARCore's point cloud (`x, y, z, confidence` per point, world space) with its ids.
pub fn feature_points_of_arcore(data: &[f32], ids: &[i32]) -> Vec<FeaturePoint> {
    data.chunks_exact(4)
        .zip(ids)
        .map(|(p, id)| FeaturePoint {
            // ids are non-negative; the cast keeps them distinct either way.
            id: u64::from(*id as u32),
            point_in_world: Vec3::new(p[0], p[1], p[2]),
        })
        .filter(|p| p.point_in_world.is_finite())
        .collect()
}

/// A plane from its centre pose (column-major; local Y is the normal) and extents along its
/// local X and Z axes; `id` tells planes apart (ARCore's handle of the plane).
pub fn plane_of_arcore(
    id: u64,
    center_pose_col_major: &[f32; 16],
    extent_m: [f32; 2],
) -> PlatformPlane {
    let pose = Mat4::from_cols_array(center_pose_col_major);
    PlatformPlane {
        id,
        center_in_world: pose.w_axis.truncate(),
        normal_in_world: pose.y_axis.truncate().normalize_or_zero(),
        extent_m,
    }
}

/// ARCore's ambient light (pixel intensity, 0.5 for a neutrally lit scene; colour correction
/// RGB gains and a fourth, the pixel intensity again, which is dropped).
pub fn light_of_arcore(pixel_intensity: f32, color_correction: [f32; 4]) -> LightEstimate {
    LightEstimate {
        ambient_intensity: pixel_intensity / 0.5,
        color_correction: [
            color_correction[0],
            color_correction[1],
            color_correction[2],
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_arcore_camera_looking_at_the_horizon_sees_ahead_along_plus_z() {
        // Held upright 1.4 m above the origin, looking along the world's -Z.
        let pose = Mat4::from_translation(Vec3::new(0.0, 1.4, 0.0)).to_cols_array();
        let world_from_camera = world_from_camera_of_arcore(&pose);
        let ahead = world_from_camera.transform_point3(Vec3::new(0.0, 0.0, 3.0));
        assert!(
            (ahead - Vec3::new(0.0, 1.4, -3.0)).length() < 1e-6,
            "{ahead}"
        );
        // An image row further down looks at the ground.
        let down = world_from_camera.transform_vector3(Vec3::Y);
        assert!(down.y < -0.99, "{down}");
    }

    #[test]
    fn the_point_cloud_keeps_each_points_id_and_drops_confidence() {
        let data = [
            0.1,
            0.2,
            -1.0,
            0.9,
            1.0,
            f32::NAN,
            0.0,
            0.5,
            -0.5,
            0.0,
            -2.0,
            0.7,
        ];
        let points = feature_points_of_arcore(&data, &[7, 8, 9]);
        assert_eq!(points.len(), 2, "the NaN point is dropped");
        assert_eq!((points[0].id, points[1].id), (7, 9));
        assert_eq!(points[1].point_in_world, Vec3::new(-0.5, 0.0, -2.0));
    }

    #[test]
    fn a_floor_planes_normal_is_its_poses_y_axis() {
        let pose = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(0.5, -1.3, -2.0),
        )
        .to_cols_array();
        let plane = plane_of_arcore(42, &pose, [2.0, 3.0]);
        assert!((plane.normal_in_world - Vec3::Y).length() < 1e-6);
        assert_eq!(plane.center_in_world, Vec3::new(0.5, -1.3, -2.0));
        assert_eq!((plane.id, plane.extent_m), (42, [2.0, 3.0]));
    }

    #[test]
    fn intrinsics_and_light_map_to_the_app_units() {
        let k = intrinsics_of_arcore([500.0, 501.0], [319.5, 239.5], [640, 480]).expect("valid");
        assert_eq!((k.width, k.height, k.fx, k.cy), (640, 480, 500.0, 239.5));
        assert!(intrinsics_of_arcore([0.0, 1.0], [0.0, 0.0], [640, 480]).is_none());
        let light = light_of_arcore(0.25, [1.0, 0.9, 0.8, 0.25]);
        assert_eq!(light.ambient_intensity, 0.5);
        assert_eq!(light.color_correction, [1.0, 0.9, 0.8]);
    }
}
