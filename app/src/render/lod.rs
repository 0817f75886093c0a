//! Levels of detail by the tree's size on screen. A coarse level of `sylva_core`'s meshes keeps
//! a fraction f of the leaf cards, each 1/√f larger (the same leaf area and silhouette, fewer
//! cards), and fewer bark triangles. The renderer draws the finest level whose cards are at
//! least [`MIN_CARD_PX`] on screen: once the finest cards shrink below that, a card holds
//! leaves smaller than a pixel and a coarser level draws the same crown with fewer, larger
//! cards, so a large or distant tree costs fewer instances, not more.

use glam::Vec3;
use sylva_core::geometry::LOD_TRIANGLE_FRACTIONS;

/// Smallest side of a drawn leaf card on screen before a coarser level is drawn, pixels.
pub const MIN_CARD_PX: f32 = 3.0;

/// Pixels per metre at `point` for a camera at `eye` looking along unit `forward` with focal
/// length `fy` (pixels): by the point's depth, at least 5 cm in front of the camera.
pub fn projected_px_per_m(fy: f32, eye: Vec3, forward: Vec3, point: Vec3) -> f32 {
    let depth = (point - eye).dot(forward).max(0.05);
    fy / depth
}

/// The level to draw of `num_levels` (finest first, their card fractions those of
/// [`LOD_TRIANGLE_FRACTIONS`]) when a finest-level card is `card_px` pixels on screen: the
/// finest whose cards reach [`MIN_CARD_PX`], else the coarsest. 0 without cards
/// (`card_px` 0).
pub fn level_for_card_px(card_px: f32, num_levels: usize) -> usize {
    if num_levels == 0 || card_px <= 0.0 {
        return 0;
    }
    let last = num_levels.min(LOD_TRIANGLE_FRACTIONS.len()) - 1;
    (0..=last)
        .find(|&level| card_px / LOD_TRIANGLE_FRACTIONS[level].sqrt() >= MIN_CARD_PX)
        .unwrap_or(last)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_near_tree_draws_its_finest_level_and_a_far_one_coarser_ones() {
        assert_eq!(level_for_card_px(10.0, 3), 0);
        assert_eq!(level_for_card_px(MIN_CARD_PX, 3), 0);
        // 0.4 of the cards, each 1/√0.4 = 1.58 times larger.
        assert_eq!(level_for_card_px(0.7 * MIN_CARD_PX, 3), 1);
        assert_eq!(level_for_card_px(0.5 * MIN_CARD_PX, 3), 2);
        assert_eq!(level_for_card_px(0.01, 3), 2);
        assert_eq!(level_for_card_px(0.01, 1), 0, "only one level built");
        assert_eq!(level_for_card_px(0.0, 3), 0, "a leafless tree");
    }

    #[test]
    fn pixels_per_metre_fall_with_depth_along_the_view() {
        let (eye, forward) = (Vec3::ZERO, Vec3::NEG_Z);
        let near = projected_px_per_m(500.0, eye, forward, Vec3::new(0.0, 0.0, -2.0));
        let far = projected_px_per_m(500.0, eye, forward, Vec3::new(3.0, 1.0, -20.0));
        assert!((near - 250.0).abs() < 1e-3 && (far - 25.0).abs() < 1e-3);
        assert!(projected_px_per_m(500.0, eye, forward, Vec3::Z).is_finite());
    }
}
