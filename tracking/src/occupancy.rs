//! World-space occupancy from several views: a sparse voxel map updated by the depth meshes of
//! keyframes, with free-space carving along the rays (log-odds, as in OctoMap), answering
//! "is this point free?" across viewpoints.
//!
//! A voxel hit by a surface sample is occupied; voxels crossed by rays before the surface are
//! free. Voxels no ray reached (inside objects, behind everything) are unknown: such a point
//! counts as inside an obstacle when every keyframe that sees its direction with a known
//! surface has it behind that surface by more than the margin. World space: metres, any
//! orientation (the map does not assume which way is up).

use std::collections::HashMap;

use glam::{Affine3A, IVec3, Vec2, Vec3};

use crate::depth_mesh::{DepthMesh, PinholeIntrinsics};

/// Tuning of the occupancy map.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OccupancyConfig {
    /// Edge of a voxel (m).
    pub voxel_size_m: f32,
    /// Sample the depth mesh every this many pixels.
    pub pixel_step: u32,
    /// Log-odds added by a surface hit and by a ray passing through.
    pub hit_log_odds: f32,
    pub miss_log_odds: f32,
    /// Clamp of the log-odds (keeps the map able to change its mind).
    pub max_abs_log_odds: f32,
    /// A point must be this far behind a keyframe's surface to count as hidden there (m).
    pub behind_margin_m: f32,
}

impl Default for OccupancyConfig {
    fn default() -> Self {
        Self {
            voxel_size_m: 0.05,
            pixel_step: 6,
            hit_log_odds: 0.85,
            miss_log_odds: -0.4,
            max_abs_log_odds: 3.5,
            behind_margin_m: 0.05,
        }
    }
}

/// What the map knows about a voxel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoxelState {
    Occupied,
    Free,
    Unknown,
}

/// A keyframe's surface, kept as a coarse depth raster for the "behind every view" test.
#[derive(Clone)]
struct KeyframeSurface {
    camera_from_world: Affine3A,
    camera: PinholeIntrinsics,
    step: u32,
    columns: u32,
    depth_m: Vec<f32>,
}

impl KeyframeSurface {
    /// `Some(true)` if the point is behind the surface, `Some(false)` if in front, `None` if
    /// this keyframe has no surface in its direction.
    fn is_behind(&self, point_in_world: Vec3, margin_m: f32) -> Option<bool> {
        let point = self.camera_from_world.transform_point3(point_in_world);
        let pixel = self.camera.pixel_from_camera(point)?;
        if !self.camera.contains(pixel) {
            return None;
        }
        let (column, row) = (
            (pixel.x / self.step as f32) as u32,
            (pixel.y / self.step as f32) as u32,
        );
        let depth = *self.depth_m.get((row * self.columns + column) as usize)?;
        (depth > 0.0).then_some(point.z > depth + margin_m)
    }
}

/// The sparse voxel map.
#[derive(Clone)]
pub struct OccupancyMap {
    config: OccupancyConfig,
    log_odds: HashMap<IVec3, f32>,
    keyframes: Vec<KeyframeSurface>,
}

impl OccupancyMap {
    pub fn new(config: OccupancyConfig) -> Self {
        Self {
            config,
            log_odds: HashMap::new(),
            keyframes: Vec::new(),
        }
    }

    pub fn num_voxels(&self) -> usize {
        self.log_odds.len()
    }

    pub fn num_keyframes(&self) -> usize {
        self.keyframes.len()
    }

    fn voxel_of(&self, point: Vec3) -> IVec3 {
        (point / self.config.voxel_size_m).floor().as_ivec3()
    }

    fn add(&mut self, voxel: IVec3, delta: f32) {
        let limit = self.config.max_abs_log_odds;
        let value = self.log_odds.entry(voxel).or_insert(0.0);
        *value = (*value + delta).clamp(-limit, limit);
    }

    /// Integrates one keyframe's depth mesh seen from `world_from_camera`.
    pub fn integrate(&mut self, mesh: &DepthMesh, world_from_camera: &Affine3A) {
        let camera = *mesh.camera();
        let step = self.config.pixel_step.max(1);
        let (columns, rows) = (camera.width.div_ceil(step), camera.height.div_ceil(step));
        let mut raster = vec![0f32; (columns * rows) as usize];
        let origin = Vec3::from(world_from_camera.translation);
        for row in 0..rows {
            for column in 0..columns {
                let pixel = Vec2::new(
                    (column * step) as f32 + 0.5 * step as f32,
                    (row * step) as f32 + 0.5 * step as f32,
                );
                let Some(depth_m) = mesh.depth_at(pixel).depth_m() else {
                    continue;
                };
                raster[(row * columns + column) as usize] = depth_m;
                let end =
                    world_from_camera.transform_point3(camera.camera_from_pixel(pixel, depth_m));
                self.carve(origin, end);
                let hit = self.voxel_of(end);
                self.add(hit, self.config.hit_log_odds);
            }
        }
        self.keyframes.push(KeyframeSurface {
            camera_from_world: world_from_camera.inverse(),
            camera,
            step,
            columns,
            depth_m: raster,
        });
    }

