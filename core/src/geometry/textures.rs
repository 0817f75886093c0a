//! The project's own bark and leaf textures, generated procedurally for each species' look
//! ([`super::Looks`]): tileable bark in four patterns ([`BarkKind`]) and alpha-masked leaf
//! blades in seven outlines ([`LeafShape`]), each with its veins.
//!
//! Images are sRGB, as glTF base colour textures expect: bark RGB8 (it is opaque), leaves RGBA8.
//! Leaf uv: u across the blade, v = 1 at the base and 0 at the tip (glTF puts v = 0 on the top
//! row). A blade is drawn in the unit square and stretched over the leaf card, so its width
//! on the tree comes from the species' leaf width.

use image::{EncodableLayout, ImageBuffer, PixelWithColorType, Rgb, RgbImage, Rgba, RgbaImage};

use super::hash_unit;
use super::looks::{BarkKind, LeafShape};

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

/// A feature point in each cell of a `period × period` lattice that wraps around: the distances
/// (lattice units) from `(x, y)` to the nearest and second nearest, and the nearest's hash.
fn periodic_cells(x: f32, y: f32, period_x: u32, period_y: u32, seed: u64) -> (f32, f32, f32) {
    let (cx, cy) = (x.floor() as i64, y.floor() as i64);
    let (mut f1, mut f2, mut id) = (f32::INFINITY, f32::INFINITY, 0.0);
    for j in cy - 1..=cy + 1 {
        for i in cx - 1..=cx + 1 {
            let wi = i.rem_euclid(i64::from(period_x)) as u64;
            let wj = j.rem_euclid(i64::from(period_y)) as u64;
            let key = seed ^ (wi << 32) ^ (wj << 12);
            let px = i as f32 + 0.15 + 0.7 * hash_unit(key ^ 0x11);
            let py = j as f32 + 0.15 + 0.7 * hash_unit(key ^ 0x22);
            let d = (px - x).hypot(py - y);
            if d < f1 {
                f2 = f1;
                f1 = d;
                id = hash_unit(key ^ 0x33);
            } else if d < f2 {
                f2 = d;
            }
        }
    }
    (f1, f2, id)
}

/// A tileable `size × size` bark texture of pattern `kind`, tinted by `color` (linear RGB).
pub fn bark_texture(kind: BarkKind, color: [f32; 3], size: u32) -> RgbImage {
    let size = size.max(8);
    RgbImage::from_fn(size, size, |x, y| {
        let (u, v) = (x as f32 / size as f32, y as f32 / size as f32);
        let (brightness, tint) = match kind {
            BarkKind::Furrowed => (furrowed(u, v), [1.0; 3]),
            BarkKind::FineRidged => (fine_ridged(u, v), [1.0; 3]),
            BarkKind::Papery => papery(u, v),
            BarkKind::Scaly => (scaly(u, v), [1.0; 3]),
        };
        let mut rgb = [0u8; 3];
        for ((out, c), t) in rgb.iter_mut().zip(color).zip(tint) {
            *out = srgb8(c * t * brightness.max(0.03));
        }
        Rgb(rgb)
    })
}

/// Ridges along the branch (v) between dark furrows, wavering sideways and broken into blocks
/// by shallow cross cracks: `ridges` across the tile, furrows `depth` (0..1) dark and
/// `furrow_width` (0..1) of a ridge's pitch wide, `blocks` cracks along it.
fn ridged(u: f32, v: f32, ridges: u32, depth: f32, furrow_width: f32, blocks: u32) -> f32 {
    let n = ridges as f32;
    let waver = (periodic_noise(u * 3.0, v * 2.0, 3, 2, 7) - 0.5) * 0.9
        + (periodic_noise(u * 7.0, v * 5.0, 7, 5, 9) - 0.5) * 0.4;
    let x = u * n + waver;
    let cell = x.floor();
    let across = (x - cell - 0.5).abs() * 2.0; // 0 on a ridge's crest, 1 in the furrow
    let width = furrow_width * (0.6 + 0.8 * periodic_noise(x, v * 4.0, ridges, 4, 11));
    let furrow = ((across - (1.0 - width)) / width.max(1e-3)).clamp(0.0, 1.0);
    // A rounded crest, lit from one side, so the ridges stand out.
    let relief = 0.8 + 0.25 * (1.0 - across * across) - 0.1 * (x - cell - 0.5);
    let crack = if blocks == 0 {
        0.0
    } else {
        let b = blocks as f32;
        let offset = hash_unit(cell.rem_euclid(n) as u64 ^ 0x5eed);
        let along = (v * b + offset + 0.3 * periodic_noise(x, v * b, ridges, blocks, 15)).fract();
        (1.0 - (along.min(1.0 - along) / 0.05)).clamp(0.0, 1.0)
    };
    let grain = periodic_noise(u * 64.0, v * 24.0, 64, 24, 13);
    relief * (1.0 - depth * furrow.powf(0.7)) * (1.0 - 0.45 * depth * crack) + 0.18 * (grain - 0.5)
}

