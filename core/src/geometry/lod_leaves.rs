//! A coarse level of detail's leaf cards: neighbouring cards merged into clusters, each drawn
//! as one larger card, so the crown keeps its leaf area and silhouette while the cards thin
//! out (the leaf clusters of SpeedTree's and Xfrog's level-of-detail cards).
//!
//! The cards are ordered along a Z-order (Morton) curve through their centres, so runs of
//! consecutive cards are spatial neighbourhoods, and the curve is cut into as many runs as the
//! level has cards. A run becomes one card: its member nearest the run's centroid, scaled
//! about its own centre to hold the run's whole card area, with the run's mean ambient light.
//! Kept in place rather than moved to the centroid (which may fall into a gap of the crown),
//! the card still covers what it covered at the finest level: at 30 years the coarsest level's
//! side view differed from the finest's by 14–24% (oak … spruce) where moving it gave 14–27%
//! and a random 15% of the cards, enlarged, 16–43%. None reaches below the ground plane. Since
//! the coarse levels give the cards the triangles the thin inner wood had (the mesher's
//! `CoarseBudget`), a run is 1.3–5 cards, and the coarsest side view differs by 9–24% at
//! 15 and 40 years (willow at 40 … poplar at 15). Repeating the leaf texture over the
//! enlarged card (keeping the leaves' size) instead of scaling it changed that by under 2
//! points either way: what is left is the cards' placement and orientation, not their grain.

use glam::Vec3;

use super::billboard_cloud::{self, CloudScratch};
use super::leaves::push_quad_indices;
use super::{Lod, TreeMesh};

/// Bits per axis of the Morton code of a card centre.
const MORTON_BITS: u32 = 10;

/// Working memory of [`merge_cards_into`].
#[derive(Default)]
pub(crate) struct MergeScratch {
    /// Card centre and area, per card of the finest level.
    centers: Vec<(Vec3, f32)>,
    /// Morton code (high 32 bits) and card index (low 32 bits), sorted.
    order: Vec<u64>,
    /// Working memory of the coarsest level's billboard cloud.
    cloud: CloudScratch,
}

/// The leaves of coarse level `lod` (its branches already meshed), at most `num_quads` quads
/// standing for all the cards of `cards`, the finest level's: the coarsest level a billboard
/// cloud ([`billboard_cloud`]), which keeps the gaps between a cluster's leaves, the others
/// merged cards ([`merge_cards_into`]), which the species' leaf texture draws. The cloud's atlas
/// also draws `wood`, the internodes whose bark the level does not mesh. Sets the level's leaf
/// index count.
#[allow(clippy::too_many_arguments)]
pub(crate) fn coarse_leaves_into(
    cards: &TreeMesh,
    wood: &[billboard_cloud::CloudWood],
    num_quads: usize,
    ground_y: f32,
    coarsest: bool,
    scratch: &mut MergeScratch,
    lod: &mut Lod,
) {
    if coarsest {
        let cloud = lod.billboards.get_or_insert_with(Default::default);
        billboard_cloud::build_cloud_into(
            cards,
            wood,
            num_quads,
            ground_y,
            &mut scratch.cloud,
            cloud,
            &mut lod.merged_leaves,
        );
    } else {
        lod.billboards = None;
        merge_cards_into(cards, num_quads, ground_y, scratch, &mut lod.merged_leaves);
    }
    lod.num_leaf_indices = lod.merged_leaves.indices.len();
}

/// `num_cards` merged cards standing for all the cards of `cards` (the finest level's), none
/// below y = `ground_y`, into `out`: what [`merge_cards_into`] makes for the levels above the
/// coarsest, for a renderer that draws the coarsest level with the species' leaf texture
/// rather than a billboard cloud's atlas (the cloud's quads drawn with the leaf texture would
/// show a leaf card where a cluster of leaves should be).
pub fn merged_cards_into(cards: &TreeMesh, num_cards: usize, ground_y: f32, out: &mut TreeMesh) {
    merge_cards_into(
        cards,
        num_cards,
        ground_y,
        &mut MergeScratch::default(),
        out,
    );
}

