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

use std::hint::black_box;

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

criterion_group!(benches, meshing);
criterion_main!(benches);
