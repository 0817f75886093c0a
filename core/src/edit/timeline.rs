//! Time (Longay 2014 §5.1.2): ungrow and regrow to any earlier iteration.
//!
//! The timeline keeps the state after each growth iteration: the latest one whole (a compact
//! copy: no shadow grid or pipe exponents, rebuilt on restore), every earlier one as the
//! difference ([`super::diff`]) that turns the next kept state back into it. A growth iteration
//! appends internodes and changes the diameters and light of the others, so the difference back
//! from it holds about a diameter and an exposure per internode, a small part of a copy: a
//! budget of memory holds many more iterations than whole copies would. Ungrowing to iteration
//! k walks the differences down from the latest state and gives back exactly the state kept at
//! k, which is the tree grown to k from the same seed (if no edit happened since k); regrowing
//! restores later states until an edit invalidates them. For a continuous slider while
//! dragging, [`skeleton_at_iteration`] shows the internodes born up to an iteration.
//!
//! With a byte budget (a multiple of the latest tree's own size) the states are thinned as the
//! tree grows: the first and the latest always stay, older iterations are kept farther apart
//! than recent ones. Thinning rebuilds the differences of the states it keeps in one walk down
//! the timeline, and thins to three quarters of the budget, so that a walk is paid once every
//! few iterations rather than at each.

use super::EditError;
use super::diff::TreeDiff;
use crate::growth::Tree;
use crate::tree::{NodeId, Skeleton};

/// Thinning leaves the kept states within this fraction of the budget.
const THIN_TO: f64 = 0.75;

/// How a kept state is held.
#[derive(Clone, Debug)]
enum Held {
    /// The latest kept state, a compact copy.
    Whole(Tree),
    /// What turns the next kept state back into this one.
    Back(TreeDiff),
}

/// A growth state kept by the timeline.
#[derive(Clone, Debug)]
struct Kept {
    iteration: u32,
    held: Held,
    /// Bytes `held` holds.
    bytes: usize,
    /// Saved-state bytes of this state ([`Tree::saved_state_bytes`]): a difference back to it
    /// holds at most about as much (its internodes and points, whole).
    tree_bytes: usize,
    /// Every iteration since the previous kept state was autonomous growth (so it regrows
    /// from that state exactly, given the same scene).
    autonomous: bool,
}

/// A kept state as [`Timeline::choose_kept`] weighs it.
struct Candidate {
    index: usize,
    iteration: u32,
    /// Estimated bytes of its difference.
    bytes: usize,
    tree_bytes: usize,
}

/// Growth states by iteration, for ungrow/regrow.
///
/// Unbounded by default, every iteration is kept. With a budget ([`Timeline::with_budget`])
/// the states are thinned as the tree grows so that together they hold at most that many times
/// the latest tree's own size ([`Tree::own_bytes`]): the first and the latest always stay, and
/// older iterations are kept farther apart than recent ones (gaps grow with age), so a thousand
/// iterations ungrow to any recent one and to a coarse ladder of older ones.
#[derive(Clone, Debug, Default)]
pub struct Timeline {
    /// Kept states in increasing iteration; the last is [`Held::Whole`], the others
    /// [`Held::Back`].
    states: Vec<Kept>,
    /// Thinning budget, in multiples of the latest tree's own size (0 = keep every iteration).
    pub budget_trees: f32,
    /// [`Tree::own_bytes`] of the latest tree kept.
    latest_own_bytes: usize,
}

impl Timeline {
    /// A timeline whose states hold at most `budget_trees` times the latest tree's own size.
    pub fn with_budget(budget_trees: f32) -> Timeline {
        Timeline {
            budget_trees,
            ..Timeline::default()
        }
    }

    /// Remembers `tree` as the state at its current iteration, dropping any later states
    /// (they belong to a future that an edit has just replaced).
    pub fn keep(&mut self, tree: &Tree) {
        self.keep_step(tree, false);
    }

    /// [`Timeline::keep`] for a state reached by one autonomous iteration from the previous
    /// one: a thinned-out iteration between such states regrows exactly
    /// ([`Timeline::regrows_autonomously`]).
    pub fn keep_autonomous(&mut self, tree: &Tree) {
        self.keep_step(tree, true);
    }

