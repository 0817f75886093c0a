//! Times meshing of a synthetic 100k-internode tree with leaves, in wall-clock and in CPU time
//! of this thread (Linux `/proc/thread-self/schedstat`), so the one-core cost can be read on a
//! busy machine where criterion's wall-clock figures include waiting for a core.
//!
//! `cargo run --release -p sylva-core --example mesh_timing [num_internodes] [repeats]`

use std::time::Instant;

use glam::Vec3;
use sylva_core::geometry::synthetic::{branching_skeleton, crown_ambient};
use sylva_core::geometry::{FruitParams, MeshParams, TreeMeshes, build_meshes_into};

/// Nanoseconds this thread has run on a CPU; `None` off Linux.
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let num_internodes: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let repeats: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(10);
    let skeleton = branching_skeleton(num_internodes, 7);
    let params = MeshParams {
        fruit: Some(FruitParams::default()),
        ..MeshParams::default()
    };
    let ambient = crown_ambient(Vec3::new(0.0, 1.5, 0.0), 2.0);
    let mut meshes = TreeMeshes::default();
    for pass in ["fresh buffers", "reused buffers"] {
        let mut best_wall = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        for _ in 0..repeats {
            if pass == "fresh buffers" {
                meshes = TreeMeshes::default();
            }
            let (wall, cpu) = (Instant::now(), thread_cpu_ns());
            build_meshes_into(&skeleton, &params, &ambient, &mut meshes);
            best_wall = best_wall.min(wall.elapsed().as_secs_f64() * 1e3);
            if let (Some(a), Some(b)) = (cpu, thread_cpu_ns()) {
                best_cpu = best_cpu.min((b - a) as f64 * 1e-6);
            }
        }
        println!(
            "{num_internodes} internodes, {pass}: best of {repeats}: {best_wall:.1} ms wall, {best_cpu:.1} ms CPU; \
             LOD triangles {} / {} / {}, {} leaves",
            meshes.num_triangles(0),
            meshes.num_triangles(1),
            meshes.num_triangles(2),
            meshes.leaves.num_triangles() / 2
        );
    }
}
