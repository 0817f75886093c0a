//! Garden benchmark (issue #24, Done when 4): ten seedlings of the six presets at random on a
//! 10 × 10 m plot grown 20 years together, on rayon's pool (all cores). Target: ≤ 0.3 s wall on
//! the 2-core machine. The 300-tree figure comes from `examples/garden_timing.rs` (one run takes
//! far longer than criterion's samples should).

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

#[path = "common/garden_stands.rs"]
mod garden_stands;
use garden_stands::{EDITS, alone, stand};

fn garden_growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("garden_growth");
    group.sample_size(10);
    group.throughput(Throughput::Elements(10));
    group.bench_function("10_trees_20_years", |b| {
        b.iter(|| {
            let mut garden = stand(10, 10.0, 2014);
            garden.grow_years(20.0);
            black_box(garden.num_internodes())
        })
    });
    group.finish();
}

/// Done when 5: an edit of tree 4 of the ten (grown 10 years) by `Garden::edit_tree`, against
/// the same edit of that tree standing alone (target: at most 20% more). Each sample edits a
/// fresh copy: the first edit of a tree, which also casts all its neighbours' shade into it.
fn garden_edits(c: &mut Criterion) {
    let mut garden = stand(10, 10.0, 2014);
    garden.grow_years(10.0);
    let mut group = c.benchmark_group("garden_edit");
    group.sample_size(20);
    for (name, edit) in EDITS {
        group.bench_function(format!("{name}_in_garden"), |b| {
            b.iter_batched(
                || garden.clone(),
                |mut g| black_box(g.edit_tree(4, edit)),
                criterion::BatchSize::LargeInput,
            )
        });
        group.bench_function(format!("{name}_alone"), |b| {
            b.iter_batched(
                || alone(&garden, 4),
                |mut tree| {
                    edit(&mut tree);
                    black_box(tree.skeleton.len())
                },
                criterion::BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, garden_growth, garden_edits);
criterion_main!(benches);
