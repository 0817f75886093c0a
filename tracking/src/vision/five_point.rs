//! The five-point relative pose problem: every essential matrix `E` with `x2ᵀ E x1 = 0` for five
//! pairs of normalised image points (Nistér, "An efficient solution to the five-point relative
//! pose problem", 2004, in the formulation of Stewénius, Engels and Nistér 2006).
//!
//! The five epipolar rows leave a four-dimensional null space, `E = x X + y Y + z Z + W`. The
//! rank condition `det E = 0` and the trace condition `2 E Eᵀ E − tr(E Eᵀ) E = 0` are ten cubic
//! equations in `(x, y, z)`: a 10 × 20 matrix over the monomials. Gauss–Jordan elimination of
//! its first ten columns (the monomials of degree three and `x², y², xy`) leaves rows whose
//! differences `⟨x²z⟩ − z⟨x²⟩`, `⟨y²z⟩ − z⟨y²⟩`, `⟨xyz⟩ − z⟨xy⟩` are linear in `(x, y, 1)`
//! with coefficients polynomial in `z` (degrees 3, 3, 4): `B(z) (x, y, 1)ᵀ = 0`. Its
//! determinant, of degree ten in `z`, gives up to ten real roots; `(x, y)` follow from `B`'s
//! null vector at each.

use glam::{DMat3, DVec2, DVec3};

/// Exponents `(x, y, z)` of the twenty monomials of degree at most three, in the order whose
/// first ten columns are eliminated (Stewénius et al. 2006).
const MONOMIALS: [[u8; 3]; 20] = [
    [3, 0, 0], // x³
    [0, 3, 0], // y³
    [2, 1, 0], // x²y
    [1, 2, 0], // xy²
    [2, 0, 1], // x²z
    [2, 0, 0], // x²
    [0, 2, 1], // y²z
    [0, 2, 0], // y²
    [1, 1, 1], // xyz
    [1, 1, 0], // xy
    [1, 0, 2], // xz²
    [1, 0, 1], // xz
    [1, 0, 0], // x
    [0, 1, 2], // yz²
    [0, 1, 1], // yz
    [0, 1, 0], // y
    [0, 0, 3], // z³
    [0, 0, 2], // z²
    [0, 0, 1], // z
    [0, 0, 0], // 1
];
const X: usize = 12;
const Y: usize = 15;
const Z: usize = 18;
const ONE: usize = 19;
/// No monomial: the product's degree is above three.
const NONE: u8 = u8::MAX;

const fn monomial_index(e: [u8; 3]) -> u8 {
    let mut i = 0;
    while i < MONOMIALS.len() {
        let m = MONOMIALS[i];
        if m[0] == e[0] && m[1] == e[1] && m[2] == e[2] {
            return i as u8;
        }
        i += 1;
    }
    NONE
}

