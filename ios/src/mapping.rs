//! ARKit's values as the app's platform frame, with no ARKit call in sight (so the mapping is
//! tested on the host). ARKit's simd matrices are column-major: a camera `transform` is an
//! OpenGL-style camera (X right, Y up, looking along -Z, in the sensor's landscape orientation)
//! in a gravity-aligned world (Y up, metres); `intrinsics` is the 3 × 3 camera matrix of the
//! captured image (columns `[fx 0 0] [0 fy 0] [cx cy 1]`); a plane anchor's normal is its
//! transform's Y axis and its `center` is in the anchor's own frame; the light estimate is an
//! ambient intensity in lumen (1000 neutral) and a colour temperature in kelvin (6500 neutral).

use glam::{Mat4, Vec3, Vec4};
use sylva_app::platform::{
    FeaturePoint, LightEstimate, PlatformIntrinsics, PlatformPlane, world_from_camera_of_gl,
};

/// A simd_float4x4's columns as a matrix.
pub fn mat4_of_columns(columns: [[f32; 4]; 4]) -> Mat4 {
    Mat4::from_cols(
        Vec4::from_array(columns[0]),
        Vec4::from_array(columns[1]),
        Vec4::from_array(columns[2]),
        Vec4::from_array(columns[3]),
    )
}

/// ARKit's camera transform as Sylva's `world_from_camera`.
pub fn world_from_camera_of_arkit(transform: [[f32; 4]; 4]) -> Mat4 {
    world_from_camera_of_gl(mat4_of_columns(transform))
}

/// ARKit's intrinsics (columns of the 3 × 3 camera matrix; the fourth lane of each simd_float3
/// is padding) and image resolution as the platform's intrinsics; None for an empty image.
pub fn intrinsics_of_arkit(
    columns: [[f32; 4]; 3],
    resolution: [f64; 2],
) -> Option<PlatformIntrinsics> {
    let (fx, fy) = (columns[0][0], columns[1][1]);
    let (cx, cy) = (columns[2][0], columns[2][1]);
    let size_ok = resolution.iter().all(|s| s.is_finite() && *s >= 1.0);
    (size_ok && [fx, fy].iter().all(|f| f.is_finite() && *f > 0.0)).then(|| PlatformIntrinsics {
        width: resolution[0].round() as u32,
        height: resolution[1].round() as u32,
        fx: f64::from(fx),
        fy: f64::from(fy),
        cx: f64::from(cx),
        cy: f64::from(cy),
    })
}

/// `rawFeaturePoints`: world points (simd_float3, padded to four lanes) with their identifiers.
pub fn feature_points_of_arkit(points: &[[f32; 4]], identifiers: &[u64]) -> Vec<FeaturePoint> {
    points
        .iter()
        .zip(identifiers)
        .map(|(p, id)| FeaturePoint {
            id: *id,
            point_in_world: Vec3::new(p[0], p[1], p[2]),
        })
        .filter(|p| p.point_in_world.is_finite())
        .collect()
}

/// An `ARPlaneAnchor`: its transform, its centre in the anchor's frame, and its extent (width
/// along the anchor's X, height along its Z); `id` tells anchors apart.
pub fn plane_of_arkit(
    id: u64,
    transform: [[f32; 4]; 4],
    center: [f32; 4],
    extent_m: [f32; 2],
) -> PlatformPlane {
    let world_from_anchor = mat4_of_columns(transform);
    PlatformPlane {
        id,
        center_in_world: world_from_anchor
            .transform_point3(Vec3::new(center[0], center[1], center[2])),
        normal_in_world: world_from_anchor.y_axis.truncate().normalize_or_zero(),
        extent_m,
    }
}

/// Linear RGB of a black body at `kelvin` (Tanner Helland's fit of the CIE data, 1000–40000 K).
fn rgb_of_temperature(kelvin: f32) -> [f32; 3] {
    let t = kelvin.clamp(1000.0, 40000.0) / 100.0;
    let red = if t <= 66.0 {
        255.0
    } else {
        329.698_73 * (t - 60.0).powf(-0.133_204_76)
    };
    let green = if t <= 66.0 {
        99.470_8 * t.ln() - 161.119_57
    } else {
        288.122_17 * (t - 60.0).powf(-0.075_514_85)
    };
    let blue = if t >= 66.0 {
        255.0
    } else if t <= 19.0 {
        0.0
    } else {
        138.517_73 * (t - 10.0).ln() - 305.044_8
    };
    [red, green, blue].map(|c| c.clamp(0.0, 255.0) / 255.0)
}

/// ARKit's light estimate (lumen, kelvin) as gains relative to a neutral scene (1000 lm,
/// 6500 K).
pub fn light_of_arkit(ambient_intensity_lm: f64, color_temperature_k: f64) -> LightEstimate {
    let neutral = rgb_of_temperature(6500.0);
    let measured = rgb_of_temperature(color_temperature_k as f32);
    LightEstimate {
        ambient_intensity: (ambient_intensity_lm / 1000.0) as f32,
        color_correction: [0, 1, 2].map(|i| measured[i] / neutral[i].max(1e-3)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const IDENTITY: [[f32; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];

    #[test]
    fn an_arkit_camera_at_rest_looks_along_minus_z_of_the_world() {
        let mut transform = IDENTITY;
        transform[3] = [0.2, 1.5, 0.0, 1.0];
        let world_from_camera = world_from_camera_of_arkit(transform);
        let ahead = world_from_camera.transform_point3(Vec3::new(0.0, 0.0, 2.0));
        assert!(
            (ahead - Vec3::new(0.2, 1.5, -2.0)).length() < 1e-6,
            "{ahead}"
        );
    }

    #[test]
    fn the_intrinsics_matrix_is_read_by_columns() {
        let columns = [
            [1450.0, 0.0, 0.0, 0.0],
            [0.0, 1451.0, 0.0, 0.0],
            [959.5, 719.5, 1.0, 0.0],
        ];
        let k = intrinsics_of_arkit(columns, [1920.0, 1440.0]).expect("valid");
        assert_eq!((k.width, k.height), (1920, 1440));
        assert_eq!((k.fx, k.fy, k.cx, k.cy), (1450.0, 1451.0, 959.5, 719.5));
        assert!(intrinsics_of_arkit(columns, [0.0, 1440.0]).is_none());
    }

    #[test]
    fn a_plane_anchors_centre_is_moved_into_the_world_and_its_normal_is_up() {
        let mut transform = IDENTITY;
        transform[3] = [1.0, -1.4, -2.0, 1.0];
        let plane = plane_of_arkit(3, transform, [0.5, 0.0, -0.25, 0.0], [2.0, 1.0]);
        assert_eq!(plane.center_in_world, Vec3::new(1.5, -1.4, -2.25));
        assert_eq!(plane.normal_in_world, Vec3::Y);
        let points = feature_points_of_arkit(&[[0.0, 1.0, 2.0, 0.0], [f32::NAN; 4]], &[11, 12]);
        assert_eq!(points.len(), 1);
        assert_eq!(points[0].id, 11);
    }

    #[test]
    fn neutral_light_is_unit_and_warm_light_is_redder() {
        let neutral = light_of_arkit(1000.0, 6500.0);
        assert!((neutral.ambient_intensity - 1.0).abs() < 1e-6);
        assert!(
            neutral
                .color_correction
                .iter()
                .all(|g| (g - 1.0).abs() < 1e-6)
        );
        let warm = light_of_arkit(500.0, 3000.0).color_correction;
        assert!(warm[0] >= 1.0 && warm[2] < 0.8, "{warm:?}");
    }
}
