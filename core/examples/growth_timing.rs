//! Times autonomous growth to 10k, 100k and 300k internodes and one brush-guided iteration on a
//! 20k-internode tree (the trees of `benches/growth.rs`), printing wall-clock and thread CPU time
//! per size and per iteration, so the scaling can be read directly.
//!
//! `cargo run --release -p sylva-core --example growth_timing [max_internodes]`

use std::time::Instant;

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::growth::StepOptions;
use sylva_core::rng::Rng;
use sylva_core::species::Species;

/// Nanoseconds this thread has run on a CPU; `None` off Linux.
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// The benchmark species (see `benches/growth.rs`).
fn bench_species() -> Species {
    let mut s = Species::by_name("maple").expect("maple preset");
    s.internode_length_m = 0.04;
    s.max_shoot_internodes = 12.0;
    s.shoot_length_halving_age_years = 0.0;
    s
}

fn cpu_ms(start: Option<u64>) -> f64 {
    match (start, thread_cpu_ns()) {
        (Some(a), Some(b)) => (b - a) as f64 / 1e6,
        _ => f64::NAN,
    }
}

fn main() {
    let max: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(300_000);
    let verbose = std::env::var_os("SYLVA_VERBOSE").is_some();
    for target in [10_000usize, 100_000, 300_000] {
        if target > max {
            break;
        }
        let mut tree = Tree::new(bench_species(), 7);
        let (wall, cpu) = (Instant::now(), thread_cpu_ns());
        while tree.skeleton.len() < target && tree.iteration < 400 {
            let (w, c) = (Instant::now(), thread_cpu_ns());
            let stats = tree.step(StepOptions {
                autonomous: true,
                scene: None,
            });
            if verbose {
                println!(
                    "  it {:3}: {:7} internodes, {:6} buds, {:7} points, {:8.2} ms wall {:8.2} ms cpu",
                    tree.iteration,
                    tree.skeleton.len(),
                    stats.num_buds,
                    stats.num_points,
                    w.elapsed().as_secs_f64() * 1e3,
                    cpu_ms(c)
                );
            }
        }
        println!(
            "grow to {:>6} internodes ({} reached in {} iterations): {:8.1} ms wall, {:8.1} ms cpu",
            target,
            tree.skeleton.len(),
            tree.iteration,
            wall.elapsed().as_secs_f64() * 1e3,
            cpu_ms(cpu)
        );
    }
    let mut tree = Tree::new(bench_species(), 7);
    while tree.skeleton.len() < 20_000 {
        tree.step(StepOptions {
            autonomous: true,
            scene: None,
        });
    }
    let top = tree.metrics().height_m;
    let mut rng = Rng::new(11);
    let centre = Vec3::new(0.0, top + 0.2, 0.0);
    let points: Vec<Vec3> = (0..300)
        .map(|_| centre + rng.in_unit_ball() * 0.4)
        .collect();
    let (mut best_wall, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
    let repeats: usize = std::env::var("SYLVA_BRUSH_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    // As in the app and the criterion bench: the tree steps with warm working memory; it is
    // restored to the 20k tree every 8 steps (untimed).
    let mut t = tree.clone();
    for i in 0..repeats {
        if i % 8 == 0 {
            t = tree.clone();
            for p in &points {
                t.environment.attraction.add_persistent(*p);
            }
            t.step(StepOptions {
                autonomous: false,
                scene: None,
            });
        }
        for p in &points {
            t.environment.attraction.add_persistent(*p);
        }
        let (w, c) = (Instant::now(), thread_cpu_ns());
        t.step(StepOptions {
            autonomous: false,
            scene: None,
        });
        best_wall = best_wall.min(w.elapsed().as_secs_f64() * 1e3);
        best_cpu = best_cpu.min(cpu_ms(c));
    }
    println!(
        "brush iteration on {} internodes: best {best_wall:.2} ms wall, {best_cpu:.2} ms cpu",
        tree.skeleton.len()
    );
}