/// `PRODUCT[i][j]`: the index of monomial i times monomial j, or [`NONE`].
const PRODUCT: [[u8; 20]; 20] = {
    let mut table = [[NONE; 20]; 20];
    let mut i = 0;
    while i < 20 {
        let mut j = 0;
        while j < 20 {
            let (a, b) = (MONOMIALS[i], MONOMIALS[j]);
            if a[0] + a[1] + a[2] + b[0] + b[1] + b[2] <= 3 {
                table[i][j] = monomial_index([a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
            }
            j += 1;
        }
        i += 1;
    }
    table
};

/// A polynomial of degree at most three in `(x, y, z)`, coefficients by [`MONOMIALS`].
type Poly = [f64; 20];

/// The product of two polynomials whose degrees add up to at most three (higher terms would be
/// dropped; the callers never form them).
fn mul(a: &Poly, b: &Poly) -> Poly {
    let mut out = [0.0; 20];
    for (i, &ai) in a.iter().enumerate() {
        if ai == 0.0 {
            continue;
        }
        for (j, &bj) in b.iter().enumerate() {
            let k = PRODUCT[i][j];
            if bj != 0.0 && k != NONE {
                out[k as usize] += ai * bj;
            }
        }
    }
    out
}

fn add(a: &Poly, b: &Poly) -> Poly {
    std::array::from_fn(|k| a[k] + b[k])
}

fn sub(a: &Poly, b: &Poly) -> Poly {
    std::array::from_fn(|k| a[k] - b[k])
}

fn scale(a: &Poly, s: f64) -> Poly {
    a.map(|v| v * s)
}

/// Row-major epipolar row of `x2ᵀ E x1 = 0`.
pub(crate) fn epipolar_row(a: DVec2, b: DVec2) -> [f64; 9] {
    [
        b.x * a.x,
        b.x * a.y,
        b.x,
        b.y * a.x,
        b.y * a.y,
        b.y,
        a.x,
        a.y,
        1.0,
    ]
}

/// An orthonormal basis of the null space of five rows of nine (rank five): Gauss–Jordan with
/// full pivoting ([`super::null_space_9`]), then Gram–Schmidt. None when the rows are of lower
/// rank (a degenerate sample).
fn null_space_5x9(rows: &[[f64; 9]; 5]) -> Option<[[f64; 9]; 4]> {
    let null = super::null_space_9(rows, 5, 1e-10)?;
    let mut basis: [[f64; 9]; 4] = null.try_into().ok()?;
    // Gram–Schmidt: the basis's conditioning carries into the cubic constraints.
    for k in 0..4 {
        for j in 0..k {
            let done = basis[j];
            let d: f64 = basis[k].iter().zip(&done).map(|(a, b)| a * b).sum();
            for (v, b) in basis[k].iter_mut().zip(&done) {
                *v -= d * b;
            }
        }
        let norm = basis[k].iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm <= 1e-12 {
            return None;
        }
        for v in basis[k].iter_mut() {
            *v /= norm;
        }
    }
    Some(basis)
}

/// The ten cubic constraints (`det E` and the nine entries of `2 E Eᵀ E − tr(E Eᵀ) E`) on
/// `E = x X + y Y + z Z + W`, one row of twenty monomial coefficients each.
fn constraint_rows(basis: &[[f64; 9]; 4]) -> [Poly; 10] {
    let entry = |k: usize| {
        let mut p = [0.0; 20];
        p[X] = basis[0][k];
        p[Y] = basis[1][k];
        p[Z] = basis[2][k];
        p[ONE] = basis[3][k];
        p
    };
    let e: [[Poly; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| entry(3 * r + c)));
    let minor = |r0: usize, c0: usize, r1: usize, c1: usize| {
        sub(&mul(&e[r0][c0], &e[r1][c1]), &mul(&e[r0][c1], &e[r1][c0]))
    };
    let det = add(
        &sub(
            &mul(&e[0][0], &minor(1, 1, 2, 2)),
            &mul(&e[0][1], &minor(1, 0, 2, 2)),
        ),
        &mul(&e[0][2], &minor(1, 0, 2, 1)),
    );
    // E Eᵀ: quadratic entries.
    let eet: [[Poly; 3]; 3] = std::array::from_fn(|r| {
        std::array::from_fn(|c| (0..3).fold([0.0; 20], |s, k| add(&s, &mul(&e[r][k], &e[c][k]))))
    });
    let half_trace = scale(&add(&add(&eet[0][0], &eet[1][1]), &eet[2][2]), 0.5);
    let mut rows = [[0.0; 20]; 10];
    rows[0] = det;
    for r in 0..3 {
        for c in 0..3 {
            // (E Eᵀ E − ½ tr(E Eᵀ) E), half of the trace constraint.
            let product = (0..3).fold([0.0; 20], |s, k| add(&s, &mul(&eet[r][k], &e[k][c])));
            rows[1 + 3 * r + c] = sub(&product, &mul(&half_trace, &e[r][c]));
        }
    }
    rows
}

/// Gauss–Jordan elimination of the first ten columns with partial pivoting: afterwards row k
/// reads `monomial_k + Σ_j rows[k][10 + j] · monomial_{10+j} = 0`. False when the ten
/// columns are singular.
fn eliminate(rows: &mut [Poly; 10]) -> bool {
    let scale = rows
        .iter()
        .flat_map(|r| r.iter())
        .fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 {
        return false;
    }
    for col in 0..10 {
        let pivot = (col..10)
            .max_by(|&a, &b| rows[a][col].abs().total_cmp(&rows[b][col].abs()))
            .unwrap_or(col);
        if rows[pivot][col].abs() <= 1e-12 * scale {
            return false;
        }
        rows.swap(col, pivot);
        let p = rows[col][col];
        for v in rows[col].iter_mut() {
            *v /= p;
        }
        let pivot_row = rows[col];
        for (r, row) in rows.iter_mut().enumerate() {
            if r != col && row[col] != 0.0 {
                let f = row[col];
                for c in col..20 {
                    row[c] -= f * pivot_row[c];
                }
            }
        }
    }
    true
}

/// Polynomials in one variable, coefficients from the constant term up.
fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, &ai) in a.iter().enumerate() {
        for (j, &bj) in b.iter().enumerate() {
            out[i + j] += ai * bj;
        }
    }
    out
}

fn poly_sub(a: &[f64], b: &[f64]) -> Vec<f64> {
    (0..a.len().max(b.len()))
        .map(|k| a.get(k).copied().unwrap_or(0.0) - b.get(k).copied().unwrap_or(0.0))
        .collect()
}

fn poly_add(a: &[f64], b: &[f64]) -> Vec<f64> {
    poly_sub(a, &b.iter().map(|v| -v).collect::<Vec<_>>())
}

fn poly_eval(p: &[f64], t: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, &c| acc * t + c)
}

