//! ORB descriptors (Rublee et al., "ORB: an efficient alternative to SIFT or SURF", 2011) of
//! given points: the intensity-centroid orientation (Rosin's moments over a disc of radius 15),
//! then 256 binary intensity tests on the image smoothed by a 7 × 7 Gaussian (σ = 2), their
//! point pairs rotated by that orientation. The test pattern is learned as ORB's was (§4.3,
//! [`learn_pattern`]): of all pairs of points in the patch, steered, the tests with the most
//! variance that are least correlated with each other, chosen greedily on training patches
//! (committed in [`super::orb_pattern`], learned on TUM fr3_cabinet, not on the fr1_rpy footage
//! the tracker is held to). BRIEF's random Gaussian pairs, which this backend used before, lose
//! much of their variance and decorrelation once steered (ORB §4.2): their distances between
//! different points are small, so more wrong matches pass the tracker's Hamming limits. Hamming
//! distance and the ratio test for matching.

use crate::frame::GrayImage;
use glam::Vec2;

/// A 256-bit ORB descriptor.
pub type Descriptor = [u8; 32];

/// Radius of ORB's orientation patch (half its 31-pixel patch).
pub const ORIENTATION_RADIUS: i32 = 15;
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

/// Radius of the disc the candidate test points of [`learn_pattern`] lie in: ORB's patch.
pub const LEARN_RADIUS: i32 = 15;
/// Spacing of the candidate test points, pixels: the smoothing's σ (finer points only repeat
/// their neighbours' values).
pub const LEARN_STEP: i32 = 2;

/// The candidate test points [`learn_pattern`] picks pairs of: a grid [`LEARN_STEP`] apart
/// inside the disc of radius [`LEARN_RADIUS`] (rotations keep them inside ORB's patch, and the
/// patch inside [`EDGE_THRESHOLD_PX`] of the border).
pub fn candidate_points() -> Vec<(i8, i8)> {
    let r = LEARN_RADIUS;
    let mut points = Vec::new();
    for y in (-r..=r).step_by(LEARN_STEP as usize) {
        for x in (-r..=r).step_by(LEARN_STEP as usize) {
            if x * x + y * y <= r * r {
                points.push((x as i8, y as i8));
            }
        }
    }
    points
}

/// The smoothed values at `points` around `p`, the points rotated by `angle_deg` and rounded
/// as the descriptor samples them.
fn sample_points(
    smoothed: &[f32],
    width: usize,
    p: Vec2,
    angle_deg: f32,
    points: &[(f32, f32)],
) -> Vec<f32> {
    let (cx, cy) = (p.x.round() as i32, p.y.round() as i32);
    let (sin, cos) = angle_deg.to_radians().sin_cos();
    points
        .iter()
        .map(|&(x, y)| {
            let u = (x * cos - y * sin).round() as i32;
            let v = (x * sin + y * cos).round() as i32;
            smoothed[(cy + v) as usize * width + (cx + u) as usize]
        })
        .collect()
}

/// Training samples for [`learn_pattern`]: for each of `corners` far enough from the border,
/// the smoothed image at every [`candidate_points`] point, steered by the corner's
/// intensity-centroid orientation exactly as descriptors are.
pub fn training_samples(image: &GrayImage, corners: &[Vec2]) -> Vec<Vec<f32>> {
    let (w, h) = (image.width as i32, image.height as i32);
    let e = EDGE_THRESHOLD_PX;
    let points: Vec<(f32, f32)> = candidate_points()
        .into_iter()
        .map(|(x, y)| (f32::from(x), f32::from(y)))
        .collect();
    let inside: Vec<(Vec2, f32)> = corners
        .iter()
        .filter(|p| {
            let (x, y) = (p.x.round() as i32, p.y.round() as i32);
            x >= e && y >= e && x < w - e && y < h - e
        })
        .filter_map(|p| Some((*p, intensity_centroid_angle_deg(image, *p)?)))
        .collect();
    if inside.is_empty() {
        return Vec::new();
    }
    let smoothed = smooth(image);
    inside
        .into_iter()
        .map(|(p, angle)| sample_points(&smoothed, w as usize, p, angle, &points))
        .collect()
}

