//! ORB descriptors (Rublee et al., "ORB: an efficient alternative to SIFT or SURF", 2011) of
//! given points: the intensity-centroid orientation (Rosin's moments over a disc of radius 15),
//! then 256 binary intensity tests on the image smoothed by a 7 × 7 Gaussian (σ = 2), their
//! point pairs rotated by that orientation. The test pattern is generated here, once, from a
//! fixed seed: BRIEF's isotropic Gaussian sampling (Calonder et al. 2010, G II, σ = S / 5 for
//! the 31-pixel patch) kept inside a disc of radius 13, so that every rotation stays in the
//! patch. Hamming distance and the ratio test for matching.

use super::SplitMix64;
use crate::frame::GrayImage;
use glam::Vec2;

/// A 256-bit ORB descriptor.
pub type Descriptor = [u8; 32];

/// Radius of ORB's orientation patch (half its 31-pixel patch).
pub const ORIENTATION_RADIUS: i32 = 15;
/// Radius every test point lies within, before and after rotation.
const PATTERN_RADIUS: f64 = 13.0;
/// BRIEF's σ for a 31-pixel patch: S / 5.
const PATTERN_SIGMA: f64 = 31.0 / 5.0;
/// Seed of the generated test pattern. Changing it changes every descriptor.
const PATTERN_SEED: u64 = 0x0B0B_5EED;
/// Points nearer the border than this get no descriptor: ORB's edge threshold (its 31-pixel
/// patch), as OpenCV's ORB drops given keypoints. Near the border lens distortion and the
/// rolling shutter change a patch most from view to view.
pub const EDGE_THRESHOLD_PX: i32 = 31;

/// Orientation of the intensity centroid (Rosin's moments m₁₀, m₀₁ over a disc of radius 15
/// around `p`), in degrees in [0, 360). None too near the border.
pub fn intensity_centroid_angle_deg(image: &GrayImage, p: Vec2) -> Option<f32> {
    let (cx, cy) = (p.x.round() as i32, p.y.round() as i32);
    let (w, h) = (image.width as i32, image.height as i32);
    let r = ORIENTATION_RADIUS;
    if cx < r || cy < r || cx + r >= w || cy + r >= h {
        return None;
    }
    let (mut m10, mut m01) = (0i64, 0i64);
    for v in -r..=r {
        let half = ((r * r - v * v) as f32).sqrt().round() as i32;
        let row = ((cy + v) * w) as usize;
        for u in -half..=half {
            let value = i64::from(image.pixels[row + (cx + u) as usize]);
            m10 += i64::from(u) * value;
            m01 += i64::from(v) * value;
        }
    }
    let angle = (m01 as f32).atan2(m10 as f32).to_degrees();
    Some(if angle < 0.0 { angle + 360.0 } else { angle })
}

/// Hamming distance between two ORB descriptors.
pub fn hamming(a: &Descriptor, b: &Descriptor) -> u32 {
    a.iter().zip(b).map(|(x, y)| (x ^ y).count_ones()).sum()
}

/// The nearest and second-nearest of the descriptors offered, for Lowe's ratio test.
pub struct NearestTwo<T> {
    best: u32,
    second: u32,
    best_item: Option<T>,
}

impl<T> Default for NearestTwo<T> {
    fn default() -> Self {
        Self {
            best: u32::MAX,
            second: u32::MAX,
            best_item: None,
        }
    }
}

impl<T> NearestTwo<T> {
    /// Offers `item` at Hamming `distance`; the first of equals stays the nearest.
    pub fn offer(&mut self, distance: u32, item: T) {
        if distance < self.best {
            self.second = self.best;
            self.best = distance;
            self.best_item = Some(item);
        } else if distance < self.second {
            self.second = distance;
        }
    }

    /// The nearest and its distance, when within `max_hamming` and clearly nearer than the
    /// second (`best < ratio · second`; a lone candidate passes).
    pub fn accepted(self, max_hamming: u32, ratio: f64) -> Option<(T, u32)> {
        let item = self.best_item?;
        let clear = self.second == u32::MAX || (self.best as f64) < ratio * self.second as f64;
        (self.best <= max_hamming && clear).then_some((item, self.best))
    }
}