/// Oak, willow, poplar: deep furrows between rugged ridges broken into blocks.
fn furrowed(u: f32, v: f32) -> f32 {
    let rough = periodic_noise(u * 24.0, v * 10.0, 24, 10, 19);
    ridged(u, v, 6, 0.9, 0.6, 4) * (0.75 + 0.5 * rough)
}

/// Maple: many shallow ridges that part and join.
fn fine_ridged(u: f32, v: f32) -> f32 {
    let a = ridged(u, v, 14, 0.55, 0.3, 0);
    let b = ridged(u + 0.37, v * 1.0 + 0.21, 9, 0.35, 0.25, 3);
    0.1 + 0.95 * a.min(b + 0.15)
}

/// Birch: pale papery bark, dark horizontal lenticels, a few black diamond scars, grey patches.
/// Returns the brightness and a tint (the dark marks are near black, not darker white).
fn papery(u: f32, v: f32) -> (f32, [f32; 3]) {
    let mottle = periodic_noise(u * 5.0, v * 9.0, 5, 9, 51);
    let fine = periodic_noise(u * 40.0, v * 64.0, 40, 64, 53);
    let mut brightness = 0.92 + 0.12 * (mottle - 0.5) + 0.06 * (fine - 0.5);
    // Lenticels: in each of 6 × 24 cells, a horizontal dash of random length and place.
    let (cols, rows) = (6.0, 24.0);
    let (cu, cv) = (u * cols, v * rows);
    let mut dark: f32 = 0.0;
    for dj in -1..=1 {
        for di in -1..=1 {
            let (i, j) = (cu.floor() as i64 + di, cv.floor() as i64 + dj);
            let key = (i.rem_euclid(cols as i64) as u64) << 32 ^ (j.rem_euclid(rows as i64) as u64);
            if hash_unit(key ^ 0x61) < 0.35 {
                continue; // no lenticel in this cell
            }
            let centre_u = i as f32 + hash_unit(key ^ 0x62);
            let centre_v = j as f32 + hash_unit(key ^ 0x63);
            let half_length = 0.25 + 0.9 * hash_unit(key ^ 0x64);
            let half_thickness = 0.08 + 0.1 * hash_unit(key ^ 0x65);
            let du = ((cu - centre_u) / half_length).abs();
            let dv = ((cv - centre_v) / half_thickness).abs();
            if du < 1.0 && dv < 1.0 - du * du {
                dark = dark.max(0.85);
            }
        }
    }
    // Black diamond scars where branches were shed: 2 × 3 cells, half of them marked.
    let (su, sv) = (u * 2.0, v * 3.0);
    let key = ((su.floor() as u64 % 2) << 32) ^ (sv.floor() as u64 % 3);
    if hash_unit(key ^ 0x71) < 0.5 {
        let du = (su.fract() - 0.5).abs() / 0.22;
        let dv = (sv.fract() - 0.5).abs() / 0.16;
        if du + dv < 1.0 {
            dark = dark.max(0.9 - 0.3 * (du + dv));
        }
    }
    // Grey, rougher patches.
    let patches = periodic_noise(u * 3.0, v * 4.0, 3, 4, 57);
    if patches > 0.7 {
        brightness *= 0.78;
    }
    let ink = [0.22, 0.2, 0.2];
    let tint = ink.map(|k| 1.0 - dark * (1.0 - k / 0.75));
    (brightness * (1.0 - 0.75 * dark).max(0.05), tint)
}

