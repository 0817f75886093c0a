//! Meshing benchmarks: branches at three levels of detail, leaves and fruit of synthetic
//! branching skeletons of 1k, 10k and 100k internodes. Target (one core): the 100k-internode
//! tree with leaves in ≤ 50 ms. Also the GLB encoding of the 10k tree.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use sylva_core::export::glb_bytes;
use sylva_core::geometry::synthetic::{branching_skeleton, crown_ambient};
use sylva_core::geometry::{FruitParams, MeshParams, TreeMeshes, build_meshes, build_meshes_into};

const SEED: u64 = 7;

fn meshing(c: &mut Criterion) {
    let params = MeshParams {
        fruit: Some(FruitParams::default()),
        ..MeshParams::default()
    };
    let ambient = crown_ambient(Vec3::new(0.0, 1.5, 0.0), 2.0);
    let mut group = c.benchmark_group("build_meshes");
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
        group.bench_function(format!("{num_internodes}_internodes_with_leaves"), |b| {
            b.iter(|| black_box(build_meshes(black_box(&skeleton), &params, &ambient)))
        });
        // Interactive re-meshing: the buffers of the previous mesh are reused.
        let mut reused = TreeMeshes::default();
        group.bench_function(
            format!("{num_internodes}_internodes_with_leaves_reusing_buffers"),
            |b| b.iter(|| build_meshes_into(black_box(&skeleton), &params, &ambient, &mut reused)),
        );
    }
    group.finish();

    let skeleton = branching_skeleton(10_000, SEED);
    let meshes = build_meshes(&skeleton, &params, &ambient);
    c.bench_function("glb_bytes_10k_internodes", |b| {
        b.iter(|| black_box(glb_bytes(black_box(&meshes)).expect("encodes")))
    });
}

criterion_group!(benches, meshing);
criterion_main!(benches);
