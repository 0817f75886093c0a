//! Leaf cards: one textured quad holding a spray of several leaves, so that small dense leaves
//! (willow, birch, needles) cost a card per spray rather than a quad per leaf (Longay 2014,
//! app. C.1.1, with the leaf clusters of SpeedTree and Xfrog libraries).
//!
//! A card's layout is a shoot: `leaves_per_card − 1` lateral leaves alternating left and right
//! along a central axis, each at [`LATERAL_ANGLE`] from it towards the tip, and a terminal leaf
//! along the axis. The card is the bounding box of its leaves. The same layout draws the card's
//! texture from the species' leaf texture ([`LeafCard::texture`]) and expands a card back into
//! its leaves ([`LeafCard::expand_into`]) for renderers that draw single leaves, so both show
//! the same leaves. One leaf per card is a card that is the leaf.
//!
//! Card space: x across (−width/2 … width/2), y along the axis from the base (0 … length),
//! metres. Card uv: u = x / width + ½ across, v = 1 at the base and 0 at the tip, as the leaf
//! texture (glTF puts v = 0 on the top row).

use glam::{Vec2, Vec3};
use image::{Rgba, RgbaImage};

use super::leaves::push_quad_indices;
use super::textures::leaf_texture;
use super::{LeafParams, TreeMesh, TreeMeshes};

/// Angle of a lateral leaf from the card's axis, radians (50°).
pub const LATERAL_ANGLE: f32 = 0.873;

/// Distance along the axis between successive lateral leaves, in leaf widths: alternating
/// sides, so leaves on one side are two steps apart and just overlap at this angle.
const LATERAL_SPACING_WIDTHS: f32 = 0.6;

/// Most leaves on one card (a damaged file must not ask for millions).
pub const MAX_LEAVES_PER_CARD: u32 = 256;

/// One leaf of a card, in card space: where its petiole end sits and the unit direction to its
/// tip.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CardLeaf {
    pub base: Vec2,
    pub direction: Vec2,
}

/// The layout of a leaf card and the blade it repeats.
#[derive(Clone, Debug, PartialEq)]
pub struct LeafCard {
    /// Blade length and width, metres.
    pub leaf_length_m: f32,
    pub leaf_width_m: f32,
    /// Card extent across and along, metres.
    pub width_m: f32,
    pub length_m: f32,
    pub leaves: Vec<CardLeaf>,
}

impl Default for LeafCard {
    fn default() -> Self {
        LeafCard::of(&LeafParams::default())
    }
}

impl LeafCard {
    /// The card of `params`: `leaves_per_card` blades of `length` × `width` (at least one).
    pub fn of(params: &LeafParams) -> Self {
        let mut card = LeafCard {
            leaf_length_m: 0.0,
            leaf_width_m: 0.0,
            width_m: 0.0,
            length_m: 0.0,
            leaves: Vec::new(),
        };
        card.set(params);
        card
    }

    /// Makes this the card of `params`, reusing its memory.
    pub fn set(&mut self, params: &LeafParams) {
        let (l, w) = (params.length.max(1e-4), params.width.max(1e-4));
        let n = params.leaves_per_card.clamp(1, MAX_LEAVES_PER_CARD) as usize;
        let spacing = LATERAL_SPACING_WIDTHS * w;
        let (sin, cos) = LATERAL_ANGLE.sin_cos();
        self.leaves.clear();
        self.leaves.extend((0..n - 1).map(|k| {
            let side = if k % 2 == 0 { -1.0 } else { 1.0 };
            CardLeaf {
                base: Vec2::new(0.0, k as f32 * spacing),
                direction: Vec2::new(side * sin, cos),
            }
        }));
        self.leaves.push(CardLeaf {
            base: Vec2::new(0.0, (n - 1) as f32 * spacing),
            direction: Vec2::Y,
        });
        let (mut half_width, mut lowest, mut highest) = (0.0f32, 0.0f32, 0.0f32);
        for corner in self.leaves.iter().flat_map(|leaf| leaf_corners(leaf, l, w)) {
            half_width = half_width.max(corner.x.abs());
            lowest = lowest.min(corner.y);
            highest = highest.max(corner.y);
        }
        // The lower corner of a lateral leaf dips below its base: shift the layout up so the
        // card starts at y = 0.
        for leaf in &mut self.leaves {
            leaf.base.y -= lowest;
        }
        self.leaf_length_m = l;
        self.leaf_width_m = w;
        self.width_m = 2.0 * half_width;
        self.length_m = highest - lowest;
    }

