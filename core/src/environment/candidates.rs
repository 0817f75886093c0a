//! Points gathered from a [`SpatialGrid`] around one place ([`SpatialGrid::gather_near`]), as
//! parallel coordinate arrays padded to whole blocks of eight, so that the many queries made
//! there (nearest point, occupancy, points within reach) scan them in fixed-size blocks that the
//! compiler turns into packed arithmetic.

use glam::Vec3;

#[cfg(doc)]
use super::SpatialGrid;

/// Values per block of the scans.
const LANES: usize = 8;
/// Rows of at most this many entries are gathered by fixed-size copies.
pub(super) const SHORT_ROW: usize = 16;
/// Index of a padding entry (its coordinates are infinite: it is never within any radius).
const PADDING: u32 = u32::MAX;

/// Points gathered from a grid in its scan order, plus padding to a whole number of blocks.
#[derive(Clone, Debug, Default)]
pub struct Candidates {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    index: Vec<u32>,
    /// Distances² of the last nearest query, block by block.
    d2: Vec<f32>,
}

impl Candidates {
    pub(super) fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.index.clear();
    }

    /// Appends rows `start..start + n` of `coordinates` (x, y, z) and `index` (n ≤
    /// [`SHORT_ROW`], each holding `start + SHORT_ROW` values) by copying whole
    /// [`SHORT_ROW`]s and dropping the excess (inline moves, no library call).
    #[inline(always)]
    pub(super) fn push_rows(
        &mut self,
        coordinates: [&[f32]; 3],
        index: &[u32],
        start: usize,
        n: usize,
    ) {
        push_row(&mut self.x, coordinates[0], start, n);
        push_row(&mut self.y, coordinates[1], start, n);
        push_row(&mut self.z, coordinates[2], start, n);
        push_row(&mut self.index, index, start, n);
    }

    /// Appends whole rows of coordinates (x, y, z) and their indices.
    pub(super) fn extend_rows(&mut self, coordinates: [&[f32]; 3], index: &[u32]) {
        self.x.extend_from_slice(coordinates[0]);
        self.y.extend_from_slice(coordinates[1]);
        self.z.extend_from_slice(coordinates[2]);
        self.index.extend_from_slice(index);
    }

    /// Appends points given as positions, with their indices.
    pub(super) fn extend_positions(&mut self, positions: &[Vec3], index: &[u32]) {
        self.x.extend(positions.iter().map(|p| p.x));
        self.y.extend(positions.iter().map(|p| p.y));
        self.z.extend(positions.iter().map(|p| p.z));
        self.index.extend_from_slice(index);
    }

    /// Pads the arrays to a whole number of blocks with points at infinity.
    pub(super) fn pad(&mut self) {
        let padded = self.index.len().next_multiple_of(LANES);
        self.x.resize(padded, f32::INFINITY);
        self.y.resize(padded, f32::INFINITY);
        self.z.resize(padded, f32::INFINITY);
        self.index.resize(padded, PADDING);
    }

    /// Number of gathered points.
    pub fn len(&self) -> usize {
        let padding = self
            .index
            .iter()
            .rev()
            .take_while(|&&i| i == PADDING)
            .count();
        self.index.len() - padding
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The index of every gathered point, in scan order.
    pub fn indices(&self) -> &[u32] {
        &self.index[..self.len()]
    }

    /// The blocks of coordinates, eight values each.
    fn blocks(&self) -> impl Iterator<Item = (&[f32; LANES], &[f32; LANES], &[f32; LANES])> {
        self.x
            .as_chunks::<LANES>()
            .0
            .iter()
            .zip(self.y.as_chunks::<LANES>().0)
            .zip(self.z.as_chunks::<LANES>().0)
            .map(|((x, y), z)| (x, y, z))
    }

    /// For a query centre inside the box the points were gathered around (within the radius
    /// they were gathered for): true when some gathered point lies within `radius` of `center`,
    /// with distances computed exactly as the grid computes them (so the answer is
    /// [`SpatialGrid::any_within`]'s).
    pub fn any_within(&self, center: Vec3, radius: f32) -> bool {
        let r2 = radius * radius;
        self.blocks().any(|(x, y, z)| {
            let mut hit = false;
            for k in 0..LANES {
                hit |= distance2(x[k], y[k], z[k], center) <= r2;
            }
            hit
        })
    }

    /// For a query centre inside the box the points were gathered around (within the radius
    /// they were gathered for): calls `f(index, position, distance²)` for every gathered point
    /// within `radius` of `center`, in scan order, with distances computed exactly as the grid
    /// computes them (so the calls are [`SpatialGrid::for_each_within`]'s). The distances of a
    /// block are computed together, then its points within reach are handed over one by one.
    pub fn for_each_within(&self, center: Vec3, radius: f32, mut f: impl FnMut(u32, Vec3, f32)) {
        let r2 = radius * radius;
        for (b, (x, y, z)) in self.blocks().enumerate() {
            let mut d2 = [0.0; LANES];
            let mut within = false;
            for k in 0..LANES {
                d2[k] = distance2(x[k], y[k], z[k], center);
                within |= d2[k] <= r2;
            }
            if !within {
                continue;
            }
            for (k, &d) in d2.iter().enumerate() {
                if d <= r2 {
                    let j = b * LANES + k;
                    f(self.index[j], Vec3::new(x[k], y[k], z[k]), d);
                }
            }
        }
    }

    /// For a query centre inside the box the points were gathered around (within the radius
    /// they were gathered for): the nearest point within `radius` of `center` that
    /// `accept(index, position, distance²)` takes (it returns what to report), with its
    /// distance²; among equally near points the first that [`SpatialGrid::for_each_within`]
    /// visits. Distances are computed exactly as the grid computes them.
    pub fn nearest_accepted<T>(
        &mut self,
        center: Vec3,
        radius: f32,
        mut accept: impl FnMut(u32, Vec3, f32) -> Option<T>,
    ) -> Option<(T, f32)> {
        let r2 = radius * radius;
        // Every block of distances is written below: only the length needs setting.
        self.d2.resize(self.index.len(), f32::INFINITY);
        // The distances, stored block by block with each lane's smallest.
        let mut lanes = [f32::INFINITY; LANES];
        let blocks = self.x.as_chunks::<LANES>().0.iter();
        let blocks = blocks
            .zip(self.y.as_chunks::<LANES>().0)
            .zip(self.z.as_chunks::<LANES>().0)
            .zip(self.d2.as_chunks_mut::<LANES>().0);
        for (((x, y), z), d2) in blocks {
            let mut block = [0.0; LANES];
            for k in 0..LANES {
                block[k] = distance2(x[k], y[k], z[k], center);
            }
            for k in 0..LANES {
                lanes[k] = if block[k] < lanes[k] {
                    block[k]
                } else {
                    lanes[k]
                };
            }
            *d2 = block;
        }
        let mut nearest = lanes_min(&lanes);
        loop {
            if nearest > r2 || nearest == f32::INFINITY {
                return None;
            }
            // The first point that near (ties go to the first in scan order).
            let j = first_equal(&self.d2, nearest)?;
            let p = Vec3::new(self.x[j], self.y[j], self.z[j]);
            if let Some(found) = accept(self.index[j], p, nearest) {
                return Some((found, nearest));
            }
            // Refused: never the nearest again.
            self.d2[j] = f32::INFINITY;
            let mut lanes = [f32::INFINITY; LANES];
            for d2 in self.d2.as_chunks::<LANES>().0 {
                for k in 0..LANES {
                    lanes[k] = if d2[k] < lanes[k] { d2[k] } else { lanes[k] };
                }
            }
            nearest = lanes_min(&lanes);
        }
    }
}

