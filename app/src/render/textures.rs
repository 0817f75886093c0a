//! The tree's textures on the GPU: the species' leaf card (its leaves' outline in the season's
//! colour, alpha outside them) and its bark, drawn by `sylva_core::geometry::textures` and
//! uploaded with mipmaps.
//!
//! A leaf card's alpha is drawn to coverage under MSAA; averaging alpha into coarser mip levels
//! would thin a distant crown (fewer texels reach the 0.5 cut), so each level's alpha is scaled
//! to keep the share of covered texels of the full-size image (coverage-preserving mipmaps,
//! Castaño 2010).

use image::{DynamicImage, RgbaImage, imageops};
use sylva_core::geometry::textures::{bark_texture, leaf_texture};

use crate::render::mesh::TreeLook;

/// Side of the leaf card texture, texels.
pub const CARD_TEXTURE_SIZE: u32 = 512;
/// Side of the bark texture tile, texels.
pub const BARK_TEXTURE_SIZE: u32 = 256;

/// The images of a look: the leaf card (RGBA) and the bark tile (RGBA, opaque).
pub fn look_images(look: &TreeLook) -> (RgbaImage, RgbaImage) {
    let leaf = leaf_texture(look.leaf_shape, look.leaf_color, CARD_TEXTURE_SIZE);
    let mut card = look.leaf_card.texture(&leaf, CARD_TEXTURE_SIZE);
    fill_transparent_with_mean(&mut card);
    let bark = DynamicImage::from(bark_texture(
        look.bark_kind,
        look.bark_color,
        BARK_TEXTURE_SIZE,
    ))
    .to_rgba8();
    (card, bark)
}

/// Gives the transparent texels of `image` the mean colour of its opaque ones, so that
/// filtering (mipmaps, bilinear taps at a blade's edge) blends the blade with its own colour,
/// not with black.
fn fill_transparent_with_mean(image: &mut RgbaImage) {
    let (mut sum, mut count) = ([0u64; 3], 0u64);
    for p in image.pixels().filter(|p| p[3] >= 128) {
        for (s, c) in sum.iter_mut().zip(p.0) {
            *s += u64::from(c);
        }
        count += 1;
    }
    let Some(mean) = (count > 0).then(|| sum.map(|s| (s / count) as u8)) else {
        return;
    };
    for p in image.pixels_mut().filter(|p| p[3] == 0) {
        p.0 = [mean[0], mean[1], mean[2], 0];
    }
}

/// Share of texels whose alpha is at least `cut` after scaling alpha by `scale`.
fn coverage(image: &RgbaImage, cut: f32, scale: f32) -> f32 {
    let covered = image
        .pixels()
        .filter(|p| f32::from(p[3]) / 255.0 * scale >= cut)
        .count();
    covered as f32 / (image.width() * image.height()).max(1) as f32
}

/// Scales `image`'s alpha so that the share of texels at or above 0.5 is `target` (as near as
/// a bisection of the scale in 0.5..8 gets).
fn preserve_coverage(image: &mut RgbaImage, target: f32) {
    let (mut lo, mut hi) = (0.5f32, 8.0f32);
    for _ in 0..16 {
        let mid = 0.5 * (lo + hi);
        if coverage(image, 0.5, mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let scale = 0.5 * (lo + hi);
    for p in image.pixels_mut() {
        p[3] = (f32::from(p[3]) * scale).round().min(255.0) as u8;
    }
}

/// The mip chain of `image`, full size first, each level half the last (box filtered, at least
/// one texel a side). With `keep_coverage`, alpha keeps the full image's covered share.
pub fn mip_chain(image: &RgbaImage, keep_coverage: bool) -> Vec<RgbaImage> {
    let target = coverage(image, 0.5, 1.0);
    let mut levels = vec![image.clone()];
    loop {
        let last = levels.last().map_or((1, 1), |l| l.dimensions());
        if last.0 <= 1 && last.1 <= 1 {
            break;
        }
        let size = ((last.0 / 2).max(1), (last.1 / 2).max(1));
        // Each level from the full image, so rounding does not pile up level after level.
        let mut level = imageops::resize(image, size.0, size.1, imageops::FilterType::Triangle);
        if keep_coverage {
            preserve_coverage(&mut level, target);
        }
        levels.push(level);
    }
    levels
}

/// An sRGB texture of `image` with its full mip chain, uploaded.
pub fn upload_mipmapped(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    image: &RgbaImage,
    keep_coverage: bool,
) -> wgpu::Texture {
    let levels = mip_chain(image, keep_coverage);
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: image.width().max(1),
            height: image.height().max(1),
            depth_or_array_layers: 1,
        },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (mip, level) in levels.iter().enumerate() {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            level.as_raw(),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(level.width() * 4),
                rows_per_image: Some(level.height()),
            },
            wgpu::Extent3d {
                width: level.width(),
                height: level.height(),
                depth_or_array_layers: 1,
            },
        );
    }
    texture
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coarse_mip_levels_of_a_leaf_card_keep_its_covered_share() {
        let (card, _) = look_images(&TreeLook::default());
        let full = coverage(&card, 0.5, 1.0);
        assert!(full > 0.1, "the card is covered by {full}");
        let levels = mip_chain(&card, true);
        assert_eq!(levels.len(), 10, "512 down to 1");
        for level in &levels[1..6] {
            let share = coverage(level, 0.5, 1.0);
            assert!(
                (share - full).abs() < 0.05,
                "{}: {share} against {full}",
                level.width()
            );
        }
        // Filtering never mixes black into the blade: transparent texels carry the leaf's colour.
        let mean_green = |img: &RgbaImage| {
            let opaque: Vec<_> = img.pixels().filter(|p| p[3] >= 128).collect();
            opaque.iter().map(|p| f32::from(p[1])).sum::<f32>() / opaque.len().max(1) as f32
        };
        let (fine, coarse) = (mean_green(&card), mean_green(&levels[5]));
        assert!(
            coarse > 0.8 * fine,
            "green {coarse} at 16 texels, {fine} at full size"
        );
    }
}
