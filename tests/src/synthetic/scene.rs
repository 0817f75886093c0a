//! The synthetic garden: a (possibly sloped) ground plane with a brick wall and a wooden box.
//!
//! World space: metres, Y up, the planting spot at the origin on the ground. Blocks are
//! axis-aligned boxes that reach below the ground, so on a slope they stand in it like real
//! walls; their tops are level.

use glam::{Vec2, Vec3};
use serde::Serialize;

use super::texture;
use super::tree::SynthTree;
use super::tree_bvh::TreeHit;

/// What a block is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BlockMaterial {
    Brick,
    Planks,
}

/// An axis-aligned box in world space.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Block {
    pub name: &'static str,
    pub min: Vec3,
    pub max: Vec3,
    pub material: BlockMaterial,
}

/// The ground: points `p` with `normal · p = 0` (it passes through the planting spot).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Ground {
    pub normal: Vec3,
    pub slope_deg: f32,
}

impl Ground {
    /// A ground rising by `slope_deg` towards −Z (away from where the walk starts).
    pub fn sloped(slope_deg: f32) -> Self {
        let slope = slope_deg.to_radians();
        Self {
            normal: Vec3::new(0.0, slope.cos(), slope.sin()),
            slope_deg,
        }
    }

    /// Height of the ground above the world origin at horizontal position (x, z).
    pub fn height_at(&self, x: f32, z: f32) -> f32 {
        -(self.normal.x * x + self.normal.z * z) / self.normal.y
    }

    /// In-plane texture coordinates (metres) of a ground point.
    fn surface_coordinates(&self, point: Vec3) -> Vec2 {
        let u_axis = Vec3::X.reject_from(self.normal).normalize_or(Vec3::X);
        let v_axis = self.normal.cross(u_axis);
        Vec2::new(point.dot(u_axis), point.dot(v_axis))
    }
}

/// What a ray hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub distance: f32,
    pub point: Vec3,
    pub normal: Vec3,
    /// `None` for the ground, else the index of the block.
    pub block: Option<usize>,
    /// Set when the ray hit the garden's tree (then `block` is `None`).
    pub tree: Option<TreeHit>,
}

/// The whole analytic scene.
#[derive(Clone, Debug, Serialize)]
pub struct Garden {
    pub ground: Ground,
    pub blocks: Vec<Block>,
    /// Unit vector towards the sun.
    pub sun_direction: Vec3,
    #[serde(skip)]
    pub texture_seed: u32,
    /// A grammar tree standing at the planting spot (the tree presets).
    #[serde(skip)]
    pub tree: Option<std::sync::Arc<SynthTree>>,
}

impl Garden {
    /// The standard garden: a wall 1.8 m behind the spot, a box to its right.
    pub fn new(ground: Ground, texture_seed: u32) -> Self {
        let level = |x: f32, z: f32| ground.height_at(x, z);
        let wall_base = level(0.0, -1.8).max(level(0.0, -2.0));
        let box_base = level(1.1, -0.4).max(level(1.1, 0.1));
        let blocks = vec![
            Block {
                name: "wall",
                min: Vec3::new(-2.6, wall_base - 3.0, -2.0),
                max: Vec3::new(2.6, wall_base + 1.2, -1.8),
                material: BlockMaterial::Brick,
            },
            Block {
                name: "box",
                min: Vec3::new(0.85, box_base - 3.0, -0.4),
                max: Vec3::new(1.35, box_base + 0.5, 0.1),
                material: BlockMaterial::Planks,
            },
        ];
        Self {
            ground,
            blocks,
            sun_direction: Vec3::new(0.45, 0.8, 0.35).normalize(),
            texture_seed,
            tree: None,
        }
    }

    /// The garden with `blocks` instead of the standard wall and box, and `tree` at the spot.
    pub fn with_tree(mut self, blocks: Vec<Block>, tree: SynthTree) -> Self {
        self.blocks = blocks;
        self.tree = Some(std::sync::Arc::new(tree));
        self
    }

    /// Nearest hit along `origin + t·direction` for `t` in `(0, max_distance)`.
    pub fn intersect(&self, origin: Vec3, direction: Vec3, max_distance: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let denominator = self.ground.normal.dot(direction);
        if denominator.abs() > 1e-9 {
            let t = -self.ground.normal.dot(origin) / denominator;
            if t > 1e-4 && t < max_distance {
                best = Some(Hit {
                    distance: t,
                    point: origin + direction * t,
                    normal: self.ground.normal,
                    block: None,
                    tree: None,
                });
            }
        }
        for (index, block) in self.blocks.iter().enumerate() {
            let limit = best.map_or(max_distance, |hit| hit.distance);
            if let Some((t, normal)) = ray_box(origin, direction, block.min, block.max, limit) {
                best = Some(Hit {
                    distance: t,
                    point: origin + direction * t,
                    normal,
                    block: Some(index),
                    tree: None,
                });
            }
        }
        if let Some(tree) = &self.tree {
            let limit = best.map_or(max_distance, |hit| hit.distance);
            if let Some(hit) = tree.bvh.intersect(origin, direction, limit) {
                best = Some(Hit {
                    distance: hit.distance,
                    point: origin + direction * hit.distance,
                    normal: hit.normal,
                    block: None,
                    tree: Some(hit),
                });
            }
        }
        best
    }