    /// Marks voxels along `origin → end` free, stopping one voxel short of the surface.
    fn carve(&mut self, origin: Vec3, end: Vec3) {
        let length = origin.distance(end);
        let half_voxel = 0.5 * self.config.voxel_size_m;
        let stop = length - 1.5 * self.config.voxel_size_m;
        if stop <= 0.0 {
            return;
        }
        let direction = (end - origin) / length;
        let end_voxel = self.voxel_of(end);
        let mut previous = None;
        let mut t = 0.0;
        while t < stop {
            let voxel = self.voxel_of(origin + direction * t);
            if Some(voxel) != previous && voxel != end_voxel {
                self.add(voxel, self.config.miss_log_odds);
                previous = Some(voxel);
            }
            t += half_voxel;
        }
    }

    pub fn state(&self, point_in_world: Vec3) -> VoxelState {
        match self.log_odds.get(&self.voxel_of(point_in_world)) {
            Some(&l) if l > 0.0 => VoxelState::Occupied,
            Some(&l) if l < 0.0 => VoxelState::Free,
            _ => VoxelState::Unknown,
        }
    }

    /// Whether a point is free of the scene, judged across all integrated keyframes.
    pub fn is_free(&self, point_in_world: Vec3) -> bool {
        match self.state(point_in_world) {
            VoxelState::Occupied => false,
            VoxelState::Free => true,
            VoxelState::Unknown => {
                let margin = self.config.behind_margin_m;
                let mut seen = false;
                for keyframe in &self.keyframes {
                    match keyframe.is_behind(point_in_world, margin) {
                        Some(false) => return true,
                        Some(true) => seen = true,
                        None => {}
                    }
                }
                !seen
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::depth_mesh::{DepthMeshConfig, Observation};
    use glam::Mat3;

    fn camera() -> PinholeIntrinsics {
        PinholeIntrinsics {
            width: 320,
            height: 240,
            fx: 260.0,
            fy: 260.0,
            cx: 159.5,
            cy: 119.5,
        }
    }

    /// A camera at `position` looking at the origin (world Y up).
    fn looking_at_origin(position: Vec3) -> Affine3A {
        let forward = (-position).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let down = forward.cross(right);
        Affine3A::from_mat3_translation(Mat3::from_cols(right, down, forward), position)
    }

    /// Depth mesh of a solid cube of half-size 0.3 at the origin, seen from `pose`.
    fn cube_mesh(pose: &Affine3A) -> DepthMesh {
        let cam = camera();
        let origin = Vec3::from(pose.translation);
        let mut observations = Vec::new();
        for row in 0..=24 {
            for column in 0..=32 {
                let pixel = Vec2::new(column as f32 * 9.9, row as f32 * 9.9);
                let direction = pose.transform_vector3(cam.camera_from_pixel(pixel, 1.0));
                let (mut near, mut far) = (0.0f32, f32::INFINITY);
                for axis in 0..3 {
                    let (t0, t1) = (
                        (-0.3 - origin[axis]) / direction[axis],
                        (0.3 - origin[axis]) / direction[axis],
                    );
                    near = near.max(t0.min(t1));
                    far = far.min(t0.max(t1));
                }
                if near <= far {
                    observations.push(Observation {
                        id: observations.len() as u64,
                        pixel,
                        depth_m: near,
                    });
                }
            }
        }
        let mut mesh = DepthMesh::new(cam, DepthMeshConfig::default());
        mesh.update(&observations);
        mesh
    }

    #[test]
    fn views_from_several_sides_tell_the_inside_of_a_cube_from_the_space_around_it() {
        let mut map = OccupancyMap::new(OccupancyConfig::default());
        for angle_deg in [0.0f32, 90.0, 180.0, 270.0] {
            let a = angle_deg.to_radians();
            let pose = looking_at_origin(Vec3::new(2.0 * a.sin(), 0.8, 2.0 * a.cos()));
            map.integrate(&cube_mesh(&pose), &pose);
        }
        assert_eq!(map.num_keyframes(), 4);
        for inside in [
            Vec3::ZERO,
            Vec3::new(0.15, 0.1, -0.2),
            Vec3::new(-0.2, -0.2, 0.1),
        ] {
            assert!(!map.is_free(inside), "{inside} inside the cube judged free");
        }
        // Behind the cube from the first view, but in front of it from the others.
        for outside in [
            Vec3::new(0.0, 0.0, -0.6),
            Vec3::new(0.6, 0.1, 0.0),
            Vec3::new(0.0, 0.5, 0.0),
        ] {
            assert!(
                map.is_free(outside),
                "{outside} around the cube judged occupied"
            );
        }
    }
}
