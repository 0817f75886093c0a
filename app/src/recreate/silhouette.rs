//! The model's silhouette seen from a tracked frame: its finest meshes (branches and leaf cards)
//! projected through the frame's camera (with the footage's distortion) and filled, for the
//! agreement with a traced outline (intersection over union) and for comparing with true masks.
//! Leaf cards are filled as the renderer draws them: only where the card's texture is opaque
//! (the alpha test), not as whole quads.

use glam::{Affine3A, DVec2, Vec2, Vec3};
use sylva_core::Tree;
use sylva_core::geometry::crown::{AlphaMask, CARD_TEXTURE_SIZE};
use sylva_core::geometry::leaf_card::card_texture;
use sylva_core::geometry::{Season, TreeMeshes};

use super::footage::TrackedFootage;
use super::hull::OutlineMask;

/// The model's triangles in the world: the branches', then from `first_leaf_index` on the leaf
/// cards', whose `uvs` the card's alpha mask tests.
pub struct WorldTriangles {
    pub positions: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<u32>,
    pub first_leaf_index: usize,
    pub card_alpha: AlphaMask,
}

impl WorldTriangles {
    /// The finest level's branches and leaf cards of `tree`, placed by `world_from_tree`.
    pub fn of_tree(tree: &Tree, world_from_tree: &Affine3A) -> Self {
        let meshes = sylva_core::geometry::build_tree_meshes_in(tree, Season::Summer);
        Self::of_meshes(&meshes, world_from_tree)
    }

    pub fn of_meshes(meshes: &TreeMeshes, world_from_tree: &Affine3A) -> Self {
        let mut out = WorldTriangles {
            positions: Vec::new(),
            uvs: Vec::new(),
            indices: Vec::new(),
            first_leaf_index: 0,
            card_alpha: AlphaMask::from_texture(&card_texture(meshes, CARD_TEXTURE_SIZE)),
        };
        let branches = meshes.lods.first().map(|lod| &lod.branches);
        for (is_leaves, mesh) in [(false, branches), (true, Some(&meshes.leaves))] {
            let Some(mesh) = mesh else {
                continue;
            };
            if is_leaves {
                out.first_leaf_index = out.indices.len();
            }
            let base = out.positions.len() as u32;
            let num_vertices = mesh.positions.len();
            out.uvs.extend(
                (0..num_vertices).map(|i| mesh.uvs.get(i).map_or(Vec2::ZERO, |uv| Vec2::from(*uv))),
            );
            out.positions.extend(
                mesh.positions
                    .iter()
                    .map(|p| world_from_tree.transform_point3(Vec3::from(*p))),
            );
            out.indices.extend(mesh.indices.iter().map(|i| base + i));
        }
        out
    }

    /// The leaf cards alone (the branches' triangles dropped).
    pub fn leaves_only(mut self) -> Self {
        self.indices.drain(..self.first_leaf_index);
        self.first_leaf_index = 0;
        self
    }
}

/// A binary image, row-major.
pub struct Silhouette {
    pub width: u32,
    pub height: u32,
    pub inside: Vec<bool>,
}

impl Silhouette {
    /// The model seen from `frame` (empty if the frame has no pose).
    pub fn render(footage: &TrackedFootage, frame: usize, model: &WorldTriangles) -> Self {
        let (width, height) = (footage.camera.width, footage.camera.height);
        let mut inside = vec![false; (width * height) as usize];
        if let Some(pose) = footage.world_from_camera.get(frame).copied().flatten() {
            let camera_from_world = pose.inverse();
            let projected: Vec<Option<DVec2>> = model
                .positions
                .iter()
                .map(|p| {
                    footage
                        .pixel_and_depth(&camera_from_world, p.as_dvec3())
                        .map(|(pixel, _)| pixel)
                })
                .collect();
            for (t, triangle) in model.indices.chunks_exact(3).enumerate() {
                let corners = [0, 1, 2].map(|k| projected[triangle[k] as usize]);
                let [Some(a), Some(b), Some(c)] = corners else {
                    continue;
                };
                if 3 * t < model.first_leaf_index {
                    fill_triangle(&mut inside, width, height, [a, b, c], None);
                } else {
                    let uvs = [0, 1, 2].map(|k| model.uvs[triangle[k] as usize]);
                    let card = Some((uvs, &model.card_alpha));
                    fill_triangle(&mut inside, width, height, [a, b, c], card);
                }
            }
        }
        Self {
            width,
            height,
            inside,
        }
    }

    /// Intersection over union with an outline, inside the image.
    pub fn iou_with_outline(&self, outline: &OutlineMask) -> f64 {
        self.iou_with(|x, y| outline.contains(DVec2::new(x as f64, y as f64)))
    }

