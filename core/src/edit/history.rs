//! Time (Longay 2014 §5.1.2): operation-level undo/redo, and ungrow/regrow to any earlier
//! iteration.
//!
//! Undo keeps whole-tree snapshots taken before each operation. A snapshot is a clone of the
//! complete growth state (skeleton, species, persistent points, generator state, iteration), so
//! an undone tree saves to exactly the bytes it saved to before the operation; a stroke, a
//! prune, a bend, a width edit or a parameter change are all undone the same way.
//!
//! The timeline keeps the state after each growth iteration. Ungrowing to iteration k restores
//! that state, which is the tree grown to k from the same seed (if no edit happened since k);
//! regrowing restores later states until an edit invalidates them. For a continuous slider
//! while dragging, [`skeleton_at_iteration`] shows the internodes born up to an iteration.

use super::EditError;
use crate::growth::Tree;
use crate::tree::{NodeId, Skeleton};

/// The kind of an undoable operation (for labels in the UI and session logs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OperationKind {
    Stroke,
    Lasso,
    Grow,
    SelectiveGrowth,
    Prune,
    Bend,
    WidthConstraint,
    Parameters,
}

#[derive(Clone, Debug)]
struct Snapshot {
    kind: OperationKind,
    tree: Tree,
}

/// Operation-level undo and redo.
#[derive(Clone, Debug, Default)]
pub struct History {
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    /// Oldest snapshots are dropped beyond this many (0 = unlimited).
    pub max_operations: usize,
}

impl History {
    pub fn new(max_operations: usize) -> History {
        History {
            max_operations,
            ..History::default()
        }
    }

    /// Call before performing an operation on `tree`: remembers the state to return to and
    /// forgets the redo branch.
    pub fn record(&mut self, kind: OperationKind, tree: &Tree) {
        self.push(kind, tree.clone());
    }

    fn push(&mut self, kind: OperationKind, before: Tree) {
        self.redo.clear();
        self.undo.push(Snapshot { kind, tree: before });
        if self.max_operations > 0 && self.undo.len() > self.max_operations {
            self.undo.remove(0);
        }
    }

    /// Runs `operation` on `tree` as one undoable step; on error the tree is left unchanged
    /// and nothing is recorded.
    pub fn perform<T>(
        &mut self,
        kind: OperationKind,
        tree: &mut Tree,
        operation: impl FnOnce(&mut Tree) -> Result<T, EditError>,
    ) -> Result<T, EditError> {
        let before = tree.clone();
        match operation(tree) {
            Ok(value) => {
                self.push(kind, before);
                Ok(value)
            }
            Err(e) => {
                *tree = before;
                Err(e)
            }
        }
    }

    /// Undoes the last operation; returns its kind, or `None` when there is nothing to undo.
    pub fn undo(&mut self, tree: &mut Tree) -> Option<OperationKind> {
        let snapshot = self.undo.pop()?;
        let kind = snapshot.kind;
        let current = std::mem::replace(tree, snapshot.tree);
        self.redo.push(Snapshot {
            kind,
            tree: current,
        });
        Some(kind)
    }

    /// Redoes the last undone operation.
    pub fn redo(&mut self, tree: &mut Tree) -> Option<OperationKind> {
        let snapshot = self.redo.pop()?;
        let kind = snapshot.kind;
        let current = std::mem::replace(tree, snapshot.tree);
        self.undo.push(Snapshot {
            kind,
            tree: current,
        });
        Some(kind)
    }

    pub fn num_undoable(&self) -> usize {
        self.undo.len()
    }

    pub fn num_redoable(&self) -> usize {
        self.redo.len()
    }
}

/// Growth states by iteration, for ungrow/regrow.
#[derive(Clone, Debug, Default)]
pub struct Timeline {
    /// `states[k]` is the tree after iteration `first + k`.
    states: Vec<Tree>,
    first: u32,
}

impl Timeline {
    /// Remembers `tree` as the state at its current iteration, dropping any later states
    /// (they belong to a future that an edit has just replaced).
    pub fn keep(&mut self, tree: &Tree) {
        let k = tree.iteration;
        let next = self.first + self.states.len() as u32;
        if self.states.is_empty() || k < self.first || k > next {
            self.states.clear();
            self.first = k;
        }
        self.states.truncate((k - self.first) as usize);
        self.states.push(tree.clone());
    }

    /// The state at `iteration`, if kept.
    pub fn at(&self, iteration: u32) -> Option<&Tree> {
        let k = iteration.checked_sub(self.first)? as usize;
        self.states.get(k)
    }

    /// Iterations available (first, last).
    pub fn range(&self) -> Option<(u32, u32)> {
        let n = self.states.len() as u32;
        (n > 0).then(|| (self.first, self.first + n - 1))
    }

    /// Replaces `tree` by its state at `iteration` (ungrow, or regrow up to the latest kept).
    pub fn go_to(&self, tree: &mut Tree, iteration: u32) -> Result<(), EditError> {
        let state = self.at(iteration).ok_or(EditError::IterationNotKept {
            iteration,
            range: self.range(),
        })?;
        *tree = state.clone();
        Ok(())
    }
}

/// The skeleton as it looked at `iteration` (internodes born later dropped), for scrubbing a
/// time slider before committing with [`Timeline::go_to`]. Ids are renumbered compactly.
pub fn skeleton_at_iteration(skeleton: &Skeleton, iteration: u32) -> Skeleton {
    let roots: Vec<NodeId> = skeleton
        .internodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.born_iteration > iteration)
        .map(|(i, _)| NodeId(i as u32))
        .collect();
    let mut view = skeleton.clone();
    let flags = view.subtree_flags(&roots);
    view.remove_flagged(&flags);
    view
}
