//! Step 8: widths by the pipe model, d^n = Σ d_i^n from the tips (diameter d_e) down.
//!
//! Width constraints split the tree into subtrees: the root's subtree and one below every
//! constrained internode. A subtree whose root is constrained to D, with boundary leaves of
//! diameters d_j (its tips, d_e, and the constrained internodes below it), gets its own exponent
//! from Σ (d_j/D)^n = 1, solved by Newton–Raphson; for M tips only this is
//! n = log M / (log D − log d_e). An unconstrained root uses the species exponent.

use super::Scratch;
use crate::tree::Skeleton;

/// Exponent bounds: outside them a constraint cannot be met by the pipe model.
const MIN_EXPONENT: f64 = 0.25;
const MAX_EXPONENT: f64 = 64.0;

/// Solves Σ_j count_j·(d_j/D)^n = 1 for n by safeguarded Newton–Raphson (bisection fallback).
/// Returns `None` when no n in [0.25, 64] satisfies it (e.g. a single leaf thinner than D).
pub fn solve_pipe_exponent(leaves: &[(f64, f64)], base_diameter: f64, initial: f64) -> Option<f64> {
    let f = |n: f64| -> (f64, f64) {
        let mut value = -1.0;
        let mut slope = 0.0;
        for &(count, d) in leaves {
            let ratio = d / base_diameter;
            let term = count * ratio.powf(n);
            value += term;
            slope += term * ratio.ln();
        }
        (value, slope)
    };
    let (mut lo, mut hi) = (MIN_EXPONENT, MAX_EXPONENT);
    let (f_lo, f_hi) = (f(lo).0, f(hi).0);
    if f_lo.signum() == f_hi.signum() {
        return None;
    }
    let decreasing = f_lo > 0.0;
    let mut n = initial.clamp(lo, hi);
    for _ in 0..100 {
        let (value, slope) = f(n);
        if value.abs() < 1e-12 {
            return Some(n);
        }
        if (value > 0.0) == decreasing {
            lo = n;
        } else {
            hi = n;
        }
        let newton = n - value / slope;
        n = if slope != 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo < 1e-12 {
            break;
        }
    }
    Some(n)
}

/// Recomputes all diameters and the per-internode exponents.
pub(crate) fn update(
    skeleton: &mut Skeleton,
    tip_diameter: f32,
    default_exponent: f32,
    exponents: &mut Vec<f32>,
    scratch: &mut Scratch,
) {
    let nodes = &mut skeleton.internodes;
    let n = nodes.len();
    exponents.clear();
    exponents.resize(n, default_exponent);
    scratch.widths_of = None;
    // Without width constraints (the usual case) the whole tree is the root's subtree with the
    // species exponent: one basipetal pass, given up at the first constrained internode.
    if basipetal(nodes, None, exponents, tip_diameter, &mut scratch.acc) {
        scratch.widths_of = Some(WidthsOf::new(n, tip_diameter, default_exponent));
        return;
    }
    let roots = &mut scratch.subtree_root;
    roots.clear();
    roots.resize(n, 0);
    for i in 0..n {
        let constrained = nodes[i].width_constraint.is_some();
        roots[i] = match nodes[i].parent {
            Some(p) if !constrained => roots[p.index()],
            _ => i as u32,
        };
    }
    solve_subtree_exponents(nodes, roots, tip_diameter, default_exponent, exponents);
    basipetal(
        nodes,
        Some(roots),
        exponents,
        tip_diameter,
        &mut scratch.acc,
    );
}

/// What `Scratch::acc` holds the sums of: an arena of `len` internodes without width
/// constraints, at these tip diameter and exponent (bits), as the last width update left it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct WidthsOf {
    len: usize,
    tip_diameter: u32,
    exponent: u32,
}

impl WidthsOf {
    fn new(len: usize, tip_diameter: f32, exponent: f32) -> Self {
        WidthsOf {
            len,
            tip_diameter: tip_diameter.to_bits(),
            exponent: exponent.to_bits(),
        }
    }
}

/// New internodes per old one above which [`update_after_growth`] is not tried.
const PATH_UPDATE_FRACTION: usize = 8;

