//! Operation-level undo and redo (Longay 2014 §5.1.2; ungrow and regrow are [`super::timeline`]).
//!
//! Undo keeps, for each operation, the difference back to the state before it
//! ([`super::diff`]): the internodes, points and state the operation changed, taken between the
//! complete growth states before and after (skeleton, species, persistent points, generator
//! state, iteration; what is derived from them, shadow grid and pipe exponents, is rebuilt on
//! restore), so an undone tree saves to exactly the bytes it saved to before the operation; a
//! stroke, a prune, a bend, a width edit or a parameter change are all undone the same way, and
//! a step costs what it changed, not a tree. The history takes an optional byte budget, a
//! multiple of the tree's own size, so its memory stays a fixed multiple of the tree's size
//! however long a session runs.

use super::EditError;
use super::diff::TreeDiff;
use crate::growth::Tree;

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

/// One undoable step: the difference back to the state before it (undo) or forward to the state
/// after it (redo), taken against the state next to it on its stack.
#[derive(Clone, Debug)]
struct Step {
    kind: OperationKind,
    diff: TreeDiff,
    /// Bytes the difference holds.
    bytes: usize,
    /// Saved-state bytes of the tree the difference gives back (the budget's "largest tree").
    tree_bytes: usize,
}

impl Step {
    /// The step that turns `to` back into `from` (a compact copy).
    fn between(kind: OperationKind, from: Tree, to: &Tree) -> Step {
        let tree_bytes = from.saved_state_bytes();
        let diff = TreeDiff::between(from, to);
        Step {
            kind,
            bytes: diff.bytes(),
            diff,
            tree_bytes,
        }
    }

    /// The tree this step gives back from `current`, whole again; `None` when `current` is not
    /// the state the difference was taken against.
    fn restored(self, current: &Tree) -> Option<Tree> {
        let mut tree = self.diff.apply(current)?;
        tree.restore_derived();
        Some(tree)
    }
}

/// Operation-level undo and redo.
///
/// Each step is kept as a difference ([`TreeDiff`]): what the operation changed, not the whole
/// tree, so a history of many steps holds little more than the edits themselves. An operation
/// begun with [`History::record`] is kept whole (a compact copy) until it is finished, by the
/// next call that records, performs, undoes or redoes, or by [`History::finish`]; the tree
/// must change only inside recorded operations: a difference applies to the state it was taken
/// against (an undo against a tree whose number of internodes or points changed since refuses
/// and forgets the history, rather than give back a wrong tree or panic).
#[derive(Clone, Debug, Default)]
pub struct History {
    undo: Vec<Step>,
    redo: Vec<Step>,
    /// The operation in progress and the state before it.
    pending: Option<(OperationKind, Tree)>,
    /// Oldest steps are dropped beyond this many (0 = unlimited).
    pub max_operations: usize,
    /// Oldest steps are dropped while all of them (undo and redo) hold more than this many
    /// times the largest tree they give back or the current one ([`Tree::own_bytes`]; 0 =
    /// unlimited); the last undo step and the next redo step always stay.
    pub budget_trees: f32,
}

impl History {
    pub fn new(max_operations: usize) -> History {
        History {
            max_operations,
            ..History::default()
        }
    }

    /// Keeps the steps within `budget_trees` times the tree's own size ([`Tree::own_bytes`]),
    /// so memory stays a fixed multiple of the tree's size.
    pub fn with_budget(self, budget_trees: f32) -> History {
        History {
            budget_trees,
            ..self
        }
    }

    /// Call before performing an operation on `tree`: remembers the state to return to and
    /// forgets the redo branch. The operation lasts until [`History::finish`] or the next call.
    pub fn record(&mut self, kind: OperationKind, tree: &Tree) {
        self.finish(tree);
        self.redo.clear();
        self.pending = Some((kind, tree.compact_clone()));
    }

    /// Ends the operation in progress, whose result is `tree`: keeps what it changed as a
    /// difference and drops the copy of the state before it.
    pub fn finish(&mut self, tree: &Tree) {
        if let Some((kind, before)) = self.pending.take() {
            self.push(Step::between(kind, before, tree), tree.own_bytes());
        }
    }

    fn push(&mut self, step: Step, current_bytes: usize) {
        self.redo.clear();
        self.undo.push(step);
        if self.max_operations > 0 && self.undo.len() > self.max_operations {
            self.undo.remove(0);
        }
        self.fit_budget(current_bytes);
    }

