//! Camera pose from 2D–3D correspondences. The minimal solver is Grunert's P3P (three rays of
//! known angles through three points of known distances; see Haralick et al., "Review and
//! analysis of solutions of the three point perspective pose estimation problem", 1994): the
//! two quadratics in the depth ratios are eliminated by their Sylvester resultant, a quartic
//! whose real roots give up to four poses, and one or two further points of the sample choose
//! among them. RANSAC keeps the hypothesis of lowest MSAC cost; Gauss–Newton
//! ([`crate::ba::refine_pose`]) refines it on its inliers.

use super::{PnpMinimal, SplitMix64, ransac_iterations};
use crate::ba::{BaConfig, refine_pose, reprojection_error_px};
use crate::camera::Camera;
use crate::pose::Se3;
use glam::{DVec2, DVec3};

/// Confidence the RANSAC stops at (OpenCV's `solvePnPRansac` as cv.rs calls it).
const CONFIDENCE: f64 = 0.99;
/// Fewest inliers for a pose.
const MIN_INLIERS: usize = 6;

/// Polynomial helpers, coefficients in ascending powers.
fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

fn poly_sub(a: &[f64], b: &[f64]) -> Vec<f64> {
    (0..a.len().max(b.len()))
        .map(|i| a.get(i).copied().unwrap_or(0.0) - b.get(i).copied().unwrap_or(0.0))
        .collect()
}

