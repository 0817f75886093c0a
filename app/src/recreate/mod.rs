//! Recreating an existing tree in place (Longay 2014 §5.4.4 and §7): the user marks the real
//! tree in the footage (the trunk base, the crown's outline in one or more views), Sylva measures
//! it (height, crown width and axes, crown base, trunk position, each with how it was obtained)
//! from the visual hull of the outlines and the tracked points on the tree, then grows a species
//! from the trunk base into the hull. The result is an ordinary tree: every edit, the years and
//! the exports work on it. World: metres, Y up, origin on the ground plane (the tracker's).

pub mod footage;
pub mod grow;
pub mod hull;
pub mod marks;
pub mod measure;
pub mod silhouette;

use glam::{Affine3A, Vec3};
use sylva_core::geometry::{TreeMesh, TreeMeshes};

/// Moves every mesh of `meshes` (built in tree space) into the world by `world_from_tree`.
pub fn place_meshes(meshes: &mut TreeMeshes, world_from_tree: &Affine3A) {
    let place = |mesh: &mut TreeMesh| {
        for p in &mut mesh.positions {
            *p = world_from_tree.transform_point3(Vec3::from(*p)).to_array();
        }
        for n in &mut mesh.normals {
            *n = world_from_tree
                .transform_vector3(Vec3::from(*n))
                .normalize_or_zero()
                .to_array();
        }
    };
    for lod in &mut meshes.lods {
        place(&mut lod.branches);
        place(&mut lod.merged_leaves);
    }
    place(&mut meshes.leaves);
    place(&mut meshes.fruit);
}