/// The 256 test pairs, generated from [`PATTERN_SEED`].
fn generate_pattern() -> Vec<[(f32, f32); 2]> {
    let mut rng = SplitMix64::new(PATTERN_SEED);
    let mut gaussian_point = || loop {
        // Box–Muller: two independent normals.
        let (u1, u2) = (rng.unit().max(1e-300), rng.unit());
        let radius = (-2.0 * u1.ln()).sqrt() * PATTERN_SIGMA;
        let theta = std::f64::consts::TAU * u2;
        let (x, y) = (radius * theta.cos(), radius * theta.sin());
        if x * x + y * y <= PATTERN_RADIUS * PATTERN_RADIUS {
            break (x.round() as f32, y.round() as f32);
        }
    };
    let mut pattern = Vec::with_capacity(256);
    while pattern.len() < 256 {
        let (a, b) = (gaussian_point(), gaussian_point());
        if a != b {
            pattern.push([a, b]);
        }
    }
    pattern
}

/// The 7 × 7 Gaussian (σ = 2) smoothing the descriptor's tests see, borders reflected.
pub fn smooth(image: &GrayImage) -> Vec<f32> {
    let (w, h) = (image.width as usize, image.height as usize);
    let raw: Vec<f64> = (-3..=3)
        .map(|k: i32| (-f64::from(k * k) / 8.0).exp())
        .collect();
    let total: f64 = raw.iter().sum();
    let kernel: Vec<f32> = raw.iter().map(|k| (k / total) as f32).collect();
    let reflect = |i: isize, n: usize| -> usize {
        let n = n as isize;
        let mut i = i;
        if n == 1 {
            return 0;
        }
        while i < 0 || i >= n {
            i = if i < 0 { -i } else { 2 * n - 2 - i };
        }
        i as usize
    };
    let mut horizontal = vec![0.0f32; w * h];
    for y in 0..h {
        let row = &image.pixels[y * w..(y + 1) * w];
        for x in 0..w {
            let mut sum = 0.0;
            for (k, weight) in kernel.iter().enumerate() {
                let xx = if (3..w.saturating_sub(3)).contains(&x) {
                    x + k - 3
                } else {
                    reflect(x as isize + k as isize - 3, w)
                };
                sum += weight * f32::from(row[xx]);
            }
            horizontal[y * w + x] = sum;
        }
    }
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        let rows: Vec<usize> = (0..7)
            .map(|k| reflect(y as isize + k as isize - 3, h) * w)
            .collect();
        for x in 0..w {
            out[y * w + x] = rows
                .iter()
                .zip(&kernel)
                .map(|(r, weight)| weight * horizontal[r + x])
                .sum();
        }
    }
    out
}

/// ORB descriptors of given points (and of Shi–Tomasi corners), portable.
pub struct Orb {
    pattern: Vec<[(f32, f32); 2]>,
}

impl Default for Orb {
    fn default() -> Self {
        Self::new()
    }
}

impl Orb {
    pub fn new() -> Self {
        Self {
            pattern: generate_pattern(),
        }
    }

    /// The descriptor at `p` on the smoothed image, its tests rotated by `angle_deg`.
    fn descriptor(&self, smoothed: &[f32], width: usize, p: Vec2, angle_deg: f32) -> Descriptor {
        let (cx, cy) = (p.x.round() as i32, p.y.round() as i32);
        let (sin, cos) = angle_deg.to_radians().sin_cos();
        let value = |(x, y): (f32, f32)| {
            let u = (x * cos - y * sin).round() as i32;
            let v = (x * sin + y * cos).round() as i32;
            smoothed[(cy + v) as usize * width + (cx + u) as usize]
        };
        let mut d = [0u8; 32];
        for (bit, [a, b]) in self.pattern.iter().enumerate() {
            if value(*a) < value(*b) {
                d[bit / 8] |= 1 << (bit % 8);
            }
        }
        d
    }

    /// Describes given points; points within [`EDGE_THRESHOLD_PX`] of the border come back as
    /// None.
    pub fn describe(&self, image: &GrayImage, points: &[Vec2]) -> Vec<Option<Descriptor>> {
        let (w, h) = (image.width as usize, image.height as usize);
        if points.is_empty() || image.pixels.len() != w * h {
            return vec![None; points.len()];
        }
        let inside = |p: &Vec2| {
            let (x, y) = (p.x.round() as i32, p.y.round() as i32);
            let e = EDGE_THRESHOLD_PX;
            x >= e && y >= e && x < w as i32 - e && y < h as i32 - e
        };
        let angles: Vec<Option<f32>> = points
            .iter()
            .map(|p| {
                inside(p)
                    .then(|| intensity_centroid_angle_deg(image, *p))
                    .flatten()
            })
            .collect();
        if angles.iter().all(Option::is_none) {
            return vec![None; points.len()];
        }
        let smoothed = smooth(image);
        points
            .iter()
            .zip(angles)
            .map(|(p, angle)| Some(self.descriptor(&smoothed, w, *p, angle?)))
            .collect()
    }

