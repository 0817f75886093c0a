//! Branch, leaf and fruit meshes of a tree skeleton, with levels of detail (Longay 2014,
//! appendix C; Pirk 2014, ch. 6).
//!
//! - **Branches** are generalized cylinders: one ring per internode joint, oriented along the
//!   joint's tangent with a reference vector carried by parallel transport (double reflection),
//!   so rings never twist. The topology is first reorganised along the thickest path (appendix
//!   C.3, [`topology`]) and the first ring of every lateral branch is laid onto its parent's
//!   surface, so dominant laterals leave no cracks. Sides per branch C = 3·dⁿ/d_e (eq. C.2).
//!   Bark UVs are tiled along the path with a small rotation per segment; normals are smooth.
//!   Where a branch runs nearly straight, its joints get no ring of their own: a joint within
//!   a quarter of the radius (or 4 mm) of the line between the rings around it is left out,
//!   unless a branch grows from it ([`MeshParams::ring_tolerance`]); a 40-year willow's bark
//!   goes from 579k to 392k triangles.
//! - **Leaves** ([`leaves`]) are alpha-textured cards on branches thinner than a threshold, at a
//!   density per metre of twig of their own (appendix C.1.1), oriented by the petiole model of
//!   appendix C.1.2; sunlit leaves turn their blade to the light. A card holds a spray of
//!   several leaves where they are small ([`leaf_card`]), so density costs cards, not quads.
//!   No leaf reaches below the ground plane through the tree's base.
//! - **Crown measures** ([`crown`]): leaf area index and porosity, by rasterising the meshes.
//! - **Fruit** grows on buds with p = r·L² above a threshold (appendix C.2).
//! - **Ambient**: every vertex carries the ambient light of the growth shadow grid, sampled
//!   through a callback so this module does not depend on growth.
//! - **Levels of detail** ([`Lod`]): 100%, 40% and 15% of the triangles (bark, cards and fruit
//!   together). A coarse level with fraction f draws √f of the sides on the thickest branches
//!   within f^1.5 of the bark's triangles (the trunk and main limbs; the thin inner wood goes)
//!   and gives the leaf cards the rest of its triangles: its n cards merge runs of
//!   neighbouring cards (along a Morton curve) into one card each, holding their area
//!   ([`lod_leaves`]), so the leaf area stays and the silhouette mostly does ([`silhouette`]
//!   measures how far it departs).
//!
//! Building: [`build_meshes`] makes every level (export, LOD switching); [`build_level`] makes
//! only the level a renderer draws, plus the whole leaf and fruit buffers; a [`Mesher`] kept
//! between calls reuses its working memory, and meshes passed back in reuse their buffers, so
//! re-meshing after an edit allocates nothing once the buffers have grown.
//!
//! Space: world metres, Y up, as the skeleton. All arrays are flat `[f32; N]` / `u32` vectors, ready
//! to be cast to GPU buffers.

pub mod billboard_cloud;
mod branches;
pub mod crown;
mod lanes;
pub mod leaf_card;
pub mod leaves;
mod lod_leaves;
mod looks;
mod mesher;
mod parent_tube;
mod petiole;
mod rings;
pub mod silhouette;
pub mod synthetic;
pub mod textures;
pub mod topology;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::tree::{NodeId, Skeleton};

pub use leaf_card::LeafCard;
pub use leaves::{FruitParams, LeafParams, ShortShoots};
pub use lod_leaves::merged_cards_into;
pub use looks::{
    BarkKind, BarkLook, FruitLook, LeafShape, Looks, Season, SeasonColors, TreeShade,
    build_tree_level, build_tree_meshes, build_tree_meshes_in, build_tree_meshes_with,
    mesh_params_for, mesh_params_in,
};
pub use mesher::{Levels, Mesher};
pub use topology::BranchTopology;

/// Ambient light at a world point: 1 = unshaded sky, 0 = full shade.
pub type AmbientFn<'a> = &'a dyn Fn(Vec3) -> f32;

/// Fractions of the full triangle count aimed at by the three levels of detail.
pub const LOD_TRIANGLE_FRACTIONS: [f32; 3] = [1.0, 0.4, 0.15];

/// Default of [`MeshParams::ring_tolerance`]: a joint off the straight line by less than a
/// quarter of the branch's radius gets no ring of its own (the bark's outline moves by at most
/// that, under a pixel until the branch is a few pixels wide).
pub const RING_TOLERANCE: f32 = 0.25;

/// Default of [`MeshParams::ring_tolerance_m`]: 4 mm, under one pixel of a 10 m tree seen whole
/// on a screen 2,160 pixels high.
pub const RING_TOLERANCE_M: f32 = 0.004;

