//! A uniform grid over a set of points, rebuilt by counting sort: O(n + cells) to build, and a
//! radius query visits only the cells the query sphere overlaps. Used for attraction points,
//! buds and occupancy centres so space colonization is never O(points × buds).
//!
//! Buffers are kept between rebuilds: a steady-state growth iteration allocates nothing here.

use glam::{IVec3, Vec3};

/// At most this many cells per stored point (plus a constant): a sparse cloud gets bigger cells.
const MAX_CELLS_PER_POINT: usize = 4;
const MIN_CELL_BUDGET: usize = 4096;

/// Empties `v` with room for `n` values. A buffer too small is replaced (with a quarter more
/// room) rather than grown: growing would copy contents that are about to be overwritten, into
/// memory that is fresh either way.
pub(crate) fn clear_with_room<T>(v: &mut Vec<T>, n: usize) {
    v.clear();
    if v.capacity() < n {
        *v = Vec::with_capacity(n + n / 4);
    }
}

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
    /// The same positions by coordinate, for gathering whole rows at once (empty unless the
    /// grid was built by [`SpatialGrid::rebuild_for_gathers`]).
    entry_x: Vec<f32>,
    entry_y: Vec<f32>,
    entry_z: Vec<f32>,
    cell_of: Vec<u32>,
}

impl SpatialGrid {
    /// Rebuilds the grid over `positions` with cells of at least `cell_size` metres.
    pub fn rebuild(&mut self, positions: &[Vec3], cell_size: f32) {
        self.rebuild_with(positions, cell_size, false);
    }

    /// [`SpatialGrid::rebuild`] for a grid queried mostly by [`SpatialGrid::gather_box`]: it
    /// also keeps the positions by coordinate, so that gathers copy whole rows of each.
    pub fn rebuild_for_gathers(&mut self, positions: &[Vec3], cell_size: f32) {
        self.rebuild_with(positions, cell_size, true);
    }

    fn rebuild_with(&mut self, positions: &[Vec3], cell_size: f32, by_coordinate: bool) {
        let n = positions.len();
        clear_with_room(&mut self.entry_index, n);
        clear_with_room(&mut self.entry_position, n);
        let coordinates = if by_coordinate { n } else { 0 };
        clear_with_room(&mut self.entry_x, coordinates);
        clear_with_room(&mut self.entry_y, coordinates);
        clear_with_room(&mut self.entry_z, coordinates);
        self.cell_start.clear();
        clear_with_room(&mut self.cell_of, n);
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
        clear_with_room(&mut self.cell_start, num_cells + 1);
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
        if by_coordinate {
            self.entry_x.extend(self.entry_position.iter().map(|p| p.x));
            self.entry_y.extend(self.entry_position.iter().map(|p| p.y));
            self.entry_z.extend(self.entry_position.iter().map(|p| p.z));
        }
        for c in (1..=num_cells).rev() {
            self.cell_start[c] = self.cell_start[c - 1];
        }
        self.cell_start[0] = 0;
    }

    pub fn len(&self) -> usize {
        self.entry_index.len()
    }

    /// Keeps only the entries whose original index `keep` accepts, in place: the cells, and the
    /// order of the kept entries within them, stay as they were.
    pub fn retain(&mut self, keep: impl Fn(u32) -> bool) {
        let by_coordinate = self.has_coordinates();
        let mut write = 0;
        let mut start = 0;
        for c in 0..self.cell_start.len().saturating_sub(1) {
            let end = self.cell_start[c + 1] as usize;
            self.cell_start[c] = write as u32;
            for read in start..end {
                if keep(self.entry_index[read]) {
                    self.entry_index[write] = self.entry_index[read];
                    self.entry_position[write] = self.entry_position[read];
                    if by_coordinate {
                        self.entry_x[write] = self.entry_x[read];
                        self.entry_y[write] = self.entry_y[read];
                        self.entry_z[write] = self.entry_z[read];
                    }
                    write += 1;
                }
            }
            start = end;
        }
        if let Some(last) = self.cell_start.last_mut() {
            *last = write as u32;
        }
        self.entry_index.truncate(write);
        self.entry_position.truncate(write);
        self.entry_x.truncate(write);
        self.entry_y.truncate(write);
        self.entry_z.truncate(write);
    }

    pub fn is_empty(&self) -> bool {
        self.entry_index.is_empty()
    }

