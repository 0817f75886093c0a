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

/// The most bits a [`CellBits`] box holds (2 MiB); cells beyond go to its hash set.
const MAX_DENSE_BITS: i64 = 1 << 24;

/// A set of cells as one bit per cell of a box that grows to take new cells (with slack of
/// half its extent, at least 2 cells, on the side that overflows), so that asking for a cell
/// is an index and a bit test instead of a hash and a probe. Cells that would make the box
/// larger than [`MAX_DENSE_BITS`] (the far nodes of a damaged tree) are kept in a hash set
/// instead: the same set either way, bounded memory.
#[derive(Clone, Debug, Default)]
pub(crate) struct CellBits {
    lo: IVec3,
    /// Cells along each axis; zero while the box is empty.
    dims: IVec3,
    words: Vec<u64>,
    overflow: CellSet,
}

impl CellBits {
    /// An empty set whose box already holds `lo..=hi` (when that is not too large).
    pub(crate) fn with_box(lo: IVec3, hi: IVec3) -> CellBits {
        let mut bits = CellBits::default();
        if let Some(dims) = box_dims(lo, hi) {
            bits.lo = lo;
            bits.dims = dims;
            bits.words = vec![0; words_for(dims)];
        }
        bits
    }

    /// The bit of cell `c`, if inside the box.
    #[inline(always)]
    fn bit(&self, c: IVec3) -> Option<usize> {
        let o = IVec3::new(
            c.x.wrapping_sub(self.lo.x),
            c.y.wrapping_sub(self.lo.y),
            c.z.wrapping_sub(self.lo.z),
        );
        let (dx, dy, dz) = (self.dims.x as u32, self.dims.y as u32, self.dims.z as u32);
        if (o.x as u32) < dx && (o.y as u32) < dy && (o.z as u32) < dz {
            Some(o.x as usize + dx as usize * (o.y as usize + dy as usize * o.z as usize))
        } else {
            None
        }
    }

    /// Whether cell `c` is in the set.
    #[inline(always)]
    pub(crate) fn contains(&self, c: IVec3) -> bool {
        match self.bit(c) {
            Some(i) => self.words[i >> 6] >> (i & 63) & 1 != 0,
            None => !self.overflow.is_empty() && self.overflow.contains(&c),
        }
    }

    /// Adds cell `c`; true when it was not in the set.
    pub(crate) fn insert(&mut self, c: IVec3) -> bool {
        if self.bit(c).is_none() && !self.grow_to(c) {
            return self.overflow.insert(c);
        }
        let Some(i) = self.bit(c) else {
            return self.overflow.insert(c);
        };
        let (word, mask) = (&mut self.words[i >> 6], 1u64 << (i & 63));
        let new = *word & mask == 0;
        *word |= mask;
        new
    }

    /// Grows the box to hold `c` (with slack); false when it would be too large.
    fn grow_to(&mut self, c: IVec3) -> bool {
        let wide = |v: IVec3| [i64::from(v.x), i64::from(v.y), i64::from(v.z)];
        let (c, lo) = (wide(c), wide(self.lo));
        let empty = self.dims.cmpeq(IVec3::ZERO).any();
        let mut new_lo = [0i64; 3];
        let mut new_hi = [0i64; 3];
        for a in 0..3 {
            let dim = i64::from(self.dims[a]);
            if empty {
                (new_lo[a], new_hi[a]) = (c[a] - 2, c[a] + 2);
            } else {
                let hi = lo[a] + dim - 1;
                let slack = (dim / 2).max(2);
                new_lo[a] = if c[a] < lo[a] { c[a] - slack } else { lo[a] };
                new_hi[a] = if c[a] > hi { c[a] + slack } else { hi };
            }
            new_lo[a] = new_lo[a].max(i64::from(i32::MIN));
            new_hi[a] = new_hi[a].min(i64::from(i32::MAX));
        }
        let narrow = |v: [i64; 3]| IVec3::new(v[0] as i32, v[1] as i32, v[2] as i32);
        let (new_lo, new_hi) = (narrow(new_lo), narrow(new_hi));
        let Some(dims) = box_dims(new_lo, new_hi) else {
            return false;
        };
        let old = std::mem::replace(self, CellBits::with_box(new_lo, new_hi));
        debug_assert_eq!(self.dims, dims);
        for cell in old.iter_box() {
            self.set(cell);
        }
        for cell in old.overflow {
            if self.bit(cell).is_some() {
                self.set(cell);
            } else {
                self.overflow.insert(cell);
            }
        }
        true
    }

    fn set(&mut self, c: IVec3) {
        if let Some(i) = self.bit(c) {
            self.words[i >> 6] |= 1u64 << (i & 63);
        }
    }

    /// The cells of the box that are set.
    fn iter_box(&self) -> impl Iterator<Item = IVec3> + '_ {
        let (dx, dy) = (self.dims.x as usize, self.dims.y as usize);
        let lo = self.lo;
        self.words
            .iter()
            .enumerate()
            .flat_map(move |(w, &word)| {
                let mut rest = word;
                std::iter::from_fn(move || {
                    if rest == 0 {
                        return None;
                    }
                    let b = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    Some(w * 64 + b)
                })
            })
            .map(move |i| {
                let (x, y, z) = (i % dx, (i / dx) % dy, i / (dx * dy));
                lo + IVec3::new(x as i32, y as i32, z as i32)
            })
    }
}

/// The cells along each axis of the box `lo..=hi`, if it holds at most [`MAX_DENSE_BITS`].
fn box_dims(lo: IVec3, hi: IVec3) -> Option<IVec3> {
    let extent = |a: i32, b: i32| (i64::from(b) - i64::from(a) + 1).max(0);
    let (x, y, z) = (extent(lo.x, hi.x), extent(lo.y, hi.y), extent(lo.z, hi.z));
    let volume = x.checked_mul(y)?.checked_mul(z)?;
    (volume > 0 && volume <= MAX_DENSE_BITS).then_some(IVec3::new(x as i32, y as i32, z as i32))
}

fn words_for(dims: IVec3) -> usize {
    (dims.x as usize * dims.y as usize * dims.z as usize).div_ceil(64)
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
        let mut set = CellSet::default();
        assert!(set.insert(IVec3::new(1, -2, 3)));
        assert!(!set.insert(IVec3::new(1, -2, 3)));
        assert!(set.contains(&IVec3::new(1, -2, 3)) && !set.contains(&IVec3::new(3, -2, 1)));
    }

    #[test]
    fn cell_bits_hold_the_same_set_as_a_hash_set_wherever_the_cells_fall() {
        let mut rng = crate::Rng::new(3);
        let mut bits = CellBits::default();
        let mut set = CellSet::default();
        let far = IVec3::new(i32::MAX - 1, i32::MIN + 1, 7);
        for k in 0..3000 {
            // Mostly a growing cloud, now and then a far cell the box cannot take.
            let c = if k % 500 == 7 {
                far + IVec3::new(0, k, 0)
            } else {
                let spread = 2.0 + k as f32 * 0.02;
                (rng.in_unit_ball() * spread).floor().as_ivec3()
            };
            assert_eq!(bits.insert(c), set.insert(c), "{c}");
        }
        assert!(!bits.overflow.is_empty());
        for x in -70..70 {
            for y in -70..70 {
                let c = IVec3::new(x, y, x / 3 - y / 2);
                assert_eq!(bits.contains(c), set.contains(&c), "{c}");
            }
        }
        for c in &set {
            assert!(bits.contains(*c), "{c}");
        }
        assert!(!bits.contains(far + IVec3::new(1, 0, 0)));
    }
}