/// Parameters of the tree mesh. Lengths in metres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshParams {
    /// Most sides a branch contour gets at the finest level of detail.
    pub max_sides: u32,
    /// Exponent n of C = 3·dⁿ/d_e (eq. C.2), diameters in metres. n > 1 scales a branch's sides
    /// by d^(n−1) against n = 1, so thin branches lose the most: the default 1.4 leaves a 1 cm
    /// twig 3 sides instead of 7 and a trunk its 16, which takes a 40-year willow's bark from
    /// 1.0M to 0.54M triangles.
    pub side_exponent: f32,
    /// Largest distance, relative to the branch's radius there, by which a joint's centre may
    /// stand off the straight line between the rings kept around it for its ring to be left
    /// out: nearly straight runs of a branch get one segment instead of one per internode. A
    /// ring where a visible branch grows out, a chain's first two rings and its tip are always
    /// kept. 0 keeps every ring (files written before this parameter).
    #[serde(default)]
    pub ring_tolerance: f32,
    /// The same distance in metres, for the thinnest twigs, whose radius is a few millimetres
    /// (the larger of the two applies). 0 in files written before this parameter.
    #[serde(default)]
    pub ring_tolerance_m: f32,
    /// Side length of one square bark texture tile on a thick branch.
    pub bark_tile_size: f32,
    /// Largest rotation of the bark texture from one segment to the next, in turns.
    pub bark_twist: f32,
    /// Radius at a branch tip relative to the radius at the base of its last internode.
    pub tip_taper: f32,
    pub leaves: LeafParams,
    /// Fruit or flowers; `None` for none.
    pub fruit: Option<FruitParams>,
    /// Linear RGB of the bark texture, leaf texture and fruit.
    pub bark_color: [f32; 3],
    pub leaf_color: [f32; 3],
    pub fruit_color: [f32; 3],
    /// Patterns of the bark and leaf textures.
    #[serde(default)]
    pub bark_kind: BarkKind,
    #[serde(default)]
    pub leaf_shape: LeafShape,
    /// Seed of the leaf order and placement jitter.
    pub seed: u64,
}

impl Default for MeshParams {
    fn default() -> Self {
        MeshParams {
            max_sides: 16,
            side_exponent: 1.4,
            ring_tolerance: RING_TOLERANCE,
            ring_tolerance_m: RING_TOLERANCE_M,
            bark_tile_size: 0.25,
            bark_twist: 0.02,
            tip_taper: 0.5,
            leaves: LeafParams::default(),
            fruit: None,
            bark_color: [0.22, 0.16, 0.11],
            leaf_color: [0.16, 0.36, 0.08],
            fruit_color: [0.65, 0.06, 0.04],
            bark_kind: BarkKind::default(),
            leaf_shape: LeafShape::default(),
            seed: 1,
        }
    }
}

/// Vertices just added to a [`TreeMesh`]: positions, normals, uvs, ambient.
pub(crate) type NewVertices<'a> = (
    &'a mut [[f32; 3]],
    &'a mut [[f32; 3]],
    &'a mut [[f32; 2]],
    &'a mut [f32],
);

/// An indexed triangle mesh with the attributes every tree part carries.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeMesh {
    /// World metres.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals.
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    /// Ambient light per vertex, 0..1.
    pub ambient: Vec<f32>,
    /// Triangles, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

impl TreeMesh {
    pub fn with_capacity(num_vertices: usize, num_indices: usize) -> Self {
        TreeMesh {
            positions: Vec::with_capacity(num_vertices),
            normals: Vec::with_capacity(num_vertices),
            uvs: Vec::with_capacity(num_vertices),
            ambient: Vec::with_capacity(num_vertices),
            indices: Vec::with_capacity(num_indices),
        }
    }

    /// Empties the mesh, keeping its capacity.
    pub fn clear(&mut self) {
        self.positions.clear();
        self.normals.clear();
        self.uvs.clear();
        self.ambient.clear();
        self.indices.clear();
    }

    pub fn reserve(&mut self, num_vertices: usize, num_indices: usize) {
        self.positions.reserve(num_vertices);
        self.normals.reserve(num_vertices);
        self.uvs.reserve(num_vertices);
        self.ambient.reserve(num_vertices);
        self.indices.reserve(num_indices);
    }

    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    pub fn num_triangles(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Grows the vertex arrays by `count` vertices and returns the new ones, to be written:
    /// positions, normals, uvs, ambient. The placeholders written first land in cache lines that
    /// are overwritten at once, so they cost no extra memory traffic.
    pub(crate) fn grow_vertices(&mut self, count: usize) -> NewVertices<'_> {
        let start = self.positions.len();
        let end = start + count;
        self.positions.resize(end, [0.0; 3]);
        self.normals.resize(end, [0.0; 3]);
        self.uvs.resize(end, [0.0; 2]);
        self.ambient.resize(end, 0.0);
        (
            &mut self.positions[start..],
            &mut self.normals[start..],
            &mut self.uvs[start..],
            &mut self.ambient[start..],
        )
    }

