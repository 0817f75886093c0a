//! How far a coarse level of detail's side view departs from the finest level's: both are
//! rasterised ([`super::crown`]) within the finest level's bounds at
//! [`SILHOUETTE_HEIGHT_PX`] screen pixels over the tree's height, about where a renderer
//! switches to its coarsest level, each screen pixel averaging [`SILHOUETTE_SUBPIXELS`]²
//! samples as a renderer's filtering does; the difference is the sum over screen pixels of
//! |Δ opacity| over the sum of the finest level's opacity ([`Coverage::filtered_difference`]).
//! A billboard-cloud level ([`super::billboard_cloud`]) is alpha-tested against its own atlas,
//! drawn from the same card texture.

use super::TreeMeshes;
use super::billboard_cloud::level_atlas;
use super::crown::{AlphaMask, CARD_TEXTURE_SIZE, Coverage, LEAF, View, WOOD, rasterise_within};
use super::leaf_card::card_texture;

/// Screen pixels over the tree's height at which levels are compared.
pub const SILHOUETTE_HEIGHT_PX: f32 = 100.0;
/// Samples per screen pixel along each axis.
pub const SILHOUETTE_SUBPIXELS: usize = 8;

/// The side views of level `lod` and of the finest level of `meshes`, and their filtered
/// difference (0 = the same image). `None` when the level is not built or the tree is empty.
pub fn side_silhouette_difference(meshes: &TreeMeshes, lod: usize) -> Option<f32> {
    let texture = card_texture(meshes, CARD_TEXTURE_SIZE);
    let mask = AlphaMask::from_texture(&texture);
    let coarse_mask =
        level_atlas(meshes, lod, &texture).map(|atlas| AlphaMask::from_texture(&atlas));
    let (fine, coarse) = side_views(meshes, lod, &mask, coarse_mask.as_ref().unwrap_or(&mask))?;
    fine.filtered_difference(&coarse, LEAF | WOOD, SILHOUETTE_SUBPIXELS)
}

/// The finest level's and level `lod`'s side views, rasterised within the finest level's
/// bounds, their leaves alpha-tested against `mask` and `lod_mask`.
pub fn side_views(
    meshes: &TreeMeshes,
    lod: usize,
    mask: &AlphaMask,
    lod_mask: &AlphaMask,
) -> Option<(Coverage, Coverage)> {
    meshes.lods.get(lod)?;
    let bounds = meshes.bounds(0)?;
    let height_m = bounds.1.y - bounds.0.y;
    if height_m <= 0.0 {
        return None;
    }
    let pixel_m = height_m / (SILHOUETTE_HEIGHT_PX * SILHOUETTE_SUBPIXELS as f32);
    let view = |level: usize, mask: &AlphaMask| {
        rasterise_within(meshes, level, mask, View::Side, pixel_m, bounds)
    };
    Some((view(0, mask), view(lod, lod_mask)))
}
