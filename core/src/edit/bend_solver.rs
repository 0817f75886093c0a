//! Global solver for the bend energy (A.2): Levenberg–Marquardt over the rigid motions of all
//! prisms of a path at once.
//!
//! Local shape matching alone propagates a displacement by about one prism per sweep and needs
//! tens of thousands of sweeps to settle a 30-prism branch (measured). A path, however, is a
//! chain: each joint couples only two neighbouring prisms, so the Gauss–Newton normal equations
//! are block tridiagonal (6×6 blocks: a rotation ω and a translation τ per prism) and are solved
//! exactly in O(n) by block elimination. Each step linearises the motion of a point x of prism i
//! about the prism's current centre cᵢ: x' ≈ x + ω × (x − cᵢ) + τ.

// Small dense matrix kernels read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use glam::{DQuat, DVec3};

/// A rigid motion x ↦ R x + t of rest-pose world points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Motion {
    pub rotation: DQuat,
    pub translation: DVec3,
}

impl Motion {
    pub const IDENTITY: Motion = Motion {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }
}

/// A joint face: Gauss points of the bilinear patch shared (in the rest pose) by prism k − 1
/// (or the fixed tree below B when k = 0) and prism k.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Face {
    pub points: [DVec3; 4],
    /// w_ij / 4: the joint weight times the Gauss weight of each point.
    pub point_weight: f64,
}

/// A positional constraint: the rest point `rest` of prism `prism` goes to `target`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pin {
    pub prism: usize,
    pub rest: DVec3,
    pub target: DVec3,
}

/// The problem: faces (face k at the start of prism k), prism centres at rest, and for each
/// prism the world point its pin holds fixed, if it is pinned. Pins are hard: a pinned prism
/// only rotates about its pin (its translation is eliminated).
pub(crate) struct Problem<'a> {
    pub faces: &'a [Face],
    pub rest_centres: &'a [DVec3],
    pub pivots: &'a [Option<DVec3>],
}

/// A deterministic start that already satisfies the pins: the whole path turned about the
/// start of B towards the farthest pin, then each pinned prism shifted onto its target.
/// Equal to the rest pose when every pin is at its rest position.
pub(crate) fn initial_motions(n: usize, base: DVec3, pins: &[Pin]) -> Vec<Motion> {
    let mut motions = vec![Motion::IDENTITY; n];
    let Some(far) = pins.iter().max_by_key(|p| p.prism) else {
        return motions;
    };
    let (from, to) = (far.rest - base, far.target - base);
    let turn = match (from.try_normalize(), to.try_normalize()) {
        (Some(a), Some(b)) if a.dot(b) > -1.0 + 1e-9 => DQuat::from_rotation_arc(a, b),
        _ => DQuat::IDENTITY,
    };
    let turned = Motion {
        rotation: turn,
        translation: base - turn * base,
    };
    motions.fill(turned);
    for pin in pins {
        let m = &mut motions[pin.prism];
        m.translation += pin.target - m.apply(pin.rest);
    }
    motions
}

type Mat6 = [[f64; 6]; 6];
type Vec6 = [f64; 6];

/// Runs Levenberg–Marquardt from `motions` until the step is below `tolerance` metres.
/// Returns the number of accepted steps.
pub(crate) fn minimise(
    problem: &Problem,
    motions: &mut [Motion],
    tolerance: f64,
    max_steps: u32,
) -> u32 {
    let n = motions.len();
    let mut system = System::new(n);
    let mut trial = motions.to_vec();
    let mut scaled = vec![[0.0; 6]; n];
    let mut energy = problem.energy(motions);
    let mut accepted = 0;
    for _ in 0..max_steps {
        if energy <= 1e-30 {
            break;
        }
        system.assemble(problem, motions);
        let step = system.solve(1e-9);
        // Backtracking along the Gauss–Newton direction: rotations make the model optimistic.
        let mut fraction = 1.0;
        let mut improved = false;
        while fraction > 1e-3 {
            for (out, s) in scaled.iter_mut().zip(step) {
                *out = s.map(|v| v * fraction);
            }
            let moved = apply_step(problem, motions, &scaled, &mut trial);
            let candidate = problem.energy(&trial);
            if candidate < energy {
                motions.copy_from_slice(&trial);
                let gain = energy - candidate;
                energy = candidate;
                improved = moved > tolerance && gain > 1e-12 * energy;
                accepted += 1;
                break;
            }
            fraction *= 0.5;
        }
        if !improved {
            break;
        }
    }
    accepted
}