    /// Grows the index array by `count` indices and returns the new ones, to be written.
    pub(crate) fn grow_indices(&mut self, count: usize) -> &mut [u32] {
        let start = self.indices.len();
        self.indices.resize(start + count, 0);
        &mut self.indices[start..]
    }

    /// Axis-aligned bounds (min, max) of the vertices used by the first `num_indices` indices;
    /// `None` when there are none.
    pub fn bounds_of_prefix(&self, num_indices: usize) -> Option<(Vec3, Vec3)> {
        let used = &self.indices[..num_indices.min(self.indices.len())];
        let mut iter = used.iter().map(|&i| Vec3::from(self.positions[i as usize]));
        let first = iter.next()?;
        Some(iter.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Bounds of the whole mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds_of_prefix(self.indices.len())
    }

    /// Number of vertices used by the first `num_indices` indices, for buffers whose triangles
    /// are stored in vertex order (leaves, fruit): the largest index plus one.
    pub fn num_vertices_of_prefix(&self, num_indices: usize) -> usize {
        self.indices[..num_indices.min(self.indices.len())]
            .iter()
            .max()
            .map_or(0, |&m| m as usize + 1)
    }
}

/// Where a branch (a chain of the thickest-path topology) starts in a branch mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BranchStart {
    /// First internode of the branch.
    pub node: NodeId,
    /// The internode whose end the branch grows from, and that internode's continuation along
    /// the thickest path; `None` for the trunk.
    pub parent: Option<(NodeId, NodeId)>,
    /// Index of the first vertex of the branch's first ring; the ring has `sides + 1` vertices
    /// (the last repeats the first with u = 1).
    pub first_vertex: u32,
    pub sides: u32,
}

/// One level of detail.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lod {
    /// Index of this level in [`LOD_TRIANGLE_FRACTIONS`] (0 = finest).
    pub level: usize,
    /// Fraction of the finest level's triangles this level aims at.
    pub target_fraction: f32,
    pub branches: TreeMesh,
    pub branch_starts: Vec<BranchStart>,
    /// This level draws the first `num_leaf_indices` of [`Lod::leaves_in`]: of
    /// [`TreeMeshes::leaves`] at the finest level, of [`Lod::merged_leaves`] at coarser ones.
    pub num_leaf_indices: usize,
    /// A coarse level's leaf cards: fewer cards, each larger, holding the leaf area of the
    /// cards it stands for, so the crown keeps its silhouette instead of going bald. Empty at
    /// the finest level.
    pub merged_leaves: TreeMesh,
    /// The coarsest level's layout of [`Lod::merged_leaves`] as a billboard cloud
    /// ([`billboard_cloud`]): each quad drawn from a rectangle of one atlas holding the leaves
    /// it stands for. `None` at the other levels, whose merged cards use the leaf texture.
    pub billboards: Option<billboard_cloud::BillboardCloud>,
    /// This level draws the first `num_fruit_indices` of [`TreeMeshes::fruit`].
    pub num_fruit_indices: usize,
}

impl Lod {
    /// The leaf cards this level draws a prefix of: its merged cards, or `finest` (the tree's
    /// [`TreeMeshes::leaves`]) at the finest level.
    pub fn leaves_in<'a>(&'a self, finest: &'a TreeMesh) -> &'a TreeMesh {
        if self.level == 0 {
            finest
        } else {
            &self.merged_leaves
        }
    }

    pub fn num_triangles(&self) -> usize {
        self.branches.num_triangles() + (self.num_leaf_indices + self.num_fruit_indices) / 3
    }
}

/// Colours of the materials, linear RGB, and the patterns of their textures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MaterialColors {
    pub bark: [f32; 3],
    pub leaf: [f32; 3],
    pub fruit: [f32; 3],
    #[serde(default)]
    pub bark_kind: BarkKind,
    #[serde(default)]
    pub leaf_shape: LeafShape,
}

