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

/// The most index cells a dense index spans (4 MiB of starts); a larger box (the far nodes of
/// a damaged tree) is indexed by sorted cells instead.
const MAX_DENSE_CELLS: i64 = 1 << 20;

/// A tree's node ends (its own space) grouped by the index cell of their garden position.
#[derive(Clone, Debug, Default)]
pub(crate) struct NodeIndex {
    /// Whether it holds the tree's current nodes.
    pub(super) built: bool,
    /// The box of the cells that hold nodes (lo above hi when none).
    lo: IVec3,
    hi: IVec3,
    /// Dense: for every cell of the box (x fastest, then y, then z), where its nodes start in
    /// `ends` (one more entry at the end). Empty when the index is sparse.
    starts: Vec<u32>,
    /// Sparse: the cells that hold nodes, in sorted order, with where their nodes start.
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

/// The cells along each axis of the box `lo..=hi` if it holds at most [`MAX_DENSE_CELLS`].
fn dense_dims(lo: IVec3, hi: IVec3) -> Option<(usize, usize, usize)> {
    let extent = |a: i32, b: i32| i64::from(b) - i64::from(a) + 1;
    let (x, y, z) = (extent(lo.x, hi.x), extent(lo.y, hi.y), extent(lo.z, hi.z));
    let volume = x.checked_mul(y)?.checked_mul(z)?;
    (x > 0 && y > 0 && z > 0 && volume <= MAX_DENSE_CELLS)
        .then_some((x as usize, y as usize, z as usize))
}

impl NodeIndex {
    /// The index of nodes `ends` (tree space) of a tree whose base is at `base` (garden space).
    pub(super) fn of(base: Vec3, ends: impl Iterator<Item = Vec3>) -> NodeIndex {
        let keyed: Vec<(IVec3, Vec3)> = ends.map(|e| (index_cell(base + e), e)).collect();
        let (lo, hi) = keyed
            .iter()
            .fold((IVec3::MAX, IVec3::MIN), |(lo, hi), &(c, _)| {
                (lo.min(c), hi.max(c))
            });
        if let Some((dx, dy, dz)) = dense_dims(lo, hi) {
            // A counting sort by dense cell.
            let slot = |c: IVec3| {
                let o = (c - lo).as_uvec3();
                o.x as usize + dx * (o.y as usize + dy * o.z as usize)
            };
            let mut starts = vec![0u32; dx * dy * dz + 1];
            for &(c, _) in &keyed {
                starts[slot(c) + 1] += 1;
            }
            for k in 1..starts.len() {
                starts[k] += starts[k - 1];
            }
            let mut next = starts.clone();
            let mut ends = vec![Vec3::ZERO; keyed.len()];
            for &(c, e) in &keyed {
                let k = &mut next[slot(c)];
                ends[*k as usize] = e;
                *k += 1;
            }
            return NodeIndex {
                built: true,
                lo,
                hi,
                starts,
                cells: Vec::new(),
                ends,
            };
        }
        let mut keyed = keyed;
        keyed.sort_unstable_by_key(|&(c, _)| cell_key(c));
        let mut cells: Vec<(IVec3, u32)> = Vec::new();
        for (k, &(c, _)) in keyed.iter().enumerate() {
            if cells.last().is_none_or(|&(last, _)| last != c) {
                cells.push((c, k as u32));
            }
        }
        NodeIndex {
            built: true,
            lo,
            hi,
            starts: Vec::new(),
            cells,
            ends: keyed.into_iter().map(|(_, e)| e).collect(),
        }
    }

    /// The node ends (tree space) whose garden position lies in index cell `c`.
    fn in_cell(&self, c: IVec3) -> &[Vec3] {
        if c.cmplt(self.lo).any() || c.cmpgt(self.hi).any() {
            return &[];
        }
        if !self.starts.is_empty() {
            let d = (self.hi - self.lo + IVec3::ONE).as_uvec3();
            let o = (c - self.lo).as_uvec3();
            let k = o.x as usize + d.x as usize * (o.y as usize + d.y as usize * o.z as usize);
            return &self.ends[self.starts[k] as usize..self.starts[k + 1] as usize];
        }
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
        if self.ends.is_empty() || cells.lo.cmpgt(self.hi).any() || cells.hi.cmplt(self.lo).any() {
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
pub(super) struct CellSet {
    seen: cell_hash::CellSet,
    cells: Vec<IVec3>,
    /// The box of `cells` (lo above hi when none).
    lo: IVec3,
    hi: IVec3,
}

impl Default for CellSet {
    fn default() -> CellSet {
        CellSet {
            seen: cell_hash::CellSet::default(),
            cells: Vec::new(),
            lo: IVec3::MAX,
            hi: IVec3::MIN,
        }
    }
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
                        self.lo = self.lo.min(c);
                        self.hi = self.hi.max(c);
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
        // A box far from every node finds none; one over all of them finds each once.
        let mut far = CellSet::default();
        far.add_box(base + Vec3::splat(40.0), base + Vec3::splat(41.0));
        let mut none = 0;
        index.for_each_in(&far, |_| none += 1);
        assert_eq!(none, 0);
        let mut all = CellSet::default();
        all.add_box(base - Vec3::splat(2.0), base + Vec3::splat(4.0));
        let mut found = Vec::new();
        index.for_each_in(&all, |e| found.push(e));
        found.sort_by(|a, b| a.x.total_cmp(&b.x));
        let mut expected = ends.to_vec();
        expected.sort_by(|a, b| a.x.total_cmp(&b.x));
        assert_eq!(found, expected);
    }

    #[test]
    fn a_sparse_index_of_far_apart_nodes_finds_the_same_as_a_dense_one() {
        let base = Vec3::ZERO;
        let near = [Vec3::new(0.2, 0.3, 0.4), Vec3::new(1.5, 0.5, -0.5)];
        let mut ends = near.to_vec();
        ends.push(Vec3::new(400.0, 300.0, -400.0));
        let sparse = NodeIndex::of(base, ends.iter().copied());
        let dense = NodeIndex::of(base, near.iter().copied());
        assert!(sparse.starts.is_empty() && !dense.starts.is_empty());
        let mut asked = CellSet::default();
        asked.add_box(Vec3::splat(-1.0), Vec3::splat(2.0));
        let (mut a, mut b) = (Vec::new(), Vec::new());
        sparse.for_each_in(&asked, |e| a.push(e));
        dense.for_each_in(&asked, |e| b.push(e));
        a.sort_by(|p, q| p.x.total_cmp(&q.x));
        b.sort_by(|p, q| p.x.total_cmp(&q.x));
        assert_eq!(a, b);
        assert_eq!(a.len(), 2);
    }
}