    /// Drops the oldest undo steps, then the farthest redo steps, beyond the byte budget. The
    /// budget is a multiple of the largest tree the steps give back or the current one, so
    /// undoing back to a smaller tree does not drop the steps before it to make room for the
    /// redo.
    fn fit_budget(&mut self, current_bytes: usize) {
        if self.budget_trees <= 0.0 {
            return;
        }
        let largest = self
            .undo
            .iter()
            .chain(&self.redo)
            .map(|s| s.tree_bytes)
            .max()
            .unwrap_or(0)
            .max(current_bytes);
        let budget = (f64::from(self.budget_trees) * largest as f64) as usize;
        let mut total: usize = self.undo.iter().chain(&self.redo).map(|s| s.bytes).sum();
        while total > budget && self.undo.len() > 1 {
            total -= self.undo.remove(0).bytes;
        }
        while total > budget && self.redo.len() > 1 {
            total -= self.redo.remove(0).bytes;
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
        self.finish(tree);
        let before = tree.compact_clone();
        match operation(tree) {
            Ok(value) => {
                self.push(Step::between(kind, before, tree), tree.own_bytes());
                Ok(value)
            }
            Err(e) => {
                *tree = before;
                tree.restore_derived();
                Err(e)
            }
        }
    }

    /// Undoes the last operation; returns its kind, or `None` when there is nothing to undo.
    pub fn undo(&mut self, tree: &mut Tree) -> Option<OperationKind> {
        self.finish(tree);
        let step = self.undo.pop()?;
        let kind = step.kind;
        let Some(before) = step.restored(tree) else {
            self.forget();
            return None;
        };
        let current = std::mem::replace(tree, before).into_compact();
        self.redo.push(Step::between(kind, current, tree));
        self.fit_budget(tree.own_bytes());
        Some(kind)
    }

    /// Redoes the last undone operation.
    pub fn redo(&mut self, tree: &mut Tree) -> Option<OperationKind> {
        self.finish(tree);
        let step = self.redo.pop()?;
        let kind = step.kind;
        let Some(after) = step.restored(tree) else {
            self.forget();
            return None;
        };
        let current = std::mem::replace(tree, after).into_compact();
        self.undo.push(Step::between(kind, current, tree));
        self.fit_budget(tree.own_bytes());
        Some(kind)
    }

    /// Drops every step (the tree changed outside the recorded operations).
    fn forget(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }

    pub fn num_undoable(&self) -> usize {
        self.undo.len() + usize::from(self.pending.is_some())
    }

    pub fn num_redoable(&self) -> usize {
        self.redo.len()
    }

    /// Bytes the steps hold (undo and redo, and the copy kept for an operation in progress).
    pub fn snapshot_bytes(&self) -> usize {
        let pending = self
            .pending
            .as_ref()
            .map_or(0, |(_, tree)| tree.saved_state_bytes());
        self.undo
            .iter()
            .chain(&self.redo)
            .map(|s| s.bytes)
            .sum::<usize>()
            + pending
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::species::Species;

    fn sapling(seed: u64) -> Tree {
        Tree::new(Species::by_name("birch").expect("preset"), seed)
    }

    #[test]
    fn a_budgeted_history_keeps_the_last_step_and_drops_the_oldest_beyond_its_budget() {
        let mut tree = sapling(4);
        let mut history = History::new(64).with_budget(0.25);
        for _ in 0..12 {
            history
                .perform(OperationKind::Grow, &mut tree, |t| {
                    t.grow(1, None);
                    Ok(())
                })
                .expect("grows");
            assert!(history.num_undoable() >= 1);
            assert!(
                history.num_undoable() == 1 || history.snapshot_bytes() <= tree.own_bytes() / 4,
                "{} undo steps hold {} bytes for a {}-byte tree",
                history.num_undoable(),
                history.snapshot_bytes(),
                tree.own_bytes()
            );
        }
        assert!(history.num_undoable() < 12, "the oldest were dropped");
        let before = tree.to_json_bytes().expect("json");
        history.undo(&mut tree).expect("one step back");
        assert_eq!(tree.iteration, 11);
        history.redo(&mut tree).expect("and forward");
        assert!(tree.to_json_bytes().expect("json") == before);
    }

    #[test]
    fn many_recorded_steps_undo_and_redo_to_the_same_bytes_holding_a_fraction_of_whole_copies() {
        let mut tree = sapling(6);
        tree.grow(6, None);
        let mut history = History::new(0);
        let mut saved = vec![tree.to_json_bytes().expect("json")];
        // What whole compact copies of the states before would hold.
        let mut copies_bytes = 0;
        for step in 0..40 {
            copies_bytes += tree.saved_state_bytes();
            if step % 3 == 0 {
                history
                    .perform(OperationKind::Grow, &mut tree, |t| {
                        t.grow(1, None);
                        Ok(())
                    })
                    .expect("grows");
            } else {
                // A stroke: recorded, then brush points and growth until the next call.
                history.record(OperationKind::Stroke, &tree);
                let tip = tree.skeleton.internodes.last().expect("a tip").end;
                tree.environment
                    .attraction
                    .add_persistent(tip + glam::Vec3::new(0.05, 0.1, 0.0));
                tree.step(crate::growth::StepOptions {
                    autonomous: false,
                    scene: None,
                });
            }
            saved.push(tree.to_json_bytes().expect("json"));
        }
        history.finish(&tree);
        assert_eq!(history.num_undoable(), 40);
        println!(
            "40 steps hold {} bytes as differences, {copies_bytes} as whole copies; the tree {}",
            history.snapshot_bytes(),
            tree.own_bytes()
        );
        assert!(
            history.snapshot_bytes() < copies_bytes / 4,
            "40 steps hold {} bytes, whole copies {copies_bytes}",
            history.snapshot_bytes(),
        );
        for k in (0..40).rev() {
            history.undo(&mut tree).expect("a step back");
            assert!(
                tree.to_json_bytes().expect("json") == saved[k],
                "undo to {k}"
            );
        }
        assert!(history.undo(&mut tree).is_none());
        for (k, expected) in saved.iter().enumerate().skip(1) {
            history.redo(&mut tree).expect("a step forward");
            assert!(
                tree.to_json_bytes().expect("json") == *expected,
                "redo to {k}"
            );
        }
    }

    #[test]
    fn an_undo_against_a_tree_changed_outside_the_history_refuses_instead_of_guessing() {
        let mut tree = sapling(8);
        let mut history = History::new(0);
        history
            .perform(OperationKind::Grow, &mut tree, |t| {
                t.grow(2, None);
                Ok(())
            })
            .expect("grows");
        tree.grow(1, None); // not recorded
        assert_eq!(history.undo(&mut tree), None);
        assert_eq!(
            history.num_undoable(),
            0,
            "the history no longer fits the tree"
        );
    }
}
