//! The tree: an arena of internodes (metamers) and their buds.
//!
//! Invariants (checked by [`Skeleton::sanity_check`]):
//! - `internodes[0]` is the root (the base of the trunk) whenever the tree is not empty;
//! - a parent always has a smaller index than its children (the arena is in topological order),
//!   so a basipetal pass (tips → base) is a reverse loop and an acropetal pass a forward loop;
//! - `parent` / `main_child` / `lateral_children` agree with each other;
//! - a child starts where its parent ends.
//!
//! Space: world metres, Y up, the tree's base at `origin`.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use smallvec::SmallVec;

use crate::rng::Rng;

/// Index of an internode in [`Skeleton::internodes`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct NodeId(pub u32);

impl NodeId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// The lateral children of an internode, in the arena: up to two held inline (one shoot per
/// lateral bud, and most species have one or two per node), more on the heap. It saves as a list,
/// like a `Vec`.
pub type Children = SmallVec<[NodeId; 2]>;

/// The lateral buds of an internode: up to two held inline, more on the heap. It saves as a
/// list, like a `Vec`.
pub type LateralBuds = SmallVec<[Bud; 2]>;

/// A bud: the meristem that may produce a new shoot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bud {
    /// Unit direction a shoot from this bud starts in (world space).
    pub direction: Vec3,
    /// False once the bud has produced a shoot or was aborted.
    pub alive: bool,
    /// Per-bud tropism T that replaces the species' gravitropism for shoots from this bud
    /// (sketch-based tropism, selective growth). Unit vector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tropism_override: Option<Vec3>,
}

impl Bud {
    /// A living bud pointing along `direction`.
    pub fn new(direction: Vec3) -> Self {
        Bud {
            direction,
            alive: true,
            tropism_override: None,
        }
    }
}

/// One metamer: an internode of fixed length with its buds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Internode {
    pub parent: Option<NodeId>,
    /// The continuation of this axis (grown from the terminal bud), if any.
    pub main_child: Option<NodeId>,
    /// Shoots grown from this internode's lateral buds.
    pub lateral_children: Children,
    /// Base of the internode, world metres.
    pub start: Vec3,
    /// Tip of the internode, world metres.
    pub end: Vec3,
    /// L axis of the HLU frame, parallel-transported along each axis from the root; unit,
    /// perpendicular to the heading. U = H × L.
    pub left: Vec3,
    /// Diameter at the base of the internode (pipe model), metres.
    pub diameter: f32,
    /// Branch order: 0 on the trunk, +1 at every lateral branching.
    pub order: u32,
    /// Growth iteration in which this internode was created (0 = the seedling).
    pub born_iteration: u32,
    /// The terminal bud, present while this internode is a tip.
    pub terminal_bud: Option<Bud>,
    /// Lateral (axillary) buds of this metamer.
    pub lateral_buds: LateralBuds,
    /// A user width constraint (diameter, metres) set on this internode.
    pub width_constraint: Option<f32>,
    /// Light exposure L of this metamer's buds at the last iteration (0 = full shade).
    pub light_exposure: f32,
}

impl Internode {
    /// Unit heading H (start → end); +Y for a degenerate internode.
    pub fn heading(&self) -> Vec3 {
        (self.end - self.start).try_normalize().unwrap_or(Vec3::Y)
    }

    pub fn length(&self) -> f32 {
        (self.end - self.start).length()
    }

    /// U axis of the HLU frame.
    pub fn up(&self) -> Vec3 {
        self.heading().cross(self.left)
    }

    /// All children, main continuation first.
    pub fn children(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.main_child
            .into_iter()
            .chain(self.lateral_children.iter().copied())
    }

    pub fn is_tip(&self) -> bool {
        self.main_child.is_none() && self.lateral_children.is_empty()
    }
}

/// What [`Skeleton::sanity_check`] found wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TreeInvariantError {
    #[error("internode {index}: {what}")]
    Broken { index: usize, what: String },
}

/// The arena of internodes plus the generator that drives all randomness of this tree.
///
/// Growth state beyond the skeleton (species parameters, environment, history) is added by the
/// modules that own it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Skeleton {
    pub internodes: Vec<Internode>,
}

impl Skeleton {
    pub fn get(&self, id: NodeId) -> &Internode {
        &self.internodes[id.index()]
    }

    pub fn len(&self) -> usize {
        self.internodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.internodes.is_empty()
    }

    /// Height of the ground: the horizontal plane through the base of the trunk (0 for a tree
    /// grown from [`crate::Tree::new`]). Growth never goes below it.
    pub fn ground_y(&self) -> f32 {
        self.internodes.first().map_or(0.0, |n| n.start.y)
    }

    /// Flags every internode in the subtrees rooted at `roots` (a root and all its descendants).
    pub fn subtree_flags(&self, roots: &[NodeId]) -> Vec<bool> {
        let mut flags = vec![false; self.internodes.len()];
        for r in roots {
            if let Some(f) = flags.get_mut(r.index()) {
                *f = true;
            }
        }
        // Parents come before children: one forward pass propagates the flags down.
        for i in 0..self.internodes.len() {
            if let Some(p) = self.internodes[i].parent
                && flags[p.index()]
            {
                flags[i] = true;
            }
        }
        flags
    }

    /// True when `node` lies in the subtree rooted at `root` (O(depth)).
    pub fn is_in_subtree(&self, node: NodeId, root: NodeId) -> bool {
        let mut current = Some(node);
        while let Some(c) = current {
            if c == root {
                return true;
            }
            if c < root {
                return false;
            }
            current = self.internodes[c.index()].parent;
        }
        false
    }

