//! The tree the app shows and edits, and the meshes drawn for it: `sylva_core`'s growth and
//! `sylva_core::geometry` meshes (every level of detail, per-vertex ambient light from the
//! growth shadow grid), converted to the renderer's bark vertices and leaf-card instances.

use glam::Vec3;
use sylva_core::geometry::{
    Levels, Mesher, Season, TreeMesh as CoreMesh, TreeMeshes, TreeShade, merged_cards_into,
    mesh_params_in,
};
use sylva_core::{Skeleton, Tree};

use crate::render::{CardInstance, LitMesh, LitVertex, TreeLevel, TreeLook, TreeMesh};
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

/// The mesh drawn for a tree in summer: bark and leaf cards at every level of detail.
pub fn mesh_of(tree: &Tree) -> TreeMesh {
    TreeMesher::default().mesh(tree).clone()
}

/// Re-meshes the tree after every edit with the same working memory: the mesher's scratch, the
/// core meshes and the renderer's vertices are all kept, so a re-mesh writes into memory the
/// process already holds (a first build into fresh memory costs over twice as much).
#[derive(Default)]
pub struct TreeMesher {
    mesher: Mesher,
    meshes: TreeMeshes,
    mesh: TreeMesh,
    /// The coarsest level's merged cards, drawn instead of its billboard cloud.
    coarse_cards: CoreMesh,
}

impl TreeMesher {
    /// The drawn mesh of `tree` in summer, as [`mesh_of`] builds it.
    pub fn mesh(&mut self, tree: &Tree) -> &TreeMesh {
        self.mesh_in(tree, Season::Summer)
    }

    /// The drawn mesh of `tree` in `season` (a deciduous tree has no leaves in winter), every
    /// level of detail, so the renderer can pick one by the tree's size on screen.
    pub fn mesh_in(&mut self, tree: &Tree, season: Season) -> &TreeMesh {
        let params = mesh_params_in(&tree.species, season);
        let shade = TreeShade::in_season(tree, season);
        // The renderer draws the coarsest level's leaves with the card texture: merged cards,
        // not a billboard cloud (clustering one costs tens of milliseconds a re-mesh).
        self.mesher.set_coarsest_as_cards(true);
        self.mesher.build_into(
            &tree.skeleton,
            &params,
            &|p| shade.at(p),
            Levels::All,
            &mut self.meshes,
        );
        draw_mesh_into(
            &self.meshes,
            tree.skeleton.ground_y(),
            &mut self.coarse_cards,
            &mut self.mesh,
        );
        &self.mesh
    }

    /// The mesh of the last [`Self::mesh`] call (empty before the first).
    pub fn current(&self) -> &TreeMesh {
        &self.mesh
    }
}

/// The renderer's mesh of `sylva_core` meshes of a tree standing at y = `ground_y`: each
/// level's bark, and its leaf cards as instances of the species' card.
pub fn draw_mesh(meshes: &TreeMeshes, ground_y: f32) -> TreeMesh {
    let mut mesh = TreeMesh::default();
    draw_mesh_into(meshes, ground_y, &mut CoreMesh::default(), &mut mesh);
    mesh
}

/// [`draw_mesh`] into `out`, reusing its buffers and `coarse_cards`. A level that is a
/// billboard cloud (the coarsest) is drawn as merged cards, as many as its quads: the renderer
/// draws every level's leaves with the species' card texture, and the cloud's quads need their
/// own atlas (`sylva_core::geometry::billboard_cloud::bake_atlas`), which it does not bind.
fn draw_mesh_into(
    meshes: &TreeMeshes,
    ground_y: f32,
    coarse_cards: &mut CoreMesh,
    out: &mut TreeMesh,
) {
    out.levels
        .resize_with(meshes.lods.len(), TreeLevel::default);
    for (lod, level) in meshes.lods.iter().zip(&mut out.levels) {
        lit_into(&lod.branches, &mut level.branches);
        if lod.billboards.is_some() {
            let num_quads = lod.num_leaf_indices.min(lod.merged_leaves.indices.len()) / 6;
            merged_cards_into(&meshes.leaves, num_quads, ground_y, coarse_cards);
            cards_into(coarse_cards, coarse_cards.indices.len(), &mut level.cards);
        } else {
            cards_into(
                lod.leaves_in(&meshes.leaves),
                lod.num_leaf_indices,
                &mut level.cards,
            );
        }
        fruit_into(&meshes.fruit, lod.num_fruit_indices, &mut level.fruit);
    }
    let colors = &meshes.colors;
    out.look = TreeLook {
        leaf_shape: colors.leaf_shape,
        leaf_color: colors.leaf,
        bark_kind: colors.bark_kind,
        bark_color: colors.bark,
        leaf_card: meshes.leaf_card.clone(),
        fruit_color: colors.fruit,
    };
}

