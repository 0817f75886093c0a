//! Undo steps as differences: what an operation changed in a tree, kept as the parts of the
//! state before it that differ from the state after it, so that applying the difference to the
//! state after gives back the state before exactly (the same saved bytes).
//!
//! The difference is taken between two whole growth states, whatever the operation was: a
//! brush-guided iteration appends internodes and changes the buds, diameters and light of some
//! others; a prune drops a subtree and renumbers what follows it; a bend moves a chain; a width
//! change sets one constraint and the diameters below it. Internodes are matched across the
//! renumbering by where they lie and when they were born; each one that differs is kept once:
//! only its diameter and light exposure when nothing else changed (the pipe model and the
//! shadow change those in many internodes each iteration), else whole. Attraction points and a
//! garden's neighbour nodes are kept as the elements the state after lost (points are appended
//! by strokes and consumed from anywhere, the rest keeping their order). Everything else of the
//! state (species, iteration, generator, depth constraint, growth mask) is small and kept whole.
//! Whatever the matching finds, the state before is given back exactly: a difference records
//! every internode and point that the matching would not give back as it was.

use std::mem::size_of;

use glam::Vec3;

use crate::environment::AttractionPoint;
use crate::growth::Tree;
use crate::tree::{Internode, NodeId};

/// What turns the state after an operation back into the state before it.
#[derive(Clone, Debug)]
pub(crate) struct TreeDiff {
    /// The state before, with its skeleton, attraction points and neighbour nodes taken out
    /// (compact: no derived state).
    shell: Tree,
    internodes: InternodeDiff,
    points: Splice<AttractionPoint>,
    neighbour_nodes: Splice<Vec3>,
    /// Lengths of the state after's internodes, attraction points and neighbour nodes: a tree
    /// of other lengths is not the state this difference was taken against.
    after_lens: [usize; 3],
}

/// The lengths a difference is checked against.
fn lens(tree: &Tree) -> [usize; 3] {
    [
        tree.skeleton.internodes.len(),
        tree.environment.attraction.points.len(),
        tree.environment.neighbour_nodes.len(),
    ]
}

impl TreeDiff {
    /// The difference that turns `after` back into `before` (a compact copy, as
    /// [`Tree::compact_clone`] makes).
    pub(crate) fn between(mut before: Tree, after: &Tree) -> TreeDiff {
        let internodes = std::mem::take(&mut before.skeleton.internodes);
        let points = std::mem::take(&mut before.environment.attraction.points);
        let neighbour_nodes = std::mem::take(&mut before.environment.neighbour_nodes);
        TreeDiff {
            internodes: InternodeDiff::between(internodes, &after.skeleton.internodes),
            points: Splice::between(points, &after.environment.attraction.points),
            neighbour_nodes: Splice::between(neighbour_nodes, &after.environment.neighbour_nodes),
            after_lens: lens(after),
            shell: before,
        }
    }

    /// The state before (compact: [`Tree::restore_derived`] makes it whole) from `after`, the
    /// state this difference was taken against (`None` for a tree whose lengths differ from it).
    pub(crate) fn apply(self, after: &Tree) -> Option<Tree> {
        if lens(after) != self.after_lens {
            return None;
        }
        let mut before = self.shell;
        before.skeleton.internodes = self.internodes.apply(&after.skeleton.internodes);
        before.environment.attraction.points =
            self.points.apply(&after.environment.attraction.points);
        before.environment.neighbour_nodes = self
            .neighbour_nodes
            .apply(&after.environment.neighbour_nodes);
        Some(before)
    }

    /// Heap and inline bytes this difference holds.
    pub(crate) fn bytes(&self) -> usize {
        // The shell's own vectors are empty; its saved-state size is its inline size.
        self.shell.saved_state_bytes() - size_of::<Tree>()
            + size_of::<TreeDiff>()
            + self.internodes.heap_bytes()
            + self.points.heap_bytes()
            + self.neighbour_nodes.heap_bytes()
    }
}

/// The internodes before, as runs of internodes after (renumbered: growth sheds and a prune
/// removes internodes, compacting the arena, and appends new ones) and those that differ.
#[derive(Clone, Debug, Default)]
struct InternodeDiff {
    /// Number of internodes before.
    len: u32,
    /// Runs of internodes before that are internodes after, their references renumbered
    /// ([`renumbered`]), in increasing index.
    runs: Vec<Run>,
    /// Internodes before that no internode after gives back, whole, in increasing index.
    whole: Vec<(NodeId, Internode)>,
    /// Diameter and light exposure before of internodes given back otherwise unchanged.
    measures: Vec<Measures>,
}

/// Internodes `before..before + len` before are `after..after + len` after.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    before: u32,
    after: u32,
    len: u32,
}

#[derive(Clone, Copy, Debug)]
struct Measures {
    id: NodeId,
    diameter: f32,
    light_exposure: f32,
}

