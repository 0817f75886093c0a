//! RANSAC ground plane (Longay §5.4.1), kornia-style: an [`Estimator`] names its model, its
//! minimal sample size, how to fit a sample and the residual of a point; [`ransac`] runs it with
//! a [`RansacConfig`]; [`refine_plane`] fits the inliers by least squares (smallest eigenvector of
//! their covariance).

use crate::frame::Plane;
use crate::linalg::symmetric_eigen;
use glam::DVec3;

/// A model fitted from minimal samples.
pub trait Estimator {
    type Model: Copy;
    /// Points in a minimal sample.
    const SAMPLE_SIZE: usize;
    /// The model through a minimal sample; None for a degenerate sample.
    fn fit(&self, sample: &[DVec3]) -> Option<Self::Model>;
    /// Distance of a point to the model.
    fn residual(&self, model: &Self::Model, point: DVec3) -> f64;
}

/// RANSAC settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RansacConfig {
    /// Maximum number of samples drawn. Default 1000.
    pub max_iterations: usize,
    /// Inlier distance, in the units of the points. Default 0.02 (2 cm for metric points).
    pub threshold: f64,
    /// Confidence to stop early once the inlier ratio makes more samples pointless. Default 0.999.
    pub confidence: f64,
    /// Fewest inliers for an accepted model. Default 10.
    pub min_inliers: usize,
    /// Seed of the sampler, for reproducible fits. Default 0x5eed.
    pub seed: u64,
}

impl Default for RansacConfig {
    fn default() -> Self {
        Self {
            max_iterations: 1000,
            threshold: 0.02,
            confidence: 0.999,
            min_inliers: 10,
            seed: 0x5eed,
        }
    }
}

/// The best model found and the indices of its inliers.
#[derive(Clone, Debug)]
pub struct RansacResult<M> {
    pub model: M,
    pub inliers: Vec<usize>,
}

/// Draws minimal samples, keeps the model with most inliers. None when no model reaches
/// `min_inliers`.
pub fn ransac<E: Estimator>(
    estimator: &E,
    points: &[DVec3],
    config: &RansacConfig,
) -> Option<RansacResult<E::Model>> {
    if points.len() < E::SAMPLE_SIZE.max(config.min_inliers) {
        return None;
    }
    let mut state = config.seed | 1;
    let mut next = move || {
        // xorshift64*
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        state.wrapping_mul(0x2545_F491_4F6C_DD1D)
    };
    let mut best: Option<RansacResult<E::Model>> = None;
    let mut needed = config.max_iterations;
    let mut sample = Vec::with_capacity(E::SAMPLE_SIZE);
    let mut iteration = 0;
    while iteration < needed.min(config.max_iterations) {
        iteration += 1;
        sample.clear();
        for _ in 0..E::SAMPLE_SIZE {
            sample.push(points[(next() % points.len() as u64) as usize]);
        }
        let Some(model) = estimator.fit(&sample) else {
            continue;
        };
        let inliers: Vec<usize> = (0..points.len())
            .filter(|&i| estimator.residual(&model, points[i]) <= config.threshold)
            .collect();
        if best
            .as_ref()
            .is_none_or(|b| inliers.len() > b.inliers.len())
        {
            let ratio = inliers.len() as f64 / points.len() as f64;
            let p_good = ratio.powi(E::SAMPLE_SIZE as i32).clamp(1e-12, 1.0 - 1e-12);
            needed = ((1.0 - config.confidence).ln() / (1.0 - p_good).ln()).ceil() as usize;
            best = Some(RansacResult { model, inliers });
        }
    }
    best.filter(|b| b.inliers.len() >= config.min_inliers)
}

/// Plane through three points.
#[derive(Clone, Copy, Debug, Default)]
pub struct PlaneEstimator;

impl Estimator for PlaneEstimator {
    type Model = Plane;
    const SAMPLE_SIZE: usize = 3;