/// Spruce: small rounded plates (a cellular pattern stretched along the branch) with dark
/// cracks between them and lighter fresh bark where a plate has flaked.
fn scaly(u: f32, v: f32) -> f32 {
    let (f1, f2, id) = periodic_cells(u * 12.0, v * 9.0, 12, 9, 81);
    let crack = ((f2 - f1) * 6.0).clamp(0.0, 1.0);
    let dome = (1.0 - f1 * 1.2).clamp(0.0, 1.0);
    let grain = periodic_noise(u * 48.0, v * 48.0, 48, 48, 83);
    let mottle = periodic_noise(u * 4.0, v * 3.0, 4, 3, 85);
    // Each plate its own tone; fresh, lighter bark where one has just flaked off.
    let tone = 0.75 + 0.35 * id + if id > 0.85 { 0.25 } else { 0.0 };
    (0.35 + 0.65 * crack) * (0.75 + 0.3 * dome) * tone * (0.8 + 0.4 * mottle) + 0.12 * (grain - 0.5)
}

/// A `size × size` leaf of outline `shape` tinted by `color` (linear RGB) with alpha 0 outside
/// the blade: base at the bottom row, tip at the top, lighter midrib and veins.
pub fn leaf_texture(shape: LeafShape, color: [f32; 3], size: u32) -> RgbaImage {
    let size = size.max(8);
    RgbaImage::from_fn(size, size, |x, y| {
        let u = (x as f32 + 0.5) / size as f32;
        let along = 1.0 - (y as f32 + 0.5) / size as f32; // 0 at the base, 1 at the tip
        let Some(shade) = blade(shape, u, along) else {
            return Rgba([0, 0, 0, 0]);
        };
        let noise = 0.9 + 0.1 * periodic_noise(u * 16.0, along * 16.0, 16, 16, 23);
        let [r, g, b] = color.map(|c| srgb8(c * shade * noise));
        Rgba([r, g, b, 255])
    })
}

/// The shade of the blade at (u across, `a` from base to tip), or `None` outside it.
fn blade(shape: LeafShape, u: f32, a: f32) -> Option<f32> {
    let x = u - 0.5;
    let across = x.abs();
    let pinnate = |half_width: f32, vein_count: f32, slope: f32| -> Option<f32> {
        if a < 0.02 || across >= half_width {
            return None;
        }
        let mut shade = 1.0;
        if across < 0.012 + 0.012 * (1.0 - a) {
            shade *= 1.4; // midrib
        } else {
            let phase = (a - across * slope) * vein_count;
            if (phase - phase.round()).abs() < 0.07 {
                shade *= 1.2;
            }
        }
        if across > half_width * 0.88 {
            shade *= 0.85; // darker rim
        }
        Some(shade)
    };
    match shape {
        LeafShape::Elliptic => pinnate(0.47 * (std::f32::consts::PI * a.powf(0.8)).sin(), 9.0, 0.9),
        LeafShape::Lobed => {
            // Obovate outline, widest beyond the middle, cut by 4–5 rounded lobes per side with
            // deep sinuses; a small pair of ear-like lobes at the base (Quercus robur).
            let envelope = 0.49 * (std::f32::consts::PI * a.clamp(0.0, 1.0).powf(1.3)).sin();
            let lobes = 0.5 + 0.5 * (std::f32::consts::TAU * 4.5 * a - 1.2).cos();
            let auricle = 0.16 * (1.0 - (a - 0.06).abs() / 0.06).max(0.0);
            let half_width = (envelope * (0.5 + 0.5 * lobes.sqrt())).max(auricle);
            pinnate(half_width, 4.5, 0.6)
        }
        LeafShape::Palmate => palmate(x, a),
        LeafShape::OvateSerrate => {
            // Ovate-triangular: a wedge-shaped base, widest a third of the way up, convex sides
            // drawn out to a long point, and a doubly toothed edge (Betula pendula).
            let envelope = if a < 0.32 {
                0.46 * (a / 0.32).powf(0.6)
            } else {
                let t = (1.0 - a) / 0.68;
                0.46 * t.powf(0.7) * (0.55 + 0.45 * t)
            };
            let tooth = (a * 14.0).fract();
            let double = (a * 42.0).fract();
            let half_width = envelope * (1.0 - 0.1 * tooth - 0.04 * double);
            pinnate(half_width, 7.0, 0.8)
        }
        LeafShape::Lanceolate => {
            // Long and tapering to both ends, finely toothed (Salix); narrow on the tree
            // because its card is.
            let envelope = 0.46 * (std::f32::consts::PI * a.powf(0.9)).sin().powf(0.8);
            let half_width = envelope * (1.0 - 0.05 * (a * 40.0).fract());
            pinnate(half_width, 14.0, 2.0)
        }
        LeafShape::Deltoid => {
            // Broad, straight-cut base with rounded corners, straight to slightly hollow sides
            // to a drawn-out tip, a finely rounded-toothed edge (Populus nigra).
            let envelope = if a < 0.12 {
                0.495 * (1.0 - (1.0 - a / 0.12).powi(2)).sqrt()
            } else {
                0.495 * ((1.0 - a) / 0.88).powf(1.35)
            };
            let crenate = (a * 26.0).fract();
            let half_width = envelope * (1.0 - 0.05 * (crenate - 0.5).abs() * 2.0);
            pinnate(half_width, 5.0, 0.35)
        }
        LeafShape::Needles => needle_shoot(x, a),
    }
}