/// What identifies an internode across renumbering: where it lies and when it was born.
fn identity(node: &Internode) -> [u32; 7] {
    let [a, b, c] = node.start.to_array().map(f32::to_bits);
    let [d, e, f] = node.end.to_array().map(f32::to_bits);
    [a, b, c, d, e, f, node.born_iteration]
}

/// Internode `id` after, its references renumbered to the numbering before through
/// `before_from_after` (a reference to an internode with no counterpart is kept as it is).
fn renumbered(node: &Internode, before_from_after: &[u32]) -> Internode {
    let map = |id: NodeId| match before_from_after.get(id.index()) {
        Some(&b) if b != u32::MAX => NodeId(b),
        _ => id,
    };
    let mut node = node.clone();
    node.parent = node.parent.map(map);
    node.main_child = node.main_child.map(map);
    for child in node.lateral_children.iter_mut() {
        *child = map(*child);
    }
    node
}

/// For each internode after, the one before it came from (`u32::MAX` for none).
fn before_from_after(runs: &[Run], num_after: usize) -> Vec<u32> {
    let mut map = vec![u32::MAX; num_after];
    for run in runs {
        for k in 0..run.len {
            map[(run.after + k) as usize] = run.before + k;
        }
    }
    map
}

impl InternodeDiff {
    fn between(before: Vec<Internode>, after: &[Internode]) -> InternodeDiff {
        let after_by_identity: std::collections::HashMap<[u32; 7], u32> = after
            .iter()
            .enumerate()
            .map(|(j, n)| (identity(n), j as u32))
            .collect();
        let mut runs: Vec<Run> = Vec::new();
        let mut claimed = vec![false; after.len()];
        for (i, node) in before.iter().enumerate() {
            let Some(&j) = after_by_identity.get(&identity(node)) else {
                continue;
            };
            if std::mem::replace(&mut claimed[j as usize], true) {
                continue;
            }
            match runs.last_mut() {
                Some(run) if run.before + run.len == i as u32 && run.after + run.len == j => {
                    run.len += 1
                }
                _ => runs.push(Run {
                    before: i as u32,
                    after: j,
                    len: 1,
                }),
            }
        }
        drop(after_by_identity);
        let map = before_from_after(&runs, after.len());
        let mut diff = InternodeDiff {
            len: before.len() as u32,
            ..InternodeDiff::default()
        };
        let mut run = runs.iter().peekable();
        for (i, old) in before.into_iter().enumerate() {
            let i = i as u32;
            while run.next_if(|r| r.before + r.len <= i).is_some() {}
            let given = run
                .peek()
                .filter(|r| r.before <= i)
                .map(|r| renumbered(&after[(r.after + i - r.before) as usize], &map));
            match given {
                Some(new) if new == old => {}
                Some(new) if same_but_measures(&old, &new) => diff.measures.push(Measures {
                    id: NodeId(i),
                    diameter: old.diameter,
                    light_exposure: old.light_exposure,
                }),
                _ => diff.whole.push((NodeId(i), old)),
            }
        }
        runs.shrink_to_fit();
        diff.runs = runs;
        diff.whole.shrink_to_fit();
        diff.measures.shrink_to_fit();
        diff
    }

    fn apply(self, after: &[Internode]) -> Vec<Internode> {
        let map = before_from_after(&self.runs, after.len());
        let mut internodes = Vec::with_capacity(self.len as usize);
        let mut whole = self.whole.into_iter().peekable();
        let mut run = self.runs.iter().peekable();
        for i in 0..self.len {
            if let Some((_, node)) = whole.next_if(|(id, _)| id.0 == i) {
                internodes.push(node);
                continue;
            }
            while run.next_if(|r| r.before + r.len <= i).is_some() {}
            // Every internode before is in a run or whole (see `between`).
            let r = run
                .peek()
                .expect("an internode before is in a run or whole");
            internodes.push(renumbered(&after[(r.after + i - r.before) as usize], &map));
        }
        for m in self.measures {
            let node = &mut internodes[m.id.index()];
            node.diameter = m.diameter;
            node.light_exposure = m.light_exposure;
        }
        internodes
    }

    fn heap_bytes(&self) -> usize {
        let spilled: usize = self
            .whole
            .iter()
            .map(|(_, n)| crate::growth::snapshot::spilled_bytes(n))
            .sum();
        self.runs.capacity() * size_of::<Run>()
            + self.whole.capacity() * size_of::<(NodeId, Internode)>()
            + self.measures.capacity() * size_of::<Measures>()
            + spilled
    }
}

