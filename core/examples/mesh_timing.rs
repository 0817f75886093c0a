//! Times meshing of a synthetic 100k-internode tree with leaves, in wall-clock and in CPU time
//! of this thread (Linux `/proc/thread-self/schedstat`), so the one-core cost can be read on a
//! busy machine where criterion's wall-clock figures include waiting for a core.
//!
//! Two builds: the drawn level of detail (level 0) with leaves and fruit, as the app re-meshes
//! after an edit, and all three levels, as the glTF export does; each with fresh buffers and
//! with a [`Mesher`] and output meshes reused from the previous call.
//!
//! `cargo run --release -p sylva-core --example mesh_timing [num_internodes] [repeats]`

use std::time::Instant;

use glam::Vec3;
use sylva_core::geometry::synthetic::{branching_skeleton, crown_ambient};
use sylva_core::geometry::{FruitParams, Levels, MeshParams, Mesher, TreeMeshes};

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
    for (what, levels) in [("level 0", Levels::One(0)), ("all levels", Levels::All)] {
        for reuse in [false, true] {
            let mut mesher = Mesher::new();
            let mut meshes = TreeMeshes::default();
            let mut best_wall = f64::INFINITY;
            let mut best_cpu = f64::INFINITY;
            for _ in 0..repeats {
                if !reuse {
                    (mesher, meshes) = (Mesher::new(), TreeMeshes::default());
                }
                let (wall, cpu) = (Instant::now(), thread_cpu_ns());
                mesher.build_into(&skeleton, &params, &ambient, levels, &mut meshes);
                best_wall = best_wall.min(wall.elapsed().as_secs_f64() * 1e3);
                if let (Some(a), Some(b)) = (cpu, thread_cpu_ns()) {
                    best_cpu = best_cpu.min((b - a) as f64 * 1e-6);
                }
            }
            let triangles: Vec<String> = (0..meshes.lods.len())
                .map(|l| meshes.num_triangles(l).to_string())
                .collect();
            println!(
                "{num_internodes} internodes, {what}, {} buffers: best of {repeats}: \
                 {best_wall:.1} ms wall, {best_cpu:.1} ms CPU; triangles {}, {} leaves",
                if reuse { "reused" } else { "fresh" },
                triangles.join(" / "),
                meshes.leaves.num_triangles() / 2
            );
        }
    }
}