    /// Shi–Tomasi corners (as [`super::detect_corners`] finds them) with their descriptors.
    pub fn describe_corners(
        &self,
        image: &GrayImage,
        max_corners: usize,
        min_distance_px: f32,
    ) -> Vec<(Vec2, Descriptor)> {
        let corners = super::detect_corners(image, max_corners, min_distance_px, &[]);
        let described = self.describe(image, &corners);
        corners
            .into_iter()
            .zip(described)
            .filter_map(|(p, d)| Some((p, d?)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textured image: smooth blobs of several sizes.
    fn texture(w: u32, h: u32, seed: u64) -> GrayImage {
        let mut rng = SplitMix64::new(seed);
        let blobs: Vec<(f32, f32, f32, f32)> = (0..120)
            .map(|_| {
                (
                    rng.unit() as f32 * w as f32,
                    rng.unit() as f32 * h as f32,
                    2.0 + 8.0 * rng.unit() as f32,
                    if rng.unit() < 0.5 { -90.0 } else { 90.0 },
                )
            })
            .collect();
        let mut img = GrayImage::filled(w, h, 0);
        for y in 0..h {
            for x in 0..w {
                let mut v = 128.0;
                for &(bx, by, r, a) in &blobs {
                    let d2 = (x as f32 - bx).powi(2) + (y as f32 - by).powi(2);
                    v += a * (-d2 / (2.0 * r * r)).exp();
                }
                img.pixels[(y * w + x) as usize] = v.clamp(0.0, 255.0) as u8;
            }
        }
        img
    }

    /// The image rotated by 90° clockwise about its centre (a square image).
    fn rotate90(img: &GrayImage) -> GrayImage {
        let n = img.width;
        let mut out = GrayImage::filled(n, n, 0);
        for y in 0..n {
            for x in 0..n {
                // (x, y) → (n − 1 − y, x)
                out.pixels[(x * n + (n - 1 - y)) as usize] = img.pixels[(y * n + x) as usize];
            }
        }
        out
    }

    #[test]
    fn pattern_is_fixed_and_inside_the_patch() {
        let (a, b) = (generate_pattern(), generate_pattern());
        assert_eq!(a, b);
        assert_eq!(a.len(), 256);
        assert!(
            a.iter()
                .flatten()
                .all(|(x, y)| x * x + y * y <= 13.5 * 13.5)
        );
        assert!(a.iter().all(|[p, q]| p != q));
    }

    #[test]
    fn descriptors_survive_rotation_and_tell_points_apart() {
        let img = texture(200, 200, 3);
        let rotated = rotate90(&img);
        let orb = Orb::new();
        let corners = super::super::detect_corners(&img, 60, 8.0, &[]);
        let inner: Vec<Vec2> = corners
            .into_iter()
            .filter(|p| (p.x - 100.0).abs() < 60.0 && (p.y - 100.0).abs() < 60.0)
            .collect();
        assert!(inner.len() >= 10, "{} corners", inner.len());
        let moved: Vec<Vec2> = inner.iter().map(|p| Vec2::new(199.0 - p.y, p.x)).collect();
        let d1 = orb.describe(&img, &inner);
        let d2 = orb.describe(&rotated, &moved);
        let mut same = Vec::new();
        let mut different = Vec::new();
        for (i, a) in d1.iter().enumerate() {
            for (j, b) in d2.iter().enumerate() {
                let (Some(a), Some(b)) = (a, b) else {
                    panic!("inner points are described")
                };
                if i == j {
                    same.push(hamming(a, b));
                } else {
                    different.push(hamming(a, b));
                }
            }
        }
        same.sort_unstable();
        different.sort_unstable();
        let median = |v: &[u32]| v[v.len() / 2];
        assert!(median(&same) <= 40, "same points: {same:?}");
        assert!(
            median(&different) >= 90,
            "different points: {}",
            median(&different)
        );
        // Near the border: no descriptor.
        assert_eq!(
            orb.describe(&img, &[Vec2::new(20.0, 100.0), Vec2::new(100.0, 175.0)]),
            vec![None, None]
        );
    }

    #[test]
    fn ratio_test_and_hamming() {
        let a = [0u8; 32];
        let mut b = [0u8; 32];
        b[0] = 0b1011;
        b[31] = 0x80;
        assert_eq!(hamming(&a, &b), 4);
        let mut n = NearestTwo::default();
        n.offer(10, 'x');
        n.offer(30, 'y');
        assert_eq!(n.accepted(50, 0.8), Some(('x', 10)));
        let mut n = NearestTwo::default();
        n.offer(10, 'x');
        n.offer(11, 'y');
        assert_eq!(n.accepted(50, 0.8), None);
    }
}