impl Problem<'_> {
    /// Σ w ‖x_a − x_b‖² over the joints.
    pub fn energy(&self, motions: &[Motion]) -> f64 {
        self.joint_energy(motions)
    }

    fn centre(&self, i: usize, m: &Motion) -> DVec3 {
        self.pivots[i].unwrap_or_else(|| m.apply(self.rest_centres[i]))
    }

    fn joint_energy(&self, motions: &[Motion]) -> f64 {
        let mut e = 0.0;
        for (k, face) in self.faces.iter().enumerate() {
            for p in face.points {
                let below = if k == 0 { p } else { motions[k - 1].apply(p) };
                e += face.point_weight * below.distance_squared(motions[k].apply(p));
            }
        }
        e
    }
}

/// x' = exp(ω)(x − c) + c + τ for every prism: R' = QR, t' = Q(t − c) + c + τ.
/// Returns the largest displacement of a prism centre.
fn apply_step(problem: &Problem, motions: &[Motion], step: &[Vec6], out: &mut [Motion]) -> f64 {
    let mut moved = 0.0f64;
    for (i, (m, s)) in motions.iter().zip(step).enumerate() {
        let centre = problem.centre(i, m);
        let omega = DVec3::new(s[0], s[1], s[2]);
        let tau = if problem.pivots[i].is_some() {
            DVec3::ZERO
        } else {
            DVec3::new(s[3], s[4], s[5])
        };
        let q = DQuat::from_scaled_axis(omega);
        out[i] = Motion {
            rotation: (q * m.rotation).normalize(),
            translation: q * (m.translation - centre) + centre + tau,
        };
        moved = moved.max(tau.length() + omega.length() * 0.1);
    }
    moved
}

/// Normal equations H δ = −g, block tridiagonal: diagonal blocks, blocks above the diagonal.
struct System {
    diagonal: Vec<Mat6>,
    upper: Vec<Mat6>,
    gradient: Vec<Vec6>,
    factors: Vec<Mat6>,
    coupling: Vec<Mat6>,
    rhs: Vec<Vec6>,
    step: Vec<Vec6>,
}

impl System {
    fn new(n: usize) -> System {
        System {
            diagonal: vec![[[0.0; 6]; 6]; n],
            upper: vec![[[0.0; 6]; 6]; n],
            gradient: vec![[0.0; 6]; n],
            factors: vec![[[0.0; 6]; 6]; n],
            coupling: vec![[[0.0; 6]; 6]; n],
            rhs: vec![[0.0; 6]; n],
            step: vec![[0.0; 6]; n],
        }
    }

