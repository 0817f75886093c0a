//! Cameras for drawing: pinhole intrinsics with the OpenCV distortion model, and the matrices that
//! take world points to wgpu clip space.
//!
//! Camera space follows the tracker (OpenCV convention): X right, Y down, Z forward, metres.
//! World space: metres, Y up, origin on the ground plane.

use glam::{Mat4, Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};

/// Pinhole intrinsics of an image, pixels, with radial-tangential distortion
/// (`k1 k2 p1 p2 k3`, OpenCV order).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Intrinsics {
    pub width: u32,
    pub height: u32,
    pub fx: f32,
    pub fy: f32,
    pub cx: f32,
    pub cy: f32,
    pub distortion: [f32; 5],
}

impl Intrinsics {
    /// An undistorted camera with the given horizontal field of view (radians).
    pub fn from_fov(width: u32, height: u32, horizontal_fov: f32) -> Self {
        let fx = 0.5 * width as f32 / (0.5 * horizontal_fov).tan();
        Intrinsics {
            width,
            height,
            fx,
            fy: fx,
            cx: 0.5 * width as f32,
            cy: 0.5 * height as f32,
            distortion: [0.0; 5],
        }
    }

    /// The same camera for an image scaled to `width` × `height`.
    pub fn scaled_to(&self, width: u32, height: u32) -> Self {
        let sx = width as f32 / self.width as f32;
        let sy = height as f32 / self.height as f32;
        Intrinsics {
            width,
            height,
            fx: self.fx * sx,
            fy: self.fy * sy,
            cx: self.cx * sx,
            cy: self.cy * sy,
            distortion: self.distortion,
        }
    }

    /// Pixel of an (undistorted, ideal) camera-space point; `None` behind the camera.
    pub fn pixel_from_camera(&self, point_in_camera: Vec3) -> Option<Vec2> {
        if point_in_camera.z <= 1e-6 {
            return None;
        }
        Some(Vec2::new(
            self.fx * point_in_camera.x / point_in_camera.z + self.cx,
            self.fy * point_in_camera.y / point_in_camera.z + self.cy,
        ))
    }

    /// Unit-depth ray (z = 1) through an ideal pixel, camera space.
    pub fn ray_from_pixel(&self, pixel: Vec2) -> Vec3 {
        Vec3::new(
            (pixel.x - self.cx) / self.fx,
            (pixel.y - self.cy) / self.fy,
            1.0,
        )
    }

    /// Where an ideal normalized point (x/z, y/z) lands in the distorted image (normalized).
    pub fn distort_normalized(&self, ideal: Vec2) -> Vec2 {
        let [k1, k2, p1, p2, k3] = self.distortion;
        let (x, y) = (ideal.x, ideal.y);
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        Vec2::new(
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )
    }
}

/// A camera placed in the world, for drawing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewCamera {
    pub intrinsics: Intrinsics,
    /// `point_in_world = world_from_camera * point_in_camera` (camera: X right, Y down, Z forward).
    pub world_from_camera: Mat4,
    pub near: f32,
    pub far: f32,
}

impl ViewCamera {
    pub fn new(intrinsics: Intrinsics, world_from_camera: Mat4) -> Self {
        ViewCamera {
            intrinsics,
            world_from_camera,
            near: 0.05,
            far: 100.0,
        }
    }

    /// A camera at `eye` looking at `target`, world Y up on screen.
    pub fn looking_at(intrinsics: Intrinsics, eye: Vec3, target: Vec3) -> Self {
        let forward = (target - eye).try_normalize().unwrap_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X);
        let down = forward.cross(right);
        let world_from_camera = Mat4::from_cols(
            right.extend(0.0),
            down.extend(0.0),
            forward.extend(0.0),
            eye.extend(1.0),
        );
        ViewCamera::new(intrinsics, world_from_camera)
    }

    pub fn camera_from_world(&self) -> Mat4 {
        self.world_from_camera.inverse()
    }

    pub fn position(&self) -> Vec3 {
        self.world_from_camera.w_axis.truncate()
    }

    /// wgpu clip space (depth 0 at `near`, 1 at `far`) from camera space.
    pub fn clip_from_camera(&self) -> Mat4 {
        let k = &self.intrinsics;
        let (w, h) = (k.width as f32, k.height as f32);
        let (n, f) = (self.near, self.far);
        Mat4::from_cols(
            Vec4::new(2.0 * k.fx / w, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -2.0 * k.fy / h, 0.0, 0.0),
            Vec4::new(2.0 * k.cx / w - 1.0, 1.0 - 2.0 * k.cy / h, f / (f - n), 1.0),
            Vec4::new(0.0, 0.0, -f * n / (f - n), 0.0),
        )
    }

    pub fn clip_from_world(&self) -> Mat4 {
        self.clip_from_camera() * self.camera_from_world()
    }

    /// Ideal pixel of a world point; `None` behind the camera.
    pub fn pixel_from_world(&self, point_in_world: Vec3) -> Option<Vec2> {
        let point_in_camera = self.camera_from_world().transform_point3(point_in_world);
        self.intrinsics.pixel_from_camera(point_in_camera)
    }

    /// Camera-space depth (Z) of a world point.
    pub fn depth_of(&self, point_in_world: Vec3) -> f32 {
        self.camera_from_world().transform_point3(point_in_world).z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_space_agrees_with_pixel_projection() {
        let k = Intrinsics::from_fov(640, 480, 1.0);
        let cam = ViewCamera::looking_at(k, Vec3::new(1.0, 1.5, 3.0), Vec3::ZERO);
        let p = Vec3::new(0.2, 0.4, -0.1);
        let clip = cam.clip_from_world() * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let px = cam.pixel_from_world(p).expect("in front");
        assert!((((ndc.x + 1.0) * 0.5 * 640.0) - px.x).abs() < 1e-2);
        assert!((((1.0 - ndc.y) * 0.5 * 480.0) - px.y).abs() < 1e-2);
        assert!(ndc.z > 0.0 && ndc.z < 1.0);
    }

    #[test]
    fn looking_at_puts_the_target_at_the_principal_point_with_up_on_top() {
        let k = Intrinsics::from_fov(640, 480, 1.0);
        let cam = ViewCamera::looking_at(k, Vec3::new(0.0, 1.0, 4.0), Vec3::new(0.0, 1.0, 0.0));
        let centre = cam
            .pixel_from_world(Vec3::new(0.0, 1.0, 0.0))
            .expect("in front");
        assert!((centre - Vec2::new(320.0, 240.0)).length() < 1e-3);
        let above = cam
            .pixel_from_world(Vec3::new(0.0, 2.0, 0.0))
            .expect("in front");
        assert!(
            above.y < 240.0,
            "world up must be up on screen, got {above}"
        );
        let right = cam
            .pixel_from_world(Vec3::new(1.0, 1.0, 0.0))
            .expect("in front");
        assert!(right.x > 320.0);
    }
}