fn poly_eval(p: &[f64], x: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

fn poly_derivative(p: &[f64]) -> Vec<f64> {
    p.iter()
        .enumerate()
        .skip(1)
        .map(|(i, c)| i as f64 * c)
        .collect()
}

/// Real roots of a polynomial (ascending coefficients), sorted: the roots of its derivative
/// split the line into monotone pieces, each bisected where its ends differ in sign (the outer
/// pieces bounded by Cauchy's bound).
pub fn real_roots(p: &[f64]) -> Vec<f64> {
    let scale = p.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let mut p: Vec<f64> = p.to_vec();
    while p.len() > 1 && p.last().is_some_and(|c| c.abs() <= 1e-14 * scale) {
        p.pop();
    }
    match p.len() {
        0 | 1 => return Vec::new(),
        2 => return vec![-p[0] / p[1]],
        3 => {
            let (c, b, a) = (p[0], p[1], p[2]);
            let d = b * b - 4.0 * a * c;
            if d < 0.0 {
                return Vec::new();
            }
            let q = -0.5 * (b + b.signum() * d.sqrt());
            let mut r = if q == 0.0 {
                vec![0.0]
            } else {
                vec![q / a, c / q]
            };
            r.sort_by(f64::total_cmp);
            return r;
        }
        _ => {}
    }
    let lead = p[p.len() - 1];
    let bound = 1.0
        + p[..p.len() - 1]
            .iter()
            .fold(0.0f64, |m, c| m.max((c / lead).abs()));
    let mut edges = vec![-bound];
    edges.extend(
        real_roots(&poly_derivative(&p))
            .into_iter()
            .filter(|r| r.abs() < bound),
    );
    edges.push(bound);
    let mut roots = Vec::new();
    for w in edges.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        let (flo, fhi) = (poly_eval(&p, lo), poly_eval(&p, hi));
        if flo == 0.0 {
            roots.push(lo);
            continue;
        }
        if flo.signum() == fhi.signum() {
            continue;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            let fm = poly_eval(&p, mid);
            if fm.signum() == flo.signum() {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-15 * hi.abs().max(1.0) {
                break;
            }
        }
        roots.push(0.5 * (lo + hi));
    }
    roots.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    roots
}

/// Up to four `camera_from_world` poses seeing world points `world[i]` along normalised
/// image coordinates `image[i]`, i = 0..3 (Grunert's P3P).
pub fn p3p(world: [DVec3; 3], image: [DVec2; 3]) -> Vec<Se3> {
    let j = image.map(|n| n.extend(1.0).normalize());
    let a2 = (world[1] - world[2]).length_squared();
    let b2 = (world[0] - world[2]).length_squared();
    let c2 = (world[0] - world[1]).length_squared();
    if a2 < 1e-18 || b2 < 1e-18 || c2 < 1e-18 {
        return Vec::new();
    }
    let cos_alpha = j[1].dot(j[2]);
    let cos_beta = j[0].dot(j[2]);
    let cos_gamma = j[0].dot(j[1]);
    // With s2 = u s1, s3 = v s1 the law of cosines in the three triangles gives, in u:
    //   b² u² − 2 b² cosγ u + b² − c² (1 + v² − 2 v cosβ) = 0
    //   b² u² − 2 b² cosα v u + b² v² − a² (1 + v² − 2 v cosβ) = 0
    let c_first = [b2 - c2, 2.0 * c2 * cos_beta, -c2];
    let c_second = [-a2, 2.0 * a2 * cos_beta, b2 - a2];
    let b_first = [-2.0 * b2 * cos_gamma];
    let b_second = [0.0, -2.0 * b2 * cos_alpha];
    // Their Sylvester resultant (divided by b²): b² (C2 − C1)² − (B2 − B1)(B1 C2 − B2 C1).
    let dc = poly_sub(&c_second, &c_first);
    let db = poly_sub(&b_second, &b_first);
    let cross = poly_sub(
        &poly_mul(&b_first, &c_second),
        &poly_mul(&b_second, &c_first),
    );
    let quartic = poly_sub(
        &poly_mul(&dc, &dc)
            .iter()
            .map(|x| x * b2)
            .collect::<Vec<_>>(),
        &poly_mul(&db, &cross),
    );
    let mut poses = Vec::new();
    for v in real_roots(&quartic) {
        if v <= 0.0 {
            continue;
        }
        // Subtracting the two quadratics leaves one linear equation in u.
        let denominator = poly_eval(&b_first, v) - poly_eval(&b_second, v);
        if denominator.abs() < 1e-14 {
            continue;
        }
        let u = (poly_eval(&c_second, v) - poly_eval(&c_first, v)) / denominator;
        let q = 1.0 + v * v - 2.0 * v * cos_beta;
        if u <= 0.0 || q <= 1e-18 {
            continue;
        }
        let s1 = (b2 / q).sqrt();
        let camera = [j[0] * s1, j[1] * (u * s1), j[2] * (v * s1)];
        if let Some(pose) = rigid_from_three(&world, &camera) {
            poses.push(pose);
        }
    }
    poses
}

/// The rigid motion taking three world points onto their camera-frame positions.
fn rigid_from_three(world: &[DVec3; 3], camera: &[DVec3; 3]) -> Option<Se3> {
    let similarity = crate::linalg::align_similarity(world, camera, false)?;
    let pose = Se3::new(similarity.rotation, similarity.translation);
    (pose.rotation.is_finite() && pose.translation.is_finite()).then_some(pose)
}

/// Camera pose from 2D–3D correspondences inside RANSAC, refined on the inliers by
/// Gauss–Newton: `camera_from_world` and the inlier indices. Image points are normalised
/// undistorted coordinates; `threshold_px` is the reprojection error of an inlier. A `guess`
/// is scored as the first hypothesis. None with fewer than six points or inliers.
pub fn pnp_ransac(
    camera: &Camera,
    world: &[DVec3],
    normalized: &[DVec2],
    guess: Option<Se3>,
    threshold_px: f32,
    iterations: i32,
    minimal: PnpMinimal,
) -> Option<(Se3, Vec<usize>)> {
    let n = world.len();
    if n < MIN_INLIERS || normalized.len() != n {
        return None;
    }
    let focal = camera.focal();
    let threshold = f64::from(threshold_px);
    let thr2 = threshold * threshold;
    let max_iterations = iterations.max(1) as usize;
    let sample_size = match minimal {
        PnpMinimal::Ap3p => 4,
        PnpMinimal::Epnp => 5,
    };
    let score = |pose: &Se3| -> (f64, usize) {
        let mut cost = 0.0;
        let mut count = 0;
        for (x, m) in world.iter().zip(normalized) {
            let e = reprojection_error_px(pose, *x, *m, focal);
            let e2 = e * e;
            if e2 <= thr2 {
                cost += e2;
                count += 1;
            } else {
                cost += thr2;
            }
        }
        (cost, count)
    };
    let mut best: Option<(f64, usize, Se3)> = guess.map(|g| {
        let (cost, count) = score(&g);
        (cost, count, g)
    });
    let mut limit = max_iterations;
    let mut rng = SplitMix64::new(0x9A95_0F3C);
    let mut sample = Vec::with_capacity(sample_size);
    let mut k = 0;
    while k < limit {
        k += 1;
        rng.sample(n, sample_size, &mut sample);
        let three = [world[sample[0]], world[sample[1]], world[sample[2]]];
        let rays = [
            normalized[sample[0]],
            normalized[sample[1]],
            normalized[sample[2]],
        ];
        // The solution the remaining sample points agree with best, if they all agree.
        let chosen = p3p(three, rays)
            .into_iter()
            .map(|pose| {
                let worst = sample[3..]
                    .iter()
                    .map(|&i| reprojection_error_px(&pose, world[i], normalized[i], focal))
                    .fold(0.0f64, f64::max);
                (worst, pose)
            })
            .filter(|(worst, _)| *worst <= threshold)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((_, pose)) = chosen else {
            continue;
        };
        let (cost, count) = score(&pose);
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, count, pose));
            limit = ransac_iterations(
                CONFIDENCE,
                count as f64 / n as f64,
                sample_size,
                max_iterations,
            );
        }
    }
    let (_, _, mut pose) = best?;
    let config = BaConfig {
        focal,
        huber_px: threshold,
        max_iterations: 10,
    };
    let inliers_of = |pose: &Se3| -> Vec<usize> {
        (0..n)
            .filter(|&i| reprojection_error_px(pose, world[i], normalized[i], focal) <= threshold)
            .collect()
    };
    let mut inliers = inliers_of(&pose);
    for _ in 0..2 {
        if inliers.len() < MIN_INLIERS {
            return None;
        }
        let (w, m): (Vec<DVec3>, Vec<DVec2>) =
            inliers.iter().map(|&i| (world[i], normalized[i])).unzip();
        let refined = refine_pose(pose, &w, &m, &config);
        let refined_inliers = inliers_of(&refined);
        if refined_inliers.len() < inliers.len() {
            break;
        }
        (pose, inliers) = (refined, refined_inliers);
    }
    (inliers.len() >= MIN_INLIERS).then_some((pose, inliers))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    fn scene(pose: &Se3, n: usize, seed: u64) -> (Vec<DVec3>, Vec<DVec2>) {
        let mut rng = SplitMix64::new(seed);
        let inverse = pose.inverse();
        let (mut w, mut m) = (Vec::new(), Vec::new());
        while w.len() < n {
            // Points in the camera's view, 1–6 m deep.
            let z = 1.0 + 5.0 * rng.unit();
            let pc = DVec3::new((rng.unit() - 0.5) * z, (rng.unit() - 0.5) * 0.75 * z, z);
            w.push(inverse.transform_point(pc));
            m.push(pc.truncate() / pc.z);
        }
        (w, m)
    }

    #[test]
    fn real_roots_of_known_polynomials() {
        // (x − 1)(x + 2)(x − 3)(x + 0.5)
        let p = poly_mul(
            &poly_mul(&[-1.0, 1.0], &[2.0, 1.0]),
            &poly_mul(&[-3.0, 1.0], &[0.5, 1.0]),
        );
        let r = real_roots(&p);
        assert_eq!(r.len(), 4, "{r:?}");
        for (a, b) in r.iter().zip([-2.0, -0.5, 1.0, 3.0]) {
            assert!((a - b).abs() < 1e-9, "{r:?}");
        }
        // x⁴ + 1 has none; x² − 4 has two.
        assert!(real_roots(&[1.0, 0.0, 0.0, 0.0, 1.0]).is_empty());
        assert_eq!(real_roots(&[-4.0, 0.0, 1.0]), vec![-2.0, 2.0]);
    }

    #[test]
    fn p3p_finds_the_true_pose_among_its_solutions() {
        let truth = Se3::new(
            DQuat::from_euler(glam::EulerRot::XYZ, 0.2, -0.4, 0.1),
            DVec3::new(0.3, -0.1, 1.5),
        );
        for seed in 0..20 {
            let (w, m) = scene(&truth, 3, seed);
            let poses = p3p([w[0], w[1], w[2]], [m[0], m[1], m[2]]);
            assert!(!poses.is_empty() && poses.len() <= 4, "seed {seed}");
            let nearest = poses
                .iter()
                .map(|p| {
                    p.rotation.angle_between(truth.rotation)
                        + (p.translation - truth.translation).length()
                })
                .fold(f64::MAX, f64::min);
            assert!(nearest < 1e-6, "seed {seed}: {nearest}");
        }
    }

    #[test]
    fn pnp_ransac_recovers_the_pose_with_outliers() {
        let camera = Camera::pinhole(640, 480, 500.0, 500.0, 320.0, 240.0);
        let truth = Se3::new(
            DQuat::from_euler(glam::EulerRot::XYZ, -0.1, 0.3, 0.05),
            DVec3::new(-0.2, 0.4, 0.8),
        );
        for minimal in [PnpMinimal::Ap3p, PnpMinimal::Epnp] {
            let (w, mut m) = scene(&truth, 120, 3);
            let mut rng = SplitMix64::new(11);
            // 0.3 px noise on all; 40 gross outliers.
            for p in m.iter_mut() {
                *p += DVec2::new(rng.unit() - 0.5, rng.unit() - 0.5) * (0.6 / 500.0);
            }
            for p in m.iter_mut().take(40) {
                *p += DVec2::new(rng.unit() - 0.5, rng.unit() - 0.5) * 0.3;
            }
            let (pose, inliers) =
                pnp_ransac(&camera, &w, &m, None, 2.0, 1000, minimal).expect("pose");
            assert!(
                pose.rotation.angle_between(truth.rotation) < 2e-3,
                "{minimal:?}"
            );
            assert!((pose.translation - truth.translation).length() < 5e-3);
            assert!(
                inliers.iter().filter(|&&i| i >= 40).count() == 80,
                "{minimal:?}"
            );
            assert!(inliers.len() <= 84, "{minimal:?}: {}", inliers.len());
        }
        // Too few points: no pose.
        let (w, m) = scene(&truth, 5, 4);
        assert!(pnp_ransac(&camera, &w, &m, None, 2.0, 100, PnpMinimal::Ap3p).is_none());
    }
}