/// Maple: five pointed lobes spreading from the top of the petiole, a few large teeth on each,
/// rounded sinuses between them, veins running out to the lobe tips (Acer platanoides).
fn palmate(x: f32, a: f32) -> Option<f32> {
    let centre = 0.18;
    let (dx, dy) = (x, a - centre);
    let r = dx.hypot(dy);
    let theta = dx.atan2(dy); // 0 towards the tip, ±π towards the petiole
    // Lobes: direction from the tip, length, half-width (radians).
    const LOBES: [(f32, f32, f32); 5] = [
        (0.0, 0.8, 0.55),
        (1.0, 0.74, 0.55),
        (-1.0, 0.74, 0.55),
        (2.05, 0.46, 0.5),
        (-2.05, 0.46, 0.5),
    ];
    let mut reach: f32 = 0.24 * (1.0 - (theta.abs() / std::f32::consts::PI).powi(4));
    let mut vein = f32::INFINITY;
    for (direction, length, half_width) in LOBES {
        let off = (theta - direction).abs();
        // A broad lobe ending in a long point, falling to a rounded sinus between lobes.
        let t = (off / half_width).min(1.5);
        let mut lobe = length * (1.0 - 0.62 * t.powf(0.7));
        // Two long-pointed teeth on each side of a lobe.
        let tooth = ((off / half_width) * 2.2 + 0.3).fract();
        if t < 1.0 {
            lobe *= 1.0 - 0.16 * tooth.powf(0.6);
        }
        reach = reach.max(lobe);
        vein = vein.min(off * r);
    }
    if r >= reach || a < 0.01 {
        // The petiole stub below the blade.
        return (a < centre && x.abs() < 0.012).then_some(0.8);
    }
    let mut shade = 1.0;
    if vein < 0.01 {
        shade *= 1.35;
    }
    if r > reach * 0.9 {
        shade *= 0.85;
    }
    Some(shade)
}

