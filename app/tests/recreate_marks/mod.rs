//! Marks drawn from the synthetic tree footage's true masks the way a user draws them (shared by
//! the recreate tests): a tap on the bottom of the trunk, and a rough polygon of 24 points around
//! the crown, a little outside it.

use std::path::Path;

/// A grey mask of frame `index` (255 foliage, 128 wood, 0 not the tree).
pub struct Mask {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<u8>,
}

pub fn mask(footage: &Path, index: usize) -> Mask {
    let list = std::fs::read_to_string(footage.join("masks.txt")).expect("masks.txt");
    let file = list
        .lines()
        .filter(|l| !l.starts_with('#'))
        .nth(index)
        .and_then(|l| l.split_whitespace().nth(1))
        .expect("a mask for the frame");
    let image = image::open(footage.join(file))
        .expect("mask png")
        .to_luma8();
    Mask {
        width: image.width() as usize,
        height: image.height() as usize,
        pixels: image.into_raw(),
    }
}

/// Small deterministic jitter in [0, 1).
fn jitter(i: usize, salt: u64) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ salt;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The crown as a user traces it: the foliage's outer boundary, walked at 24 evenly spaced
/// points, each pushed 2–3.5 px outwards from the crown's centre.
pub fn traced_outline(mask: &Mask, salt: u64) -> Vec<[f64; 2]> {
    let mut corners = Vec::new();
    for y in 0..mask.height {
        for x in 0..mask.width {
            if mask.pixels[y * mask.width + x] == 255 {
                // The pixel's four corners, so the hull covers whole pixels.
                for (dx, dy) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
                    corners.push(glam::Vec2::new(x as f32 + dx, y as f32 + dy));
                }
            }
        }
    }
    assert!(!corners.is_empty(), "no foliage in the mask");
    let hull: Vec<(f64, f64)> = sylva_core::geometry::crown::convex_hull(corners)
        .into_iter()
        .map(|p| (f64::from(p.x), f64::from(p.y)))
        .collect();
    let n = hull.len();
    let lengths: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt()
        })
        .collect();
    let perimeter: f64 = lengths.iter().sum();
    let centre = hull.iter().fold((0.0, 0.0), |c, p| (c.0 + p.0, c.1 + p.1));
    let centre = (centre.0 / n as f64, centre.1 / n as f64);
    const NUM_POINTS: usize = 24;
    let mut outline = Vec::new();
    let (mut edge, mut walked) = (0, 0.0);
    for k in 0..NUM_POINTS {
        let target = perimeter * k as f64 / NUM_POINTS as f64;
        while walked + lengths[edge] < target {
            walked += lengths[edge];
            edge += 1;
        }
        let f = (target - walked) / lengths[edge].max(1e-9);
        let (a, b) = (hull[edge], hull[(edge + 1) % n]);
        let p = (a.0 + (b.0 - a.0) * f, a.1 + (b.1 - a.1) * f);
        let (dx, dy) = (p.0 - centre.0, p.1 - centre.1);
        let d = (dx * dx + dy * dy).sqrt().max(1e-9);
        // A chord between two points on a convex boundary stays within a pixel of it at this
        // spacing; the push covers that and is the user's "a little outside".
        let push = 2.0 + 1.5 * jitter(k, salt);
        outline.push([p.0 + dx / d * push, p.1 + dy / d * push]);
    }
    outline
}

/// The tap on the trunk base: the bottom of the wood below the crown, in its middle.
pub fn base_tap(mask: &Mask) -> [f64; 2] {
    for y in (0..mask.height).rev() {
        let row: Vec<usize> = (0..mask.width)
            .filter(|&x| mask.pixels[y * mask.width + x] == 128)
            .collect();
        if !row.is_empty() {
            let middle = row.iter().sum::<usize>() as f64 / row.len() as f64;
            return [middle, y as f64];
        }
    }
    panic!("no trunk in the mask");
}
