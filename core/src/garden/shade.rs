//! Where a garden tree's shadow grid holds its neighbours' shade.
//!
//! A tree reads its shadow grid only at its own nodes (the light of its buds, the shade of its
//! meshes). A neighbour's node shades the voxels of its pyramid alone: at most q_max voxels
//! below it and q_max to each side. So the grid need hold a neighbour's pyramid only where the
//! tree has nodes: in cells of q_max + 1 voxels of the grid along each axis, a node that shades
//! a point of cell c lies in c, in the cell above it, or in one of those two's eight horizontal
//! neighbours (a pyramid never reaches more than q_max voxels sideways or down). The cover keeps
//! the cells that ever held a node of the tree and, as `cells`, each of them with those 17
//! around it; a neighbour's node casts into the grid exactly when its cell is in `cells`. Every point of a
//! cell that holds a node of the tree then reads exactly the shade it would read with every
//! node of every linked neighbour cast, so growth is the same bit for bit, at the cost of the
//! pyramids of the neighbours' nodes near the tree instead of all of them.
//!
//! The cover only grows (a shed node's cell stays covered): when a tree's new nodes open new
//! cells, the neighbours' nodes already in those cells are cast then. An edited tree's cover
//! is everywhere: an edit (a brush stroke, several years) may grow far from the crown within
//! one call, before the cover could follow, so its grid takes in all its neighbours' nodes at
//! its first edit, as a garden did for every tree before covers.

use glam::{IVec3, Vec3};

use super::cell_hash::{CellBits, CellSet};

use crate::Tree;
use crate::environment::{MAX_SHADOW_DEPTH_VOXELS, floor_to_ivec3};

/// The cells of a tree's space whose neighbours' shade its grid holds (module doc).
#[derive(Clone, Debug, Default)]
pub(crate) struct ShadeCover {
    /// The grid's voxel edge, metres; 0 before the cover is made.
    voxel_m: f32,
    /// Voxels along a cell's edge: the pyramid's depth q_max + 1.
    cell_voxels: i32,
    /// Once the tree has been edited ([`super::Garden::edit_tree`]) its grid holds every
    /// linked neighbour's node, wherever it is: an edit may grow anywhere. (Until the garden
    /// is loaded again, which makes the cover anew.)
    pub(super) everywhere: bool,
    /// 1 / `cell_voxels` and half of it (see [`floor_div`]).
    per_cell: f64,
    half_cell: f64,
    /// Cells that ever held a node of the tree.
    node_cells: CellBits,
    /// `node_cells`, each with the 17 above and beside it whose nodes can shade it.
    cells: CellBits,
    /// A box (this tree's space, metres) holding every point whose cell is in `cells`: the
    /// cells' box grown by a voxel, far beyond the rounding of a point's voxel. Empty (lo
    /// above hi) while no cell is covered.
    bounds: (Vec3, Vec3),
    /// The box of the cells in `cells`.
    cells_lo: IVec3,
    cells_hi: IVec3,
}

/// `v.div_euclid(d)` for the `d` (1 to 65, `per = 1/d`, `half = 1/(2d)`) of a cover, by a
/// multiply instead of a division: v/d is either a whole number k, or lies at least 1/d from
/// one; v·per + half is then within 2^-20 of k + 1/(2d), or of a value at least 1/(2d) from
/// any whole number, for every i32 v, so its floor is exactly ⌊v/d⌋.
#[inline(always)]
fn floor_div(v: i32, per: f64, half: f64) -> i32 {
    let x = f64::from(v) * per + half;
    // The floor by truncation (x is within i32's range): one less for a negative fraction.
    let t = x as i32;
    t - i32::from(f64::from(t) > x)
}

/// Derived from the trees (and rebuilt on load): never part of a garden's value.
impl PartialEq for ShadeCover {
    fn eq(&self, _: &ShadeCover) -> bool {
        true
    }
}

/// A set of cells with its bounding box (a cheap first test).
#[derive(Clone, Debug)]
pub(crate) struct Cells {
    set: CellSet,
    lo: IVec3,
    hi: IVec3,
}

impl Default for Cells {
    fn default() -> Cells {
        Cells {
            set: CellSet::default(),
            lo: IVec3::MAX,
            hi: IVec3::MIN,
        }
    }
}

impl Cells {
    fn insert(&mut self, c: IVec3) -> bool {
        self.lo = self.lo.min(c);
        self.hi = self.hi.max(c);
        self.set.insert(c)
    }

    fn contains(&self, c: IVec3) -> bool {
        c.cmpge(self.lo).all() && c.cmple(self.hi).all() && self.set.contains(&c)
    }

    pub(super) fn is_empty(&self) -> bool {
        self.set.is_empty()
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = IVec3> + '_ {
        self.set.iter().copied()
    }
}

impl ShadeCover {
    /// The cover of `tree`'s nodes as they are, in cells sized for its shadow grid.
    pub(super) fn of(tree: &Tree) -> ShadeCover {
        let cell_voxels = tree
            .species
            .shadow_depth_voxels
            .min(MAX_SHADOW_DEPTH_VOXELS) as i32
            + 1;
        let mut cover = ShadeCover {
            voxel_m: tree.environment.shadow.voxel_size(),
            cell_voxels,
            per_cell: 1.0 / f64::from(cell_voxels),
            half_cell: 0.5 / f64::from(cell_voxels),
            bounds: (Vec3::INFINITY, Vec3::NEG_INFINITY),
            cells_lo: IVec3::MAX,
            cells_hi: IVec3::MIN,
            ..ShadeCover::default()
        };
        cover.extend(tree.skeleton.internodes.iter().map(|n| n.end));
        cover
    }

