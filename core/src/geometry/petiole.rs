//! The petiole model of Longay 2014, appendix C.1.2, integrated for one leaf or for four at
//! once.
//!
//! A petiole is an inextensible rod whose frame H, L, U turns at the rates
//! Ω_H = −e_H L·T (twist), Ω_L = e_L H·T (bend), Ω_U = e_U L·(T × (H × T)) (turn), integrated
//! in steps Δs; the blade at its end lies in the H–L plane. The steps of one leaf depend on
//! each other, so one leaf at a time waits on its divisions and square roots; the four-lane
//! path integrates four independent leaves side by side (`[f32; 4]` lanes that the compiler
//! turns into SIMD), with exactly the arithmetic of the one-leaf path, so both give the same
//! bits.

use glam::{Vec3, Vec4};

use super::LeafParams;
use super::any_perpendicular;
use super::lanes::V4;

/// Where a petiole starts: the point on the branch surface, the branch heading there, the unit
/// direction from the branch axis to the point, and the ambient light (which scales the rates).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Attachment {
    pub point: Vec3,
    pub heading: Vec3,
    pub radial: Vec3,
    pub light: f32,
}

/// A leaf blade: corners (base-left, base-right, tip-left, tip-right) and unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Blade {
    pub corners: [[f32; 3]; 4],
    pub normal: [f32; 3],
}

/// The constants of the petiole model and the blade, shared by every leaf.
pub(crate) struct Petiole {
    /// sin and cos of the insertion angle.
    sin_insertion: f32,
    cos_insertion: f32,
    steps: u32,
    /// Δs.
    step_length: f32,
    /// Tropism target T, unit.
    target: Vec3,
    /// e_H, e_L, e_U.
    twist_rate: f32,
    bend_rate: f32,
    turn_rate: f32,
    blade_length: f32,
    half_width: f32,
}

/// The components (a, b, c) of Ω·Δs/2 in the frame H, L, U, from H·T, L·T and L·H.
#[inline(always)]
fn rotation_components(petiole: &Petiole, h_t: f32, l_t: f32, l_h: f32, half: f32) -> [f32; 3] {
    // L·(T × (H × T)) = L·H − (L·T)(H·T) for unit T.
    [
        -petiole.twist_rate * l_t * half,
        petiole.bend_rate * h_t * half,
        petiole.turn_rate * (l_h - l_t * h_t) * half,
    ]
}

/// The new H and L coordinates, in the frame H, L, U, after the rotation by the quaternion
/// (w, 1) normalised, w = (a, b, c): v' = v + s·(w × v) + s·w × (w × v), s = 2/(1 + |w|²),
/// written out with H × L = U, L × U = H, U × H = L. No trigonometry: the angle
/// 2·atan(|Ω|Δs/2) equals |Ω|Δs to first order.
#[inline(always)]
fn rotated_frame([a, b, c]: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let s = 2.0 / (1.0 + a * a + b * b + c * c);
    (
        [1.0 - s * (b * b + c * c), s * (c + a * b), s * (a * c - b)],
        [s * (a * b - c), 1.0 - s * (a * a + c * c), s * (a + b * c)],
    )
}

impl Petiole {
    pub(crate) fn new(params: &LeafParams) -> Self {
        let (sin_insertion, cos_insertion) = params.insertion_angle.sin_cos();
        let steps = params.petiole_steps.max(1);
        Petiole {
            sin_insertion,
            cos_insertion,
            steps,
            step_length: params.petiole_length / steps as f32,
            target: Vec3::from(params.light_direction)
                .try_normalize()
                .unwrap_or(Vec3::Y),
            twist_rate: params.twist_rate,
            bend_rate: params.bend_rate,
            turn_rate: params.turn_rate,
            blade_length: params.length,
            half_width: 0.5 * params.width,
        }
    }

    /// The blade of one leaf.
    pub(crate) fn blade(&self, at: &Attachment) -> Blade {
        let mut h = at.heading * self.cos_insertion + at.radial * self.sin_insertion;
        let mut l = at
            .heading
            .cross(at.radial)
            .try_normalize()
            .unwrap_or_else(|| any_perpendicular(h));
        let ds = self.step_length;
        let half = 0.5 * at.light * ds;
        let mut position = at.point;
        for _ in 0..self.steps {
            let u = h.cross(l);
            let (h_t, l_t) = (h.dot(self.target), l.dot(self.target));
            let w = rotation_components(self, h_t, l_t, l.dot(h), half);
            let ([hh, hl, hu], [lh, ll, lu]) = rotated_frame(w);
            let next_h = h * hh + l * hl + u * hu;
            l = h * lh + l * ll + u * lu;
            h = next_h;
            position += h * ds;
        }
        let h = h.try_normalize().unwrap_or(at.heading);
        let l = (l - h * l.dot(h))
            .try_normalize()
            .unwrap_or_else(|| any_perpendicular(h));
        let half_width = l * self.half_width;
        let tip = position + h * self.blade_length;
        Blade {
            corners: [
                (position - half_width).to_array(),
                (position + half_width).to_array(),
                (tip - half_width).to_array(),
                (tip + half_width).to_array(),
            ],
            normal: h.cross(l).to_array(),
        }
    }