/// Spruce: a twig along the card with short stiff needles set all round it, drawn as those on
/// either side, those pointing at the viewer foreshortened, all angled towards the tip.
fn needle_shoot(x: f32, a: f32) -> Option<f32> {
    let twig_half_width = 0.035 * (1.0 - 0.5 * a);
    if a > 0.02 && a < 0.97 && x.abs() < twig_half_width {
        return Some(0.55); // the brown-green twig shows between the needles
    }
    let spacing = 0.045;
    let mut best: Option<f32> = None;
    // Needles leave the twig at several positions, alternating sides and angles.
    let k0 = ((a - 0.45) / spacing).floor() as i64;
    for k in (k0 - 1)..=(k0 + 10) {
        let base = k as f32 * spacing;
        if !(0.03..=0.93).contains(&base) {
            continue;
        }
        for side in [-1.0f32, 1.0] {
            for (angle_deg, length) in [(48.0f32, 0.44), (28.0, 0.3)] {
                let jitter =
                    hash_unit((k as u64) << 8 ^ (side > 0.0) as u64 ^ (length * 100.0) as u64);
                let angle = (angle_deg + 10.0 * (jitter - 0.5)).to_radians();
                let length = length * (0.85 + 0.3 * jitter) * (1.0 - 0.35 * base);
                let (dir_x, dir_a) = (side * angle.sin(), angle.cos());
                // Distance from the pixel to the needle segment from (0, base).
                let (px, pa) = (x, a - base);
                let t = (px * dir_x + pa * dir_a).clamp(0.0, length);
                let (qx, qa) = (px - dir_x * t, pa - dir_a * t);
                let thickness = 0.022 * (1.0 - 0.7 * t / length);
                if qx.hypot(qa) < thickness {
                    let shade = 0.85 + 0.3 * (t / length) + 0.1 * (jitter - 0.5);
                    best = Some(best.map_or(shade, |b: f32| b.max(shade)));
                }
            }
        }
    }
    best
}

