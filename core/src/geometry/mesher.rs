//! The mesher: a tree's meshes at every level of detail or only at the one drawn, with the
//! working memory (internode copies, topology, ring frames, leaf slots) kept between calls so
//! that interactive re-meshing allocates nothing once its buffers have grown.

use glam::Vec3;

use super::branches::RingFrames;
use super::leaves::{self, LeafScratch};
use super::lod_leaves::{self, MergeScratch};
use super::topology::{BranchTopology, Links};
use super::{
    AmbientFn, FruitParams, LOD_TRIANGLE_FRACTIONS, Lod, MaterialColors, MeshParams, NodeGeom,
    TreeMeshes, prefix_indices,
};
use crate::tree::Skeleton;

/// The levels of detail a build makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Levels {
    /// Every level of [`LOD_TRIANGLE_FRACTIONS`], finest first (export, LOD tests).
    All,
    /// Only this level (index into [`LOD_TRIANGLE_FRACTIONS`], clamped to the coarsest): what
    /// a renderer draws. The leaf and fruit buffers are built whole all the same.
    One(usize),
}

impl Levels {
    fn range(self) -> std::ops::Range<usize> {
        match self {
            Levels::All => 0..LOD_TRIANGLE_FRACTIONS.len(),
            Levels::One(level) => {
                let level = level.min(LOD_TRIANGLE_FRACTIONS.len() - 1);
                level..level + 1
            }
        }
    }
}

/// Builds tree meshes, keeping its working memory between calls.
#[derive(Default)]
pub struct Mesher {
    nodes: Vec<NodeGeom>,
    diameters: Vec<f32>,
    topology: BranchTopology,
    frames: RingFrames,
    leaf_scratch: LeafScratch,
    merge_scratch: MergeScratch,
    kept: Vec<bool>,
    /// Centres of the fruit, in arena and bud order.
    fruit_centers: Vec<Vec3>,
    /// Parents and children of the internodes, for the topology.
    links: Links,
}

impl Mesher {
    pub fn new() -> Self {
        Mesher::default()
    }

    /// Builds the branch meshes of `levels` and the leaf and fruit buffers of `skeleton` into
    /// `meshes` (their buffers are reused), sampling `ambient` once per ring, leaf and fruit.
    pub fn build_into(
        &mut self,
        skeleton: &Skeleton,
        params: &MeshParams,
        ambient: AmbientFn,
        levels: Levels,
        meshes: &mut TreeMeshes,
    ) {
        self.collect(skeleton, params.fruit.as_ref());
        let ground_y = skeleton.ground_y();
        self.topology.build_with_links(&self.links, &self.diameters);
        self.frames
            .build_into(&self.nodes, &self.topology, params, ambient);
        leaves::build_leaves_into(
            &self.nodes,
            &params.leaves,
            params.seed,
            ambient,
            ground_y,
            &mut self.leaf_scratch,
            &mut meshes.leaves,
        );
        meshes.fruit.clear();
        if let Some(fruit) = &params.fruit {
            leaves::push_fruit(
                &mut meshes.fruit,
                &self.fruit_centers,
                fruit,
                ambient,
                ground_y,
            );
        }
        let levels = levels.range();
        meshes.lods.resize_with(levels.len(), Lod::default);
        for (lod, level) in meshes.lods.iter_mut().zip(levels) {
            self.mesh_level(level, lod);
            let num_cards = prefix_indices(meshes.leaves.indices.len(), 6, lod.target_fraction);
            if level == 0 {
                lod.merged_leaves.clear();
            } else {
                lod_leaves::merge_cards_into(
                    &meshes.leaves,
                    num_cards / 6,
                    ground_y,
                    &mut self.merge_scratch,
                    &mut lod.merged_leaves,
                );
            }
            lod.num_leaf_indices = num_cards;
            lod.num_fruit_indices =
                prefix_indices(meshes.fruit.indices.len(), 3, lod.target_fraction);
        }
        meshes.leaf_card.set(&params.leaves);
        meshes.colors = MaterialColors {
            bark: params.bark_color,
            leaf: params.leaf_color,
            fruit: params.fruit_color,
            bark_kind: params.bark_kind,
            leaf_shape: params.leaf_shape,
        };
    }