    fn fit(&self, s: &[DVec3]) -> Option<Plane> {
        let normal = (s[1] - s[0]).cross(s[2] - s[0]);
        let length = normal.length();
        (length > 1e-12).then(|| {
            let normal = normal / length;
            Plane {
                normal,
                offset: normal.dot(s[0]),
            }
        })
    }

    fn residual(&self, model: &Plane, point: DVec3) -> f64 {
        model.signed_distance(point).abs()
    }
}

/// Planes with a known normal (e.g. perpendicular to gravity): one point fixes the offset.
#[derive(Clone, Copy, Debug)]
pub struct OrientedPlaneEstimator {
    pub normal: DVec3,
}

impl Estimator for OrientedPlaneEstimator {
    type Model = Plane;
    const SAMPLE_SIZE: usize = 1;

    fn fit(&self, s: &[DVec3]) -> Option<Plane> {
        Some(Plane {
            normal: self.normal,
            offset: self.normal.dot(s[0]),
        })
    }

    fn residual(&self, model: &Plane, point: DVec3) -> f64 {
        model.signed_distance(point).abs()
    }
}

/// Least-squares plane through points: centroid and smallest eigenvector of the covariance.
/// The normal keeps the side of `orient_like`.
pub fn refine_plane(points: &[DVec3], orient_like: DVec3) -> Option<Plane> {
    if points.len() < 3 {
        return None;
    }
    let centroid = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let mut cov = [0.0; 9];
    for p in points {
        let d = *p - centroid;
        let d = [d.x, d.y, d.z];
        for a in 0..3 {
            for b in 0..3 {
                cov[a * 3 + b] += d[a] * d[b];
            }
        }
    }
    let (_, vectors) = symmetric_eigen(&cov, 3);
    let mut normal = DVec3::new(vectors[2], vectors[5], vectors[8]).normalize();
    if normal.dot(orient_like) < 0.0 {
        normal = -normal;
    }
    Some(Plane {
        normal,
        offset: normal.dot(centroid),
    })
}

/// RANSAC then least squares on the inliers; refitting keeps the inliers of the refined plane.
pub fn fit_plane<E: Estimator<Model = Plane>>(
    estimator: &E,
    points: &[DVec3],
    config: &RansacConfig,
    orient_like: DVec3,
) -> Option<RansacResult<Plane>> {
    let found = ransac(estimator, points, config)?;
    let inlier_points: Vec<DVec3> = found.inliers.iter().map(|&i| points[i]).collect();
    let model = refine_plane(&inlier_points, orient_like)?;
    let inliers = (0..points.len())
        .filter(|&i| model.signed_distance(points[i]).abs() <= config.threshold)
        .collect();
    Some(RansacResult { model, inliers })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_noisy_floor_with_a_box_on_it_gives_the_floor() {
        let mut points = Vec::new();
        let mut seed = 7u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for _ in 0..300 {
            points.push(DVec3::new(rand() * 4.0, 0.003 * rand(), rand() * 4.0));
        }
        for _ in 0..150 {
            points.push(DVec3::new(
                0.5 + rand() * 0.5,
                0.2 + rand() * 0.4,
                rand() * 0.5,
            ));
        }
        let found =
            fit_plane(&PlaneEstimator, &points, &RansacConfig::default(), DVec3::Y).expect("plane");
        let angle = found.model.normal.angle_between(DVec3::Y).to_degrees();
        assert!(angle < 0.5, "normal off by {angle}°");
        assert!(
            found.model.offset.abs() < 0.005,
            "offset {}",
            found.model.offset
        );
        let box_inliers = found.inliers.iter().filter(|&&i| i >= 300).count();
        assert!(box_inliers < 10, "{box_inliers} box points taken as floor");
        assert!(
            found.inliers.len() >= 290,
            "only {} floor inliers",
            found.inliers.len()
        );
    }
}