/// Encodes an image (RGB or RGBA) as PNG bytes.
pub fn png_bytes<P>(image: &ImageBuffer<P, Vec<P::Subpixel>>) -> Result<Vec<u8>, image::ImageError>
where
    P: PixelWithColorType,
    [P::Subpixel]: EncodableLayout,
{
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

    const BARKS: [BarkKind; 4] = [
        BarkKind::Furrowed,
        BarkKind::Papery,
        BarkKind::Scaly,
        BarkKind::FineRidged,
    ];
    const SHAPES: [LeafShape; 7] = [
        LeafShape::Elliptic,
        LeafShape::Lobed,
        LeafShape::Palmate,
        LeafShape::OvateSerrate,
        LeafShape::Lanceolate,
        LeafShape::Deltoid,
        LeafShape::Needles,
    ];

    #[test]
    fn every_bark_tiles_seamlessly_across_its_edges() {
        let size = 128;
        for kind in BARKS {
            let bark = bark_texture(kind, [0.3, 0.2, 0.1], size);
            // The difference across each wrap-around edge is no larger than between neighbours
            // in the same direction (the mean over every pair of adjacent columns, or rows).
            let step = |a: &Rgb<u8>, b: &Rgb<u8>| (i32::from(a[1]) - i32::from(b[1])).abs();
            let (mut wrap_x, mut wrap_y, mut inner_x, mut inner_y) = (0, 0, 0, 0);
            for i in 0..size {
                wrap_x += step(bark.get_pixel(size - 1, i), bark.get_pixel(0, i));
                wrap_y += step(bark.get_pixel(i, size - 1), bark.get_pixel(i, 0));
                for j in 0..size - 1 {
                    inner_x += step(bark.get_pixel(j, i), bark.get_pixel(j + 1, i));
                    inner_y += step(bark.get_pixel(i, j), bark.get_pixel(i, j + 1));
                }
            }
            let (inner_x, inner_y) = (inner_x / (size as i32 - 1), inner_y / (size as i32 - 1));
            assert!(
                wrap_x <= inner_x * 3 + size as i32 * 4 && wrap_y <= inner_y * 3 + size as i32 * 4,
                "{kind:?}: seams {wrap_x}, {wrap_y} vs inner {inner_x}, {inner_y}"
            );
        }
    }

    #[test]
    fn bark_is_an_opaque_rgb_png() {
        let png = png_bytes(&bark_texture(BarkKind::Scaly, [0.3, 0.2, 0.1], 32)).expect("png");
        let decoded = image::load_from_memory(&png).expect("decodes");
        assert_eq!(decoded.color(), image::ColorType::Rgb8);
    }

    #[test]
    fn birch_bark_is_pale_with_dark_marks_and_oak_bark_is_dark_and_furrowed() {
        let luminance = |img: &RgbImage| -> Vec<f32> {
            img.pixels()
                .map(|p| (f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2])) / 765.0)
                .collect()
        };
        let mut birch = luminance(&bark_texture(BarkKind::Papery, [0.72, 0.7, 0.66], 128));
        birch.sort_by(f32::total_cmp);
        let median = birch[birch.len() / 2];
        let dark_share =
            birch.iter().filter(|&&l| l < 0.45 * median).count() as f32 / birch.len() as f32;
        assert!(median > 0.75, "birch bark median luminance {median}");
        assert!(
            (0.03..0.3).contains(&dark_share),
            "birch lenticels cover {dark_share}"
        );
        let oak = luminance(&bark_texture(BarkKind::Furrowed, [0.2, 0.17, 0.14], 128));
        let mean = oak.iter().sum::<f32>() / oak.len() as f32;
        assert!(mean < 0.5 * median, "oak bark mean luminance {mean}");
    }

    #[test]
    fn every_leaf_is_opaque_on_its_midline_and_transparent_in_the_corners() {
        for shape in SHAPES {
            let leaf = leaf_texture(shape, [0.1, 0.4, 0.1], 128);
            assert_eq!(leaf.get_pixel(64, 64)[3], 255, "{shape:?} middle");
            assert_eq!(leaf.get_pixel(64, 100)[3], 255, "{shape:?} lower midline");
            for (x, y) in [(0, 0), (127, 0), (0, 127), (127, 127)] {
                assert_eq!(leaf.get_pixel(x, y)[3], 0, "{shape:?} corner {x},{y}");
            }
            let png = png_bytes(&leaf).expect("png encodes");
            assert_eq!(&png[1..4], b"PNG");
        }
    }

    /// Share of the card the blade covers, edge crossings per row, and the number of sinuses:
    /// rows where the blade's width is a clear local minimum (a cut between two lobes).
    fn outline(shape: LeafShape) -> (f32, f32, usize) {
        let size = 128;
        let leaf = leaf_texture(shape, [0.1, 0.4, 0.1], size);
        let opaque = |x: u32, y: u32| leaf.get_pixel(x, y)[3] == 255;
        let (mut covered, mut edges) = (0, 0);
        let mut widths = Vec::new();
        for y in 0..size {
            let width = (0..size).filter(|&x| opaque(x, y)).count();
            covered += width;
            widths.push(width as i32);
            edges += (1..size)
                .filter(|&x| opaque(x, y) != opaque(x - 1, y))
                .count();
        }
        let sinuses = (4..size as usize - 4)
            .filter(|&y| {
                let w = widths[y];
                w > 0
                    && (1..=4).all(|k| widths[y - k] >= w && widths[y + k] >= w)
                    && widths[y - 4] > w + 4
                    && widths[y + 4] > w + 4
            })
            .count();
        let n = (size * size) as f32;
        (covered as f32 / n, edges as f32 / size as f32, sinuses)
    }

    #[test]
    fn leaf_outlines_differ_as_their_species_do() {
        let (elliptic, elliptic_edges, elliptic_sinuses) = outline(LeafShape::Elliptic);
        let (needles, needle_edges, _) = outline(LeafShape::Needles);
        let (palmate, _, _) = outline(LeafShape::Palmate);
        let (_, _, oak_sinuses) = outline(LeafShape::Lobed);
        let (lanceolate, _, _) = outline(LeafShape::Lanceolate);
        println!(
            "coverage elliptic {elliptic:.2} palmate {palmate:.2} lanceolate {lanceolate:.2} \
             needles {needles:.2}; edges per row elliptic {elliptic_edges:.1} needles \
             {needle_edges:.1}; sinuses elliptic {elliptic_sinuses} oak {oak_sinuses}"
        );
        // A shoot of needles is mostly gaps, with many edges in a row; a blade has two.
        assert!(needles < 0.7 * elliptic, "needles cover {needles}");
        assert!(needle_edges > 3.0 * elliptic_edges);
        // An oak leaf is cut into lobes on each side; a plain blade has no sinus.
        assert_eq!(elliptic_sinuses, 0);
        assert!(oak_sinuses >= 3, "oak sinuses {oak_sinuses}");
        // A maple hand is cut deep between its lobes.
        assert!(palmate < 0.8 * elliptic, "palmate covers {palmate}");
    }
}
