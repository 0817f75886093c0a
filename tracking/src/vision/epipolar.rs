//! Two-view geometry. The essential matrix by Hartley's normalised eight-point algorithm or
//! Nistér's five-point solver ([`super::five_point`], every real solution of each sample scored,
//! as OpenCV's `findEssentialMat` does) inside MSAC RANSAC on the Sampson distance, polished by Hartley's normalised eight-point least squares
//! over its inliers while that lowers the cost; the pose among its four decompositions that puts the most
//! points in front of both cameras (cheirality). The homography by Hartley's normalised
//! four-point DLT inside RANSAC on the transfer error, refitted on its inliers.

use super::five_point::{epipolar_row, essentials_from_five};
use super::{EssentialMinimal, SplitMix64, least_squares_null_9, null_vector_9, ransac_iterations};
use crate::camera::Camera;
use crate::pose::Se3;
use glam::{DMat3, DQuat, DVec2, DVec3};

/// RANSAC settings of OpenCV's `findEssentialMat` / `findHomography` defaults as cv.rs calls
/// them.
const ESSENTIAL_CONFIDENCE: f64 = 0.999;
const ESSENTIAL_MAX_ITERATIONS: usize = 1000;
const HOMOGRAPHY_CONFIDENCE: f64 = 0.995;
const HOMOGRAPHY_MAX_ITERATIONS: usize = 2000;
/// Points farther than this many baselines count as at infinity for cheirality (OpenCV's 50).
const CHEIRALITY_MAX_DEPTH: f64 = 50.0;

/// Hartley's normalisation: centroid to the origin, mean distance √2. `(scale, centre)`: a
/// point `p` maps to `scale · (p − centre)`.
fn normalisation(points: &[DVec2]) -> (f64, DVec2) {
    let n = points.len().max(1) as f64;
    let centre = points.iter().copied().sum::<DVec2>() / n;
    let mean = points.iter().map(|p| (*p - centre).length()).sum::<f64>() / n;
    let scale = if mean > 1e-12 {
        std::f64::consts::SQRT_2 / mean
    } else {
        1.0
    };
    (scale, centre)
}

/// The 3 × 3 matrix `[[s, 0, −s cx], [0, s, −s cy], [0, 0, 1]]` of a normalisation.
/// Both point sets moved and scaled by [`normalisation`] (Hartley), with the matrices that
/// did it: `t1`, `t2m` map the first and second set's points to `q1`, `q2`.
struct Normalised {
    t1: DMat3,
    t2m: DMat3,
    q1: Vec<DVec2>,
    q2: Vec<DVec2>,
}

impl Normalised {
    fn of(first: &[DVec2], second: &[DVec2]) -> Normalised {
        let (n1, n2) = (normalisation(first), normalisation(second));
        Normalised {
            t1: normalisation_matrix(n1),
            t2m: normalisation_matrix(n2),
            q1: first.iter().map(|p| n1.0 * (*p - n1.1)).collect(),
            q2: second.iter().map(|p| n2.0 * (*p - n2.1)).collect(),
        }
    }
}

fn normalisation_matrix((s, c): (f64, DVec2)) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(s, 0.0, 0.0),
        DVec3::new(0.0, s, 0.0),
        DVec3::new(-s * c.x, -s * c.y, 1.0),
    )
}

/// Row-major 9-vector to a matrix.
fn mat_from_rows(h: &[f64; 9]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(h[0], h[3], h[6]),
        DVec3::new(h[1], h[4], h[7]),
        DVec3::new(h[2], h[5], h[8]),
    )
}

/// Singular value decomposition `m = U diag(s) Vᵀ` of a 3 × 3 matrix with `U`, `V` rotations
/// (the sign of the smallest singular value absorbs a reflection). From the eigenvectors of
/// `mᵀm`; None when the two largest singular values are not both positive.
pub fn svd3(m: &DMat3) -> Option<(DMat3, DVec3, DMat3)> {
    let mtm = m.transpose() * *m;
    let flat: Vec<f64> = (0..9).map(|k| mtm.col(k % 3)[k / 3]).collect();
    let (values, vectors) = crate::linalg::symmetric_eigen(&flat, 3);
    let v_col = |c: usize| DVec3::new(vectors[c], vectors[3 + c], vectors[6 + c]);
    let (v0, v1) = (v_col(0).normalize(), v_col(1).normalize());
    let v2 = v0.cross(v1);
    let s0 = values[0].max(0.0).sqrt();
    let s1 = values[1].max(0.0).sqrt();
    if s1 <= 1e-12 * s0.max(1e-300) || !s0.is_finite() {
        return None;
    }
    let u0 = (*m * v0) / s0;
    let u1 = (*m * v1) / s1;
    let u1 = (u1 - u0 * u0.dot(u1)).normalize();
    let u0 = u0.normalize();
    let u2 = u0.cross(u1);
    // The third singular value with its sign: m v2 = s2 u2.
    let s2 = (*m * v2).dot(u2);
    Some((
        DMat3::from_cols(u0, u1, u2),
        DVec3::new(s0, s1, s2),
        DMat3::from_cols(v0, v1, v2),
    ))
}

