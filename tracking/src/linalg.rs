//! Small dense linear algebra in f64: symmetric eigen-decomposition (Jacobi), Cholesky solves and
//! Horn's closed-form similarity alignment. glam covers 2–4 dimensions; bundle adjustment needs
//! more.

use glam::{DMat3, DQuat, DVec3};

/// Eigenvalues and eigenvectors (columns of `vectors`, row-major `n x n`) of a symmetric matrix,
/// by cyclic Jacobi rotations. Sorted by decreasing eigenvalue.
pub fn symmetric_eigen(matrix: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = matrix.to_vec();
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    for _sweep in 0..60 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j] * a[i * n + j])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[p * n + q];
                if apq.abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let akp = a[k * n + p];
                    let akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let apk = a[p * n + k];
                    let aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
                for k in 0..n {
                    let vkp = v[k * n + p];
                    let vkq = v[k * n + q];
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| a[j * n + j].total_cmp(&a[i * n + i]));
    let values = order.iter().map(|&i| a[i * n + i]).collect();
    let mut vectors = vec![0.0; n * n];
    for (col, &i) in order.iter().enumerate() {
        for row in 0..n {
            vectors[row * n + col] = v[row * n + i];
        }
    }
    (values, vectors)
}

/// Solves `A x = b` for symmetric positive-definite `A` (row-major `n x n`) by Cholesky.
/// None when `A` is not positive definite.
pub fn cholesky_solve(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut sum = a[i * n + j];
            for k in 0..j {
                sum -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                if sum <= 0.0 || !sum.is_finite() {
                    return None;
                }
                l[i * n + i] = sum.sqrt();
            } else {
                l[i * n + j] = sum / l[j * n + j];
            }
        }
    }
    let mut y = vec![0.0; n];
    for i in 0..n {
        let mut sum = b[i];
        for k in 0..i {
            sum -= l[i * n + k] * y[k];
        }
        y[i] = sum / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let mut sum = y[i];
        for k in i + 1..n {
            sum -= l[k * n + i] * x[k];
        }
        x[i] = sum / l[i * n + i];
    }
    Some(x)
}

/// A similarity `y = scale * rotation * x + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Similarity {
    pub scale: f64,
    pub rotation: DQuat,
    pub translation: DVec3,
}

impl Similarity {
    pub const IDENTITY: Self = Self {
        scale: 1.0,
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    pub fn transform_point(&self, x: DVec3) -> DVec3 {
        self.scale * (self.rotation * x) + self.translation
    }
}

/// Least-squares similarity mapping `source[i]` onto `target[i]` (Umeyama's criterion, solved
/// with Horn's unit-quaternion method). With `with_scale = false` the scale stays 1 (SE(3)).
/// None with fewer than 3 pairs or degenerate (collinear) sources.
pub fn align_similarity(
    source: &[DVec3],
    target: &[DVec3],
    with_scale: bool,
) -> Option<Similarity> {
    let n = source.len();
    if n < 3 || target.len() != n {
        return None;
    }
    let mean_s = source.iter().copied().sum::<DVec3>() / n as f64;
    let mean_t = target.iter().copied().sum::<DVec3>() / n as f64;
    let mut m = DMat3::ZERO; // Σ x' y'ᵀ, m.col(b)[a] = Σ x_a y_b
    let mut var_s = 0.0;
    for (s, t) in source.iter().zip(target) {
        let (x, y) = (*s - mean_s, *t - mean_t);
        m += DMat3::from_cols(x * y.x, x * y.y, x * y.z);
        var_s += x.length_squared();
    }
    if var_s < 1e-18 {
        return None;
    }
    let s = |a: usize, b: usize| m.col(b)[a];
    let (sxx, sxy, sxz) = (s(0, 0), s(0, 1), s(0, 2));
    let (syx, syy, syz) = (s(1, 0), s(1, 1), s(1, 2));
    let (szx, szy, szz) = (s(2, 0), s(2, 1), s(2, 2));
    #[rustfmt::skip]
    let horn = [
        sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,
        syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,
        szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,
        sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz,
    ];
    let (_, vectors) = symmetric_eigen(&horn, 4);
    let rotation = DQuat::from_xyzw(vectors[4], vectors[8], vectors[12], vectors[0]).normalize();
    let scale = if with_scale {
        let dot: f64 = source
            .iter()
            .zip(target)
            .map(|(s, t)| (*t - mean_t).dot(rotation * (*s - mean_s)))
            .sum();
        dot / var_s
    } else {
        1.0
    };
    if !scale.is_finite() || scale <= 0.0 {
        return None;
    }
    Some(Similarity {
        scale,
        rotation,
        translation: mean_t - scale * (rotation * mean_s),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn similarity_alignment_recovers_a_known_transform() {
        let truth = Similarity {
            scale: 2.5,
            rotation: DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.2, 2.0),
            translation: DVec3::new(1.0, -2.0, 0.5),
        };
        let source: Vec<DVec3> = (0..20)
            .map(|i| {
                let f = i as f64;
                DVec3::new((f * 0.7).sin(), (f * 1.3).cos(), f * 0.1)
            })
            .collect();
        let target: Vec<DVec3> = source.iter().map(|&p| truth.transform_point(p)).collect();
        let found = align_similarity(&source, &target, true).expect("alignment");
        assert!(
            (found.scale - truth.scale).abs() < 1e-9,
            "scale {}",
            found.scale
        );
        assert!(found.rotation.angle_between(truth.rotation) < 1e-9);
        assert!((found.translation - truth.translation).length() < 1e-9);
    }

    #[test]
    fn cholesky_solves_a_positive_definite_system() {
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let x = cholesky_solve(&a, &[1.0, 2.0, 3.0], 3).expect("solve");
        for row in 0..3 {
            let b: f64 = (0..3).map(|k| a[row * 3 + k] * x[k]).sum();
            assert!((b - [1.0, 2.0, 3.0][row]).abs() < 1e-12);
        }
    }
}
