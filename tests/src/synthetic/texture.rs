//! Procedural textures of the synthetic garden: grass, paving, brick and planks.
//!
//! Every texture is a function of a surface coordinate in metres and of the pixel footprint
//! `footprint_m` (the width one pixel covers on the surface). Octaves and edges finer than the
//! footprint fade to their mean, an analytic prefilter: the renderer takes one sample per pixel
//! and still does not alias, so corners stay stable from frame to frame and track well.
//! Colours are linear RGB in `[0, 1]`.

use glam::{Vec2, Vec3};

/// A 2D integer hash (seeded), well mixed in all bits.
pub fn hash2(x: i32, y: i32, seed: u32) -> u32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ seed.wrapping_mul(0xcb1a_b31f).wrapping_add(0x9e37_79b9);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    h
}

/// [`hash2`] mapped to `[0, 1)`.
pub fn hash01(x: i32, y: i32, seed: u32) -> f32 {
    (hash2(x, y, seed) >> 8) as f32 / (1u32 << 24) as f32
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// Hermite smoothstep of `x` between `edge0` and `edge1` (either order).
pub fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    if (edge1 - edge0).abs() < 1e-9 {
        return if x < edge0 { 0.0 } else { 1.0 };
    }
    smooth(((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0))
}

/// Value noise in `[0, 1]` on the unit lattice.
pub fn value_noise(p: Vec2, seed: u32) -> f32 {
    let cell = p.floor();
    let (ix, iy) = (cell.x as i32, cell.y as i32);
    let f = p - cell;
    let (u, v) = (smooth(f.x), smooth(f.y));
    let a = hash01(ix, iy, seed);
    let b = hash01(ix + 1, iy, seed);
    let c = hash01(ix, iy + 1, seed);
    let d = hash01(ix + 1, iy + 1, seed);
    let top = a + (b - a) * u;
    let bottom = c + (d - c) * u;
    top + (bottom - top) * v
}

/// Fractal value noise in `[0, 1]`: octaves from `base_frequency` (cycles per metre) doubling,
/// each faded out once its wavelength drops below two pixel footprints.
pub fn fbm(p: Vec2, seed: u32, base_frequency: f32, num_octaves: u32, footprint_m: f32) -> f32 {
    let mut sum = 0.0;
    let mut total = 0.0;
    let mut amplitude = 1.0;
    let mut frequency = base_frequency;
    for octave in 0..num_octaves {
        let wavelength = 1.0 / frequency;
        let weight = (wavelength / footprint_m.max(1e-6) - 1.0).clamp(0.0, 1.0);
        let n = value_noise(p * frequency, seed.wrapping_add(octave * 7919));
        sum += amplitude * (0.5 + weight * (n - 0.5));
        total += amplitude;
        amplitude *= 0.55;
        frequency *= 2.0;
    }
    sum / total
}

/// Coverage of a line of half-width `half_width` at signed distance `distance`, box-filtered
/// over one footprint: 1 on the line, 0 far from it.
fn line_coverage(distance: f32, half_width: f32, footprint_m: f32) -> f32 {
    let soft = 0.5 * footprint_m.max(1e-6);
    1.0 - smoothstep(half_width - soft, half_width + soft, distance.abs())
}

/// Grass: multi-scale green noise, dark clover patches and small flowers.
pub fn grass(p: Vec2, footprint_m: f32, seed: u32) -> Vec3 {
    let broad = fbm(p, seed ^ 0x51, 0.7, 3, footprint_m);
    let fine = fbm(p, seed ^ 0x52, 9.0, 6, footprint_m);
    let base = Vec3::new(0.10, 0.26, 0.05).lerp(Vec3::new(0.28, 0.42, 0.10), broad);
    let mut colour = base * (0.45 + 1.1 * fine);
    // Clover patches: thresholded mid-scale noise gives blobs with corners.
    let patch = fbm(p, seed ^ 0x53, 3.0, 3, footprint_m);
    let soft = (footprint_m * 2.0).max(0.02);
    let clover = smoothstep(0.60 - soft, 0.60 + soft, patch);
    colour = colour.lerp(Vec3::new(0.04, 0.15, 0.03), 0.8 * clover);
    let dry = smoothstep(0.66 - soft, 0.66 + soft, 1.0 - patch);
    colour = colour.lerp(Vec3::new(0.45, 0.40, 0.18), 0.7 * dry);
    colour + flowers(p, footprint_m, seed)
}

/// Small white and yellow flowers scattered over 0.16 m cells: bright blobs, strong corners.
fn flowers(p: Vec2, footprint_m: f32, seed: u32) -> Vec3 {
    const CELL_M: f32 = 0.16;
    let q = p / CELL_M;
    let cell = q.floor();
    let (ix, iy) = (cell.x as i32, cell.y as i32);
    if hash01(ix, iy, seed ^ 0xf1) > 0.35 {
        return Vec3::ZERO;
    }
    let centre = Vec2::new(
        0.2 + 0.6 * hash01(ix, iy, seed ^ 0xf2),
        0.2 + 0.6 * hash01(ix, iy, seed ^ 0xf3),
    );
    let radius_m = 0.012 + 0.014 * hash01(ix, iy, seed ^ 0xf4);
    let distance_m = (q - cell - centre).length() * CELL_M;
    let cover = line_coverage(distance_m, radius_m, footprint_m);
    let petal = if hash01(ix, iy, seed ^ 0xf5) < 0.5 {
        Vec3::new(0.85, 0.85, 0.80)
    } else {
        Vec3::new(0.90, 0.75, 0.10)
    };
    petal * cover
}

/// Running-bond paving stones (0.40 × 0.20 m) with dark joints and per-stone tint.
pub fn paving(p: Vec2, footprint_m: f32, seed: u32) -> Vec3 {
    const LENGTH_M: f32 = 0.40;
    const WIDTH_M: f32 = 0.20;
    const JOINT_HALF_M: f32 = 0.008;
    let row = (p.y / WIDTH_M).floor();
    let shift = if (row as i32).rem_euclid(2) == 1 {
        0.5 * LENGTH_M
    } else {
        0.0
    };
    let x = p.x + shift;
    let column = (x / LENGTH_M).floor();
    let (ix, iy) = (column as i32, row as i32);
    let local = Vec2::new(x - column * LENGTH_M, p.y - row * WIDTH_M);
    let edge_distance = local
        .x
        .min(LENGTH_M - local.x)
        .min(local.y.min(WIDTH_M - local.y));
    let joint = line_coverage(edge_distance, JOINT_HALF_M, footprint_m);
    let tint = hash01(ix, iy, seed ^ 0xa1);
    let stone = Vec3::new(0.55, 0.50, 0.42).lerp(Vec3::new(0.78, 0.72, 0.62), tint);
    let speckle = fbm(p, seed ^ 0xa2, 14.0, 5, footprint_m);
    let worn = fbm(p, seed ^ 0xa3, 2.5, 3, footprint_m);
    let stone = stone * (0.55 + 0.8 * speckle) * (0.8 + 0.4 * worn);
    stone.lerp(Vec3::new(0.08, 0.08, 0.07), joint)
}

/// Brick wall (0.215 × 0.065 m bricks, 10 mm mortar); `p` = (along the wall, height).
pub fn brick(p: Vec2, footprint_m: f32, seed: u32) -> Vec3 {
    const LENGTH_M: f32 = 0.225;
    const COURSE_M: f32 = 0.075;
    const MORTAR_HALF_M: f32 = 0.005;
    let course = (p.y / COURSE_M).floor();
    let shift = if (course as i32).rem_euclid(2) == 1 {
        0.5 * LENGTH_M
    } else {
        0.0
    };
    let x = p.x + shift;
    let column = (x / LENGTH_M).floor();
    let local = Vec2::new(x - column * LENGTH_M, p.y - course * COURSE_M);
    let edge_distance = local
        .x
        .min(LENGTH_M - local.x)
        .min(local.y.min(COURSE_M - local.y));
    let mortar = line_coverage(edge_distance, MORTAR_HALF_M, footprint_m);
    let tint = hash01(column as i32, course as i32, seed ^ 0xb1);
    let clay = Vec3::new(0.42, 0.13, 0.07).lerp(Vec3::new(0.70, 0.32, 0.16), tint);
    let grain = fbm(p, seed ^ 0xb2, 20.0, 4, footprint_m);
    (clay * (0.7 + 0.6 * grain)).lerp(Vec3::new(0.72, 0.70, 0.64), mortar)
}

/// Wooden planks 0.10 m wide with dark gaps and grain; `p` = (along the planks, across).
pub fn planks(p: Vec2, footprint_m: f32, seed: u32) -> Vec3 {
    const WIDTH_M: f32 = 0.10;
    let board = (p.y / WIDTH_M).floor();
    let across = p.y - board * WIDTH_M;
    let gap = line_coverage(across.min(WIDTH_M - across), 0.006, footprint_m);
    let tint = hash01(board as i32, 3, seed ^ 0xc1);
    let wood = Vec3::new(0.45, 0.28, 0.12).lerp(Vec3::new(0.72, 0.52, 0.28), tint);
    let grain = fbm(
        Vec2::new(p.x * 1.5, p.y * 12.0),
        seed ^ (board as i32 as u32),
        4.0,
        5,
        footprint_m,
    );
    let knots = fbm(p, seed ^ 0xc2, 6.0, 3, footprint_m);
    let wood = wood * (0.6 + 0.8 * grain) * (0.75 + 0.5 * knots);
    wood.lerp(Vec3::new(0.05, 0.04, 0.03), gap)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_stays_in_the_unit_interval_and_is_deterministic() {
        for i in 0..500 {
            let p = Vec2::new(i as f32 * 0.37 - 50.0, i as f32 * 0.11 - 20.0);
            let n = fbm(p, 7, 1.0, 6, 0.001);
            assert!((0.0..=1.0).contains(&n), "fbm out of range: {n}");
            assert_eq!(n, fbm(p, 7, 1.0, 6, 0.001));
        }
    }

    #[test]
    fn octaves_finer_than_the_footprint_fade_to_their_mean() {
        // With a footprint far larger than every octave, the noise is flat.
        let a = fbm(Vec2::new(0.3, 0.7), 1, 10.0, 4, 10.0);
        let b = fbm(Vec2::new(5.3, 2.7), 1, 10.0, 4, 10.0);
        assert!((a - b).abs() < 1e-6 && (a - 0.5).abs() < 1e-6);
    }
}