/// The nearest essential matrix (singular values 1, 1, 0) and its `U`, `V`.
fn essential_from(m: &DMat3) -> Option<(DMat3, DMat3, DMat3)> {
    let (u, _, v) = svd3(m)?;
    let e = u * DMat3::from_diagonal(DVec3::new(1.0, 1.0, 0.0)) * v.transpose();
    Some((e, u, v))
}

/// Sampson distance², normalised units, of `x2ᵀ E x1 = 0`.
fn sampson_sq(e: &DMat3, x1: DVec2, x2: DVec2) -> f64 {
    let (a, b) = (x1.extend(1.0), x2.extend(1.0));
    let ea = *e * a;
    let etb = e.transpose() * b;
    let r = b.dot(ea);
    let d = ea.x * ea.x + ea.y * ea.y + etb.x * etb.x + etb.y * etb.y;
    if d <= 1e-300 { f64::MAX } else { r * r / d }
}

/// Eight-point rows of `x̂2ᵀ F̂ x̂1 = 0` for the given pairs of normalised-normalised points.
fn epipolar_rows(p1: &[DVec2], p2: &[DVec2], indices: &[usize]) -> Vec<[f64; 9]> {
    indices
        .iter()
        .map(|&i| epipolar_row(p1[i], p2[i]))
        .collect()
}

/// MSAC score (lower is better) and inlier count of an essential matrix.
fn score_essential(e: &DMat3, first: &[DVec2], second: &[DVec2], t2: f64) -> (f64, usize) {
    let mut cost = 0.0;
    let mut count = 0;
    for (a, b) in first.iter().zip(second) {
        let d = sampson_sq(e, *a, *b);
        if d < t2 {
            cost += d;
            count += 1;
        } else {
            cost += t2;
        }
    }
    (cost, count)
}

/// An essential matrix from the rows in normalised-normalised space, back in normalised
/// coordinates: `E = T2ᵀ F̂ T1`, projected onto the essential manifold.
fn essential_from_null(f: &[f64; 9], t1: &DMat3, t2: &DMat3) -> Option<DMat3> {
    let e = t2.transpose() * mat_from_rows(f) * *t1;
    essential_from(&e).map(|(e, _, _)| e)
}