/// (p − c)·(p − c), summed as glam's `distance_squared` sums it.
#[inline(always)]
fn distance2(x: f32, y: f32, z: f32, c: Vec3) -> f32 {
    let (dx, dy, dz) = (x - c.x, y - c.y, z - c.z);
    dx * dx + dy * dy + dz * dz
}

/// The first index of `values` (whole blocks) holding `value`, a block at a time.
fn first_equal(values: &[f32], value: f32) -> Option<usize> {
    let blocks = values.as_chunks::<LANES>().0;
    let b = blocks.iter().position(|block| {
        let mut equal = false;
        for &d in block {
            equal |= d == value;
        }
        equal
    })?;
    let k = blocks[b].iter().position(|&d| d == value)?;
    Some(b * LANES + k)
}

/// The smallest of the lanes (∞ for none; NaNs ignored).
fn lanes_min(lanes: &[f32; LANES]) -> f32 {
    lanes
        .iter()
        .fold(f32::INFINITY, |m, &d| if d < m { d } else { m })
}

/// Appends `from[start..start + n]` to `out` (n ≤ [`SHORT_ROW`], `from` holding
/// `start + SHORT_ROW` values) by copying a whole [`SHORT_ROW`] and dropping the excess.
#[inline(always)]
fn push_row<T: Copy>(out: &mut Vec<T>, from: &[T], start: usize, n: usize) {
    let row: &[T; SHORT_ROW] = from[start..start + SHORT_ROW]
        .try_into()
        .unwrap_or_else(|_| unreachable!());
    let len = out.len() + n;
    out.extend_from_slice(row);
    out.truncate(len);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::SpatialGrid;
    use crate::rng::Rng;

    /// `count` query centres in the box `lo..=hi`: its low corner, then random points inside.
    fn centres_in(rng: &mut Rng, lo: Vec3, hi: Vec3, count: usize) -> Vec<Vec3> {
        (0..count)
            .map(|k| {
                let t = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                if k == 0 { lo } else { lo + (hi - lo) * t }
            })
            .collect()
    }

    /// The first strictly nearest accepted point in the grid's scan order (the reference).
    fn first_nearest_accepted(
        grid: &SpatialGrid,
        center: Vec3,
        radius: f32,
        accept: impl Fn(u32, Vec3, f32) -> Option<u32>,
    ) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        grid.for_each_within(center, radius, |i, p, d2| {
            if best.is_none_or(|(_, bd)| d2 < bd)
                && let Some(found) = accept(i, p, d2)
            {
                best = Some((found, d2));
            }
        });
        best
    }

    #[test]
    fn gathered_candidates_answer_nearest_queries_like_the_grid() {
        let mut rng = Rng::new(13);
        let mut points: Vec<Vec3> = (0..3000).map(|_| rng.in_unit_ball() * 2.0).collect();
        for i in 0..300 {
            points.push(Vec3::new((i % 6) as f32, (i / 6 % 5) as f32, (i / 30) as f32) * 0.2);
        }
        let mut grid = SpatialGrid::default();
        grid.rebuild(&points, 0.2);
        // Gathers from a grid that keeps positions by coordinate and from one that does not.
        let mut by_coordinate = SpatialGrid::default();
        by_coordinate.rebuild_for_gathers(&points, 0.2);
        let mut candidates = Candidates::default();
        for q in 0..200 {
            let radius = rng.range_f32(0.05, 0.5);
            // Every fourth query box starts between lattice points (exact distance ties).
            let lo = if q % 4 == 0 {
                Vec3::new((q % 5) as f32, (q % 4) as f32, (q % 7) as f32) * 0.2 + Vec3::splat(0.1)
            } else {
                rng.in_unit_ball() * 2.0
            };
            let hi = lo + Vec3::splat(rng.range_f32(0.0, 0.4));
            [&grid, &by_coordinate][q % 2].gather_near(lo, hi, radius, &mut candidates);
            for center in centres_in(&mut rng, lo, hi, 5) {
                let accept = |i: u32, _: Vec3, _: f32| (i % 3 != 1).then_some(i);
                assert_eq!(
                    candidates.nearest_accepted(center, radius, accept),
                    first_nearest_accepted(&grid, center, radius, accept),
                );
            }
        }
    }

    #[test]
    fn gathered_candidates_answer_occupancy_queries_like_the_grid() {
        let mut rng = Rng::new(17);
        let mut points: Vec<Vec3> = (0..2000).map(|_| rng.in_unit_ball() * 2.0).collect();
        // Points exactly at the query radius from lattice centres (boundary cases).
        for i in 0..50 {
            points.push(Vec3::new(i as f32 * 0.1, 0.25, 0.0));
        }
        let mut grid = SpatialGrid::default();
        grid.rebuild(&points, 0.3);
        // Gathers from a grid that keeps positions by coordinate and from one that does not.
        let mut by_coordinate = SpatialGrid::default();
        by_coordinate.rebuild_for_gathers(&points, 0.3);
        let mut candidates = Candidates::default();
        let (mut inside, mut outside) = (0, 0);
        for q in 0..300 {
            let radius = if q % 3 == 0 {
                0.25
            } else {
                rng.range_f32(0.01, 0.4)
            };
            let lo = if q % 3 == 0 {
                Vec3::new((q % 40) as f32 * 0.1, 0.0, 0.0)
            } else {
                rng.in_unit_ball() * 2.5
            };
            let hi = lo + Vec3::splat(rng.range_f32(0.0, 0.3));
            [&grid, &by_coordinate][q % 2].gather_near(lo, hi, radius, &mut candidates);
            for center in centres_in(&mut rng, lo, hi, 4) {
                let expected = grid.any_within(center, radius);
                assert_eq!(
                    candidates.any_within(center, radius),
                    expected,
                    "{center} {radius}"
                );
                if expected {
                    inside += 1;
                } else {
                    outside += 1;
                }
            }
        }
        assert!(inside > 100 && outside > 100, "{inside} {outside}");
    }

    #[test]
    fn gathered_candidates_visit_the_points_within_reach_like_the_grid() {
        let mut rng = Rng::new(23);
        let points: Vec<Vec3> = (0..2500).map(|_| rng.in_unit_ball() * 2.0).collect();
        let mut grid = SpatialGrid::default();
        grid.rebuild_for_gathers(&points, 0.3);
        let mut candidates = Candidates::default();
        let mut visited = 0;
        for _ in 0..100 {
            let lo = rng.in_unit_ball() * 2.2;
            let hi = lo + Vec3::splat(rng.range_f32(0.0, 0.3));
            let radius = rng.range_f32(0.05, 0.6);
            grid.gather_near(lo, hi, radius, &mut candidates);
            for center in centres_in(&mut rng, lo, hi, 3) {
                let (mut expected, mut got) = (Vec::new(), Vec::new());
                grid.for_each_within(center, radius, |i, p, d2| expected.push((i, p, d2)));
                candidates.for_each_within(center, radius, |i, p, d2| got.push((i, p, d2)));
                visited += got.len();
                assert_eq!(got, expected);
            }
        }
        assert!(visited > 1000, "{visited}");
    }
}