    fn keep_step(&mut self, tree: &Tree, autonomous: bool) {
        let k = tree.iteration;
        let contiguous = match (self.states.first(), self.states.last()) {
            (Some(first), Some(last)) => first.iteration <= k && k <= last.iteration + 1,
            _ => false,
        };
        if !contiguous {
            self.states.clear();
        }
        self.drop_from(k);
        let compact = tree.compact_clone();
        // The previous latest state becomes the difference back from this one.
        if let Some(mut previous) = self.states.pop() {
            match previous.held {
                Held::Whole(before) => {
                    let diff = TreeDiff::between(before, &compact);
                    previous.bytes = diff.bytes();
                    previous.held = Held::Back(diff);
                    self.states.push(previous);
                }
                // Not reached (the last state is whole); start afresh rather than guess.
                Held::Back(_) => self.states.clear(),
            }
        }
        self.latest_own_bytes = tree.own_bytes();
        self.states.push(Kept {
            iteration: k,
            bytes: compact.saved_state_bytes(),
            tree_bytes: compact.saved_state_bytes(),
            held: Held::Whole(compact),
            autonomous,
        });
        self.thin();
    }

    /// Drops the states at `iteration` and later; the latest one left is made whole again.
    fn drop_from(&mut self, iteration: u32) {
        let Some(cut) = self.states.iter().position(|s| s.iteration >= iteration) else {
            return;
        };
        if cut == 0 {
            self.states.clear();
            return;
        }
        match self.compact_at(cut - 1) {
            Some(whole) => {
                self.states.truncate(cut);
                if let Some(last) = self.states.last_mut() {
                    last.bytes = whole.saved_state_bytes();
                    last.held = Held::Whole(whole);
                }
            }
            None => self.states.clear(),
        }
    }

    /// The compact state kept at `index`, by the differences down from the latest; `None` only
    /// if the timeline's invariant is broken (then nothing is given back rather than a wrong
    /// tree).
    fn compact_at(&self, index: usize) -> Option<Tree> {
        let last = self.states.len().checked_sub(1)?;
        if index > last {
            return None;
        }
        let Held::Whole(latest) = &self.states[last].held else {
            return None;
        };
        let mut tree = latest.clone();
        for kept in self.states[index..last].iter().rev() {
            let Held::Back(diff) = &kept.held else {
                return None;
            };
            tree = diff.clone().apply(&tree)?;
        }
        Some(tree)
    }

    /// Thins interior states while over the budget: each time the one whose removal leaves the
    /// smallest gap relative to its age, down to [`THIN_TO`] of the budget by the estimated
    /// sizes, then rebuilds the differences between the states kept.
    fn thin(&mut self) {
        if self.budget_trees <= 0.0 {
            return;
        }
        let budget = (f64::from(self.budget_trees) * self.latest_own_bytes as f64) as usize;
        // Each round removes at least one state, so this ends; a few rounds at most in practice
        // (a rebuilt difference can be larger than estimated).
        while self.kept_bytes() > budget && self.states.len() > 2 {
            let target = (THIN_TO * budget as f64) as usize;
            let keep = self.choose_kept(target);
            self.rebuild(&keep);
        }
    }

    /// Which states stay (by index) when thinning to `target` bytes: greedily drops the
    /// interior state that loses the least time resolution per byte it saves. The resolution
    /// lost is the gap its removal leaves relative to its age (old iterations may lie farther
    /// apart than recent ones); the bytes saved are estimated from the difference across the
    /// gap, which holds as much as the larger of the two it replaces (growth changes the same
    /// diameters again) but no more than the earlier state itself (a difference back to a
    /// small tree is small, however large the one after it).
    fn choose_kept(&self, target: usize) -> Vec<usize> {
        let Some(latest) = self.states.last() else {
            return Vec::new();
        };
        let latest_iteration = latest.iteration;
        let mut left: Vec<Candidate> = self
            .states
            .iter()
            .enumerate()
            .map(|(index, s)| Candidate {
                index,
                iteration: s.iteration,
                bytes: s.bytes,
                tree_bytes: s.tree_bytes,
            })
            .collect();
        let mut total: usize = left.iter().map(|l| l.bytes).sum();
        let mut removed_any = false;
        while (total > target || !removed_any) && left.len() > 2 {
            let merged = |i: usize| {
                left[i - 1]
                    .bytes
                    .max(left[i].bytes)
                    .min(left[i - 1].tree_bytes.max(left[i - 1].bytes))
            };
            let cost = |i: usize| {
                let gap = left[i + 1].iteration - left[i - 1].iteration;
                let age = latest_iteration - left[i].iteration + 1;
                let saved = (left[i - 1].bytes + left[i].bytes).saturating_sub(merged(i));
                f64::from(gap) / f64::from(age) / saved.max(1) as f64
            };
            let victim = (1..left.len() - 1)
                .min_by(|&a, &b| cost(a).total_cmp(&cost(b)))
                .unwrap_or(1);
            let merged = merged(victim);
            let dropped = left.remove(victim);
            // The state before the victim now differs from the one after it.
            total = total - dropped.bytes - left[victim - 1].bytes + merged;
            left[victim - 1].bytes = merged;
            removed_any = true;
        }
        left.into_iter().map(|l| l.index).collect()
    }