/// The essential matrix of `x2ᵀ E x1 = 0` between normalised coordinates, by MSAC RANSAC over
/// the `minimal` solver's models (Hartley's eight points, or every real solution of Nistér's
/// five, [`super::five_point`]) with inliers within `threshold` (normalised units, Sampson
/// distance). None with fewer than eight pairs (as OpenCV's backend) or no non-degenerate sample.
pub fn find_essential(
    first: &[DVec2],
    second: &[DVec2],
    threshold: f64,
    minimal: EssentialMinimal,
) -> Option<DMat3> {
    let n = first.len();
    if n < 8 || second.len() != n {
        return None;
    }
    let thr2 = threshold * threshold;
    let Normalised { t1, t2m, q1, q2 } = Normalised::of(first, second);
    let sample_size = minimal.sample_size();
    let mut rng = SplitMix64::new(0x5EED_E55E);
    let mut sample = Vec::with_capacity(sample_size);
    let mut best: Option<(f64, DMat3)> = None;
    let mut iterations = ESSENTIAL_MAX_ITERATIONS;
    let mut k = 0;
    while k < iterations {
        k += 1;
        rng.sample(n, sample_size, &mut sample);
        let models = match minimal {
            EssentialMinimal::EightPoint => null_vector_9(&epipolar_rows(&q1, &q2, &sample))
                .and_then(|f| essential_from_null(&f, &t1, &t2m))
                .into_iter()
                .collect(),
            EssentialMinimal::FivePoint => {
                let a: [DVec2; 5] = std::array::from_fn(|i| first[sample[i]]);
                let b: [DVec2; 5] = std::array::from_fn(|i| second[sample[i]]);
                essentials_from_five(&a, &b)
            }
        };
        for e in models {
            let (cost, count) = score_essential(&e, first, second, thr2);
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, e));
                iterations = ransac_iterations(
                    ESSENTIAL_CONFIDENCE,
                    count as f64 / n as f64,
                    sample_size,
                    ESSENTIAL_MAX_ITERATIONS,
                );
            }
        }
    }
    let (mut cost, mut e) = best?;
    // Polish: Hartley's normalised eight-point least squares over the inliers (Hartley 1997),
    // kept while it lowers the MSAC cost. A sample fits its points exactly and carries their
    // noise; the refit averages it over every inlier.
    for _ in 0..3 {
        let inliers: Vec<usize> = (0..n)
            .filter(|&i| sampson_sq(&e, first[i], second[i]) < thr2)
            .collect();
        let Some(f) = least_squares_null_9(&epipolar_rows(&q1, &q2, &inliers)) else {
            break;
        };
        let Some(refit) = essential_from_null(&f, &t1, &t2m) else {
            break;
        };
        let (refit_cost, _) = score_essential(&refit, first, second, thr2);
        if refit_cost >= cost {
            break;
        }
        (cost, e) = (refit_cost, refit);
    }
    Some(e)
}

/// Depths of a point along both rays for `x2 ~ R x1 + t` (least squares), None when the rays
/// are parallel.
fn depths(r: &DMat3, t: DVec3, x1: DVec2, x2: DVec2) -> Option<(f64, f64)> {
    let a = *r * x1.extend(1.0);
    let b = x2.extend(1.0);
    // λ1 a − λ2 b = −t.
    let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
    let (at, bt) = (a.dot(-t), b.dot(-t));
    let det = aa * bb - ab * ab;
    if det.abs() < 1e-14 * aa * bb {
        return None;
    }
    let l1 = (at * bb - ab * bt) / det;
    // Depth in the second camera of the point λ1 x1.
    let z2 = (a * l1 + t).z;
    Some((l1, z2))
}

/// The rotation and unit translation among the essential matrix's four decompositions that
/// puts the most of the flagged points in front of both cameras (nearer than 50 baselines), and
/// the mask of those points.
pub fn recover_pose(
    e: &DMat3,
    first: &[DVec2],
    second: &[DVec2],
    candidates: &[bool],
) -> Option<(Se3, Vec<bool>)> {
    let (_, u, v) = essential_from(e)?;
    let w = DMat3::from_cols(
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
    );
    let (r1, r2) = (u * w * v.transpose(), u * w.transpose() * v.transpose());
    let t = u.col(2);
    let mut best: Option<(usize, DMat3, DVec3, Vec<bool>)> = None;
    for (r, t) in [(r1, t), (r1, -t), (r2, t), (r2, -t)] {
        let mask: Vec<bool> = (0..first.len())
            .map(|i| {
                candidates.get(i).copied().unwrap_or(false)
                    && depths(&r, t, first[i], second[i]).is_some_and(|(z1, z2)| {
                        z1 > 0.0
                            && z2 > 0.0
                            && z1 < CHEIRALITY_MAX_DEPTH
                            && z2 < CHEIRALITY_MAX_DEPTH
                    })
            })
            .collect();
        let count = mask.iter().filter(|&&m| m).count();
        if best.as_ref().is_none_or(|b| count > b.0) {
            best = Some((count, r, t, mask));
        }
    }
    let (count, r, t, mask) = best?;
    if count == 0 {
        return None;
    }
    let rotation = DQuat::from_mat3(&r).normalize();
    Some((Se3::new(rotation, t.normalize()), mask))
}

/// Relative pose from an essential matrix (RANSAC) and cheirality: `second_from_first` with a
/// unit translation, plus the inlier mask (inliers in front of both cameras). Inputs are
/// normalised undistorted coordinates; `threshold_px` is the Sampson distance in pixels.
pub fn relative_pose(
    camera: &Camera,
    first: &[DVec2],
    second: &[DVec2],
    threshold_px: f64,
) -> Option<(Se3, Vec<bool>)> {
    relative_pose_with(
        camera,
        first,
        second,
        threshold_px,
        EssentialMinimal::default(),
    )
}

