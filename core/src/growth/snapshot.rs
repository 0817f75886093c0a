//! Compact copies of a tree for the undo history and the timeline: the saved state (skeleton,
//! species, attraction points, generator, iteration) without what is derived from it again (the
//! shadow grid, the pipe exponents, the working memory), which is most of a grown tree's memory.

use std::mem::size_of;

use super::Tree;
use crate::environment::{AttractionPoint, Environment, ShadowGrid};
use crate::tree::{Bud, Internode, NodeId};

impl Tree {
    /// The tree without its derived state; [`Tree::restore_derived`] makes it whole again, equal
    /// to `self` and growing on exactly as `self` would.
    pub(crate) fn compact_clone(&self) -> Tree {
        let env = &self.environment;
        Tree {
            species: self.species.clone(),
            iteration: self.iteration,
            skeleton: self.skeleton.clone(),
            environment: Environment {
                attraction: env.attraction.clone(),
                shadow: ShadowGrid::default(),
                depth_constraint: env.depth_constraint,
                neighbour_nodes: env.neighbour_nodes.clone(),
                neighbour_tropism: env.neighbour_tropism,
            },
            growth_mask: self.growth_mask,
            rng: self.rng.clone(),
            pipe_exponents: Vec::new(),
            scratch: Box::default(),
        }
    }

    /// The tree itself made compact (its derived state dropped), without copying.
    pub(crate) fn into_compact(mut self) -> Tree {
        self.environment.shadow = ShadowGrid::default();
        self.pipe_exponents = Vec::new();
        self.scratch = Box::default();
        self
    }

    /// Rebuilds what [`Tree::compact_clone`] left out (as loading a saved tree does).
    pub(crate) fn restore_derived(&mut self) {
        self.rebuild_shadow();
        self.update_widths();
    }

    /// Bytes of the whole tree: its saved state plus the shadow grid and pipe exponents derived
    /// from it (the working memory of an iteration aside). The budgets of the undo history and
    /// the timeline are multiples of it.
    pub fn own_bytes(&self) -> usize {
        self.saved_state_bytes()
            + self.environment.shadow.num_voxels() * size_of::<i32>()
            + self.pipe_exponents.capacity() * size_of::<f32>()
    }

    /// Heap and inline bytes of the tree's saved state: what a [`Tree::compact_clone`] holds.
    pub fn saved_state_bytes(&self) -> usize {
        let internodes = &self.skeleton.internodes;
        let spilled: usize = internodes.iter().map(spilled_bytes).sum();
        size_of::<Tree>()
            + internodes.capacity() * size_of::<Internode>()
            + spilled
            + self.environment.attraction.points.capacity() * size_of::<AttractionPoint>()
            + self.environment.neighbour_nodes.capacity() * size_of::<glam::Vec3>()
    }
}

/// Heap bytes an internode's small vectors took once they outgrew their inline room.
pub(crate) fn spilled_bytes(n: &Internode) -> usize {
    let buds = if n.lateral_buds.spilled() {
        n.lateral_buds.capacity() * size_of::<Bud>()
    } else {
        0
    };
    let children = if n.lateral_children.spilled() {
        n.lateral_children.capacity() * size_of::<NodeId>()
    } else {
        0
    };
    buds + children
}

#[cfg(test)]
mod tests {
    use crate::Tree;
    use crate::species::Species;

    #[test]
    fn a_restored_compact_copy_equals_the_tree_and_grows_on_identically() {
        let species = Species::by_name("oak").expect("preset");
        let mut tree = Tree::new(species, 5);
        tree.grow(8, None);
        let mut copy = tree.compact_clone();
        assert!(copy.saved_state_bytes() <= tree.saved_state_bytes());
        copy.restore_derived();
        assert!(copy == tree);
        tree.grow(3, None);
        copy.grow(3, None);
        assert_eq!(
            copy.to_json_bytes().expect("json"),
            tree.to_json_bytes().expect("json")
        );
    }
}