    pub fn num_leaves(&self) -> usize {
        self.leaves.len()
    }

    /// Corners of leaf `k` in card uv (base-left, base-right, tip-left, tip-right).
    fn leaf_uv_corners(&self, leaf: &CardLeaf) -> [Vec2; 4] {
        leaf_corners(leaf, self.leaf_length_m, self.leaf_width_m)
            .map(|c| Vec2::new(c.x / self.width_m + 0.5, 1.0 - c.y / self.length_m))
    }

    /// The card's texture, `size` × `size`: the leaves of the layout drawn from `leaf` (a blade
    /// texture, base at the bottom row), transparent elsewhere. With one leaf it is `leaf`
    /// resampled.
    pub fn texture(&self, leaf: &RgbaImage, size: u32) -> RgbaImage {
        let size = size.max(8);
        let (lw, lh) = (leaf.width().max(1), leaf.height().max(1));
        let (l, w) = (self.leaf_length_m, self.leaf_width_m);
        RgbaImage::from_fn(size, size, |px, py| {
            let u = (px as f32 + 0.5) / size as f32;
            let v = (py as f32 + 0.5) / size as f32;
            let p = Vec2::new((u - 0.5) * self.width_m, (1.0 - v) * self.length_m);
            // Later leaves lie over earlier ones: the terminal leaf on top.
            for leaf_in_card in self.leaves.iter().rev() {
                let d = leaf_in_card.direction;
                let rel = p - leaf_in_card.base;
                let along = rel.dot(d) / l;
                let across = rel.dot(-d.perp()) / w + 0.5;
                if !(0.0..1.0).contains(&along) || !(0.0..1.0).contains(&across) {
                    continue;
                }
                let tx = ((across * lw as f32) as u32).min(lw - 1);
                let ty = (((1.0 - along) * lh as f32) as u32).min(lh - 1);
                let texel = *leaf.get_pixel(tx, ty);
                if texel[3] >= 128 {
                    return texel;
                }
            }
            Rgba([0, 0, 0, 0])
        })
    }

    /// The single leaves of the first `num_indices` indices of `cards` (quads of 4 vertices
    /// and 6 indices as the leaf buffer holds them), into `out` (cleared first): a quad per
    /// leaf with the leaf texture's uvs, the card's normal and ambient.
    pub fn expand_into(&self, cards: &TreeMesh, num_indices: usize, out: &mut TreeMesh) {
        out.clear();
        let num_cards = num_indices.min(cards.indices.len()) / 6;
        let per_card = self.leaves.len();
        out.reserve(4 * per_card * num_cards, 6 * per_card * num_cards);
        let uv_corners: Vec<[Vec2; 4]> = self
            .leaves
            .iter()
            .map(|leaf| self.leaf_uv_corners(leaf))
            .collect();
        for card in 0..num_cards {
            // The leaf buffer stores each card's 4 vertices in order at 4·card.
            let first = cards.indices[6 * card] as usize;
            let corner = |k: usize| Vec3::from(cards.positions[first + k]);
            let (origin, across, along) = (corner(0), corner(1) - corner(0), corner(2) - corner(0));
            let base = out.positions.len() as u32;
            let (positions, normals, uvs, ambient) = out.grow_vertices(4 * per_card);
            for (k, leaf) in uv_corners.iter().enumerate() {
                for (j, uv) in leaf.iter().enumerate() {
                    let world = origin + across * uv.x + along * (1.0 - uv.y);
                    positions[4 * k + j] = world.to_array();
                }
                uvs[4 * k..4 * k + 4].copy_from_slice(&[
                    [0.0, 1.0],
                    [1.0, 1.0],
                    [0.0, 0.0],
                    [1.0, 0.0],
                ]);
            }
            normals.fill(cards.normals[first]);
            ambient.fill(cards.ambient[first]);
            push_quad_indices(out, base, per_card);
        }
    }
}

