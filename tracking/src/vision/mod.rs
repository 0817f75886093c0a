//! The tracker's pure-Rust vision backend: what [`crate::cv`] offers the tracker, written here
//! so that phones (no OpenCV) run the same tracker. Shi–Tomasi corners ([`corners`]), the
//! essential matrix (Nistér's five-point solver, [`five_point`]) and pose recovery, homography
//! RANSAC ([`epipolar`]), PnP RANSAC ([`pnp`]),
//! ORB descriptors and Hamming matching ([`orb`]). Lucas–Kanade is [`crate::lk`]. Every RANSAC
//! draws from a fixed-seed generator ([`SplitMix64`]), so a run replays identically.

pub mod corners;
pub mod epipolar;
pub mod five_point;
pub mod orb;
pub mod orb_pattern;
pub mod pnp;

pub use corners::detect_corners;
pub use epipolar::{homography_inliers, relative_pose, relative_pose_with};
pub use orb::{Descriptor, NearestTwo, Orb, hamming};
pub use pnp::pnp_ransac;

/// The minimal solver a PnP RANSAC runs on each hypothesis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PnpMinimal {
    /// EPnP on five points (OpenCV backend); the portable backend solves P3P on three points
    /// and keeps the solution the fourth and fifth agree with best.
    Epnp,
    /// Algebraic P3P on four points (three and one to choose among the solutions): several
    /// times cheaper than EPnP's SVD, for the thousand hypotheses of relocalisation.
    Ap3p,
}

/// The minimal solver the essential matrix's RANSAC runs on each sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EssentialMinimal {
    /// Hartley's normalised eight-point algorithm: one model per sample of eight.
    #[default]
    EightPoint,
    /// Nistér's five-point solver ([`five_point`]): up to ten models per sample of five, the
    /// minimal case (OpenCV's `findEssentialMat`), exact for planar scenes too.
    FivePoint,
}

impl EssentialMinimal {
    pub fn sample_size(self) -> usize {
        match self {
            Self::EightPoint => 8,
            Self::FivePoint => 5,
        }
    }
}

/// SplitMix64 (Steele, Lea and Flood 2014): a small, fast generator for RANSAC samples.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (n > 0; Lemire's multiply-shift, bias below 2⁻³²  for small n).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() >> 32).wrapping_mul(n as u64) >> 32) as usize
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// `k` distinct indices in `0..n` (k ≤ n) into `out`.
    pub fn sample(&mut self, n: usize, k: usize, out: &mut Vec<usize>) {
        out.clear();
        while out.len() < k.min(n) {
            let i = self.below(n);
            if !out.contains(&i) {
                out.push(i);
            }
        }
    }
}

/// RANSAC iterations for `confidence` that a sample of `k` is all inliers when a fraction
/// `inlier_ratio` of the points are, at most `max`.
pub(crate) fn ransac_iterations(confidence: f64, inlier_ratio: f64, k: usize, max: usize) -> usize {
    let all_in = inlier_ratio.clamp(0.0, 1.0).powi(k as i32);
    if all_in >= 1.0 - 1e-12 {
        return 1;
    }
    if all_in <= 1e-12 {
        return max;
    }
    let n = (1.0 - confidence).ln() / (1.0 - all_in).ln();
    if n.is_finite() {
        (n.ceil().max(1.0) as usize).min(max)
    } else {
        max
    }
}

/// A null vector of the `rows × 9` matrix `a` (row-major) of rank 8: Gauss–Jordan elimination
/// with full pivoting, the free column set to 1. None when the rank is below 8.
pub(crate) fn null_vector_9(a: &[[f64; 9]]) -> Option<[f64; 9]> {
    let x = null_space_9(a, 8, 1e-12)?.pop()?;
    let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
    Some(x.map(|v| v / norm))
}