    /// Intersection over union with `other(x, y)`.
    pub fn iou_with(&self, other: impl Fn(u32, u32) -> bool) -> f64 {
        let (mut both, mut either) = (0usize, 0usize);
        for y in 0..self.height {
            for x in 0..self.width {
                let a = self.inside[(y * self.width + x) as usize];
                let b = other(x, y);
                both += (a && b) as usize;
                either += (a || b) as usize;
            }
        }
        if either == 0 {
            0.0
        } else {
            both as f64 / either as f64
        }
    }

    /// 8-bit grey PNG: 255 on the model.
    pub fn save_png(&self, path: &std::path::Path) -> anyhow::Result<()> {
        save_mask_png(path, &self.inside, self.width, self.height)
    }
}

/// A `width` × `height` mask as an 8-bit grey PNG: 255 where `inside`, 0 elsewhere.
pub(crate) fn save_mask_png(
    path: &std::path::Path,
    inside: &[bool],
    width: u32,
    height: u32,
) -> anyhow::Result<()> {
    let pixels: Vec<u8> = inside.iter().map(|&v| if v { 255 } else { 0 }).collect();
    image::save_buffer(path, &pixels, width, height, image::ColorType::L8)?;
    Ok(())
}

/// Texture coordinates of a triangle's corners and the texture's alpha mask.
type CardUvs<'a> = ([Vec2; 3], &'a AlphaMask);

/// Marks the pixels whose centres lie inside triangle `abc` (either winding) and, for a leaf
/// card's triangle, where its texture is opaque at the pixel (uv interpolated across the
/// projected triangle: a card spans a few pixels, so perspective does not matter there).
fn fill_triangle(
    inside: &mut [bool],
    width: u32,
    height: u32,
    [a, b, c]: [DVec2; 3],
    card: Option<CardUvs>,
) {
    let area = (b - a).perp_dot(c - a);
    if area.abs() < 1e-12 {
        return;
    }
    let low = a.min(b).min(c);
    let high = a.max(b).max(c);
    let x0 = low.x.ceil().max(0.0) as i64;
    let y0 = low.y.ceil().max(0.0) as i64;
    let x1 = high.x.floor().min(width as f64 - 1.0) as i64;
    let y1 = high.y.floor().min(height as f64 - 1.0) as i64;
    let sign = area.signum();
    for y in y0..=y1 {
        for x in x0..=x1 {
            let p = DVec2::new(x as f64, y as f64);
            let w0 = (b - a).perp_dot(p - a) * sign;
            let w1 = (c - b).perp_dot(p - b) * sign;
            let w2 = (a - c).perp_dot(p - c) * sign;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            if let Some((uv, alpha)) = card {
                // w0 weighs c (the corner opposite ab), w1 weighs a, w2 weighs b.
                let total = (w0 + w1 + w2).max(1e-12);
                let at = (uv[0] * w1 as f32 + uv[1] * w2 as f32 + uv[2] * w0 as f32) / total as f32;
                if !alpha.is_opaque(at) {
                    continue;
                }
            }
            inside[(y as u32 * width + x as u32) as usize] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_filled_triangle_covers_half_its_bounding_square() {
        let mut inside = vec![false; 100 * 100];
        let corners = [
            DVec2::new(0.0, 0.0),
            DVec2::new(99.0, 0.0),
            DVec2::new(0.0, 99.0),
        ];
        fill_triangle(&mut inside, 100, 100, corners, None);
        let count = inside.iter().filter(|&&v| v).count();
        assert!((4900..5100).contains(&count), "{count} pixels");
    }

    #[test]
    fn a_leaf_card_is_filled_only_where_its_texture_is_opaque() {
        // The left half of the texture is opaque, the right half transparent.
        let texture =
            image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba([0, 0, 0, 255 * (1 - x as u8)]));
        let alpha = AlphaMask::from_texture(&texture);
        let mut inside = vec![false; 100 * 100];
        let corners = [
            DVec2::new(0.0, 0.0),
            DVec2::new(99.0, 0.0),
            DVec2::new(0.0, 99.0),
        ];
        let uvs = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
        ];
        fill_triangle(&mut inside, 100, 100, corners, Some((uvs, &alpha)));
        let count = inside.iter().filter(|&&v| v).count();
        assert!(inside[10 * 100 + 10] && !inside[10 * 100 + 80]);
        // The triangle's part with u < ½: ¾ of its 4950 pixels.
        assert!((3600..3850).contains(&count), "{count} pixels");
    }
}