/// The texture of the leaf cards of `meshes`, `size` × `size`: their layout drawn from the
/// species' leaf texture. What exports embed and crown measures alpha-test.
pub fn card_texture(meshes: &TreeMeshes, size: u32) -> RgbaImage {
    meshes.leaf_card.texture(
        &leaf_texture(meshes.colors.leaf_shape, meshes.colors.leaf, size),
        size,
    )
}

/// Corners of a leaf of length `l` and width `w` in card space: base-left, base-right,
/// tip-left, tip-right (left is −x for the upright terminal leaf).
fn leaf_corners(leaf: &CardLeaf, l: f32, w: f32) -> [Vec2; 4] {
    let d = leaf.direction;
    let half = -d.perp() * (0.5 * w);
    let tip = leaf.base + d * l;
    [leaf.base - half, leaf.base + half, tip - half, tip + half]
}

/// Default of [`LeafParams::leaves_per_card`] for files written before cards: one leaf.
pub(crate) fn one_leaf_per_card() -> u32 {
    1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(leaves_per_card: u32) -> LeafParams {
        LeafParams {
            length: 0.1,
            width: 0.03,
            leaves_per_card,
            ..LeafParams::default()
        }
    }

    #[test]
    fn a_card_of_one_leaf_is_the_leaf() {
        let card = LeafCard::of(&params(1));
        assert_eq!(card.num_leaves(), 1);
        assert!((card.width_m - 0.03).abs() < 1e-6 && (card.length_m - 0.1).abs() < 1e-6);
        let uv = card.leaf_uv_corners(&card.leaves[0]);
        let expected = [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]].map(Vec2::from);
        for (a, b) in uv.iter().zip(expected) {
            assert!(a.distance(b) < 1e-5, "{a} vs {b}");
        }
    }

    #[test]
    fn every_leaf_of_a_card_lies_inside_the_card() {
        for n in [1, 2, 5, 12] {
            let card = LeafCard::of(&params(n));
            assert_eq!(card.num_leaves(), n as usize);
            for leaf in &card.leaves {
                for uv in card.leaf_uv_corners(leaf) {
                    assert!(
                        (-1e-4..=1.0001).contains(&uv.x) && (-1e-4..=1.0001).contains(&uv.y),
                        "{n} leaves: corner {uv} outside the card"
                    );
                }
            }
        }
    }

    #[test]
    fn a_card_texture_holds_about_the_blade_area_of_its_leaves() {
        let leaf = leaf_texture(super::super::LeafShape::Elliptic, [0.1, 0.4, 0.1], 128);
        let leaf_fraction = leaf.pixels().filter(|p| p[3] >= 128).count() as f32
            / (leaf.width() * leaf.height()) as f32;
        let card = LeafCard::of(&params(5));
        let texture = card.texture(&leaf, 256);
        let opaque = texture.pixels().filter(|p| p[3] >= 128).count() as f32 / 65_536.0;
        let card_blade_m2 = opaque * card.width_m * card.length_m;
        let leaves_blade_m2 = 5.0 * leaf_fraction * 0.1 * 0.03;
        // Overlapping leaves count once on the card, so it holds a little less.
        assert!(
            card_blade_m2 <= leaves_blade_m2 * 1.03 && card_blade_m2 >= 0.7 * leaves_blade_m2,
            "card {card_blade_m2} m² vs leaves {leaves_blade_m2} m²"
        );
    }

    #[test]
    fn an_expanded_card_gives_its_leaves_inside_its_quad() {
        let card = LeafCard::of(&params(4));
        let mut cards = TreeMesh::default();
        let corners = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 3.0, 0.0],
            [2.0, 3.0, 0.0],
        ];
        let (p, n, uv, a) = cards.grow_vertices(4);
        p.copy_from_slice(&corners);
        n.fill([0.0, 0.0, 1.0]);
        uv.fill([0.0, 0.0]);
        a.fill(0.5);
        cards.grow_indices(6).copy_from_slice(&[0, 2, 3, 0, 3, 1]);
        let mut leaves = TreeMesh::default();
        card.expand_into(&cards, 6, &mut leaves);
        assert_eq!(leaves.num_vertices(), 16);
        assert_eq!(leaves.num_triangles(), 8);
        for q in &leaves.positions {
            assert!((-1e-4..=2.0001).contains(&q[0]) && (-1e-4..=3.0001).contains(&q[1]));
        }
        assert!(leaves.ambient.iter().all(|&x| x == 0.5));
    }
}
