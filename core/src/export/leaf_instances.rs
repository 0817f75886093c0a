//! Leaf cards as instances of one card mesh (`EXT_mesh_gpu_instancing`): each card of the leaf
//! buffer (a quad of 4 vertices, base-left, base-right, tip-left, tip-right) becomes a
//! translation, rotation and scale of the card mesh, whose corners in card space are
//! (∓w/2, 0, 0) at the base and (∓w/2, l, 0) at the tip for the species' card of w × l
//! (x across, y along the card, z its normal's axis).
//!
//! glTF has no per-instance colour, so the cards' baked ambient light is binned into
//! [`AMBIENT_LEVELS`] levels, each drawn by a card mesh of its own colour; a card's normal
//! points along −z or +z of card space, and each side has its own card meshes too.

use glam::{Mat3, Quat, Vec3};

use super::quantize::Quantizer;
use crate::geometry::TreeMesh;

/// Levels of the baked ambient light of the leaf cards: steps of 1/15 of the range.
pub(super) const AMBIENT_LEVELS: usize = 16;

/// Which card mesh draws a card: its ambient level and the side of card space its normal
/// points to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(super) struct CardKind {
    pub(super) ambient_level: usize,
    /// The normal along +z (`true`) or −z of card space.
    pub(super) normal_up: bool,
}

impl CardKind {
    /// The ambient light (0..1) this kind's cards are drawn with.
    pub(super) fn ambient(self) -> f32 {
        self.ambient_level as f32 / (AMBIENT_LEVELS - 1) as f32
    }
}

/// One card placed in the node space of a [`Quantizer`]: translation of its base's midpoint,
/// rotation of card space, and scale (card space x, y, z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CardInstance {
    pub(super) translation: Vec3,
    pub(super) rotation: Quat,
    pub(super) scale: Vec3,
}

impl CardInstance {
    /// Where this instance puts card-space point `p` in world space, under the node transform
    /// of `quantizer`.
    #[cfg(test)]
    pub(super) fn world(&self, p: Vec3, quantizer: &Quantizer) -> Vec3 {
        let node = self.translation + self.rotation * (self.scale * p);
        quantizer.center + node * quantizer.half_extent
    }
}

/// The instances of the first `num_indices` indices' cards of `cards`, grouped by
/// [`CardKind`] (sorted by kind), for cards of `width_m` × `length_m`, in the node space of
/// `quantizer`.
pub(super) fn card_instances(
    cards: &TreeMesh,
    num_indices: usize,
    (width_m, length_m): (f32, f32),
    quantizer: &Quantizer,
) -> Vec<(CardKind, Vec<CardInstance>)> {
    let num_cards = num_indices.min(cards.indices.len()) / 6;
    let mut groups: Vec<(CardKind, Vec<CardInstance>)> = Vec::new();
    let (width_m, length_m) = (width_m.max(1e-6), length_m.max(1e-6));
    for card in 0..num_cards {
        let corner = |k: usize| Vec3::from(cards.positions[4 * card + k]);
        let across = corner(1) - corner(0);
        let along = corner(2) - corner(0);
        let x = across.try_normalize().unwrap_or(Vec3::X);
        let y = (along - x * along.dot(x))
            .try_normalize()
            .unwrap_or_else(|| crate::geometry::any_perpendicular(x));
        let z = x.cross(y);
        let rotation = Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize();
        // One sign for the quaternion: w ≥ 0.
        let rotation = if rotation.w < 0.0 {
            -rotation
        } else {
            rotation
        };
        let sx = across.length() / width_m;
        let sy = along.dot(y) / length_m;
        let base = (corner(0) + corner(1)) * 0.5;
        let instance = CardInstance {
            translation: quantizer.node_from_world(base),
            rotation,
            scale: Vec3::new(sx, sy, sx) / quantizer.half_extent,
        };
        let ambient = cards.ambient[4 * card].clamp(0.0, 1.0);
        let kind = CardKind {
            ambient_level: (ambient * (AMBIENT_LEVELS - 1) as f32).round() as usize,
            normal_up: Vec3::from(cards.normals[4 * card]).dot(z) >= 0.0,
        };
        match groups.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, instances)) => instances.push(instance),
            None => groups.push((kind, vec![instance])),
        }
    }
    groups.sort_by_key(|(kind, _)| *kind);
    groups
}

/// The scale every one of `instances` has, within a part in 10⁴ (the first one's); `None` when
/// they differ.
pub(super) fn common_scale(instances: &[CardInstance]) -> Option<Vec3> {
    let first = instances.first()?.scale;
    let tolerance = 1e-4 * first.max_element();
    instances
        .iter()
        .all(|i| (i.scale - first).abs().max_element() <= tolerance)
        .then_some(first)
}

/// The card mesh's corners in card space, in the leaf buffer's order, and their texture
/// coordinates (v = 1 at the base).
pub(super) fn card_corners((width_m, length_m): (f32, f32)) -> [([f32; 3], [f32; 2]); 4] {
    let half = 0.5 * width_m;
    [
        ([-half, 0.0, 0.0], [0.0, 1.0]),
        ([half, 0.0, 0.0], [1.0, 1.0]),
        ([-half, length_m, 0.0], [0.0, 0.0]),
        ([half, length_m, 0.0], [1.0, 0.0]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::leaves::push_quad_indices;

    #[test]
    fn an_instanced_card_puts_its_corners_where_the_quad_had_them() {
        let (w, l) = (0.06, 0.11);
        let quantizer = Quantizer::of((Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 9.0, 4.0)));
        let mut cards = TreeMesh::default();
        // A card of twice the size, tilted and turned, shaded at ambient 0.4.
        let x = Vec3::new(1.0, 0.2, -0.3).normalize();
        let y = x.cross(Vec3::new(0.3, 0.1, 1.0)).normalize();
        let base = Vec3::new(1.5, 6.0, -2.0);
        let corners = [
            base - x * w,
            base + x * w,
            base - x * w + y * 2.0 * l,
            base + x * w + y * 2.0 * l,
        ];
        let (p, n, uv, a) = cards.grow_vertices(4);
        for (out, c) in p.iter_mut().zip(corners) {
            *out = c.to_array();
        }
        n.fill(y.cross(x).to_array());
        uv.fill([0.0, 0.0]);
        a.fill(0.4);
        push_quad_indices(&mut cards, 0, 1);
        let groups = card_instances(&cards, 6, (w, l), &quantizer);
        assert_eq!(groups.len(), 1);
        let (kind, instances) = &groups[0];
        assert_eq!(kind.ambient_level, 6);
        assert!(!kind.normal_up, "the normal is −z of card space");
        for (k, (local, _)) in card_corners((w, l)).iter().enumerate() {
            let world = instances[0].world(Vec3::from(*local), &quantizer);
            assert!(world.distance(corners[k]) < 1e-5, "corner {k}: {world}");
        }
    }
}
