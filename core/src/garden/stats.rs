//! Measures of a garden: each tree's crown (centroid, extents) and Ripley's K (Longay 2014
//! eq. 6.6) of trunk bases and crown centroids.

use glam::{Vec2, Vec3};

use super::GardenTree;

/// The search radius t of the Ripley excess, metres (Longay 2014's measurements).
pub const RIPLEY_RADIUS_M: f32 = 5.0;

/// A tree's crown in garden space: its branches (every internode of order ≥ 1; the trunk for a
/// tree without any), weighted by length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrownStats {
    /// The trunk base.
    pub base: Vec3,
    /// The length-weighted centroid of the crown's internodes.
    pub centroid: Vec3,
    /// Horizontal extents of the crown's internode ends: along x (min, max), along z.
    pub lo: Vec2,
    pub hi: Vec2,
    pub num_internodes: usize,
}

impl CrownStats {
    pub fn of(t: &GardenTree) -> CrownStats {
        let base = t.base();
        let nodes = &t.tree.skeleton.internodes;
        let has_branches = nodes.iter().any(|n| n.order >= 1);
        let (mut sum, mut length) = (Vec3::ZERO, 0.0f32);
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for n in nodes.iter().filter(|n| n.order >= 1 || !has_branches) {
            let l = n.start.distance(n.end);
            sum += (n.start + n.end) * 0.5 * l;
            length += l;
            let e = Vec2::new(n.end.x, n.end.z);
            lo = lo.min(e);
            hi = hi.max(e);
        }
        if length <= 0.0 {
            return CrownStats {
                base,
                centroid: base,
                lo: Vec2::new(base.x, base.z),
                hi: Vec2::new(base.x, base.z),
                num_internodes: nodes.len(),
            };
        }
        let flat = Vec2::new(base.x, base.z);
        CrownStats {
            base,
            centroid: base + sum / length,
            lo: lo + flat,
            hi: hi + flat,
            num_internodes: nodes.len(),
        }
    }

    /// [`CrownStats::radius_m`] of [`CrownStats::of`], the same bits, in one pass without the
    /// centroid (no square roots): what the neighbourhood tropism asks of every tree each round.
    pub(super) fn radius_only_m(t: &GardenTree) -> f32 {
        let base = t.base();
        let nodes = &t.tree.skeleton.internodes;
        let has_branches = nodes.iter().any(|n| n.order >= 1);
        let mut has_length = false;
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for n in nodes.iter().filter(|n| n.order >= 1 || !has_branches) {
            // A length sqrt(d) adds to a positive (or NaN) sum exactly when d is not <= 0.
            let d = n.start.distance_squared(n.end);
            has_length |= d > 0.0 || d.is_nan();
            let e = Vec2::new(n.end.x, n.end.z);
            lo = lo.min(e);
            hi = hi.max(e);
        }
        let flat = Vec2::new(base.x, base.z);
        let (lo, hi) = if has_length {
            (lo + flat, hi + flat)
        } else {
            (flat, flat)
        };
        let extent = (hi - lo).max(Vec2::ZERO);
        0.25 * (extent.x + extent.y)
    }

    /// Horizontal offset of the crown's centroid from the trunk base (x, z), metres.
    pub fn offset(&self) -> Vec2 {
        Vec2::new(self.centroid.x - self.base.x, self.centroid.z - self.base.z)
    }

    /// The crown's width along x and along z, metres.
    pub fn extent(&self) -> Vec2 {
        (self.hi - self.lo).max(Vec2::ZERO)
    }

    /// Half the mean of the widths along x and z, metres.
    pub fn radius_m(&self) -> f32 {
        0.25 * (self.extent().x + self.extent().y)
    }
}

/// K(t) − πt² (Longay 2014 eq. 6.6: K(t) = λ⁻¹ Σ_{i≠j} I(d_ij < t) / n, λ = n / A) of `points`
/// (x, z) on the plot `plot_lo..plot_hi` (area A), at radius `t_m`.
///
/// Edges are handled by the border method (minus sampling): only points at least `t_m` inside
/// the plot are centres i (every point counts as a neighbour j), and the sum is divided by their
/// number instead of n, so no centre's circle is cut by the plot's edge; λ = n / A counts the
/// points on the plot. With no point that far inside, there is no estimate: `None`.
pub fn ripley_excess(points: &[Vec2], plot_lo: Vec2, plot_hi: Vec2, t_m: f32) -> Option<f32> {
    let plot = plot_hi - plot_lo;
    let area = plot.x * plot.y;
    let on_plot = points
        .iter()
        .filter(|p| p.cmpge(plot_lo).all() && p.cmple(plot_hi).all())
        .count();
    if on_plot < 2 || area.is_nan() || area <= 0.0 {
        return None;
    }
    let (inner_lo, inner_hi) = (plot_lo + Vec2::splat(t_m), plot_hi - Vec2::splat(t_m));
    if inner_lo.cmpge(inner_hi).any() {
        return None;
    }
    let mut centres = 0usize;
    let mut pairs = 0usize;
    for (i, p) in points.iter().enumerate() {
        if p.cmplt(inner_lo).any() || p.cmpgt(inner_hi).any() {
            continue;
        }
        centres += 1;
        pairs += points
            .iter()
            .enumerate()
            .filter(|&(j, q)| j != i && p.distance(*q) < t_m)
            .count();
    }
    if centres == 0 {
        return None;
    }
    let lambda = on_plot as f32 / area;
    let k = pairs as f32 / centres as f32 / lambda;
    Some(k - std::f32::consts::PI * t_m * t_m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn ripley_excess_is_near_zero_for_uniform_points_and_positive_for_clusters() {
        let (lo, hi) = (Vec2::splat(-15.0), Vec2::splat(15.0));
        let mut rng = Rng::new(3);
        let uniform: Vec<Vec2> = (0..600)
            .map(|_| Vec2::new(rng.range_f32(-15.0, 15.0), rng.range_f32(-15.0, 15.0)))
            .collect();
        let excess = ripley_excess(&uniform, lo, hi, 5.0).expect("estimate");
        assert!(excess.abs() < 6.0, "uniform excess {excess}");
        let clustered: Vec<Vec2> = (0..600)
            .map(|k| {
                let c = [Vec2::new(-6.0, -6.0), Vec2::new(6.0, 5.0)][k % 2];
                c + Vec2::new(rng.range_f32(-2.0, 2.0), rng.range_f32(-2.0, 2.0))
            })
            .collect();
        let excess = ripley_excess(&clustered, lo, hi, 5.0).expect("estimate");
        assert!(excess > 100.0, "clustered excess {excess}");
        assert_eq!(ripley_excess(&uniform[..1], lo, hi, 5.0), None);
        assert_eq!(
            ripley_excess(&uniform, Vec2::splat(-4.0), Vec2::splat(4.0), 5.0),
            None
        );
    }
}
