//! Done-when item 6 of issue 3: PriMo bending restores circularly, stiffness r⁴/l makes thick
//! parts deform less, and with stretching disabled branch lengths are kept.

mod edit_common;

use edit_common::{max_displacement, trunk_with_branches};
use glam::Vec3;
use sylva_core::edit::{Bend, BendSettings, PositionalConstraint};
use sylva_core::tree::NodeId;

fn pin(node: NodeId, end_position: Vec3) -> PositionalConstraint {
    PositionalConstraint { node, end_position }
}

/// Angle (radians) between the rest and bent headings of an internode.
fn turn(
    before: &sylva_core::tree::Skeleton,
    after: &sylva_core::tree::Skeleton,
    id: NodeId,
) -> f32 {
    before
        .get(id)
        .heading()
        .angle_between(after.get(id).heading())
}

#[test]
fn moving_the_end_and_back_restores_every_internode_within_a_tenth_of_a_millimetre() {
    let (rest, trunk) = trunk_with_branches(40, 0.1, |k| 0.08 - 0.0018 * k as f32, 4);
    let mut tree = rest.clone();
    let bend = Bend::new(&tree, trunk[3], trunk[39], BendSettings::default()).expect("valid path");
    let end_rest = rest.get(trunk[39]).end;
    let middle_rest = rest.get(trunk[20]).end;
    let gestures = [
        vec![pin(trunk[39], end_rest + Vec3::new(1.2, -0.6, 0.3))],
        vec![
            pin(trunk[39], end_rest + Vec3::new(-0.8, -0.4, 0.0)),
            pin(trunk[20], middle_rest + Vec3::new(0.3, 0.0, 0.2)),
        ],
        vec![pin(trunk[39], end_rest + Vec3::new(0.0, 0.7, 0.0))],
    ];
    for constraints in &gestures {
        let pose = bend.solve(constraints).expect("solvable");
        bend.apply(&pose, &mut tree);
        tree.sanity_check().expect("bent tree stays connected");
        let moved = max_displacement(&rest, &tree);
        assert!(moved > 0.2, "the bend moved the tree by only {moved} m");
        let reached = tree
            .get(trunk[39])
            .end
            .distance(constraints[0].end_position);
        assert!(reached < 1e-3, "E missed its target by {reached} m");
        let back: Vec<_> = constraints
            .iter()
            .map(|c| pin(c.node, rest.get(c.node).end))
            .collect();
        let pose = bend.solve(&back).expect("solvable");
        bend.apply(&pose, &mut tree);
        let error = max_displacement(&rest, &tree);
        assert!(
            error < 1e-4,
            "moving the constraints back left an error of {error} m"
        );
    }
}

/// Total bending (sum of heading changes between neighbouring internodes) over trunk[range].
fn bending(
    rest: &sylva_core::tree::Skeleton,
    bent: &sylva_core::tree::Skeleton,
    trunk: &[NodeId],
    range: std::ops::Range<usize>,
) -> f32 {
    range
        .map(|k| (turn(rest, bent, trunk[k]) - turn(rest, bent, trunk[k - 1])).abs())
        .sum()
}

fn bend_tip(diameter: impl Fn(usize) -> f32, offset: Vec3) -> (f32, f32) {
    let (rest, trunk) = trunk_with_branches(30, 0.1, diameter, 0);
    let mut tree = rest.clone();
    let bend = Bend::new(&tree, trunk[0], trunk[29], BendSettings::default()).expect("valid path");
    let target = rest.get(trunk[29]).end + offset;
    bend.apply(
        &bend.solve(&[pin(trunk[29], target)]).expect("solvable"),
        &mut tree,
    );
    (
        bending(&rest, &tree, &trunk, 1..15),
        bending(&rest, &tree, &trunk, 16..30),
    )
}

#[test]
fn thick_internodes_bend_less_than_thin_ones_under_the_same_displacement() {
    let offset = Vec3::new(1.0, -0.5, 0.0);
    // Lower half 6 cm thick, upper half 1.5 cm: w = r⁴/l differs by 256×.
    let (thick, thin) = bend_tip(|k| if k < 15 { 0.06 } else { 0.015 }, offset);
    assert!(thin > 0.3, "the thin half turned only {thin} rad");
    assert!(
        thick < 0.25 * thin,
        "thick half bent {thick} rad, thin half {thin} rad"
    );
    // The same path, thin all along: its lower half takes a real share of the bend.
    let (lower, upper) = bend_tip(|_| 0.015, offset);
    println!(
        "bending (rad) lower/upper: thick/thin {thick:.3}/{thin:.3}, uniform {lower:.3}/{upper:.3}"
    );
    assert!(
        thick < 0.25 * lower,
        "thick lower half bent {thick} rad, thin lower half {lower} rad"
    );
}

fn path_length(tree: &sylva_core::tree::Skeleton, path: &[NodeId]) -> f32 {
    path.iter().map(|&id| tree.get(id).length()).sum()
}

