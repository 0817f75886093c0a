//! Horn's closed-form absolute orientation (Horn 1987): the rotation that best maps a weighted
//! point set onto another, as the eigenvector of the largest eigenvalue of a symmetric 4×4
//! matrix built from the cross-covariance. Used by the bend solver's local shape matching.

// Small dense matrix kernels read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use glam::{DQuat, DVec3};

/// Accumulates the weighted cross-covariance S = Σ w (a − a₀)(b − b₀)ᵀ of source points `a`
/// and target points `b` about fixed centres `a₀`, `b₀`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CrossCovariance {
    /// S as rows: `rows[i][j]` = Σ w aᵢ bⱼ.
    rows: [[f64; 3]; 3],
}

impl CrossCovariance {
    pub(crate) fn add(&mut self, weight: f64, a: DVec3, b: DVec3) {
        let a = a * weight;
        let (a, b) = (a.to_array(), b.to_array());
        for (row, ai) in self.rows.iter_mut().zip(a) {
            for (cell, bj) in row.iter_mut().zip(b) {
                *cell += ai * bj;
            }
        }
    }

    /// The rotation R maximising Σ w (b − b₀)·R(a − a₀); identity for an empty or degenerate set.
    pub(crate) fn best_rotation(&self, hint: DQuat) -> DQuat {
        let s = &self.rows;
        let (sxx, sxy, sxz) = (s[0][0], s[0][1], s[0][2]);
        let (syx, syy, syz) = (s[1][0], s[1][1], s[1][2]);
        let (szx, szy, szz) = (s[2][0], s[2][1], s[2][2]);
        let n = [
            [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
            [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
            [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
            [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
        ];
        let [w, x, y, z] = largest_eigenvector(n, [hint.w, hint.x, hint.y, hint.z]);
        let q = DQuat::from_xyzw(x, y, z, w);
        let len = q.length();
        if !len.is_finite() || len < 1e-12 {
            return DQuat::IDENTITY;
        }
        let q = q / len;
        // q and −q are the same rotation; keep the hemisphere of the hint for continuity.
        if q.dot(hint) < 0.0 { -q } else { q }
    }
}

/// Eigenvector of the largest eigenvalue of a symmetric 4×4 matrix by cyclic Jacobi rotations.
/// When the top eigenvalue is (numerically) repeated, the hint decides among the eigenvectors.
fn largest_eigenvector(mut a: [[f64; 4]; 4], hint: [f64; 4]) -> [f64; 4] {
    let mut v = [[0.0f64; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let scale: f64 = a.iter().flatten().map(|x| x.abs()).sum::<f64>().max(1e-300);
    for _sweep in 0..12 {
        let off: f64 = (0..4)
            .flat_map(|p| ((p + 1)..4).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q].abs())
            .sum();
        if off <= 1e-13 * scale {
            break;
        }
        for p in 0..3 {
            for q in (p + 1)..4 {
                jacobi_rotate(&mut a, &mut v, p, q);
            }
        }
    }
    let top = (0..4).fold(0, |best, i| if a[i][i] > a[best][best] { i } else { best });
    // Gather the eigenvectors whose eigenvalue ties with the top one and project the hint on them.
    let tie = 1e-9 * scale;
    let mut result = [0.0f64; 4];
    let mut tied = 0;
    for k in 0..4 {
        if a[top][top] - a[k][k] <= tie {
            tied += 1;
            let column = [v[0][k], v[1][k], v[2][k], v[3][k]];
            let dot: f64 = column.iter().zip(hint).map(|(c, h)| c * h).sum();
            for (r, c) in result.iter_mut().zip(column) {
                *r += dot * c;
            }
        }
    }
    let norm: f64 = result.iter().map(|x| x * x).sum::<f64>().sqrt();
    if tied > 1 && norm > 1e-9 {
        result
    } else {
        [v[0][top], v[1][top], v[2][top], v[3][top]]
    }
}

fn jacobi_rotate(a: &mut [[f64; 4]; 4], v: &mut [[f64; 4]; 4], p: usize, q: usize) {
    let apq = a[p][q];
    if apq.abs() < 1e-300 {
        return;
    }
    let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
    let t = if theta == 0.0 { 1.0 } else { t };
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    for k in 0..4 {
        let (akp, akq) = (a[k][p], a[k][q]);
        a[k][p] = c * akp - s * akq;
        a[k][q] = s * akp + c * akq;
    }
    for k in 0..4 {
        let (apk, aqk) = (a[p][k], a[q][k]);
        a[p][k] = c * apk - s * aqk;
        a[q][k] = s * apk + c * aqk;
    }
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = c * vp - s * vq;
        row[q] = s * vp + c * vq;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    #[test]
    fn recovers_a_known_rotation_from_rotated_points() {
        let truth = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
        let points = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.5),
            DVec3::new(-1.0, 0.3, 1.0),
            DVec3::new(0.2, -1.0, -0.7),
        ];
        let mut s = CrossCovariance::default();
        for p in points {
            s.add(0.7, p, truth * p);
        }
        let q = s.best_rotation(DQuat::IDENTITY);
        assert!(
            q.dot(truth).abs() > 1.0 - 1e-9,
            "got {q:?}, wanted {truth:?}"
        );
    }

    #[test]
    fn identical_point_sets_give_the_identity() {
        let mut s = CrossCovariance::default();
        for p in [DVec3::X, DVec3::Y * 2.0, DVec3::new(0.0, -1.0, 3.0)] {
            s.add(1.0, p, p);
        }
        let q = s.best_rotation(DQuat::IDENTITY);
        assert!((q.w - 1.0).abs() < 1e-12, "{q:?}");
        assert!(DMat3::from_quat(q).abs_diff_eq(DMat3::IDENTITY, 1e-9));
    }

    #[test]
    fn collinear_points_keep_the_hinted_twist() {
        // Points on the x axis fix the rotation only up to a twist about x: the hint decides.
        let hint = DQuat::from_rotation_x(0.4);
        let mut s = CrossCovariance::default();
        for p in [DVec3::X, -DVec3::X * 2.0] {
            s.add(1.0, p, p);
        }
        let q = s.best_rotation(hint);
        assert!(q.dot(hint).abs() > 1.0 - 1e-9, "{q:?}");
    }
}
