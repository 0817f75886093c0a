//! The tree the app shows and edits, and the meshes drawn for it.
//!
//! Until `sylva_core`'s growth and geometry land, the skeleton and mesh come from the clearly
//! named stand-ins in [`crate::standin`].

use glam::Vec3;
use sylva_core::Skeleton;

use crate::render::TreeMesh;
use crate::standin::{standin_skeleton, standin_tree_mesh};

/// Seed of the tree in the golden images.
pub const GOLDEN_SEED: u64 = 7;

/// The skeleton of the golden-image tree.
pub fn golden_skeleton() -> Skeleton {
    standin_skeleton(GOLDEN_SEED, 5)
}

/// The mesh of the golden-image tree.
pub fn golden_tree_mesh() -> TreeMesh {
    standin_tree_mesh(&golden_skeleton())
}

/// The point of the golden tree's trunk at height `h` (metres above its base).
pub fn golden_trunk_point(h: f32) -> Vec3 {
    trunk_point(&golden_skeleton(), h)
}

/// The point of the trunk (the main axis from the root) at height `h`, or its top when the
/// trunk is lower.
pub fn trunk_point(skeleton: &Skeleton, h: f32) -> Vec3 {
    let Some(mut node) = skeleton.internodes.first() else {
        return Vec3::ZERO;
    };
    loop {
        if node.end.y >= h {
            let span = node.end.y - node.start.y;
            let t = if span > 1e-6 {
                (h - node.start.y) / span
            } else {
                1.0
            };
            return node.start.lerp(node.end, t.clamp(0.0, 1.0));
        }
        match node.main_child {
            Some(child) => node = skeleton.get(child),
            None => return node.end,
        }
    }
}

/// The mesh drawn for a skeleton.
pub fn mesh_of(skeleton: &Skeleton) -> TreeMesh {
    standin_tree_mesh(skeleton)
}