/// Whether two internodes differ in nothing but their diameter and light exposure. Every field
/// is named, so a new one cannot be forgotten here.
fn same_but_measures(a: &Internode, b: &Internode) -> bool {
    let Internode {
        parent,
        main_child,
        lateral_children,
        start,
        end,
        left,
        diameter: _,
        order,
        born_iteration,
        terminal_bud,
        lateral_buds,
        width_constraint,
        light_exposure: _,
    } = a;
    *parent == b.parent
        && *main_child == b.main_child
        && *lateral_children == b.lateral_children
        && *start == b.start
        && *end == b.end
        && *left == b.left
        && *order == b.order
        && *born_iteration == b.born_iteration
        && *terminal_bud == b.terminal_bud
        && *lateral_buds == b.lateral_buds
        && *width_constraint == b.width_constraint
}

/// A sequence before, as the elements of the sequence after that it keeps, in order, and the
/// ones it had that the sequence after does not (a growth step removes consumed points from
/// anywhere, keeping the order of the rest, and a stroke appends new ones).
#[derive(Clone, Debug)]
struct Splice<T> {
    /// Number of elements before.
    len: usize,
    /// Elements before not taken from the sequence after, with their index before, in order.
    removed: Vec<(u32, T)>,
}

impl<T: Clone + PartialEq> Splice<T> {
    fn between(before: Vec<T>, after: &[T]) -> Splice<T> {
        let len = before.len();
        let mut next = 0;
        let mut removed = Vec::new();
        for (i, old) in before.into_iter().enumerate() {
            if after.get(next) == Some(&old) {
                next += 1;
            } else {
                removed.push((i as u32, old));
            }
        }
        removed.shrink_to_fit();
        Splice { len, removed }
    }

    fn apply(self, after: &[T]) -> Vec<T> {
        let mut before = Vec::with_capacity(self.len);
        let mut removed = self.removed.into_iter().peekable();
        let mut kept = after.iter();
        for i in 0..self.len as u32 {
            match removed.next_if(|(at, _)| *at == i) {
                Some((_, old)) => before.push(old),
                // Every element before is either removed or the next kept one (see `between`).
                None => before.extend(kept.next().cloned()),
            }
        }
        before
    }

    fn heap_bytes(&self) -> usize {
        self.removed.capacity() * size_of::<(u32, T)>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::{prune_at, set_width_constraint};
    use crate::species::Species;

    fn round_trip(before: &Tree, after: &Tree) -> usize {
        let diff = TreeDiff::between(before.compact_clone(), after);
        let bytes = diff.bytes();
        let mut back = diff.apply(after).expect("taken against it");
        back.restore_derived();
        assert!(
            back.to_json_bytes().expect("json") == before.to_json_bytes().expect("json"),
            "the difference gives back the state before"
        );
        assert!(back == *before, "and the same growth state");
        bytes
    }

    #[test]
    fn a_growth_step_prune_and_width_change_undo_exactly_from_their_differences() {
        let mut tree = Tree::new(Species::by_name("oak").expect("preset"), 7);
        tree.grow(10, None);
        let before = tree.clone();
        tree.grow(1, None);
        let grown = round_trip(&before, &tree);
        assert!(
            grown < tree.saved_state_bytes() / 2,
            "one iteration's difference holds {grown} bytes of a {}-byte tree",
            tree.saved_state_bytes()
        );

        let before = tree.clone();
        let pick = tree.skeleton.internodes[tree.skeleton.len() / 2].end;
        prune_at(&mut tree, pick).expect("a branch to prune");
        round_trip(&before, &tree);

        let before = tree.clone();
        set_width_constraint(&mut tree, NodeId(3), Some(0.05)).expect("width");
        let widened = round_trip(&before, &tree);
        assert!(widened < tree.saved_state_bytes() / 2, "{widened} bytes");
    }

    #[test]
    fn a_difference_restores_a_larger_or_smaller_tree_and_changed_points() {
        let mut small = Tree::new(Species::by_name("birch").expect("preset"), 2);
        small.grow(3, None);
        let mut large = small.clone();
        large.grow(4, None);
        large
            .environment
            .attraction
            .add_persistent(Vec3::new(0.1, 1.0, 0.2));
        round_trip(&small, &large);
        round_trip(&large, &small);
        round_trip(&small, &small);
    }

    #[test]
    fn a_splice_keeps_only_the_elements_the_sequence_after_lost() {
        let before = vec![1, 2, 3, 4, 5, 6];
        // 2 and 5 consumed, 9 and 9 appended.
        let after = [1, 3, 4, 6, 9, 9];
        let splice = Splice::between(before.clone(), &after);
        assert_eq!(splice.removed, vec![(1, 2), (4, 5)]);
        assert_eq!(splice.apply(&after), before);
        // Any two sequences round-trip, however unlike.
        for (a, b) in [
            (vec![3, 1, 2], vec![1, 2, 3]),
            (vec![], vec![7]),
            (vec![7, 7], vec![]),
        ] {
            assert_eq!(Splice::between(a.clone(), &b).apply(&b), a);
        }
    }
}