    /// The original index of every entry, slot by slot (cell by cell, input order within a
    /// cell).
    pub fn entry_indices(&self) -> &[u32] {
        &self.entry_index
    }

    /// Renumbers the entries by slot: entry s, the s-th in [`SpatialGrid::entry_indices`]
    /// order, is reported as index s from now on (for a caller that reordered its own data the
    /// same way). Positions, cells and scan order stay as they were.
    pub fn number_entries_by_slot(&mut self) {
        for (slot, index) in self.entry_index.iter_mut().enumerate() {
            *index = slot as u32;
        }
    }

    /// Whether the positions are also kept by coordinate ([`SpatialGrid::rebuild_for_gathers`]).
    fn has_coordinates(&self) -> bool {
        self.entry_x.len() == self.entry_index.len()
    }

    /// Every stored point as (index, position), cell by cell: neighbours in space come close
    /// together, so queries made in this order reuse cached cells.
    pub fn entries(&self) -> impl Iterator<Item = (u32, Vec3)> + '_ {
        self.entry_index
            .iter()
            .copied()
            .zip(self.entry_position.iter().copied())
    }

    fn cell_coord(&self, p: Vec3) -> IVec3 {
        floor_to_ivec3((p - self.origin) * self.inv_cell_size)
            .clamp(IVec3::ZERO, self.dims - IVec3::ONE)
    }

    /// The stored points cell by cell: each non-empty cell's indices and positions (in input
    /// order).
    pub fn cells(&self) -> impl Iterator<Item = (&[u32], &[Vec3])> + '_ {
        self.cell_start.windows(2).filter_map(|w| {
            let (start, end) = (w[0] as usize, w[1] as usize);
            (start < end).then(|| {
                (
                    &self.entry_index[start..end],
                    &self.entry_position[start..end],
                )
            })
        })
    }

    /// Gathers, in scan order, every stored point in the cells that overlap the box `lo..=hi`
    /// (a superset of the points within the box) into `out`, replacing its contents.
    pub fn gather_box(&self, lo: Vec3, hi: Vec3, out: &mut Candidates) {
        out.clear();
        let Some((lo, hi)) = self.cell_range(lo, hi) else {
            return;
        };
        let by_coordinate = self.has_coordinates();
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                let slots = self.row_slots(y, z, lo.x, hi.x);
                let n = slots.len();
                if by_coordinate && n <= SHORT_ROW && slots.start + SHORT_ROW <= self.len() {
                    // A short row: fixed-size copies (inline moves, no library call), the
                    // entries copied past the row's end dropped again.
                    push_row(&mut out.x, &self.entry_x, slots.start, n);
                    push_row(&mut out.y, &self.entry_y, slots.start, n);
                    push_row(&mut out.z, &self.entry_z, slots.start, n);
                    push_row(&mut out.index, &self.entry_index, slots.start, n);
                    continue;
                }
                if by_coordinate {
                    out.x.extend_from_slice(&self.entry_x[slots.clone()]);
                    out.y.extend_from_slice(&self.entry_y[slots.clone()]);
                    out.z.extend_from_slice(&self.entry_z[slots.clone()]);
                } else {
                    let row = &self.entry_position[slots.clone()];
                    out.x.extend(row.iter().map(|p| p.x));
                    out.y.extend(row.iter().map(|p| p.y));
                    out.z.extend(row.iter().map(|p| p.z));
                }
                out.index.extend_from_slice(&self.entry_index[slots]);
            }
        }
    }

    /// The slots of cells `x0..=x1` of the row (`y`, `z`): cells along x are contiguous, so one
    /// range covers them, in increasing order.
    #[inline]
    fn row_slots(&self, y: i32, z: i32, x0: i32, x1: i32) -> std::ops::Range<usize> {
        let row = self.cell_index(IVec3::new(x0, y, z));
        self.cell_start[row] as usize..self.cell_start[row + (x1 - x0) as usize + 1] as usize
    }

    fn cell_index(&self, c: IVec3) -> usize {
        (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize
    }

    /// Calls `f(index, position, distance²)` for every stored point within `radius` of `center`,
    /// cell by cell and, within a cell, in input order (deterministic).
    pub fn for_each_within(&self, center: Vec3, radius: f32, mut f: impl FnMut(u32, Vec3, f32)) {
        let reach = Vec3::splat(radius);
        self.scan_box(
            center,
            radius,
            center - reach,
            center + reach,
            |slot, p, d2| {
                f(self.entry_index[slot], p, d2);
                false
            },
        );
    }

    /// [`SpatialGrid::for_each_within`] limited to the cells that overlap the box `lo..=hi`
    /// (world coordinates): the same calls in the same order, except for points in cells
    /// outside the box, which the caller knows it does not need.
    pub fn for_each_within_box(
        &self,
        center: Vec3,
        radius: f32,
        lo: Vec3,
        hi: Vec3,
        mut f: impl FnMut(u32, Vec3, f32),
    ) {
        let reach = Vec3::splat(radius);
        let (lo, hi) = (lo.max(center - reach), hi.min(center + reach));
        self.scan_box(center, radius, lo, hi, |slot, p, d2| {
            f(self.entry_index[slot], p, d2);
            false
        });
    }

    /// True when some stored point lies within `radius` of `center` (stops at the first).
    pub fn any_within(&self, center: Vec3, radius: f32) -> bool {
        let mut found = false;
        let reach = Vec3::splat(radius);
        self.scan_box(center, radius, center - reach, center + reach, |_, _, _| {
            found = true;
            true
        });
        found
    }

    /// The cells that the box `lo..=hi` (world coordinates) overlaps, clamped to the grid, or
    /// `None` when it misses the grid or the grid is empty.
    #[inline]
    fn cell_range(&self, lo: Vec3, hi: Vec3) -> Option<(IVec3, IVec3)> {
        if self.entry_index.is_empty() {
            return None;
        }
        let lo = floor_to_ivec3((lo - self.origin) * self.inv_cell_size);
        let hi = floor_to_ivec3((hi - self.origin) * self.inv_cell_size);
        if hi.cmplt(IVec3::ZERO).any() || lo.cmpge(self.dims).any() {
            return None;
        }
        Some((lo.max(IVec3::ZERO), hi.min(self.dims - IVec3::ONE)))
    }

    /// Visits the points within `radius` cell by cell (z, then y, then x: increasing slots) until
    /// `f(slot, position, distance²)` returns true. Rows of cells that the sphere misses are
    /// skipped and every row is trimmed to the cells its slice of the sphere overlaps (with a
    /// margin for rounding, so no point within `radius` is ever left out).
    #[inline]
    fn scan_box(
        &self,
        center: Vec3,
        radius: f32,
        lo: Vec3,
        hi: Vec3,
        mut f: impl FnMut(usize, Vec3, f32) -> bool,
    ) {
        let Some((lo, hi)) = self.cell_range(lo, hi) else {
            return;
        };
        let r2 = radius * radius;
        // In cell units: the centre, and the radius grown by the rounding margin.
        let c = (center - self.origin) * self.inv_cell_size;
        let reach = radius * self.inv_cell_size + CELL_MARGIN;
        let reach2 = reach * reach;
        for z in lo.z..=hi.z {
            let gz = axis_gap(c.z, z);
            for y in lo.y..=hi.y {
                let gy = axis_gap(c.y, y);
                let g2 = gy * gy + gz * gz;
                if g2 > reach2 {
                    continue;
                }
                let half = (reach2 - g2).sqrt();
                let x0 = lo.x.max((c.x - half) as i32);
                let x1 = hi.x.min((c.x + half) as i32);
                if x0 > x1 {
                    continue;
                }
                for slot in self.row_slots(y, z, x0, x1) {
                    let p = self.entry_position[slot];
                    let d2 = p.distance_squared(center);
                    if d2 <= r2 && f(slot, p, d2) {
                        return;
                    }
                }
            }
        }
    }
}