/// A binary test's outcomes over the training samples, packed 64 to a word.
struct TestBits {
    pair: (u16, u16),
    bits: Vec<u64>,
    ones: u32,
}

/// ORB's learned test pattern (Rublee et al. 2011, §4.3) from `samples` (rows of
/// [`training_samples`]): every pair of [`candidate_points`] at least [`LEARN_STEP`] apart is a
/// candidate test; candidates are ordered by how near their mean over the samples is to 0.5
/// (high variance), then taken greedily, each kept only if its correlation with every test
/// kept so far is at most a threshold, raised from 0.2 in steps of 0.05 until `count` tests
/// are kept. Steered tests that are nearly always the same, or that repeat each other, add no
/// information to a descriptor; random ones (BRIEF's) lose much of it once steered. None when
/// there are too few samples (under 64) or candidates.
pub fn learn_pattern(samples: &[Vec<f32>], count: usize) -> Option<Vec<[(i8, i8); 2]>> {
    let points = candidate_points();
    if samples.len() < 64 || samples.iter().any(|s| s.len() != points.len()) {
        return None;
    }
    let words = samples.len().div_ceil(64);
    let n = samples.len() as f64;
    let min_d2 = LEARN_STEP * LEARN_STEP;
    let mut tests: Vec<TestBits> = Vec::new();
    for a in 0..points.len() {
        for b in a + 1..points.len() {
            let (pa, pb) = (points[a], points[b]);
            let (dx, dy) = (i32::from(pa.0 - pb.0), i32::from(pa.1 - pb.1));
            if dx * dx + dy * dy < min_d2 {
                continue;
            }
            let mut bits = vec![0u64; words];
            for (k, s) in samples.iter().enumerate() {
                if s[a] < s[b] {
                    bits[k / 64] |= 1 << (k % 64);
                }
            }
            let ones = bits.iter().map(|w| w.count_ones()).sum();
            tests.push(TestBits {
                pair: (a as u16, b as u16),
                bits,
                ones,
            });
        }
    }
    // Nearest 0.5 first; ties in candidate order, so the result is deterministic.
    let balance = |t: &TestBits| (f64::from(t.ones) / n - 0.5).abs();
    tests.sort_by(|x, y| balance(x).total_cmp(&balance(y)).then(x.pair.cmp(&y.pair)));
    let correlation = |x: &TestBits, y: &TestBits| {
        let both: u32 = x
            .bits
            .iter()
            .zip(&y.bits)
            .map(|(a, b)| (a & b).count_ones())
            .sum();
        let (px, py) = (f64::from(x.ones) / n, f64::from(y.ones) / n);
        let var = (px * (1.0 - px) * py * (1.0 - py)).sqrt();
        if var <= 1e-12 {
            1.0
        } else {
            ((f64::from(both) / n - px * py) / var).abs()
        }
    };
    let mut threshold = 0.2;
    while threshold <= 1.0 + 1e-9 {
        let mut kept: Vec<usize> = Vec::with_capacity(count);
        for (i, t) in tests.iter().enumerate() {
            if kept.iter().all(|&k| correlation(&tests[k], t) <= threshold) {
                kept.push(i);
                if kept.len() == count {
                    return Some(
                        kept.iter()
                            .map(|&k| {
                                let (a, b) = tests[k].pair;
                                [points[a as usize], points[b as usize]]
                            })
                            .collect(),
                    );
                }
            }
        }
        threshold += 0.05;
    }
    None
}

