//! Passes over a [`SpatialGrid`] on several threads with results independent of their number:
//! the grid's cells are cut into runs of whole cells, each run fills its own part of a result
//! array held in slot order, and every slot's value is computed by the same code from the same
//! inputs whichever thread runs it. Nothing is summed across runs, so 1, 2 or 8 threads give
//! the same bits.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use crate::environment::{Candidates, SpatialGrid};

/// Entries per run of cells: large enough that a run outweighs handing it to a thread, small
/// enough that two cores share a pass of a few thousand points.
pub(crate) const RUN_ENTRIES: usize = 1024;

/// Calls `f(candidates, first_slot, indices, positions, out)` for every non-empty cell of
/// `grid`, with `out` the cell's part of `slot_values` (one value per slot of the grid), runs of
/// `runs` ([`SpatialGrid::cell_runs`]) in parallel. `candidates` is the working memory of the
/// thread; `spare` serves a pass of one run, which runs on the calling thread.
pub(crate) fn for_each_cell<T: Send>(
    grid: &SpatialGrid,
    runs: &[Range<usize>],
    slot_values: &mut [T],
    spare: &mut Candidates,
    f: impl Fn(&mut Candidates, usize, &[u32], &[Vec3], &mut [T]) + Sync,
) {
    let run = |candidates: &mut Candidates, cells: Range<usize>, values: &mut [T]| {
        let base = grid.slots_of(cells.clone()).start;
        for (first, indices, positions) in grid.cells_in(cells) {
            let out = &mut values[first - base..first - base + indices.len()];
            f(candidates, first, indices, positions, out);
        }
    };
    if runs.len() <= 1 || rayon::current_num_threads() <= 1 {
        for cells in runs {
            let slots = grid.slots_of(cells.clone());
            run(spare, cells.clone(), &mut slot_values[slots]);
        }
        return;
    }
    let mut pieces = Vec::with_capacity(runs.len());
    let mut rest = slot_values;
    let mut taken = 0;
    for cells in runs {
        let slots = grid.slots_of(cells.clone());
        let (_, tail) = rest.split_at_mut(slots.start - taken);
        let (piece, tail) = tail.split_at_mut(slots.len());
        pieces.push((cells.clone(), piece));
        rest = tail;
        taken = slots.end;
    }
    pieces
        .into_par_iter()
        .for_each_init(Candidates::default, |candidates, (cells, values)| {
            run(candidates, cells, values)
        });
}