/// [`update`] after internodes were only appended to an arena of `num_before` internodes
/// (no internode removed, no link or constraint changed among the old ones) whose widths the
/// last update computed: only the new internodes and their ancestors change, and they are
/// recomputed from the kept sums, in the same descending order and with the same sums as the
/// whole pass (a node's sum adds its children's masses from the highest index down, as the
/// reverse loop does), so every diameter comes out bit for bit the same. False, having
/// changed nothing, when the kept sums do not describe the arena or the paths would cover
/// too much of it (the caller then runs [`update`]).
pub(crate) fn update_after_growth(
    skeleton: &mut Skeleton,
    tip_diameter: f32,
    default_exponent: f32,
    exponents: &mut Vec<f32>,
    scratch: &mut Scratch,
    num_before: usize,
) -> bool {
    let nodes = &mut skeleton.internodes;
    let n = nodes.len();
    if scratch.widths_of != Some(WidthsOf::new(num_before, tip_diameter, default_exponent))
        || scratch.acc.len() != num_before
        || exponents.len() != num_before
        || num_before == 0
        || n < num_before
        || (n - num_before).saturating_mul(PATH_UPDATE_FRACTION) > num_before
    {
        return false;
    }
    // The old ancestors of the new internodes, each once.
    let (marked, dirty) = (&mut scratch.on_path, &mut scratch.path_nodes);
    marked.clear();
    marked.resize(num_before, false);
    dirty.clear();
    let limit = num_before / 4;
    for i in num_before..n {
        let mut node = nodes[i].parent.map(|p| p.index());
        while let Some(p) = node {
            if p >= num_before || marked[p] {
                break;
            }
            marked[p] = true;
            dirty.push(p as u32);
            node = nodes[p].parent.map(|q| q.index());
        }
        if dirty.len() > limit {
            return false;
        }
    }
    let constrained = |i: usize| nodes[i].width_constraint.is_some();
    if (num_before..n).any(constrained) || dirty.iter().any(|&i| constrained(i as usize)) {
        return false;
    }
    dirty.sort_unstable_by(|a, b| b.cmp(a));
    exponents.resize(n, default_exponent);
    let acc = &mut scratch.acc;
    acc.resize(n, 0.0);
    let exponent = f64::from(default_exponent);
    let tip_mass = f64::from(tip_diameter).powf(exponent);
    let new_nodes = (num_before..n).rev();
    for i in new_nodes.chain(dirty.iter().map(|&i| i as usize)) {
        // The children's masses, highest index first (the order the reverse pass adds them).
        let mut children: smallvec::SmallVec<[u32; 4]> = nodes[i].children().map(|c| c.0).collect();
        children.sort_unstable_by(|a, b| b.cmp(a));
        let mut sum = 0.0f64;
        for &c in &children {
            let child = &nodes[c as usize];
            sum += if child.is_tip() {
                tip_mass
            } else {
                acc[c as usize]
            };
        }
        let node = &nodes[i];
        let diameter = if node.is_tip() {
            tip_diameter
        } else {
            match (node.main_child, node.lateral_children.is_empty()) {
                (Some(c), true) if !nodes[c.index()].is_tip() => nodes[c.index()].diameter,
                _ => sum.powf(1.0 / exponent) as f32,
            }
        };
        acc[i] = sum;
        nodes[i].diameter = diameter;
    }
    scratch.widths_of = Some(WidthsOf::new(n, tip_diameter, default_exponent));
    true
}

