//! Depth mesh speed: an incremental frame update with 1,000 visible points of which 10 %
//! change (target ≤ 0.5 ms), the same share of 10,000 points, 100 changes among 10,000 points
//! (the cost follows the changed points, not the points held), and depth queries per second
//! in random and in scan-line pixel order.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec2;
use sylva_tracking::depth_mesh::{DepthMesh, DepthMeshConfig, Observation, PinholeIntrinsics};

/// Fixed seed for the random scene.
const SEED: u64 = 0xbe4c_0001;

fn next(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

fn camera() -> PinholeIntrinsics {
    PinholeIntrinsics {
        width: 640,
        height: 480,
        fx: 525.0,
        fy: 525.0,
        cx: 319.5,
        cy: 239.5,
    }
}

/// Depth of a ground plane seen from 1.5 m, pitched 30° down (inverse depth affine in v).
fn ground_depth(pixel: Vec2) -> f32 {
    let inverse = (0.5 + 0.866 * (pixel.y - 239.5) / 525.0) / 1.5;
    1.0 / inverse.max(0.02)
}

fn observation(id: u64, state: &mut u64) -> Observation {
    let pixel = Vec2::new(next(state) * 639.0, next(state) * 479.0);
    Observation {
        id,
        pixel,
        depth_m: ground_depth(pixel),
    }
}

/// Changes `num_changed` random points of `frame`: a third lost (replaced by new points),
/// two thirds moved by up to 3 pixels (jitter, the hard case for keeping vertices in place).
fn change_frame(frame: &mut [Observation], num_changed: usize, next_id: &mut u64, state: &mut u64) {
    for k in 0..num_changed {
        let index = (next(state) * frame.len() as f32) as usize % frame.len();
        if k % 3 == 0 {
            frame[index] = observation(*next_id, state);
            *next_id += 1;
        } else {
            let pixel = (frame[index].pixel
                + Vec2::new(next(state) - 0.5, next(state) - 0.5) * 6.0)
                .clamp(Vec2::ZERO, Vec2::new(639.0, 479.0));
            frame[index] = Observation {
                pixel,
                depth_m: ground_depth(pixel),
                ..frame[index]
            };
        }
    }
}

fn update_bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("depth_mesh_update");
    for (name, num_points, num_changed) in [
        ("10pct_changed", 1_000u64, 100usize),
        ("10pct_changed", 10_000, 1_000),
        ("100_changed", 10_000, 100),
    ] {
        let mut state = SEED;
        let mut frame: Vec<Observation> = (0..num_points)
            .map(|id| observation(id, &mut state))
            .collect();
        let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
        mesh.update(&frame);
        let mut next_id = num_points;
        group.throughput(Throughput::Elements(num_changed as u64));
        group.bench_function(BenchmarkId::new(name, num_points), |b| {
            b.iter(|| {
                change_frame(&mut frame, num_changed, &mut next_id, &mut state);
                mesh.update(&frame)
            })
        });
    }
    group.finish();
}

fn query_bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("depth_mesh_query");
    for num_points in [1_000u64, 10_000] {
        let mut state = SEED;
        let frame: Vec<Observation> = (0..num_points)
            .map(|id| observation(id, &mut state))
            .collect();
        let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
        mesh.update(&frame);
        let random: Vec<Vec2> = (0..10_000)
            .map(|_| Vec2::new(next(&mut state) * 639.0, next(&mut state) * 479.0))
            .collect();
        // Every 4th pixel of every 4th row, row by row (a depth image at quarter resolution).
        let scan: Vec<Vec2> = (0..120)
            .flat_map(|row| (0..160).map(move |column| Vec2::new(column as f32, row as f32) * 4.0))
            .collect();
        for (order, probes) in [("random", &random), ("scan", &scan)] {
            group.throughput(Throughput::Elements(probes.len() as u64));
            let id = BenchmarkId::new(format!("depth_at_{order}_pixels"), num_points);
            group.bench_function(id, |b| {
                b.iter(|| {
                    probes
                        .iter()
                        .filter_map(|&p| mesh.depth_at(p).depth_m())
                        .sum::<f32>()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, update_bench, query_bench);
criterion_main!(benches);