/// The real roots of a polynomial (constant term first), each simple or odd-fold root once:
/// the roots of the derivative split the real line into monotone pieces (Cauchy's bound
/// closes the outer two), and each piece with a sign change holds one root, found by
/// bisection. Even-fold roots (touching zero) are missed, which for the five-point problem
/// means a degenerate configuration.
pub(crate) fn real_roots(p: &[f64]) -> Vec<f64> {
    let largest = p.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return Vec::new();
    }
    let degree = match p.iter().rposition(|v| v.abs() > 1e-14 * largest) {
        Some(d) => d,
        None => return Vec::new(),
    };
    let p = &p[..=degree];
    match degree {
        0 => return Vec::new(),
        1 => return vec![-p[0] / p[1]],
        _ => {}
    }
    let lead = p[degree];
    let bound = 1.0
        + p[..degree]
            .iter()
            .fold(0.0f64, |s, v| s.max((v / lead).abs()));
    let derivative: Vec<f64> = (1..=degree).map(|k| k as f64 * p[k]).collect();
    let mut ends = vec![-bound];
    let mut critical = real_roots(&derivative);
    critical.sort_by(f64::total_cmp);
    ends.extend(critical.into_iter().filter(|c| c.abs() < bound));
    ends.push(bound);
    let mut roots = Vec::new();
    for pair in ends.windows(2) {
        let (mut a, mut b) = (pair[0], pair[1]);
        let (mut fa, fb) = (poly_eval(p, a), poly_eval(p, b));
        if fa == 0.0 {
            if roots.last().is_none_or(|&r: &f64| r != a) {
                roots.push(a);
            }
            continue;
        }
        if fb == 0.0 {
            roots.push(b);
            continue;
        }
        if (fa < 0.0) == (fb < 0.0) {
            continue;
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            let fm = poly_eval(p, m);
            if fm == 0.0 {
                (a, b) = (m, m);
                break;
            }
            if (fm < 0.0) == (fa < 0.0) {
                (a, fa) = (m, fm);
            } else {
                b = m;
            }
        }
        roots.push(0.5 * (a + b));
    }
    roots
}