#[test]
fn branch_lengths_change_by_under_one_percent_when_stretching_is_disabled() {
    let (rest, trunk) = trunk_with_branches(25, 0.1, |k| 0.05 - 0.0015 * k as f32, 3);
    let rest_length = path_length(&rest, &trunk);
    // Pull the tip upwards and sideways beyond its reach: only stretching can get it there.
    let target = rest.get(trunk[24]).end + Vec3::new(0.6, 0.8, 0.0);
    let stretchy = BendSettings::default();
    let rigid = BendSettings {
        allow_stretching: false,
        ..stretchy
    };
    let mut stretched = rest.clone();
    let bend = Bend::new(&stretched, trunk[0], trunk[24], stretchy).expect("valid path");
    bend.apply(
        &bend.solve(&[pin(trunk[24], target)]).expect("solvable"),
        &mut stretched,
    );
    let grown = path_length(&stretched, &trunk) / rest_length - 1.0;
    assert!(
        grown > 0.05,
        "with stretching the branch grew by only {grown}"
    );

    let mut kept = rest.clone();
    let bend = Bend::new(&kept, trunk[0], trunk[24], rigid).expect("valid path");
    bend.apply(
        &bend.solve(&[pin(trunk[24], target)]).expect("solvable"),
        &mut kept,
    );
    kept.sanity_check().expect("connected");
    for (a, b) in rest.internodes.iter().zip(&kept.internodes) {
        let change = (b.length() / a.length() - 1.0).abs();
        assert!(change < 0.01, "an internode length changed by {change}");
    }
    let total = (path_length(&kept, &trunk) / rest_length - 1.0).abs();
    assert!(total < 0.01, "branch length changed by {total}");
    assert!(
        max_displacement(&rest, &kept) > 0.3,
        "the rigid bend did not bend"
    );
}

#[test]
fn a_wider_prism_trades_bending_for_stretching() {
    let (rest, trunk) = trunk_with_branches(20, 0.1, |_| 0.04, 0);
    let target = rest.get(trunk[19]).end + Vec3::new(0.8, -0.4, 0.0);
    let stretch_for = |factor: f32| {
        let mut tree = rest.clone();
        let settings = BendSettings {
            prism_width_factor: factor,
            ..BendSettings::default()
        };
        let bend = Bend::new(&tree, trunk[0], trunk[19], settings).expect("valid path");
        bend.apply(
            &bend.solve(&[pin(trunk[19], target)]).expect("solvable"),
            &mut tree,
        );
        path_length(&tree, &trunk) / path_length(&rest, &trunk) - 1.0
    };
    let (narrow, wide) = (stretch_for(0.5), stretch_for(8.0));
    println!("length change: narrow prisms {narrow:.4}, wide prisms {wide:.4}");
    assert!(
        wide.abs() > narrow.abs() + 0.01,
        "length change with narrow prisms {narrow}, with wide prisms {wide}"
    );
}

#[test]
fn other_branches_keep_their_pose_relative_to_their_supporting_internode() {
    let (rest, trunk) = trunk_with_branches(24, 0.1, |_| 0.03, 4);
    let mut tree = rest.clone();
    let bend = Bend::new(&tree, trunk[0], trunk[23], BendSettings::default()).expect("valid path");
    let target = rest.get(trunk[23]).end + Vec3::new(0.9, -0.3, 0.4);
    bend.apply(
        &bend.solve(&[pin(trunk[23], target)]).expect("solvable"),
        &mut tree,
    );
    for k in (0..24).step_by(4) {
        let support = trunk[k];
        let branch = rest.get(support).lateral_children[0];
        let (h0, h1) = (rest.get(support).heading(), tree.get(support).heading());
        let (b0, b1) = (rest.get(branch).heading(), tree.get(branch).heading());
        let angle_change = (h0.angle_between(b0) - h1.angle_between(b1)).abs();
        assert!(
            angle_change < 1e-3,
            "branch at {k} changed its angle by {angle_change}"
        );
        assert!(tree.get(branch).start.distance(tree.get(support).end) < 1e-5);
    }
}

#[test]
fn bad_paths_and_constraints_are_refused_with_clear_errors() {
    let (tree, trunk) = trunk_with_branches(10, 0.1, |_| 0.03, 3);
    assert!(Bend::new(&tree, trunk[5], trunk[2], BendSettings::default()).is_err());
    assert!(Bend::new(&tree, NodeId(999), trunk[2], BendSettings::default()).is_err());
    let bend = Bend::new(&tree, trunk[2], trunk[9], BendSettings::default()).expect("valid path");
    let err = bend
        .solve(&[pin(trunk[1], Vec3::ZERO)])
        .expect_err("below the base");
    assert!(err.to_string().contains("not on the path"), "{err}");
    assert!(bend.solve(&[pin(trunk[9], Vec3::NAN)]).is_err());
}