/// Rows of at most this many entries are gathered by fixed-size copies.
const SHORT_ROW: usize = 16;

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

/// Slack of row trimming in cells: far more than the rounding of a cell coordinate.
const CELL_MARGIN: f32 = 1e-3;

/// Distance (in cells) from coordinate `c` to cell `i`'s interval [i, i + 1] along one axis.
#[inline]
fn axis_gap(c: f32, i: i32) -> f32 {
    let i = i as f32;
    (i - c).max(c - (i + 1.0)).max(0.0)
}

/// ⌊v⌋ per component without a libm call (x86-64's baseline has no SSE4.1 `roundps`, so
/// `f32::floor` is a function call in the hot query loops). Saturates like `as`, NaN gives 0.
#[inline]
pub(crate) fn floor_to_ivec3(v: Vec3) -> IVec3 {
    let t = v.as_ivec3();
    t - IVec3::select(v.cmplt(t.as_vec3()), IVec3::ONE, IVec3::ZERO)
}

/// Points gathered from a grid in its scan order ([`SpatialGrid::gather_box`]) as parallel
/// arrays, so that many nearest-point queries around one place scan them linearly.
#[derive(Clone, Debug, Default)]
pub struct Candidates {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    index: Vec<u32>,
    d2: Vec<f32>,
}

