//! Garden benchmark (issue #24, Done when 4): ten seedlings of the six presets at random on a
//! 10 × 10 m plot grown 20 years together, on rayon's pool (all cores). Target: ≤ 0.3 s wall on
//! the 2-core machine. The 300-tree figure comes from `examples/garden_timing.rs` (one run takes
//! far longer than criterion's samples should).

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

#[path = "common/garden_stands.rs"]
mod garden_stands;
use garden_stands::stand;

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

criterion_group!(benches, garden_growth);
criterion_main!(benches);
