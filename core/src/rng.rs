//! The one source of randomness in a tree: a PCG32 generator whose state is saved with the tree.
//!
//! Written here rather than taken from a crate so that its output sequence, and so every saved
//! tree, can never change under a dependency update: byte-identical saves are a promise of the
//! file format.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// PCG-XSH-RR 32-bit output, 64-bit state (O'Neill 2014).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rng {
    state: u64,
    increment: u64,
}

const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

impl Rng {
    /// A generator for `seed`; different seeds give independent-looking streams.
    pub fn new(seed: u64) -> Self {
        let mut rng = Rng {
            state: 0,
            increment: (seed.rotate_left(17) ^ 0xda3e_39cb_94b9_5bdb) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// A generator derived from this one for an independent purpose (e.g. one per tree).
    pub fn fork(&mut self) -> Self {
        let seed = (u64::from(self.next_u32()) << 32) | u64::from(self.next_u32());
        Rng::new(seed)
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULTIPLIER).wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Skips `delta` outputs: the generator is then where `delta` calls of
    /// [`Rng::next_u32`] would have left it (O(log delta) steps, PCG's jump-ahead by
    /// squaring the affine step; Brown 1994). Lets several threads draw consecutive parts of
    /// one stream, each from where its part starts.
    pub fn advance(&mut self, mut delta: u64) {
        let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
        let (mut cur_mult, mut cur_plus) = (MULTIPLIER, self.increment);
        while delta > 0 {
            if delta & 1 == 1 {
                acc_mult = acc_mult.wrapping_mul(cur_mult);
                acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
            }
            cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
            cur_mult = cur_mult.wrapping_mul(cur_mult);
            delta >>= 1;
        }
        self.state = acc_mult.wrapping_mul(self.state).wrapping_add(acc_plus);
    }

    /// Uniform in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in [lo, hi).
    pub fn range_f32(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }

    /// Uniform integer in [0, n); 0 when n == 0.
    pub fn below(&mut self, n: u32) -> u32 {
        if n == 0 {
            return 0;
        }
        ((u64::from(self.next_u32()) * u64::from(n)) >> 32) as u32
    }

    /// Uniform point in the unit ball (rejection sampling).
    pub fn in_unit_ball(&mut self) -> Vec3 {
        loop {
            let p = Vec3::new(
                self.range_f32(-1.0, 1.0),
                self.range_f32(-1.0, 1.0),
                self.range_f32(-1.0, 1.0),
            );
            if p.length_squared() <= 1.0 {
                return p;
            }
        }
    }

    /// Uniform direction on the unit sphere.
    pub fn unit_vector(&mut self) -> Vec3 {
        loop {
            let p = self.in_unit_ball();
            if let Some(n) = p.try_normalize() {
                return n;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_gives_same_stream_and_other_seed_differs() {
        let mut a = Rng::new(7);
        let mut b = Rng::new(7);
        let mut c = Rng::new(8);
        let sa: Vec<u32> = (0..16).map(|_| a.next_u32()).collect();
        let sb: Vec<u32> = (0..16).map(|_| b.next_u32()).collect();
        let sc: Vec<u32> = (0..16).map(|_| c.next_u32()).collect();
        assert_eq!(sa, sb);
        assert_ne!(sa, sc);
    }

    #[test]
    fn advancing_skips_exactly_as_many_outputs_as_drawing_them() {
        for delta in [0u64, 1, 2, 3, 7, 64, 1000, 12_345] {
            let mut drawn = Rng::new(99);
            let mut skipped = drawn.clone();
            for _ in 0..delta {
                drawn.next_u32();
            }
            skipped.advance(delta);
            assert_eq!(skipped, drawn, "delta {delta}");
            assert_eq!(skipped.next_u32(), drawn.next_u32());
        }
    }

    #[test]
    fn floats_stay_in_unit_interval_and_balls_in_ball() {
        let mut rng = Rng::new(1);
        for _ in 0..10_000 {
            let x = rng.next_f32();
            assert!((0.0..1.0).contains(&x));
            assert!(rng.in_unit_ball().length() <= 1.0 + 1e-6);
            assert!(rng.below(5) < 5);
        }
    }
}