impl Candidates {
    fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.index.clear();
    }

    pub fn len(&self) -> usize {
        self.index.len()
    }

    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }

    /// For a query whose sphere lies inside the gathered box: true when some gathered point lies
    /// within `radius` of `center`, with distances computed exactly as the grid computes them
    /// (so the answer is [`SpatialGrid::any_within`]'s).
    pub fn any_within(&self, center: Vec3, radius: f32) -> bool {
        const LANES: usize = 8;
        let r2 = radius * radius;
        let mut lanes = [f32::INFINITY; LANES];
        let (xs, ys, zs) = (
            self.x.chunks_exact(LANES),
            self.y.chunks_exact(LANES),
            self.z.chunks_exact(LANES),
        );
        let tail = (xs.remainder(), ys.remainder(), zs.remainder());
        for ((x, y), z) in xs.zip(ys).zip(zs) {
            for k in 0..LANES {
                // (p − c)·(p − c), as glam's `distance_squared` sums it.
                let (dx, dy, dz) = (x[k] - center.x, y[k] - center.y, z[k] - center.z);
                let d2 = dx * dx + dy * dy + dz * dz;
                lanes[k] = if d2 < lanes[k] { d2 } else { lanes[k] };
            }
        }
        for (((m, &x), &y), &z) in lanes.iter_mut().zip(tail.0).zip(tail.1).zip(tail.2) {
            let (dx, dy, dz) = (x - center.x, y - center.y, z - center.z);
            let d2 = dx * dx + dy * dy + dz * dz;
            *m = if d2 < *m { d2 } else { *m };
        }
        lanes.iter().any(|&d2| d2 <= r2)
    }

    /// For a query whose sphere lies inside the gathered box: the nearest point within `radius`
    /// of `center` that `accept(index, position, distance²)` takes (it returns what to report),
    /// with its distance²; among equally near points the first that
    /// [`SpatialGrid::for_each_within`] visits. Distances are computed exactly as the grid
    /// computes them.
    pub fn nearest_accepted<T>(
        &mut self,
        center: Vec3,
        radius: f32,
        mut accept: impl FnMut(u32, Vec3, f32) -> Option<T>,
    ) -> Option<(T, f32)> {
        let r2 = radius * radius;
        self.d2.clear();
        self.d2.extend(
            self.x
                .iter()
                .zip(&self.y)
                .zip(&self.z)
                .map(|((&x, &y), &z)| {
                    // (p − c)·(p − c), as glam's `distance_squared` sums it.
                    let (dx, dy, dz) = (x - center.x, y - center.y, z - center.z);
                    dx * dx + dy * dy + dz * dz
                }),
        );
        loop {
            // The smallest distance left, then its first point (ties go to the first).
            let nearest = min_of(&self.d2);
            if nearest > r2 || nearest == f32::INFINITY {
                return None;
            }
            let j = first_equal(&self.d2, nearest)?;
            let p = Vec3::new(self.x[j], self.y[j], self.z[j]);
            if let Some(found) = accept(self.index[j], p, nearest) {
                return Some((found, nearest));
            }
            // Refused: never the nearest again.
            self.d2[j] = f32::INFINITY;
        }
    }
}

/// The first index holding `value`, eight values at a time (one packed compare and one branch
/// per eight, instead of a branch per value).
fn first_equal(values: &[f32], value: f32) -> Option<usize> {
    const LANES: usize = 8;
    let chunks = values.chunks_exact(LANES);
    let rest = chunks.remainder();
    for (c, chunk) in chunks.enumerate() {
        let mut bits = 0u32;
        for (k, &d) in chunk.iter().enumerate() {
            bits |= u32::from(d == value) << k;
        }
        if bits != 0 {
            return Some(c * LANES + bits.trailing_zeros() as usize);
        }
    }
    let tail = values.len() - rest.len();
    rest.iter().position(|&d| d == value).map(|k| tail + k)
}

