//! Meshing benchmarks on synthetic branching skeletons of 1k, 10k and 100k internodes, with
//! leaves and fruit.
//!
//! - `mesh_drawn_level`: the finest level of detail (the one the app draws) plus the leaf and
//!   fruit buffers, as the app re-meshes after an edit. Issue #4's target (one core): the
//!   100k-internode tree in ≤ 50 ms.
//! - `mesh_all_levels`: all three levels of detail plus leaves and fruit, as the glTF export
//!   builds them.
//!
//! Each with fresh buffers and with a [`Mesher`] and output meshes reused from the previous
//! call. Also the GLB encoding of the 10k tree.
//!
//! - `mesh_drawn_level_cpu`: the 100k drawn level reusing buffers again, measured in CPU time
//!   of the benchmark thread (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`) instead of wall-clock
//!   time: the one-core cost, without the time spent waiting for a core on a busy machine.

use std::hint::black_box;

#[path = "common/thread_cpu.rs"]
mod thread_cpu;

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use sylva_core::export::glb_bytes;
use sylva_core::geometry::synthetic::{branching_skeleton, crown_ambient};
use sylva_core::geometry::{
    FruitParams, Levels, MeshParams, Mesher, TreeMeshes, build_level, build_meshes,
};

const SEED: u64 = 7;

fn params() -> MeshParams {
    MeshParams {
        fruit: Some(FruitParams::default()),
        ..MeshParams::default()
    }
}

fn meshing(c: &mut Criterion) {
    let params = params();
    let ambient = crown_ambient(Vec3::new(0.0, 1.5, 0.0), 2.0);
    for (group_name, levels) in [
        ("mesh_drawn_level", Levels::One(0)),
        ("mesh_all_levels", Levels::All),
    ] {
        let mut group = c.benchmark_group(group_name);
        group.sample_size(20);
        for num_internodes in [1_000, 10_000, 100_000] {
            let skeleton = branching_skeleton(num_internodes, SEED);
            let meshes = build_meshes(&skeleton, &params, &ambient);
            println!(
                "{num_internodes} internodes: {} leaves, LOD triangles {} / {} / {}",
                meshes.leaves.num_triangles() / 2,
                meshes.num_triangles(0),
                meshes.num_triangles(1),
                meshes.num_triangles(2)
            );
            group.throughput(Throughput::Elements(num_internodes as u64));
            let name = match levels {
                Levels::One(_) => format!("{num_internodes}_internodes_level0_with_leaves"),
                Levels::All => format!("{num_internodes}_internodes_3_lods_with_leaves"),
            };
            group.bench_function(&name, |b| {
                b.iter(|| match levels {
                    Levels::One(level) => {
                        black_box(build_level(black_box(&skeleton), &params, &ambient, level))
                    }
                    Levels::All => black_box(build_meshes(black_box(&skeleton), &params, &ambient)),
                })
            });
            // Interactive re-meshing: working memory and output buffers of the previous call
            // are reused.
            let mut mesher = Mesher::new();
            let mut reused = TreeMeshes::default();
            group.bench_function(format!("{name}_reusing_buffers"), |b| {
                b.iter(|| {
                    mesher.build_into(black_box(&skeleton), &params, &ambient, levels, &mut reused)
                })
            });
        }
        group.finish();
    }

    let skeleton = branching_skeleton(10_000, SEED);
    let meshes = build_meshes(&skeleton, &params, &ambient);
    c.bench_function("glb_bytes_10k_internodes", |b| {
        b.iter(|| black_box(glb_bytes(black_box(&meshes)).expect("encodes")))
    });
}

/// CPU time of the calling thread, in nanoseconds (wall-clock time where the kernel does not
/// report it).
struct ThreadCpuTime;

impl ThreadCpuTime {
    fn now_ns() -> u64 {
        thread_cpu::thread_cpu_ns().unwrap_or_else(|| {
            static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
            START
                .get_or_init(std::time::Instant::now)
                .elapsed()
                .as_nanos() as u64
        })
    }
}

impl Measurement for ThreadCpuTime {
    type Intermediate = u64;
    type Value = u64;

    fn start(&self) -> u64 {
        Self::now_ns()
    }

    fn end(&self, start: u64) -> u64 {
        Self::now_ns().saturating_sub(start)
    }

    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }

    fn zero(&self) -> u64 {
        0
    }

    fn to_f64(&self, value: &u64) -> f64 {
        *value as f64
    }

    fn formatter(&self) -> &dyn ValueFormatter {
        // Nanoseconds, as wall-clock time: shown as durations.
        WallTime.formatter()
    }
}

fn meshing_cpu(c: &mut Criterion<ThreadCpuTime>) {
    let params = params();
    let ambient = crown_ambient(Vec3::new(0.0, 1.5, 0.0), 2.0);
    let skeleton = branching_skeleton(100_000, SEED);
    let mut group = c.benchmark_group("mesh_drawn_level_cpu");
    group.sample_size(20);
    group.throughput(Throughput::Elements(100_000));
    let mut mesher = Mesher::new();
    let mut reused = TreeMeshes::default();
    group.bench_function(
        "100000_internodes_level0_with_leaves_reusing_buffers",
        |b| {
            b.iter(|| {
                mesher.build_into(
                    black_box(&skeleton),
                    &params,
                    &ambient,
                    Levels::One(0),
                    &mut reused,
                )
            })
        },
    );
    group.finish();
}

criterion_group!(benches, meshing);
criterion_group! {
    name = cpu_benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = meshing_cpu
}
criterion_main!(benches, cpu_benches);