    fn assemble(&mut self, problem: &Problem, motions: &[Motion]) {
        let zero = [[0.0; 6]; 6];
        self.diagonal.fill(zero);
        self.upper.fill(zero);
        self.gradient.fill([0.0; 6]);
        let centres: Vec<DVec3> = motions
            .iter()
            .enumerate()
            .map(|(i, m)| problem.centre(i, m))
            .collect();
        for (k, face) in problem.faces.iter().enumerate() {
            let w = face.point_weight;
            for p in face.points {
                let xb = motions[k].apply(p);
                let db = xb - centres[k];
                let xa = if k == 0 { p } else { motions[k - 1].apply(p) };
                let r = xa - xb;
                // r(δ) = r + A δ_a − B δ_b with A = J(d_a), B = J(d_b), J(d) = [−[d]×, I].
                add_jtj(&mut self.diagonal[k], w, db, db);
                add_jtr(&mut self.gradient[k], -w, db, r);
                if k > 0 {
                    let da = xa - centres[k - 1];
                    add_jtj(&mut self.diagonal[k - 1], w, da, da);
                    add_jtj(&mut self.upper[k - 1], -w, da, db);
                    add_jtr(&mut self.gradient[k - 1], w, da, r);
                }
            }
        }
        // A pinned prism has no translation: drop its τ rows and columns.
        for (i, pivot) in problem.pivots.iter().enumerate() {
            if pivot.is_none() {
                continue;
            }
            for a in 3..6 {
                for b in 0..6 {
                    self.diagonal[i][a][b] = 0.0;
                    self.diagonal[i][b][a] = 0.0;
                    self.upper[i][a][b] = 0.0;
                    if i > 0 {
                        self.upper[i - 1][b][a] = 0.0;
                    }
                }
                self.diagonal[i][a][a] = 1.0;
                self.gradient[i][a] = 0.0;
            }
        }
    }

    /// Solves (H + μ diag H) δ = −g by block Cholesky elimination along the chain:
    /// with S_{i−1} = L Lᵀ and W = L⁻¹ U_{i−1}, S_i = D_i − WᵀW and y_i = −g_i − Wᵀ L⁻¹ y_{i−1}.
    fn solve(&mut self, damping: f64) -> &[Vec6] {
        let n = self.diagonal.len();
        for i in 0..n {
            let mut s = self.diagonal[i];
            for (j, row) in s.iter_mut().enumerate() {
                row[j] += damping * (self.diagonal[i][j][j] + 1e-12);
            }
            let mut y = self.gradient[i].map(|g| -g);
            if i > 0 {
                let w = &self.coupling[i - 1];
                let z = forward_solve(&self.factors[i - 1], self.rhs[i - 1]);
                for a in 0..6 {
                    for b in a..6 {
                        let mut acc = 0.0;
                        for c in 0..6 {
                            acc += w[c][a] * w[c][b];
                        }
                        s[a][b] -= acc;
                        if a != b {
                            s[b][a] -= acc;
                        }
                    }
                    let mut acc = 0.0;
                    for c in 0..6 {
                        acc += w[c][a] * z[c];
                    }
                    y[a] -= acc;
                }
            }
            self.factors[i] = cholesky(s);
            self.rhs[i] = y;
            if i + 1 < n {
                let mut w = [[0.0; 6]; 6];
                for b in 0..6 {
                    let column = std::array::from_fn(|a| self.upper[i][a][b]);
                    let solved = forward_solve(&self.factors[i], column);
                    for a in 0..6 {
                        w[a][b] = solved[a];
                    }
                }
                self.coupling[i] = w;
            }
        }
        for i in (0..n).rev() {
            let mut y = self.rhs[i];
            if i + 1 < n {
                let next = self.step[i + 1];
                for (a, ya) in y.iter_mut().enumerate() {
                    *ya -= (0..6).map(|b| self.upper[i][a][b] * next[b]).sum::<f64>();
                }
            }
            self.step[i] = cholesky_solve(&self.factors[i], y);
        }
        &self.step
    }
}

/// m += w J(a)ᵀ J(b) with J(d) = [−[d]×, I]:
/// J(a)ᵀJ(b) = [[(a·b) I − b aᵀ, [a]×], [−[b]×, I]].
fn add_jtj(m: &mut Mat6, w: f64, a: DVec3, b: DVec3) {
    let ab = a.dot(b);
    let (aa, ba) = (a.to_array(), b.to_array());
    for r in 0..3 {
        for c in 0..3 {
            let identity = if r == c { 1.0 } else { 0.0 };
            m[r][c] += w * (ab * identity - ba[r] * aa[c]);
            m[r + 3][c + 3] += w * identity;
        }
    }
    let skew = |v: DVec3| [[0.0, -v.z, v.y], [v.z, 0.0, -v.x], [-v.y, v.x, 0.0]];
    let (sa, sb) = (skew(a), skew(b));
    for r in 0..3 {
        for c in 0..3 {
            m[r][c + 3] += w * sa[r][c];
            m[r + 3][c] -= w * sb[r][c];
        }
    }
}

