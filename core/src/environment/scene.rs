//! Scenes: "is this point free?". The tracking side implements [`Scene`] for the depth mesh of
//! the real scene; core ships a half-space, a box and a sphere for its own tests and demos.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Anything that can say whether a point in world space is free (not inside an obstacle).
pub trait Scene: Send + Sync {
    fn is_free(&self, point_in_world: Vec3) -> bool;

    /// True when the straight segment `a → b` stays free, judged at a few samples.
    fn is_segment_free(&self, a: Vec3, b: Vec3) -> bool {
        const SAMPLES: usize = 4;
        (1..=SAMPLES).all(|i| self.is_free(a.lerp(b, i as f32 / SAMPLES as f32)))
    }
}

/// How growth reacts to a scene (Longay 2014 §5.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SceneMode {
    /// Grow in front of the scene: attraction points in occupied space are discarded and no new
    /// internode may enter occupied space.
    GrowInFront,
    /// Grow freely, then cut every internode that entered occupied space (with its subtree) and
    /// recompute widths.
    PruneToScene,
}

/// Free on the side of the plane the normal points to (`(p − point_on_plane)·normal ≥ 0`),
/// occupied behind it: a wall or the ground.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HalfSpace {
    pub point_on_plane: Vec3,
    /// Unit normal pointing into free space.
    pub normal_to_free: Vec3,
}

impl HalfSpace {
    /// A wall whose free side faces `normal_to_free` (normalised here; +Y if degenerate).
    pub fn new(point_on_plane: Vec3, normal_to_free: Vec3) -> Self {
        HalfSpace {
            point_on_plane,
            normal_to_free: normal_to_free.try_normalize().unwrap_or(Vec3::Y),
        }
    }

    /// Signed distance to the plane, positive on the free side.
    pub fn signed_distance(&self, point_in_world: Vec3) -> f32 {
        (point_in_world - self.point_on_plane).dot(self.normal_to_free)
    }
}

impl Scene for HalfSpace {
    fn is_free(&self, point_in_world: Vec3) -> bool {
        self.signed_distance(point_in_world) >= 0.0
    }
}

/// An axis-aligned solid box: occupied inside.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoxScene {
    pub min: Vec3,
    pub max: Vec3,
}

impl Scene for BoxScene {
    fn is_free(&self, point_in_world: Vec3) -> bool {
        !(point_in_world.cmpge(self.min).all() && point_in_world.cmple(self.max).all())
    }
}

/// A solid ball: occupied inside.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphereScene {
    pub center: Vec3,
    pub radius: f32,
}

impl Scene for SphereScene {
    fn is_free(&self, point_in_world: Vec3) -> bool {
        point_in_world.distance_squared(self.center) > self.radius * self.radius
    }
}

/// Several scenes at once: free where all of them are free.
impl<S: Scene> Scene for [S] {
    fn is_free(&self, point_in_world: Vec3) -> bool {
        self.iter().all(|s| s.is_free(point_in_world))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_space_box_and_sphere_answer_free_and_occupied() {
        let wall = HalfSpace::new(Vec3::new(1.5, 0.0, 0.0), Vec3::NEG_X);
        assert!(wall.is_free(Vec3::ZERO));
        assert!(!wall.is_free(Vec3::new(2.0, 1.0, 0.0)));
        assert!(!wall.is_segment_free(Vec3::ZERO, Vec3::new(3.0, 0.0, 0.0)));
        let block = BoxScene {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        assert!(!block.is_free(Vec3::ZERO));
        assert!(block.is_free(Vec3::new(0.0, 2.0, 0.0)));
        let ball = SphereScene {
            center: Vec3::Y,
            radius: 0.5,
        };
        assert!(!ball.is_free(Vec3::new(0.0, 1.2, 0.0)));
        assert!(ball.is_free(Vec3::ZERO));
    }
}