    /// The blades of four leaves, bit for bit as [`Petiole::blade`] gives them; `None` when a
    /// frame of one of them degenerates (then [`Petiole::blade`] handles each with its
    /// fallbacks).
    pub(crate) fn blades4(&self, at: &[Attachment; 4]) -> Option<[Blade; 4]> {
        let heading = V4::gather(at.map(|a| a.heading));
        let radial = V4::gather(at.map(|a| a.radial));
        let mut h = heading
            .scale(Vec4::splat(self.cos_insertion))
            .add(radial.scale(Vec4::splat(self.sin_insertion)));
        let mut l = heading.cross(radial).try_normalize()?;
        let target = V4::splat(self.target);
        let ds = Vec4::splat(self.step_length);
        let light = Vec4::new(at[0].light, at[1].light, at[2].light, at[3].light);
        let half = Vec4::splat(0.5) * light * ds;
        let (twist, bend, turn) = (
            Vec4::splat(-self.twist_rate),
            Vec4::splat(self.bend_rate),
            Vec4::splat(self.turn_rate),
        );
        let one = Vec4::ONE;
        let mut position = V4::gather(at.map(|a| a.point));
        for _ in 0..self.steps {
            let u = h.cross(l);
            let (h_t, l_t, l_h) = (h.dot(target), l.dot(target), l.dot(h));
            // rotation_components and rotated_frame in four lanes.
            let a = twist * l_t * half;
            let b = bend * h_t * half;
            let c = turn * (l_h - l_t * h_t) * half;
            let (aa, bb, cc) = (a * a, b * b, c * c);
            let s = Vec4::splat(2.0) / (one + aa + bb + cc);
            let next_h = h
                .scale(one - s * (bb + cc))
                .add(l.scale(s * (c + a * b)))
                .add(u.scale(s * (a * c - b)));
            l = h
                .scale(s * (a * b - c))
                .add(l.scale(one - s * (aa + cc)))
                .add(u.scale(s * (a + b * c)));
            h = next_h;
            position = position.add(h.scale(ds));
        }
        let h = h.try_normalize()?;
        let l = l.sub(h.scale(l.dot(h))).try_normalize()?;
        let half_width = l.scale(Vec4::splat(self.half_width));
        let tip = position.add(h.scale(Vec4::splat(self.blade_length)));
        let corners = [
            position.sub(half_width),
            position.add(half_width),
            tip.sub(half_width),
            tip.add(half_width),
        ];
        let normal = h.cross(l);
        let blade = |i: usize| Blade {
            corners: [
                corners[0].lane(i),
                corners[1].lane(i),
                corners[2].lane(i),
                corners[3].lane(i),
            ],
            normal: normal.lane(i),
        };
        Some([blade(0), blade(1), blade(2), blade(3)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::hash_unit;

    fn attachment(seed: u64) -> Attachment {
        let r = |k: u64| 2.0 * hash_unit(seed * 8 + k) - 1.0;
        let heading = Vec3::new(r(0), r(1), r(2)).normalize();
        let radial = any_perpendicular(heading);
        Attachment {
            point: Vec3::new(r(3), r(4), r(5)) * 3.0,
            heading,
            radial: (radial * r(6).cos() + heading.cross(radial) * r(6).sin()).normalize(),
            light: 0.5 + 0.5 * r(7),
        }
    }

    #[test]
    fn four_lane_blades_equal_one_leaf_blades_bit_for_bit() {
        let petiole = Petiole::new(&LeafParams::default());
        for group in 0..500 {
            let at: [Attachment; 4] = std::array::from_fn(|i| attachment(group * 4 + i as u64));
            let four = petiole.blades4(&at).expect("regular frames");
            for (one, blade) in at.iter().zip(four) {
                assert_eq!(petiole.blade(one), blade);
            }
        }
    }

    #[test]
    fn a_degenerate_attachment_sends_its_group_to_the_one_leaf_path() {
        let petiole = Petiole::new(&LeafParams::default());
        let mut at: [Attachment; 4] = std::array::from_fn(|i| attachment(i as u64));
        at[2].radial = at[2].heading;
        assert!(petiole.blades4(&at).is_none());
        let blade = petiole.blade(&at[2]);
        assert!(blade.corners.iter().flatten().all(|c| c.is_finite()));
        assert!((Vec3::from(blade.normal).length() - 1.0).abs() < 1e-4);
    }
}