/// The cards of the first `num_indices` indices of `cards` (quads of 4 vertices and 6 indices,
/// each card's vertices stored in order: base-left, base-right, tip-left, tip-right), into `out`.
fn cards_into(cards: &CoreMesh, num_indices: usize, out: &mut Vec<CardInstance>) {
    out.clear();
    let num_cards = num_indices.min(cards.indices.len()) / 6;
    out.extend((0..num_cards).map(|card| {
        let first = cards.indices[6 * card] as usize;
        let corner = |k: usize| Vec3::from(cards.positions[first + k]);
        CardInstance {
            origin: corner(0).to_array(),
            across: (corner(1) - corner(0)).to_array(),
            along: (corner(2) - corner(0)).to_array(),
            normal: cards.normals[first],
            ambient: cards.ambient[first],
        }
    }));
}

/// The fruit of the first `num_indices` indices of `fruit` (stored in vertex order, so they use
/// a prefix of its vertices), into `out`.
fn fruit_into(fruit: &CoreMesh, num_indices: usize, out: &mut LitMesh) {
    let num_indices = num_indices.min(fruit.indices.len());
    let num_vertices = fruit.num_vertices_of_prefix(num_indices);
    out.vertices.clear();
    out.vertices.extend((0..num_vertices).map(|i| LitVertex {
        position: fruit.positions[i],
        normal: fruit.normals[i],
        ambient: fruit.ambient[i],
        uv: fruit.uvs[i],
    }));
    out.indices.clear();
    out.indices.extend_from_slice(&fruit.indices[..num_indices]);
}

/// Writes the renderer's vertices of `mesh` into `out`, reusing its buffers.
fn lit_into(mesh: &CoreMesh, out: &mut LitMesh) {
    out.vertices.clear();
    out.vertices
        .extend((0..mesh.positions.len()).map(|i| LitVertex {
            position: mesh.positions[i],
            normal: mesh.normals[i],
            ambient: mesh.ambient[i],
            uv: mesh.uvs[i],
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

    #[test]
    fn the_coarsest_level_is_drawn_as_merged_cards_never_as_a_cloud() {
        let tree = golden_tree();
        let mut mesher = TreeMesher::default();
        let mesh = mesher.mesh(&tree).clone();
        let coarsest = mesher.meshes.lods.last().expect("levels");
        assert!(coarsest.billboards.is_none(), "the app builds no cloud");
        assert_eq!(
            mesh.levels.last().unwrap().cards.len(),
            coarsest.num_leaf_indices / 6
        );
        // Meshes with a cloud (the core's default) are drawn as merged cards all the same.
        let mut meshes = TreeMeshes::default();
        let params = mesh_params_in(&tree.species, Season::Summer);
        let shade = TreeShade::in_season(&tree, Season::Summer);
        let ambient = |p: Vec3| shade.at(p);
        Mesher::default().build_into(&tree.skeleton, &params, &ambient, Levels::All, &mut meshes);
        let cloud = meshes
            .lods
            .last()
            .unwrap()
            .billboards
            .as_ref()
            .expect("a cloud");
        let mesh = draw_mesh(&meshes, tree.skeleton.ground_y());
        let drawn = &mesh.levels.last().expect("levels").cards;
        assert!(!drawn.is_empty());
        assert_eq!(drawn.len(), cloud.num_quads());
        // Merged cards keep the leaf area of the cards they stand for (a cloud's quads,
        // bounding rectangles of clusters, hold more).
        let area = |cards: &[CardInstance]| -> f32 {
            cards
                .iter()
                .map(|c| Vec3::from(c.across).cross(Vec3::from(c.along)).length())
                .sum()
        };
        let (finest, coarse) = (area(mesh.cards()), area(drawn));
        assert!(
            (coarse - finest).abs() < 0.02 * finest,
            "{coarse} vs {finest}"
        );
        let ground_y = tree.skeleton.ground_y();
        for card in drawn {
            assert!(card.corners().iter().all(|p| p.y >= ground_y - 1e-4));
        }
    }
}