    pub(super) fn is_made(&self) -> bool {
        self.voxel_m > 0.0
    }

    /// The cell of `point` (this tree's space), from its voxel as the grid finds it.
    #[inline(always)]
    fn cell(&self, point: Vec3) -> IVec3 {
        let v = floor_to_ivec3(point / self.voxel_m);
        let (per, half) = (self.per_cell, self.half_cell);
        IVec3::new(
            floor_div(v.x, per, half),
            floor_div(v.y, per, half),
            floor_div(v.z, per, half),
        )
    }

    /// Whether a neighbour's node at `point` (this tree's space) casts into its grid.
    #[inline]
    pub(super) fn covers(&self, point: Vec3) -> bool {
        self.everywhere || (self.within_bounds(point) && self.cells.contains(self.cell(point)))
    }

    /// Whether `point` (this tree's space) lies in the box of the covered cells (grown by a
    /// voxel): a point outside it is covered only where the cover is everywhere.
    #[inline(always)]
    fn within_bounds(&self, point: Vec3) -> bool {
        point.cmpge(self.bounds.0).all() && point.cmple(self.bounds.1).all()
    }

    /// Whether some point of the box `lo..=hi` (this tree's space) may be covered: false
    /// only when no point of it is.
    pub(super) fn may_cover_box(&self, lo: Vec3, hi: Vec3) -> bool {
        self.everywhere || (lo.cmple(self.bounds.1).all() && hi.cmpge(self.bounds.0).all())
    }

    /// The corners of cell `c` (this tree's space), metres.
    pub(super) fn cell_box(&self, c: IVec3) -> (Vec3, Vec3) {
        let edge = self.cell_voxels as f32 * self.voxel_m;
        let lo = c.as_vec3() * edge;
        (lo, lo + Vec3::splat(edge))
    }

    /// Whether a node of the tree at `point` (its own space) would open a new cell.
    pub(super) fn opens(&self, point: Vec3) -> bool {
        !self.node_cells.contains(self.cell(point))
    }

    /// Whether `point` (this tree's space) lies in one of `new` (cells [`ShadeCover::extend`]
    /// returned).
    pub(super) fn in_cells(&self, new: &Cells, point: Vec3) -> bool {
        new.contains(self.cell(point))
    }

    /// Takes in the tree's `nodes` (its own space); returns the cells that became covered.
    pub(super) fn extend(&mut self, nodes: impl IntoIterator<Item = Vec3>) -> Cells {
        let mut new = Cells::default();
        for p in nodes {
            let c = self.cell(p);
            if !self.node_cells.insert(c) {
                continue;
            }
            for dx in -1..=1 {
                for dy in 0..=1 {
                    for dz in -1..=1 {
                        let around = c + IVec3::new(dx, dy, dz);
                        if self.cells.insert(around) {
                            new.insert(around);
                            self.cells_lo = self.cells_lo.min(around);
                            self.cells_hi = self.cells_hi.max(around);
                        }
                    }
                }
            }
        }
        if !new.is_empty() {
            let edge = self.cell_voxels as f32 * self.voxel_m;
            let voxel = Vec3::splat(self.voxel_m);
            self.bounds = (
                self.cells_lo.as_vec3() * edge - voxel,
                self.cells_hi.saturating_add(IVec3::ONE).as_vec3() * edge + voxel,
            );
        }
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::species::Species;

    #[test]
    fn a_cover_holds_the_cells_around_the_nodes_and_reports_the_new_ones() {
        let tree = Tree::new(Species::by_name("birch").expect("preset"), 1);
        let mut cover = ShadeCover::of(&tree);
        let c = cover.voxel_m * cover.cell_voxels as f32;
        assert_eq!(cover.cell_voxels, 7);
        let node = tree.skeleton.internodes[0].end;
        // A node up to a cell above or beside shades this one's cell; one below never does.
        assert!(cover.covers(node + Vec3::new(0.9 * c, 0.9 * c, -0.9 * c)));
        assert!(!cover.covers(node - Vec3::Y * 1.5 * c));
        assert!(!cover.covers(node + Vec3::new(2.5 * c, 0.0, 0.0)));
        let far = node + Vec3::new(5.0 * c, 0.0, 0.0);
        let new = cover.extend([far]);
        assert_eq!(new.set.len(), 18);
        assert!(cover.in_cells(&new, far) && cover.covers(far));
        assert!(cover.extend([far]).is_empty());
        // The bounds hold every covered point and reject boxes beyond them.
        assert!(cover.may_cover_box(far, far) && cover.may_cover_box(node, node));
        let beyond = far + Vec3::new(3.0 * c, 0.0, 0.0);
        assert!(!cover.covers(beyond) && !cover.may_cover_box(beyond, beyond + Vec3::ONE));
    }

    #[test]
    fn the_cell_division_by_multiply_is_the_euclidean_one() {
        for d in 1..=65 {
            let (per, half) = (1.0 / f64::from(d), 0.5 / f64::from(d));
            let edges = [
                i32::MIN,
                i32::MIN + 1,
                -1 << 30,
                -(1 << 20) - 3,
                0,
                1 << 25,
                i32::MAX,
            ];
            for &e in &edges {
                for k in -300..300 {
                    let v = e.saturating_add(k);
                    assert_eq!(floor_div(v, per, half), v.div_euclid(d), "{v} / {d}");
                }
            }
        }
    }
}