/// The smallest value (∞ for none; NaNs ignored), in eight independent lanes so that it
/// compiles to packed minimums.
fn min_of(values: &[f32]) -> f32 {
    const LANES: usize = 8;
    let mut lanes = [f32::INFINITY; LANES];
    let chunks = values.chunks_exact(LANES);
    let rest = chunks.remainder();
    for chunk in chunks {
        for (m, &d) in lanes.iter_mut().zip(chunk) {
            *m = if d < *m { d } else { *m };
        }
    }
    for (m, &d) in lanes.iter_mut().zip(rest) {
        *m = if d < *m { d } else { *m };
    }
    lanes
        .iter()
        .fold(f32::INFINITY, |m, &d| if d < m { d } else { m })
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
            [&grid, &by_coordinate][q % 2].gather_box(
                lo - Vec3::splat(radius),
                hi + Vec3::splat(radius),
                &mut candidates,
            );
            for k in 0..5 {
                let t = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                let center = if k == 0 { lo } else { lo + (hi - lo) * t };
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
            let reach = Vec3::splat(radius);
            [&grid, &by_coordinate][q % 2].gather_box(lo - reach, hi + reach, &mut candidates);
            for k in 0..4 {
                let t = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                let center = if k == 0 { lo } else { lo + (hi - lo) * t };
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
    fn retained_grids_answer_queries_over_the_kept_points_in_the_same_order() {
        let mut rng = Rng::new(21);
        let points: Vec<Vec3> = (0..1500).map(|_| rng.in_unit_ball() * 2.0).collect();
        let mut grid = SpatialGrid::default();
        grid.rebuild(&points, 0.4);
        let mut kept = grid.clone();
        kept.retain(|i| i % 3 != 0);
        assert_eq!(kept.len(), points.len() - points.len().div_ceil(3));
        for _ in 0..100 {
            let center = rng.in_unit_ball() * 2.0;
            let radius = rng.range_f32(0.0, 1.0);
            let (mut all, mut some) = (Vec::new(), Vec::new());
            grid.for_each_within(center, radius, |i, p, d2| all.push((i, p, d2)));
            kept.for_each_within(center, radius, |i, p, d2| some.push((i, p, d2)));
            all.retain(|&(i, _, _)| i % 3 != 0);
            assert_eq!(all, some);
        }
    }

    #[test]
    fn entries_list_every_point_once_grouped_by_cell() {
        let mut rng = Rng::new(9);
        let points: Vec<Vec3> = (0..500).map(|_| rng.in_unit_ball() * 2.0).collect();
        let mut grid = SpatialGrid::default();
        grid.rebuild(&points, 0.5);
        let mut seen: Vec<u32> = grid.entries().map(|(i, _)| i).collect();
        assert!(grid.entries().all(|(i, p)| points[i as usize] == p));
        seen.sort_unstable();
        assert_eq!(seen, (0..500).collect::<Vec<u32>>());
    }

    #[test]
    fn entries_renumbered_by_slot_keep_their_positions_and_scan_order() {
        let mut rng = Rng::new(29);
        let points: Vec<Vec3> = (0..400).map(|_| rng.in_unit_ball() * 2.0).collect();
        let mut grid = SpatialGrid::default();
        grid.rebuild_for_gathers(&points, 0.5);
        let order = grid.entry_indices().to_vec();
        let mut renumbered = grid.clone();
        renumbered.number_entries_by_slot();
        let reordered: Vec<Vec3> = order.iter().map(|&i| points[i as usize]).collect();
        let mut candidates = Candidates::default();
        let (lo, hi) = (Vec3::splat(-0.7), Vec3::splat(0.4));
        renumbered.gather_box(lo, hi, &mut candidates);
        let by_slot: Vec<u32> = candidates.index.clone();
        grid.gather_box(lo, hi, &mut candidates);
        assert!(by_slot.len() > 20);
        for (slot, original) in by_slot.iter().zip(&candidates.index) {
            assert_eq!(order[*slot as usize], *original);
            assert_eq!(reordered[*slot as usize], points[*original as usize]);
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
