//! Issue 3, done-when item 8: a brush-guided iteration on a 20k-internode tree (target ≤ 4 ms on
//! one core) and a bend solve on a 200-internode path (target ≤ 2 ms).

use std::hint::black_box;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use sylva_core::edit::{
    Bend, BendSettings, BrushPlane, BrushSettings, BrushStroke, PositionalConstraint, StrokeCamera,
};
use sylva_core::growth::Tree;
use sylva_core::species::Species;
use sylva_core::tree::{Bud, Children, Internode, LateralBuds, NodeId, Skeleton};

/// A 200-internode tapering trunk (0.1 m internodes) with a 3-internode branch every 5th node.
fn trunk_200() -> (Skeleton, Vec<NodeId>) {
    let mut skeleton = Skeleton {
        internodes: Vec::new(),
    };
    let node = |parent: Option<NodeId>, start: Vec3, dir: Vec3, diameter: f32| Internode {
        parent,
        main_child: None,
        lateral_children: Children::new(),
        start,
        end: start + dir * 0.1,
        left: dir.any_orthonormal_vector(),
        diameter,
        order: 0,
        born_iteration: 0,
        terminal_bud: Some(Bud::new(dir)),
        lateral_buds: LateralBuds::new(),
        width_constraint: None,
        light_exposure: 1.0,
    };
    let mut trunk = Vec::new();
    for k in 0..200 {
        let parent = trunk.last().copied();
        let d = 0.2 * (1.0 - k as f32 / 200.0) + 0.01;
        skeleton
            .internodes
            .push(node(parent, Vec3::Y * (k as f32 * 0.1), Vec3::Y, d));
        let id = NodeId(k as u32);
        if let Some(p) = parent {
            skeleton.internodes[p.index()].main_child = Some(id);
        }
        trunk.push(id);
    }
    for &k in trunk.iter().step_by(5) {
        let mut parent = k;
        for j in 0..3 {
            let start = skeleton.get(parent).end;
            let id = NodeId(skeleton.len() as u32);
            skeleton
                .internodes
                .push(node(Some(parent), start, Vec3::X, 0.01));
            if j == 0 {
                skeleton.internodes[parent.index()]
                    .lateral_children
                    .push(id);
            } else {
                skeleton.internodes[parent.index()].main_child = Some(id);
            }
            parent = id;
        }
    }
    (skeleton, trunk)
}

fn bend(c: &mut Criterion) {
    let (skeleton, trunk) = trunk_200();
    let bend = Bend::new(&skeleton, trunk[0], trunk[199], BendSettings::default()).expect("path");
    let tip = skeleton.get(trunk[199]).end;
    let mut group = c.benchmark_group("bend_solve_200_internode_path");
    for (name, offset) in [
        ("tip_moved_1m", Vec3::new(1.0, -0.3, 0.0)),
        ("tip_moved_2m", Vec3::new(2.0, -0.6, 0.0)),
    ] {
        let constraint = [PositionalConstraint {
            node: trunk[199],
            end_position: tip + offset,
        }];
        group.bench_function(name, |b| {
            b.iter(|| black_box(bend.solve(black_box(&constraint))))
        });
    }
    group.finish();
}

fn tree_of_about(internodes: usize) -> Tree {
    let species = Species::by_name("oak").expect("oak preset");
    let mut tree = Tree::new(species, 7);
    while tree.skeleton.len() < internodes {
        tree.grow(1, None);
    }
    tree
}

fn brush(c: &mut Criterion) {
    let tree = tree_of_about(20_000);
    eprintln!("brush bench tree: {} internodes", tree.skeleton.len());
    let top = tree
        .skeleton
        .internodes
        .iter()
        .map(|n| n.end.y)
        .fold(0.0, f32::max);
    let plane = BrushPlane::new(Vec3::ZERO, Vec3::Z).expect("plane");
    let camera = StrokeCamera::facing(plane, 5.0).expect("camera");
    c.bench_function("brush_iteration_20k_internodes", |b| {
        b.iter_batched(
            || {
                let mut stroke = BrushStroke::new(5.0, BrushSettings::default()).expect("stroke");
                stroke
                    .add_point(0.0, camera, Vec3::new(-1.0, top, 0.0), 0.4)
                    .expect("point");
                stroke
                    .add_point(0.1, camera, Vec3::new(1.0, top + 0.5, 0.0), 0.4)
                    .expect("point");
                (tree.clone(), stroke)
            },
            |(mut tree, mut stroke)| {
                // Return the tree so that dropping it stays outside the measurement.
                let stats = stroke.iterate(&mut tree);
                black_box((tree, stats))
            },
            BatchSize::LargeInput,
        )
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bend, brush
}
criterion_main!(benches);