    /// Keeps only the states at `keep` (increasing indices, the first and the last included),
    /// with their differences taken anew between consecutive kept states in one walk down
    /// from the latest.
    fn rebuild(&mut self, keep: &[usize]) {
        let old = std::mem::take(&mut self.states);
        let is_kept = |i: usize| keep.binary_search(&i).is_ok();
        // A kept state was reached autonomously from the kept one below it when it and every
        // state dropped in between were.
        let mut autonomous: Vec<bool> = Vec::with_capacity(old.len());
        let mut dropped_autonomous = true;
        for (i, s) in old.iter().enumerate() {
            autonomous.push(s.autonomous && dropped_autonomous);
            dropped_autonomous = if is_kept(i) {
                true
            } else {
                dropped_autonomous && s.autonomous
            };
        }
        let mut walk = old.into_iter().enumerate().rev();
        let Some((latest_index, mut latest)) = walk.next() else {
            return;
        };
        latest.autonomous = autonomous[latest_index];
        let Held::Whole(latest_tree) = &latest.held else {
            return;
        };
        // `above`: the compact state of the nearest kept state above the walk; `current`: the
        // state at the index the walk has reached, when it differs from `above`.
        let mut above = latest_tree.clone();
        let mut current: Option<Tree> = None;
        let mut rebuilt: Vec<Kept> = Vec::with_capacity(keep.len());
        for (index, kept) in walk {
            let Held::Back(diff) = kept.held else {
                // Not reached (only the last state is whole): keep the latest alone.
                rebuilt.clear();
                break;
            };
            let Some(tree) = diff.apply(current.as_ref().unwrap_or(&above)) else {
                rebuilt.clear();
                break;
            };
            if is_kept(index) {
                let diff = TreeDiff::between(tree.clone(), &above);
                above = tree;
                current = None;
                rebuilt.push(Kept {
                    iteration: kept.iteration,
                    bytes: diff.bytes(),
                    tree_bytes: kept.tree_bytes,
                    held: Held::Back(diff),
                    autonomous: autonomous[index],
                });
            } else {
                current = Some(tree);
            }
        }
        rebuilt.reverse();
        rebuilt.push(latest);
        self.states = rebuilt;
    }

    /// Whether every iteration from the kept `from` up to `to` was autonomous growth, so that
    /// growing the state at `from` autonomously reaches the state `to` had.
    pub fn regrows_autonomously(&self, from: u32, to: u32) -> bool {
        self.is_kept(from)
            && self
                .states
                .iter()
                .find(|s| s.iteration > from)
                .is_some_and(|next| next.iteration >= to && next.autonomous)
    }

    fn index_of(&self, iteration: u32) -> Option<usize> {
        self.states
            .binary_search_by_key(&iteration, |s| s.iteration)
            .ok()
    }

    /// The state at `iteration`, if kept.
    pub fn at(&self, iteration: u32) -> Option<Tree> {
        let mut tree = self.compact_at(self.index_of(iteration)?)?;
        tree.restore_derived();
        Some(tree)
    }

    /// Whether the state at `iteration` is kept.
    pub fn is_kept(&self, iteration: u32) -> bool {
        self.index_of(iteration).is_some()
    }

