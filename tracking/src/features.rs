//! Feature tracks: corners followed from frame to frame by Lucas–Kanade, either attached to a
//! map point or waiting (as candidates) for enough parallax to be triangulated.

use crate::camera::Camera;
use crate::pose::Se3;
use glam::{DVec2, DVec3, Vec2};

/// Where a candidate track was first seen.
#[derive(Clone, Copy, Debug)]
pub struct TrackOrigin {
    pub keyframe: usize,
    pub pixel: Vec2,
    pub normalized: DVec2,
}

/// A corner followed through the footage.
#[derive(Clone, Copy, Debug)]
pub struct Track {
    /// Raw pixel in the latest frame.
    pub pixel: Vec2,
    /// The map point it sees, once triangulated.
    pub point: Option<u64>,
    /// The keyframe it was born in, while it is a candidate.
    pub origin: Option<TrackOrigin>,
}

/// Angle (radians) between the rays of a normalised coordinate seen from two poses.
pub fn parallax_rad(
    first: &Se3,
    first_normalized: DVec2,
    second: &Se3,
    second_normalized: DVec2,
) -> f64 {
    let ray1 = first.rotation.inverse() * first_normalized.extend(1.0);
    let ray2 = second.rotation.inverse() * second_normalized.extend(1.0);
    ray1.angle_between(ray2)
}

/// Midpoint triangulation of two rays given by `camera_from_world` poses and normalised
/// coordinates. None for (near-)parallel rays.
pub fn triangulate(
    first: &Se3,
    first_normalized: DVec2,
    second: &Se3,
    second_normalized: DVec2,
) -> Option<DVec3> {
    let (w1, w2) = (first.inverse(), second.inverse());
    let (c1, c2) = (w1.translation, w2.translation);
    let d1 = (w1.rotation * first_normalized.extend(1.0)).normalize();
    let d2 = (w2.rotation * second_normalized.extend(1.0)).normalize();
    // Minimise |c1 + a d1 − c2 − b d2|².
    let r = c2 - c1;
    let b12 = d1.dot(d2);
    let det = 1.0 - b12 * b12;
    if det < 1e-10 {
        return None;
    }
    let (r1, r2) = (r.dot(d1), r.dot(d2));
    let a = (r1 - b12 * r2) / det;
    let b = (b12 * r1 - r2) / det;
    let point = 0.5 * ((c1 + a * d1) + (c2 + b * d2));
    point.is_finite().then_some(point)
}

/// Normalised coordinates of a track's pixel.
pub fn normalized(camera: &Camera, pixel: Vec2) -> DVec2 {
    camera.normalized_from_pixel(pixel.as_dvec2())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    #[test]
    fn triangulating_two_exact_rays_recovers_the_point() {
        let point = DVec3::new(0.3, -0.2, 4.0);
        let first = Se3::IDENTITY;
        let second = Se3::new(DQuat::from_rotation_y(0.1), DVec3::new(-0.5, 0.05, 0.1));
        let project = |pose: &Se3| {
            let pc = pose.transform_point(point);
            DVec2::new(pc.x / pc.z, pc.y / pc.z)
        };
        let found =
            triangulate(&first, project(&first), &second, project(&second)).expect("rays meet");
        assert!((found - point).length() < 1e-9, "found {found}");
        assert!(parallax_rad(&first, project(&first), &second, project(&second)) > 0.05);
    }
}
