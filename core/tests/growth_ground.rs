//! The ground: the horizontal plane through the tree's base. No shoot grows below it and no
//! attraction point below it feeds a bud, so a weeping willow's curtain stops at the lawn
//! instead of hanging metres into the earth.

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::growth::StepOptions;
use sylva_core::species::Species;

fn lowest_point(tree: &Tree) -> f32 {
    tree.skeleton
        .internodes
        .iter()
        .map(|n| n.start.y.min(n.end.y))
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn a_weeping_willow_hangs_down_to_the_ground_and_no_further() {
    for seed in [11, 3] {
        let mut tree = Tree::new(Species::by_name("weeping_willow").expect("preset"), seed);
        for _ in 0..12 {
            tree.grow(1, None);
            let lowest = lowest_point(&tree);
            assert!(
                lowest >= tree.ground_y(),
                "seed {seed}, year {}: a branch reaches {lowest} m, below the ground",
                tree.iteration
            );
        }
        // The curtain does reach the ground: the rule is what stops it.
        let near_ground = tree
            .skeleton
            .internodes
            .iter()
            .filter(|n| n.end.y < 0.25 && n.order > 0)
            .count();
        println!(
            "seed {seed}: {} internodes, {near_ground} branch ends within 25 cm of the ground",
            tree.skeleton.len()
        );
        assert!(
            near_ground >= 20,
            "seed {seed}: only {near_ground} branch ends came near the ground"
        );
        tree.sanity_check().expect("sane");
    }
}

#[test]
fn brushed_points_below_the_ground_are_dropped_and_grow_nothing() {
    let mut tree = Tree::new(Species::by_name("maple").expect("preset"), 5);
    tree.grow(3, None);
    let height = tree.metrics().height_m;
    // A dab straddling the ground beside the trunk, and one in the crown.
    let beside = Vec3::new(0.5, 0.0, 0.0);
    let crown = Vec3::new(0.0, height + 0.15, 0.0);
    for k in 0..200 {
        let t = k as f32 / 200.0;
        let around = Vec3::new((t * 37.0).sin(), (t * 23.0).cos(), (t * 51.0).sin()) * 0.2;
        tree.environment.attraction.add_persistent(beside + around);
        tree.environment.attraction.add_persistent(crown + around);
    }
    let before = tree.skeleton.len();
    for _ in 0..4 {
        tree.step(StepOptions {
            autonomous: false,
            scene: None,
        });
        assert!(
            tree.environment
                .attraction
                .points
                .iter()
                .all(|p| p.position.y >= tree.ground_y()),
            "a point below the ground survived a step"
        );
    }
    assert!(
        tree.skeleton.len() > before,
        "the crown dab grew nothing ({before} internodes before and after)"
    );
    assert!(lowest_point(&tree) >= tree.ground_y());
}
