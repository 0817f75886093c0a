//! Growth benchmarks: autonomous growth to 10k, 100k and 300k internodes with the full model
//! (space colonization, shadow grid, vigor, shedding, widths), and one brush-guided iteration on
//! a 20k-internode tree. Targets (one core): 100k internodes ≤ 0.5 s, linear scaling,
//! brush iteration ≤ 4 ms.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use sylva_core::Tree;
use sylva_core::growth::StepOptions;
use sylva_core::rng::Rng;
use sylva_core::species::Species;

const SEED: u64 = 7;

/// Maple with short internodes (4 cm), long shoots (n_max = 12) and no age slow-down: a dense
/// crown that reaches 100k internodes in about 24 iterations.
fn bench_species() -> Species {
    let mut s = Species::by_name("maple").expect("maple preset");
    s.internode_length_m = 0.04;
    s.max_shoot_internodes = 12.0;
    s.shoot_length_halving_age_years = 0.0;
    s
}

/// Grows autonomously until the tree has at least `target` internodes.
fn grow_to(target: usize) -> Tree {
    let mut tree = Tree::new(bench_species(), SEED);
    while tree.skeleton.len() < target && tree.iteration < 400 {
        tree.step(StepOptions {
            autonomous: true,
            scene: None,
        });
    }
    tree
}

fn autonomous_growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("autonomous_growth");
    group.sample_size(10);
    for target in [10_000usize, 100_000, 300_000] {
        group.throughput(Throughput::Elements(target as u64));
        group.bench_function(format!("{}k_internodes", target / 1000), |b| {
            b.iter(|| black_box(grow_to(target)).skeleton.len())
        });
    }
    group.finish();
}

fn brush_iteration(c: &mut Criterion) {
    let tree = grow_to(20_000);
    let top = tree.metrics().height_m;
    let mut rng = Rng::new(11);
    // A brush dab: 300 points in a 0.4 m sphere just outside the crown top.
    let centre = Vec3::new(0.0, top + 0.2, 0.0);
    let points: Vec<Vec3> = (0..300)
        .map(|_| centre + rng.in_unit_ball() * 0.4)
        .collect();
    let mut group = c.benchmark_group("brush_iteration");
    // As under a finger in the app: the same tree steps again and again with warm working
    // memory. Every few steps the 20k tree is restored (untimed) so it does not outgrow 20k.
    group.bench_function("20k_internodes", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut t = tree.clone();
            for i in 0..iters {
                if i % STEPS_PER_RESTORE == 0 {
                    t = tree.clone();
                    brush_step(&mut t, &points);
                }
                for p in &points {
                    t.environment.attraction.add_persistent(*p);
                }
                let start = Instant::now();
                black_box(t.step(StepOptions {
                    autonomous: false,
                    scene: None,
                }));
                total += start.elapsed();
            }
            total
        })
    });
    group.finish();
}

/// Brush steps between restores of the 20k tree in the brush benchmark.
const STEPS_PER_RESTORE: u64 = 8;

/// One untimed brush step (warms the tree's working memory after a clone).
fn brush_step(tree: &mut Tree, points: &[Vec3]) {
    for p in points {
        tree.environment.attraction.add_persistent(*p);
    }
    tree.step(StepOptions {
        autonomous: false,
        scene: None,
    });
}

criterion_group!(benches, autonomous_growth, brush_iteration);
criterion_main!(benches);