/// [`relative_pose`] with the essential matrix's minimal solver chosen.
pub fn relative_pose_with(
    camera: &Camera,
    first: &[DVec2],
    second: &[DVec2],
    threshold_px: f64,
    minimal: EssentialMinimal,
) -> Option<(Se3, Vec<bool>)> {
    if first.len() < 8 || second.len() != first.len() {
        return None;
    }
    let threshold = threshold_px / camera.focal();
    let e = find_essential(first, second, threshold, minimal)?;
    let t2 = threshold * threshold;
    let inliers: Vec<bool> = first
        .iter()
        .zip(second)
        .map(|(a, b)| sampson_sq(&e, *a, *b) < t2)
        .collect();
    recover_pose(&e, first, second, &inliers)
}

/// Four-point DLT rows of `p2 ~ H p1`.
fn homography_rows(p1: &[DVec2], p2: &[DVec2], indices: &[usize]) -> Vec<[f64; 9]> {
    let mut rows = Vec::with_capacity(2 * indices.len());
    for &i in indices {
        let (a, b) = (p1[i], p2[i]);
        rows.push([a.x, a.y, 1.0, 0.0, 0.0, 0.0, -b.x * a.x, -b.x * a.y, -b.x]);
        rows.push([0.0, 0.0, 0.0, a.x, a.y, 1.0, -b.y * a.x, -b.y * a.y, -b.y]);
    }
    rows
}

/// Squared transfer error `|H p1 − p2|²`.
fn transfer_sq(h: &DMat3, a: DVec2, b: DVec2) -> f64 {
    let q = *h * a.extend(1.0);
    if q.z.abs() < 1e-12 {
        return f64::MAX;
    }
    (q.truncate() / q.z - b).length_squared()
}

/// `H = T2⁻¹ Ĥ T1` from a null vector in normalised space.
fn homography_from_null(h: &[f64; 9], t1: &DMat3, t2: &DMat3) -> DMat3 {
    t2.inverse() * mat_from_rows(h) * *t1
}

/// The homography `p2 ~ H p1` with the most points within `threshold` (transfer error, the
/// points' units), by RANSAC then a least-squares refit on the inliers, and its inlier mask.
pub fn find_homography(
    first: &[DVec2],
    second: &[DVec2],
    threshold: f64,
) -> Option<(DMat3, Vec<bool>)> {
    let n = first.len();
    if n < 4 || second.len() != n {
        return None;
    }
    let Normalised { t1, t2m, q1, q2 } = Normalised::of(first, second);
    let thr2 = threshold * threshold;
    let count = |h: &DMat3| {
        first
            .iter()
            .zip(second)
            .filter(|(a, b)| transfer_sq(h, **a, **b) < thr2)
            .count()
    };
    let mut rng = SplitMix64::new(0x4011_0C4A);
    let mut sample = Vec::with_capacity(4);
    let mut best: Option<(usize, DMat3)> = None;
    let mut iterations = HOMOGRAPHY_MAX_ITERATIONS;
    let mut k = 0;
    while k < iterations {
        k += 1;
        rng.sample(n, 4, &mut sample);
        let mut rows = homography_rows(&q1, &q2, &sample);
        // Eight equations: pad to a square system is unnecessary; rank 8 gives the null vector.
        rows.truncate(8);
        let Some(h) = null_vector_9(&rows) else {
            continue;
        };
        let h = homography_from_null(&h, &t1, &t2m);
        let c = count(&h);
        if best.as_ref().is_none_or(|b| c > b.0) {
            best = Some((c, h));
            iterations = ransac_iterations(
                HOMOGRAPHY_CONFIDENCE,
                c as f64 / n as f64,
                4,
                HOMOGRAPHY_MAX_ITERATIONS,
            );
        }
    }
    let (mut best_count, mut h) = best?;
    for _ in 0..3 {
        let inliers: Vec<usize> = (0..n)
            .filter(|&i| transfer_sq(&h, first[i], second[i]) < thr2)
            .collect();
        if inliers.len() < 4 {
            break;
        }
        let Some(v) = least_squares_null_9(&homography_rows(&q1, &q2, &inliers)) else {
            break;
        };
        let refit = homography_from_null(&v, &t1, &t2m);
        let c = count(&refit);
        if c <= best_count {
            break;
        }
        (best_count, h) = (c, refit);
    }
    let mask = (0..n)
        .map(|i| transfer_sq(&h, first[i], second[i]) < thr2)
        .collect();
    Some((h, mask))
}