/// The `9 − rank` null vectors of the `rows × 9` matrix `a` of rank `rank` by Gauss–Jordan
/// elimination with full pivoting, one per free column (set to 1, the others 0; not
/// normalised). None when a pivot falls below `tolerance` times the largest entry.
pub(crate) fn null_space_9(a: &[[f64; 9]], rank: usize, tolerance: f64) -> Option<Vec<[f64; 9]>> {
    let mut m: Vec<[f64; 9]> = a.to_vec();
    let rows = m.len();
    let mut pivot_cols = vec![usize::MAX; rank];
    let mut used = [false; 9];
    let scale = m
        .iter()
        .flat_map(|r| r.iter())
        .fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 || rows < rank || rank > 8 {
        return None;
    }
    for (step, pivot_col) in pivot_cols.iter_mut().enumerate() {
        // The largest remaining entry (full pivoting).
        let (mut best, mut br, mut bc) = (0.0, 0, 0);
        for (r, row) in m.iter().enumerate().skip(step) {
            for c in (0..9).filter(|&c| !used[c]) {
                if row[c].abs() > best {
                    (best, br, bc) = (row[c].abs(), r, c);
                }
            }
        }
        if best <= tolerance * scale {
            return None;
        }
        m.swap(step, br);
        used[bc] = true;
        *pivot_col = bc;
        let p = m[step][bc];
        for v in m[step].iter_mut() {
            *v /= p;
        }
        let pivot_row = m[step];
        for (r, row) in m.iter_mut().enumerate() {
            if r != step && row[bc] != 0.0 {
                let f = row[bc];
                for c in 0..9 {
                    row[c] -= f * pivot_row[c];
                }
            }
        }
    }
    let null = (0..9)
        .filter(|&c| !used[c])
        .map(|free| {
            let mut x = [0.0; 9];
            x[free] = 1.0;
            for (step, &c) in pivot_cols.iter().enumerate() {
                x[c] = -m[step][free];
            }
            x
        })
        .collect();
    Some(null)
}

/// The unit vector minimising `|A x|` for `A` given by its rows (least squares over more than
/// eight rows): the smallest eigenvector of AᵀA.
pub(crate) fn least_squares_null_9(a: &[[f64; 9]]) -> Option<[f64; 9]> {
    if a.len() < 8 {
        return None;
    }
    let mut ata = [0.0; 81];
    for row in a {
        for i in 0..9 {
            for j in i..9 {
                ata[i * 9 + j] += row[i] * row[j];
            }
        }
    }
    for i in 0..9 {
        for j in 0..i {
            ata[i * 9 + j] = ata[j * 9 + i];
        }
    }
    let (_, vectors) = crate::linalg::symmetric_eigen(&ata, 9);
    let x: [f64; 9] = std::array::from_fn(|row| vectors[row * 9 + 8]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn null_vector_of_a_rank_eight_matrix_is_found() {
        let truth = [0.3, -0.1, 0.5, 0.2, 0.7, -0.4, 0.1, 0.05, -0.6];
        let mut rng = SplitMix64::new(7);
        let rows: Vec<[f64; 9]> = (0..8)
            .map(|_| {
                let mut r: [f64; 9] = std::array::from_fn(|_| rng.unit() - 0.5);
                // Make r orthogonal to truth.
                let d: f64 = r.iter().zip(&truth).map(|(a, b)| a * b).sum::<f64>()
                    / truth.iter().map(|v| v * v).sum::<f64>();
                for (v, t) in r.iter_mut().zip(&truth) {
                    *v -= d * t;
                }
                r
            })
            .collect();
        let norm = truth.iter().map(|v| v * v).sum::<f64>().sqrt();
        for x in [
            null_vector_9(&rows).expect("rank 8"),
            least_squares_null_9(&rows).expect("ls"),
        ] {
            let dot: f64 = x.iter().zip(&truth).map(|(a, b)| a * b / norm).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-9, "dot {dot}");
        }
    }

    #[test]
    fn samples_are_distinct_and_in_range() {
        let mut rng = SplitMix64::new(1);
        let mut out = Vec::new();
        for _ in 0..1000 {
            rng.sample(10, 5, &mut out);
            assert_eq!(out.len(), 5);
            assert!(out.iter().all(|&i| i < 10));
            for (k, i) in out.iter().enumerate() {
                assert!(!out[k + 1..].contains(i));
            }
        }
        assert_eq!(ransac_iterations(0.99, 1.0, 4, 100), 1);
        assert_eq!(ransac_iterations(0.99, 0.0, 4, 100), 100);
        // 0.5⁴ = 1/16: log(0.01)/log(15/16) = 71.4.
        assert_eq!(ransac_iterations(0.99, 0.5, 4, 1000), 72);
    }
}
