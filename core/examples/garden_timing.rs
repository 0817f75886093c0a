//! Times gardens of mixed presets grown 20 years together (issue #24, Done when 4): 10 trees on a
//! 10 × 10 m plot and 300 on a 30 × 30 m plot, random layout, on 1 thread and on all cores,
//! printing wall-clock and process CPU time, internodes, the Ripley excess of bases and crowns, and an FNV-1a
//! digest of each garden file (the same for every thread count).
//!
//! `cargo run --release -p sylva-core --example garden_timing [max_trees]`

use std::time::Instant;

use glam::Vec2;
use sylva_core::garden::{RIPLEY_RADIUS_M, ripley_excess};

#[path = "../benches/common/garden_stands.rs"]
mod garden_stands;
use garden_stands::stand;
#[path = "../benches/common/digest.rs"]
mod digest;

/// CPU time of the whole process so far, seconds (all threads): on a shared machine the wall
/// time says how busy the others were, this how much the garden cost.
fn process_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes to it.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if status == 0 {
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

fn main() {
    let max: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(300);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    for (count, side_m) in [(10usize, 10.0f32), (300, 30.0)] {
        if count > max {
            break;
        }
        for threads in [1, cores] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            let (elapsed_s, cpu_s, garden) = pool.install(|| {
                let (started, cpu_started) = (Instant::now(), process_cpu_s());
                let mut garden = stand(count, side_m, 2014);
                garden.grow_years(20.0);
                (
                    started.elapsed().as_secs_f64(),
                    process_cpu_s() - cpu_started,
                    garden,
                )
            });
            let crowns = garden.crowns();
            let (lo, hi) = (Vec2::splat(-0.5 * side_m), Vec2::splat(0.5 * side_m));
            let bases: Vec<Vec2> = crowns
                .iter()
                .map(|c| Vec2::new(c.base.x, c.base.z))
                .collect();
            let centres: Vec<Vec2> = crowns
                .iter()
                .map(|c| Vec2::new(c.centroid.x, c.centroid.z))
                .collect();
            println!(
                "{count:3} trees on {side_m} x {side_m} m, 20 years, {threads} thread(s): {elapsed_s:.3} s wall, {cpu_s:.3} s CPU, {} internodes, crown offset {:.3} m, Ripley excess bases {:?} crowns {:?}, digest {}",
                garden.num_internodes(),
                garden.mean_crown_offset_m(),
                ripley_excess(&bases, lo, hi, RIPLEY_RADIUS_M),
                ripley_excess(&centres, lo, hi, RIPLEY_RADIUS_M),
                digest::fnv1a_hex(&garden.to_json_bytes())
            );
        }
    }
}
