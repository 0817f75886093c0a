//! CPU ray caster: one primary ray per pixel (textures are prefiltered by the pixel
//! footprint), motion blur by averaging sub-exposure poses, exposure gain, sRGB encoding and
//! seeded sensor noise. Rows render in parallel (rayon).

use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use super::scene::Garden;
use super::texture::hash01;

/// Pinhole intrinsics without distortion (pixels).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Pinhole {
    pub width: u32,
    pub height: u32,
    pub fx: f32,
    pub fy: f32,
    pub cx: f32,
    pub cy: f32,
}

impl Pinhole {
    /// The TUM "ROS default" camera: 525 px focal length at 640 × 480, scaled to other sizes.
    pub fn tum_default(width: u32, height: u32) -> Self {
        let scale = width as f32 / 640.0;
        Self {
            width,
            height,
            fx: 525.0 * scale,
            fy: 525.0 * scale,
            cx: 0.5 * width as f32 - 0.5,
            cy: 0.5 * height as f32 - 0.5,
        }
    }

    /// Unit ray direction through pixel centre (u, v), in camera space.
    fn ray_in_camera(&self, u: f32, v: f32) -> Vec3 {
        Vec3::new((u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0).normalize()
    }
}

/// How one colour frame is exposed.
#[derive(Clone, Debug)]
pub struct Exposure {
    /// Camera poses spread over the shutter interval (one = no motion blur).
    pub world_from_camera: Vec<Affine3A>,
    /// Linear gain applied before encoding.
    pub gain: f32,
    /// Standard deviation of the sensor noise, in 8-bit levels.
    pub noise_sigma: f32,
    pub noise_seed: u32,
}

const MAX_DISTANCE_M: f32 = 60.0;

fn sky(direction_in_world: Vec3) -> Vec3 {
    let up = direction_in_world.y.clamp(0.0, 1.0);
    Vec3::new(0.75, 0.82, 0.92).lerp(Vec3::new(0.35, 0.52, 0.85), up)
}

/// Linear radiance along one ray.
fn trace(garden: &Garden, origin: Vec3, direction: Vec3, pixel_angle: f32) -> Vec3 {
    match garden.intersect(origin, direction, MAX_DISTANCE_M) {
        Some(hit) => {
            let incidence = hit.normal.dot(direction).abs().max(0.05);
            let footprint_m = hit.distance * pixel_angle / incidence.sqrt();
            garden.shade(&hit, footprint_m)
        }
        None => sky(direction),
    }
}

fn encode_srgb(linear: f32) -> f32 {
    let v = linear.max(0.0);
    let v = v / (1.0 + 0.12 * v);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Renders an RGB8 frame (row-major, 3 bytes per pixel).
pub fn render_rgb(garden: &Garden, camera: &Pinhole, exposure: &Exposure) -> Vec<u8> {
    let (width, height) = (camera.width as usize, camera.height as usize);
    let pixel_angle = 1.0 / camera.fx;
    let poses = &exposure.world_from_camera;
    let weight = 1.0 / poses.len().max(1) as f32;
    let mut pixels = vec![0u8; width * height * 3];
    pixels
        .par_chunks_mut(width * 3)
        .enumerate()
        .for_each(|(row, line)| {
            for column in 0..width {
                let ray = camera.ray_in_camera(column as f32, row as f32);
                let mut radiance = Vec3::ZERO;
                for pose in poses {
                    let direction = pose.transform_vector3(ray);
                    radiance += trace(garden, pose.translation.into(), direction, pixel_angle);
                }
                let radiance = radiance * weight * exposure.gain;
                for channel in 0..3 {
                    let (x, y) = (column as i32, row as i32);
                    let seed = exposure
                        .noise_seed
                        .wrapping_add(channel as u32 * 0x1000_0001);
                    let u1 = hash01(x, y, seed).max(1e-7);
                    let u2 = hash01(x, y, seed ^ 0x5555_5555);
                    let gaussian = (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos();
                    let level =
                        encode_srgb(radiance[channel]) * 255.0 + exposure.noise_sigma * gaussian;
                    line[column * 3 + channel] = level.round().clamp(0.0, 255.0) as u8;
                }
            }
        });
    pixels
}

/// Renders the depth map (camera Z in metres, 0 where nothing was hit) for one pose.
pub fn render_depth_m(garden: &Garden, camera: &Pinhole, world_from_camera: &Affine3A) -> Vec<f32> {
    let (width, height) = (camera.width as usize, camera.height as usize);
    let origin: Vec3 = world_from_camera.translation.into();
    let mut depth = vec![0f32; width * height];
    depth
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, line)| {
            for (column, value) in line.iter_mut().enumerate() {
                let ray = camera.ray_in_camera(column as f32, row as f32);
                let direction = world_from_camera.transform_vector3(ray);
                if let Some(hit) = garden.intersect(origin, direction, MAX_DISTANCE_M) {
                    *value = hit.distance * ray.z;
                }
            }
        });
    depth
}

/// Value of a tree-mask pixel showing foliage, and wood (0 = not the tree).
pub const MASK_FOLIAGE: u8 = 255;
pub const MASK_WOOD: u8 = 128;

/// The tree's silhouette for one pose, one ray per pixel centre (nothing in the gardens stands
/// between the walk and the tree): [`MASK_FOLIAGE`], [`MASK_WOOD`] or 0 per pixel, row-major.
pub fn render_tree_mask(
    tree: &super::SynthTree,
    camera: &Pinhole,
    world_from_camera: &Affine3A,
) -> Vec<u8> {
    let (width, height) = (camera.width as usize, camera.height as usize);
    let origin: Vec3 = world_from_camera.translation.into();
    let mut mask = vec![0u8; width * height];
    mask.par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, line)| {
            for (column, value) in line.iter_mut().enumerate() {
                let ray = camera.ray_in_camera(column as f32, row as f32);
                let direction = world_from_camera.transform_vector3(ray);
                if let Some(hit) = tree.bvh.intersect(origin, direction, MAX_DISTANCE_M) {
                    *value = match hit.part {
                        super::tree::TreePart::Foliage => MASK_FOLIAGE,
                        super::tree::TreePart::Wood => MASK_WOOD,
                    };
                }
            }
        });
    mask
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::scene::Ground;
    use glam::Mat3;

    #[test]
    fn depth_of_a_camera_looking_straight_down_equals_its_height() {
        let garden = Garden::new(Ground::sloped(0.0), 1);
        let camera = Pinhole::tum_default(64, 48);
        // Looking down: camera Z = world −Y, camera X = world X, camera Y = world Z... (right-handed)
        let rotation = Mat3::from_cols(Vec3::X, Vec3::Z, Vec3::NEG_Y);
        let pose = Affine3A::from_mat3_translation(rotation, Vec3::new(-1.0, 1.5, 4.0));
        let depth = render_depth_m(&garden, &camera, &pose);
        assert!(
            depth.iter().all(|&z| (z - 1.5).abs() < 1e-4),
            "depth {:?}",
            &depth[..4]
        );
    }

    #[test]
    fn frames_with_the_same_seed_are_identical() {
        let garden = Garden::new(Ground::sloped(0.0), 1);
        let camera = Pinhole::tum_default(64, 48);
        let rotation = Mat3::from_cols(Vec3::X, Vec3::Z, Vec3::NEG_Y);
        let pose = Affine3A::from_mat3_translation(rotation, Vec3::new(-1.0, 1.5, 4.0));
        let exposure = Exposure {
            world_from_camera: vec![pose],
            gain: 1.0,
            noise_sigma: 2.0,
            noise_seed: 9,
        };
        let a = render_rgb(&garden, &camera, &exposure);
        assert_eq!(a, render_rgb(&garden, &camera, &exposure));
        let spread =
            a.iter().map(|&v| v as i32).max().unwrap() - a.iter().map(|&v| v as i32).min().unwrap();
        assert!(spread > 60, "texture too flat: spread {spread}");
    }
}
