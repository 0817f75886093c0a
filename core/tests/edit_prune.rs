//! Done-when item 5 of issue 3: prune removes exactly the subtree above the chosen branching
//! point, the remaining widths equal a fresh pipe-model computation, a width constraint below
//! keeps the stub's width; and width constraints in general.

use sylva_core::edit::{branch_to_prune, prune_at, set_width_constraint};
use sylva_core::growth::Tree;
use sylva_core::species::Species;
use sylva_core::tree::NodeId;

fn grown() -> Tree {
    let mut tree = Tree::new(Species::by_name("oak").expect("oak"), 0xC0FFEE);
    tree.grow(8, None);
    tree
}

/// A point on a lateral branch of order 1 that carries a few internodes.
fn pick_on_a_branch(tree: &Tree) -> glam::Vec3 {
    let s = &tree.skeleton;
    let id = (1..s.len())
        .map(|i| NodeId(i as u32))
        .find(|&id| {
            s.get(id).order == 1
                && s.get(id)
                    .main_child
                    .is_some_and(|c| s.get(c).main_child.is_some())
        })
        .expect("a lateral branch with three internodes");
    let child = s.get(id).main_child.expect("checked");
    s.get(child).start.lerp(s.get(child).end, 0.5)
}

#[test]
fn prune_removes_exactly_the_subtree_and_widths_are_recomputed() {
    let mut tree = grown();
    let before = tree.clone();
    let pick = pick_on_a_branch(&tree);
    let (root, stub) = branch_to_prune(&tree.skeleton, pick).expect("a branch");
    let flags = before.skeleton.subtree_flags(&[root]);
    let expected_removed = flags.iter().filter(|&&f| f).count();
    let pruned = prune_at(&mut tree, pick).expect("pruned");
    assert_eq!((pruned.root, pruned.stub), (root, stub));
    assert_eq!(pruned.num_removed, expected_removed);
    assert!(
        before.skeleton.get(stub).children().count() > 1,
        "the cut is at a branching point"
    );
    // Survivors are the old internodes outside the subtree, in order, in place.
    let survivors: Vec<_> = before
        .skeleton
        .internodes
        .iter()
        .zip(&flags)
        .filter(|(_, f)| !**f)
        .map(|(n, _)| n)
        .collect();
    assert_eq!(survivors.len(), tree.skeleton.len());
    for (old, new) in survivors.iter().zip(&tree.skeleton.internodes) {
        assert_eq!(
            (old.start, old.end, old.born_iteration),
            (new.start, new.end, new.born_iteration)
        );
    }
    tree.sanity_check().expect("sane after pruning");
    // Widths: as a fresh pipe-model computation of the pruned skeleton.
    let mut fresh = tree.clone();
    for node in &mut fresh.skeleton.internodes {
        node.diameter = 0.0;
    }
    fresh.update_widths();
    for (a, b) in tree
        .skeleton
        .internodes
        .iter()
        .zip(&fresh.skeleton.internodes)
    {
        assert!(
            (a.diameter - b.diameter).abs() <= 1e-6 * b.diameter.max(1e-6),
            "{} vs {}",
            a.diameter,
            b.diameter
        );
    }
    let thinner = tree.skeleton.internodes[0].diameter < before.skeleton.internodes[0].diameter;
    assert!(
        thinner,
        "the trunk did not get thinner after losing a branch"
    );
}

#[test]
fn a_width_constraint_just_below_keeps_the_stub_width() {
    let mut tree = grown();
    let pick = pick_on_a_branch(&tree);
    let (_, stub) = branch_to_prune(&tree.skeleton, pick).expect("a branch");
    let width = tree.skeleton.get(stub).diameter;
    set_width_constraint(&mut tree, stub, Some(width)).expect("constraint");
    prune_at(&mut tree, pick).expect("pruned");
    let after = tree.skeleton.get(stub).diameter;
    assert!(
        (after - width).abs() < 1e-7,
        "stub width {after}, constrained to {width}"
    );
}

#[test]
fn width_constraints_set_the_width_and_the_pipe_model_holds_around_them() {
    let mut tree = grown();
    let trunk_mid = {
        let mut id = NodeId(0);
        for _ in 0..3 {
            id = tree.skeleton.get(id).main_child.expect("a trunk");
        }
        id
    };
    let wanted = tree.skeleton.get(trunk_mid).diameter * 2.0;
    set_width_constraint(&mut tree, trunk_mid, Some(wanted)).expect("constraint");
    assert!((tree.skeleton.get(trunk_mid).diameter - wanted).abs() < 1e-7);
    for (i, node) in tree.skeleton.internodes.iter().enumerate() {
        if node.is_tip() || node.width_constraint.is_some() {
            continue;
        }
        let n = f64::from(tree.pipe_exponent(NodeId(i as u32)));
        let sum: f64 = node
            .children()
            .map(|c| f64::from(tree.skeleton.get(c).diameter).powf(n))
            .sum();
        let own = f64::from(node.diameter).powf(n);
        assert!(
            (own - sum).abs() <= 1e-4 * own,
            "pipe model broken at {i}: {own} vs {sum}"
        );
    }
    assert!(set_width_constraint(&mut tree, trunk_mid, Some(-1.0)).is_err());
    assert!(set_width_constraint(&mut tree, NodeId(1 << 30), Some(0.1)).is_err());
    set_width_constraint(&mut tree, trunk_mid, None).expect("cleared");
    assert!(tree.skeleton.get(trunk_mid).diameter < wanted * 0.75);
}
