//! A wall (half-space) 1.5 m from the trunk: growing in front of it no internode crosses it;
//! pruning to it no internode remains behind it and widths are recomputed.

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::environment::{HalfSpace, Scene, SceneMode};
use sylva_core::species::Species;

const YEARS: u32 = 14;

fn wall() -> HalfSpace {
    // The wall's face is the plane x = 1.5 m; free space is towards the trunk (−X).
    HalfSpace::new(Vec3::new(1.5, 0.0, 0.0), Vec3::NEG_X)
}

fn oak(seed: u64) -> Tree {
    Tree::new(Species::by_name("oak").expect("oak preset"), seed)
}

fn max_x(tree: &Tree) -> f32 {
    tree.skeleton
        .internodes
        .iter()
        .map(|n| n.end.x.max(n.start.x))
        .fold(f32::MIN, f32::max)
}

#[test]
fn without_a_wall_the_test_tree_reaches_past_1_5_m() {
    let mut free = oak(3);
    free.grow(YEARS, None);
    assert!(
        max_x(&free) > 1.8,
        "the unconstrained tree only reaches x = {}",
        max_x(&free)
    );
}

#[test]
fn growing_in_front_of_a_wall_no_internode_crosses_it() {
    let wall = wall();
    let mut tree = oak(3);
    for _ in 0..YEARS {
        tree.grow(1, Some((&wall, SceneMode::GrowInFront)));
        for (i, n) in tree.skeleton.internodes.iter().enumerate() {
            assert!(
                wall.is_free(n.start) && wall.is_free(n.end),
                "internode {i} crosses the wall: {} → {}",
                n.start,
                n.end
            );
        }
    }
    assert!(
        max_x(&tree) > 1.0,
        "the tree never approached the wall (max x {})",
        max_x(&tree)
    );
    tree.sanity_check().expect("sane");
}

#[test]
fn pruning_to_a_wall_leaves_nothing_behind_it_and_recomputes_widths() {
    let wall = wall();
    let mut tree = oak(3);
    let mut pruned = 0;
    for _ in 0..YEARS {
        pruned += tree
            .grow(1, Some((&wall, SceneMode::PruneToScene)))
            .num_pruned_internodes;
        for (i, n) in tree.skeleton.internodes.iter().enumerate() {
            assert!(
                wall.is_segment_free(n.start, n.end) && wall.is_free(n.start),
                "internode {i} remains behind the wall: {} → {}",
                n.start,
                n.end
            );
        }
    }
    assert!(
        pruned > 0,
        "nothing grew into the wall, so nothing was pruned"
    );
    let mut fresh = tree.clone();
    fresh.update_widths();
    let widths = |t: &Tree| {
        t.skeleton
            .internodes
            .iter()
            .map(|n| n.diameter)
            .collect::<Vec<_>>()
    };
    assert_eq!(
        widths(&tree),
        widths(&fresh),
        "widths were not recomputed after pruning"
    );
    tree.sanity_check().expect("sane");
}