    /// Removes every flagged internode (flags must be closed under descendants, as
    /// [`Skeleton::subtree_flags`] makes them), keeping the arena in topological order.
    /// Parents drop their links to removed children. Returns the new id of each old index
    /// (`None` for removed ones).
    pub fn remove_flagged(&mut self, removed: &[bool]) -> Vec<Option<NodeId>> {
        let mut remap: Vec<Option<NodeId>> = Vec::with_capacity(self.internodes.len());
        let mut next = 0u32;
        for (i, &gone) in removed.iter().enumerate().take(self.internodes.len()) {
            let gone = gone
                || self.internodes[i]
                    .parent
                    .is_some_and(|p| remap[p.index()].is_none());
            remap.push(if gone {
                None
            } else {
                next += 1;
                Some(NodeId(next - 1))
            });
        }
        remap.resize(self.internodes.len(), None);
        self.compact(&remap, |_| {});
        remap
    }

    /// [`Skeleton::remove_flagged`] for flags closed under descendants (a removed internode's
    /// children are flagged too, as [`Skeleton::subtree_flags`] makes them), one flag per
    /// internode: the new ids follow from the flags alone, so the arena is read once, by the
    /// compaction, which hands every removed internode to `on_removed` (in arena order) before
    /// dropping it.
    pub(crate) fn remove_closed_flags(
        &mut self,
        removed: &[bool],
        on_removed: impl FnMut(&Internode),
    ) -> Vec<Option<NodeId>> {
        let mut next = 0u32;
        let remap: Vec<Option<NodeId>> = (0..self.internodes.len())
            .map(|i| {
                if removed.get(i).copied().unwrap_or(true) {
                    None
                } else {
                    next += 1;
                    Some(NodeId(next - 1))
                }
            })
            .collect();
        self.compact(&remap, on_removed);
        remap
    }

    /// Compacts the arena in place by `remap` (each kept internode renumbered, then moved once
    /// towards the front; links to removed children dropped), handing every removed internode
    /// to `on_removed` in arena order before dropping it.
    fn compact(&mut self, remap: &[Option<NodeId>], mut on_removed: impl FnMut(&Internode)) {
        let mut read = 0;
        self.internodes.retain_mut(|node| {
            read += 1;
            if remap[read - 1].is_none() {
                on_removed(node);
                return false;
            }
            node.parent = node.parent.and_then(|p| remap[p.index()]);
            node.main_child = node.main_child.and_then(|c| remap[c.index()]);
            node.lateral_children.retain(|c| remap[c.index()].is_some());
            for c in &mut node.lateral_children {
                *c = remap[c.index()].unwrap_or(*c);
            }
            true
        });
    }

    /// Checks the arena invariants listed in the module doc.
    pub fn sanity_check(&self) -> Result<(), TreeInvariantError> {
        let broken = |index: usize, what: String| Err(TreeInvariantError::Broken { index, what });
        for (index, node) in self.internodes.iter().enumerate() {
            for v in [node.start, node.end, node.left] {
                if !v.is_finite() {
                    return broken(index, format!("non-finite vector {v}"));
                }
            }
            if !node.diameter.is_finite() || node.diameter < 0.0 {
                return broken(index, format!("bad diameter {}", node.diameter));
            }
            match node.parent {
                None if index != 0 => return broken(index, "no parent but not the root".into()),
                Some(p) if p.index() >= index => {
                    return broken(index, format!("parent {} not before child", p.0));
                }
                Some(p) => {
                    let parent = &self.internodes[p.index()];
                    let me = NodeId(index as u32);
                    if !parent.children().any(|c| c == me) {
                        return broken(index, format!("parent {} does not list it", p.0));
                    }
                    if parent.end.distance(node.start) > 1e-4 {
                        return broken(index, "does not start at its parent's end".into());
                    }
                }
                None => {}
            }
            for child in node.children() {
                if child.index() >= self.internodes.len() {
                    return broken(index, format!("child {} out of range", child.0));
                }
                if self.internodes[child.index()].parent != Some(NodeId(index as u32)) {
                    return broken(index, format!("child {} has another parent", child.0));
                }
            }
        }
        Ok(())
    }
}

/// Shared by every module that needs per-tree randomness.
pub type TreeRng = Rng;

#[cfg(test)]
mod tests {
    use crate::Tree;
    use crate::species::Species;

    use super::NodeId;

    #[test]
    fn compacting_by_closed_flags_matches_remove_flagged_and_hands_over_every_removed_node() {
        let mut tree = Tree::new(Species::by_name("oak").expect("oak preset"), 5);
        tree.grow(6, None);
        let nodes = tree.skeleton.len();
        let roots: Vec<NodeId> = (1..nodes as u32).step_by(37).map(NodeId).collect();
        let flags = tree.skeleton.subtree_flags(&roots);
        let flagged: Vec<_> = (0..nodes).filter(|&i| flags[i]).collect();
        assert!(
            flagged.len() > 10 && flagged.len() < nodes,
            "{}",
            flagged.len()
        );
        let before = tree.skeleton.clone();
        let mut expected = before.clone();
        let expected_remap = expected.remove_flagged(&flags);
        let mut handed = Vec::new();
        let remap = tree
            .skeleton
            .remove_closed_flags(&flags, |node| handed.push(node.end));
        assert_eq!(remap, expected_remap);
        assert_eq!(tree.skeleton, expected);
        let ends: Vec<_> = flagged.iter().map(|&i| before.internodes[i].end).collect();
        assert_eq!(handed, ends);
        tree.skeleton
            .sanity_check()
            .expect("compacted arena is sound");
    }
}