    /// The internode geometry, diameters and links, and the fruit centres, in one pass over the
    /// arena (each internode is read once, while it is in cache).
    fn collect(&mut self, skeleton: &Skeleton, fruit: Option<&FruitParams>) {
        self.nodes.clear();
        self.diameters.clear();
        self.fruit_centers.clear();
        self.links.clear();
        for (index, node) in skeleton.internodes.iter().enumerate() {
            self.nodes.push(NodeGeom::new(node));
            self.diameters.push(node.diameter);
            self.links.push(node);
            if let Some(fruit) = fruit {
                leaves::fruit_centers(node, index as u32, fruit, &mut self.fruit_centers);
            }
        }
    }

    /// The branches of level `level`: all chains with their finest sides at level 0; coarser
    /// levels scale the sides by √fraction and keep the thickest chains within the budget.
    fn mesh_level(&mut self, level: usize, lod: &mut Lod) {
        let fraction = LOD_TRIANGLE_FRACTIONS[level];
        let (mesh, starts) = (&mut lod.branches, &mut lod.branch_starts);
        if fraction >= 1.0 {
            self.frames
                .mesh_into(&self.topology, 1.0, None, mesh, starts);
        } else {
            let full = self.frames.num_triangles(1.0, None);
            let target = (full as f32 * fraction) as usize;
            let side_scale = fraction.sqrt();
            self.frames
                .chains_within_budget(&self.topology, side_scale, target, &mut self.kept);
            self.frames
                .mesh_into(&self.topology, side_scale, Some(&self.kept), mesh, starts);
        }
        lod.level = level;
        lod.target_fraction = fraction;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::synthetic::{branching_skeleton, crown_ambient};
    use crate::geometry::{FruitParams, build_level, build_meshes};

    #[test]
    fn one_level_built_alone_equals_that_level_of_a_full_build() {
        let skeleton = branching_skeleton(4_000, 11);
        let params = MeshParams {
            fruit: Some(FruitParams::default()),
            ..MeshParams::default()
        };
        let ambient = crown_ambient(Vec3::new(0.0, 1.0, 0.0), 1.5);
        let all = build_meshes(&skeleton, &params, &ambient);
        assert_eq!(all.lods.len(), LOD_TRIANGLE_FRACTIONS.len());
        for (level, full_lod) in all.lods.iter().enumerate() {
            assert_eq!(full_lod.level, level);
            let one = build_level(&skeleton, &params, &ambient, level);
            assert_eq!(one.lods.len(), 1);
            assert_eq!(&one.lods[0], full_lod, "level {level}");
            assert_eq!(one.leaves, all.leaves);
            assert_eq!(one.fruit, all.fruit);
            assert_eq!(one.colors, all.colors);
        }
        let coarsest = build_level(&skeleton, &params, &ambient, 99);
        assert_eq!(coarsest.lods[0].level, LOD_TRIANGLE_FRACTIONS.len() - 1);
    }

    #[test]
    fn a_reused_mesher_gives_the_same_meshes_as_a_fresh_one_for_another_tree() {
        let params = MeshParams::default();
        let ambient = |_: Vec3| 0.8;
        let mut mesher = Mesher::new();
        let mut reused = TreeMeshes::default();
        for (num_internodes, seed) in [(3_000, 1), (1_000, 2), (2_000, 3)] {
            let skeleton = branching_skeleton(num_internodes, seed);
            for levels in [Levels::All, Levels::One(1), Levels::One(0)] {
                mesher.build_into(&skeleton, &params, &ambient, levels, &mut reused);
                let mut fresh = TreeMeshes::default();
                Mesher::new().build_into(&skeleton, &params, &ambient, levels, &mut fresh);
                assert_eq!(reused, fresh, "{num_internodes} internodes, {levels:?}");
            }
        }
    }
}
