//! A uniform grid over a set of points, rebuilt by counting sort: O(n + cells) to build, and a
//! radius query visits only the cells the query sphere overlaps. Used for attraction points,
//! buds and occupancy centres so space colonization is never O(points × buds).
//!
//! Buffers are kept between rebuilds: a steady-state growth iteration allocates nothing here.

use glam::{IVec3, Vec3};

use rayon::prelude::*;

use super::candidates::Candidates;

/// At least this many points make a rebuild compute their cells and bounds on all threads.
const PARALLEL_ENTRIES: usize = 32 * 1024;
/// Points per block of those parallel passes.
const PARALLEL_CHUNK: usize = 8 * 1024;
/// At most this many runs of cells fill a large grid (each scans every entry).
const MAX_FILL_RUNS: usize = 4;

/// The smallest box holding every position (not empty). Minimum and maximum are exact, so
/// blocks combined in any order give the same box.
fn bounds(positions: &[Vec3]) -> (Vec3, Vec3) {
    let serial = |chunk: &[Vec3]| {
        chunk
            .iter()
            .fold((chunk[0], chunk[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    };
    if positions.len() < PARALLEL_ENTRIES {
        return serial(positions);
    }
    positions
        .par_chunks(PARALLEL_CHUNK)
        .map(serial)
        .reduce_with(|a, b| (a.0.min(b.0), a.1.max(b.1)))
        .unwrap_or((positions[0], positions[0]))
}

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

    /// [`SpatialGrid::rebuild`] for a grid queried mostly by [`SpatialGrid::gather_near`]: it
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
        let (min, max) = bounds(positions);
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
        // Each position's cell (on all threads for a large set: every value is computed alone,
        // so the grid is the same on any number of threads), then the counts.
        let mut cell_of = std::mem::take(&mut self.cell_of);
        cell_of.resize(n, 0);
        let grid = &*self;
        let cell_of_chunk = |cells: &mut [u32], chunk: &[Vec3]| {
            for (c, p) in cells.iter_mut().zip(chunk) {
                *c = grid.cell_index(grid.cell_coord(*p)) as u32;
            }
        };
        if n >= PARALLEL_ENTRIES {
            cell_of
                .par_chunks_mut(PARALLEL_CHUNK)
                .zip(positions.par_chunks(PARALLEL_CHUNK))
                .for_each(|(cells, chunk)| cell_of_chunk(cells, chunk));
        } else {
            cell_of_chunk(&mut cell_of, positions);
        }
        self.cell_of = cell_of;
        for &c in &self.cell_of {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..num_cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.entry_index.resize(positions.len(), 0);
        self.entry_position.resize(positions.len(), Vec3::ZERO);
        // Fill each cell in input order (stable): the cursor is cell_start shifted by one.
        self.fill_cells(positions, num_cells);
        if by_coordinate {
            let (xs, ys, zs) = (&mut self.entry_x, &mut self.entry_y, &mut self.entry_z);
            let sorted = &self.entry_position;
            let split =
                |out: &mut Vec<f32>, axis: usize| out.extend(sorted.iter().map(|p| p[axis]));
            if n >= PARALLEL_ENTRIES {
                rayon::join(
                    || split(xs, 0),
                    || rayon::join(|| split(ys, 1), || split(zs, 2)),
                );
            } else {
                split(xs, 0);
                split(ys, 1);
                split(zs, 2);
            }
        }
        // The cursors ended at each cell's end: shifted by one cell they are the starts.
        self.cell_start.copy_within(0..num_cells, 1);
        self.cell_start[0] = 0;
    }

    /// Writes every entry to its cell's next slot, in input order within each cell (the cells'
    /// starts in `cell_start[..num_cells]` become their ends). For a large set, the cells are
    /// cut into one run per thread holding about as many entries; each run scans all entries
    /// and fills only its own cells, so every slot gets what the serial fill gives it.
    fn fill_cells(&mut self, positions: &[Vec3], num_cells: usize) {
        let n = positions.len();
        let threads = rayon::current_num_threads().min(MAX_FILL_RUNS);
        let cell_of = &self.cell_of;
        let fill = |cells: std::ops::Range<usize>,
                    cursors: &mut [u32],
                    first_slot: usize,
                    index: &mut [u32],
                    position: &mut [Vec3]| {
            for (i, (&c, p)) in cell_of.iter().zip(positions).enumerate() {
                let c = c as usize;
                if cells.contains(&c) {
                    let cursor = &mut cursors[c - cells.start];
                    let slot = *cursor as usize - first_slot;
                    *cursor += 1;
                    index[slot] = i as u32;
                    position[slot] = *p;
                }
            }
        };
        if n < PARALLEL_ENTRIES || threads <= 1 {
            fill(
                0..num_cells,
                &mut self.cell_start[..num_cells],
                0,
                &mut self.entry_index,
                &mut self.entry_position,
            );
            return;
        }
        // Run k starts at the first cell whose entries start at or after k·n/threads.
        let mut starts: Vec<usize> = (0..threads)
            .map(|k| {
                self.cell_start[..num_cells].partition_point(|&s| (s as usize) < k * n / threads)
            })
            .collect();
        starts[0] = 0;
        starts.push(num_cells);
        starts.dedup();
        let mut runs = Vec::with_capacity(starts.len());
        let (mut cursors, mut index, mut position) = (
            &mut self.cell_start[..num_cells],
            &mut self.entry_index[..],
            &mut self.entry_position[..],
        );
        for w in starts.windows(2) {
            let (c0, c1) = (w[0], w[1]);
            let first_slot = cursors[0] as usize;
            let last_slot = if c1 - c0 < cursors.len() {
                cursors[c1 - c0] as usize
            } else {
                n
            };
            let (run_cursors, rest) = std::mem::take(&mut cursors).split_at_mut(c1 - c0);
            cursors = rest;
            let (run_index, rest) = std::mem::take(&mut index).split_at_mut(last_slot - first_slot);
            index = rest;
            let (run_position, rest) =
                std::mem::take(&mut position).split_at_mut(last_slot - first_slot);
            position = rest;
            runs.push((c0..c1, run_cursors, first_slot, run_index, run_position));
        }
        runs.into_par_iter()
            .for_each(|(cells, cursors, first_slot, index, position)| {
                fill(cells, cursors, first_slot, index, position)
            });
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

    /// Splits the cells into consecutive runs of whole cells, each holding at least
    /// `min_entries` entries (the last one may hold fewer), into `runs` as ranges of cells: the
    /// blocks of work of a parallel pass over the grid ([`SpatialGrid::cells_in`]).
    pub fn cell_runs(&self, min_entries: usize, runs: &mut Vec<std::ops::Range<usize>>) {
        runs.clear();
        let num_cells = self.cell_start.len().saturating_sub(1);
        let mut first = 0;
        for c in 0..num_cells {
            if (self.cell_start[c + 1] - self.cell_start[first]) as usize >= min_entries.max(1) {
                runs.push(first..c + 1);
                first = c + 1;
            }
        }
        if first < num_cells && self.cell_start[num_cells] > self.cell_start[first] {
            runs.push(first..num_cells);
        }
    }

    /// The slots of the entries of cells `cells` (a range of [`SpatialGrid::cell_runs`]).
    pub fn slots_of(&self, cells: std::ops::Range<usize>) -> std::ops::Range<usize> {
        self.cell_start[cells.start] as usize..self.cell_start[cells.end] as usize
    }

    /// [`SpatialGrid::cells`] for the cells `cells` only, each with its first slot.
    pub fn cells_in(
        &self,
        cells: std::ops::Range<usize>,
    ) -> impl Iterator<Item = (usize, &[u32], &[Vec3])> + '_ {
        self.cell_start[cells.start..=cells.end]
            .windows(2)
            .filter_map(|w| {
                let (start, end) = (w[0] as usize, w[1] as usize);
                (start < end).then(|| {
                    (
                        start,
                        &self.entry_index[start..end],
                        &self.entry_position[start..end],
                    )
                })
            })
    }

    /// Gathers, in scan order, every stored point in the cells that overlap the box `lo..=hi`
    /// grown by `radius` on every side (a superset of the points within `radius` of any point of
    /// the box) into `out`, replacing its contents.
    pub fn gather_near(&self, lo: Vec3, hi: Vec3, radius: f32, out: &mut Candidates) {
        out.clear();
        let reach = Vec3::splat(radius);
        let Some((cell_lo, cell_hi)) = self.cell_range(lo - reach, hi + reach) else {
            out.pad();
            return;
        };
        let by_coordinate = self.has_coordinates();
        for z in cell_lo.z..=cell_hi.z {
            for y in cell_lo.y..=cell_hi.y {
                let slots = self.row_slots(y, z, cell_lo.x, cell_hi.x);
                let n = slots.len();
                if by_coordinate && n <= SHORT_ROW && slots.start + SHORT_ROW <= self.len() {
                    // A short row: fixed-size copies (inline moves, no library call), the
                    // entries copied past the row's end dropped again.
                    out.push_rows(
                        [&self.entry_x, &self.entry_y, &self.entry_z],
                        &self.entry_index,
                        slots.start,
                        n,
                    );
                } else if by_coordinate {
                    out.extend_rows(
                        [
                            &self.entry_x[slots.clone()],
                            &self.entry_y[slots.clone()],
                            &self.entry_z[slots.clone()],
                        ],
                        &self.entry_index[slots],
                    );
                } else {
                    out.extend_positions(
                        &self.entry_position[slots.clone()],
                        &self.entry_index[slots],
                    );
                }
            }
        }
        out.pad();
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
const SHORT_ROW: usize = super::candidates::SHORT_ROW;

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

    /// A grid of `points` built on a pool of `threads` threads.
    fn built_on(threads: usize, points: &[Vec3], cell: f32, by_coordinate: bool) -> SpatialGrid {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let mut grid = SpatialGrid::default();
        pool.install(|| grid.rebuild_with(points, cell, by_coordinate));
        grid
    }

    #[test]
    fn large_grids_built_on_several_threads_match_the_serial_build() {
        let mut rng = Rng::new(8);
        // Clustered, so that the runs of cells hold very different numbers of cells.
        let mut points: Vec<Vec3> = (0..3 * PARALLEL_ENTRIES)
            .map(|i| {
                let spread = if i % 4 == 0 { 3.0 } else { 0.3 };
                rng.in_unit_ball() * spread + Vec3::new(1.0, 0.5, -2.0)
            })
            .collect();
        // Duplicates keep their input order within a cell.
        points.extend_from_within(..1000);
        for by_coordinate in [false, true] {
            let serial = built_on(1, &points, 0.05, by_coordinate);
            for threads in [2, 3, 8] {
                let parallel = built_on(threads, &points, 0.05, by_coordinate);
                assert_eq!(parallel.origin, serial.origin);
                assert_eq!(parallel.dims, serial.dims);
                assert_eq!(parallel.cell_start, serial.cell_start);
                assert_eq!(parallel.entry_index, serial.entry_index);
                assert_eq!(parallel.entry_position, serial.entry_position);
                assert_eq!(parallel.entry_x, serial.entry_x);
                assert_eq!(parallel.entry_z, serial.entry_z);
            }
            let entries: Vec<(u32, Vec3)> = serial.entries().collect();
            assert_eq!(entries.len(), points.len());
            let mut seen = vec![false; points.len()];
            for w in entries.windows(2) {
                let (a, b) = (w[0], w[1]);
                let (ca, cb) = (
                    serial.cell_index(serial.cell_coord(a.1)),
                    serial.cell_index(serial.cell_coord(b.1)),
                );
                assert!(ca < cb || (ca == cb && a.0 < b.0), "{a:?} then {b:?}");
            }
            for (i, p) in entries {
                assert_eq!(points[i as usize], p);
                seen[i as usize] = true;
            }
            assert!(seen.iter().all(|&s| s));
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
        renumbered.gather_near(lo, hi, 0.0, &mut candidates);
        let by_slot: Vec<u32> = candidates.indices().to_vec();
        grid.gather_near(lo, hi, 0.0, &mut candidates);
        assert!(by_slot.len() > 20);
        for (slot, original) in by_slot.iter().zip(candidates.indices()) {
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