    /// Linear RGB radiance seen at a hit, `footprint_m` = pixel width on the surface.
    pub fn shade(&self, hit: &Hit, footprint_m: f32) -> Vec3 {
        let seed = self.texture_seed;
        let albedo = match hit.block {
            None if hit.tree.is_some() => match &hit.tree {
                Some(tree_hit) => super::tree::albedo(tree_hit, footprint_m, seed),
                None => Vec3::ZERO,
            },
            None => self.ground_albedo(hit.point, footprint_m),
            Some(index) => {
                let block = &self.blocks[index];
                let p = hit.point;
                let face = if hit.normal.x.abs() > 0.5 {
                    Vec2::new(p.z, p.y)
                } else if hit.normal.z.abs() > 0.5 {
                    Vec2::new(p.x, p.y)
                } else {
                    Vec2::new(p.x, p.z)
                };
                match block.material {
                    BlockMaterial::Brick if hit.normal.y > 0.5 => {
                        texture::paving(face * 0.7, footprint_m * 0.7, seed ^ 0x77) * 0.9
                    }
                    BlockMaterial::Brick => texture::brick(face, footprint_m, seed),
                    BlockMaterial::Planks => texture::planks(face, footprint_m, seed ^ 0x33),
                }
            }
        };
        let lit = hit.normal.dot(self.sun_direction).max(0.0);
        let sun = if lit > 0.0 && self.shadowed(hit.point + hit.normal * 1e-3) {
            0.0
        } else {
            lit
        };
        let sky_fill = 0.35 + 0.15 * hit.normal.y.max(0.0);
        albedo * (sky_fill + 0.9 * sun)
    }

    fn ground_albedo(&self, point: Vec3, footprint_m: f32) -> Vec3 {
        let seed = self.texture_seed;
        let uv = self.ground.surface_coordinates(point);
        // A winding paved path passing left of the planting spot, grass elsewhere.
        let path_centre = -1.0 + 0.35 * (uv.y * 0.6).sin();
        let half_width = 0.65;
        let d = (uv.x - path_centre).abs();
        let soft = footprint_m.max(0.005);
        let on_path = 1.0 - texture::smoothstep(half_width - soft, half_width + soft, d);
        let grass = if on_path < 1.0 {
            texture::grass(uv, footprint_m, seed)
        } else {
            Vec3::ZERO
        };
        let stones = if on_path > 0.0 {
            texture::paving(uv, footprint_m, seed)
        } else {
            Vec3::ZERO
        };
        grass.lerp(stones, on_path)
    }

    fn shadowed(&self, point: Vec3) -> bool {
        self.blocks
            .iter()
            .any(|b| ray_box(point, self.sun_direction, b.min, b.max, 100.0).is_some())
            || self.tree.as_ref().is_some_and(|tree| {
                tree.bvh
                    .intersect(point, self.sun_direction, 100.0)
                    .is_some()
            })
    }
}

/// Slab test: entry distance and outward normal of the entered face.
fn ray_box(origin: Vec3, direction: Vec3, min: Vec3, max: Vec3, limit: f32) -> Option<(f32, Vec3)> {
    let mut t_near = 1e-4_f32;
    let mut t_far = limit;
    let mut normal = Vec3::ZERO;
    for axis in 0..3 {
        let (o, d) = (origin[axis], direction[axis]);
        if d.abs() < 1e-12 {
            if o < min[axis] || o > max[axis] {
                return None;
            }
            continue;
        }
        let (mut t0, mut t1) = ((min[axis] - o) / d, (max[axis] - o) / d);
        let mut face = Vec3::ZERO;
        face[axis] = -d.signum();
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        if t0 > t_near {
            t_near = t0;
            normal = face;
        }
        t_far = t_far.min(t1);
        if t_near > t_far {
            return None;
        }
    }
    (normal != Vec3::ZERO).then_some((t_near, normal))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_straight_down_hits_the_ground_at_the_camera_height() {
        let garden = Garden::new(Ground::sloped(0.0), 1);
        let hit = garden
            .intersect(Vec3::new(0.0, 1.5, 2.0), Vec3::NEG_Y, 100.0)
            .expect("ground below");
        assert!((hit.distance - 1.5).abs() < 1e-5 && hit.block.is_none());
    }

    #[test]
    fn a_ray_towards_the_wall_stops_at_its_front_face() {
        let garden = Garden::new(Ground::sloped(0.0), 1);
        let hit = garden
            .intersect(Vec3::new(0.0, 0.5, 2.0), Vec3::NEG_Z, 100.0)
            .expect("wall ahead");
        assert_eq!(hit.block, Some(0));
        assert!((hit.point.z + 1.8).abs() < 1e-5 && hit.normal == Vec3::Z);
    }

    #[test]
    fn sloped_ground_contains_the_origin_and_rises_away_from_the_start() {
        let ground = Ground::sloped(8.0);
        assert!(ground.height_at(0.0, 0.0).abs() < 1e-6);
        assert!(ground.height_at(0.0, -2.0) > 0.2);
    }
}
