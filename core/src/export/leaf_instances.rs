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
use gltf_json as json;
use json::validation::Checked::Valid;

use super::ambient_color;
use super::glb::{Builder, f32_bytes};
use super::quantize::{self, Quantizer, snorm16, snorm16_up};
use crate::geometry::TreeMesh;

/// The glTF extension drawing a node's mesh once per instance transform.
pub(super) const EXT_MESH_GPU_INSTANCING: &str = "EXT_mesh_gpu_instancing";

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

impl Builder<'_> {
    /// The card mesh of `kind`'s cards: one quad of `size` (width, length) in card space, of
    /// the colour of its ambient level, with the leaf material.
    /// With `baked_scale`, the quad is scaled by it (the instances then carry no scale).
    pub(super) fn card_mesh(
        &mut self,
        kind: CardKind,
        size: (f32, f32),
        baked_scale: Option<glam::Vec3>,
        material: json::Index<json::Material>,
    ) -> json::Index<json::Mesh> {
        use json::accessor::ComponentType::{F32, U8, U16};
        use json::accessor::Type::{Scalar, Vec2, Vec3, Vec4};
        use json::buffer::Target::{ArrayBuffer, ElementArrayBuffer};
        let mut corners = card_corners(size);
        if let Some(scale) = baked_scale {
            for (p, _) in &mut corners {
                *p = (glam::Vec3::from(*p) * scale).to_array();
            }
        }
        let normal_z = if kind.normal_up { 1.0 } else { -1.0 };
        let positions = f32_bytes(corners.iter().flat_map(|(p, _)| p));
        let normals = f32_bytes([0.0, 0.0, normal_z].iter().cycle().take(12));
        let uvs = f32_bytes(corners.iter().flat_map(|(_, uv)| uv));
        let c = quantize::unorm8(ambient_color(kind.ambient()));
        let colors = [c, c, c, 255].repeat(4);
        let indices: Vec<u8> = [0u16, 2, 3, 0, 3, 1]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let (lo, hi) = (corners[0].0, corners[3].0);
        let view = self.view(&positions, Some(ArrayBuffer), Some(12));
        let position = self.accessor(
            view,
            0,
            4,
            F32,
            Vec3,
            false,
            Some((lo.to_vec(), hi.to_vec())),
        );
        let view = self.view(&normals, Some(ArrayBuffer), Some(12));
        let normal = self.accessor(view, 0, 4, F32, Vec3, false, None);
        let view = self.view(&uvs, Some(ArrayBuffer), Some(8));
        let uv = self.accessor(view, 0, 4, F32, Vec2, false, None);
        let view = self.view(&colors, Some(ArrayBuffer), Some(4));
        let color = self.accessor(view, 0, 4, U8, Vec4, true, None);
        let view = self.view(&indices, Some(ElementArrayBuffer), None);
        let index = self.accessor(view, 0, 6, U16, Scalar, false, None);
        let mut attributes = std::collections::BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), position);
        attributes.insert(Valid(json::mesh::Semantic::Normals), normal);
        attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), uv);
        attributes.insert(Valid(json::mesh::Semantic::Colors(0)), color);
        self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(format!(
                "leaf_card_ambient{}_{}",
                kind.ambient_level,
                if kind.normal_up { "up" } else { "down" }
            )),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(index),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        })
    }

    /// A node drawing `mesh` once per instance (`EXT_mesh_gpu_instancing`), the instances'
    /// translations, rotations and scales as normalized signed shorts (`KHR_mesh_quantization`);
    /// scales above 1 in node space (a tree under a metre across) as floats, and none
    /// `with_scale` false (the mesh holds the one scale of all of them).
    pub(super) fn instance_node(
        &mut self,
        name: String,
        mesh: json::Index<json::Mesh>,
        instances: &[CardInstance],
        with_scale: bool,
    ) -> json::Index<json::Node> {
        use json::accessor::ComponentType::{F32, I16};
        use json::accessor::Type::{Vec3, Vec4};
        let count = instances.len();
        let padded = |v: glam::Vec3| [snorm16(v.x), snorm16(v.y), snorm16(v.z), 0];
        // Heights round up, so that no card quantized below the ground sinks into it.
        let raised = |v: glam::Vec3| [snorm16(v.x), snorm16_up(v.y), snorm16(v.z), 0];
        let bytes: Vec<u8> = instances
            .iter()
            .flat_map(|i| raised(i.translation))
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let view = self.view(&bytes, None, Some(8));
        let translation = self.accessor(view, 0, count, I16, Vec3, true, None);
        let bytes: Vec<u8> = instances
            .iter()
            .flat_map(|i| i.rotation.to_array().map(snorm16))
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let view = self.view(&bytes, None, None);
        let rotation = self.accessor(view, 0, count, I16, Vec4, true, None);
        let fits = instances.iter().all(|i| i.scale.max_element() <= 1.0);
        let scale = if !with_scale {
            None
        } else if fits {
            let bytes: Vec<u8> = instances
                .iter()
                .flat_map(|i| padded(i.scale))
                .flat_map(|c| c.to_le_bytes())
                .collect();
            let view = self.view(&bytes, None, Some(8));
            Some(self.accessor(view, 0, count, I16, Vec3, true, None))
        } else {
            let bytes = f32_bytes(
                instances
                    .iter()
                    .flat_map(|i| i.scale.to_array())
                    .collect::<Vec<_>>()
                    .iter(),
            );
            let view = self.view(&bytes, None, None);
            Some(self.accessor(view, 0, count, F32, Vec3, false, None))
        };
        let mut attributes = serde_json::json!({
            "TRANSLATION": translation.value(),
            "ROTATION": rotation.value(),
        });
        if let Some(scale) = scale {
            attributes["SCALE"] = scale.value().into();
        }
        let mut others = serde_json::Map::new();
        others.insert(
            EXT_MESH_GPU_INSTANCING.into(),
            serde_json::json!({ "attributes": attributes }),
        );
        self.root.push(json::Node {
            mesh: Some(mesh),
            name: Some(name),
            extensions: Some(json::extensions::scene::Node { others }),
            ..Default::default()
        })
    }
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