/// g += w J(d)ᵀ r = w [d × r; r].
fn add_jtr(g: &mut Vec6, w: f64, d: DVec3, r: DVec3) {
    let torque = d.cross(r);
    for (slot, v) in g
        .iter_mut()
        .zip([torque.x, torque.y, torque.z, r.x, r.y, r.z])
    {
        *slot += w * v;
    }
}

/// Lower Cholesky factor of a symmetric positive definite 6×6 matrix (pivots floored).
fn cholesky(a: Mat6) -> Mat6 {
    let mut l = [[0.0; 6]; 6];
    for j in 0..6 {
        let mut d = a[j][j];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        let d = d.max(1e-300).sqrt();
        l[j][j] = d;
        for i in (j + 1)..6 {
            let mut s = a[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            l[i][j] = s / d;
        }
    }
    l
}

/// Solves L y = b for the lower triangular L.
fn forward_solve(l: &Mat6, b: Vec6) -> Vec6 {
    let mut y = [0.0; 6];
    for i in 0..6 {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i][k] * y[k];
        }
        y[i] = s / l[i][i];
    }
    y
}

fn cholesky_solve(l: &Mat6, b: Vec6) -> Vec6 {
    let y = forward_solve(l, b);
    let mut x = [0.0; 6];
    for i in (0..6).rev() {
        let mut s = y[i];
        for k in (i + 1)..6 {
            s -= l[k][i] * x[k];
        }
        x[i] = s / l[i][i];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_elimination_solves_a_coupled_chain_exactly() {
        // Two prisms, one joint between them and one anchored face: check H δ = −g.
        let face = |y: f64| Face {
            points: [
                DVec3::new(0.1, y, 0.1),
                DVec3::new(-0.1, y, 0.1),
                DVec3::new(0.1, y, -0.1),
                DVec3::new(-0.1, y, -0.1),
            ],
            point_weight: 1.0,
        };
        let faces = [face(0.0), face(1.0)];
        let centres = [DVec3::new(0.0, 0.5, 0.0), DVec3::new(0.0, 1.5, 0.0)];
        let pins = [Pin {
            prism: 1,
            rest: DVec3::new(0.0, 2.0, 0.0),
            target: DVec3::new(0.3, 1.9, 0.0),
        }];
        let pivots = [None, Some(pins[0].target)];
        let problem = Problem {
            faces: &faces,
            rest_centres: &centres,
            pivots: &pivots,
        };
        let mut motions = initial_motions(2, DVec3::ZERO, &pins);
        let before = problem.energy(&motions);
        let steps = minimise(&problem, &mut motions, 1e-12, 100);
        let after = problem.energy(&motions);
        assert!(
            steps > 0 && after < 0.5 * before,
            "energy {before} → {after}"
        );
        assert!(motions[1].apply(pins[0].rest).distance(pins[0].target) < 1e-12);
        // At the optimum the gradient vanishes: no small rigid nudge lowers the energy.
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            for sign in [-1.0, 1.0] {
                let mut nudged = motions.clone();
                nudged[0].translation += axis * sign * 1e-4;
                assert!(problem.energy(&nudged) >= after - 1e-12);
                let q = DQuat::from_scaled_axis(axis * sign * 1e-4);
                let pivot = pins[0].target;
                nudged = motions.clone();
                nudged[1].rotation = q * nudged[1].rotation;
                nudged[1].translation = q * (nudged[1].translation - pivot) + pivot;
                assert!(problem.energy(&nudged) >= after - 1e-12);
            }
        }
    }
}