/// The 256 test pairs of [`LEARNED_PATTERN`](super::orb_pattern::LEARNED_PATTERN).
fn learned_pattern() -> Vec<[(f32, f32); 2]> {
    super::orb_pattern::LEARNED_PATTERN
        .iter()
        .map(|&[ax, ay, bx, by]| {
            [
                (f32::from(ax), f32::from(ay)),
                (f32::from(bx), f32::from(by)),
            ]
        })
        .collect()
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
            pattern: learned_pattern(),
        }
    }

    /// ORB with another test pattern (pairs of points within [`LEARN_RADIUS`]), for learning
    /// and comparing patterns.
    pub fn with_pattern(pattern: &[[(i8, i8); 2]]) -> Self {
        Self {
            pattern: pattern
                .iter()
                .map(|&[a, b]| {
                    [
                        (f32::from(a.0), f32::from(a.1)),
                        (f32::from(b.0), f32::from(b.1)),
                    ]
                })
                .collect(),
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
    use super::super::SplitMix64;
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
    fn the_learned_pattern_is_256_distinct_pairs_inside_the_patch() {
        let pattern = learned_pattern();
        assert_eq!(pattern.len(), 256);
        let r = LEARN_RADIUS as f32;
        let step = LEARN_STEP as f32;
        for (k, [a, b]) in pattern.iter().enumerate() {
            assert!(a.0 * a.0 + a.1 * a.1 <= r * r && b.0 * b.0 + b.1 * b.1 <= r * r);
            assert!(
                (a.0 - b.0).powi(2) + (a.1 - b.1).powi(2) >= step * step,
                "{a:?} {b:?}"
            );
            assert!(!pattern[k + 1..].contains(&[*a, *b]), "pair {k} repeats");
        }
    }

    /// Mean |correlation| over all pairs of tests, and mean |mean − 0.5|, of `pattern` on the
    /// samples (points given as indices into [`candidate_points`]).
    fn pattern_statistics(samples: &[Vec<f32>], pattern: &[[(i8, i8); 2]]) -> (f64, f64) {
        let points = candidate_points();
        let index = |p: (i8, i8)| points.iter().position(|q| *q == p).expect("candidate");
        let bits: Vec<Vec<f64>> = pattern
            .iter()
            .map(|[a, b]| {
                let (a, b) = (index(*a), index(*b));
                samples
                    .iter()
                    .map(|s| if s[a] < s[b] { 1.0 } else { 0.0 })
                    .collect()
            })
            .collect();
        let n = samples.len() as f64;
        let means: Vec<f64> = bits.iter().map(|b| b.iter().sum::<f64>() / n).collect();
        let (mut total, mut pairs) = (0.0, 0usize);
        for i in 0..bits.len() {
            for j in i + 1..bits.len() {
                let cov = bits[i]
                    .iter()
                    .zip(&bits[j])
                    .map(|(x, y)| (x - means[i]) * (y - means[j]))
                    .sum::<f64>()
                    / n;
                let var = (means[i] * (1.0 - means[i]) * means[j] * (1.0 - means[j])).sqrt();
                total += if var > 1e-12 { (cov / var).abs() } else { 1.0 };
                pairs += 1;
            }
        }
        let balance = means.iter().map(|m| (m - 0.5).abs()).sum::<f64>() / means.len() as f64;
        (total / pairs as f64, balance)
    }

    #[test]
    fn learning_keeps_balanced_decorrelated_tests() {
        let mut samples = Vec::new();
        for seed in 0..6 {
            let img = texture(240, 240, 10 + seed);
            let corners = super::super::detect_corners(&img, 200, 6.0, &[]);
            samples.extend(training_samples(&img, &corners));
        }
        assert!(samples.len() >= 200, "{} samples", samples.len());
        assert_eq!(learn_pattern(&samples[..63], 64), None);
        let learned = learn_pattern(&samples, 64).expect("a pattern");
        assert_eq!(learn_pattern(&samples, 64).as_ref(), Some(&learned));
        // The same number of random pairs of candidate points, for comparison.
        let points = candidate_points();
        let mut rng = SplitMix64::new(5);
        let random: Vec<[(i8, i8); 2]> = (0..64)
            .map(|_| {
                loop {
                    let (a, b) = (
                        points[rng.below(points.len())],
                        points[rng.below(points.len())],
                    );
                    let d2 = (i32::from(a.0) - i32::from(b.0)).pow(2)
                        + (i32::from(a.1) - i32::from(b.1)).pow(2);
                    if d2 >= LEARN_STEP * LEARN_STEP {
                        break [a, b];
                    }
                }
            })
            .collect();
        let (learned_corr, learned_balance) = pattern_statistics(&samples, &learned);
        let (random_corr, random_balance) = pattern_statistics(&samples, &random);
        assert!(
            learned_corr < 0.8 * random_corr && learned_balance < random_balance,
            "learned |corr| {learned_corr:.3}, |mean − ½| {learned_balance:.3}; random \
             {random_corr:.3}, {random_balance:.3}"
        );
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
