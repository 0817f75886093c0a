//! Steps 1 and 3: light exposure of buds from the shadow grid, and bud input Q = b·L^κ with
//! gravimorphism b = cos²τ + d·sin²τ (Longay 2014 eq. 4.2, 4.6).

use glam::Vec3;
use rayon::prelude::*;

use super::buds::TERMINAL;
use super::{Scratch, Tree};
use crate::environment::ShadowGrid;
use crate::species::{ControlEllipse, Species};

/// L = max(C − s + a, 0) at a node (all its buds share its voxel); [`super::buds::collect`]
/// stores it on every node with buds and on their buds.
pub(crate) fn exposure(s: &Species, shadow: &ShadowGrid, node_end: Vec3) -> f32 {
    (s.full_exposure - shadow.shadow_at(node_end) + s.shadow_strength).max(0.0)
}

/// Enables the buds that won at least one attraction point (step 2's end) and sets
/// Q = b·L^κ for them (0 for the others); returns how many are enabled.
pub(crate) fn bud_input(tree: &Tree, scratch: &mut Scratch) -> usize {
    let s = &tree.species;
    let nodes = &tree.skeleton.internodes;
    // On all threads, bud by bud (each bud's Q is its own; the count is an integer sum).
    scratch
        .buds
        .par_iter_mut()
        .zip(scratch.won.par_iter())
        .with_min_len(PARALLEL_BUDS)
        .map(|(bud, won)| {
            bud.enabled = won.count > 0;
            if !bud.enabled {
                bud.q = 0.0;
                return 0;
            }
            let b = if bud.slot == TERMINAL {
                1.0
            } else {
                gravimorphism(
                    &s.gravimorphism,
                    nodes[bud.node as usize].heading(),
                    bud.direction,
                )
            };
            bud.q = b * bud.light.powf(s.light_sensitivity);
            1
        })
        .sum()
}

/// Buds per block of the parallel bud-input pass.
const PARALLEL_BUDS: usize = 4096;

/// b = cos²τ + d·sin²τ: τ the angle between the parent axis H and the vertical, d the distance
/// from the axis to the control ellipse in the bud's polar direction χ (HVP frame).
pub fn gravimorphism(ellipse: &ControlEllipse, parent_heading: Vec3, bud_direction: Vec3) -> f32 {
    let h = parent_heading;
    let cos_tau = h.y.clamp(-1.0, 1.0);
    let sin2_tau = 1.0 - cos_tau * cos_tau;
    if sin2_tau < 1e-8 {
        return 1.0;
    }
    // V: most vertical direction ⟂ H; P = V × H, parallel to the ground.
    let Some(v) = (Vec3::Y - cos_tau * h).try_normalize() else {
        return 1.0;
    };
    let p = v.cross(h);
    let (cv, cp) = (bud_direction.dot(v), bud_direction.dot(p));
    let norm = (cv * cv + cp * cp).sqrt();
    if norm < 1e-6 {
        return 1.0;
    }
    let d = ellipse_distance(ellipse, cv / norm, cp / norm);
    cos_tau * cos_tau + d * sin2_tau
}

/// Distance from the axis (origin) to the ellipse along the unit direction (cos χ, sin χ) in
/// (V, P): the positive root of ((t·cos χ − e_v)/s_v)² + (t·sin χ/s_p)² = 1, or 0 if none.
fn ellipse_distance(e: &ControlEllipse, cos_chi: f32, sin_chi: f32) -> f32 {
    let (sv2, sp2) = (e.vertical_semi_axis.powi(2), e.parallel_semi_axis.powi(2));
    let a = cos_chi * cos_chi / sv2 + sin_chi * sin_chi / sp2;
    let b = -2.0 * cos_chi * e.vertical_offset / sv2;
    let c = e.vertical_offset * e.vertical_offset / sv2 - 1.0;
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || a <= 0.0 {
        return 0.0;
    }
    ((-b + disc.sqrt()) / (2.0 * a)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centred_unit_ellipse_is_neutral_and_an_upward_shift_favours_upper_buds() {
        let neutral = ControlEllipse {
            vertical_semi_axis: 1.0,
            parallel_semi_axis: 1.0,
            vertical_offset: 0.0,
        };
        let horizontal = Vec3::X;
        for dir in [Vec3::Y, Vec3::NEG_Y, Vec3::Z] {
            assert!((gravimorphism(&neutral, horizontal, dir) - 1.0).abs() < 1e-5);
        }
        let up = ControlEllipse {
            vertical_offset: 0.5,
            ..neutral
        };
        let upper = gravimorphism(&up, horizontal, Vec3::Y);
        let lower = gravimorphism(&up, horizontal, Vec3::NEG_Y);
        assert!(
            (upper - 1.5).abs() < 1e-5 && (lower - 0.5).abs() < 1e-5,
            "{upper} {lower}"
        );
        // A vertical axis shows no gravimorphism.
        assert!((gravimorphism(&up, Vec3::Y, Vec3::X) - 1.0).abs() < 1e-5);
    }
}