/// The basipetal pass: acc[i] = Σ over children of d_c^{n_i}; d_i = acc^{1/n_i}. `roots` gives
/// each internode's subtree; `None` means one subtree for all, and then the pass stops (false)
/// at the first width constraint.
fn basipetal(
    nodes: &mut [crate::tree::Internode],
    roots: Option<&[u32]>,
    exponents: &[f32],
    tip_diameter: f32,
    acc: &mut Vec<f64>,
) -> bool {
    let n = nodes.len();
    let same_subtree = |a: usize, b: usize| roots.is_none_or(|r| r[a] == r[b]);
    acc.clear();
    acc.resize(n, 0.0);
    // d_e^n of a tip, for the last exponent seen (almost always the same one).
    let mut tip_mass = (f64::NAN, 0.0);
    for i in (0..n).rev() {
        if roots.is_none() && nodes[i].width_constraint.is_some() {
            return false;
        }
        let exponent = f64::from(exponents[i]);
        // A node whose only child is an unconstrained inner node of its own subtree sums that
        // child's mass alone (0 + m = m exactly), so its diameter is the child's: no power.
        let chain_diameter = match (nodes[i].main_child, nodes[i].lateral_children.is_empty()) {
            (Some(c), true) => {
                let child = &nodes[c.index()];
                let c = c.index();
                (child.width_constraint.is_none()
                    && !child.is_tip()
                    && same_subtree(c, i)
                    && exponents[c] == exponents[i])
                    .then_some(child.diameter)
            }
            _ => None,
        };
        let node = &mut nodes[i];
        let (diameter, mass) = if let Some(d) = node.width_constraint {
            (d, f64::from(d).powf(exponent))
        } else if node.is_tip() {
            if tip_mass.0 != exponent {
                tip_mass = (exponent, f64::from(tip_diameter).powf(exponent));
            }
            (tip_diameter, tip_mass.1)
        } else {
            let diameter = chain_diameter.unwrap_or_else(|| (acc[i].powf(1.0 / exponent)) as f32);
            (diameter, acc[i])
        };
        node.diameter = diameter;
        if let Some(p) = node.parent {
            let p = p.index();
            acc[p] += if same_subtree(i, p) {
                mass
            } else {
                f64::from(diameter).powf(f64::from(exponents[p]))
            };
        }
    }
    true
}

fn solve_subtree_exponents(
    nodes: &[crate::tree::Internode],
    roots: &[u32],
    tip_diameter: f32,
    default_exponent: f32,
    exponents: &mut [f32],
) {
    // Boundary leaves per subtree root: (root, count, diameter).
    let mut leaves: Vec<(u32, f64, f64)> = Vec::new();
    for (i, node) in nodes.iter().enumerate() {
        if let (Some(d), Some(p)) = (node.width_constraint, node.parent) {
            leaves.push((roots[p.index()], 1.0, f64::from(d)));
        } else if node.width_constraint.is_none() && node.is_tip() {
            leaves.push((roots[i], 1.0, f64::from(tip_diameter)));
        }
    }
    leaves.sort_by(|a, b| a.0.cmp(&b.0).then(a.2.total_cmp(&b.2)));
    // Merge equal diameters so M identical tips cost one term.
    let mut merged: Vec<(u32, f64, f64)> = Vec::new();
    for leaf in leaves {
        match merged.last_mut() {
            Some(last) if last.0 == leaf.0 && last.2 == leaf.2 => last.1 += leaf.1,
            _ => merged.push(leaf),
        }
    }
    let mut start = 0;
    while start < merged.len() {
        let root = merged[start].0;
        let end = start + merged[start..].iter().take_while(|l| l.0 == root).count();
        if let Some(d) = nodes[root as usize].width_constraint {
            let terms: Vec<(f64, f64)> = merged[start..end].iter().map(|l| (l.1, l.2)).collect();
            if let Some(n) = solve_pipe_exponent(&terms, f64::from(d), f64::from(default_exponent))
            {
                exponents[root as usize] = n as f32;
            }
        }
        start = end;
    }
    for i in 0..nodes.len() {
        exponents[i] = exponents[roots[i] as usize];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newton_recovers_the_closed_form_exponent_for_identical_tips() {
        // M tips of d_e under a base of D: n = log M / (log D − log d_e).
        let (m, d_e, d_b) = (1000.0f64, 0.005, 0.3);
        let n = solve_pipe_exponent(&[(m, d_e)], d_b, 2.0).unwrap();
        let closed = m.ln() / (d_b.ln() - d_e.ln());
        assert!((n - closed).abs() < 1e-9, "{n} vs {closed}");
        assert!(solve_pipe_exponent(&[(1.0, 0.01)], 0.3, 2.0).is_none());
    }
}
