//! A uniform grid over a set of points, rebuilt by counting sort: O(n + cells) to build, and a
//! radius query visits only the cells the query sphere overlaps. Used for attraction points,
//! buds and occupancy centres so space colonization is never O(points × buds).
//!
//! Buffers are kept between rebuilds: a steady-state growth iteration allocates nothing here.

use glam::{IVec3, Vec3};

/// At most this many cells per stored point (plus a constant): a sparse cloud gets bigger cells.
const MAX_CELLS_PER_POINT: usize = 4;
const MIN_CELL_BUDGET: usize = 4096;

#[derive(Clone, Debug, Default)]
pub struct SpatialGrid {
    origin: Vec3,
    cell_size: f32,
    inv_cell_size: f32,
    dims: IVec3,
    /// `cell_start[c]..cell_start[c + 1]` are the entries of cell `c`.
    cell_start: Vec<u32>,
    /// Original index of each entry, sorted by cell.
    entry_index: Vec<u32>,
    /// Position of each entry, sorted by cell (kept next to the index for cache-friendly scans).
    entry_position: Vec<Vec3>,
    cell_of: Vec<u32>,
}

impl SpatialGrid {
    /// Rebuilds the grid over `positions` with cells of at least `cell_size` metres.
    pub fn rebuild(&mut self, positions: &[Vec3], cell_size: f32) {
        self.entry_index.clear();
        self.entry_position.clear();
        self.cell_start.clear();
        self.cell_of.clear();
        if positions.is_empty() {
            self.dims = IVec3::ZERO;
            self.cell_start.push(0);
            return;
        }
        let (mut min, mut max) = (positions[0], positions[0]);
        for p in positions {
            min = min.min(*p);
            max = max.max(*p);
        }
        let extent = (max - min).max(Vec3::splat(1e-6));
        let budget = (positions.len() * MAX_CELLS_PER_POINT).max(MIN_CELL_BUDGET) as f32;
        let mut cell = cell_size.max(1e-6);
        // Enlarge cells until the dense cell array fits the budget.
        while ((extent / cell).floor() + Vec3::ONE).element_product() > budget {
            cell *= 1.5;
        }
        self.origin = min;
        self.cell_size = cell;
        self.inv_cell_size = 1.0 / cell;
        self.dims = ((extent * self.inv_cell_size).as_ivec3() + IVec3::ONE).max(IVec3::ONE);
        let num_cells = (self.dims.x * self.dims.y * self.dims.z) as usize;
        self.cell_start.resize(num_cells + 1, 0);
        for p in positions {
            let c = self.cell_index(self.cell_coord(*p));
            self.cell_of.push(c as u32);
            self.cell_start[c + 1] += 1;
        }
        for c in 0..num_cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.entry_index.resize(positions.len(), 0);
        self.entry_position.resize(positions.len(), Vec3::ZERO);
        // Fill each cell in input order (stable): the cursor is cell_start shifted by one.
        for (i, p) in positions.iter().enumerate() {
            let c = self.cell_of[i] as usize;
            let slot = self.cell_start[c] as usize;
            self.cell_start[c] += 1;
            self.entry_index[slot] = i as u32;
            self.entry_position[slot] = *p;
        }
        for c in (1..=num_cells).rev() {
            self.cell_start[c] = self.cell_start[c - 1];
        }
        self.cell_start[0] = 0;
    }

    pub fn len(&self) -> usize {
        self.entry_index.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entry_index.is_empty()
    }

    fn cell_coord(&self, p: Vec3) -> IVec3 {
        floor_to_ivec3((p - self.origin) * self.inv_cell_size)
            .clamp(IVec3::ZERO, self.dims - IVec3::ONE)
    }

    fn cell_index(&self, c: IVec3) -> usize {
        (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize
    }

    /// Calls `f(index, position, distance²)` for every stored point within `radius` of `center`,
    /// cell by cell and, within a cell, in input order (deterministic).
    pub fn for_each_within(&self, center: Vec3, radius: f32, mut f: impl FnMut(u32, Vec3, f32)) {
        self.scan(center, radius, |i, p, d2| {
            f(i, p, d2);
            false
        });
    }

    /// True when some stored point lies within `radius` of `center` (stops at the first).
    pub fn any_within(&self, center: Vec3, radius: f32) -> bool {
        self.scan(center, radius, |_, _, _| true)
    }

    /// Visits the points within `radius` until `f` returns true; returns whether it did.
    fn scan(&self, center: Vec3, radius: f32, mut f: impl FnMut(u32, Vec3, f32) -> bool) -> bool {
        if self.entry_index.is_empty() {
            return false;
        }
        let r2 = radius * radius;
        let lo = floor_to_ivec3((center - Vec3::splat(radius) - self.origin) * self.inv_cell_size);
        let hi = floor_to_ivec3((center + Vec3::splat(radius) - self.origin) * self.inv_cell_size);
        if hi.cmplt(IVec3::ZERO).any() || lo.cmpge(self.dims).any() {
            return false;
        }
        let lo = lo.max(IVec3::ZERO);
        let hi = hi.min(self.dims - IVec3::ONE);
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                let row = self.cell_index(IVec3::new(lo.x, y, z));
                let start = self.cell_start[row] as usize;
                let end = self.cell_start[row + (hi.x - lo.x) as usize + 1] as usize;
                // Cells along x are contiguous: one scan covers the whole row.
                for slot in start..end {
                    let p = self.entry_position[slot];
                    let d2 = p.distance_squared(center);
                    if d2 <= r2 && f(self.entry_index[slot], p, d2) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// ⌊v⌋ per component without a libm call (x86-64's baseline has no SSE4.1 `roundps`, so
/// `f32::floor` is a function call in the hot query loops). Saturates like `as`, NaN gives 0.
#[inline]
pub(crate) fn floor_to_ivec3(v: Vec3) -> IVec3 {
    let t = v.as_ivec3();
    t - IVec3::select(v.cmplt(t.as_vec3()), IVec3::ONE, IVec3::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn radius_queries_match_brute_force() {
        let mut rng = Rng::new(3);
        let points: Vec<Vec3> = (0..2000).map(|_| rng.in_unit_ball() * 5.0).collect();
        let mut grid = SpatialGrid::default();
        grid.rebuild(&points, 0.7);
        for _ in 0..200 {
            let center = rng.in_unit_ball() * 6.0;
            let radius = rng.range_f32(0.0, 2.0);
            let mut found = Vec::new();
            grid.for_each_within(center, radius, |i, _, _| found.push(i));
            found.sort_unstable();
            let expected: Vec<u32> = (0..points.len() as u32)
                .filter(|&i| points[i as usize].distance_squared(center) <= radius * radius)
                .collect();
            assert_eq!(found, expected);
        }
    }

    #[test]
    fn fast_floor_matches_floor() {
        for x in [-2.5f32, -2.0, -1e-7, 0.0, 1e-7, 0.999, 1.0, 3.5, -0.5] {
            let v = Vec3::new(x, -x, x * 3.0);
            assert_eq!(floor_to_ivec3(v), v.floor().as_ivec3(), "{v}");
        }
    }

    #[test]
    fn empty_and_single_point_grids_answer_queries() {
        let mut grid = SpatialGrid::default();
        grid.rebuild(&[], 1.0);
        assert!(!grid.any_within(Vec3::ZERO, 10.0));
        grid.rebuild(&[Vec3::ONE], 1.0);
        assert!(grid.any_within(Vec3::ZERO, 2.0));
        assert!(!grid.any_within(Vec3::ZERO, 1.0));
    }
}
