//! A fast hash for the integer cells the garden keeps in sets (shade covers, contact cells,
//! index cells asked for). The standard library's SipHash guards maps against keys chosen by an
//! adversary; cells come from the trees' own nodes, and hashing them was a visible part of a
//! garden round. Every use only asks whether a cell is in the set or walks it to add up
//! integer sums or boolean tests, so the order the set keeps (like SipHash's random one)
//! changes nothing grown.

use std::collections::HashSet;
use std::hash::{BuildHasherDefault, Hasher};

use glam::IVec3;

/// Multiplier of the mix (2^64 divided by the golden ratio, odd).
const MIX: u64 = 0x9E37_79B9_7F4A_7C15;

/// Folds each integer written into one word by rotate, xor and multiply; `finish` folds the
/// 128-bit product of that word so the low bits (the bucket) depend on all of the key.
#[derive(Default, Clone, Copy)]
pub(crate) struct CellHasher(u64);

impl CellHasher {
    #[inline(always)]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(23) ^ word).wrapping_mul(MIX);
    }
}

impl Hasher for CellHasher {
    #[inline(always)]
    fn finish(&self) -> u64 {
        let wide = u128::from(self.0) * u128::from(MIX);
        (wide as u64) ^ ((wide >> 64) as u64)
    }

    #[inline(always)]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.add(u64::from(b));
        }
    }

    #[inline(always)]
    fn write_i32(&mut self, i: i32) {
        self.add(u64::from(i as u32));
    }

    #[inline(always)]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }
}

/// A set of cells hashed by [`CellHasher`].
pub(crate) type CellSet = HashSet<IVec3, BuildHasherDefault<CellHasher>>;

/// An empty [`CellSet`] with room for `n` cells.
pub(crate) fn cell_set_with_capacity(n: usize) -> CellSet {
    CellSet::with_capacity_and_hasher(n, BuildHasherDefault::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_cells_spread_over_the_low_bits() {
        let mut buckets = [0u32; 64];
        for x in -4..4 {
            for y in 0..4 {
                for z in -4..4 {
                    let h = std::hash::BuildHasher::hash_one(
                        &BuildHasherDefault::<CellHasher>::default(),
                        IVec3::new(x, y, z),
                    );
                    buckets[(h & 63) as usize] += 1;
                }
            }
        }
        // 256 cells in 64 buckets: 4 each on average; none may take a large share.
        assert!(buckets.iter().all(|&n| n <= 14), "{buckets:?}");
        let mut set = cell_set_with_capacity(4);
        assert!(set.insert(IVec3::new(1, -2, 3)));
        assert!(!set.insert(IVec3::new(1, -2, 3)));
        assert!(set.contains(&IVec3::new(1, -2, 3)) && !set.contains(&IVec3::new(3, -2, 1)));
    }
}
