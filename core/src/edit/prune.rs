//! Pruning (Longay 2014 §5.3.3): remove the branch at the branching point nearest a picked
//! point. Widths are then recomputed by the pipe model as if the branch had never grown; a width
//! constraint on the internode just below the cut keeps the stub at its width.

use glam::Vec3;

use super::EditError;
use crate::growth::Tree;
use crate::tree::{NodeId, Skeleton};

/// What a prune removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pruned {
    /// Id (before the prune) of the first internode removed.
    pub root: NodeId,
    /// Its parent, the internode at the branching point (ids below the cut do not change).
    pub stub: NodeId,
    pub num_removed: usize,
}

/// Index of the internode whose segment passes closest to `point`.
pub fn nearest_internode(skeleton: &Skeleton, point: Vec3) -> Option<NodeId> {
    let mut best = None;
    let mut best_distance = f32::INFINITY;
    for (i, node) in skeleton.internodes.iter().enumerate() {
        let d = distance_to_segment(point, node.start, node.end);
        if d < best_distance {
            best_distance = d;
            best = Some(NodeId(i as u32));
        }
    }
    best
}

pub(crate) fn distance_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// The branch to cut for a pick: from the picked internode, walk towards the root to the first
/// internode that starts at a branching point (its parent has more than one child).
pub fn branch_to_prune(skeleton: &Skeleton, pick: Vec3) -> Result<(NodeId, NodeId), EditError> {
    if !pick.is_finite() {
        return Err(EditError::NonFinite {
            what: "prune pick point",
        });
    }
    let mut node = nearest_internode(skeleton, pick).ok_or(EditError::EmptyTree)?;
    loop {
        let Some(parent) = skeleton.get(node).parent else {
            return Err(EditError::NothingToPrune);
        };
        if skeleton.get(parent).children().count() > 1 {
            return Ok((node, parent));
        }
        node = parent;
    }
}

/// Removes the branch at the branching point nearest `pick` and recomputes every width.
pub fn prune_at(tree: &mut Tree, pick: Vec3) -> Result<Pruned, EditError> {
    let (root, stub) = branch_to_prune(&tree.skeleton, pick)?;
    let num_removed = tree.remove_subtrees(&[root]);
    tree.update_widths();
    Ok(Pruned {
        root,
        stub,
        num_removed,
    })
}
