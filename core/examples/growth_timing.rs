//! Times autonomous growth to 10k, 100k and 300k internodes and one brush-guided iteration on a
//! 20k-internode tree (the trees of `benches/growth.rs`), printing wall-clock, thread CPU and
//! process CPU time (all threads: growth runs on rayon's pool, `RAYON_NUM_THREADS`) per size and
//! per iteration, so the scaling can be read directly. The main thread's CPU leaves out the
//! parallel passes (rayon's pool runs them while the main thread waits): for the brush step,
//! whose work is mostly those passes, read the all-threads CPU or the wall time.
//!
//! `cargo run --release -p sylva-core --example growth_timing [max_internodes]`
//!
//! After each size it prints the time of each step of the iterations
//! (`sylva_core::growth::timing`: buds, points, space, input, vigor, shoots, shed, finish,
//! widths), summed over the iterations: process CPU time (all threads), or wall-clock time with
//! `SYLVA_PHASE_CLOCK=wall`.
//!
//! `SYLVA_VERBOSE=1` prints every iteration; `SYLVA_DIGEST=1` prints an FNV-1a digest of each
//! saved tree (and of the brushed tree), so two builds can be checked to grow the same trees.
//! `SYLVA_BENCH_SPECIES=FILE` writes the benchmark's species there, for `sylva grow --species
//! FILE --years 25 --seed 7` (the 100k tree; 9 and 45 years for 10k and 300k).

use std::time::Instant;

use sylva_core::growth::timing;

#[path = "../benches/common/growth_trees.rs"]
mod growth_trees;
use growth_trees::{brush_iteration, brush_points, grow_to_with, next_brush_tree};

#[path = "../benches/common/digest.rs"]
mod digest;
#[path = "../benches/common/thread_cpu.rs"]
mod thread_cpu;
use thread_cpu::{process_cpu_ns, thread_cpu_ns};

fn cpu_ms(start: Option<u64>) -> f64 {
    elapsed_ms(start, thread_cpu_ns())
}

fn elapsed_ms(start: Option<u64>, now: Option<u64>) -> f64 {
    match (start, now) {
        (Some(a), Some(b)) => (b - a) as f64 / 1e6,
        _ => f64::NAN,
    }
}

/// FNV-1a (64 bit) of the tree's saved JSON.
fn digest(tree: &sylva_core::Tree) -> String {
    digest::fnv1a_hex(&tree.to_json_bytes().expect("tree serializes"))
}

/// The phase totals since the last reset, as one line.
fn phase_line(clock_name: &str) -> String {
    let times = timing::phase_times();
    let parts: Vec<String> = times
        .iter()
        .map(|(phase, t)| format!("{} {:.1}", phase.name(), t.as_secs_f64() * 1e3))
        .collect();
    format!("  phases (ms {clock_name}): {}", parts.join(", "))
}

fn main() {
    // The phases by the process's CPU time (all threads) unless SYLVA_PHASE_CLOCK=wall: on a
    // loaded machine wall time mostly measures waiting for a core.
    let wall_phases = std::env::var("SYLVA_PHASE_CLOCK").is_ok_and(|v| v == "wall");
    let clock: fn() -> u64 = if wall_phases {
        timing::wall_clock_ns
    } else {
        || process_cpu_ns().unwrap_or(0)
    };
    timing::enable_phase_times(Some(clock));
    let clock_name = if wall_phases {
        "wall"
    } else {
        "cpu, all threads"
    };
    let max: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(300_000);
    let verbose = std::env::var_os("SYLVA_VERBOSE").is_some();
    let digests = std::env::var_os("SYLVA_DIGEST").is_some();
    if let Some(path) = std::env::var_os("SYLVA_BENCH_SPECIES") {
        let json = serde_json::to_string_pretty(&growth_trees::bench_species())
            .expect("species serializes");
        std::fs::write(&path, json).expect("species file written");
    }
    for target in [10_000usize, 100_000, 300_000] {
        if target > max {
            break;
        }
        timing::reset_phase_times();
        let (wall, cpu, all_cpu) = (Instant::now(), thread_cpu_ns(), process_cpu_ns());
        let (mut w, mut c) = (Instant::now(), thread_cpu_ns());
        let tree = grow_to_with(target, |tree, stats| {
            if verbose {
                println!(
                    "  it {:3}: {:7} internodes, {:6} buds ({:6} enabled), {:7} points, {:6} new, {:6} shed, {:8.2} ms wall {:8.2} ms cpu",
                    tree.iteration,
                    tree.skeleton.len(),
                    stats.num_buds,
                    stats.num_enabled_buds,
                    stats.num_points,
                    stats.num_new_internodes,
                    stats.num_shed_internodes,
                    w.elapsed().as_secs_f64() * 1e3,
                    cpu_ms(c)
                );
            }
            (w, c) = (Instant::now(), thread_cpu_ns());
        });
        println!(
            "grow to {:>6} internodes ({} reached in {} iterations): {:8.1} ms wall, {:8.1} ms cpu, {:8.1} ms cpu on {} threads",
            target,
            tree.skeleton.len(),
            tree.iteration,
            wall.elapsed().as_secs_f64() * 1e3,
            cpu_ms(cpu),
            elapsed_ms(all_cpu, process_cpu_ns()),
            rayon::current_num_threads()
        );
        println!("{}", phase_line(clock_name));
        if digests {
            println!("  digest {}", digest(&tree));
        }
    }
    let tree = grow_to_with(20_000, |_, _| {});
    let points = brush_points(&tree);
    let (mut best_wall, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
    let mut best_all_cpu = f64::INFINITY;
    let mut total_wall = 0.0;
    let repeats: u64 = std::env::var("SYLVA_BRUSH_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    // As in the criterion bench: warm working memory, the 20k tree restored now and then.
    let mut t = tree.clone();
    timing::reset_phase_times();
    for i in 0..repeats {
        next_brush_tree(i, &mut t, &tree, &points);
        let (w, c, all) = (Instant::now(), thread_cpu_ns(), process_cpu_ns());
        brush_iteration(&mut t);
        let wall_ms = w.elapsed().as_secs_f64() * 1e3;
        best_wall = best_wall.min(wall_ms);
        total_wall += wall_ms;
        best_cpu = best_cpu.min(cpu_ms(c));
        best_all_cpu = best_all_cpu.min(elapsed_ms(all, process_cpu_ns()));
    }
    println!(
        "brush iteration on {} internodes: best {best_wall:.2} ms wall, {best_cpu:.2} ms cpu (main thread), {best_all_cpu:.2} ms cpu (all threads), mean {:.2} ms wall",
        tree.skeleton.len(),
        total_wall / repeats.max(1) as f64
    );
    println!(
        "{} (all {repeats} steps and the restores' steps)",
        phase_line(clock_name)
    );
    if digests {
        println!("  digest after {repeats} brush steps {}", digest(&t));
    }
}
