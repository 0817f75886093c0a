//! The mesher: a tree's meshes at every level of detail or only at the one drawn, with the
//! working memory (internode copies, topology, ring frames, leaf slots) kept between calls so
//! that interactive re-meshing allocates nothing once its buffers have grown.

use glam::Vec3;

use super::billboard_cloud::CloudWood;
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
    /// The internodes of the chains the coarsest level drops, for its billboard cloud's atlas.
    dropped_wood: Vec<CloudWood>,
    /// Centres of the fruit, in arena and bud order.
    fruit_centers: Vec<Vec3>,
    /// Parents and children of the internodes, for the topology.
    links: Links,
    /// Whether the coarsest level's leaves are merged cards (as the other coarse levels')
    /// rather than a billboard cloud: for a renderer that draws every level with the leaf
    /// texture, so that it does not pay for clustering a cloud it never draws.
    coarsest_as_cards: bool,
}

impl Mesher {
    pub fn new() -> Self {
        Mesher::default()
    }

    /// Makes the coarsest level's leaves merged cards instead of a billboard cloud (the
    /// default) from the next build on.
    pub fn set_coarsest_as_cards(&mut self, as_cards: bool) {
        self.coarsest_as_cards = as_cards;
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
        let total_cards = meshes.leaves.indices.len() / 6;
        let total_fruit = meshes.fruit.indices.len();
        for (lod, level) in meshes.lods.iter_mut().zip(levels) {
            let num_fruit = prefix_indices(total_fruit, 3, LOD_TRIANGLE_FRACTIONS[level]);
            let finest = FinestCounts {
                cards: total_cards,
                fruit_triangles: total_fruit / 3,
            };
            let num_cards = self.mesh_level(level, finest, num_fruit / 3, lod);
            if level == 0 {
                lod.merged_leaves.clear();
                lod.billboards = None;
                lod.num_leaf_indices = 6 * num_cards;
            } else {
                let cloud = level + 1 == LOD_TRIANGLE_FRACTIONS.len() && !self.coarsest_as_cards;
                self.dropped_wood.clear();
                if cloud {
                    self.collect_dropped_wood(params.bark_color, ambient);
                }
                lod_leaves::coarse_leaves_into(
                    &meshes.leaves,
                    &self.dropped_wood,
                    num_cards,
                    ground_y,
                    cloud,
                    &mut self.merge_scratch,
                    lod,
                );
            }
            lod.num_fruit_indices = num_fruit;
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

    /// The internodes of the chains the last coarse level meshed leaves out (`kept`), in the
    /// bark's colour times its baked ambient light at their middle, into `dropped_wood`.
    fn collect_dropped_wood(&mut self, bark_color: [f32; 3], ambient: AmbientFn) {
        for (chain, &kept) in self.kept.iter().enumerate() {
            if kept {
                continue;
            }
            for &node in self.topology.nodes_of(chain) {
                let node = &self.nodes[node as usize];
                let light = crate::export::ambient_color(ambient(0.5 * (node.start + node.end)));
                self.dropped_wood.push(CloudWood {
                    start: node.start.to_array(),
                    end: node.end.to_array(),
                    diameter: node.diameter,
                    color: bark_color.map(|c| c * light),
                });
            }
        }
    }

    /// The branches of level `level`, and the number of leaf cards it draws: level 0 has every
    /// chain at its finest sides and every card. A coarser level has [`LOD_TRIANGLE_FRACTIONS`]
    /// of the finest level's triangles, shared out as [`coarse_budget`] says.
    fn mesh_level(
        &mut self,
        level: usize,
        finest: FinestCounts,
        num_fruit_triangles: usize,
        lod: &mut Lod,
    ) -> usize {
        let fraction = LOD_TRIANGLE_FRACTIONS[level];
        let (mesh, starts) = (&mut lod.branches, &mut lod.branch_starts);
        lod.level = level;
        lod.target_fraction = fraction;
        if fraction >= 1.0 {
            self.frames
                .mesh_into(&self.topology, 1.0, None, mesh, starts);
            return finest.cards;
        }
        let full_bark = self.frames.num_triangles(1.0, None);
        let budget = CoarseBudget::of(fraction, full_bark, finest);
        let side_scale = fraction.sqrt();
        self.frames
            .chains_within_budget(&self.topology, side_scale, budget.bark, &mut self.kept);
        self.frames
            .mesh_into(&self.topology, side_scale, Some(&self.kept), mesh, starts);
        let left = budget
            .total
            .saturating_sub(mesh.num_triangles() + num_fruit_triangles);
        (left / 2).min(finest.cards)
    }
}

/// The finest level's leaf cards and fruit triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FinestCounts {
    cards: usize,
    fruit_triangles: usize,
}

/// How a coarse level's triangles are shared out between bark and leaf cards.
///
/// A level with a fraction f of the finest level's triangles draws its branches with √f of
/// their sides; were it to keep f of the bark triangles it would keep √f of the branches'
/// length (39% at the coarsest level), far more of the thin inner wood than a distant tree
/// shows, while its cards had to merge runs of 1/f. The bark gets f^1.5 of its triangles
/// instead: the same √f of the sides on the thickest chains that hold f of the length (the
/// trunk and the main limbs), and the leaf cards get the rest of the level's triangles, so
/// they merge fewer cards each. At 40 years this takes the coarsest level's side view from
/// 13–22% to 8–19% off the finest's (`examples/export_report`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct CoarseBudget {
    /// The level's triangles: f of the finest level's (bark, cards and fruit).
    total: usize,
    /// At most this many bark triangles.
    bark: usize,
}

impl CoarseBudget {
    fn of(fraction: f32, full_bark: usize, finest: FinestCounts) -> Self {
        let full = full_bark + 2 * finest.cards + finest.fruit_triangles;
        CoarseBudget {
            total: (full as f32 * fraction) as usize,
            bark: (full_bark as f32 * fraction.powf(1.5)) as usize,
        }
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
