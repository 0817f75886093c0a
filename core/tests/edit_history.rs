//! Done-when item 7 of issue 3: any random sequence of 50 operations undone step by step gives
//! a byte-identical tree at every step (and redone, too); ungrowing to iteration k equals the
//! tree saved at iteration k with the same seed and no edits.

use glam::{Vec2, Vec3};
use sylva_core::Rng;
use sylva_core::edit::{
    Bend, BendSettings, BrushPlane, BrushSettings, BrushStroke, EditError, History, Lasso,
    OperationKind, PositionalConstraint, StrokeCamera, Timeline, begin_selective_growth,
    end_selective_growth, prune_at, set_width_constraint, skeleton_at_iteration,
};
use sylva_core::growth::{StepOptions, Tree};
use sylva_core::species::Species;
use sylva_core::tree::NodeId;

const SEED: u64 = 0x0050_0e55;

fn bytes(tree: &Tree) -> Vec<u8> {
    tree.to_json_bytes().expect("serialises")
}

fn random_point_near(tree: &Tree, rng: &mut Rng) -> Vec3 {
    let n = tree.skeleton.len() as u32;
    let node = tree.skeleton.get(NodeId(rng.below(n)));
    node.end + rng.in_unit_ball() * 0.2
}

fn stroke(tree: &mut Tree, rng: &mut Rng) -> Result<(), EditError> {
    // A still camera 10 m in front of the plane z = 0.
    let camera = StrokeCamera::facing(BrushPlane::new(Vec3::ZERO, Vec3::Z)?, 10.0)?;
    let settings = BrushSettings {
        sketch_tropism: rng.below(2) == 1,
        ..BrushSettings::default()
    };
    let mut stroke = BrushStroke::new(10.0, settings)?;
    let start = random_point_near(tree, rng);
    stroke.add_point(0.0, camera, start, rng.range_f32(0.0, 0.5))?;
    stroke.add_point(
        0.2,
        camera,
        start + rng.in_unit_ball() * 0.6,
        rng.range_f32(0.0, 0.5),
    )?;
    for _ in 0..=rng.below(2) {
        stroke.iterate(tree);
    }
    Ok(())
}

fn bend(tree: &mut Tree, rng: &mut Rng) -> Result<(), EditError> {
    let end = NodeId(rng.below(tree.skeleton.len() as u32));
    let mut base = end;
    for _ in 0..(2 + rng.below(8)) {
        base = tree.skeleton.get(base).parent.unwrap_or(base);
    }
    let settings = BendSettings {
        allow_stretching: rng.below(2) == 1,
        ..BendSettings::default()
    };
    let bend = Bend::new(&tree.skeleton, base, end, settings)?;
    let target = tree.skeleton.get(end).end + rng.in_unit_ball() * 0.3;
    let pose = bend.solve(&[PositionalConstraint {
        node: end,
        end_position: target,
    }])?;
    bend.apply_to_tree(&pose, tree);
    Ok(())
}

fn lasso(tree: &mut Tree, rng: &mut Rng) -> Result<(), EditError> {
    let centre = random_point_near(tree, rng);
    let outline = (0..24)
        .map(|i| Vec2::from_angle(i as f32 / 24.0 * std::f32::consts::TAU) * 0.4)
        .collect();
    let lasso = Lasso::new(centre, Vec3::X, Vec3::Y, outline)?;
    lasso.envelope(32).add_points_to(tree, 60);
    tree.step(StepOptions {
        autonomous: false,
        scene: None,
    });
    Ok(())
}

fn selective(tree: &mut Tree, rng: &mut Rng) -> Result<(), EditError> {
    let pick = random_point_near(tree, rng);
    begin_selective_growth(tree, pick, rng.unit_vector())?;
    let result = stroke(tree, rng);
    end_selective_growth(tree);
    result
}