    /// The latest kept iteration at or before `iteration` (where ungrowing to a thinned-out
    /// iteration lands).
    pub fn kept_at_or_before(&self, iteration: u32) -> Option<u32> {
        self.states
            .iter()
            .rev()
            .map(|s| s.iteration)
            .find(|&k| k <= iteration)
    }

    /// Iterations available (first, last); with a budget some between them are thinned out.
    pub fn range(&self) -> Option<(u32, u32)> {
        Some((
            self.states.first()?.iteration,
            self.states.last()?.iteration,
        ))
    }

    /// Number of states kept.
    pub fn num_kept(&self) -> usize {
        self.states.len()
    }

    /// Bytes the kept states hold (the latest whole, the others as differences).
    pub fn kept_bytes(&self) -> usize {
        self.states.iter().map(|s| s.bytes).sum()
    }

    /// Replaces `tree` by its state at `iteration` (ungrow, or regrow up to the latest kept).
    pub fn go_to(&self, tree: &mut Tree, iteration: u32) -> Result<(), EditError> {
        *tree = self.at(iteration).ok_or(EditError::IterationNotKept {
            iteration,
            range: self.range(),
        })?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::species::Species;
    use std::collections::BTreeMap;

    fn sapling(seed: u64) -> Tree {
        Tree::new(Species::by_name("birch").expect("preset"), seed)
    }

    /// Grows `tree` `iterations` times, keeping each state; the saved bytes by iteration.
    fn grow_kept(
        tree: &mut Tree,
        timeline: &mut Timeline,
        iterations: u32,
        autonomous: bool,
    ) -> BTreeMap<u32, Vec<u8>> {
        let mut saved = BTreeMap::new();
        for _ in 0..iterations {
            tree.grow(1, None);
            if autonomous {
                timeline.keep_autonomous(tree);
            } else {
                timeline.keep(tree);
            }
            saved.insert(tree.iteration, tree.to_json_bytes().expect("json"));
            assert!(
                timeline.kept_bytes() as f64
                    <= f64::from(timeline.budget_trees) * tree.own_bytes() as f64 + 1.0
                    || timeline.budget_trees <= 0.0
                    || timeline.num_kept() <= 2,
                "{} bytes kept for a {}-byte tree",
                timeline.kept_bytes(),
                tree.own_bytes()
            );
        }
        saved
    }

    #[test]
    fn thinning_drops_the_big_old_difference_before_the_small_recent_ones() {
        // A seedling, a big difference (a tree grown autonomously from it, then shed), and a
        // dozen small brush-guided iterations on a tree of 2 MB.
        let seedling = sapling(1);
        let state = |iteration: u32, bytes: usize, tree_bytes: usize| Kept {
            iteration,
            held: Held::Whole(seedling.clone()),
            bytes,
            tree_bytes,
            autonomous: false,
        };
        let mut states = vec![state(1, 5_000, 5_000), state(18, 1_000_000, 2_000_000)];
        states.extend((30..42).map(|k| state(k, 1_000, 2_000_000)));
        states.push(state(42, 2_000_000, 2_000_000));
        let timeline = Timeline {
            states,
            budget_trees: 1.0,
            latest_own_bytes: 4_000_000,
        };
        let keep = timeline.choose_kept(2_100_000);
        let kept: Vec<u32> = keep.iter().map(|&i| timeline.states[i].iteration).collect();
        assert!(
            !kept.contains(&18),
            "the big difference goes first: {kept:?}"
        );
        assert!(
            (30..42).all(|k| kept.contains(&k)),
            "the recent iterations stay: {kept:?}"
        );
    }

    #[test]
    fn an_unbounded_timeline_ungrows_to_every_iteration_exactly_holding_less_than_copies() {
        let mut tree = sapling(2);
        let mut timeline = Timeline::default();
        timeline.keep(&tree);
        let mut copies_bytes = tree.saved_state_bytes();
        let mut saved = BTreeMap::from([(0, tree.to_json_bytes().expect("json"))]);
        for _ in 0..24 {
            tree.grow(1, None);
            timeline.keep(&tree);
            copies_bytes += tree.saved_state_bytes();
            saved.insert(tree.iteration, tree.to_json_bytes().expect("json"));
        }
        assert_eq!(timeline.num_kept(), 25);
        assert!(
            timeline.kept_bytes() * 3 < copies_bytes,
            "25 states hold {} bytes, whole copies {copies_bytes}",
            timeline.kept_bytes()
        );
        for (&k, bytes) in saved.iter().rev() {
            let mut back = tree.clone();
            timeline.go_to(&mut back, k).expect("kept");
            assert!(
                back.to_json_bytes().expect("json") == *bytes,
                "ungrow to {k}"
            );
        }
    }

    #[test]
    fn a_budgeted_timeline_stays_within_its_multiple_of_the_tree_and_ungrows_exactly() {
        let mut tree = sapling(3);
        let mut timeline = Timeline::with_budget(1.0);
        timeline.keep(&tree);
        let saved = grow_kept(&mut tree, &mut timeline, 40, false);
        assert_eq!(timeline.range(), Some((0, 40)), "first and latest stay");
        assert!(
            timeline.num_kept() < 41,
            "thinned: {} kept",
            timeline.num_kept()
        );
        let kept: Vec<u32> = (1..=40).filter(|&k| timeline.is_kept(k)).collect();
        // Whole copies of the tree would fit the budget this many times.
        let copies = tree.own_bytes() / tree.saved_state_bytes();
        assert!(
            kept.len() > 2 * copies,
            "the differences leave room for more states than {copies} copies: {} kept",
            kept.len()
        );
        for &k in &kept {
            let mut back = tree.clone();
            timeline.go_to(&mut back, k).expect("kept");
            assert!(
                back.to_json_bytes().expect("json") == saved[&k],
                "ungrow to {k}"
            );
        }
        let missing = (1..40)
            .find(|&k| !timeline.is_kept(k))
            .expect("one thinned");
        assert!(timeline.go_to(&mut tree.clone(), missing).is_err());
        let landed = timeline.kept_at_or_before(missing).expect("an earlier one");
        assert!(landed < missing && timeline.is_kept(landed));
        assert!(
            !timeline.regrows_autonomously(landed, missing),
            "kept by keep()"
        );
    }

    #[test]
    fn a_thinned_autonomous_iteration_regrows_exactly_from_the_state_before_it() {
        let mut tree = sapling(5);
        let mut timeline = Timeline::with_budget(0.3);
        timeline.keep(&tree);
        let saved = grow_kept(&mut tree, &mut timeline, 80, true);
        let missing = (1..80).find(|&k| !timeline.is_kept(k)).expect("thinned");
        let from = timeline.kept_at_or_before(missing).expect("earlier");
        assert!(timeline.regrows_autonomously(from, missing));
        let mut back = tree.clone();
        timeline.go_to(&mut back, from).expect("kept");
        back.grow(missing - from, None);
        assert!(back.to_json_bytes().expect("json") == saved[&missing]);
    }

    #[test]
    fn an_edit_after_ungrowing_replaces_the_later_states_and_the_earlier_ones_stay_exact() {
        let mut tree = sapling(7);
        let mut timeline = Timeline::default();
        timeline.keep(&tree);
        let saved = grow_kept(&mut tree, &mut timeline, 12, true);
        timeline.go_to(&mut tree, 6).expect("kept");
        // An edit at iteration 6 (a state of its own), then growth from it.
        let tip = tree.skeleton.internodes.last().expect("a tip").end;
        tree.environment
            .attraction
            .add_persistent(tip + glam::Vec3::new(0.1, 0.1, 0.0));
        timeline.keep(&tree);
        assert_eq!(timeline.range(), Some((0, 6)));
        let edited = tree.to_json_bytes().expect("json");
        let later = grow_kept(&mut tree, &mut timeline, 3, false);
        assert_eq!(timeline.range(), Some((0, 9)));
        assert!(
            !timeline.regrows_autonomously(6, 7),
            "the edit is not growth"
        );
        for k in 0..=5 {
            let mut back = tree.clone();
            timeline.go_to(&mut back, k).expect("kept");
            let expected = if k == 0 { None } else { saved.get(&k) };
            if let Some(expected) = expected {
                assert!(back.to_json_bytes().expect("json") == *expected, "{k}");
            }
        }
        let mut back = tree.clone();
        timeline.go_to(&mut back, 6).expect("kept");
        assert!(back.to_json_bytes().expect("json") == edited);
        timeline.go_to(&mut back, 8).expect("kept");
        assert!(back.to_json_bytes().expect("json") == later[&8]);
    }
}
