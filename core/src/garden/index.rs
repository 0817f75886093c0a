//! Each garden tree's nodes bucketed by coarse cells of garden space, so that a tree asks a
//! neighbour only for its nodes near a place (the space a bud perceives, the cells its shade
//! cover has just opened) instead of walking all of them.

use glam::{IVec3, Vec3};

use super::cell_hash;

use crate::environment::floor_to_ivec3;

/// Edge of an index cell, metres: about the size of the places asked for.
const INDEX_CELL_M: f32 = 1.0;
/// Slack added to every box asked for, metres: far beyond the rounding between a node's garden
/// position and the same node seen from another tree.
const BOX_SLACK_M: f32 = 1e-3;

/// A tree's node ends (its own space) sorted by the index cell of their garden position.
#[derive(Clone, Debug, Default)]
pub(crate) struct NodeIndex {
    /// Whether it holds the tree's current nodes.
    pub(super) built: bool,
    /// Index cells that hold nodes, in sorted order, with where their nodes start in `ends`.
    cells: Vec<(IVec3, u32)>,
    ends: Vec<Vec3>,
}

/// Derived from the tree: never part of a garden's value.
impl PartialEq for NodeIndex {
    fn eq(&self, _: &NodeIndex) -> bool {
        true
    }
}

fn cell_key(c: IVec3) -> (i32, i32, i32) {
    (c.y, c.z, c.x)
}

/// The index cell of a point in garden space.
fn index_cell(point: Vec3) -> IVec3 {
    floor_to_ivec3(point / INDEX_CELL_M)
}

impl NodeIndex {
    /// The index of nodes `ends` (tree space) of a tree whose base is at `base` (garden space).
    pub(super) fn of(base: Vec3, ends: impl Iterator<Item = Vec3>) -> NodeIndex {
        let mut keyed: Vec<(IVec3, Vec3)> = ends.map(|e| (index_cell(base + e), e)).collect();
        keyed.sort_unstable_by_key(|&(c, _)| cell_key(c));
        let mut cells: Vec<(IVec3, u32)> = Vec::new();
        for (k, &(c, _)) in keyed.iter().enumerate() {
            if cells.last().is_none_or(|&(last, _)| last != c) {
                cells.push((c, k as u32));
            }
        }
        NodeIndex {
            built: true,
            cells,
            ends: keyed.into_iter().map(|(_, e)| e).collect(),
        }
    }

    /// The node ends (tree space) whose garden position lies in index cell `c`.
    fn in_cell(&self, c: IVec3) -> &[Vec3] {
        let key = cell_key(c);
        match self.cells.binary_search_by_key(&key, |&(c, _)| cell_key(c)) {
            Ok(k) => {
                let start = self.cells[k].1 as usize;
                let end = self
                    .cells
                    .get(k + 1)
                    .map_or(self.ends.len(), |&(_, s)| s as usize);
                &self.ends[start..end]
            }
            Err(_) => &[],
        }
    }

    /// Calls `f` with every node end (tree space) in one of `cells`.
    pub(super) fn for_each_in(&self, cells: &CellSet, mut f: impl FnMut(Vec3)) {
        if self.cells.is_empty() {
            return;
        }
        for &c in &cells.cells {
            for &e in self.in_cell(c) {
                f(e);
            }
        }
    }
}

/// Index cells asked for: those touched by a set of boxes (garden space).
#[derive(Default)]
pub(super) struct CellSet {
    seen: cell_hash::CellSet,
    cells: Vec<IVec3>,
}

impl CellSet {
    /// Adds the index cells the box `lo..=hi` (garden space, grown by the slack) touches.
    pub(super) fn add_box(&mut self, lo: Vec3, hi: Vec3) {
        let (lo, hi) = (
            index_cell(lo - Vec3::splat(BOX_SLACK_M)),
            index_cell(hi + Vec3::splat(BOX_SLACK_M)),
        );
        for y in lo.y..=hi.y {
            for z in lo.z..=hi.z {
                for x in lo.x..=hi.x {
                    let c = IVec3::new(x, y, z);
                    if self.seen.insert(c) {
                        self.cells.push(c);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_index_finds_the_nodes_in_the_cells_asked_for_and_no_others() {
        let base = Vec3::new(10.3, 0.0, -4.2);
        let ends = [
            Vec3::new(0.1, 0.5, 0.1),
            Vec3::new(-0.9, 2.5, 0.3),
            Vec3::new(0.2, 0.7, 0.0),
            Vec3::new(3.0, 0.2, 3.0),
        ];
        let index = NodeIndex::of(base, ends.iter().copied());
        let mut asked = CellSet::default();
        let p = base + ends[0];
        asked.add_box(p, p);
        let mut found = Vec::new();
        index.for_each_in(&asked, |e| found.push(e));
        found.sort_by(|a, b| a.x.total_cmp(&b.x));
        assert_eq!(found, vec![ends[0], ends[2]]);
    }
}
