//! Property tests over random parameters: no NaN or infinite value anywhere, widths never
//! increase from parent to child and satisfy the pipe model within 1e-6 relative, the tree stays
//! connected, and `sanity_check()` holds after every iteration.

use proptest::prelude::*;
use sylva_core::Tree;
use sylva_core::species::{Phyllotaxis, Species};

const ITERATIONS: u32 = 7;

prop_compose! {
    fn random_species()(
        lambda in 0.3f32..0.75,
        kappa in 0.0f32..3.0,
        weights in (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1.0),
        theta in 0.0f32..180.0,
        psi in 5.0f32..85.0,
        delta in 0.0f32..40.0,
        r in 0.5f32..3.0,
        d in 0.5f32..3.0,
        zeta in 30.0f32..300.0,
        th in 0.0f32..0.3,
        phyllotaxis in 0usize..4,
        k in 1u32..6,
        n_max in 1.0f32..9.0,
        e_v in -0.9f32..0.9,
        s_v in 0.3f32..2.0,
        n in 1.5f32..3.0,
        upward in any::<bool>(),
        at_end in any::<bool>(),
    ) -> Species {
        let mut s = Species::by_name("oak").expect("oak preset");
        s.apical_dominance = lambda;
        s.light_sensitivity = kappa;
        let total = (weights.0 + weights.1 + weights.2).max(1e-3);
        s.straightness = weights.0 / total;
        s.tropism_weight = weights.1 / total;
        s.environment_weight = 1.0 - s.straightness - s.tropism_weight;
        s.gravitropism_angle_deg = theta;
        s.branching_angle_deg = psi;
        s.deflection_angle_deg = delta;
        s.occupancy_radius_internodes = r;
        s.perception_distance_internodes = d;
        s.perception_angle_deg = zeta;
        s.shedding_threshold = th;
        s.phyllotaxis = [Phyllotaxis::Distichous, Phyllotaxis::Spiral, Phyllotaxis::Decussate, Phyllotaxis::Whorled][phyllotaxis];
        s.buds_per_whorl = k;
        s.max_shoot_internodes = n_max;
        s.gravimorphism.vertical_offset = e_v;
        s.gravimorphism.vertical_semi_axis = s_v;
        s.pipe_exponent = n;
        s.upward_main_axis = upward;
        s.lateral_buds_only_at_shoot_end = at_end;
        s
    }
}

fn check_tree(tree: &Tree) -> Result<(), TestCaseError> {
    if let Err(e) = tree.sanity_check() {
        return Err(TestCaseError::fail(format!(
            "sanity check after iteration {}: {e}",
            tree.iteration
        )));
    }
    let nodes = &tree.skeleton.internodes;
    for (i, node) in nodes.iter().enumerate() {
        let vectors = [node.start, node.end, node.left];
        prop_assert!(
            vectors.iter().all(|v| v.is_finite()),
            "internode {i} has a non-finite vector"
        );
        prop_assert!(
            node.diameter.is_finite() && node.diameter > 0.0,
            "internode {i} diameter {}",
            node.diameter
        );
        prop_assert!(node.light_exposure.is_finite());
        for bud in node.terminal_bud.iter().chain(&node.lateral_buds) {
            prop_assert!(
                bud.direction.is_finite(),
                "internode {i} has a non-finite bud"
            );
        }
        if node.is_tip() {
            continue;
        }
        // Pipe model d^n = Σ d_i^n, in f64 from the stored widths.
        let n = f64::from(tree.pipe_exponent(sylva_core::NodeId(i as u32)));
        let parent = f64::from(node.diameter).powf(n);
        let children: f64 = node
            .children()
            .map(|c| f64::from(nodes[c.index()].diameter).powf(n))
            .sum();
        prop_assert!(
            (parent - children).abs() <= 1e-6 * parent,
            "internode {i}: d^n = {parent:e} but Σ children d^n = {children:e} (n = {n})"
        );
        for c in node.children() {
            prop_assert!(
                nodes[c.index()].diameter <= node.diameter,
                "child {} is wider than its parent {i}",
                c.0
            );
        }
    }
    // Connected: every internode reaches the root through its parents (indices decrease).
    for (i, node) in nodes.iter().enumerate() {
        let mut current = node.parent;
        let mut steps = 0;
        while let Some(p) = current {
            current = nodes[p.index()].parent;
            steps += 1;
            prop_assert!(steps <= nodes.len(), "internode {i} has a cycle above it");
        }
        prop_assert!(i == 0 || steps > 0);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn random_parameters_keep_the_tree_finite_connected_and_pipe_consistent(
        species in random_species(),
        seed in any::<u64>(),
    ) {
        prop_assert!(species.validate().is_ok(), "{:?}", species.validate());
        let mut tree = Tree::new(species, seed);
        check_tree(&tree)?;
        for _ in 0..ITERATIONS {
            tree.grow(1, None);
            check_tree(&tree)?;
        }
    }
}

#[test]
fn a_width_constraint_is_met_by_re_solving_the_subtree_exponent() {
    let mut tree = Tree::new(Species::by_name("maple").expect("maple"), 5);
    tree.grow(6, None);
    let tips = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.is_tip())
        .count();
    assert!(tips > 10, "only {tips} tips");
    tree.skeleton.internodes[0].width_constraint = Some(0.2);
    tree.update_widths();
    assert_eq!(tree.skeleton.internodes[0].diameter, 0.2);
    let n = f64::from(tree.pipe_exponent(sylva_core::NodeId(0)));
    let closed = (tips as f64).ln() / (0.2f64.ln() - f64::from(tree.species.tip_diameter_m).ln());
    assert!(
        (n - closed).abs() < 1e-4,
        "Newton n = {n}, closed form {closed}"
    );
    let nodes = &tree.skeleton.internodes;
    let sum: f64 = nodes[0]
        .children()
        .map(|c| f64::from(nodes[c.index()].diameter).powf(n))
        .sum();
    assert!((sum - 0.2f64.powf(n)).abs() < 1e-5 * 0.2f64.powf(n));
}
