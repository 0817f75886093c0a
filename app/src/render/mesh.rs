//! What the renderer draws, as plain CPU data: the tree (bark and instanced leaf cards, lit, at
//! each level of detail), the scene
//! occluder (depth-only), and line/point overlays. World space: metres, Y up.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use sylva_core::geometry::{BarkKind, LeafCard, LeafShape};

/// A vertex of a lit surface (bark).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LitVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// Ambient (indirect) light at this vertex in [0, 1], from the growth shadow grid.
    pub ambient: f32,
    /// Bark texture coordinates (around the branch, along it in tiles).
    pub uv: [f32; 2],
}

/// Triangles of lit vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LitMesh {
    pub vertices: Vec<LitVertex>,
    pub indices: Vec<u32>,
}

impl LitMesh {
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Axis-aligned bounds, `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.vertices.iter().map(|v| Vec3::from(v.position));
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Appends another mesh.
    pub fn append(&mut self, other: &LitMesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }
}

/// One leaf card, drawn as an instance of the species' card quad: where its corners lie.
/// Corner (a, b) of the quad, a across and b along in 0..1, is `origin + a·across + b·along`;
/// it samples the card texture at (a, 1 − b) (the base on the bottom row, as
/// `sylva_core::geometry::leaf_card` draws it).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CardInstance {
    /// The card's base corner on its left side, world metres.
    pub origin: [f32; 3],
    /// From that corner across the card to the base's right corner, metres.
    pub across: [f32; 3],
    /// From that corner along the card to its tip's left corner, metres.
    pub along: [f32; 3],
    /// Unit normal of the card's front face.
    pub normal: [f32; 3],
    /// Ambient light of the card in [0, 1], from the growth shadow grid.
    pub ambient: f32,
}

impl CardInstance {
    /// The four corners: base-left, base-right, tip-left, tip-right.
    pub fn corners(&self) -> [Vec3; 4] {
        let (o, a, b) = (
            Vec3::from(self.origin),
            Vec3::from(self.across),
            Vec3::from(self.along),
        );
        [o, o + a, o + b, o + a + b]
    }
}

/// One level of detail of the drawn tree: its bark, its leaf cards and its fruit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeLevel {
    pub branches: LitMesh,
    pub cards: Vec<CardInstance>,
    /// Fruit of the season (acorns), in [`TreeLook::fruit_color`]; empty for none.
    pub fruit: LitMesh,
}

impl TreeLevel {
    /// Triangles drawn: the bark's, two per card and the fruit's.
    pub fn num_triangles(&self) -> usize {
        (self.branches.indices.len() + self.fruit.indices.len()) / 3 + 2 * self.cards.len()
    }

    /// Bounds of the bark and the cards' corners, `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let cards = self
            .cards
            .iter()
            .flat_map(CardInstance::corners)
            .map(|p| (p, p))
            .reduce(|(a0, a1), (b0, b1)| (a0.min(b0), a1.max(b1)));
        match (self.branches.bounds(), cards) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
            (a, b) => a.or(b),
        }
    }
}

/// What the species' textures are drawn from: the leaf outline, card layout and colour of the
/// season, the bark's pattern and colour. The renderer draws the textures again only when this
/// changes.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeLook {
    pub leaf_shape: LeafShape,
    /// Linear RGB of the leaves in the drawn season, and of the bark.
    pub leaf_color: [f32; 3],
    pub bark_kind: BarkKind,
    pub bark_color: [f32; 3],
    /// How the leaves lie on a card.
    pub leaf_card: LeafCard,
    /// Linear RGB of the fruit.
    pub fruit_color: [f32; 3],
}

impl Default for TreeLook {
    /// A generic broadleaf in the renderer's former fixed colours.
    fn default() -> Self {
        TreeLook {
            leaf_shape: LeafShape::default(),
            leaf_color: [0.16, 0.38, 0.09],
            bark_kind: BarkKind::default(),
            bark_color: [0.30, 0.21, 0.14],
            leaf_card: LeafCard::default(),
            fruit_color: [0.65, 0.06, 0.04],
        }
    }
}

/// The tree as drawn: its levels of detail, finest first (the renderer draws one, by the
/// tree's size on screen), in the species' look in its season.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeMesh {
    pub levels: Vec<TreeLevel>,
    pub look: TreeLook,
}

impl TreeMesh {
    /// The finest level (bark and every leaf card), `None` when nothing is drawn.
    pub fn finest(&self) -> Option<&TreeLevel> {
        self.levels.first()
    }

    /// The finest level's bark (empty when there is none).
    pub fn branches(&self) -> &[LitVertex] {
        self.finest()
            .map_or(&[], |l| l.branches.vertices.as_slice())
    }

    /// The finest level's leaf cards.
    pub fn cards(&self) -> &[CardInstance] {
        self.finest().map_or(&[], |l| l.cards.as_slice())
    }

    /// Bounds of the finest level: bark and leaf cards together.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.finest().and_then(TreeLevel::bounds)
    }

    /// Triangles of the finest level.
    pub fn num_triangles(&self) -> usize {
        self.finest().map_or(0, TreeLevel::num_triangles)
    }
}

/// The real scene as a triangle mesh in world space (the depth mesh): drawn into depth only.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OccluderMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<u32>,
}

impl OccluderMesh {
    /// Edges of every triangle as a line list (each shared edge once per triangle).
    pub fn wireframe(&self) -> Vec<[f32; 3]> {
        let mut lines = Vec::with_capacity(self.indices.len() * 2);
        for tri in self.indices.chunks_exact(3) {
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let (Some(pa), Some(pb)) = (
                    self.positions.get(tri[a] as usize),
                    self.positions.get(tri[b] as usize),
                ) else {
                    continue;
                };
                lines.push(pa.to_array());
                lines.push(pb.to_array());
            }
        }
        lines
    }

    /// An axis-aligned box (used for synthetic scenes: walls, fences, cabinets).
    pub fn add_box(&mut self, min: Vec3, max: Vec3) {
        let base = self.positions.len() as u32;
        for i in 0..8u32 {
            self.positions.push(Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            ));
        }
        const FACES: [[u32; 4]; 6] = [
            [0, 2, 6, 4],
            [1, 5, 7, 3],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 6, 7, 5],
        ];
        for f in FACES {
            self.indices
                .extend([f[0], f[1], f[2], f[0], f[2], f[3]].map(|i| base + i));
        }
    }
}

/// The fitted ground plane, world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundPlane {
    pub point: Vec3,
    /// Unit normal pointing up, out of the ground.
    pub normal: Vec3,
}

impl Default for GroundPlane {
    fn default() -> Self {
        GroundPlane {
            point: Vec3::ZERO,
            normal: Vec3::Y,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_has_twelve_triangles_and_a_wireframe_of_their_edges() {
        let mut m = OccluderMesh::default();
        m.add_box(Vec3::ZERO, Vec3::ONE);
        assert_eq!(m.indices.len(), 36);
        assert_eq!(m.wireframe().len(), 72);
    }

    #[test]
    fn appended_meshes_keep_their_triangles() {
        let v = LitVertex::default();
        let mut a = LitMesh {
            vertices: vec![v; 3],
            indices: vec![0, 1, 2],
        };
        let b = a.clone();
        a.append(&b);
        assert_eq!(a.indices, vec![0, 1, 2, 3, 4, 5]);
    }
}