/// Number of homography inliers (RANSAC, `threshold_px` transfer error in ideal pixels)
/// between two views given in normalised coordinates, for model selection.
pub fn homography_inliers(
    camera: &Camera,
    first: &[DVec2],
    second: &[DVec2],
    threshold_px: f64,
) -> usize {
    let ideal = |n: &DVec2| DVec2::new(camera.fx * n.x + camera.cx, camera.fy * n.y + camera.cy);
    let p1: Vec<DVec2> = first.iter().map(ideal).collect();
    let p2: Vec<DVec2> = second.iter().map(ideal).collect();
    find_homography(&p1, &p2, threshold_px)
        .map(|(_, mask)| mask.iter().filter(|&&m| m).count())
        .unwrap_or(0)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::pinhole(640, 480, 520.0, 520.0, 320.0, 240.0)
    }

    /// Random points in front of both cameras, their normalised coordinates in each.
    pub(crate) fn scene(motion: &Se3, n: usize, seed: u64) -> (Vec<DVec2>, Vec<DVec2>) {
        let mut rng = SplitMix64::new(seed);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        while a.len() < n {
            let p = DVec3::new(
                4.0 * rng.unit() - 2.0,
                3.0 * rng.unit() - 1.5,
                2.0 + 6.0 * rng.unit(),
            );
            let q = motion.transform_point(p);
            if q.z < 0.5 {
                continue;
            }
            a.push(p.truncate() / p.z);
            b.push(q.truncate() / q.z);
        }
        (a, b)
    }

    #[test]
    fn svd_of_a_rotation_times_diagonal_is_recovered() {
        let u = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1));
        let v = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, -1.2, 0.2, 0.4));
        let m = u * DMat3::from_diagonal(DVec3::new(3.0, 2.0, 0.5)) * v.transpose();
        let (su, s, sv) = svd3(&m).expect("svd");
        let back = su * DMat3::from_diagonal(s) * sv.transpose();
        assert!((back - m).to_cols_array().iter().all(|d| d.abs() < 1e-9));
        assert!((s - DVec3::new(3.0, 2.0, 0.5)).length() < 1e-9, "{s}");
        assert!((su.determinant() - 1.0).abs() < 1e-9 && (sv.determinant() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn relative_pose_recovers_a_known_motion_despite_outliers() {
        for (seed, motion) in [
            (
                1,
                Se3::new(DQuat::from_rotation_y(0.1), DVec3::new(-0.4, 0.05, 0.1)),
            ),
            (
                2,
                Se3::new(DQuat::from_rotation_x(-0.05), DVec3::new(0.0, 0.0, -0.3)),
            ),
            (
                3,
                Se3::new(DQuat::from_rotation_z(0.2), DVec3::new(0.3, -0.2, 0.0)),
            ),
        ] {
            let (a, mut b) = scene(&motion, 200, seed);
            // A quarter of the matches wrong.
            let mut rng = SplitMix64::new(seed + 100);
            for p in b.iter_mut().take(50) {
                *p += DVec2::new(rng.unit() - 0.5, rng.unit() - 0.5) * 0.2;
            }
            for minimal in [EssentialMinimal::EightPoint, EssentialMinimal::FivePoint] {
                let (pose, mask) =
                    relative_pose_with(&camera(), &a, &b, 1.0, minimal).expect("pose");
                let t = motion.translation.normalize();
                // Wrong matches that happen to lie near their epipolar line count as inliers: a
                // model slightly off that takes them in has the lower MSAC cost, and they pull the
                // refit a little: a thousandth or two of a radian.
                let angle = pose.rotation.angle_between(motion.rotation);
                let shift = (pose.translation - t).length();
                assert!(
                    angle < 2e-3 && shift < 2e-2,
                    "seed {seed}, {minimal:?}: {angle} rad, {shift}"
                );
                let inliers = mask.iter().filter(|&&m| m).count();
                assert!(
                    mask[50..].iter().all(|&m| m),
                    "seed {seed}: clean points are inliers"
                );
                assert!(inliers <= 160, "seed {seed}: {inliers} inliers");
            }
        }
    }

    #[test]
    fn five_point_relative_pose_holds_with_pixel_noise_and_outliers() {
        let cam = camera();
        let motion = Se3::new(
            DQuat::from_euler(glam::EulerRot::XYZ, 0.02, -0.06, 0.01),
            DVec3::new(-0.3, 0.05, 0.05),
        );
        let mut rng = SplitMix64::new(77);
        let mut noise = || (rng.unit() - 0.5) * 2.0 / cam.focal();
        // (A nearly planar scene has two essential matrices explaining it, the twisted pair of
        // the plane's homography: no solver can tell which is true.)
        for (name, depth_spread) in [("deep", 6.0), ("shallow", 1.5)] {
            let mut points = SplitMix64::new(31);
            let (mut a, mut b) = (Vec::new(), Vec::new());
            while a.len() < 300 {
                let p = DVec3::new(
                    4.0 * points.unit() - 2.0,
                    3.0 * points.unit() - 1.5,
                    3.0 + depth_spread * points.unit(),
                );
                let q = motion.transform_point(p);
                a.push(p.truncate() / p.z + DVec2::new(noise(), noise()));
                b.push(q.truncate() / q.z + DVec2::new(noise(), noise()));
            }
            // A fifth of the matches wrong.
            let mut wrong = SplitMix64::new(78);
            for p in b.iter_mut().step_by(5) {
                *p += DVec2::new(wrong.unit() - 0.5, wrong.unit() - 0.5) * 0.3;
            }
            let (pose, _) =
                relative_pose_with(&cam, &a, &b, 1.0, EssentialMinimal::FivePoint).expect("pose");
            let angle = pose.rotation.angle_between(motion.rotation);
            let direction = pose.translation.angle_between(motion.translation);
            // A sideways step with a turn about the vertical is the ambiguous case of two-view
            // geometry (rotation and translation trade off): at 1 px noise a few mrad and a
            // few degrees of direction are the scatter of the estimate itself.
            assert!(
                angle < 0.03 && direction < 0.3,
                "{name}: rotation off by {angle} rad, translation direction by {direction} rad"
            );
        }
    }

    #[test]
    fn too_few_points_give_no_pose() {
        let motion = Se3::new(DQuat::IDENTITY, DVec3::X);
        let (a, b) = scene(&motion, 7, 4);
        assert!(relative_pose(&camera(), &a, &b, 1.0).is_none());
        assert!(relative_pose(&camera(), &a, &b[..3], 1.0).is_none());
    }

    #[test]
    fn homography_of_a_plane_and_of_a_rotation_explains_their_points() {
        let cam = camera();
        // Pure rotation: every point fits one homography.
        let rotation = Se3::new(DQuat::from_rotation_y(0.08), DVec3::ZERO);
        let (a, b) = scene(&rotation, 150, 5);
        assert_eq!(homography_inliers(&cam, &a, &b, 1.0), 150);
        // General motion of a deep scene: far from all points fit.
        let motion = Se3::new(DQuat::from_rotation_y(0.05), DVec3::new(-0.5, 0.0, 0.1));
        let (a, b) = scene(&motion, 150, 6);
        assert!(homography_inliers(&cam, &a, &b, 1.0) < 100);
        // A known homography between pixel sets, with outliers.
        let h = DMat3::from_cols(
            DVec3::new(1.1, 0.05, 1e-4),
            DVec3::new(-0.03, 0.95, -2e-4),
            DVec3::new(12.0, -7.0, 1.0),
        );
        let mut rng = SplitMix64::new(9);
        let p1: Vec<DVec2> = (0..100)
            .map(|_| DVec2::new(640.0 * rng.unit(), 480.0 * rng.unit()))
            .collect();
        let mut p2: Vec<DVec2> = p1
            .iter()
            .map(|p| {
                let q = h * p.extend(1.0);
                q.truncate() / q.z
            })
            .collect();
        for p in p2.iter_mut().take(20) {
            *p += DVec2::new(30.0, -25.0);
        }
        let (found, mask) = find_homography(&p1, &p2, 1.0).expect("homography");
        assert!(mask[20..].iter().all(|&m| m) && mask[..20].iter().all(|&m| !m));
        let (found, h) = (found / found.col(2).z, h);
        assert!(
            (found - h).to_cols_array().iter().all(|d| d.abs() < 1e-6),
            "{found}"
        );
    }
}