/// Every essential matrix (up to ten; unit Frobenius norm) with `x2ᵀ E x1 = 0` for the five
/// pairs `(first[i], second[i])` of normalised coordinates. Empty for a degenerate sample.
pub fn essentials_from_five(first: &[DVec2; 5], second: &[DVec2; 5]) -> Vec<DMat3> {
    let rows: [[f64; 9]; 5] = std::array::from_fn(|i| epipolar_row(first[i], second[i]));
    let Some(basis) = null_space_5x9(&rows) else {
        return Vec::new();
    };
    let mut constraints = constraint_rows(&basis);
    if !eliminate(&mut constraints) {
        return Vec::new();
    }
    // B(z): rows ⟨x²z⟩ − z⟨x²⟩, ⟨y²z⟩ − z⟨y²⟩, ⟨xyz⟩ − z⟨xy⟩ over the columns of the
    // remaining monomials xz², xz, x | yz², yz, y | z³, z², z, 1.
    let b_rows: Vec<[Vec<f64>; 3]> = [(4, 5), (6, 7), (8, 9)]
        .iter()
        .map(|&(with_z, without)| {
            let a = &constraints[with_z][10..];
            let b = &constraints[without][10..];
            [
                vec![a[2], a[1] - b[2], a[0] - b[1], -b[0]],
                vec![a[5], a[4] - b[5], a[3] - b[4], -b[3]],
                vec![a[9], a[8] - b[9], a[7] - b[8], a[6] - b[7], -b[6]],
            ]
        })
        .collect();
    let [p1, q1, r1] = &b_rows[0];
    let [p2, q2, r2] = &b_rows[1];
    let [p3, q3, r3] = &b_rows[2];
    let det = poly_add(
        &poly_sub(
            &poly_mul(p1, &poly_sub(&poly_mul(q2, r3), &poly_mul(q3, r2))),
            &poly_mul(q1, &poly_sub(&poly_mul(p2, r3), &poly_mul(p3, r2))),
        ),
        &poly_mul(r1, &poly_sub(&poly_mul(p2, q3), &poly_mul(p3, q2))),
    );
    let mut solutions = Vec::new();
    for z in real_roots(&det) {
        let at = |row: &[Vec<f64>; 3]| {
            DVec3::new(
                poly_eval(&row[0], z),
                poly_eval(&row[1], z),
                poly_eval(&row[2], z),
            )
        };
        let (b1, b2, b3) = (at(&b_rows[0]), at(&b_rows[1]), at(&b_rows[2]));
        // B's null vector (x, y, 1): the cross product of its two most independent rows.
        let Some(v) = [b1.cross(b2), b1.cross(b3), b2.cross(b3)]
            .into_iter()
            .max_by(|a, b| a.z.abs().total_cmp(&b.z.abs()))
            .filter(|v| v.z.abs() > 1e-300 && v.is_finite())
        else {
            continue;
        };
        let (x, y) = (v.x / v.z, v.y / v.z);
        let e: [f64; 9] = std::array::from_fn(|k| {
            x * basis[0][k] + y * basis[1][k] + z * basis[2][k] + basis[3][k]
        });
        let norm = e.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            continue;
        }
        let e = e.map(|v| v / norm);
        solutions.push(DMat3::from_cols(
            DVec3::new(e[0], e[3], e[6]),
            DVec3::new(e[1], e[4], e[7]),
            DVec3::new(e[2], e[5], e[8]),
        ));
    }
    solutions
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::Se3;
    use crate::vision::SplitMix64;
    use glam::DQuat;

    /// `[t]×`: the cross-product matrix.
    fn skew(t: DVec3) -> DMat3 {
        DMat3::from_cols(
            DVec3::new(0.0, t.z, -t.y),
            DVec3::new(-t.z, 0.0, t.x),
            DVec3::new(t.y, -t.x, 0.0),
        )
    }

    /// Five pairs of a random scene (the epipolar tests' points in front of both cameras).
    fn five_pairs(motion: &Se3, seed: u64) -> ([DVec2; 5], [DVec2; 5]) {
        let (a, b) = crate::vision::epipolar::tests::scene(motion, 5, seed);
        (std::array::from_fn(|i| a[i]), std::array::from_fn(|i| b[i]))
    }

    #[test]
    fn real_roots_of_a_product_of_known_factors_are_found() {
        let roots = [-3.5, -0.25, 0.001, 0.7, 12.0];
        // (t − r) for each root, times (t² + 1), which has none.
        let mut p = vec![1.0, 0.0, 1.0];
        for r in roots {
            p = poly_mul(&p, &[-r, 1.0]);
        }
        let mut found = real_roots(&p);
        found.sort_by(f64::total_cmp);
        assert_eq!(found.len(), roots.len(), "{found:?}");
        for (f, r) in found.iter().zip(roots) {
            assert!((f - r).abs() < 1e-9 * r.abs().max(1.0), "{f} for {r}");
        }
    }

    #[test]
    fn one_of_the_five_point_solutions_is_the_true_essential_matrix() {
        let mut rng = SplitMix64::new(0xF1FE);
        let mut errors = Vec::new();
        for trial in 0..200 {
            let motion = Se3::new(
                DQuat::from_euler(
                    glam::EulerRot::XYZ,
                    0.3 * (rng.unit() - 0.5),
                    0.3 * (rng.unit() - 0.5),
                    0.3 * (rng.unit() - 0.5),
                ),
                DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5),
            );
            let (a, b) = five_pairs(&motion, 1000 + trial);
            let truth = skew(motion.translation) * DMat3::from_quat(motion.rotation);
            let truth = truth
                / truth
                    .to_cols_array()
                    .iter()
                    .map(|v| v * v)
                    .sum::<f64>()
                    .sqrt();
            let solutions = essentials_from_five(&a, &b);
            assert!(
                !solutions.is_empty() && solutions.len() <= 10,
                "trial {trial}: {} solutions",
                solutions.len()
            );
            let distance = |e: &DMat3| {
                let d = (*e - truth).to_cols_array();
                let s = (*e + truth).to_cols_array();
                d.iter()
                    .map(|v| v * v)
                    .sum::<f64>()
                    .min(s.iter().map(|v| v * v).sum())
                    .sqrt()
            };
            let Some(nearest) = solutions
                .iter()
                .min_by(|p, q| distance(p).total_cmp(&distance(q)))
            else {
                continue;
            };
            // It satisfies the five constraints and is essential (det 0).
            for (p, q) in a.iter().zip(&b) {
                let r = q.extend(1.0).dot(*nearest * p.extend(1.0));
                assert!(r.abs() < 1e-6, "trial {trial}: residual {r}");
            }
            assert!(
                nearest.determinant().abs() < 1e-6,
                "trial {trial}: det {}",
                nearest.determinant()
            );
            errors.push(distance(nearest));
        }
        // Minimal solvers lose digits on ill-conditioned samples: most are exact to rounding, a
        // few to a few parts in a million.
        errors.sort_by(f64::total_cmp);
        let (median, worst) = (errors[errors.len() / 2], errors[errors.len() - 1]);
        assert!(
            median < 1e-9 && worst < 1e-4,
            "distance of the nearest solution from the truth: median {median:e}, worst {worst:e}"
        );
    }

    #[test]
    fn coincident_points_give_no_solution() {
        let p = [DVec2::new(0.1, 0.2); 5];
        assert!(essentials_from_five(&p, &p).is_empty());
    }
}