/// `num_cards` cards standing for all the cards of `cards` (quads of 4 vertices and 6 indices,
/// card k's vertices at 4k), into `out` (cleared first), none below y = `ground_y`.
pub(crate) fn merge_cards_into(
    cards: &TreeMesh,
    num_cards: usize,
    ground_y: f32,
    scratch: &mut MergeScratch,
    out: &mut TreeMesh,
) {
    out.clear();
    let total = cards.indices.len() / 6;
    let num_cards = num_cards.min(total);
    if num_cards == 0 {
        return;
    }
    let corner = |card: usize, k: usize| Vec3::from(cards.positions[4 * card + k]);
    let centers = &mut scratch.centers;
    centers.clear();
    centers.extend((0..total).map(|card| {
        let center = (0..4).map(|k| corner(card, k)).sum::<Vec3>() * 0.25;
        let across = corner(card, 1) - corner(card, 0);
        let along = corner(card, 2) - corner(card, 0);
        (center, across.cross(along).length())
    }));
    let (lo, hi) = centers.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &(c, _)| (lo.min(c), hi.max(c)),
    );
    let cells = (1u32 << MORTON_BITS) as f32;
    let scale = (cells - 1.0) / (hi - lo).max_element().max(1e-6);
    let order = &mut scratch.order;
    order.clear();
    order.extend(centers.iter().enumerate().map(|(index, &(c, _))| {
        let q = ((c - lo) * scale)
            .min(Vec3::splat(cells - 1.0))
            .max(Vec3::ZERO);
        let code = morton3(q.x as u32, q.y as u32, q.z as u32);
        (u64::from(code) << 32) | index as u64
    }));
    order.sort_unstable();
    out.reserve(4 * num_cards, 6 * num_cards);
    let (positions, normals, uvs, ambient) = out.grow_vertices(4 * num_cards);
    for cluster in 0..num_cards {
        let run = &order[cluster * total / num_cards..(cluster + 1) * total / num_cards];
        let members = || run.iter().map(|&key| key as u32 as usize);
        let (mut sum_center, mut sum_area, mut sum_light) = (Vec3::ZERO, 0.0f32, 0.0f32);
        for member in members() {
            let (center, area) = centers[member];
            sum_center += center;
            sum_area += area;
            sum_light += cards.ambient[4 * member];
        }
        let count = run.len() as f32;
        let centroid = sum_center / count;
        let nearest = members()
            .min_by(|&a, &b| {
                let da = centers[a].0.distance_squared(centroid);
                let db = centers[b].0.distance_squared(centroid);
                da.total_cmp(&db).then(a.cmp(&b))
            })
            .unwrap_or(0);
        let (center, area) = centers[nearest];
        let grow = (sum_area / area.max(1e-12)).sqrt();
        let range = 4 * cluster..4 * cluster + 4;
        let mut lowest = f32::INFINITY;
        for (k, out_corner) in positions[range.clone()].iter_mut().enumerate() {
            let p = center + (corner(nearest, k) - center) * grow;
            lowest = lowest.min(p.y);
            *out_corner = p.to_array();
        }
        let lift = (ground_y - lowest).max(0.0);
        for out_corner in &mut positions[range.clone()] {
            out_corner[1] += lift;
        }
        normals[range.clone()].copy_from_slice(&cards.normals[4 * nearest..4 * nearest + 4]);
        uvs[range.clone()].copy_from_slice(&cards.uvs[4 * nearest..4 * nearest + 4]);
        ambient[range].fill(sum_light / count);
    }
    push_quad_indices(out, 0, num_cards);
}

/// Interleaves the low 10 bits ([`MORTON_BITS`]) of x, y and z (x lowest); the billboard
/// cloud's octree keys use it too.
pub(super) fn morton3(x: u32, y: u32, z: u32) -> u32 {
    fn spread(mut v: u32) -> u32 {
        v &= 0x3ff;
        v = (v | (v << 16)) & 0x0300_00ff;
        v = (v | (v << 8)) & 0x0300_f00f;
        v = (v | (v << 4)) & 0x030c_30c3;
        (v | (v << 2)) & 0x0924_9249
    }
    spread(x) | (spread(y) << 1) | (spread(z) << 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geometry::synthetic::{branching_skeleton, crown_ambient};
    use crate::geometry::{LeafParams, MeshParams, build_meshes};

    #[test]
    fn merged_cards_keep_the_card_area_and_stay_above_the_ground() {
        let params = MeshParams {
            leaves: LeafParams {
                leaves_per_metre: 60.0,
                ..LeafParams::default()
            },
            ..MeshParams::default()
        };
        let skeleton = branching_skeleton(3_000, 5);
        let meshes = build_meshes(&skeleton, &params, &crown_ambient(Vec3::Y, 1.5));
        let cards = &meshes.leaves;
        let area = |mesh: &TreeMesh| {
            mesh.indices
                .chunks_exact(3)
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[t[k] as usize]));
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum::<f32>()
        };
        let num_cards = cards.indices.len() / 6;
        assert!(num_cards > 1_000, "{num_cards} cards");
        let mut merged = TreeMesh::default();
        let ground_y = 0.4;
        merge_cards_into(
            cards,
            num_cards / 7,
            ground_y,
            &mut MergeScratch::default(),
            &mut merged,
        );
        assert_eq!(merged.indices.len() / 6, num_cards / 7);
        let (fine, coarse) = (area(cards), area(&merged));
        assert!(
            (coarse / fine - 1.0).abs() < 1e-3,
            "{coarse} m² of merged cards for {fine} m²"
        );
        assert!(merged.positions.iter().all(|p| p[1] >= ground_y - 1e-5));
    }

    #[test]
    fn morton_codes_interleave_the_axes() {
        assert_eq!(morton3(1, 0, 0), 1);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 4);
        assert_eq!(morton3(3, 0, 0), 0b001_001);
        assert_eq!(morton3(1023, 1023, 1023), (1 << 30) - 1);
    }
}
