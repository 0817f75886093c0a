//! Growth benchmarks: autonomous growth to 10k, 100k and 300k internodes with the full model
//! (space colonization, shadow grid, vigor, shedding, widths), and one brush-guided iteration on
//! a 20k-internode tree. Growth runs on rayon's pool: run once with `RAYON_NUM_THREADS=1` and
//! once with `RAYON_NUM_THREADS=2` (the trees are the same on both). Targets: one core, 100k
//! internodes ≤ 0.5 s and brush iteration ≤ 4 ms; two cores (issue #26), 100k ≤ 0.34 s, 300k
//! ≤ 1.45 s, brush iteration on the 22k tree ≤ 0.5 ms.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

#[path = "common/growth_trees.rs"]
mod growth_trees;
use growth_trees::{brush_iteration, brush_points, grow_to_with, next_brush_tree};

fn autonomous_growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("autonomous_growth");
    group.sample_size(10);
    for target in [10_000usize, 100_000, 300_000] {
        group.throughput(Throughput::Elements(target as u64));
        group.bench_function(format!("{}k_internodes", target / 1000), |b| {
            b.iter(|| black_box(grow_to_with(target, |_, _| {})).skeleton.len())
        });
    }
    group.finish();
}

fn brush_iterations(c: &mut Criterion) {
    let tree = grow_to_with(20_000, |_, _| {});
    let points = brush_points(&tree);
    let mut group = c.benchmark_group("brush_iteration");
    // As under a finger in the app: the same tree steps again and again with warm working
    // memory, restored now and then (untimed) so it does not outgrow 20k.
    group.bench_function("20k_internodes", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut t = tree.clone();
            for i in 0..iters {
                next_brush_tree(i, &mut t, &tree, &points);
                let start = Instant::now();
                black_box(brush_iteration(&mut t));
                total += start.elapsed();
            }
            total
        })
    });
    group.finish();
}

criterion_group!(benches, autonomous_growth, brush_iterations);
criterion_main!(benches);
