//! The tree the app shows and edits, and the meshes drawn for it: `sylva_core`'s growth and
//! `sylva_core::geometry` meshes (finest level of detail, per-vertex ambient light from the
//! growth shadow grid), converted to the renderer's vertices.

use glam::Vec3;
use sylva_core::geometry::{
    Levels, Mesher, Season, TreeMeshes, TreeShade, build_tree_level, mesh_params_in,
};
use sylva_core::{Skeleton, Tree};

use crate::render::{LitMesh, LitVertex, TreeMesh};
use crate::state::species_named;

/// Seed of the tree in the golden images.
pub const GOLDEN_SEED: u64 = 7;
/// Species of the tree in the golden images.
pub const GOLDEN_SPECIES: &str = "maple";
/// Autonomous growth iterations of the golden-image tree.
pub const GOLDEN_ITERATIONS: u32 = 8;

/// The golden-image tree: a young maple grown autonomously.
pub fn golden_tree() -> Tree {
    let mut tree = Tree::new(species_named(GOLDEN_SPECIES), GOLDEN_SEED);
    tree.grow(GOLDEN_ITERATIONS, None);
    tree
}

/// The mesh of the golden-image tree.
pub fn golden_tree_mesh() -> TreeMesh {
    mesh_of(&golden_tree())
}

/// The point of the golden tree's trunk at height `h` (metres above its base).
pub fn golden_trunk_point(h: f32) -> Vec3 {
    trunk_point(&golden_tree().skeleton, h)
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

/// The mesh drawn for a tree: bark and alpha-cut leaves of the finest level of detail (only
/// that level is built).
pub fn mesh_of(tree: &Tree) -> TreeMesh {
    draw_mesh(&build_tree_level(tree, 0))
}

/// Re-meshes the tree after every edit with the same working memory: the mesher's scratch, the
/// core meshes and the renderer's vertices are all kept, so a re-mesh writes into memory the
/// process already holds (a first build into fresh memory costs over twice as much).
#[derive(Default)]
pub struct TreeMesher {
    mesher: Mesher,
    meshes: TreeMeshes,
    /// The leaf cards expanded into single leaves, which the leaf shader draws.
    leaves: sylva_core::geometry::TreeMesh,
    mesh: TreeMesh,
}

impl TreeMesher {
    /// The drawn mesh of `tree` (level 0 and leaves), as [`mesh_of`] builds it.
    pub fn mesh(&mut self, tree: &Tree) -> &TreeMesh {
        self.mesh_in(tree, Season::Summer)
    }

    /// The drawn mesh of `tree` in `season` (a deciduous tree has no leaves in winter).
    pub fn mesh_in(&mut self, tree: &Tree, season: Season) -> &TreeMesh {
        let params = mesh_params_in(&tree.species, season);
        let shade = TreeShade::in_season(tree, season);
        self.mesher.build_into(
            &tree.skeleton,
            &params,
            &|p| shade.at(p),
            Levels::One(0),
            &mut self.meshes,
        );
        match self.meshes.lods.first() {
            Some(lod) => lit_into(&lod.branches, |uv| uv, &mut self.mesh.branches),
            None => self.mesh.branches = LitMesh::default(),
        }
        let cards = &self.meshes.leaves;
        self.meshes
            .leaf_card
            .expand_into(cards, cards.indices.len(), &mut self.leaves);
        lit_into(&self.leaves, leaf_uv, &mut self.mesh.leaves);
        self.mesh.bark_color = self.meshes.colors.bark;
        self.mesh.leaf_color = self.meshes.colors.leaf;
        &self.mesh
    }

    /// The mesh of the last [`Self::mesh`] call (empty before the first).
    pub fn current(&self) -> &TreeMesh {
        &self.mesh
    }
}

/// Leaf texture coordinates from the core's to the renderer's (see [`draw_mesh`]).
fn leaf_uv([u, v]: [f32; 2]) -> [f32; 2] {
    [u - 0.5, 1.0 - v]
}

/// The renderer's mesh of `sylva_core` meshes (level 0). Leaf texture coordinates go from
/// the core's (u across 0..1, v from tip 0 to petiole 1) to the renderer's (x across −½..½,
/// y from petiole 0 to tip 1).
pub fn draw_mesh(meshes: &TreeMeshes) -> TreeMesh {
    let branches = meshes
        .lods
        .first()
        .map(|lod| lit(&lod.branches, |uv| uv))
        .unwrap_or_default();
    // The leaf shader draws one blade per quad: the cards expanded into their leaves.
    let mut single_leaves = sylva_core::geometry::TreeMesh::default();
    meshes.leaf_card.expand_into(
        &meshes.leaves,
        meshes.leaves.indices.len(),
        &mut single_leaves,
    );
    let leaves = lit(&single_leaves, leaf_uv);
    TreeMesh {
        branches,
        leaves,
        bark_color: meshes.colors.bark,
        leaf_color: meshes.colors.leaf,
    }
}

fn lit(mesh: &sylva_core::geometry::TreeMesh, uv_of: impl Fn([f32; 2]) -> [f32; 2]) -> LitMesh {
    let mut out = LitMesh::default();
    lit_into(mesh, uv_of, &mut out);
    out
}

/// Writes the renderer's vertices of `mesh` into `out`, reusing its buffers.
fn lit_into(
    mesh: &sylva_core::geometry::TreeMesh,
    uv_of: impl Fn([f32; 2]) -> [f32; 2],
    out: &mut LitMesh,
) {
    out.vertices.clear();
    out.vertices
        .extend((0..mesh.positions.len()).map(|i| LitVertex {
            position: mesh.positions[i],
            normal: mesh.normals[i],
            ambient: mesh.ambient[i],
            uv: uv_of(mesh.uvs[i]),
        }));
    out.indices.clear();
    out.indices.extend_from_slice(&mesh.indices);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reusing_mesher_draws_what_a_fresh_build_draws_edit_after_edit() {
        let mut tree = golden_tree();
        let mut mesher = TreeMesher::default();
        for _ in 0..3 {
            assert_eq!(mesher.mesh(&tree), &mesh_of(&tree));
            tree.grow(1, None);
        }
        // And after the tree shrinks (buffers longer than needed must not leak old data).
        let cut: Vec<_> = (1..tree.skeleton.len())
            .filter(|&i| tree.skeleton.internodes[i].order == 1)
            .map(|i| sylva_core::NodeId(i as u32))
            .collect();
        tree.remove_subtrees(&cut);
        assert_eq!(mesher.mesh(&tree), &mesh_of(&tree));
    }
}
