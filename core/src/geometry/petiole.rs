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

use glam::Vec3;

use super::LeafParams;
use super::any_perpendicular;

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
        let heading = V4::gather(at, |a| a.heading);
        let radial = V4::gather(at, |a| a.radial);
        let mut h = heading
            .scale1(self.cos_insertion)
            .add(radial.scale1(self.sin_insertion));
        let mut l = heading.cross(radial).try_normalize()?;
        let target = V4::splat(self.target);
        let ds = self.step_length;
        let half = lanes(|i| 0.5 * at[i].light * ds);
        let mut position = V4::gather(at, |a| a.point);
        for _ in 0..self.steps {
            let u = h.cross(l);
            let (h_t, l_t, l_h) = (h.dot(target), l.dot(target), l.dot(h));
            let mut frame = [[[0.0; 3]; 2]; 4];
            for (i, lane) in frame.iter_mut().enumerate() {
                let (new_h, new_l) =
                    rotated_frame(rotation_components(self, h_t[i], l_t[i], l_h[i], half[i]));
                *lane = [new_h, new_l];
            }
            let coefficient = |axis: usize, k: usize| lanes(|i| frame[i][axis][k]);
            let next_h = h
                .scale(coefficient(0, 0))
                .add(l.scale(coefficient(0, 1)))
                .add(u.scale(coefficient(0, 2)));
            l = h
                .scale(coefficient(1, 0))
                .add(l.scale(coefficient(1, 1)))
                .add(u.scale(coefficient(1, 2)));
            h = next_h;
            position = position.add(h.scale1(ds));
        }
        let h = h.try_normalize()?;
        let l = l.sub(h.scale(l.dot(h))).try_normalize()?;
        let half_width = l.scale1(self.half_width);
        let tip = position.add(h.scale1(self.blade_length));
        let corners = [
            position.sub(half_width),
            position.add(half_width),
            tip.sub(half_width),
            tip.add(half_width),
        ];
        let normal = h.cross(l);
        Some(std::array::from_fn(|i| Blade {
            corners: corners.map(|c| c.lane(i)),
            normal: normal.lane(i),
        }))
    }
}

type Lanes = [f32; 4];

#[inline(always)]
fn lanes(f: impl Fn(usize) -> f32) -> Lanes {
    std::array::from_fn(f)
}

/// Four vectors, one per lane, stored by component.
#[derive(Clone, Copy)]
struct V4 {
    x: Lanes,
    y: Lanes,
    z: Lanes,
}

/// The operations below repeat glam's `Vec3` arithmetic operation for operation, lane by lane.
impl V4 {
    #[inline(always)]
    fn gather(at: &[Attachment; 4], f: impl Fn(&Attachment) -> Vec3) -> V4 {
        let v: [Vec3; 4] = std::array::from_fn(|i| f(&at[i]));
        V4 {
            x: lanes(|i| v[i].x),
            y: lanes(|i| v[i].y),
            z: lanes(|i| v[i].z),
        }
    }

    #[inline(always)]
    fn splat(v: Vec3) -> V4 {
        V4 {
            x: [v.x; 4],
            y: [v.y; 4],
            z: [v.z; 4],
        }
    }

    #[inline(always)]
    fn lane(&self, i: usize) -> [f32; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }

    #[inline(always)]
    fn add(self, o: V4) -> V4 {
        V4 {
            x: lanes(|i| self.x[i] + o.x[i]),
            y: lanes(|i| self.y[i] + o.y[i]),
            z: lanes(|i| self.z[i] + o.z[i]),
        }
    }

    #[inline(always)]
    fn sub(self, o: V4) -> V4 {
        V4 {
            x: lanes(|i| self.x[i] - o.x[i]),
            y: lanes(|i| self.y[i] - o.y[i]),
            z: lanes(|i| self.z[i] - o.z[i]),
        }
    }

    #[inline(always)]
    fn scale(self, s: Lanes) -> V4 {
        V4 {
            x: lanes(|i| self.x[i] * s[i]),
            y: lanes(|i| self.y[i] * s[i]),
            z: lanes(|i| self.z[i] * s[i]),
        }
    }

    #[inline(always)]
    fn scale1(self, s: f32) -> V4 {
        self.scale([s; 4])
    }

    #[inline(always)]
    fn dot(self, o: V4) -> Lanes {
        lanes(|i| (self.x[i] * o.x[i]) + (self.y[i] * o.y[i]) + (self.z[i] * o.z[i]))
    }

    #[inline(always)]
    fn cross(self, o: V4) -> V4 {
        V4 {
            x: lanes(|i| self.y[i] * o.z[i] - o.y[i] * self.z[i]),
            y: lanes(|i| self.z[i] * o.x[i] - o.z[i] * self.x[i]),
            z: lanes(|i| self.x[i] * o.y[i] - o.x[i] * self.y[i]),
        }
    }

    /// glam's `try_normalize` in every lane; `None` when it fails in any.
    #[inline(always)]
    fn try_normalize(self) -> Option<V4> {
        let length = self.dot(self).map(f32::sqrt);
        let recip = length.map(|x| 1.0 / x);
        recip
            .iter()
            .all(|r| r.is_finite() && *r > 0.0)
            .then(|| self.scale(recip))
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
