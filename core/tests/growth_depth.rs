//! Depth constraint (Longay 2014, appendix B): attraction points only within a depth of a plane
//! through the base, for autonomous growth as for brushing. The tree may reach slightly past the
//! depth (points steer growth; branches are not cut), but its crown is flat.

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::environment::DepthConstraint;
use sylva_core::species::Species;

const YEARS: f32 = 12.0;

fn grown(constraint: Option<DepthConstraint>) -> Tree {
    let mut tree = Tree::new(Species::by_name("oak").expect("oak preset"), 5);
    tree.environment.depth_constraint = constraint;
    tree.grow_years(YEARS);
    tree
}

/// 95th percentile of |z| and of |x| over the internode ends.
fn spread(tree: &Tree) -> (f32, f32) {
    let percentile = |mut v: Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[(v.len() * 95) / 100]
    };
    let nodes = &tree.skeleton.internodes;
    (
        percentile(nodes.iter().map(|n| n.end.z.abs()).collect()),
        percentile(nodes.iter().map(|n| n.end.x.abs()).collect()),
    )
}

#[test]
fn a_depth_constraint_flattens_autonomous_growth_to_its_depth() {
    let depth = 0.3;
    let free = grown(None);
    let flat = grown(DepthConstraint::new(Vec3::Z, depth));
    let l = flat.species.internode_length_m;
    let (free_z, free_x) = spread(&free);
    let (flat_z, flat_x) = spread(&flat);
    println!(
        "95th percentile |z| / |x|: free {free_z:.2} / {free_x:.2} m, flat {flat_z:.2} / {flat_x:.2} m"
    );
    assert!(
        free_z > depth + 3.0 * l,
        "the free crown is only {free_z} m deep"
    );
    assert!(
        flat_z <= depth + 2.0 * l,
        "the constrained crown reaches {flat_z} m from the plane (depth {depth} m)"
    );
    assert!(
        flat_x > 0.5 * free_x,
        "the constrained tree still spreads along the plane: {flat_x} vs {free_x} m"
    );
    flat.sanity_check().expect("sanity");
}

#[test]
fn a_bad_depth_constraint_is_refused() {
    assert!(DepthConstraint::new(Vec3::ZERO, 0.3).is_none());
    assert!(DepthConstraint::new(Vec3::Z, -1.0).is_none());
    assert!(DepthConstraint::new(Vec3::Z, f32::NAN).is_none());
}

#[test]
fn a_tree_file_keeps_its_depth_constraint_in_the_format_older_files_have() {
    let mut tree = Tree::new(Species::by_name("oak").expect("oak preset"), 5);
    tree.environment.depth_constraint = DepthConstraint::new(Vec3::Z, 0.3);
    tree.grow(3, None);
    let bytes = tree.to_json_bytes().expect("serialises");
    let json: serde_json::Value = serde_json::from_slice(&bytes).expect("json");
    let written = &json["tree"]["environment"]["depth_constraint"];
    let mut keys: Vec<&str> = written
        .as_object()
        .expect("a depth constraint object")
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort();
    // A slab through the base is written as files were before slabs had a centre, and such a
    // file (the same bytes) loads back to the same slab.
    assert_eq!(keys, ["depth_m", "normal"]);
    let loaded = Tree::from_json_bytes(&bytes).expect("loads");
    assert_eq!(
        loaded.environment.depth_constraint,
        tree.environment.depth_constraint
    );
    // A slab about another centre keeps it.
    let mut moved = tree.clone();
    moved.environment.depth_constraint =
        DepthConstraint::through(Vec3::new(1.0, 0.0, 2.0), Vec3::Z, 0.3);
    let reloaded =
        Tree::from_json_bytes(&moved.to_json_bytes().expect("serialises")).expect("loads");
    assert_eq!(
        reloaded.environment.depth_constraint,
        moved.environment.depth_constraint
    );
}