/// Every mesh of a tree: branches per level of detail, one randomly ordered leaf buffer and one
/// fruit buffer whose prefixes the levels draw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeMeshes {
    /// The levels built, finest first: all of them, or the one asked for ([`Levels`]).
    pub lods: Vec<Lod>,
    /// Leaf cards ([`LeafCard`]): quads of 4 vertices and 6 indices each, in random order.
    pub leaves: TreeMesh,
    /// The layout of the leaves on each card of [`Self::leaves`].
    pub leaf_card: LeafCard,
    /// Fruit meshes in random order.
    pub fruit: TreeMesh,
    pub colors: MaterialColors,
}

impl TreeMeshes {
    /// Triangles drawn at `lods[lod]`; 0 for a level that was not built.
    pub fn num_triangles(&self, lod: usize) -> usize {
        self.lods.get(lod).map_or(0, Lod::num_triangles)
    }

    /// Bounds of everything drawn at level `lod`.
    pub fn bounds(&self, lod: usize) -> Option<(Vec3, Vec3)> {
        let level = self.lods.get(lod)?;
        [
            level.branches.bounds(),
            level
                .leaves_in(&self.leaves)
                .bounds_of_prefix(level.num_leaf_indices),
            self.fruit.bounds_of_prefix(level.num_fruit_indices),
        ]
        .into_iter()
        .flatten()
        .reduce(|(a0, a1), (b0, b1)| (a0.min(b0), a1.max(b1)))
    }
}

/// Builds the branch, leaf and fruit meshes of `skeleton` at the three levels of detail of
/// [`LOD_TRIANGLE_FRACTIONS`], sampling `ambient` once per ring, leaf and fruit.
pub fn build_meshes(skeleton: &Skeleton, params: &MeshParams, ambient: AmbientFn) -> TreeMeshes {
    let mut meshes = TreeMeshes::default();
    build_meshes_into(skeleton, params, ambient, &mut meshes);
    meshes
}

/// [`build_meshes`] into existing meshes, reusing their buffers. Interactive re-meshing that
/// should allocate nothing keeps a [`Mesher`] (its working memory) between calls.
pub fn build_meshes_into(
    skeleton: &Skeleton,
    params: &MeshParams,
    ambient: AmbientFn,
    meshes: &mut TreeMeshes,
) {
    Mesher::new().build_into(skeleton, params, ambient, Levels::All, meshes);
}

/// The meshes of `skeleton` at level of detail `level` only (0 = finest; clamped to the
/// coarsest), with the whole leaf and fruit buffers: what a renderer draws, at a fraction of
/// the cost of every level. `lods` holds that one level, whose [`Lod::level`] says which.
pub fn build_level(
    skeleton: &Skeleton,
    params: &MeshParams,
    ambient: AmbientFn,
    level: usize,
) -> TreeMeshes {
    let mut meshes = TreeMeshes::default();
    Mesher::new().build_into(skeleton, params, ambient, Levels::One(level), &mut meshes);
    meshes
}

/// The number of indices of a `fraction` prefix, rounded to whole primitives of `unit` indices.
fn prefix_indices(num_indices: usize, unit: usize, fraction: f32) -> usize {
    let units = num_indices / unit;
    ((units as f32 * fraction).round() as usize).min(units) * unit
}

/// The geometry of one internode, copied out of the skeleton in one sequential pass: meshing
/// walks chains and leaves in orders that jump around the arena, and this compact copy keeps
/// those jumps in cache.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeGeom {
    pub start: Vec3,
    pub end: Vec3,
    pub left: Vec3,
    pub diameter: f32,
    /// Unit heading H (start → end); +Y for a degenerate internode.
    pub heading: Vec3,
    pub length: f32,
}

impl NodeGeom {
    pub(crate) fn new(node: &crate::tree::Internode) -> Self {
        let axis = node.end - node.start;
        NodeGeom {
            start: node.start,
            end: node.end,
            left: node.left,
            diameter: node.diameter,
            heading: axis.try_normalize().unwrap_or(Vec3::Y),
            length: axis.length(),
        }
    }

    /// The geometry of every internode of `skeleton`, into `nodes` (cleared first).
    pub(crate) fn collect_into(skeleton: &Skeleton, nodes: &mut Vec<NodeGeom>) {
        nodes.clear();
        nodes.extend(skeleton.internodes.iter().map(NodeGeom::new));
    }
}

/// Deterministic hash of an integer to [0, 1): placement jitter and the fruit lottery r.
pub(crate) fn hash_unit(mut x: u64) -> f32 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^= x >> 33;
    (x >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// Any unit vector perpendicular to unit `v`.
pub(crate) fn any_perpendicular(v: Vec3) -> Vec3 {
    let other = if v.x.abs() < 0.9 { Vec3::X } else { Vec3::Z };
    v.cross(other).try_normalize().unwrap_or(Vec3::Z)
}
