//! The project's own bark and leaf textures, generated procedurally: tileable bark (furrowed
//! periodic value noise) and an alpha-masked leaf blade with midrib and veins.
//!
//! Images are sRGB RGBA8, as glTF base colour textures expect. Leaf uv: u across the blade,
//! v = 1 at the base and 0 at the tip (glTF puts v = 0 on the top row).

use image::{Rgba, RgbaImage};

use super::hash_unit;

/// Linear to sRGB-encoded 8-bit.
fn srgb8(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let encoded = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0 + 0.5) as u8
}

/// Value noise on a lattice of `period_x × period_y` cells that wraps around, so the texture
/// tiles; `x`, `y` in lattice units.
fn periodic_noise(x: f32, y: f32, period_x: u32, period_y: u32, seed: u64) -> f32 {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (smooth(fx), smooth(fy));
    let lattice = |i: i64, j: i64| {
        let i = i.rem_euclid(i64::from(period_x)) as u64;
        let j = j.rem_euclid(i64::from(period_y)) as u64;
        hash_unit(seed ^ (i << 32) ^ (j << 8) ^ 0x5bd1)
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let top = lattice(i, j) * (1.0 - sx) + lattice(i + 1, j) * sx;
    let bottom = lattice(i, j + 1) * (1.0 - sx) + lattice(i + 1, j + 1) * sx;
    top * (1.0 - sy) + bottom * sy
}

/// A tileable `size × size` bark texture tinted by `color` (linear RGB): vertical ridges and
/// dark furrows with fine grain.
pub fn bark_texture(color: [f32; 3], size: u32) -> RgbaImage {
    let size = size.max(8);
    RgbaImage::from_fn(size, size, |x, y| {
        let (u, v) = (x as f32 / size as f32, y as f32 / size as f32);
        // Ridges: stretched along v (the branch), wavering sideways.
        let waver = periodic_noise(u * 4.0, v * 3.0, 4, 3, 7) * 0.6;
        let ridges = periodic_noise(u * 12.0 + waver, v * 2.0, 12, 2, 11);
        let furrow = ((ridges - 0.35) * 3.0).clamp(0.0, 1.0);
        let grain = periodic_noise(u * 48.0, v * 24.0, 48, 24, 13);
        let plates = periodic_noise(u * 6.0, v * 6.0, 6, 6, 17);
        let brightness = 0.35 + 0.75 * furrow + 0.25 * (grain - 0.5) + 0.2 * (plates - 0.5);
        let [r, g, b] = color.map(|c| srgb8(c * brightness.max(0.05)));
        Rgba([r, g, b, 255])
    })
}

/// A `size × size` leaf blade tinted by `color` (linear RGB) with alpha 0 outside the blade:
/// base at the bottom row, tip at the top, lighter midrib and veins.
pub fn leaf_texture(color: [f32; 3], size: u32) -> RgbaImage {
    let size = size.max(8);
    RgbaImage::from_fn(size, size, |x, y| {
        let u = (x as f32 + 0.5) / size as f32;
        let along = 1.0 - (y as f32 + 0.5) / size as f32; // 0 at the base, 1 at the tip
        let half_width = 0.47 * (std::f32::consts::PI * along.powf(0.8)).sin().max(0.0);
        let across = (u - 0.5).abs();
        let inside = across < half_width && along > 0.02;
        let mut shade = 0.85 + 0.15 * periodic_noise(u * 16.0, along * 16.0, 16, 16, 23);
        if across < 0.012 + 0.01 * (1.0 - along) {
            shade *= 1.45; // midrib
        } else {
            let vein_phase = (along - across * 0.9) * 9.0;
            if (vein_phase - vein_phase.round()).abs() < 0.06 {
                shade *= 1.25;
            }
        }
        if half_width > 0.0 && across > half_width * 0.85 {
            shade *= 0.85; // darker rim
        }
        let [r, g, b] = color.map(|c| srgb8(c * shade));
        Rgba([r, g, b, if inside { 255 } else { 0 }])
    })
}

/// Encodes an image as PNG bytes.
pub fn png_bytes(image: &RgbaImage) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    image.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bark_tiles_seamlessly_across_its_edges() {
        let size = 64;
        let bark = bark_texture([0.3, 0.2, 0.1], size);
        // The difference across the wrap-around edge is no larger than between neighbours.
        let step = |a: &Rgba<u8>, b: &Rgba<u8>| (i32::from(a[0]) - i32::from(b[0])).abs();
        let mut wrap = 0;
        let mut inner = 0;
        for y in 0..size {
            wrap += step(bark.get_pixel(size - 1, y), bark.get_pixel(0, y));
            inner += step(bark.get_pixel(size / 2, y), bark.get_pixel(size / 2 + 1, y));
        }
        assert!(
            wrap <= inner * 3 + size as i32 * 4,
            "seam {wrap} vs inner {inner}"
        );
    }

    #[test]
    fn leaf_is_opaque_in_the_middle_and_transparent_in_the_corners() {
        let leaf = leaf_texture([0.1, 0.4, 0.1], 64);
        assert_eq!(leaf.get_pixel(32, 32)[3], 255);
        assert_eq!(leaf.get_pixel(0, 0)[3], 0);
        assert_eq!(leaf.get_pixel(63, 63)[3], 0);
        let png = png_bytes(&leaf).expect("png encodes");
        assert_eq!(&png[1..4], b"PNG");
    }
}