/// One random operation; returns its kind and whether it changed anything it could.
fn random_operation(
    history: &mut History,
    tree: &mut Tree,
    rng: &mut Rng,
) -> Result<OperationKind, EditError> {
    let choice = rng.below(8);
    let mut op_rng = rng.fork();
    let rng = &mut op_rng;
    let (kind, result) = match choice {
        0 => (
            OperationKind::Stroke,
            history.perform(OperationKind::Stroke, tree, |t| stroke(t, rng)),
        ),
        1 => (
            OperationKind::Grow,
            history.perform(OperationKind::Grow, tree, |t| {
                t.grow(1, None);
                Ok(())
            }),
        ),
        2 => (
            OperationKind::Prune,
            history.perform(OperationKind::Prune, tree, |t| {
                let pick = random_point_near(t, rng);
                prune_at(t, pick).map(|_| ())
            }),
        ),
        3 => (
            OperationKind::Bend,
            history.perform(OperationKind::Bend, tree, |t| bend(t, rng)),
        ),
        4 => (
            OperationKind::WidthConstraint,
            history.perform(OperationKind::WidthConstraint, tree, |t| {
                let id = NodeId(rng.below(t.skeleton.len() as u32));
                let width = t.skeleton.get(id).diameter * rng.range_f32(0.5, 2.0);
                set_width_constraint(t, id, Some(width))
            }),
        ),
        5 => (
            OperationKind::Parameters,
            history.perform(OperationKind::Parameters, tree, |t| {
                t.species.apical_dominance = rng.range_f32(0.3, 0.7);
                t.species.tropism_weight = rng.range_f32(0.05, 0.3);
                Ok(())
            }),
        ),
        6 => (
            OperationKind::Lasso,
            history.perform(OperationKind::Lasso, tree, |t| lasso(t, rng)),
        ),
        _ => (
            OperationKind::SelectiveGrowth,
            history.perform(OperationKind::SelectiveGrowth, tree, |t| selective(t, rng)),
        ),
    };
    result.map(|()| kind)
}

#[test]
fn fifty_random_operations_undo_and_redo_to_byte_identical_trees() {
    let mut tree = Tree::new(Species::by_name("oak").expect("oak"), SEED);
    tree.grow(4, None);
    let mut rng = Rng::new(SEED);
    let mut history = History::new(0);
    let mut before = Vec::new();
    let mut after = Vec::new();
    let mut kinds = Vec::new();
    let mut refused = 0;
    while before.len() < 50 {
        let snapshot = bytes(&tree);
        match random_operation(&mut history, &mut tree, &mut rng) {
            Ok(kind) => {
                before.push(snapshot);
                after.push(bytes(&tree));
                kinds.push(kind);
            }
            Err(_) => {
                refused += 1;
                assert_eq!(
                    bytes(&tree),
                    snapshot,
                    "a refused operation changed the tree"
                );
            }
        }
        tree.sanity_check().expect("sane after every operation");
    }
    println!(
        "50 operations ({refused} refused and left no trace), final tree {} internodes",
        tree.skeleton.len()
    );
    assert_eq!(history.num_undoable(), 50);
    for k in (0..50).rev() {
        assert_eq!(history.undo(&mut tree), Some(kinds[k]));
        assert!(
            bytes(&tree) == before[k],
            "undo of operation {k} ({:?}) is not byte-identical",
            kinds[k]
        );
    }
    assert_eq!(history.undo(&mut tree), None);
    for k in 0..50 {
        assert_eq!(history.redo(&mut tree), Some(kinds[k]));
        assert!(
            bytes(&tree) == after[k],
            "redo of operation {k} ({:?}) is not byte-identical",
            kinds[k]
        );
    }
    // A new operation after undoing forgets the redo branch.
    history.undo(&mut tree);
    history
        .perform(OperationKind::Grow, &mut tree, |t| {
            t.grow(1, None);
            Ok(())
        })
        .expect("grows");
    assert_eq!(history.num_redoable(), 0);
}

#[test]
fn ungrowing_to_iteration_k_equals_the_tree_saved_at_k() {
    let species = Species::by_name("birch").expect("birch");
    let mut tree = Tree::new(species.clone(), SEED);
    let mut timeline = Timeline::default();
    timeline.keep(&tree);
    let mut saved = Vec::new();
    for _ in 0..8 {
        saved.push(bytes(&tree));
        tree.grow(1, None);
        timeline.keep(&tree);
    }
    saved.push(bytes(&tree));
    for k in [0u32, 3, 5] {
        let mut fresh = Tree::new(species.clone(), SEED);
        fresh.grow(k, None);
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join(format!("tree_{k}.json"));
        fresh.save(&path).expect("saved");
        let on_disk = std::fs::read(&path).expect("read back");
        timeline.go_to(&mut tree, k).expect("kept");
        assert!(
            bytes(&tree) == on_disk,
            "ungrow to {k} differs from the tree saved at {k}"
        );
        let view = skeleton_at_iteration(&saved_tree(&saved[8]).skeleton, k);
        assert!(view.internodes.iter().all(|n| n.born_iteration <= k));
        view.sanity_check()
            .expect("the slider view is a valid skeleton");
    }
    timeline.go_to(&mut tree, 8).expect("regrow");
    assert!(bytes(&tree) == saved[8], "regrow to 8 differs");
    assert!(timeline.go_to(&mut tree, 9).is_err());
    // An edit at iteration 4 replaces the future.
    timeline.go_to(&mut tree, 4).expect("kept");
    tree.species.apical_dominance = 0.7;
    tree.grow(1, None);
    timeline.keep(&tree);
    assert_eq!(timeline.range(), Some((0, 5)));
}

fn saved_tree(bytes: &[u8]) -> Tree {
    Tree::from_json_bytes(bytes).expect("loads")
}
